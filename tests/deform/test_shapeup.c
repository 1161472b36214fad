/* Shape-Up in the MLS deformation (shapeup.h): constraints that the unconstrained
 * deformation already satisfies (a rigid motion of the whole box, bending only) give back
 * the unconstrained deformation after one alternation; a sheared box keeps a side face planar,
 * a block rigid and an edge a similar copy, far better than without; the sparse (section 6.1)
 * and mean-centred formulations both converge, the sparse one with a sparser C. */
#include "cadmorph/shapeup.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* n^3 hex cells over [0,1]^3 */
static cm_mesh *box(cm_context *ctx, int n)
{
    cm_mesh *m = NULL;
    if (cm_mesh_create(ctx, &m) != CM_OK) return NULL;
    cm_mesh_resize_nodes(ctx, m, (size_t)(n + 1) * (n + 1) * (n + 1), 0);
    for (int k = 0; k <= n; ++k)
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) {
                double *p = m->xyz + 3 * (((size_t)k * (n + 1) + j) * (n + 1) + i);
                p[0] = (double)i / n, p[1] = (double)j / n, p[2] = (double)k / n;
            }
#define ID(i, j, k) ((int64_t)(((size_t)(k) * (n + 1) + (j)) * (n + 1) + (i)))
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                int64_t c[8] = {ID(i, j, k),         ID(i + 1, j, k),         ID(i + 1, j + 1, k),
                                ID(i, j + 1, k),     ID(i, j, k + 1),         ID(i + 1, j, k + 1),
                                ID(i + 1, j + 1, k + 1), ID(i, j + 1, k + 1)};
                cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, c, 8, 0, 0, 0);
            }
#undef ID
    return m;
}

/* nodes with coordinate a equal to v (within 1e-12) and, if b >= 0, coordinate b equal to w */
static size_t select_nodes(const cm_mesh *m, int a, double v, int b, double w, int64_t *out)
{
    size_t n = 0;
    for (size_t i = 0; i < m->n_nodes; ++i)
        if (fabs(m->xyz[3 * i + a] - v) < 1e-12 && (b < 0 || fabs(m->xyz[3 * i + b] - w) < 1e-12))
            out[n++] = (int64_t)i;
    return n;
}

static double plane_residual(cm_context *ctx, const cm_mesh *m, const double *d, size_t n,
                             const int64_t *nodes)
{
    double *y = calloc(n * 3, sizeof *y), *p = calloc(n * 3, sizeof *p), r = 0;
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a)
            y[3 * i + a] = m->xyz[3 * nodes[i] + a] + d[3 * nodes[i] + a];
    cm_shape_project_plane(ctx, n, y, p, NULL);
    for (size_t i = 0; i < n; ++i)
        r = fmax(r, sqrt((y[3 * i] - p[3 * i]) * (y[3 * i] - p[3 * i]) +
                         (y[3 * i + 1] - p[3 * i + 1]) * (y[3 * i + 1] - p[3 * i + 1]) +
                         (y[3 * i + 2] - p[3 * i + 2]) * (y[3 * i + 2] - p[3 * i + 2])));
    free(y), free(p);
    return r;
}

