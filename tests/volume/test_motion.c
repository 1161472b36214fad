/* Boundary motion by patch kind (motion.h) on hex blocks built here: the kinds from the patch
 * kinds and the user's choice, lines where two slide planes meet, the 2-D and wedge
 * recognition, the projection, cm_warp_mesh under a motion (slide nodes keep their plane
 * exactly, 2-D pairs one motion, wedge planes planar) and, without slides, the same bits as
 * the warp without a motion (docs/DESIGN.md, "Boundary motion by patch kind"). */
#include "cadmorph/motion.h"
#include "cadmorph/warp.h"

#include "test_mesh.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { SIDE_XMIN, SIDE_XMAX, SIDE_YMIN, SIDE_YMAX, SIDE_ZMIN, SIDE_ZMAX };

#define NODE(i, j, k) ((int64_t)(i) + (int64_t)(nx + 1) * ((j) + (int64_t)(ny + 1) * (k)))

/* A block of nx x ny x nz hexes on [0,nx h] x [0,ny h] x [0,nz hz] with its six sides as quads of
 * the groups tags[side] (dim 2; tag 0: no quads), named names[side], of the kinds kinds[side]
 * (two sides may share a group). */
static cm_mesh *block(cm_context *ctx, int nx, int ny, int nz, double hz, const int tags[6],
                      const char *const names[6], const cm_patch_kind kinds[6])
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block b = {.nx = nx, .ny = ny, .nz = nz, .h = {1.0 / nx, 1.0 / ny, hz}};
    uint64_t seed = 1;
    test_add_block(ctx, m, &b, &seed);
    for (int s = 0; s < 6; ++s) {
        if (!tags[s]) continue;
        int seen = 0;
        for (size_t g = 0; g < m->n_groups; ++g)
            seen |= m->groups[g].tag == tags[s];
        if (!seen) {
            cm_mesh_add_group(ctx, m, 2, tags[s], names[s]);
            m->groups[m->n_groups - 1].kind = kinds[s];
        }
        int d = s / 2, hi = s % 2, n[3] = {nx, ny, nz};
        int a = (d + 1) % 3, c = (d + 2) % 3;
        for (int u = 0; u < n[a]; ++u)
            for (int v = 0; v < n[c]; ++v) {
                int64_t q[4];
                static const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
                for (int k = 0; k < 4; ++k) {
                    int ijk[3];
                    ijk[d] = hi ? n[d] : 0, ijk[a] = u + du[k], ijk[c] = v + dv[k];
                    q[k] = NODE(ijk[0], ijk[1], ijk[2]);
                }
                cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, q, 4, tags[s], 0, 0);
            }
    }
    return m;
}

static cm_boundary_motion *motion_of(cm_context *ctx, const cm_mesh *m, const unsigned char *pre,
                                     const cm_motion_options *opt, cm_status *st)
{
    cm_mesh_boundary *b = NULL;
    cm_boundary_motion *mo = NULL;
    *st = cm_mesh_boundary_create(ctx, m, &b);
    if (*st >= 0) *st = cm_boundary_motion_create(ctx, m, b, pre, opt, &mo);
    cm_mesh_boundary_destroy(&b);
    return mo;
}

/* 3-D: a symmetry plane y = 0 and a symmetry plane z = 0 (their edge: a line along x), plain
 * sides fixed, one interior node prescribed. */
