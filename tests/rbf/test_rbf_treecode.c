/* Tests of the r^3 treecode (rbf/sum/rbf_treecode.c) and of the iterative solver with fast
 * matvecs: the error bound |fast_i - exact_i| <= tol sum_j |w_j| phi_ij on random and on real
 * RBF weights, at the centres and elsewhere; fits with fast_sum on against direct matvecs
 * and the dense solver; affine data; the choice of the fast evaluation; the hand-written
 * AVX-512 products against the compiled fallbacks. */
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "rbf_tuning.h"
#include "sum/rbf_treecode.h"
#include "rbf_test_sets.h"
#include "test_rng.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

/* max_i |fast_i - exact_i| / S_i with S_i = sum_j |w_j| phi_ij, over nc components; exact by
 * compensated sums. c: 3 x m SoA, p: 3 x n SoA. Also the cancellation max S / max |exact|. */
static double bound_ratio(const cm_rbf_tree *t, size_t m, const double *c, const double *w,
                          int nc, size_t n, const double *p, int self, double *cancel)
{
    double *fast = malloc(n * (size_t)nc * sizeof *fast), *ex = malloc(n * (size_t)nc * sizeof *ex);
    double *S = malloc(n * (size_t)nc * sizeof *S), *aw = malloc(m * (size_t)nc * sizeof *aw);
    int st = self ? cm_rbf_tree_sum_self(t, w, nc, fast, (size_t)nc, 2)
                  : cm_rbf_tree_sum(t, w, nc, n, p, n, fast, (size_t)nc, 2);
    CHECK(st == 0);
    cm_rbf_kernel_sum_acc(m, c, w, nc, n, p, n, ex, (size_t)nc, 2);
    for (size_t j = 0; j < m * (size_t)nc; ++j) aw[j] = fabs(w[j]);
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, aw, nc, n, p, n, S, (size_t)nc, 2);
    double worst = 0.0, smax = 0.0, emax = 0.0;
    for (size_t i = 0; i < n * (size_t)nc; ++i) {
        worst = fmax(worst, fabs(fast[i] - ex[i]) / S[i]);
        smax = fmax(smax, S[i]);
        emax = fmax(emax, fabs(ex[i]));
    }
    if (cancel) *cancel = smax / emax;
    free(fast), free(ex), free(S), free(aw);
    return worst;
}

/* max_i |fast_i - ex_i| / S_i over the first nc of 4 components (ex, S: n x 4) */
static double ratio4(const double *fast, int nc, size_t n, const double *ex, const double *S)
{
    double worst = 0.0;
    for (size_t i = 0; i < n; ++i)
        for (int q = 0; q < nc; ++q)
            worst = fmax(worst, fabs(fast[i * (size_t)nc + (size_t)q] - ex[4 * i + (size_t)q]) /
                                    S[4 * i + (size_t)q]);
    return worst;
}

/* The bound on random weights, for tolerances of the table, at the centres (the solver's
 * use) and at points inside the box (evaluation), for 1..4 components. */
