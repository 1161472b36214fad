/* Tests of the iterative RBF solver (FGMRES + two-level restricted Schwarz): agreement with
 * the dense solver on a box-with-bore boundary set, affine data, two bodies far apart,
 * thread-count independence, plain evaluation at a loose tolerance, the solver choice and the
 * option checks. */
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "rbf_tuning.h"
#include "rbf_test_sets.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Fits values on x with the given options and evaluates at p (np points). */
static cm_status fit_eval_opt(cm_context *ctx, const cm_rbf_options *opt, const cm_rbf_tuning *tun, size_t m,
                              const double *x, const double *val, size_t np, const double *p,
                              double *out, cm_rbf_stats *stats)
{
    cm_rbf_options o = *opt;
    cm_rbf *r = NULL;
    cm_status st = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, tun, &r);
    if (st == CM_OK) st = cm_rbf_solve(ctx, r, 3, val);
    if (st == CM_OK) st = cm_rbf_evaluate(ctx, r, np, p, out);
    if (r) cm_rbf_get_stats(r, stats);
    cm_rbf_destroy(&r);
    return st;
}

static cm_status fit_eval(cm_context *ctx, cm_rbf_solver solver, size_t m, const double *x,
                          const double *val, size_t np, const double *p, double *out,
                          cm_rbf_stats *stats)
{
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = solver;
    return fit_eval_opt(ctx, &o, &tun, m, x, val, np, p, out, stats);
}


/* The box-with-bore set at m ~ 5k: iterative vs dense at the centres and inside, then the
 * iterative fit again on one thread. */