static void test_kinds_3d(cm_context *ctx)
{
    const int nx = 6, ny = 5, nz = 4;
    const int tags[6] = {1, 2, 3, 4, 5, 6};
    const char *const names[6] = {"inlet", "outlet", "sym", "top", "back", "front"};
    const cm_patch_kind kinds[6] = {CM_PATCH_PLAIN, CM_PATCH_PLAIN, CM_PATCH_SYMMETRY,
                                    CM_PATCH_PLAIN, CM_PATCH_SYMMETRY, CM_PATCH_PLAIN};
    cm_mesh *m = block(ctx, nx, ny, nz, 0.25, tags, names, kinds);
    size_t n = m->n_nodes, p = (size_t)NODE(3, 2, 2);
    unsigned char *pre = calloc(n, 1);
    pre[p] = 1;
    cm_status s;
    cm_boundary_motion *mo = motion_of(ctx, m, pre, NULL, &s);
    CHECK(s == CM_OK && mo);
    CHECK(cm_boundary_motion_kind(mo, p) == CM_MOTION_PRESCRIBED);
    CHECK(cm_boundary_motion_kind(mo, (size_t)NODE(3, 0, 2)) == CM_MOTION_SLIDE_PLANE);
    CHECK(cm_boundary_motion_kind(mo, (size_t)NODE(3, 2, 0)) == CM_MOTION_SLIDE_PLANE);
    CHECK(cm_boundary_motion_kind(mo, (size_t)NODE(3, 0, 0)) == CM_MOTION_SLIDE_LINE);
    CHECK(cm_boundary_motion_kind(mo, (size_t)NODE(0, 0, 0)) == CM_MOTION_FIXED);
    CHECK(cm_boundary_motion_kind(mo, (size_t)NODE(3, 5, 2)) == CM_MOTION_FIXED);
    CHECK(cm_boundary_motion_kind(mo, (size_t)NODE(2, 2, 2)) == CM_MOTION_FREE);
    CHECK(cm_boundary_motion_reduction(mo, NULL, NULL) == CM_MOTION_3D);
    CHECK(cm_boundary_motion_count(mo, CM_MOTION_SLIDE_LINE) == (size_t)(nx - 1));
    /* the projection: plane nodes lose their normal component, line nodes all but x */
    double *d = calloc(3 * n, sizeof *d), *x0 = malloc(3 * n * sizeof *x0);
    for (size_t i = 0; i < 3 * n; ++i)
        d[i] = 0.01 * (double)(i % 7) - 0.02;
    CHECK(cm_boundary_motion_project(ctx, mo, d) == CM_OK);
    CHECK(d[3 * NODE(3, 0, 2) + 1] == 0 && d[3 * NODE(3, 2, 0) + 2] == 0);
    CHECK(d[3 * NODE(3, 0, 0) + 1] == 0 && d[3 * NODE(3, 0, 0) + 2] == 0);
    CHECK(d[3 * NODE(0, 0, 0)] == 0 && d[3 * NODE(3, 5, 2) + 1] == 0);
    /* the warp: the prescribed node moves, the symmetry nodes slide in their planes */
    memset(d, 0, 3 * n * sizeof *d);
    d[3 * p] = 0.05, d[3 * p + 1] = -0.04, d[3 * p + 2] = -0.03;
    memcpy(x0, m->xyz, 3 * n * sizeof *x0);
    cm_warp_mesh_stats st;
    s = cm_warp_mesh(ctx, m, d, pre, mo, NULL, NULL, NULL, &st);
    CHECK(s == CM_OK);
    CHECK(st.slide_nodes > 0);
    size_t slid = 0, bad = 0;
    for (size_t i = 0; i < n; ++i) {
        cm_motion_kind k = cm_boundary_motion_kind(mo, i);
        const double *a = x0 + 3 * i, *b = m->xyz + 3 * i;
        if (k == CM_MOTION_FIXED) bad += a[0] != b[0] || a[1] != b[1] || a[2] != b[2];
        if (a[1] == 0 && k != CM_MOTION_FIXED) bad += b[1] != 0, slid += b[0] != a[0];
        if (a[2] == 0 && k != CM_MOTION_FIXED) bad += b[2] != 0;
    }
    CHECK_MSG(bad == 0, "%zu nodes off their constraint", bad);
    CHECK(slid > 0);
    CHECK(m->xyz[3 * p] == x0[3 * p] + 0.05);
    cm_boundary_motion_destroy(&mo);
    free(d), free(x0), free(pre);
    cm_mesh_destroy(&m);
}

