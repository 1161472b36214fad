/* MLS space deformation (deform/mls.h): shape functions (partition of unity, linear
 * precision, analytic derivatives against central differences, coplanar samples) and the
 * deformation (zero motion, affine motion with everything else free, two components, a flat
 * plate, the warp method). Meshes are built in code. */
#include "cadmorph/mls.h"
#include "cadmorph/warp.h"
#include "mls_internal.h"
#include "test_rng.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double urand(unsigned *s)
{
    *s = *s * 1103515245u + 12345u;
    return (double)((*s >> 8) & 0xFFFFFF) / 16777216.0;
}

/* nx*ny*nz hex cells over [x0, x0+1] x [0,1] x [0,1], appended to mesh. */
static void add_box(cm_context *ctx, cm_mesh *m, int n, double x0)
{
    size_t base = m->n_nodes;
    cm_mesh_resize_nodes(ctx, m, base + (size_t)(n + 1) * (n + 1) * (n + 1), 0);
    for (int k = 0; k <= n; ++k)
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) {
                double *p = m->xyz + 3 * (base + ((size_t)k * (n + 1) + j) * (n + 1) + i);
                p[0] = x0 + (double)i / n, p[1] = (double)j / n, p[2] = (double)k / n;
            }
#define ID(i, j, k) ((int64_t)(base + ((size_t)(k) * (n + 1) + (j)) * (n + 1) + (i)))
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                int64_t c[8] = {ID(i, j, k),         ID(i + 1, j, k),     ID(i + 1, j + 1, k),
                                ID(i, j + 1, k),     ID(i, j, k + 1),     ID(i + 1, j, k + 1),
                                ID(i + 1, j + 1, k + 1), ID(i, j + 1, k + 1)};
                cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, c, 8, 0, 0, 0);
            }
#undef ID
}