static void test_satisfied(cm_context *ctx)
{
    cm_mesh *m = box(ctx, 6);
    size_t n = m->n_nodes;
    unsigned char *con = calloc(n, 1);
    int64_t *side = malloc(n * sizeof *side), *edge = malloc(n * sizeof *edge);
    int64_t *block = malloc(n * sizeof *block), *ring = malloc(n * sizeof *ring);
    for (size_t i = 0; i < n; ++i) {
        if (m->xyz[3 * i] < 1e-12) con[i] = 1;
        if (m->xyz[3 * i] > 1 - 1e-12) con[i] = 2;
    }
    size_t ns = select_nodes(m, 1, 0, -1, 0, side), ne = select_nodes(m, 1, 1, 2, 1, edge);
    size_t nb = 0, nr = 0;
    for (size_t i = 0; i < n; ++i) {
        const double *x = m->xyz + 3 * i;
        if (x[0] > 0.3 && x[0] < 0.7 && x[1] > 0.3 && x[1] < 0.7 && x[2] > 0.3 && x[2] < 0.7)
            block[nb++] = (int64_t)i;
        /* the 8 nodes around the centre of the face y = 1 at distance sqrt(2)/6: a circle */
        if (fabs(x[1] - 1) < 1e-12 && fabs(hypot(x[0] - 0.5, x[2] - 0.5) - sqrt(2) / 6) < 1e-12)
            ring[nr++] = (int64_t)i;
    }
    CHECK(nr == 4);
    /* rigid motion of everything constrained; bending only: its MLS field is the motion */
    double ang = 0.3, c = cos(ang), sn = sin(ang), t[3] = {0.1, -0.2, 0.05};
    double *d = calloc(n * 3, sizeof *d), *d2 = calloc(n * 3, sizeof *d2);
    for (size_t i = 0; i < n; ++i) {
        const double *x = m->xyz + 3 * i;
        d[3 * i] = c * x[0] - sn * x[1] + t[0] - x[0];
        d[3 * i + 1] = sn * x[0] + c * x[1] + t[1] - x[1];
        d[3 * i + 2] = t[2];
    }
    memcpy(d2, d, n * 3 * sizeof *d);
    cm_mls_options o;
    cm_mls_options_init(&o);
    o.stretch = 0;
    o.samples = 120;
    cm_mls *mls = NULL;
    CHECK(cm_mls_create(ctx, m, con, &o, &mls) == CM_OK);
    double res;
    CHECK(cm_mls_apply(ctx, mls, d, &res) == CM_OK);
    cm_shape_set sets[5] = {{CM_SHAPE_PLANE, ns, side},
                            {CM_SHAPE_LINE, ne, edge},
                            {CM_SHAPE_RIGID, nb, block},
                            {CM_SHAPE_CIRCLE, nr, ring},
                            {CM_SHAPE_CYLINDER, 0, NULL}};
    /* a cylinder: the ring on every y layer */
    int64_t *cyl = malloc(n * sizeof *cyl);
    size_t nc = 0;
    for (size_t i = 0; i < n; ++i)
        if (fabs(hypot(m->xyz[3 * i] - 0.5, m->xyz[3 * i + 2] - 0.5) - sqrt(2) / 6) < 1e-12)
            cyl[nc++] = (int64_t)i;
    sets[4].n = nc, sets[4].nodes = cyl;
    for (int sparse = 0; sparse <= 1; ++sparse) {
        cm_shapeup_options so;
        cm_shapeup_options_init(&so);
        so.sparse = sparse;
        cm_shapeup *su = NULL;
        CHECK(cm_shapeup_create(ctx, mls, m, 5, sets, &so, &su) == CM_OK);
        double r0[5], r1[5];
        cm_shapeup_report rep;
        double *d3 = malloc(n * 3 * sizeof *d3);
        memcpy(d3, d2, n * 3 * sizeof *d3);
        CHECK(cm_shapeup_apply(ctx, su, d3, r0, r1, &rep) == CM_OK);
        double diff = 0;
        for (size_t i = 0; i < 3 * n; ++i)
            diff = fmax(diff, fabs(d3[i] - d[i]));
        CHECK_MSG(diff < 1e-9, "sparse %d: satisfied constraints changed the deformation by %g",
                  sparse, diff);
        CHECK_MSG(rep.iterations == 1 && rep.converged, "sparse %d: %d iterations", sparse,
                  rep.iterations);
        for (int t = 0; t < 5; ++t)
            CHECK_MSG(r0[t] < 1e-9 && r1[t] < 1e-9, "set %d: residual %g -> %g", t, r0[t], r1[t]);
        free(d3);
        cm_shapeup_destroy(&su);
        CHECK(su == NULL);
    }
    cm_mls_destroy(&mls);
    cm_mesh_destroy(&m);
    free(con), free(side), free(edge), free(block), free(ring), free(cyl), free(d), free(d2);
}

