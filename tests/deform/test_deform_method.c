/* The table of point-set deformations (deform.h): every row gives, to the last bit, the
 * displacements of the direct calls it stands for (rbf with both kernels, dmffd, mls, shell),
 * one deformation applied twice gives the same field twice, and the table's names, stats and
 * argument errors. */
#include "cadmorph/deform.h"
#include "test_mesh.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static uint64_t seed = 12345;

/* n points in a box, every third one constrained (group 1 or 2) with a random motion; the
 * free points' disp entries are NaN so that a row that forgets one shows it. */
static void make_points(size_t n, double *xyz, unsigned char *con, double *disp)
{
    for (size_t i = 0; i < n; ++i) {
        con[i] = i % 3 == 0 ? (unsigned char)(1 + (i / 3) % 2) : 0;
        for (int a = 0; a < 3; ++a) {
            xyz[3 * i + a] = (a + 1) * test_rand(&seed);
            disp[3 * i + a] = con[i] ? 0.05 * test_rand(&seed) : NAN;
        }
    }
}

/* create + apply of one row on a copy of disp; out: n x 3. */
static cm_status run_row(const cm_deform_options *o, size_t n, const double *xyz,
                         const unsigned char *con, const cm_mesh *mesh, const double *disp,
                         double *out, double *residual)
{
    memcpy(out, disp, n * 3 * sizeof *out);
    cm_deform *d = NULL;
    cm_status s = cm_deform_create(ctx, o, n, xyz, con, mesh, &d);
    if (s >= 0) s = cm_deform_apply(ctx, d, out, residual);
    cm_deform_destroy(&d);
    return s;
}

static int same_bits(const double *a, const double *b, size_t n)
{
    return memcmp(a, b, n * sizeof *a) == 0;
}

/* The constrained points (c, v) and the free ones (f), in point order. */
static void split(size_t n, const double *xyz, const unsigned char *con, const double *disp,
                  double *c, double *v, double *f, size_t *nc, size_t *nf)
{
    *nc = *nf = 0;
    for (size_t i = 0; i < n; ++i)
        if (con[i]) {
            memcpy(c + 3 * *nc, xyz + 3 * i, 3 * sizeof *c);
            memcpy(v + 3 * (*nc)++, disp + 3 * i, 3 * sizeof *v);
        } else {
            memcpy(f + 3 * (*nf)++, xyz + 3 * i, 3 * sizeof *f);
        }
}

/* The free points' results (n_free x 3) against the row's output, constrained ones untouched. */
static int matches(size_t n, const unsigned char *con, const double *disp, const double *row,
                   const double *direct)
{
    int ok = 1;
    for (size_t i = 0, b = 0; i < n; ++i)
        ok &= con[i] ? same_bits(row + 3 * i, disp + 3 * i, 3)
                     : same_bits(row + 3 * i, direct + 3 * b++, 3);
    return ok;
}