static void test_against_dense(cm_context *ctx)
{
    const double off[3] = {10.0, -3.0, 2.0};
    size_t m = box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.076, off, NULL);
    double *x = malloc(m * 3 * sizeof *x), *d = malloc(m * 3 * sizeof *d);
    box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.076, off, x);
    double *xl = malloc(m * 3 * sizeof *xl);
    for (size_t i = 0; i < m; ++i)
        for (int e = 0; e < 3; ++e) xl[3 * i + e] = x[3 * i + e] - off[e];
    bore_motion(m, xl, 2.0, 1.0, d);
    free(xl);
    size_t np;
    double *p = eval_points(m, x, 2000, 0.3, &np);
    for (size_t i = m; i < np; ++i)
        for (int e = 0; e < 3; ++e) p[3 * i + e] += off[e];
    double *sd = malloc(np * 3 * sizeof *sd), *si = malloc(np * 3 * sizeof *si);
    double *s1 = malloc(np * 3 * sizeof *s1);
    cm_rbf_stats std, sti, st1;
    cm_status a = fit_eval(ctx, CM_RBF_SOLVER_DENSE, m, x, d, np, p, sd, &std);
    cm_status b = fit_eval(ctx, CM_RBF_SOLVER_ITERATIVE, m, x, d, np, p, si, &sti);
    CHECK_MSG(a == CM_OK && b == CM_OK, "dense %d iterative %d: %s", a, b, cm_context_message(ctx));
    double range = fmax(range_of(m * 3, d), 1e-300);
    double diff = max_diff(np * 3, sd, si) / range;
    double tol = fmax(1e-9, 3.0 * std.residual);
    printf("box with bore: m = %zu, iterative %d iterations, %d subdomains, coarse %d, "
           "residual %.3g (dense %.3g), floor %.3g, |iterative - dense| = %.3g of the range\n",
           m, sti.iterations, sti.subdomains, sti.coarse_size, sti.residual, std.residual,
           sti.floor, diff);
    CHECK(m > 4000 && m < 7000);
    CHECK(std.solver == CM_RBF_SOLVER_DENSE && sti.solver == CM_RBF_SOLVER_ITERATIVE);
    CHECK_MSG(diff <= tol, "%.3g > %.3g", diff, tol);
    CHECK_MSG(sti.residual <= fmax(1e-10, sti.floor), "%.3g", sti.residual);
    /* exactness at the centres, measured here independently of the solver's own figure */
    CHECK_MSG(max_diff(m * 3, si, d) / range <= 1e-9, "%.3g", max_diff(m * 3, si, d) / range);
    CHECK_MSG(sti.iterations >= 1 && sti.iterations <= 25, "%d iterations", sti.iterations);
    CHECK(sti.subdomains > 10 && sti.memory_bytes > 0 && sti.matvecs >= sti.iterations);

    /* relaxed products (the default, relax = 1: plain sums as the residual falls; 2: the
     * loose treecode too, which the default uses from 5e4 centres) against none: the same
     * interpolant, the exact residual within the tolerance, fewer compensated products */
    {
        cm_rbf_stats sr[2];
        double *sx = malloc(np * 3 * sizeof *sx);
        cm_status sts[2];
        for (int v = 0; v < 2; ++v) {
            cm_rbf_options o;
            cm_rbf_tuning tun;
            cm_rbf_options_init(&o);
            cm_rbf_tuning_init(&tun);
            o.solver = CM_RBF_SOLVER_ITERATIVE;
            tun.relax = v == 0 ? 0 : 2;
            sts[v] = fit_eval_opt(ctx, &o, &tun, m, x, d, np, p, v == 0 ? s1 : sx, &sr[v]);
        }
        double d0 = max_diff(np * 3, s1, sd) / range, d2 = max_diff(np * 3, sx, sd) / range;
        printf("relax 0: %d iterations, %d compensated + %d plain + %d fast products, residual "
               "%.3g, |. - dense| %.3g; relax 1: %d + %d + %d; relax 2: %d iterations, "
               "%d + %d + %d, residual %.3g, |. - dense| %.3g\n", sr[0].iterations,
               sr[0].matvecs_compensated, sr[0].matvecs_plain, sr[0].matvecs_fast,
               sr[0].residual, d0, sti.matvecs_compensated, sti.matvecs_plain, sti.matvecs_fast,
               sr[1].iterations, sr[1].matvecs_compensated, sr[1].matvecs_plain,
               sr[1].matvecs_fast, sr[1].residual, d2);
        CHECK(sts[0] == CM_OK && sts[1] == CM_OK);
        CHECK_MSG(d0 <= tol && d2 <= tol, "%.3g %.3g > %.3g", d0, d2, tol);
        CHECK_MSG(sr[1].residual <= 1e-10 && sti.residual <= 1e-10, "%.3g %.3g",
                  sr[1].residual, sti.residual);
        for (int v = 0; v < 2; ++v)
            CHECK(sr[v].matvecs == sr[v].matvecs_compensated + sr[v].matvecs_plain +
                                   sr[v].matvecs_fast);
        CHECK(sti.matvecs == sti.matvecs_compensated + sti.matvecs_plain + sti.matvecs_fast);
        /* without relaxation only the cycle ends' low-part and floor sums are plain */
        CHECK(sr[0].matvecs_fast == 0 && sr[0].matvecs_compensated >= sr[0].iterations);
        /* each cycle relaxes to its own goal (the first one's is far above the tolerance):
         * fewer than half the compensated products of the unrelaxed solve (bore 5k: 2 of 8;
         * 4 when the first cycle aimed at the final tolerance too) */
        CHECK_MSG(2 * sti.matvecs_compensated < sr[0].matvecs_compensated &&
                      sti.matvecs_fast == 0,
                  "relax 1: %d compensated, relax 0: %d", sti.matvecs_compensated,
                  sr[0].matvecs_compensated);
        CHECK_MSG(sr[1].matvecs_fast >= 1 &&
                  sr[1].matvecs_compensated < sr[0].matvecs_compensated, "relax 2: %d fast",
                  sr[1].matvecs_fast);
        free(sx);
    }

    /* one thread: same result within the tolerance */
    cm_context_set_threads(ctx, 1);
    cm_status c = fit_eval(ctx, CM_RBF_SOLVER_ITERATIVE, m, x, d, np, p, s1, &st1);
    cm_context_set_threads(ctx, 2);
    double dt = max_diff(np * 3, s1, si) / range;
    printf("threads 1 vs 2: %.3g of the range (%d vs %d iterations)\n", dt, st1.iterations,
           sti.iterations);
    CHECK(c == CM_OK);
    CHECK_MSG(dt <= 1e-9, "%.3g", dt);

    /* the variants of the preconditioner converge to the same interpolant: the coarse
     * correction before the local solves only (the default is before and after), after
     * them only, and subdomains grown by a distance (twice the coarse fill distance, capped
     * at 2000) with a sparser coarse space (300: then the distance reaches beyond the 1400
     * nearest) */
    for (int v = 0; v < 3; ++v) {
        cm_rbf_options o;
        cm_rbf_tuning tun;
        cm_rbf_options_init(&o);
        cm_rbf_tuning_init(&tun);
        o.solver = CM_RBF_SOLVER_ITERATIVE;
        if (v == 0) tun.coarse_post = 0;
        if (v == 1) tun.coarse_post = 2;
        if (v == 2) {
            tun.overlap = 2.0;
            tun.local_max = 2000;
            tun.coarse_size = 300;
        }
        cm_rbf_stats sv;
        cm_status e = fit_eval_opt(ctx, &o, &tun, m, x, d, np, p, s1, &sv);
        double dv = max_diff(np * 3, s1, sd) / range;
        printf("variant %d: %d iterations, coarse %d, residual %.3g, |variant - dense| = %.3g "
               "of the range\n", v, sv.iterations, sv.coarse_size, sv.residual, dv);
        CHECK_MSG(e == CM_OK, "variant %d: %s", v, cm_context_message(ctx));
        CHECK_MSG(dv <= tol, "variant %d: %.3g > %.3g", v, dv, tol);
        CHECK_MSG(sv.iterations >= 1 && sv.iterations <= 40, "variant %d: %d", v, sv.iterations);
        if (v == 2) CHECK_MSG(sv.coarse_size == 300, "%d", sv.coarse_size);
    }
    free(x), free(d), free(p), free(sd), free(si), free(s1);
}