static void test_basis(cm_context *ctx, int flat)
{
    unsigned seed = flat ? 7 : 3;
    size_t k = 400, np = 300;
    double *c = malloc(k * 3 * sizeof *c), *x = malloc(np * 3 * sizeof *x);
    for (size_t i = 0; i < 3 * k; ++i)
        c[i] = urand(&seed);
    for (size_t i = 0; i < 3 * np; ++i)
        x[i] = 0.1 + 0.8 * urand(&seed);
    if (flat) {
        for (size_t i = 0; i < k; ++i)
            c[3 * i + 2] = 0.5;
        for (size_t i = 0; i < np; ++i)
            x[3 * i + 2] = 0.5;
    }
    cm_mls_basis *b = NULL;
    CHECK(cm_mls_basis_create(ctx, k, c, np, x, 5, &b) == CM_OK);
    if (!b) return;
    size_t mx = cm_mls_basis_max_support(b), cnt, cnt2;
    int32_t *idx = malloc(mx * sizeof *idx), *idx2 = malloc(mx * sizeof *idx2);
    double *phi = malloc(mx * sizeof *phi), *gr = malloc(3 * mx * sizeof *gr);
    double *lap = malloc(mx * sizeof *lap), *phi2 = malloc(mx * sizeof *phi2);
    double *fp = malloc(mx * sizeof *fp), *fm = malloc(mx * sizeof *fm);
    double worst_pu = 0, worst_lp = 0, worst_g = 0, worst_l = 0, worst_dpu = 0;
    size_t min_cover = 1000, fd_points = 0;
    int finite = 1;
    for (size_t i = 0; i < np; ++i) {
        const double *p = x + 3 * i;
        CHECK(cm_mls_basis_eval(ctx, b, p, mx, &cnt, idx, phi, gr, lap) == CM_OK);
        if (cnt < min_cover) min_cover = cnt;
        double s = 0, lx[3] = {0, 0, 0}, gs[3] = {0, 0, 0}, ls = 0, gl[9] = {0};
        for (size_t q = 0; q < cnt; ++q) {
            finite &= isfinite(phi[q]) && isfinite(gr[3 * q]) && isfinite(gr[3 * q + 1]) &&
                      isfinite(gr[3 * q + 2]) && isfinite(lap[q]);
            s += phi[q];
            ls += lap[q];
            for (int a = 0; a < 3; ++a) {
                lx[a] += phi[q] * c[3 * idx[q] + a];
                gs[a] += gr[3 * q + a];
                for (int d = 0; d < 3; ++d)
                    gl[3 * a + d] += gr[3 * q + d] * c[3 * idx[q] + a];
            }
        }
        worst_pu = fmax(worst_pu, fabs(s - 1));
        for (int a = 0; a < 3; ++a)
            worst_lp = fmax(worst_lp, fabs(lx[a] - p[a]));
        /* derivatives of the same identities: sum grad = 0, sum grad c_a = e_a, sum lap = 0 */
        for (int a = 0; a < 3; ++a) {
            worst_dpu = fmax(worst_dpu, fabs(gs[a]));
            if (!flat)
                for (int d = 0; d < 3; ++d)
                    worst_dpu = fmax(worst_dpu, fabs(gl[3 * a + d] - (a == d)));
        }
        if (!flat) worst_dpu = fmax(worst_dpu, fabs(ls) * 1e-2);
        if (flat) continue;
        /* central differences where the support set does not change within +-h */
        double h = 1e-6, g_scale = 0, l_fd[64] = {0}, gmax = 0;
        int same = cnt <= 64;
        double gfd[3 * 64];
        for (int d = 0; d < 3 && same; ++d) {
            double xp[3] = {p[0], p[1], p[2]}, xm[3] = {p[0], p[1], p[2]};
            xp[d] += h, xm[d] -= h;
            cm_mls_basis_eval(ctx, b, xp, mx, &cnt2, idx2, fp, NULL, NULL);
            same &= cnt2 == cnt && !memcmp(idx, idx2, cnt * sizeof *idx);
            cm_mls_basis_eval(ctx, b, xm, mx, &cnt2, idx2, fm, NULL, NULL);
            same &= cnt2 == cnt && !memcmp(idx, idx2, cnt * sizeof *idx);
            for (size_t q = 0; q < cnt && same; ++q)
                gfd[3 * q + d] = (fp[q] - fm[q]) / (2 * h);
            double hl = 1e-5; /* below this, round-off dominates */
            xp[d] = p[d] + hl, xm[d] = p[d] - hl;
            cm_mls_basis_eval(ctx, b, xp, mx, &cnt2, idx2, fp, NULL, NULL);
            same &= cnt2 == cnt && !memcmp(idx, idx2, cnt * sizeof *idx);
            cm_mls_basis_eval(ctx, b, xm, mx, &cnt2, idx2, fm, NULL, NULL);
            same &= cnt2 == cnt && !memcmp(idx, idx2, cnt * sizeof *idx);
            for (size_t q = 0; q < cnt && same; ++q)
                l_fd[q] += (fp[q] - 2 * phi[q] + fm[q]) / (hl * hl);
        }
        if (!same) continue;
        ++fd_points;
        for (size_t q = 0; q < cnt; ++q) {
            for (int d = 0; d < 3; ++d)
                g_scale = fmax(g_scale, fabs(gr[3 * q + d]));
            gmax = fmax(gmax, fabs(lap[q]));
        }
        for (size_t q = 0; q < cnt; ++q) {
            for (int d = 0; d < 3; ++d)
                worst_g = fmax(worst_g, fabs(gr[3 * q + d] - gfd[3 * q + d]) / g_scale);
            worst_l = fmax(worst_l, fabs(lap[q] - l_fd[q]) / gmax);
        }
    }
    CHECK(finite);
    CHECK(min_cover >= 5);
    CHECK_MSG(worst_pu <= 1e-12, "partition of unity %g", worst_pu);
    CHECK_MSG(worst_lp <= 1e-12, "linear precision %g", worst_lp);
    CHECK_MSG(worst_dpu <= 1e-9, "derivative identities %g", worst_dpu);
    if (!flat) {
        CHECK_MSG(fd_points > np / 2, "%zu points with a stable support", fd_points);
        CHECK_MSG(worst_g <= 1e-7, "gradient vs central differences (relative) %g", worst_g);
        CHECK_MSG(worst_l <= 1e-5, "Laplacian vs central differences (relative) %g", worst_l);
    }
    printf("basis%s: pu %.2e lp %.2e grad-fd %.2e lap-fd %.2e over %zu points\n",
           flat ? " (coplanar)" : "", worst_pu, worst_lp, worst_g, worst_l, fd_points);
    cm_mls_basis_destroy(&b);
    CHECK(b == NULL);
    free(c), free(x), free(idx), free(idx2), free(phi), free(gr), free(lap), free(phi2);
    free(fp), free(fm);
}

