/* The reverse products of deform.h (docs/DESIGN.md, "Gradients"): cm_ffd_deform_transpose
 * against cm_ffd_deform (points inside, outside and on a moved lattice), cm_dmffd_solve_transpose
 * against cm_dmffd_solve (under- and over-determined, singular values truncated), and
 * cm_deform_apply_transpose against cm_deform_apply for dmffd and mls (the residual blend on
 * and off, constrained nodes kept or given the field's value): the dot-product test
 * <v, A x> = <A^T v, x> to 1e-10 relative with random x and v; the methods without one say so
 * (shell). */
#include "deform_test_util.h"
#include "test_mesh.h"
#include "test_util.h"

#include <math.h>
#include <string.h>

static cm_context *ctx;

static double dot(const double *a, const double *b, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; ++i)
        s += a[i] * b[i];
    return s;
}

/* |<v, y> - <w, x>| relative to sum |v_i y_i| (random sums can cancel, their terms do not) */
static double dot_error(const double *v, const double *y, size_t ny, const double *w,
                        const double *x, size_t nx)
{
    double scale = 0;
    for (size_t i = 0; i < ny; ++i)
        scale += fabs(v[i] * y[i]);
    return fabs(dot(v, y, ny) - dot(w, x, nx)) / (scale > 0 ? scale : 1);
}

static void test_ffd(void)
{
    for (int moved = 0; moved < 2; ++moved) {
        cm_ffd_desc desc;
        rotated_desc(&desc, 6, CM_FFD_BSPLINE, CM_FFD_KNOTS_UNIFORM);
        cm_ffd *f = NULL;
        CHECK(cm_ffd_create(ctx, &desc, &f) == CM_OK);
        size_t nc = cm_ffd_control_count(f), n = 300;
        if (moved) { /* a pre-deformed lattice: Newton locates the points */
            double *c = malloc(nc * 3 * sizeof *c);
            cm_ffd_control_points(f, c);
            for (size_t i = 0; i < 3 * nc; ++i)
                c[i] += 0.01 * urange(-1, 1);
            CHECK(cm_ffd_set_control_points(ctx, f, c) == CM_OK);
            free(c);
        }
        double *x = malloc(n * 3 * sizeof *x), *dc = malloc(nc * 3 * sizeof *dc);
        double *d = malloc(n * 3 * sizeof *d), *v = malloc(n * 3 * sizeof *v);
        double *g = malloc(nc * 3 * sizeof *g);
        /* around the rotated box, some points outside it */
        for (size_t i = 0; i < 3 * n; ++i)
            x[i] = urange(-0.5, 2.5);
        for (size_t i = 0; i < 3 * nc; ++i)
            dc[i] = urange(-1, 1);
        for (size_t i = 0; i < 3 * n; ++i)
            v[i] = urange(-1, 1);
        cm_ffd_stats st;
        CHECK(cm_ffd_deform(ctx, f, dc, n, x, d, &st) == CM_OK);
        CHECK(st.inside > 0 && st.outside > 0);
        CHECK(cm_ffd_deform_transpose(ctx, f, n, x, v, g, NULL) == CM_OK);
        double e = dot_error(v, d, 3 * n, g, dc, 3 * nc);
        CHECK_MSG(e <= 1e-10, "ffd (moved %d): %.3g", moved, e);
        CHECK(cm_ffd_deform_transpose(ctx, NULL, n, x, v, g, NULL) == CM_ERR_ARGUMENT);
        free(x), free(dc), free(d), free(v), free(g);
        cm_ffd_destroy(&f);
    }
}

static void test_dmffd(void)
{
    /* handles: fewer than the active control points (least norm), more (least squares), and
     * a cluster whose Phi has singular values below the clamp */
    const size_t counts[3] = {20, 400, 60};
    for (int c = 0; c < 3; ++c) {
        cm_ffd_desc desc;
        cm_ffd_desc_init(&desc);
        desc.n[0] = desc.n[1] = desc.n[2] = 6;
        cm_ffd *f = NULL;
        CHECK(cm_ffd_create(ctx, &desc, &f) == CM_OK);
        size_t m = counts[c], nc = cm_ffd_control_count(f);
        double *h = malloc(m * 3 * sizeof *h), *dh = malloc(m * 3 * sizeof *dh);
        double *dc = malloc(nc * 3 * sizeof *dc), *g = malloc(nc * 3 * sizeof *g);
        double *gh = malloc(m * 3 * sizeof *gh);
        for (size_t i = 0; i < 3 * m; ++i)
            h[i] = c == 2 ? 0.5 + 1e-6 * urange(-1, 1) : urange(0.05, 0.95);
        for (size_t i = 0; i < 3 * m; ++i)
            dh[i] = urange(-1, 1);
        for (size_t i = 0; i < 3 * nc; ++i)
            g[i] = urange(-1, 1);
        cm_dmffd_options o;
        cm_dmffd_options_init(&o);
        if (c == 2) o.eps = 1e-3;
        cm_dmffd *dm = NULL;
        CHECK(cm_dmffd_create(ctx, f, m, h, &o, &dm) == CM_OK);
        cm_dmffd_info info;
        cm_dmffd_get_info(dm, &info);
        if (c == 2) CHECK(info.clamped > 0);
        CHECK(cm_dmffd_solve(ctx, dm, dh, dc) == CM_OK);
        CHECK(cm_dmffd_solve_transpose(ctx, dm, g, gh) == CM_OK);
        double e = dot_error(g, dc, 3 * nc, gh, dh, 3 * m);
        CHECK_MSG(e <= 1e-10, "dmffd %zu handles: %.3g", m, e);
        CHECK(cm_dmffd_solve_transpose(ctx, dm, NULL, gh) == CM_ERR_ARGUMENT);
        free(h), free(dh), free(dc), free(g), free(gh);
        cm_dmffd_destroy(&dm);
        cm_ffd_destroy(&f);
    }
}