/* Affine data lie in the polynomial space: the weights are zero and the fit is exact. */
static void test_affine(cm_context *ctx)
{
    const double off[3] = {0.0, 0.0, 0.0};
    size_t m = box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.11, off, NULL);
    double *x = malloc(m * 3 * sizeof *x), *d = malloc(m * 3 * sizeof *d);
    box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.11, off, x);
    size_t np;
    double *p = eval_points(m, x, 500, 0.3, &np);
    double *ref = malloc(np * 3 * sizeof *ref), *out = malloc(np * 3 * sizeof *out);
    for (size_t i = 0; i < np; ++i)
        for (int e = 0; e < 3; ++e) {
            const double *y = p + 3 * i;
            double v = 0.3 * e - 1.0 + (1.0 + e) * y[0] - 0.5 * y[1] + 2.0 * e * y[2];
            ref[3 * i + e] = v;
            if (i < m) d[3 * i + e] = v;
        }
    cm_rbf_stats st;
    cm_status s = fit_eval(ctx, CM_RBF_SOLVER_ITERATIVE, m, x, d, np, p, out, &st);
    double err = max_diff(np * 3, out, ref) / range_of(np * 3, ref);
    printf("affine: m = %zu, error %.3g, %d iterations\n", m, err, st.iterations);
    CHECK(s == CM_OK);
    CHECK_MSG(err <= 1e-13, "%.3g", err);
    free(x), free(d), free(p), free(ref), free(out);
}

/* The storage of the local inverse rows (local_float 0 double, 1 float, 2 mixed): the same
 * interpolant to 1e-9 of the range, iterations within one, float smaller. */
static void test_storage(cm_context *ctx)
{
    double *x = NULL, *d = NULL;
    size_t m = bore_set(0.09, &x, &d);
    size_t np;
    double *p = eval_points(m, x, 500, 0.3, &np);
    double *out[3];
    cm_rbf_stats st[3];
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    const double range = range_of(m * 3, d);
    for (int f = 0; f < 3; ++f) {
        out[f] = malloc(np * 3 * sizeof *out[f]);
        tun.local_float = f;
        cm_status s = fit_eval_opt(ctx, &o, &tun, m, x, d, np, p, out[f], &st[f]);
        CHECK_MSG(s == CM_OK, "local_float %d: %s", f, cm_context_message(ctx));
        CHECK_MSG(st[f].residual <= o.tolerance, "local_float %d: %.3g", f, st[f].residual);
    }
    for (int f = 1; f < 3; ++f) {
        double diff = max_diff(np * 3, out[f], out[0]) / range;
        printf("storage: m = %zu, local_float %d vs double: %.3g of the range, %d vs %d "
               "iterations, %.1f vs %.1f MB\n",
               m, f, diff, st[f].iterations, st[0].iterations, st[f].memory_bytes / 1e6,
               st[0].memory_bytes / 1e6);
        CHECK_MSG(diff <= 1e-9, "local_float %d: %.3g", f, diff);
        CHECK(abs(st[f].iterations - st[0].iterations) <= 1);
        CHECK(st[f].memory_bytes < st[0].memory_bytes);
        free(out[f]);
    }
    free(out[0]);
    tun.local_float = 3;
    cm_rbf *bad = NULL;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &bad) == CM_ERR_ARGUMENT);
    CHECK(bad == NULL);
    free(x), free(d), free(p);
}