static void affine(const double *p, double *d)
{
    d[0] = 0.1 * p[0] + 0.05 * p[1] - 0.02 * p[2] + 0.3;
    d[1] = -0.04 * p[0] + 0.08 * p[2] - 0.1;
    d[2] = 0.06 * p[1] + 0.03 * p[2] + 0.2;
}

static void test_deform(cm_context *ctx)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    add_box(ctx, m, 8, 0);
    size_t n = m->n_nodes;
    unsigned char *con = calloc(n, 1);
    double *d = calloc(3 * n, sizeof *d);
    /* handles: the faces x = 0 and x = 1; everything else free */
    for (size_t i = 0; i < n; ++i)
        con[i] = m->xyz[3 * i] < 1e-9 || m->xyz[3 * i] > 1 - 1e-9;
    cm_mls_options o;
    cm_mls_options_init(&o);
    o.samples = 150;
    o.stretch = 0; /* pure bending: an affine field has zero energy and no miss */
    cm_mls *mls = NULL;
    CHECK(cm_mls_create(ctx, m, con, &o, &mls) == CM_OK);
    if (!mls) {
        fprintf(stderr, "%s\n", cm_context_message(ctx));
        return;
    }
    double res = -1;
    CHECK(cm_mls_apply(ctx, mls, d, &res) == CM_OK);
    double worst = 0;
    for (size_t i = 0; i < 3 * n; ++i)
        worst = fmax(worst, fabs(d[i]));
    CHECK_MSG(worst == 0 && res == 0, "zero motion: %g, residual %g", worst, res);
    for (size_t i = 0; i < n; ++i)
        if (con[i]) affine(m->xyz + 3 * i, d + 3 * i);
    CHECK(cm_mls_apply(ctx, mls, d, &res) == CM_OK);
    worst = 0;
    for (size_t i = 0; i < n; ++i) {
        double e[3];
        affine(m->xyz + 3 * i, e);
        for (int a = 0; a < 3; ++a)
            worst = fmax(worst, fabs(d[3 * i + a] - e[a]));
    }
    CHECK_MSG(worst <= 1e-8 && res <= 1e-8, "affine: %g off, residual %g", worst, res);
    printf("affine handles, bending: max error %.2e, residual %.2e\n", worst, res);
    cm_mls_stats st;
    cm_mls_get_stats(mls, &st);
    CHECK(st.samples == 150 && st.cubature > 0 && st.phi_nonzeros >= 5 * n);
    cm_mls_destroy(&mls);
    CHECK(mls == NULL);

    /* stretching and bending: the miss shrinks as gamma_f grows, and a translation is exact */
    o.stretch = 1;
    double prev = INFINITY;
    for (int t = 0; t < 2; ++t) {
        o.fix = t ? 1e5 : 1e3;
        CHECK(cm_mls_create(ctx, m, con, &o, &mls) == CM_OK);
        for (size_t i = 0; i < n; ++i)
            if (con[i]) affine(m->xyz + 3 * i, d + 3 * i);
        CHECK(cm_mls_apply(ctx, mls, d, &res) == CM_OK);
        CHECK_MSG(res < prev && res < 0.05, "gamma_f %g: residual %g", o.fix, res);
        prev = res;
        for (size_t i = 0; i < n; ++i)
            d[3 * i] = 0.25, d[3 * i + 1] = -0.5, d[3 * i + 2] = 0.125;
        CHECK(cm_mls_apply(ctx, mls, d, &res) == CM_OK);
        worst = 0;
        for (size_t i = 0; i < n; ++i)
            worst = fmax(worst, fabs(d[3 * i] - 0.25) + fabs(d[3 * i + 1] + 0.5) +
                                    fabs(d[3 * i + 2] - 0.125));
        CHECK_MSG(worst <= 1e-8, "translation: %g", worst);
        cm_mls_destroy(&mls);
    }
    free(con), free(d);
    cm_mesh_destroy(&m);
}