static void test_bound_random(void)
{
    size_t m;
    double *x = bore_centres(0.06, &m); /* ~8k centres */
    double *c = malloc(3 * m * sizeof *c), *w = malloc(4 * m * sizeof *w);
    for (size_t i = 0; i < m; ++i)
        for (int d = 0; d < 3; ++d) c[(size_t)d * m + i] = x[3 * i + d] / 4.0;
    uint64_t rng = 7;
    for (size_t i = 0; i < 4 * m; ++i) w[i] = test_rng_range(&rng, -1.0, 1.0);
    const size_t n = 3000;
    double *p = malloc(3 * n * sizeof *p);
    for (size_t i = 0; i < n; ++i) {
        p[i] = test_rng_range(&rng, 0.0, 1.0);
        p[n + i] = test_rng_range(&rng, 0.0, 0.5);
        p[2 * n + i] = test_rng_range(&rng, 0.0, 0.25);
    }
    /* exact sums (compensated) and the scales S = sum |w| phi, at the centres and at p */
    double *exc = malloc(4 * m * sizeof *exc), *Sc = malloc(4 * m * sizeof *Sc);
    double *exp_ = malloc(4 * n * sizeof *exp_), *Sp = malloc(4 * n * sizeof *Sp);
    double *aw = malloc(4 * m * sizeof *aw), *fast = malloc(4 * m * sizeof *fast);
    for (size_t j = 0; j < 4 * m; ++j) aw[j] = fabs(w[j]);
    cm_rbf_kernel_sum_acc(m, c, w, 4, m, c, m, exc, 4, 2);
    cm_rbf_kernel_sum_acc(m, c, w, 4, n, p, n, exp_, 4, 2);
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, aw, 4, m, c, m, Sc, 4, 2);
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, aw, 4, n, p, n, Sp, 4, 2);
    const double tols[] = {1e-4, 1e-7, 1e-10, 1e-12};
    for (int k = 0; k < 4; ++k) {
        int order;
        double theta;
        cm_rbf_tree_params(tols[k], &order, &theta);
        cm_rbf_tree *t = cm_rbf_tree_create(m, c, order, theta);
        CHECK(t != NULL);
        if (!t) continue;
        int nc = 1 + k;
        CHECK(cm_rbf_tree_sum_self(t, w, nc, fast, (size_t)nc, 2) == 0);
        double rs = ratio4(fast, nc, m, exc, Sc);
        CHECK(cm_rbf_tree_sum(t, w, nc, n, p, n, fast, (size_t)nc, 2) == 0);
        double ro = ratio4(fast, nc, n, exp_, Sp);
        printf("random weights, m = %zu, tol %.0e (order %d, theta %.2f), %d components: "
               "max err / sum|w|phi = %.3g at the centres, %.3g inside\n",
               m, tols[k], order, theta, nc, rs, ro);
        CHECK_MSG(rs <= tols[k] && ro <= tols[k], "%.3g %.3g > %.3g", rs, ro, tols[k]);
        /* and not trivially: the far field was used (a direct sum would be at 1e-16) */
        if (k < 2) CHECK_MSG(rs > 1e-3 * tols[k], "%.3g: far field unused?", rs);
        /* the a-posteriori check sees an error of the same order as the true one */
        if (k == 1) {
            double e, sabs;
            cm_rbf_tree_check(t, w, nc, n, p, n, fast, (size_t)nc, 256, NULL, &e, &sabs, 2);
            double etrue = 0.0;
            for (size_t i = 0; i < n; ++i)
                for (int q = 0; q < nc; ++q)
                    etrue = fmax(etrue, fabs(fast[i * (size_t)nc + (size_t)q] - exp_[4 * i + (size_t)q]));
            printf("sampled error %.3g, true max error %.3g\n", e, etrue);
            CHECK_MSG(e <= etrue * (1 + 1e-6) && 4.0 * e >= etrue, "%.3g vs %.3g", e, etrue);
        }
        cm_rbf_tree_destroy(&t);
    }
    /* fewer centres than one proxy grid: all direct, exact to rounding */
    cm_rbf_tree *t = cm_rbf_tree_create(300, c, 8, 0.5);
    double *ex3 = malloc(3 * 300 * sizeof *ex3), *w3 = malloc(3 * 300 * sizeof *w3);
    for (int q = 0; q < 3; ++q) memcpy(w3 + q * 300, w + (size_t)q * m, 300 * sizeof *w3);
    CHECK(t && cm_rbf_tree_sum_self(t, w3, 3, fast, 3, 2) == 0);
    cm_rbf_kernel_sum_acc(300, c, w3, 3, 300, c, 300, ex3, 3, 2);
    double e300 = 0.0, s300 = 0.0;
    for (size_t i = 0; i < 900; ++i) e300 = fmax(e300, fabs(fast[i] - ex3[i])), s300 = fmax(s300, fabs(ex3[i]));
    CHECK_MSG(e300 <= 1e-13 * s300, "%.3g", e300 / s300);
    cm_rbf_tree_destroy(&t);
    free(x), free(c), free(w), free(p), free(exc), free(Sc), free(exp_), free(Sp), free(aw);
    free(fast), free(ex3), free(w3);
}

/* Real weights (an RBF fit of the bore motion): the bound holds all the same, relative to
 * sum |w| phi, and the cancellation makes the error relative to the result that much
 * larger. */
/* The compensated levels (cm_rbf_tree_set_compensated) on real, cancelling weights: each
 * within the bound, the levels the same sums to rounding of sum |w| phi; with all sums
 * direct (order 14: no cluster but the root has proxies, and the centres never see the
 * root as far) level 1 is the compensated direct sum, to a relative 1e-13 of the result,
 * where plain accumulation errs by more. */