/* Counts the debug lines of Krylov cycles after the first (a restart): user is an int. */
static void count_restarts(void *user, cm_log_level level, const char *message)
{
    (void)level;
    const char *c = strstr(message, ", cycle ");
    if (c && strncmp(message, "cm_rbf_solve: column", 20) == 0 && atoi(c + 8) >= 2 &&
        strstr(c, "iterations"))
        ++*(int *)user;
}

/* A loose tolerance evaluates with plain sums (their rounding, a tenth of it at most, is all
 * the fit needs: rbf_evaluate.c), checks its residuals by plain sums, and still reproduces
 * the data to the tolerance; the default stays compensated. The scales that choice goes by are the forward solve's: a transposed
 * evaluation in between changes neither the choice nor a bit of the result. */
static void test_loose_evaluation(cm_context *ctx)
{
    double *x = NULL, *d = NULL;
    size_t m = bore_set(0.09, &x, &d), np;
    double *p = eval_points(m, x, 500, 0.3, &np);
    double *out = malloc(np * 3 * sizeof *out), *again = malloc(np * 3 * sizeof *again);
    double *ref = malloc(np * 3 * sizeof *ref), *v = malloc(np * 3 * sizeof *v);
    double *g = malloc(m * 3 * sizeof *g);
    for (size_t i = 0; i < np * 3; ++i) v[i] = sin(0.37 * (double)i);
    const double range = range_of(m * 3, d);
    cm_rbf_options o;
    cm_rbf_options_init(&o);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    cm_rbf_stats st0;
    cm_status s0 = fit_eval(ctx, CM_RBF_SOLVER_ITERATIVE, m, x, d, np, p, ref, &st0);
    o.tolerance = 1e-6;
    cm_rbf *r = NULL;
    cm_status s = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &r);
    /* the cold solve ends in its first cycle, where GMRES's own residual meets the
     * tolerance in the max-norm (a wrong estimate of it would end the cycle early and
     * restart) */
    int restarts = 0;
    cm_context *lc = NULL;
    if (s == CM_OK && cm_context_create(&lc) == CM_OK) {
        cm_context_set_threads(lc, 2);
        cm_context_set_log(lc, count_restarts, &restarts);
        s = cm_rbf_solve(lc, r, 3, d);
        cm_context_destroy(&lc);
    }
    if (s == CM_OK) s = cm_rbf_evaluate(ctx, r, np, p, out);
    cm_rbf_stats st;
    cm_rbf_get_stats(r, &st);
    CHECK_MSG(s0 == CM_OK && s == CM_OK, "%s", cm_context_message(ctx));
    const double at_centres = max_diff(m * 3, out, d) / range;
    const double to_exact = max_diff(np * 3, out, ref) / range;
    printf("loose evaluation: m = %zu, tolerance 1e-6: %s sums, residual %.3g, data missed by "
           "%.3g, %.3g from the 1e-10 fit (%s sums); floor %.3g; products compensated + plain "
           "%d + %d (1e-10: %d + %d)\n", m,
           st.eval_plain ? "plain" : "compensated", st.residual, at_centres, to_exact,
           st0.eval_plain ? "plain" : "compensated", st.floor, st.matvecs_compensated,
           st.matvecs_plain, st0.matvecs_compensated, st0.matvecs_plain);
    CHECK(st.eval_plain == 1 && st0.eval_plain == 0 && st.eval_fast == 0);
    CHECK_MSG(restarts == 0, "%d columns restarted", restarts);
    /* the exact residuals of a loose solve are plain sums too */
    CHECK_MSG(st.matvecs_compensated < st0.matvecs_compensated, "%d, 1e-10: %d",
              st.matvecs_compensated, st0.matvecs_compensated);
    CHECK_MSG(at_centres <= 1.1e-6, "%.3g", at_centres);
    /* the interior moves by about the tolerance x the motion, no more */
    CHECK_MSG(to_exact <= 1e-5, "%.3g", to_exact);
    if (s == CM_OK) s = cm_rbf_evaluate_transpose(ctx, r, np, p, 3, v, g);
    if (s == CM_OK) s = cm_rbf_evaluate(ctx, r, np, p, again);
    cm_rbf_get_stats(r, &st);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    CHECK(st.eval_plain == 1 && memcmp(out, again, np * 3 * sizeof *out) == 0);
    cm_rbf_destroy(&r);
    free(x), free(d), free(p), free(out), free(again), free(ref), free(v), free(g);
}