static void test_rbf(cm_rbf_kernel kernel)
{
    size_t n = 90, nc, nf;
    double *xyz = malloc(n * 3 * sizeof *xyz), *disp = malloc(n * 3 * sizeof *disp);
    double *out = malloc(n * 3 * sizeof *out), *again = malloc(n * 3 * sizeof *again);
    double *c = malloc(n * 3 * sizeof *c), *v = malloc(n * 3 * sizeof *v);
    double *f = malloc(n * 3 * sizeof *f), *ref = malloc(n * 3 * sizeof *ref);
    unsigned char *con = malloc(n);
    make_points(n, xyz, con, disp);
    cm_deform_options o;
    cm_deform_options_init(&o);
    CHECK(o.method == CM_DEFORM_RBF && o.kernel == CM_RBF_TRIHARMONIC);
    o.kernel = kernel;
    double res = -1;
    CHECK(run_row(&o, n, xyz, con, NULL, disp, out, &res) == CM_OK);
    CHECK(res == 0);
    /* the direct calls */
    split(n, xyz, con, disp, c, v, f, &nc, &nf);
    cm_rbf *rbf = NULL;
    CHECK(cm_rbf_create(ctx, kernel, 3, nc, c, &rbf) == CM_OK);
    CHECK(cm_rbf_solve(ctx, rbf, 3, v) == CM_OK);
    CHECK(cm_rbf_evaluate(ctx, rbf, nf, f, ref) == CM_OK);
    cm_rbf_destroy(&rbf);
    CHECK_MSG(matches(n, con, disp, out, ref), "rbf kernel %d differs from the direct calls",
              (int)kernel);
    /* one deformation, two applies: the same field */
    cm_deform *d = NULL;
    CHECK(cm_deform_create(ctx, &o, n, xyz, con, NULL, &d) == CM_OK);
    memcpy(again, disp, n * 3 * sizeof *again);
    CHECK(cm_deform_apply(ctx, d, again, NULL) == CM_OK);
    memcpy(again, disp, n * 3 * sizeof *again);
    CHECK(cm_deform_apply(ctx, d, again, NULL) == CM_OK);
    CHECK(same_bits(again, out, 3 * n));
    cm_deform_stats st;
    cm_deform_get_stats(d, &st);
    CHECK(st.method == CM_DEFORM_RBF && st.constrained == nc && st.free == nf);
    CHECK(st.rbf.centres == nc && st.residual == 0);
    CHECK(cm_deform_get_mls(d) == NULL);
    cm_deform_destroy(&d);
    CHECK(d == NULL);
    free(xyz), free(disp), free(out), free(again), free(c), free(v), free(f), free(ref), free(con);
}

static void test_dmffd(void)
{
    size_t n = 120, nc, nf;
    double *xyz = malloc(n * 3 * sizeof *xyz), *disp = malloc(n * 3 * sizeof *disp);
    double *out = malloc(n * 3 * sizeof *out);
    double *c = malloc(n * 3 * sizeof *c), *v = malloc(n * 3 * sizeof *v);
    double *f = malloc(n * 3 * sizeof *f), *ref = malloc(n * 3 * sizeof *ref);
    unsigned char *con = malloc(n);
    make_points(n, xyz, con, disp);
    cm_deform_options o;
    cm_deform_options_init(&o);
    o.method = CM_DEFORM_DMFFD;
    o.lattice = 6;
    o.clamp = 1e-8;
    double res = -1;
    CHECK(run_row(&o, n, xyz, con, NULL, disp, out, &res) == CM_OK);
    /* the direct calls: the lattice enclosing every point, grown by 1e-3 of the diagonal */
    double bb[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a)
            bb[a] = fmin(bb[a], xyz[3 * i + a]), bb[a + 3] = fmax(bb[a + 3], xyz[3 * i + a]);
    split(n, xyz, con, disp, c, v, f, &nc, &nf);
    cm_ffd_desc desc;
    cm_ffd_desc_enclosing(&desc, bb, 1e-3, 6);
    cm_ffd *ffd = NULL;
    cm_dmffd *dm = NULL;
    cm_dmffd_options dopt;
    cm_dmffd_options_init(&dopt);
    dopt.eps = 1e-8;
    CHECK(cm_ffd_create(ctx, &desc, &ffd) == CM_OK);
    double *dc = malloc(cm_ffd_control_count(ffd) * 3 * sizeof *dc);
    CHECK(cm_dmffd_create(ctx, ffd, nc, c, &dopt, &dm) == CM_OK);
    CHECK(cm_dmffd_solve(ctx, dm, v, dc) == CM_OK);
    CHECK(cm_ffd_deform(ctx, ffd, dc, nf, f, ref, NULL) == CM_OK);
    cm_dmffd_info info;
    cm_dmffd_get_info(dm, &info);
    CHECK(matches(n, con, disp, out, ref));
    CHECK(res == info.residual_abs);
    /* the stats report the lattice */
    cm_deform *d = NULL;
    CHECK(cm_deform_create(ctx, &o, n, xyz, con, NULL, &d) == CM_OK);
    cm_deform_stats st;
    cm_deform_get_stats(d, &st);
    CHECK(st.lattice == 6 && st.control_points == 216 && st.dmffd.handles == nc);
    cm_deform_destroy(&d);
    cm_dmffd_destroy(&dm);
    cm_ffd_destroy(&ffd);
    free(dc);
    free(xyz), free(disp), free(out), free(c), free(v), free(f), free(ref), free(con);
}