/* Without a sliding patch (and with --no-slide), the same bits as without a motion. */
static void test_as_before(cm_context *ctx)
{
    const int nx = 5, ny = 4, nz = 3;
    const int tags[6] = {1, 1, 1, 2, 3, 3};
    const char *const names[6] = {"walls", "walls", "walls", "lid", "sides", "sides"};
    const cm_patch_kind plain[6] = {0, 0, 0, 0, 0, 0};
    const cm_patch_kind sym[6] = {0, 0, 0, 0, CM_PATCH_SYMMETRY, CM_PATCH_SYMMETRY};
    for (int variant = 0; variant < 2; ++variant) {
        cm_mesh *m0 = block(ctx, nx, ny, nz, 1.0 / nz, tags, names, variant ? sym : plain);
        cm_mesh *m1 = NULL;
        cm_mesh_copy(ctx, m0, &m1);
        size_t n = m0->n_nodes;
        unsigned char *pre = calloc(n, 1);
        double *d0 = calloc(3 * n, sizeof *d0), *d1 = calloc(3 * n, sizeof *d1);
        for (int i = 1; i < nx; ++i) { /* the lid moves up in a bump */
            size_t v = (size_t)NODE(i, ny, 1);
            pre[v] = 1, d0[3 * v + 1] = d1[3 * v + 1] = 0.02 * i * (nx - i);
        }
        cm_motion_options opt;
        cm_motion_options_init(&opt);
        opt.all_fixed = variant;
        cm_status s;
        cm_boundary_motion *mo = motion_of(ctx, m1, pre, &opt, &s);
        CHECK(s == CM_OK && cm_boundary_motion_count(mo, CM_MOTION_SLIDE_PLANE) == 0);
        CHECK(cm_warp_mesh(ctx, m0, d0, pre, NULL, NULL, NULL, NULL, NULL) == CM_OK);
        CHECK(cm_warp_mesh(ctx, m1, d1, pre, mo, NULL, NULL, NULL, NULL) == CM_OK);
        CHECK_MSG(!memcmp(m0->xyz, m1->xyz, 3 * n * sizeof *m0->xyz), "variant %d", variant);
        CHECK(m0->xyz[3 * NODE(2, 2, 1) + 1] != 0.5); /* the interior moved */
        cm_boundary_motion_destroy(&mo);
        free(pre), free(d0), free(d1);
        cm_mesh_destroy(&m0), cm_mesh_destroy(&m1);
    }
}

/* One cell thick between two empty planes: a 2-D mesh; a handle on the front plane only
 * moves its partner too; motion out of the plane is dropped with a warning. */
static void test_2d(cm_context *ctx)
{
    const int nx = 8, ny = 6, nz = 1;
    const int tags[6] = {1, 1, 2, 3, 4, 4};
    const char *const names[6] = {"ends", "ends", "floor", "lid", "frontAndBack", "frontAndBack"};
    const cm_patch_kind kinds[6] = {0, 0, 0, 0, CM_PATCH_EMPTY, CM_PATCH_EMPTY};
    cm_mesh *m = block(ctx, nx, ny, nz, 0.1, tags, names, kinds);
    size_t n = m->n_nodes;
    unsigned char *pre = calloc(n, 1);
    double *d = calloc(3 * n, sizeof *d), *x0 = malloc(3 * n * sizeof *x0);
    for (int i = 2; i <= 6; ++i) { /* the lid's middle, front plane only, with some dz */
        size_t v = (size_t)NODE(i, ny, 1);
        pre[v] = 1, d[3 * v] = 0.03, d[3 * v + 1] = -0.02 * (i - 1), d[3 * v + 2] = 0.01;
    }
    cm_status s;
    cm_boundary_motion *mo = motion_of(ctx, m, pre, NULL, &s);
    CHECK(s == CM_OK);
    double axis[6];
    CHECK(cm_boundary_motion_reduction(mo, axis, NULL) == CM_MOTION_2D);
    CHECK(fabs(axis[5]) == 1 && axis[3] == 0 && axis[4] == 0);
    CHECK(cm_boundary_motion_partner(mo, (size_t)NODE(3, 2, 0)) == NODE(3, 2, 1));
    CHECK(cm_boundary_motion_kind(mo, (size_t)NODE(3, ny, 0)) == CM_MOTION_PRESCRIBED);
    CHECK(cm_boundary_motion_kind(mo, (size_t)NODE(3, 2, 0)) == CM_MOTION_SLIDE_PLANE);
    memcpy(x0, m->xyz, 3 * n * sizeof *x0);
    s = cm_warp_mesh(ctx, m, d, pre, mo, NULL, NULL, NULL, NULL);
    CHECK(s == CM_OK);
    size_t bad = 0, moved = 0;
    for (int k = 0; k <= ny; ++k)
        for (int i = 0; i <= nx; ++i) {
            const double *a = m->xyz + 3 * NODE(i, k, 0), *b = m->xyz + 3 * NODE(i, k, 1);
            bad += a[0] != b[0] || a[1] != b[1];
            bad += a[2] != x0[3 * NODE(i, k, 0) + 2] || b[2] != x0[3 * NODE(i, k, 1) + 2];
            moved += a[1] != x0[3 * NODE(i, k, 0) + 1];
        }
    CHECK_MSG(bad == 0, "%zu pairs apart or off their plane", bad);
    CHECK(moved > 10);
    CHECK(m->xyz[3 * NODE(3, ny, 0) + 1] == x0[3 * NODE(3, ny, 0) + 1] - 0.04);
    /* a fixed node stays */
    CHECK(m->xyz[3 * NODE(0, 3, 0) + 1] == x0[3 * NODE(0, 3, 0) + 1]);
    cm_boundary_motion_destroy(&mo);
    /* --fixed-patches frontAndBack: no reduction, the planes fixed; unknown names named */
    cm_motion_options opt;
    cm_motion_options_init(&opt);
    const char *fixed[] = {"frontAndBack"}, *bogus[] = {"nosuch"};
    opt.fixed = fixed, opt.n_fixed = 1;
    mo = motion_of(ctx, m, pre, &opt, &s);
    CHECK(s == CM_OK && cm_boundary_motion_reduction(mo, NULL, NULL) == CM_MOTION_3D);
    CHECK(cm_boundary_motion_count(mo, CM_MOTION_SLIDE_PLANE) == 0);
    cm_boundary_motion_destroy(&mo);
    opt.slide = bogus, opt.n_slide = 1, opt.n_fixed = 0;
    mo = motion_of(ctx, m, pre, &opt, &s);
    CHECK(s == CM_ERR_ARGUMENT && !mo);
    CHECK(strstr(cm_context_message(ctx), "nosuch") && strstr(cm_context_message(ctx), "lid"));
    free(pre), free(d), free(x0);
    cm_mesh_destroy(&m);
}