static void test_compensated(const cm_rbf *r)
{
    if (!cm_rbf_isa_supported(CM_RBF_ISA_AVX512)) {
        printf("no AVX-512 here: compensated tree sums not run (they fall back to plain)\n");
        return;
    }
    const size_t m = r->m;
    double *out[3], *ex = malloc(3 * m * sizeof *ex), *S = malloc(3 * m * sizeof *S);
    double *aw = malloc(3 * m * sizeof *aw);
    for (int k = 0; k < 3; ++k) out[k] = malloc(3 * m * sizeof(double));
    cm_rbf_kernel_sum_acc(m, r->c, r->w, 3, m, r->c, m, ex, 3, 2);
    for (size_t j = 0; j < 3 * m; ++j) aw[j] = fabs(r->w[j]);
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, r->c, aw, 3, m, r->c, m, S, 3, 2);
    double smax = 0.0, emax = 0.0;
    for (size_t i = 0; i < 3 * m; ++i) smax = fmax(smax, S[i]), emax = fmax(emax, fabs(ex[i]));
    for (int pass = 0; pass < 2; ++pass) {
        const double tol = pass == 0 ? 1e-6 : 1e-14;
        int order = 14;
        double theta = 0.35;
        if (pass == 0) cm_rbf_tree_params(tol, &order, &theta);
        cm_rbf_tree *t = cm_rbf_tree_create(m, r->c, order, theta);
        CHECK(t != NULL);
        if (!t) break;
        double err[3], dev = 0.0;
        for (int k = 0; k < 3; ++k) {
            cm_rbf_tree_set_compensated(t, k);
            CHECK(cm_rbf_tree_sum_self(t, r->w, 3, out[k], 3, 2) == 0);
            err[k] = 0.0;
            for (size_t i = 0; i < 3 * m; ++i) {
                err[k] = fmax(err[k], fabs(out[k][i] - ex[i]) / S[i]);
                if (k) dev = fmax(dev, fabs(out[k][i] - out[0][i]));
            }
        }
        double e1 = 0.0, e0 = 0.0;
        for (size_t i = 0; i < 3 * m; ++i) {
            e0 = fmax(e0, fabs(out[0][i] - ex[i]));
            e1 = fmax(e1, fabs(out[1][i] - ex[i]));
        }
        printf("compensated levels, order %d theta %.2f: err / sum|w|phi %.3g %.3g %.3g, "
               "levels vs plain %.3g of max sum|w|phi; err / max result plain %.3g, "
               "level 1 %.3g\n", order, theta, err[0], err[1], err[2], dev / smax, e0 / emax,
               e1 / emax);
        for (int k = 0; k < 3; ++k) CHECK_MSG(err[k] <= (pass ? 1e-14 : tol), "%.3g", err[k]);
        CHECK_MSG(dev <= 1e-13 * smax, "%.3g", dev / smax);
        if (pass == 1) {
            CHECK_MSG(e1 <= 1e-13 * emax, "%.3g", e1 / emax);
            CHECK_MSG(e1 < e0, "%.3g vs %.3g", e1, e0);
        }
        cm_rbf_tree_destroy(&t);
    }
    for (int k = 0; k < 3; ++k) free(out[k]);
    free(ex), free(S), free(aw);
}

static void test_bound_real(cm_context *ctx)
{
    size_t m;
    double *x = bore_centres(0.076, &m); /* ~5k centres */
    double *d = malloc(m * 3 * sizeof *d);
    bore_motion(m, x, 2.0, 1.0, d);
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_DENSE;
    cm_rbf *r = NULL;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_OK);
    CHECK(cm_rbf_solve(ctx, r, 3, d) == CM_OK);
    const double tols[] = {1e-6, 1e-10};
    for (int k = 0; k < 2; ++k) {
        int order;
        double theta, cancel;
        cm_rbf_tree_params(tols[k], &order, &theta);
        cm_rbf_tree *t = cm_rbf_tree_create(r->m, r->c, order, theta);
        double rs = bound_ratio(t, r->m, r->c, r->w, 3, r->m, r->c, 1, &cancel);
        printf("real weights, m = %zu, tol %.0e: max err / sum|w|phi = %.3g, cancellation "
               "(max sum|w|phi / max|A w|) %.3g\n", r->m, tols[k], rs, cancel);
        CHECK_MSG(rs <= tols[k], "%.3g > %.3g", rs, tols[k]);
        CHECK_MSG(cancel > 10.0, "%.3g", cancel); /* the weights do cancel */
        cm_rbf_tree_destroy(&t);
    }
    test_compensated(r);
    cm_rbf_destroy(&r);
    free(x), free(d);
}