static void test_two_components(cm_context *ctx)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    add_box(ctx, m, 6, 0);
    size_t na = m->n_nodes;
    add_box(ctx, m, 6, 3);
    size_t n = m->n_nodes;
    unsigned char *con = calloc(n, 1);
    double *d = calloc(3 * n, sizeof *d);
    for (size_t i = 0; i < n; ++i) {
        double x = m->xyz[3 * i];
        con[i] = fabs(x) < 1e-9 || fabs(x - 4) < 1e-9; /* one face of each box */
        if (con[i] && i < na) d[3 * i + 1] = 0.3;     /* box A moves, box B stays */
    }
    cm_mls_options o;
    cm_mls_options_init(&o);
    o.samples = 200;
    cm_mls *mls = NULL;
    CHECK(cm_mls_create(ctx, m, con, &o, &mls) == CM_OK);
    double res = -1, ea = 0, eb = 0;
    CHECK(mls && cm_mls_apply(ctx, mls, d, &res) == CM_OK);
    for (size_t i = 0; i < n; ++i) {
        double ey = i < na ? d[3 * i + 1] - 0.3 : d[3 * i + 1];
        double e = fabs(d[3 * i]) + fabs(ey) + fabs(d[3 * i + 2]);
        if (i < na)
            ea = fmax(ea, e);
        else
            eb = fmax(eb, e);
    }
    CHECK_MSG(ea <= 1e-9 && eb <= 1e-9, "two components: moved %g, fixed %g", ea, eb);
    printf("two components: %.2e %.2e\n", ea, eb);
    cm_mls_destroy(&mls);

    /* the warp method on the same mesh: boundary constrained, approximate, residual reported */
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) >= 0);
    cm_warp_options wo;
    cm_warp_options_init(&wo);
    CHECK(cm_warp_method_from_name("mls") == CM_WARP_MLS);
    wo.method = CM_WARP_MLS;
    cm_warp *w = NULL;
    CHECK(cm_warp_create(ctx, m, b, NULL, &wo, &w) == CM_OK);
    for (size_t i = 0; i < n; ++i)
        affine(m->xyz + 3 * i, d + 3 * i);
    double *pre = malloc(3 * n * sizeof *pre);
    memcpy(pre, d, 3 * n * sizeof *pre);
    CHECK(w && cm_warp_apply(ctx, w, d) == CM_OK);
    double r = cm_warp_residual(w), keep = 0, inner = 0;
    for (size_t i = 0; i < b->n_nodes; ++i)
        for (int a = 0; a < 3; ++a)
            keep = fmax(keep, fabs(d[3 * b->nodes[i] + a] - pre[3 * b->nodes[i] + a]));
    for (size_t i = 0; i < 3 * n; ++i)
        inner = fmax(inner, fabs(d[i] - pre[i]));
    CHECK_MSG(keep == 0, "boundary kept: %g", keep);
    CHECK_MSG(r > 0 && r < 2e-3 && inner < 2e-3, "warp residual %g, interior off affine %g", r,
              inner);
    printf("warp mls: residual %.3e, interior vs affine %.3e\n", r, inner);
    cm_warp_destroy(&w);
    cm_mesh_boundary_destroy(&b);
    free(pre), free(con), free(d);
    cm_mesh_destroy(&m);
}