/* A wedge of 5 degrees about the x axis, r in [1, 2]: recognised, warped in its slab, both
 * wedge planes planar and every pair at one (r, z) afterwards. */
static void test_wedge(cm_context *ctx)
{
    const int nx = 6, ny = 5, nz = 1;
    const int tags[6] = {1, 2, 3, 4, 5, 6};
    const char *const names[6] = {"inlet", "outlet", "inner", "outer", "front", "back"};
    const cm_patch_kind kinds[6] = {0, 0, 0, 0, CM_PATCH_WEDGE, CM_PATCH_WEDGE};
    cm_mesh *m = block(ctx, nx, ny, nz, 1.0, tags, names, kinds);
    size_t n = m->n_nodes;
    const double half = 2.5 * acos(-1.0) / 180;
    for (size_t i = 0; i < n; ++i) { /* (x, y, k) -> axial x, radius 1 + y, angle +-half */
        double *p = m->xyz + 3 * i, r = 1 + p[1], th = p[2] > 0.5 ? half : -half;
        p[1] = r * cos(th), p[2] = r * sin(th);
    }
    unsigned char *pre = calloc(n, 1);
    double *d = calloc(3 * n, sizeof *d), *x0 = malloc(3 * n * sizeof *x0);
    for (int i = 2; i <= 4; ++i) /* the inner wall's middle grows radially, both planes */
        for (int k = 0; k <= 1; ++k) {
            size_t v = (size_t)NODE(i, 0, k);
            pre[v] = 1, d[3 * v + 1] = 0.1 * m->xyz[3 * v + 1], d[3 * v + 2] = 0.1 * m->xyz[3 * v + 2];
            d[3 * v] = 0.02;
        }
    cm_status s;
    cm_boundary_motion *mo = motion_of(ctx, m, pre, NULL, &s);
    CHECK(s == CM_OK);
    double axis[6], angle;
    CHECK(cm_boundary_motion_reduction(mo, axis, &angle) == CM_MOTION_AXISYMMETRIC);
    CHECK_NEAR(angle, 2 * half, 1e-12);
    CHECK(fabs(axis[3]) == 1 && fabs(axis[1]) < 1e-12 && fabs(axis[2]) < 1e-12);
    CHECK(cm_boundary_motion_partner(mo, (size_t)NODE(3, 2, 0)) == NODE(3, 2, 1));
    memcpy(x0, m->xyz, 3 * n * sizeof *x0);
    CHECK(cm_warp_mesh(ctx, m, d, pre, mo, NULL, NULL, NULL, NULL) == CM_OK);
    double off = 0, apart = 0;
    size_t moved = 0;
    for (int k = 0; k <= ny; ++k)
        for (int i = 0; i <= nx; ++i) {
            const double *a = m->xyz + 3 * NODE(i, k, 0), *b = m->xyz + 3 * NODE(i, k, 1);
            off = fmax(off, fabs(atan2(a[2], a[1]) + half));
            off = fmax(off, fabs(atan2(b[2], b[1]) - half));
            apart = fmax(apart, fabs(a[0] - b[0]));
            apart = fmax(apart, fabs(hypot(a[1], a[2]) - hypot(b[1], b[2])));
            moved += a[0] != x0[3 * NODE(i, k, 0)];
        }
    CHECK_MSG(off < 1e-14 && apart < 1e-14, "off the planes %g, pairs apart %g", off, apart);
    CHECK(moved > 5);
    CHECK_NEAR(hypot(m->xyz[3 * NODE(3, 0, 0) + 1], m->xyz[3 * NODE(3, 0, 0) + 2]), 1.1, 1e-14);
    cm_boundary_motion_destroy(&mo);
    free(pre), free(d), free(x0);
    cm_mesh_destroy(&m);
}