/* cm_deform_apply_transpose on a jittered hex block, boundary and some interior nodes
 * constrained */
static void check_deform(const cm_deform_options *o, const char *what)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    uint64_t seed = 11;
    test_block b = {4, 4, 4, {0, 0, 0}, {0.25, 0.25, 0.25}, 0, 0.2};
    CHECK(test_add_block(ctx, m, &b, &seed) == 0);
    size_t n = m->n_nodes, n3 = 3 * n;
    unsigned char *con = calloc(n, 1);
    for (size_t v = 0; v < n; ++v) {
        const double *x = m->xyz + 3 * v;
        int edge = 0;
        for (int k = 0; k < 3; ++k)
            edge |= x[k] < 1e-9 || x[k] > 1 - 1e-9;
        con[v] = edge || v % 7 == 3;
    }
    double *d = malloc(n3 * sizeof *d), *jd = malloc(n3 * sizeof *jd);
    double *v = malloc(n3 * sizeof *v), *out = malloc(n3 * sizeof *out);
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            d[3 * i + k] = con[i] ? urange(-1, 1) : 0;
            v[3 * i + k] = urange(-1, 1);
        }
    memcpy(jd, d, n3 * sizeof *jd);
    cm_deform *def = NULL;
    cm_status s = cm_deform_create(ctx, o, n, m->xyz, con, m, &def);
    if (s >= 0) s = cm_deform_apply(ctx, def, jd, NULL);
    if (s >= 0) s = cm_deform_apply_transpose(ctx, def, v, out);
    CHECK_MSG(s == CM_OK, "%s: %s", what, cm_context_message(ctx));
    if (s == CM_OK) {
        double e = dot_error(v, jd, n3, out, d, n3);
        printf("%-22s dot %.2e\n", what, e);
        CHECK_MSG(e <= 1e-10, "%s: %.3g", what, e);
        int zero = 1;
        for (size_t i = 0; i < n; ++i)
            if (!con[i]) zero &= out[3 * i] == 0 && out[3 * i + 1] == 0 && out[3 * i + 2] == 0;
        CHECK_MSG(zero, "%s: J^T v is not 0 at the free points", what);
        cm_deform_stats st;
        cm_deform_get_stats(def, &st);
        if (o->method == CM_DEFORM_MLS && o->mls.keep_constrained && o->mls.blend > 0)
            CHECK(st.mls.blend_nodes > 0); /* the blend's part of J is there to be checked */
        CHECK(cm_deform_apply_transpose(ctx, def, v, v + 1) == CM_ERR_ARGUMENT);
        CHECK(cm_deform_apply_transpose(ctx, def, NULL, out) == CM_ERR_ARGUMENT);
    }
    free(d), free(jd), free(v), free(out), free(con);
    cm_deform_destroy(&def);
    cm_mesh_destroy(&m);
}

static void test_deform(void)
{
    cm_deform_options o;
    cm_deform_options_init(&o);
    o.method = CM_DEFORM_DMFFD;
    o.lattice = 6;
    check_deform(&o, "dmffd");
    cm_deform_options_init(&o);
    o.method = CM_DEFORM_MLS;
    o.mls.samples = 60;
    check_deform(&o, "mls");
    o.mls.blend = 0;
    check_deform(&o, "mls without blend");
    o.mls.blend = 1.5;
    o.mls.keep_constrained = 0;
    check_deform(&o, "mls, field at the con.");

    /* a method without a reverse product says which and why, and writes nothing */
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    const double p[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    cm_mesh_resize_nodes(ctx, m, 4, 0);
    memcpy(m->xyz, p, sizeof p);
    const int64_t t0[3] = {0, 1, 2}, t1[3] = {1, 3, 2};
    cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, t0, 3, 0, 0, 0);
    cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, t1, 3, 0, 0, 0);
    unsigned char con[4] = {1, 1, 0, 0};
    cm_deform_options_init(&o);
    o.method = CM_DEFORM_SHELL;
    cm_deform *def = NULL;
    CHECK(cm_deform_create(ctx, &o, 4, NULL, con, m, &def) == CM_OK);
    double v[12] = {0}, out[12] = {7};
    CHECK(cm_deform_apply_transpose(ctx, def, v, out) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "shell") != NULL);
    CHECK(out[0] == 7);
    cm_deform_destroy(&def);
    cm_mesh_destroy(&m);
}

int main(void)
{
    cm_context_create(&ctx);
    test_ffd();
    test_dmffd();
    test_deform();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