/* A 4 x 4 x 4 hex block: x = 0 fixed (group 1), x = 1 moved (group 2), the rest free. */
static cm_mesh *block_mesh(double **disp, unsigned char **con)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    test_block b = {4, 4, 4, {0, 0, 0}, {0.25, 0.25, 0.25}, 0, 0.2};
    CHECK(test_add_block(ctx, m, &b, &seed) == 0);
    *disp = malloc(m->n_nodes * 3 * sizeof **disp);
    *con = calloc(m->n_nodes, 1);
    for (size_t i = 0; i < m->n_nodes; ++i) {
        double x = m->xyz[3 * i];
        (*con)[i] = x < 1e-12 ? 1 : x > 1 - 1e-12 ? 2 : 0;
        for (int a = 0; a < 3; ++a)
            (*disp)[3 * i + a] = (*con)[i] == 2 ? 0.02 * (a + 1) : (*con)[i] ? 0 : NAN;
    }
    return m;
}

static void test_mls(void)
{
    double *disp = NULL;
    unsigned char *con = NULL;
    cm_mesh *m = block_mesh(&disp, &con);
    size_t n = m->n_nodes;
    double *out = malloc(n * 3 * sizeof *out), *ref = malloc(n * 3 * sizeof *ref);
    cm_deform_options o;
    cm_deform_options_init(&o);
    o.method = CM_DEFORM_MLS;
    double res = -1, ref_res = -2;
    /* xyz is the mesh's: NULL is accepted */
    CHECK(run_row(&o, n, NULL, con, m, disp, out, &res) == CM_OK);
    cm_mls *mls = NULL;
    cm_mls_options mo;
    cm_mls_options_init(&mo);
    memcpy(ref, disp, n * 3 * sizeof *ref);
    CHECK(cm_mls_create(ctx, m, con, &mo, &mls) == CM_OK);
    CHECK(cm_mls_apply(ctx, mls, ref, &ref_res) == CM_OK);
    cm_mls_destroy(&mls);
    CHECK(same_bits(out, ref, 3 * n));
    CHECK(res == ref_res);
    /* the MLS behind the row, for shape constraints */
    cm_deform *d = NULL;
    CHECK(cm_deform_create(ctx, &o, n, m->xyz, con, m, &d) == CM_OK);
    CHECK(cm_deform_get_mls(d) != NULL);
    cm_deform_stats st;
    cm_deform_get_stats(d, &st);
    CHECK(st.mls.samples > 0 && st.constrained + st.free == n);
    cm_deform_destroy(&d);
    /* without its mesh: an argument error, not a crash */
    CHECK(cm_deform_create(ctx, &o, n, m->xyz, con, NULL, &d) == CM_ERR_ARGUMENT && !d);
    free(out), free(ref), free(disp), free(con);
    cm_mesh_destroy(&m);
}