static cm_status fit_eval(cm_context *ctx, const cm_rbf_options *o, const cm_rbf_tuning *tun, size_t m, const double *x,
                          const double *d, size_t np, const double *p, double *out,
                          cm_rbf_stats *st)
{
    cm_rbf *r = NULL;
    cm_status s = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, o, tun, &r);
    if (s == CM_OK) s = cm_rbf_solve(ctx, r, 3, d);
    if (s == CM_OK) s = cm_rbf_evaluate(ctx, r, np, p, out);
    if (r) cm_rbf_get_stats(r, st);
    cm_rbf_destroy(&r);
    return s;
}

/* Iterative fits with fast matvecs (and refinement) against direct matvecs and dense. */
static void test_fit(cm_context *ctx)
{
    size_t m;
    double *x = bore_centres(0.076, &m);
    double *d = malloc(m * 3 * sizeof *d);
    bore_motion(m, x, 2.0, 1.0, d);
    const size_t nin = 4000, np = m + nin;
    double *p = malloc(np * 3 * sizeof *p);
    memcpy(p, x, m * 3 * sizeof *p);
    uint64_t rng = 11;
    for (size_t i = 0; i < nin; ++i) {
        p[3 * (m + i)] = test_rng_range(&rng, 0.1, 3.9);
        p[3 * (m + i) + 1] = test_rng_range(&rng, 0.1, 0.5);
        p[3 * (m + i) + 2] = test_rng_range(&rng, 0.1, 0.9);
    }
    double *sf = malloc(np * 3 * sizeof *sf), *sd = malloc(np * 3 * sizeof *sd);
    double *sn = malloc(np * 3 * sizeof *sn);
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    o.fast_sum = 0;
    cm_rbf_stats a, b, dn;
    cm_status s0 = fit_eval(ctx, &o, &tun, m, x, d, np, p, sd, &a);
    o.fast_sum = 1;
    cm_status s1 = fit_eval(ctx, &o, &tun, m, x, d, np, p, sf, &b);
    o.solver = CM_RBF_SOLVER_DENSE;
    cm_status s2 = fit_eval(ctx, &o, &tun, m, x, d, np, p, sn, &dn);
    CHECK_MSG(s0 == CM_OK && s1 == CM_OK && s2 == CM_OK, "%d %d %d: %s", s0, s1, s2,
              cm_context_message(ctx));
    const double range = range_of(m * 3, d);
    double agree = max_diff(np * 3, sf, sd) / range, vsd = max_diff(np * 3, sf, sn) / range;
    double exact = max_diff(m * 3, sf, d) / range;
    printf("fit m = %zu: fast %d iterations, %d refinements, residual after the first solve "
           "%.3g, final %.3g; direct %d iterations; |fast - direct| = %.3g, |fast - dense| = "
           "%.3g (dense residual %.3g), exact at the centres %.3g of the range\n",
           m, b.iterations, b.refinements, b.fast_residual, b.residual, a.iterations, agree,
           vsd, dn.residual, exact);
    CHECK(b.fast_sum == 1 && a.fast_sum == 0 && b.fast_direct == 0);
    CHECK_MSG(b.refinements >= 1 && b.refinements <= 3, "%d", b.refinements);
    CHECK_MSG(b.residual <= 1e-10, "%.3g", b.residual);
    CHECK_MSG(agree <= 1e-9, "%.3g", agree);
    CHECK_MSG(vsd <= fmax(1e-9, 3.0 * dn.residual), "%.3g", vsd);
    CHECK_MSG(exact <= 1e-9, "%.3g", exact);
    /* a treecode far too loose for the corrections (as at 121k on two bodies far apart at
     * 1e-12): the fast steps stop short, and the solve is done again with direct products */
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    tun.fast_tol = 1e-3;
    cm_rbf_stats e;
    cm_status s4 = fit_eval(ctx, &o, &tun, m, x, d, np, p, sf, &e);
    agree = max_diff(np * 3, sf, sd) / range;
    printf("fast_tol 1e-3: %d refinements, residual after the first %.3g, direct step %d, "
           "final %.3g, |fast - direct| = %.3g\n", e.refinements, e.fast_residual,
           e.fast_direct, e.residual, agree);
    CHECK_MSG(s4 == CM_OK, "%d: %s", s4, cm_context_message(ctx));
    CHECK_MSG(e.fast_direct == 1 && e.fast_residual > 1e-10, "%d %.3g", e.fast_direct,
              e.fast_residual);
    CHECK_MSG(e.residual <= 1e-10, "%.3g", e.residual);
    CHECK_MSG(agree <= 1e-9, "%.3g", agree);
    /* a loose tolerance: the refinement's residual by plain sums (the compensated ones only
     * where plain sums could err by 10 % of the tolerance), the result still within it at
     * the centres by the compensated sums of cm_rbf_evaluate */
    tun.fast_tol = 1e-12;
    o.tolerance = 1e-5;
    cm_rbf_stats l;
    cm_status s5 = fit_eval(ctx, &o, &tun, m, x, d, np, p, sf, &l);
    double dmax = 0.0;
    for (size_t i = 0; i < m * 3; ++i) dmax = fmax(dmax, fabs(d[i]));
    exact = max_diff(m * 3, sf, d) / dmax;
    printf("tolerance 1e-5: %d refinements, products %d compensated + %d plain + %d fast, "
           "residual %.3g, floor %.3g, at the centres %.3g of max |d|\n", l.refinements,
           l.matvecs_compensated, l.matvecs_plain, l.matvecs_fast, l.residual, l.floor, exact);
    CHECK_MSG(s5 == CM_OK, "%d: %s", s5, cm_context_message(ctx));
    CHECK_MSG(l.matvecs_compensated == 0 && l.matvecs_plain >= 1, "%d %d",
              l.matvecs_compensated, l.matvecs_plain);
    CHECK_MSG(l.residual <= 1e-5 && exact <= 1e-5, "%.3g %.3g", l.residual, exact);
    o.tolerance = 1e-10;
    /* no refinement: the treecode's own residual, looser but reported as such */
    tun.fast_refine = 0;
    tun.fast_tol = 1e-6;
    cm_rbf_stats c;
    cm_status s3 = fit_eval(ctx, &o, &tun, m, x, d, np, p, sf, &c);
    printf("fast_tol 1e-6 without refinement: residual %.3g, |fast - direct| = %.3g\n",
           c.residual, max_diff(np * 3, sf, sd) / range);
    CHECK(s3 >= CM_OK && c.refinements == 0);
    CHECK_MSG(max_diff(np * 3, sf, sd) / range <= 1e-2, "%.3g", max_diff(np * 3, sf, sd) / range);
    free(x), free(d), free(p), free(sf), free(sd), free(sn);
}

