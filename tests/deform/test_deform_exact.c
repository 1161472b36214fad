/* The defaults of the handle and fixed constraints (deform.h, mls.h): an MLS deformation
 * gives its handle (H) and fixed (F) nodes exactly their prescribed motion unless asked for
 * the paper's weighted fit (keep_constrained = 0), which misses them; with no free point at
 * all, rbf, dmffd and the exact mls build nothing and return the prescribed motion (and the
 * approximate mls still builds: its result is the field's). */
#include "cadmorph/deform.h"
#include "test_mesh.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static uint64_t seed = 4242;

/* A jittered 6 x 6 x 6 hex block on [0, 1]^3: F the face x = 0, H the face x = 1 (a twist
 * and a lift, so that no linear field can meet both), the rest free. */
static cm_mesh *block(double **disp, unsigned char **con)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    test_block b = {6, 6, 6, {0, 0, 0}, {1.0 / 6, 1.0 / 6, 1.0 / 6}, 0, 0.2};
    CHECK(test_add_block(ctx, m, &b, &seed) == 0);
    *disp = malloc(m->n_nodes * 3 * sizeof **disp);
    *con = calloc(m->n_nodes, 1);
    for (size_t i = 0; i < m->n_nodes; ++i) {
        const double *x = m->xyz + 3 * i;
        (*con)[i] = x[0] < 1e-12 ? 1 : x[0] > 1 - 1e-12 ? 2 : 0;
        double *d = *disp + 3 * i;
        d[0] = d[1] = d[2] = 0;
        if ((*con)[i] == 2) d[0] = 0.1 * x[1] * x[2], d[1] = -0.15 * (x[2] - 0.5), d[2] = 0.2;
    }
    return m;
}

/* The largest miss at the constrained nodes, relative to the largest prescribed motion. */
static double miss(const cm_mesh *m, const unsigned char *con, const double *want, const double *got)
{
    double e = 0, big = 0;
    for (size_t i = 0; i < m->n_nodes; ++i) {
        if (!con[i]) continue;
        double d = 0, w = 0;
        for (int a = 0; a < 3; ++a)
            d += (got[3 * i + a] - want[3 * i + a]) * (got[3 * i + a] - want[3 * i + a]),
                w += want[3 * i + a] * want[3 * i + a];
        e = fmax(e, sqrt(d)), big = fmax(big, sqrt(w));
    }
    return e / big;
}

static void test_defaults(void)
{
    cm_deform_options o;
    cm_deform_options_init(&o);
    CHECK(o.mls.keep_constrained == 1 && o.mls.blend > 0);
    cm_mls_options mo;
    cm_mls_options_init(&mo);
    CHECK(mo.keep_constrained == 1);

    double *disp = NULL;
    unsigned char *con = NULL;
    cm_mesh *m = block(&disp, &con);
    size_t n = m->n_nodes;
    double *out = malloc(n * 3 * sizeof *out);
    o.method = CM_DEFORM_MLS;
    o.mls.samples = 120;
    for (int exact = 1; exact >= 0; --exact) {
        o.mls.keep_constrained = exact;
        cm_deform *d = NULL;
        double res = -1;
        memcpy(out, disp, n * 3 * sizeof *out);
        CHECK(cm_deform_create(ctx, &o, n, NULL, con, m, &d) == CM_OK);
        CHECK(cm_deform_apply(ctx, d, out, &res) == CM_OK);
        double e = miss(m, con, disp, out);
        /* the field itself misses in both: the residual says by how much */
        CHECK_MSG(res > 1e-4, "residual %g", res);
        if (exact) {
            CHECK_MSG(e <= 1e-12, "exact by default: miss %g of the motion", e);
        } else {
            CHECK_MSG(e > 1e-3, "approximate: the field's value, miss %g", e);
            /* and the residual is that miss (the largest prescribed motion is H's at y = z = 1:
             * |(0.1, -0.075, 0.2)|) */
            CHECK_NEAR(e * sqrt(0.01 + 0.075 * 0.075 + 0.04), res, 1e-12);
        }
        /* the free nodes follow in both */
        double free_move = 0;
        for (size_t i = 0; i < n; ++i)
            if (!con[i]) free_move = fmax(free_move, fabs(out[3 * i + 2]));
        CHECK(free_move > 0.05);
        cm_deform_destroy(&d);
    }
    free(out), free(disp), free(con);
    cm_mesh_destroy(&m);
}