/* A flat quad plate (coplanar samples): finite, the handle lifts, the fixed rim stays. */
static void test_plate(cm_context *ctx)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    int n = 30;
    cm_mesh_resize_nodes(ctx, m, (size_t)(n + 1) * (n + 1), 0);
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            double *p = m->xyz + 3 * ((size_t)j * (n + 1) + i);
            p[0] = (double)i / n, p[1] = (double)j / n, p[2] = 0;
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            int64_t c[4] = {j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
                            (j + 1) * (n + 1) + i};
            cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, c, 4, 0, 0, 0);
        }
    size_t nn = m->n_nodes;
    unsigned char *con = calloc(nn, 1);
    double *d = calloc(3 * nn, sizeof *d);
    for (size_t i = 0; i < nn; ++i) {
        double x = m->xyz[3 * i], y = m->xyz[3 * i + 1];
        int rim = x < 1e-9 || y < 1e-9 || x > 1 - 1e-9 || y > 1 - 1e-9;
        int handle = fabs(x - 0.5) < 0.08 && fabs(y - 0.5) < 0.08;
        con[i] = rim || handle;
        if (handle) d[3 * i + 2] = 0.1;
    }
    for (int e = 0; e < 2; ++e) {
        cm_mls_options o;
        cm_mls_options_init(&o);
        o.samples = 300;
        o.stretch = e ? 1 : 0;
        o.bend = e ? 0 : 1;
        o.keep_constrained = 0;
        cm_mls *mls = NULL;
        CHECK(cm_mls_create(ctx, m, con, &o, &mls) == CM_OK);
        double res = -1;
        CHECK(mls && cm_mls_apply(ctx, mls, d, &res) == CM_OK);
        int finite = 1;
        double centre = 0, rim = 0;
        for (size_t i = 0; i < nn; ++i) {
            finite &= isfinite(d[3 * i]) && isfinite(d[3 * i + 1]) && isfinite(d[3 * i + 2]);
            double x = m->xyz[3 * i], y = m->xyz[3 * i + 1];
            if (fabs(x - 0.5) < 1e-9 && fabs(y - 0.5) < 1e-9) centre = d[3 * i + 2];
            if (x < 1e-9) rim = fmax(rim, fabs(d[3 * i + 2]));
        }
        CHECK(finite);
        CHECK_MSG(centre > 0.095 && rim < 5e-3 && res < 5e-3, "%s: centre %g rim %g residual %g",
                  e ? "stretch" : "bend", centre, rim, res);
        printf("plate %s: centre %.4f rim %.2e residual %.2e\n", e ? "stretch" : "bend", centre,
               rim, res);
        for (size_t i = 0; i < nn; ++i)
            if (!con[i]) d[3 * i] = d[3 * i + 1] = d[3 * i + 2] = 0;
        for (size_t i = 0; i < nn; ++i)
            if (con[i]) {
                double x = m->xyz[3 * i], y = m->xyz[3 * i + 1];
                d[3 * i] = d[3 * i + 1] = 0;
                d[3 * i + 2] = fabs(x - 0.5) < 0.08 && fabs(y - 0.5) < 0.08 ? 0.1 : 0;
            }
        cm_mls_destroy(&mls);
    }
    free(con), free(d);
    cm_mesh_destroy(&m);
}

/* The grid-and-heap farthest-point sampler picks exactly what the definition does (scan
 * every point per pick, the lowest index on a tie): on random points, on a lattice (many
 * equal distances) and on a flat set. */
static void test_farthest(cm_context *ctx)
{
    for (int kind = 0; kind < 3; ++kind) {
        size_t n = kind == 1 ? 15 * 15 * 15 : 6000, k = kind == 2 ? 700 : 400;
        double *x = malloc(n * 3 * sizeof *x), *out = malloc(k * 3 * sizeof *out), *d = malloc(n * sizeof *d);
        uint64_t rng = 1500 + (uint64_t)kind;
        for (size_t i = 0; i < n; ++i)
            for (int a = 0; a < 3; ++a)
                x[3 * i + a] = kind == 1 ? (double)(a == 0 ? i % 15 : a == 1 ? i / 15 % 15 : i / 225) * 0.1
                               : kind == 2 && a == 2 ? 0.5 : test_rng_range(&rng, -1, 2 + a);
        CHECK(mls_farthest(ctx, x, n, k, 7 + (uint64_t)kind, out) == CM_OK);
        size_t cur = n;
        for (size_t i = 0; i < n; ++i)
            if (!memcmp(x + 3 * i, out, 3 * sizeof *x)) cur = i;
        CHECK(cur < n);
        for (size_t i = 0; i < n; ++i) d[i] = 1e300;
        size_t same = 0;
        for (size_t j = 0; j < k && cur < n; ++j) {
            same += !memcmp(x + 3 * cur, out + 3 * j, 3 * sizeof *x);
            const double *c = x + 3 * cur;
            size_t best = 0;
            for (size_t i = 0; i < n; ++i) {
                const double *p = x + 3 * i;
                double e = (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2]);
                if (e < d[i]) d[i] = e;
                if (d[i] > d[best]) best = i;
            }
            cur = best;
        }
        CHECK_MSG(same == k, "farthest points, set %d: %zu of %zu picks as the plain scan's", kind, same, k);
        free(x), free(out), free(d);
    }
}