/* Affine data: reproduced exactly with fast matvecs (the weights are zero). */
static void test_affine(cm_context *ctx)
{
    size_t m;
    double *x = bore_centres(0.1, &m);
    double *d = malloc(m * 3 * sizeof *d), *out = malloc(m * 3 * sizeof *out);
    for (size_t i = 0; i < m; ++i) {
        d[3 * i] = 1.0 + 0.5 * x[3 * i] - 0.25 * x[3 * i + 2];
        d[3 * i + 1] = -2.0 + x[3 * i + 1];
        d[3 * i + 2] = 0.125 * x[3 * i] + 0.375 * x[3 * i + 1];
    }
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    o.fast_sum = 1;
    cm_rbf_stats st;
    cm_status s = fit_eval(ctx, &o, &tun, m, x, d, m, x, out, &st);
    double err = max_diff(m * 3, out, d);
    printf("affine data with fast sums: max error %.3g\n", err);
    CHECK(s == CM_OK);
    CHECK_MSG(err <= 1e-12, "%.3g", err);
    free(x), free(d), free(out);
}

/* Evaluation: fast when its estimated error is within fast_eval_tol x max |data|, else
 * direct; the result within that tolerance of the direct one either way. Widely spaced
 * centres with a smooth field cancel little (fast accepted), the bore set cancels more. */
