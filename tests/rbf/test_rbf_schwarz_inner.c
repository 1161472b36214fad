/* The Schwarz preconditioner with its coarse problem solved by an inner Krylov method
 * (coarse_inner > 0, rbf_schwarz_coarse.c): the fit agrees with the dense solver and with
 * the dense-coarse preconditioner, the inner solver really ran (and the preconditioner with
 * a tight inner tolerance takes the dense coarse factor's iterations), and bad options are
 * refused. Small subdomains (leaves of <= 128 grown to 500-700), so that the inner Schwarz
 * on the coarse centres is a real one (with the default 1,400 its subdomains would be the
 * whole coarse set). */
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "rbf_tuning.h"
#include "rbf_test_sets.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* fit, evaluate at the np points p; inner solves / iterations of the preconditioner */
static cm_status fit(cm_context *ctx, const cm_rbf_options *o, const cm_rbf_tuning *tun, size_t m, const double *x,
                     const double *d, size_t np, const double *p, double *out,
                     cm_rbf_stats *st, long *solves, long *its)
{
    cm_rbf *r = NULL;
    cm_status s = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, o, tun, &r);
    if (s == CM_OK) s = cm_rbf_solve(ctx, r, 3, d);
    if (s == CM_OK) s = cm_rbf_evaluate(ctx, r, np, p, out);
    if (r) {
        cm_rbf_get_stats(r, st);
        if (solves)
            cm_rbf_coarse_inner_stats(cm_rbf_schwarz_inner(cm_rbf_iterative_pc(r)), solves, its);
    }
    cm_rbf_destroy(&r);
    return s;
}

static void test_inner(cm_context *ctx)
{
    double *x = NULL, *d = NULL;
    size_t m = bore_set(0.076, &x, &d);
    size_t np = 0;
    double *p = eval_points(m, x, 1500, 1.8, &np);
    double *sd = malloc(np * 3 * sizeof *sd), *s0 = malloc(np * 3 * sizeof *s0);
    double *s1 = malloc(np * 3 * sizeof *s1);
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_DENSE;
    cm_rbf_stats std, st0, st1;
    cm_status a = fit(ctx, &o, &tun, m, x, d, np, p, sd, &std, NULL, NULL);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    tun.leaf_size = 128;
    tun.local_size = 500;
    tun.local_max = 700;
    long n0 = -1, i0 = -1, n1 = 0, i1 = 0;
    cm_status b = fit(ctx, &o, &tun, m, x, d, np, p, s0, &st0, &n0, &i0);
    /* the same coarse space (m/4: the most the rule allows) solved inexactly */
    tun.coarse_inner = 20;
    cm_status c = fit(ctx, &o, &tun, m, x, d, np, p, s1, &st1, &n1, &i1);
    CHECK_MSG(a == CM_OK && b == CM_OK && c == CM_OK, "%d %d %d: %s", a, b, c,
              cm_context_message(ctx));
    const double range = fmax(range_of(m * 3, d), 1e-300);
    const double tol = fmax(1e-9, 3.0 * std.residual);
    double d1 = max_diff(np * 3, s1, sd) / range, d0 = max_diff(np * 3, s0, sd) / range;
    printf("m = %zu: dense-coarse %d iterations (coarse %d), inner-coarse %d iterations "
           "(coarse %d; %ld inner solves, %ld inner iterations), residual %.3g, "
           "|inner - dense| = %.3g, |dense-coarse - dense| = %.3g of the range\n",
           m, st0.iterations, st0.coarse_size, st1.iterations, st1.coarse_size, n1, i1,
           st1.residual, d1, d0);
    CHECK(n0 == 0 && i0 == 0);       /* the default has no inner solver */
    CHECK(st1.coarse_size == (int)(m / 4));
    CHECK_MSG(n1 >= st1.iterations && i1 >= n1, "%ld solves, %ld iterations", n1, i1);
    CHECK_MSG(i1 <= 20 * n1, "%ld > 20 x %ld", i1, n1);
    CHECK_MSG(d1 <= tol, "%.3g > %.3g", d1, tol);
    CHECK_MSG(st1.residual <= fmax(1e-10, st1.floor), "%.3g", st1.residual);
    CHECK_MSG(max_diff(m * 3, s1, d) / range <= 1e-9, "%.3g", max_diff(m * 3, s1, d) / range);
    CHECK_MSG(st1.iterations >= 1 && st1.iterations <= 30, "%d iterations", st1.iterations);

    /* a tight inner tolerance is the exact coarse solve in all but rounding: the same
     * iteration count as the dense coarse factor of the same coarse space */
    cm_rbf_stats st2;
    tun.coarse_inner = 60;
    tun.coarse_inner_tol = 1e-9;
    cm_status e = fit(ctx, &o, &tun, m, x, d, np, p, s1, &st2, &n1, &i1);
    printf("inner to 1e-9: %d iterations (dense coarse: %d), %ld inner iterations\n",
           st2.iterations, st0.iterations, i1);
    CHECK(e == CM_OK);
    CHECK_MSG(abs(st2.iterations - st0.iterations) <= 1, "%d vs %d", st2.iterations,
              st0.iterations);
    CHECK_MSG(max_diff(np * 3, s1, sd) / range <= tol, "%.3g", max_diff(np * 3, s1, sd) / range);

    /* refused: negative counts and tolerances outside (0, 1) */
    cm_rbf *r = NULL;
    tun.coarse_inner = -1;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT && !r);
    tun.coarse_inner = 5;
    tun.coarse_inner_tol = 1.5;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT && !r);
    CHECK(strstr(cm_context_message(ctx), "coarse_inner") != NULL);
    free(x), free(d), free(p), free(sd), free(s0), free(s1);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    test_inner(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