/* The residual blend (options.blend): constrained nodes keep their prescribed motion either
 * way; the first layer of free nodes next to a wiggly handle the subspace cannot follow sees a
 * smaller jump to it with the blend; a band narrower than the node spacing changes nothing. */
static void test_blend(cm_context *ctx)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    add_box(ctx, m, 10, 0);
    size_t n = m->n_nodes;
    unsigned char *con = calloc(n, 1);
    double *d[3] = {calloc(3 * n, sizeof(double)), calloc(3 * n, sizeof(double)), calloc(3 * n, sizeof(double))};
    const double blend[3] = {0, 1.5, 0.01};
    size_t blended[3] = {0, 0, 0};
    double res[3] = {0, 0, 0};
    for (int v = 0; v < 3; ++v) {
        for (size_t i = 0; i < n; ++i) {
            const double *x = m->xyz + 3 * i;
            con[i] = x[0] < 1e-9 || x[0] > 1 - 1e-9;
            if (x[0] > 1 - 1e-9) d[v][3 * i] = 0.05 * sin(27 * x[1] + 0.3) * cos(19 * x[2]);
        }
        cm_mls_options o;
        cm_mls_options_init(&o);
        o.samples = 120;
        o.blend = blend[v];
        cm_mls *mls = NULL;
        CHECK(cm_mls_create(ctx, m, con, &o, &mls) == CM_OK);
        if (!mls) continue;
        CHECK(cm_mls_apply(ctx, mls, d[v], &res[v]) == CM_OK);
        cm_mls_stats st;
        cm_mls_get_stats(mls, &st);
        blended[v] = st.blend_nodes;
        cm_mls_destroy(&mls);
    }
    /* the jump across the first layer at x = 1: |d(1 - h) - d(1)| over the face */
    double jump[2] = {0, 0}, h = 0.1;
    int same_con = 1;
    for (size_t i = 0; i < n; ++i) {
        const double *x = m->xyz + 3 * i;
        if (con[i]) same_con &= d[0][3 * i] == d[1][3 * i] && d[0][3 * i + 1] == d[1][3 * i + 1];
        if (fabs(x[0] - (1 - h)) > 1e-9) continue;
        for (size_t j = 0; j < n; ++j) {
            const double *y = m->xyz + 3 * j;
            if (y[0] > 1 - 1e-9 && fabs(y[1] - x[1]) < 1e-9 && fabs(y[2] - x[2]) < 1e-9)
                for (int v = 0; v < 2; ++v) jump[v] += fabs(d[v][3 * i] - d[v][3 * j]);
        }
    }
    CHECK(same_con);
    CHECK_MSG(res[0] > 0.01, "the handle should be beyond the subspace: residual %g", res[0]);
    CHECK_MSG(blended[0] == 0 && blended[1] > n / 4 && blended[2] == 0, "blended nodes %zu %zu %zu",
              blended[0], blended[1], blended[2]);
    CHECK_MSG(jump[1] < 0.85 * jump[0], "first-layer jump %g with the blend vs %g without", jump[1], jump[0]);
    CHECK_MSG(!memcmp(d[0], d[2], 3 * n * sizeof(double)), "a band narrower than a cell changed the field");
    printf("blend: first-layer jump %.3g -> %.3g, %zu nodes blended\n", jump[0], jump[1], blended[1]);
    for (int v = 0; v < 3; ++v) free(d[v]);
    free(con);
    cm_mesh_destroy(&m);
}