static void test_shear(cm_context *ctx)
{
    cm_mesh *m = box(ctx, 8);
    size_t n = m->n_nodes;
    unsigned char *con = calloc(n, 1);
    int64_t *side = malloc(n * sizeof *side), *block = malloc(n * sizeof *block);
    double *d = calloc(n * 3, sizeof *d);
    for (size_t i = 0; i < n; ++i) {
        const double *x = m->xyz + 3 * i;
        if (x[2] < 1e-12) con[i] = 1;
        /* half of the top lifted, the other half fixed: a bend, not an affine motion */
        if (x[2] > 1 - 1e-12) con[i] = 1;
        if (x[2] > 1 - 1e-12 && x[0] > 0.5 + 1e-12) con[i] = 2, d[3 * i] = 0.1, d[3 * i + 2] = 0.3;
    }
    size_t nb = 0;
    for (size_t i = 0; i < n; ++i) {
        const double *x = m->xyz + 3 * i;
        if (x[0] > 0.3 && x[0] < 0.7 && x[1] > 0.2 && x[1] < 0.8 && x[2] > 0.5 && x[2] < 0.8)
            block[nb++] = (int64_t)i;
    }
    size_t ns = select_nodes(m, 2, 0.5, -1, 0, side); /* the mid-section z = 0.5 */
    cm_mls_options o;
    cm_mls_options_init(&o);
    o.stretch = 0;
    o.samples = 200;
    o.keep_constrained = 0; /* the output is the field everywhere: residuals can be checked on it */
    cm_mls *mls = NULL;
    CHECK(cm_mls_create(ctx, m, con, &o, &mls) == CM_OK);
    double *d0 = malloc(n * 3 * sizeof *d0);
    memcpy(d0, d, n * 3 * sizeof *d);
    double res;
    CHECK(cm_mls_apply(ctx, mls, d0, &res) == CM_OK);
    double before = plane_residual(ctx, m, d0, ns, side);
    CHECK_MSG(before > 1e-3, "the shear bends the side face: %g", before);
    cm_shape_set sets[2] = {{CM_SHAPE_PLANE, ns, side}, {CM_SHAPE_RIGID, nb, block}};
    size_t cnnz[2] = {0, 0};
    /* gamma_c = 10 (the paper's) trades the constraints against bending; 1000 nearly
     * enforces them, in more alternations */
    /* passes 4, 5: gamma_c = 1000 with Anderson acceleration: the same fixed point in fewer
     * alternations */
    double plain_r1[2][2] = {{0, 0}, {0, 0}};
    int plain_it[2] = {0, 0};
    for (int pass = 0; pass < 6; ++pass) {
        int sparse = pass & 1;
        double gamma = pass < 2 ? 10 : 1000, fplane = pass < 2 ? 0.5 : 0.05, frigid = pass < 2 ? 0.9 : 0.25;
        cm_shapeup_options so;
        cm_shapeup_options_init(&so);
        so.sparse = sparse;
        so.tolerance = 1e-10;
        so.max_iterations = 30000;
        so.weight = gamma;
        so.anderson = pass >= 4 ? 5 : 0;
        cm_shapeup *su = NULL;
        CHECK(cm_shapeup_create(ctx, mls, m, 2, sets, &so, &su) == CM_OK);
        double *d1 = malloc(n * 3 * sizeof *d1), r0[2], r1[2];
        memcpy(d1, d, n * 3 * sizeof *d);
        cm_shapeup_report rep;
        cm_status st = cm_shapeup_apply(ctx, su, d1, r0, r1, &rep);
        CHECK(st == CM_OK);
        CHECK_NEAR(r0[0], before, 1e-12);
        CHECK_MSG(r1[0] < fplane * before, "sparse %d: plane residual %g -> %g (%d iterations)", sparse,
                  r0[0], r1[0], rep.iterations);
        CHECK_MSG(r1[1] < frigid * r0[1], "sparse %d: rigid residual %g -> %g", sparse, r0[1], r1[1]);
        CHECK_NEAR(plane_residual(ctx, m, d1, ns, side), r1[0], 1e-12);
        /* the handle still moves as prescribed, to the MLS residual's order */
        CHECK_MSG(rep.fix_residual < 10 * res + 1e-3, "fix residual %g (unconstrained %g)",
                  rep.fix_residual, res);
        cnnz[sparse] = rep.c_nonzeros;
        printf("gamma_c %g, anderson %d, sparse %d: plane %.3g -> %.3g, rigid %.3g -> %.3g, %d iterations, C nnz %zu, "
               "update nnz %zu, factor nnz %zu, update %.3f s, iterations %.3f s\n",
               gamma, so.anderson, sparse, r0[0], r1[0], r0[1], r1[1], rep.iterations, rep.c_nonzeros,
               rep.update_nonzeros, rep.factor_nonzeros, rep.t_factor, rep.t_iterate);
        if (pass >= 2 && pass < 4)
            plain_r1[sparse][0] = r1[0], plain_r1[sparse][1] = r1[1], plain_it[sparse] = rep.iterations;
        if (pass >= 4) {
            CHECK_MSG(fabs(r1[0] - plain_r1[sparse][0]) < 1e-3 * plain_r1[sparse][0] + 1e-7 &&
                          fabs(r1[1] - plain_r1[sparse][1]) < 1e-3 * plain_r1[sparse][1] + 1e-7,
                      "anderson: residuals %g %g vs plain %g %g", r1[0], r1[1], plain_r1[sparse][0],
                      plain_r1[sparse][1]);
            CHECK_MSG(rep.iterations * 3 < plain_it[sparse], "anderson: %d iterations vs plain %d",
                      rep.iterations, plain_it[sparse]);
        }
        if (pass >= 2) {
            free(d1);
            cm_shapeup_destroy(&su);
            continue;
        }
        /* a cap of 2 iterations reports a warning */
        so.max_iterations = 2;
        cm_shapeup_destroy(&su);
        CHECK(cm_shapeup_create(ctx, mls, m, 2, sets, &so, &su) == CM_OK);
        memcpy(d1, d, n * 3 * sizeof *d);
        CHECK(cm_shapeup_apply(ctx, su, d1, NULL, NULL, &rep) == CM_WARNING);
        CHECK(rep.iterations == 2 && !rep.converged);
        cm_shapeup_destroy(&su);
        free(d1);
    }
    CHECK(cnnz[1] == 2 * (ns - 1 + nb - 1));
    CHECK(cnnz[0] == ns * ns + nb * nb);
    /* bad sets */
    cm_shapeup *su = NULL;
    int64_t bad[3] = {0, 1, (int64_t)n};
    cm_shape_set b1 = {CM_SHAPE_PLANE, 3, bad};
    CHECK(cm_shapeup_create(ctx, mls, m, 1, &b1, NULL, &su) == CM_ERR_ARGUMENT && su == NULL);
    cm_shape_set b2 = {CM_SHAPE_CYLINDER, 3, bad};
    CHECK(cm_shapeup_create(ctx, mls, m, 1, &b2, NULL, &su) == CM_ERR_ARGUMENT && su == NULL);
    cm_mls_destroy(&mls);
    cm_mesh_destroy(&m);
    free(con), free(side), free(block), free(d), free(d0);
}