/* A bumped n x n grid of triangles in z = 0: left column fixed, right column lifted. */
static void test_shell(void)
{
    int g = 8;
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    size_t n = (size_t)(g + 1) * (g + 1);
    CHECK(cm_mesh_resize_nodes(ctx, m, n, 0) == CM_OK);
    for (int j = 0; j <= g; ++j)
        for (int i = 0; i <= g; ++i) {
            double *p = m->xyz + 3 * (j * (g + 1) + i);
            p[0] = (double)i / g, p[1] = (double)j / g, p[2] = 0.1 * p[0] * p[1];
        }
    for (int j = 0; j < g; ++j)
        for (int i = 0; i < g; ++i) {
            int64_t a = j * (g + 1) + i, t0[3] = {a, a + 1, a + g + 2}, t1[3] = {a, a + g + 2, a + g + 1};
            CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, t0, 3, 0, 0, 0) == CM_OK);
            CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, t1, 3, 0, 0, 0) == CM_OK);
        }
    unsigned char *con = calloc(n, 1);
    double *disp = malloc(n * 3 * sizeof *disp), *out = malloc(n * 3 * sizeof *out);
    double *ref = malloc(n * 3 * sizeof *ref);
    for (size_t i = 0; i < n; ++i) {
        int col = (int)(i % (size_t)(g + 1));
        con[i] = col == 0 ? 1 : col == g ? 2 : 0;
        for (int a = 0; a < 3; ++a)
            disp[3 * i + a] = con[i] == 2 && a == 2 ? 0.1 : 0;
    }
    cm_deform_options o;
    cm_deform_options_init(&o);
    o.method = CM_DEFORM_SHELL;
    o.mls.stretch = 1, o.mls.bend = 0.5, o.mls.fix = 100;
    double res = -1;
    CHECK(run_row(&o, n, NULL, con, m, disp, out, &res) == CM_OK);
    memcpy(ref, disp, n * 3 * sizeof *ref);
    CHECK(cm_mls_shell(ctx, m, con, 1, 0.5, 100, ref) == CM_OK);
    CHECK(same_bits(out, ref, 3 * n));
    CHECK(res == 0);
    /* a face with a repeated corner, then one whose corners are on a line: bad input naming
     * the cell, not a factorisation failure, and disp untouched */
    const int64_t good[3] = {m->conn[m->offset[5]], m->conn[m->offset[5] + 1], m->conn[m->offset[5] + 2]};
    m->conn[m->offset[5] + 1] = good[0];
    memcpy(ref, disp, n * 3 * sizeof *ref);
    CHECK(cm_mls_shell(ctx, m, con, 1, 0.5, 100, ref) == CM_ERR_FORMAT);
    CHECK_MSG(strstr(cm_context_message(ctx), "cell 5 (0-based, tri3): corners 1 and 2 are the same node"),
              "%s", cm_context_message(ctx));
    CHECK(same_bits(ref, disp, 3 * n));
    m->conn[m->offset[5] + 1] = good[1];
    double keep[3];
    memcpy(keep, m->xyz + 3 * good[1], sizeof keep);
    for (int a = 0; a < 3; ++a) /* the middle corner halfway between the other two */
        m->xyz[3 * good[1] + a] = 0.5 * (m->xyz[3 * good[0] + a] + m->xyz[3 * good[2] + a]);
    CHECK(cm_mls_shell(ctx, m, con, 1, 0.5, 100, ref) == CM_ERR_FORMAT);
    CHECK_MSG(strstr(cm_context_message(ctx), "cell 5 (0-based, tri3, nodes") &&
                  strstr(cm_context_message(ctx), "the face has no area"),
              "%s", cm_context_message(ctx));
    memcpy(m->xyz + 3 * good[1], keep, sizeof keep);
    CHECK(cm_mls_shell(ctx, m, con, 1, 0.5, 100, ref) == CM_OK);
    free(con), free(disp), free(out), free(ref);
    cm_mesh_destroy(&m);
}

static void test_table(void)
{
    static const char *names[CM_DEFORM_N_METHODS] = {"rbf", "mls", "shell", "dmffd"};
    for (int mth = 0; mth < CM_DEFORM_N_METHODS; ++mth) {
        CHECK(cm_deform_method_name(mth) && !strcmp(cm_deform_method_name(mth), names[mth]));
        CHECK(cm_deform_method_from_name(names[mth]) == mth);
    }
    CHECK(cm_deform_method_name(CM_DEFORM_N_METHODS) == NULL);
    CHECK(cm_deform_method_from_name("femwarp") == -1 && cm_deform_method_from_name(NULL) == -1);

    double xyz[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1}, disp[15] = {0};
    unsigned char con[5] = {0}, all[5] = {1, 1, 1, 1, 0};
    cm_deform_options o;
    cm_deform_options_init(&o);
    cm_deform *d = NULL;
    o.method = CM_DEFORM_DMFFD;
    CHECK(cm_deform_create(ctx, &o, 5, xyz, con, NULL, &d) == CM_ERR_ARGUMENT && !d);
    o.lattice = 3;
    CHECK(cm_deform_create(ctx, &o, 5, xyz, all, NULL, &d) == CM_ERR_ARGUMENT && !d);
    o.method = (cm_deform_method)CM_DEFORM_N_METHODS;
    CHECK(cm_deform_create(ctx, &o, 5, xyz, all, NULL, &d) == CM_ERR_ARGUMENT && !d);
    /* the defaults: rbf through four non-coplanar points */
    CHECK(cm_deform_create(ctx, NULL, 5, xyz, all, NULL, &d) == CM_OK);
    CHECK(cm_deform_apply(ctx, d, NULL, NULL) == CM_ERR_ARGUMENT);
    CHECK(cm_deform_apply(ctx, d, disp, NULL) == CM_OK && disp[12] == 0);
    cm_deform_destroy(&d);
    cm_deform_destroy(&d); /* twice: harmless */
    /* coplanar constrained points: the RBF's own error, unprefixed */
    double flat[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0.5, 0.5, 1};
    o.method = CM_DEFORM_RBF;
    o.lattice = 0;
    CHECK(cm_deform_create(ctx, &o, 5, flat, all, NULL, &d) == CM_ERR_NUMERIC && !d);
}