static void test_evaluation(cm_context *ctx)
{
    uint64_t rng = 5;
    for (int set = 0; set < 2; ++set) {
        size_t m;
        double *x, *d;
        if (set == 0) {
            m = 3000;
            x = malloc(m * 3 * sizeof *x);
            for (size_t i = 0; i < 3 * m; ++i) x[i] = test_rng_range(&rng, 0.0, 1.0);
        } else {
            x = bore_centres(0.1, &m);
        }
        d = malloc(m * 3 * sizeof *d);
        for (size_t i = 0; i < m; ++i)
            for (int e = 0; e < 3; ++e)
                d[3 * i + e] = 0.01 * sin(1.0 + e + x[3 * i]) * cos(x[3 * i + 1] - 0.5 * x[3 * i + 2]);
        if (set == 1) bore_motion(m, x, 2.0, 1.0, d);
        const size_t n = 10000;
        double *p = malloc(n * 3 * sizeof *p), *a = malloc(n * 3 * sizeof *a);
        double *b = malloc(n * 3 * sizeof *b);
        for (size_t i = 0; i < n; ++i)
            for (int e = 0; e < 3; ++e) p[3 * i + e] = x[3 * (i % m) + e] * 0.97 + 0.01;
        cm_rbf_options o;
        cm_rbf_tuning tun;
        cm_rbf_options_init(&o);
        cm_rbf_tuning_init(&tun);
        o.solver = CM_RBF_SOLVER_ITERATIVE;
        o.fast_sum = 0;
        cm_rbf_stats sa, sb;
        cm_status s0 = fit_eval(ctx, &o, &tun, m, x, d, n, p, a, &sa);
        o.fast_sum = 1;
        cm_status s1 = fit_eval(ctx, &o, &tun, m, x, d, n, p, b, &sb);
        double dmax = 0.0;
        for (size_t i = 0; i < 3 * m; ++i) dmax = fmax(dmax, fabs(d[i]));
        double diff = max_diff(n * 3, a, b) / dmax;
        printf("evaluation, %s set, m = %zu: fast %s (estimated error %.3g of max |d|, "
               "order %d, theta %.2f), |fast - direct| = %.3g of max |d|\n",
               set ? "bore" : "random", m, sb.eval_fast ? "accepted" : "refused",
               sb.eval_error, sb.eval_order, sb.eval_theta, diff);
        CHECK(s0 == CM_OK && s1 == CM_OK && sa.eval_fast == 0);
        CHECK_MSG(diff <= 1e-9 + 3e-10, "%.3g", diff); /* + the two solves' difference */
        if (sb.eval_fast) CHECK_MSG(sb.eval_error <= 1e-9, "%.3g", sb.eval_error);
        if (set == 0) CHECK_MSG(sb.eval_fast == 1, "smooth set: fast refused (%.3g)", sb.eval_error);
        if (set == 1) {
            /* a tolerance below what any sum in doubles reaches: the fast sum is taken only
             * within the direct sums' own rounding (about 4 eps sum |w| phi, 1e-12 of max
             * |d| here with the weights' 2e4-fold cancellation), else refused */
            tun.fast_eval_tol = 1e-17;
            cm_status s2 = fit_eval(ctx, &o, &tun, m, x, d, n, p, b, &sb);
            double d2 = max_diff(n * 3, a, b) / dmax;
            printf("fast_eval_tol 1e-17: fast %s (estimate %.3g), |result - direct| = %.3g\n",
                   sb.eval_fast ? "accepted" : "refused", sb.eval_error, d2);
            CHECK(s2 == CM_OK && sb.eval_error > 1e-17);
            CHECK_MSG(sb.eval_fast == 0 || sb.eval_error <= 1e-11, "%.3g", sb.eval_error);
            CHECK_MSG(d2 <= 3e-10, "%.3g", d2);
        }
        free(x), free(d), free(p), free(a), free(b);
    }
}

static void test_options(cm_context *ctx)
{
    size_t m;
    double *x = bore_centres(0.2, &m);
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    CHECK(o.fast_sum == -1 && tun.fast_tol == 1e-12 && tun.fast_refine == 3 && tun.fast_eval_tol == 1e-9);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    cm_rbf *r = NULL;
    tun.fast_tol = 0.0;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT);
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    o.fast_sum = 2;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT);
    CHECK(r == NULL);
    /* the table: finer tolerances never give a lower order or a wider angle */
    int prev_n = 0;
    double prev_t = 1.0;
    for (double tol = 1e-3; tol >= 1e-14; tol *= 0.1) {
        int n;
        double th;
        cm_rbf_tree_params(tol, &n, &th);
        CHECK(n >= prev_n && th <= prev_t);
        prev_n = n, prev_t = th;
    }
    free(x);
}