/* Two parts far apart (10 part sizes): the coarse space and the subdomains must not couple
 * them wrongly, and the null space is that of the whole set. */
static void test_two_bodies(cm_context *ctx)
{
    const double off0[3] = {0.0, 0.0, 0.0};
    const double off1[3] = {40.0, 15.0, -8.0};
    size_t m0 = box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.1, off0, NULL);
    size_t m1 = box_with_bore(3.0, 1.5, 1.0, 1.5, 0.75, 0.3, 0.1, off1, NULL);
    size_t m = m0 + m1;
    double *x = malloc(m * 3 * sizeof *x), *d = malloc(m * 3 * sizeof *d);
    box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.1, off0, x);
    box_with_bore(3.0, 1.5, 1.0, 1.5, 0.75, 0.3, 0.1, off1, x + 3 * m0);
    bore_motion(m0, x, 2.0, 1.0, d);
    for (size_t i = m0; i < m; ++i) { /* the second part moves rigidly, a little rotated */
        d[3 * i] = 0.2 - 0.01 * (x[3 * i + 1] - off1[1]);
        d[3 * i + 1] = 0.01 * (x[3 * i] - off1[0]);
        d[3 * i + 2] = 0.05;
    }
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    cm_rbf *r = NULL;
    cm_status s = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r);
    if (s == CM_OK) s = cm_rbf_solve(ctx, r, 3, d);
    cm_rbf_stats st;
    cm_rbf_get_stats(r, &st);
    double *out = malloc(m * 3 * sizeof *out);
    if (s == CM_OK) s = cm_rbf_evaluate(ctx, r, m, x, out);
    double err = s == CM_OK ? max_diff(m * 3, out, d) / range_of(m * 3, d) : 1.0;
    /* the dense solver on the same set: how far the system itself lets a solve go */
    double *dn = malloc(m * 3 * sizeof *dn);
    cm_rbf_stats sd;
    cm_status s2 = fit_eval(ctx, CM_RBF_SOLVER_DENSE, m, x, d, m, x, dn, &sd);
    double agree = max_diff(m * 3, out, dn) / range_of(m * 3, d);
    double derr = max_diff(m * 3, dn, d) / range_of(m * 3, d);
    printf("two bodies: m = %zu, %d iterations, residual %.3g (floor %.3g, at floor %d; dense "
           "%.3g), error at the centres %.3g (dense %.3g), vs dense %.3g\n",
           m, st.iterations, st.residual, st.floor, st.floor_limited, sd.residual, err, derr,
           agree);
    CHECK_MSG(s == CM_OK && s2 == CM_OK, "%s", cm_context_message(ctx));
    CHECK_MSG(st.residual <= 1e-10 && !st.floor_limited, "%.3g", st.residual);
    /* Far apart, the parts need sum |w| = 3e6 x max |d|: plain sums, as the dense path
     * evaluates, reproduce the data at the centres only to about eps times that (5.7e-9
     * measured, the floor in the stats); the iterative path evaluates with compensated sums
     * and is exact to its residual. */
    CHECK_MSG(err <= 1e-9, "%.3g (dense %.3g)", err, derr);
    CHECK_MSG(st.floor > 1e-10 && derr <= 10.0 * st.floor, "floor %.3g, dense %.3g", st.floor, derr);
    CHECK_MSG(agree <= fmax(1e-9, 3.0 * derr), "%.3g", agree);

    /* a second right-hand side on the same preconditioner (an absolute study): 2 d + affine */
    double *d2 = malloc(m * 3 * sizeof *d2), *out2 = malloc(m * 3 * sizeof *out2);
    for (size_t i = 0; i < m * 3; ++i) d2[i] = 2.0 * d[i] + 0.1 + 0.01 * x[i];
    cm_status s3 = cm_rbf_solve(ctx, r, 3, d2);
    if (s3 == CM_OK) s3 = cm_rbf_evaluate(ctx, r, m, x, out2);
    double err2 = s3 == CM_OK ? max_diff(m * 3, out2, d2) / range_of(m * 3, d2) : 1.0;
    printf("two bodies, second right-hand side: error at the centres %.3g\n", err2);
    CHECK_MSG(s3 == CM_OK && err2 <= 1e-9, "%.3g", err2);
    /* a loose tolerance at which plain sums are not exact enough here (their bound,
     * 1e-13 S(w) with S(w) = 2e7 max |d|, is 2e-6): the checks try them once, then stay
     * compensated; the evaluation stays compensated */
    cm_rbf *rl = NULL;
    o.tolerance = 1e-8;
    cm_status s4 = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &rl);
    if (s4 == CM_OK) s4 = cm_rbf_solve(ctx, rl, 3, d);
    if (s4 == CM_OK) s4 = cm_rbf_evaluate(ctx, rl, m, x, out2);
    cm_rbf_stats sl;
    cm_rbf_get_stats(rl, &sl);
    const double errl = s4 == CM_OK ? max_diff(m * 3, out2, d) / range_of(m * 3, d) : 1.0;
    printf("two bodies, tolerance 1e-8: residual %.3g, error at the centres %.3g, %s "
           "evaluation, %d iterations\n", sl.residual, errl,
           sl.eval_plain ? "plain" : "compensated", sl.iterations);
    CHECK_MSG(s4 == CM_OK && sl.residual <= 1e-8 && errl <= 1e-8, "%.3g %.3g", sl.residual,
              errl);
    CHECK(sl.eval_plain == 0);
    cm_rbf_destroy(&rl);
    free(d2), free(out2), free(dn);
    /* 5 since the local part keeps no linear moment on either body (rbf_bodies.c); 11 before */
    CHECK_MSG(st.iterations <= 8, "%d iterations", st.iterations);
    cm_rbf_destroy(&r);
    free(x), free(d), free(out);
}