/* The reverse product (cm_deform_apply_transpose) of the rbf row: <v, apply(D)> =
 * <J^T v, D> with random D and v, J^T v = 0 at the free points and, for a row without a
 * transpose (shell), CM_ERR_UNSUPPORTED. */
static void test_transpose(cm_rbf_kernel kernel)
{
    size_t n = 400;
    double *xyz = malloc(n * 3 * sizeof *xyz), *disp = malloc(n * 3 * sizeof *disp);
    double *out = malloc(n * 3 * sizeof *out), *v = malloc(n * 3 * sizeof *v);
    double *jtv = malloc(n * 3 * sizeof *jtv);
    unsigned char *con = malloc(n);
    make_points(n, xyz, con, disp);
    for (size_t i = 0; i < n * 3; ++i) v[i] = test_rand(&seed);
    cm_deform_options o;
    cm_deform_options_init(&o);
    o.kernel = kernel;
    cm_deform *d = NULL;
    CHECK(cm_deform_create(ctx, &o, n, xyz, con, NULL, &d) == CM_OK);
    memcpy(out, disp, n * 3 * sizeof *out);
    CHECK(cm_deform_apply(ctx, d, out, NULL) == CM_OK);
    CHECK(cm_deform_apply_transpose(ctx, d, v, jtv) == CM_OK);
    CHECK(cm_deform_apply_transpose(ctx, d, v, v + 3) == CM_ERR_ARGUMENT);
    long double a = 0.0L, b = 0.0L;
    double scale = 0.0;
    int zero = 1;
    for (size_t i = 0; i < n * 3; ++i) {
        a += (long double)v[i] * out[i];
        scale += fabs(v[i] * out[i]);
        if (con[i / 3])
            b += (long double)jtv[i] * disp[i];
        else
            zero &= jtv[i] == 0.0;
    }
    CHECK(zero);
    CHECK_MSG(fabs((double)(a - b)) <= 1e-10 * scale, "kernel %d: %.17g vs %.17g", (int)kernel,
              (double)a, (double)b);
    cm_deform_destroy(&d);
    if (kernel == CM_RBF_TRIHARMONIC) { /* a row without one */
        double *d2 = NULL;
        unsigned char *c2 = NULL;
        cm_mesh *m = block_mesh(&d2, &c2);
        free(d2);
        o.method = CM_DEFORM_SHELL;
        CHECK(cm_deform_create(ctx, &o, m->n_nodes, NULL, c2, m, &d) >= 0);
        double *v2 = calloc(m->n_nodes * 3, sizeof *v2), *o2 = malloc(m->n_nodes * 3 * sizeof *o2);
        CHECK(cm_deform_apply_transpose(ctx, d, v2, o2) == CM_ERR_UNSUPPORTED);
        cm_deform_destroy(&d);
        cm_mesh_destroy(&m);
        free(c2), free(v2), free(o2);
    }
    free(xyz), free(disp), free(out), free(v), free(jtv), free(con);
}

int main(void)
{
    CHECK(cm_context_create(&ctx) == CM_OK);
    test_table();
    test_rbf(CM_RBF_TRIHARMONIC);
    test_rbf(CM_RBF_BIHARMONIC);
    test_dmffd();
    test_mls();
    test_shell();
    test_transpose(CM_RBF_TRIHARMONIC);
    test_transpose(CM_RBF_BIHARMONIC);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