/* The snap with exact constraints (the defaults): the faces x = 0 and y = 0 of a box whose
 * bottom is fixed and whose top stretches within both faces (d = (0.1 x, 0.1 y, 0.2)) stay on
 * their planes to rounding, their common edge on both; the field alone leaves them. */
static void test_snap_exact(cm_context *ctx)
{
    cm_mesh *m = box(ctx, 6);
    size_t n = m->n_nodes;
    unsigned char *con = calloc(n, 1);
    int64_t *fx = malloc(n * sizeof *fx), *fy = malloc(n * sizeof *fy);
    double *d = calloc(n * 3, sizeof *d), *d0 = malloc(n * 3 * sizeof *d0);
    for (size_t i = 0; i < n; ++i) {
        const double *x = m->xyz + 3 * i;
        if (x[2] < 1e-12) con[i] = 1;
        if (x[2] > 1 - 1e-12) con[i] = 2, d[3 * i] = 0.1 * x[0], d[3 * i + 1] = 0.1 * x[1], d[3 * i + 2] = 0.2;
    }
    size_t nx = select_nodes(m, 0, 0, -1, 0, fx), ny = select_nodes(m, 1, 0, -1, 0, fy);
    cm_mls_options o;
    cm_mls_options_init(&o); /* keep_constrained: exact */
    o.samples = 150;
    cm_mls *mls = NULL;
    CHECK(cm_mls_create(ctx, m, con, &o, &mls) == CM_OK);
    memcpy(d0, d, n * 3 * sizeof *d);
    double res = 0, off = 0;
    CHECK(cm_mls_apply(ctx, mls, d0, &res) == CM_OK);
    for (size_t i = 0; i < nx; ++i)
        off = fmax(off, fabs(d0[3 * fx[i]]));
    CHECK_MSG(off > 1e-6, "the field leaves the face x = 0: %g", off);
    cm_shape_set sets[2] = {{CM_SHAPE_PLANE, nx, fx}, {CM_SHAPE_PLANE, ny, fy}};
    for (int snap = 0; snap < 2; ++snap) {
        cm_shapeup_options so;
        cm_shapeup_options_init(&so);
        so.snap = snap;
        cm_shapeup *su = NULL;
        CHECK(cm_shapeup_create(ctx, mls, m, 2, sets, &so, &su) == CM_OK);
        memcpy(d0, d, n * 3 * sizeof *d);
        double r1[2] = {-1, -1};
        cm_shapeup_report rep;
        CHECK(cm_shapeup_apply(ctx, su, d0, NULL, r1, &rep) >= 0);
        cm_shapeup_destroy(&su);
        double ex = 0, ey = 0, miss = 0;
        for (size_t i = 0; i < nx; ++i)
            ex = fmax(ex, fabs(d0[3 * fx[i]]));
        for (size_t i = 0; i < ny; ++i)
            ey = fmax(ey, fabs(d0[3 * fy[i] + 1]));
        for (size_t i = 0; i < n; ++i)
            if (con[i])
                for (int a = 0; a < 3; ++a)
                    miss = fmax(miss, fabs(d0[3 * i + a] - d[3 * i + a]));
        CHECK_MSG(miss == 0, "snap %d: handles and fixed nodes exact: %g", snap, miss);
        if (snap) {
            CHECK_MSG(ex <= 1e-15 && ey <= 1e-15, "snapped: off x = 0 by %g, y = 0 by %g", ex, ey);
            CHECK_MSG(r1[0] <= 1e-14 && r1[1] <= 1e-14, "snapped: residuals of the result %g %g",
                      r1[0], r1[1]);
        } else {
            CHECK_MSG(ex > 1e-9 || ey > 1e-9, "not snapped: the faces hold only approximately");
        }
    }
    cm_mls_destroy(&mls);
    free(con), free(fx), free(fy), free(d), free(d0);
    cm_mesh_destroy(&m);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    test_satisfied(ctx);
    test_shear(ctx);
    test_snap_exact(ctx);
    cm_shape_type t;
    CHECK(cm_shape_type_parse(ctx, "cylinder", &t) == CM_OK && t == CM_SHAPE_CYLINDER);
    CHECK(cm_shape_type_parse(ctx, "cone", &t) == CM_OK && t == CM_SHAPE_CONE);
    CHECK(!strcmp(cm_shape_type_name(CM_SHAPE_CONE), "cone"));
    CHECK(cm_shape_type_parse(ctx, "sphere", &t) == CM_ERR_ARGUMENT);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