/* AUTO: dense for small sets and other kernels; the iterative solver refuses other kernels
 * and bad options. */
static void test_choice(cm_context *ctx)
{
    const double off[3] = {0.0, 0.0, 0.0};
    size_t m = box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.2, off, NULL);
    double *x = malloc(m * 3 * sizeof *x);
    box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.2, off, x);
    cm_rbf *r = NULL;
    cm_rbf_stats st;
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &r) == CM_OK);
    cm_rbf_get_stats(r, &st);
    CHECK(st.solver == CM_RBF_SOLVER_DENSE && st.centres == m);
    cm_rbf_destroy(&r);
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_BIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_UNSUPPORTED);
    CHECK(r == NULL);
    o.tolerance = 0.0;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT);
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    tun.local_size = 8; /* smaller than the leaves */
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT);
    tun.local_size = 700;
    tun.coarse_post = 3;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT);
    tun.coarse_post = 0;
    tun.overlap = -1.0;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT);
    tun.overlap = 2.0;
    tun.relax = 3;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT);
    /* the cost model: dense at 2k, iterative at 20k (measured with subdomains of 700 and an
     * overlap of 2 H: the crossover near 3.5k, iterative 5x faster at 10k) */
    CHECK(cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 2000, 1) == 1);
    CHECK(cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 20000, 1) == 0);
    CHECK(cm_rbf_auto_dense(CM_RBF_BIHARMONIC, 20000, 1) == 1);
    /* the coarse space: 2000 up to 2e4 centres (m/4 below 8000), then grown as sqrt(m) up
     * to coarse_max */
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    CHECK(cm_rbf_coarse_count(&tun, 20000) == 2000 && cm_rbf_coarse_count(&tun, 6000) == 1500);
    CHECK(cm_rbf_coarse_count(&tun, 80000) == 4000 && cm_rbf_coarse_count(&tun, 1000000) == 14142);
    CHECK(cm_rbf_coarse_count(&tun, 2000000) == 16000);
    tun.coarse_max = 3000;
    CHECK(cm_rbf_coarse_count(&tun, 80000) == 3000);
    tun.coarse_grow = 0;
    CHECK(cm_rbf_coarse_count(&tun, 150000) == 2000);
    free(x);
}

/* CM_TEST_VERBOSE=1 shows the solver's debug log (iterations per restart cycle). */
static void log_stderr(void *user, cm_log_level level, const char *message)
{
    (void)user;
    (void)level;
    fprintf(stderr, "%s\n", message);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    if (getenv("CM_TEST_VERBOSE")) cm_context_set_log(ctx, log_stderr, NULL);
    cm_context_set_threads(ctx, 2);
    test_against_dense(ctx);
    test_affine(ctx);
    test_storage(ctx);
    test_loose_evaluation(ctx);
    test_two_bodies(ctx);
    test_choice(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
