/* cm_deform_apply_many against k separate cm_deform_apply calls (k = 1, 2, 5, blocks of sizes
 * 1e-3 to 1e3): rbf with both kernels, dense (bit for bit at k = 1, to rounding above) and
 * iterative (to its tolerance); dmffd through the loop over apply (bit for bit, the residual
 * the largest of the blocks); merged duplicate points whose values differ in a small block
 * are refused as in that block's own apply, although a large block beside it would hide the
 * difference; argument errors. */
#include "cadmorph/deform.h"
#include "test_mesh.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;

/* n points in a box, every third one constrained; the free points' entries of the k blocks
 * NaN (apply reads none of them); block j of size 10^(1.5 j - 3). */
static void make_points(uint64_t *seed, size_t n, size_t k, double *xyz, unsigned char *con,
                        double *disp)
{
    for (size_t i = 0; i < n; ++i) {
        con[i] = i % 3 == 0;
        for (int a = 0; a < 3; ++a)
            xyz[3 * i + a] = (a + 1) * test_rand(seed);
    }
    for (size_t j = 0; j < k; ++j) {
        const double size = pow(10.0, 1.5 * (double)j - 3.0);
        for (size_t i = 0; i < 3 * n; ++i)
            disp[j * 3 * n + i] = con[i / 3] ? size * test_rand(seed) : NAN;
    }
}

/* The largest over the blocks of |many - apply| / max |apply| of the block (-1 on failure). */
static double compare(const cm_deform_options *o, size_t k)
{
    uint64_t seed = 7 + k;
    const size_t n = 240, n3 = 3 * n;
    double *xyz = malloc(n3 * sizeof *xyz), *many = malloc(k * n3 * sizeof *many);
    double *want = malloc(k * n3 * sizeof *want);
    unsigned char *con = malloc(n);
    make_points(&seed, n, k, xyz, con, many);
    memcpy(want, many, k * n3 * sizeof *want);
    cm_deform *d = NULL;
    double worst = -1, rmax = 0, r = -1;
    cm_status s = cm_deform_create(ctx, o, n, xyz, con, NULL, &d);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    for (size_t j = 0; s >= 0 && j < k; ++j) {
        double rj = 0;
        s = cm_deform_apply(ctx, d, want + j * n3, &rj);
        rmax = fmax(rmax, rj);
    }
    if (s >= 0) s = cm_deform_apply_many(ctx, d, k, many, &r);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    if (s >= 0) {
        CHECK_MSG(r == rmax, "residual %.17g, largest of the blocks %.17g", r, rmax);
        worst = 0;
        for (size_t j = 0; j < k; ++j) {
            double dmax = 0, vmax = 0;
            for (size_t i = 0; i < n3; ++i) {
                const double a = many[j * n3 + i], b = want[j * n3 + i];
                vmax = fmax(vmax, fabs(b));
                dmax = a == a ? fmax(dmax, fabs(a - b)) : INFINITY;
            }
            worst = fmax(worst, dmax / vmax);
        }
    }
    printf("  %s, k = %zu: largest relative difference %.3g\n", cm_deform_method_name(o->method),
           k, worst);
    cm_deform_destroy(&d);
    free(xyz), free(many), free(want), free(con);
    return worst;
}

/* Two coincident constrained points (merged by the RBF): equal values in the large block,
 * values 1e-6 of the small block apart in the small one. */
static void test_duplicates(void)
{
    uint64_t seed = 3;
    const size_t n = 60, n3 = 3 * n, k = 2;
    double *xyz = malloc(n3 * sizeof *xyz), *disp = malloc(k * n3 * sizeof *disp);
    unsigned char *con = malloc(n);
    make_points(&seed, n, k, xyz, con, disp);
    memcpy(xyz + 3 * 3, xyz, 3 * sizeof *xyz); /* point 3 on point 0, both constrained */
    for (int a = 0; a < 3; ++a) {
        disp[3 * 3 + a] = disp[a] = 1e3 * (a + 1); /* block 0 is the large one */
        disp[n3 + a] = 1e-3;
        disp[n3 + 3 * 3 + a] = 1e-3 * (1 + 1e-6);
    }
    cm_deform_options o;
    cm_deform_options_init(&o);
    o.solver = CM_RBF_SOLVER_DENSE;
    cm_deform *d = NULL;
    CHECK(cm_deform_create(ctx, &o, n, xyz, con, NULL, &d) >= 0);
    double *one = malloc(n3 * sizeof *one);
    memcpy(one, disp + n3, n3 * sizeof *one);
    CHECK(d && cm_deform_apply(ctx, d, one, NULL) == CM_ERR_NUMERIC);
    cm_context_clear(ctx);
    cm_status s = d ? cm_deform_apply_many(ctx, d, k, disp, NULL) : CM_OK;
    CHECK_MSG(s == CM_ERR_NUMERIC && strstr(cm_context_message(ctx), "coincide"),
              "status %d: %s", (int)s, cm_context_message(ctx));
    cm_context_clear(ctx);
    /* the large block alone is fine */
    CHECK(d && cm_deform_apply_many(ctx, d, 1, disp, NULL) == CM_OK);
    /* argument errors; k = 0 does nothing */
    CHECK(cm_deform_apply_many(ctx, NULL, 1, disp, NULL) == CM_ERR_ARGUMENT);
    CHECK(cm_deform_apply_many(ctx, d, 1, NULL, NULL) == CM_ERR_ARGUMENT);
    CHECK(cm_deform_apply_many(ctx, d, 0, NULL, NULL) == CM_OK);
    cm_context_clear(ctx);
    cm_deform_destroy(&d);
    free(xyz), free(disp), free(con), free(one);
}

int main(void)
{
    CHECK(cm_context_create(&ctx) == CM_OK);
    const size_t ks[3] = {1, 2, 5};
    cm_deform_options o;
    for (int i = 0; i < 3; ++i) {
        cm_deform_options_init(&o);
        o.solver = CM_RBF_SOLVER_DENSE;
        /* k > 1: LAPACK's blocked solves round differently for 3k right-hand sides, and r^3's
         * system of random points (some close) magnifies it by its condition */
        CHECK(compare(&o, ks[i]) <= (ks[i] == 1 ? 0 : 1e-10));
        o.kernel = CM_RBF_BIHARMONIC;
        CHECK(compare(&o, ks[i]) <= (ks[i] == 1 ? 0 : 1e-13));
        cm_deform_options_init(&o);
        o.solver = CM_RBF_SOLVER_ITERATIVE;
        o.tolerance = 1e-10;
        const double it = compare(&o, ks[i]);
        CHECK(it >= 0 && it <= 1e-7);
        cm_deform_options_init(&o);
        o.method = CM_DEFORM_DMFFD;
        o.lattice = 5;
        CHECK(compare(&o, ks[i]) == 0); /* the loop over apply: the same calls */
    }
    test_duplicates();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