/* The products' code: every ISA this CPU runs (the hand-written AVX-512 block of the direct
 * sums, its compiled predecessor, AVX2, baseline) gives the same sums to rounding on the
 * same tree, and each is within the bound; targets not a multiple of the register block
 * (batches end in a tail of 1..3 vectors) and 1..4 components. */
static void test_isa(void)
{
    size_t m;
    double *x = bore_centres(0.08, &m); /* ~4.5k centres */
    double *c = malloc(3 * m * sizeof *c), *w = malloc(4 * m * sizeof *w);
    for (size_t i = 0; i < m; ++i)
        for (int d = 0; d < 3; ++d) c[(size_t)d * m + i] = x[3 * i + d] / 4.0;
    uint64_t rng = 11;
    for (size_t i = 0; i < 4 * m; ++i) w[i] = test_rng_range(&rng, -1.0, 1.0);
    const size_t n = 1001;
    double *p = malloc(3 * n * sizeof *p);
    for (size_t i = 0; i < n; ++i) {
        p[i] = test_rng_range(&rng, 0.0, 1.0);
        p[n + i] = test_rng_range(&rng, 0.0, 0.5);
        p[2 * n + i] = test_rng_range(&rng, 0.0, 0.25);
    }
    double *ex = malloc(4 * n * sizeof *ex), *S = malloc(4 * n * sizeof *S);
    double *aw = malloc(4 * m * sizeof *aw), *ref = malloc(4 * n * sizeof *ref);
    double *out = malloc(4 * (m > n ? m : n) * sizeof *out), *refs = malloc(4 * m * sizeof *refs);
    for (size_t j = 0; j < 4 * m; ++j) aw[j] = fabs(w[j]);
    cm_rbf_kernel_sum_acc(m, c, w, 4, n, p, n, ex, 4, 2);
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, aw, 4, n, p, n, S, 4, 2);
    double smax = 0.0;
    for (size_t i = 0; i < 4 * n; ++i) smax = fmax(smax, S[i]);
    const cm_rbf_isa isas[] = {CM_RBF_ISA_GENERIC, CM_RBF_ISA_AVX2, CM_RBF_ISA_AVX512_AUTOVEC,
                               CM_RBF_ISA_AVX512};
    const double tol = 1e-6; /* order 5: proxies for clusters of > 216 centres */
    int order;
    double theta;
    cm_rbf_tree_params(tol, &order, &theta);
    cm_rbf_tree *t = cm_rbf_tree_create(m, c, order, theta);
    CHECK(t != NULL);
    int ran = 0;
    for (int nc = 1; t && nc <= 4; nc += 3) {
        for (int k = 0; k < 4; ++k) {
            if (!cm_rbf_isa_supported(isas[k])) continue;
            cm_rbf_tree_set_isa(t, isas[k]);
            CHECK(cm_rbf_tree_sum(t, w, nc, n, p, n, out, (size_t)nc, 2) == 0);
            double rs = ratio4(out, nc, n, ex, S), dev = 0.0;
            if (k == 0) memcpy(ref, out, n * (size_t)nc * sizeof *ref);
            for (size_t i = 0; i < n * (size_t)nc; ++i) dev = fmax(dev, fabs(out[i] - ref[i]));
            CHECK(cm_rbf_tree_sum_self(t, w, nc, out, (size_t)nc, 2) == 0);
            if (k == 0) memcpy(refs, out, m * (size_t)nc * sizeof *refs);
            for (size_t i = 0; i < m * (size_t)nc; ++i) dev = fmax(dev, fabs(out[i] - refs[i]));
            printf("isa %d, %d components: max err / sum|w|phi = %.3g, vs baseline %.3g of "
                   "max sum|w|phi\n", (int)isas[k], nc, rs, dev / smax);
            CHECK_MSG(rs <= tol, "isa %d: %.3g > %.3g", (int)isas[k], rs, tol);
            CHECK_MSG(rs > 1e-3 * tol, "isa %d: %.3g: far field unused?", (int)isas[k], rs);
            /* the same terms in the same order: only the last bits of each product differ
             * (FMA contraction, which sqrt unit) */
            CHECK_MSG(dev <= 1e-14 * smax, "isa %d: %.3g", (int)isas[k], dev / smax);
            ran += k == 3;
        }
    }
    /* AUTO is the hand-written block where the CPU has AVX-512 */
    if (t && cm_rbf_isa_supported(CM_RBF_ISA_AVX512)) {
        double *o2 = malloc(4 * n * sizeof *o2);
        cm_rbf_tree_set_isa(t, CM_RBF_ISA_AVX512);
        CHECK(cm_rbf_tree_sum(t, w, 4, n, p, n, out, 4, 2) == 0);
        cm_rbf_tree_set_isa(t, CM_RBF_ISA_AUTO);
        CHECK(cm_rbf_tree_sum(t, w, 4, n, p, n, o2, 4, 2) == 0);
        CHECK(memcmp(out, o2, 4 * n * sizeof *o2) == 0);
        free(o2);
        CHECK(ran == 2);
    } else {
        printf("no AVX-512 here: the hand-written path was not run\n");
    }
    cm_rbf_tree_destroy(&t);
    free(x), free(c), free(w), free(p), free(ex), free(S), free(aw), free(ref), free(out);
    free(refs);
}