/* --graded: on a box whose cells shrink towards x = 0 (x -> x^3), graded 1 puts the samples
 * where the cells are (46 % of them lie in x < 0.1, 10 % of the volume), graded 0 by volume;
 * the dense points' measures still add up to the volume and the area (unbiased weights), and
 * an affine motion stays exact under bending. */
static void test_graded(cm_context *ctx)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    add_box(ctx, m, 12, 0);
    size_t n = m->n_nodes;
    for (size_t i = 0; i < n; ++i)
        m->xyz[3 * i] = m->xyz[3 * i] * m->xyz[3 * i] * m->xyz[3 * i];
    for (int g = 0; g <= 1; ++g) {
        mls_dense d;
        CHECK(mls_dense_create(ctx, m, 20000, 20000, g, 7, &d) == CM_OK);
        double area = 0, vol = 0;
        for (size_t i = 0; i < d.n_s; ++i)
            area += d.measure[i];
        for (size_t i = d.n_s; i < d.n_s + d.n_v; ++i)
            vol += d.measure[i];
        CHECK_MSG(fabs(area - 6) < 0.03 * 6 && fabs(vol - 1) < 0.03,
                  "graded %d: dense measures add up to area %g (6), volume %g (1)", g, area, vol);
        mls_dense_free(&d);
    }
    unsigned char *con = calloc(n, 1);
    double *dsp = calloc(3 * n, sizeof *dsp);
    for (size_t i = 0; i < n; ++i)
        con[i] = m->xyz[3 * i] < 1e-9 || m->xyz[3 * i] > 1 - 1e-9;
    double share[2] = {0, 0};
    for (int g = 0; g <= 1; ++g) {
        cm_mls_options o;
        cm_mls_options_init(&o);
        o.samples = 300;
        o.stretch = 0;
        o.graded = g;
        cm_mls *mls = NULL;
        CHECK(cm_mls_create(ctx, m, con, &o, &mls) == CM_OK);
        if (!mls) break;
        size_t k = 0;
        const double *c = cm_mls_samples(mls, &k);
        for (size_t j = 0; j < k; ++j)
            share[g] += c[3 * j] < 0.1 ? 1.0 / (double)k : 0;
        for (size_t i = 0; i < n; ++i)
            if (con[i]) affine(m->xyz + 3 * i, dsp + 3 * i);
        double res = -1, worst = 0;
        CHECK(cm_mls_apply(ctx, mls, dsp, &res) == CM_OK);
        for (size_t i = 0; i < n; ++i) {
            double e[3];
            affine(m->xyz + 3 * i, e);
            for (int a = 0; a < 3; ++a)
                worst = fmax(worst, fabs(dsp[3 * i + a] - e[a]));
        }
        CHECK_MSG(worst <= 1e-8 && res <= 1e-8, "graded %d, affine: %g off, residual %g", g, worst, res);
        cm_mls_destroy(&mls);
    }
    printf("graded box: samples in x < 0.1 (10 %% of the volume, 46 %% of the cells): graded 0 "
           "%.2f, graded 1 %.2f\n", share[0], share[1]);
    CHECK_MSG(share[0] < 0.25 && share[1] > 0.35 && share[1] > 2 * share[0],
              "samples in x < 0.1: graded 0 %.2f, graded 1 %.2f", share[0], share[1]);
    cm_mls_options o;
    cm_mls_options_init(&o);
    o.graded = 1.5;
    cm_mls *bad = NULL;
    CHECK(cm_mls_create(ctx, m, con, &o, &bad) == CM_ERR_ARGUMENT && bad == NULL);
    free(con), free(dsp);
    cm_mesh_destroy(&m);
}

int main(void)
{
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_farthest(ctx);
    test_blend(ctx);
    test_basis(ctx, 0);
    test_basis(ctx, 1);
    test_deform(ctx);
    test_two_components(ctx);
    test_plate(ctx);
    test_graded(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