/* every node a handle or fixed: the prescribed motion, nothing built */
static void test_no_free(void)
{
    double *disp = NULL;
    unsigned char *con = NULL;
    cm_mesh *m = block(&disp, &con);
    size_t n = m->n_nodes;
    for (size_t i = 0; i < n; ++i)
        if (!con[i]) {
            con[i] = 2;
            for (int a = 0; a < 3; ++a)
                disp[3 * i + a] = 0.01 * test_rand(&seed);
        }
    double *out = malloc(2 * n * 3 * sizeof *out), *v = malloc(n * 3 * sizeof *v);
    static const cm_deform_method methods[] = {CM_DEFORM_RBF, CM_DEFORM_DMFFD, CM_DEFORM_MLS};
    for (int q = 0; q < 3; ++q) {
        cm_deform_options o;
        cm_deform_options_init(&o);
        o.method = methods[q];
        o.mls.samples = 120;
        cm_deform *d = NULL;
        CHECK(cm_deform_create(ctx, &o, n, m->xyz, con, m, &d) == CM_OK);
        cm_deform_stats st;
        cm_deform_get_stats(d, &st);
        CHECK_MSG(st.prescribed_only == 1 && st.free == 0 && st.constrained == n,
                  "%s: prescribed_only %d", cm_deform_method_name(methods[q]), st.prescribed_only);
        /* nothing built: no RBF centre, no lattice, no MLS */
        CHECK(st.rbf.centres == 0 && st.control_points == 0 && st.mls.samples == 0);
        CHECK(cm_deform_get_mls(d) == NULL);
        double res = -1;
        memcpy(out, disp, n * 3 * sizeof *out);
        CHECK(cm_deform_apply(ctx, d, out, &res) == CM_OK);
        CHECK(res == 0 && memcmp(out, disp, n * 3 * sizeof *out) == 0);
        memcpy(out + 3 * n, disp, n * 3 * sizeof *out);
        CHECK(cm_deform_apply_many(ctx, d, 2, out, &res) == CM_OK);
        CHECK(memcmp(out + 3 * n, disp, n * 3 * sizeof *out) == 0);
        /* apply is the identity: so is its transpose */
        for (size_t i = 0; i < 3 * n; ++i)
            v[i] = test_rand(&seed);
        CHECK(cm_deform_apply_transpose(ctx, d, v, out) == CM_OK);
        CHECK(memcmp(out, v, n * 3 * sizeof *out) == 0);
        cm_deform_destroy(&d);
    }
    /* the approximate MLS gives the field's values: it is built */
    cm_deform_options o;
    cm_deform_options_init(&o);
    o.method = CM_DEFORM_MLS;
    o.mls.samples = 120;
    o.mls.keep_constrained = 0;
    cm_deform *d = NULL;
    CHECK(cm_deform_create(ctx, &o, n, m->xyz, con, m, &d) == CM_OK);
    cm_deform_stats st;
    cm_deform_get_stats(d, &st);
    CHECK(st.prescribed_only == 0 && st.mls.samples > 0 && cm_deform_get_mls(d) != NULL);
    cm_deform_destroy(&d);
    free(out), free(v), free(disp), free(con);
    cm_mesh_destroy(&m);
}

int main(void)
{
    CHECK(cm_context_create(&ctx) == CM_OK);
    test_defaults();
    test_no_free();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