static void log_stderr(void *user, cm_log_level level, const char *message)
{
    (void)user;
    (void)level;
    fprintf(stderr, "%s\n", message);
}

/* A pilot over every k-th batch of targets gives, at its points, exactly the sums of the
 * whole evaluation (the same batches open the same clusters), and touches no other target:
 * so its error there is the error the whole sum will have. */
static void test_pilot(void)
{
    size_t m;
    double *x = bore_centres(0.08, &m);
    double *c = malloc(3 * m * sizeof *c), *w = malloc(3 * m * sizeof *w);
    for (size_t i = 0; i < m; ++i)
        for (int d = 0; d < 3; ++d) c[(size_t)d * m + i] = x[3 * i + d] / 4.0;
    uint64_t rng = 17;
    for (size_t i = 0; i < 3 * m; ++i) w[i] = test_rng_range(&rng, -1.0, 1.0);
    const size_t n = 20000, batches = 8, per = 5;
    double *p = malloc(3 * n * sizeof *p), *all = malloc(3 * n * sizeof *all);
    double *pil = malloc(3 * n * sizeof *pil);
    size_t idx[8 * 5], stride = 0;
    for (size_t i = 0; i < n; ++i) {
        p[i] = test_rng_range(&rng, 0.0, 1.0);
        p[n + i] = test_rng_range(&rng, 0.0, 0.5);
        p[2 * n + i] = test_rng_range(&rng, 0.0, 0.25);
    }
    int order;
    double theta;
    cm_rbf_tree_params(1e-9, &order, &theta);
    cm_rbf_tree *t = cm_rbf_tree_create(m, c, order, theta);
    cm_rbf_tree_targets *tg = cm_rbf_tree_targets_create(n, p, n);
    CHECK(t && tg);
    if (t && tg) {
        for (size_t i = 0; i < 3 * n; ++i) pil[i] = NAN;
        size_t np = cm_rbf_tree_targets_pilot(tg, batches, per, idx, &stride);
        CHECK(cm_rbf_tree_sum_targets(t, tg, 1, w, 3, all, 3, 2) == 0);
        CHECK(cm_rbf_tree_sum_targets(t, tg, stride, w, 3, pil, 3, 2) == 0);
        size_t same = 0, touched = 0;
        for (size_t k = 0; k < np; ++k)
            same += memcmp(all + 3 * idx[k], pil + 3 * idx[k], 3 * sizeof *all) == 0;
        for (size_t i = 0; i < n; ++i) touched += !isnan(pil[3 * i]);
        printf("pilot: %zu of %zu targets summed (stride %zu), %zu of %zu checked points as "
               "in the whole sum\n", touched, n, stride, same, np);
        CHECK(np > batches / 2 && np <= batches * per && stride > 1);
        CHECK(same == np);
        /* about batches / (n / batch) of the targets; a whole sum would be n */
        CHECK_MSG(touched >= np && touched <= n / 4, "%zu", touched);
    }
    cm_rbf_tree_targets_destroy(&tg);
    cm_rbf_tree_destroy(&t);
    free(x), free(c), free(w), free(p), free(all), free(pil);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    if (getenv("CM_TEST_VERBOSE")) cm_context_set_log(ctx, log_stderr, NULL);
    cm_context_set_threads(ctx, 2);
    test_bound_random();
    test_isa();
    test_pilot();
    test_bound_real(ctx);
    test_fit(ctx);
    test_affine(ctx);
    test_evaluation(ctx);
    test_options(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