/* A plain patch the user slides that is not flat: its nodes stay on its initial surface. */
static void test_surface(cm_context *ctx)
{
    const int nx = 8, ny = 4, nz = 4;
    const int tags[6] = {1, 1, 1, 2, 1, 1};
    const char *const names[6] = {"box", "box", "box", "bump", "box", "box"};
    const cm_patch_kind kinds[6] = {0, 0, 0, 0, 0, 0};
    cm_mesh *m = block(ctx, nx, ny, nz, 0.25, tags, names, kinds);
    size_t n = m->n_nodes;
    for (size_t i = 0; i < n; ++i) /* the top bulges: y = 1 + 0.1 sin(pi x) at y = 1 */
        m->xyz[3 * i + 1] *= 1 + 0.1 * sin(acos(-1.0) * m->xyz[3 * i]);
    cm_motion_options opt;
    cm_motion_options_init(&opt);
    const char *slide[] = {"bump"};
    opt.slide = slide, opt.n_slide = 1;
    cm_status s;
    cm_boundary_motion *mo = motion_of(ctx, m, NULL, &opt, &s);
    CHECK(s == CM_OK);
    size_t v = (size_t)NODE(4, ny, 2);
    CHECK(cm_boundary_motion_kind(mo, v) == CM_MOTION_SLIDE_SURFACE);
    double *d = calloc(3 * n, sizeof *d);
    d[3 * v] = 0.05, d[3 * v + 1] = 0.2, d[3 * v + 2] = 0.01;
    CHECK(cm_boundary_motion_project(ctx, mo, d) == CM_OK);
    double p[3] = {m->xyz[3 * v] + d[3 * v], m->xyz[3 * v + 1] + d[3 * v + 1],
                   m->xyz[3 * v + 2] + d[3 * v + 2]};
    /* on the surface (its chords: within the sagitta of a face of the bump) */
    CHECK_NEAR(p[1], 1 + 0.1 * sin(acos(-1.0) * p[0]), 3e-3);
    CHECK(d[3 * v] > 0.01 && d[3 * v + 1] < 0.01);
    /* projecting again changes nothing (to round-off) */
    double e[3] = {d[3 * v], d[3 * v + 1], d[3 * v + 2]};
    CHECK(cm_boundary_motion_project(ctx, mo, d) == CM_OK);
    CHECK(fabs(d[3 * v] - e[0]) + fabs(d[3 * v + 1] - e[1]) + fabs(d[3 * v + 2] - e[2]) < 1e-14);
    cm_boundary_motion_destroy(&mo);
    free(d);
    cm_mesh_destroy(&m);
}

int main(void)
{
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_kinds_3d(ctx);
    test_as_before(ctx);
    test_2d(ctx);
    test_wedge(ctx);
    test_surface(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
