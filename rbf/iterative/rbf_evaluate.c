/* Evaluation of an iterative fit: compensated direct sums, plain ones where the solve's
 * tolerance allows them, or the r^3 treecode where n x m is large and a sampled check (after
 * a pilot that may pick a cheaper treecode) shows its error within fast_eval_tol x max
 * |data|. */
#include "rbf_iter.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

/* fast_sum = -1 (auto): evaluation by the treecode from this many point-centre pairs */
#define CM_RBF_FAST_EVAL_PAIRS 2e9
/* samples for the a-posteriori error estimate of a fast evaluation, and the factor on the
 * largest sampled error (the sampled max was within it of the true max on the real sets).
 * The treecode's errors are spiky below its finest orders: over 32,768 of the two-body
 * interior points at order 10, every 256-point subset found at least 1/6.4 of their
 * largest error, every 1,024-point one 1/2.2 (RESULTS.md, RBF solvers); 1,024
 * compensated sums cost ~1 % of a 10^6-point evaluation */
#define CM_RBF_FAST_SAMPLES 1024
#define CM_RBF_FAST_SAFETY 4.0

/* Why compensated sums for evaluation too: the weights of large or spread sets are large
 * (sum |w| of 1e6..1e7 x max |d| on the bracket and on two bodies far apart), and plain sums
 * then reproduce the data at the centres only to eps sum |w_j phi_ij| (bracket, m = 59k:
 * 1e-7 of the range, although the residual is 6e-11). The dense path keeps plain sums: its
 * callers at m <= ~3,500 do not see that floor, and it is 2.4x faster.
 * A fit solved to a loose tolerance does not need them: plain sums are taken where their
 * rounding, at most CM_RBF_PLAIN_ERR x S_c(x) with S_c(x) = sum_j |w_cj| phi(|x - c_j|),
 * is within CM_RBF_PLAIN_RES_SHARE of the tolerance x the column's scale, for every column
 * (as the solve takes plain products for its exact residuals). S_c is convex in x (each
 * |x - c_j|^3 is), so over the convex hull of the centres, where a warp's interior nodes
 * lie, it is largest at a centre: the solve's smax (cm_rbf_scales). CM_RBF_FAST_SAMPLES
 * points spread over the others stand for any outside it. So with the default tolerance
 * (1e-10) the sums stay compensated (S_c is 1e4..1e9 x the data on real sets), and at 1e-6
 * (a study's --rbf-tol) they are plain on the bore (20.6k centres: S_c 6e4..6e5 x the data,
 * RESULTS.md, Study). */
/* Evaluation by the treecode if its error can be shown to be within fast_eval_tol x max
 * |data|: the order is chosen from sum_j |w_j| phi_ij at a few of the points (the scale of
 * its bound, which the cancellation of the weights makes 1e4..1e7 x the result), then the
 * fast result is checked against compensated direct sums at CM_RBF_FAST_SAMPLES points.
 * Those are exact for the rounded entries phi_ij, not for the true ones, so they err by up
 * to about CM_RBF_PHI_ROUND eps sum_j |w_j| phi_ij themselves: 7.8e-9 of max |d| on two
 * bodies at 1e6 points against a long-double reference, where the order-14 treecode errs by
 * 1.0e-9 (RESULTS.md, RBF solvers). The check cannot see below
 * that, and the fallback is no better, so the fast sum is accepted within the larger of
 * fast_eval_tol x max |data| and that floor; eval_error says which was met.
 *
 * The bound is relative to sum |w| phi at each point and is often far from the error on
 * real weights: on two bodies far apart (121k centres, 10^6 points) the row for 1e-12
 * erred no more than the finest (1.0e-16 x max sum |w| phi, the rounding floor) at 0.66x
 * its CPU, while on the bracket (60.6k) only the finest met the floor (RESULTS.md, RBF
 * solvers). So the row for CM_RBF_PILOT_GAIN x the asked tolerance is tried
 * first on a pilot, every k-th batch of targets (CM_RBF_PILOT_BATCHES of them: the same
 * batches as the whole sum, so the same clusters go by their proxies), and taken if its
 * error at CM_RBF_PILOT_PER points of each batch passes the check's test; the check itself
 * still decides, and a coarser row that fails it is followed by the asked one before
 * direct sums. The pilot costs about CM_RBF_PILOT_BATCHES / (n / 192) of a coarse sum
 * (bracket, 211k points: 3 %). 1 if out holds the accepted fast result; 0 (out undefined)
 * if direct sums must do it. */
#define CM_RBF_PILOT_GAIN 1e2
#define CM_RBF_PILOT_BATCHES 32
#define CM_RBF_PILOT_PER 16

/* The treecode sums of all components at the targets of every stride-th batch (1: all),
 * reported to tick (NULL: none) in whole sums. */
static int tree_sum_all(const cm_rbf *r, const cm_rbf_tree *t, const cm_rbf_tree_targets *tg,
                        size_t stride, double *out, int threads, cm_rbf_tick *tick)
{
    const size_t m = r->m, nc = (size_t)r->ncomp;
    for (size_t g = 0; g < nc; g += CM_RBF_SUM_MAX_NC) {
        int gc = nc - g < CM_RBF_SUM_MAX_NC ? (int)(nc - g) : CM_RBF_SUM_MAX_NC;
        if (cm_rbf_tree_sum_targets_tick(t, tg, stride, r->w + g * m, gc, out + g, nc, threads,
                                         tick))
            return -1;
    }
    return 0;
}

/* The largest error of the fast sums out (n x nc) against compensated direct sums at
 * `samples` of the targets (the indices idx, or NULL: spread over them), over all the
 * components. */
static double check_all(const cm_rbf *r, const cm_rbf_tree *t, size_t n, const double *p,
                        const double *out, size_t samples, const size_t *idx, int threads)
{
    const size_t m = r->m, nc = (size_t)r->ncomp;
    double err = 0.0;
    for (size_t g = 0; g < nc; g += CM_RBF_SUM_MAX_NC) {
        int gc = nc - g < CM_RBF_SUM_MAX_NC ? (int)(nc - g) : CM_RBF_SUM_MAX_NC;
        double e;
        cm_rbf_tree_check(t, r->w + g * m, gc, n, p, n, out + g, nc, samples, idx, &e, NULL,
                          threads);
        err = fmax(err, e);
    }
    return err;
}

/* 1 if the treecode t passes the pilot: its largest error at the pilot's points, x
 * CM_RBF_FAST_SAFETY, is within accept. out: n x nc scratch. */
static int pilot_passes(const cm_rbf *r, const cm_rbf_tree *t, const cm_rbf_tree_targets *tg,
                        size_t n, const double *p, double accept, double *out, int threads)
{
    size_t *idx = malloc(CM_RBF_PILOT_BATCHES * CM_RBF_PILOT_PER * sizeof *idx), stride = 1;
    if (!idx) return 0;
    const size_t np =
        cm_rbf_tree_targets_pilot(tg, CM_RBF_PILOT_BATCHES, CM_RBF_PILOT_PER, idx, &stride);
    const int pass = tree_sum_all(r, t, tg, stride, out, threads, NULL) == 0 &&
                     CM_RBF_FAST_SAFETY * check_all(r, t, n, p, out, np, idx, threads) <= accept;
    free(idx);
    return pass;
}

int cm_rbf_abs_sums(const cm_rbf *r, const double *a, int nc, size_t n, const double *p,
                    size_t ns, double *s, int threads)
{
    const size_t m = r->m;
    ns = n < ns ? n : ns;
    double *sp = calloc(3 * ns, sizeof *sp), *ab = malloc(ns * (size_t)nc * sizeof *ab);
    if (!sp || !ab) {
        free(sp), free(ab);
        return -1;
    }
    for (size_t k = 0; k < ns; ++k)
        for (int d = 0; d < 3; ++d)
            sp[(size_t)d * ns + k] = p[(size_t)d * n + (size_t)((double)k * (double)n / (double)ns)];
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, r->c, a, nc, ns, sp, ns, ab, (size_t)nc, threads);
    for (int c = 0; c < nc; ++c) s[c] = 0.0;
    for (size_t i = 0; i < ns * (size_t)nc; ++i)
        s[i % (size_t)nc] = fmax(s[i % (size_t)nc], ab[i]);
    free(sp), free(ab);
    return 0;
}

/* cm_rbf_abs_sums of the fit's weights */
static int sampled_abs_sums(const cm_rbf *r, size_t n, const double *p, size_t ns, double *s,
                            int threads)
{
    const size_t nw = (size_t)r->ncomp * r->m;
    double *aw = malloc(nw * sizeof *aw);
    if (!aw) return -1;
    for (size_t j = 0; j < nw; ++j) aw[j] = fabs(r->w[j]);
    const int st = cm_rbf_abs_sums(r, aw, r->ncomp, n, p, ns, s, threads);
    free(aw);
    return st;
}

static int evaluate_fast(const cm_rbf *r, size_t n, const double *p, double *out, int threads,
                         cm_rbf_tick *tick)
{
    cm_rbf_iter *it = r->iter;
    const size_t nc = (size_t)r->ncomp;
    const double target = r->tun.fast_eval_tol * it->scales.fmax;
    it->eval_fast = 0;
    it->eval_error = 0.0;
    if (!(target > 0.0)) return 0;
    double *s = malloc(nc * sizeof *s), smax = 0.0;
    const int ok = s && sampled_abs_sums(r, n, p, 64, s, threads) == 0;
    for (size_t c = 0; ok && c < nc; ++c) smax = fmax(smax, s[c]);
    free(s);
    if (!ok) return 0;
    /* what the direct fallback itself can promise (see above) */
    const double accept = fmax(target, CM_RBF_PHI_ROUND * DBL_EPSILON * smax);
    /* the row that should meet it with room for the estimate's factor; below the rounding
     * of the finest row (about 1e-16 x sum |w| phi) the finest is asked for */
    const double tau = fmax(accept / (smax * CM_RBF_FAST_SAFETY), CM_RBF_TREE_TOL_MIN);
    int order, order_c;
    double theta, theta_c;
    cm_rbf_tree_params(tau, &order, &theta);
    cm_rbf_tree_params(CM_RBF_PILOT_GAIN * tau, &order_c, &theta_c);
    cm_rbf_tree_targets *tg = cm_rbf_tree_targets_create(n, p, n);
    if (!tg) return 0;
    /* the coarser row first if it passes the pilot (at the table's coarse end it is the
     * same row) */
    int coarse = order_c != order || theta_c != theta;
    if (coarse) {
        const cm_rbf_tree *t = cm_rbf_iterative_tree(r, order_c, theta_c);
        coarse = t && pilot_passes(r, t, tg, n, p, accept, out, threads);
    }
    for (;; coarse = 0) {
        const int o = coarse ? order_c : order;
        const double th = coarse ? theta_c : theta;
        const cm_rbf_tree *t = cm_rbf_iterative_tree(r, o, th);
        if (tick) /* in whole sums; a second row starts over */
            cm_rbf_tick_restart(tick, (double)((nc + CM_RBF_SUM_MAX_NC - 1) / CM_RBF_SUM_MAX_NC));
        if (!t || tree_sum_all(r, t, tg, 1, out, threads, tick)) break;
        const double err = check_all(r, t, n, p, out, CM_RBF_FAST_SAMPLES, NULL, threads);
        it->eval_error = CM_RBF_FAST_SAFETY * err / it->scales.fmax;
        it->eval_fast = CM_RBF_FAST_SAFETY * err <= accept;
        it->eval_order = o;
        it->eval_theta = th;
        if (it->eval_fast || !coarse) break;
    }
    cm_rbf_tree_targets_destroy(&tg);
    return it->eval_fast;
}

int cm_rbf_iterative_evaluate_fast(const cm_rbf *r, size_t n, const double *p, double *out,
                                   int threads, cm_rbf_tick *tick)
{
    const int fs = r->opt.fast_sum;
    if (fs == 1 || (fs < 0 && (double)n * (double)r->m >= CM_RBF_FAST_EVAL_PAIRS))
        return evaluate_fast(r, n, p, out, threads, tick);
    r->iter->eval_fast = 0; /* eval_error stays that of the last evaluation that tried */
    return 0;
}

/* 1 if plain direct sums of the fit's weights at the n points p are within its tolerance
 * (see the top of the file), given s (their sampled sums of |w| phi, NULL: unknown). */
static int plain_enough(const cm_rbf *r, const double *s)
{
    const cm_rbf_scales *sc = &r->iter->scales;
    const size_t nc = (size_t)r->ncomp;
    const double tol = r->opt.tolerance;
    int ok = sc->n == nc && s;
    for (size_t c = 0; ok && c < nc; ++c) /* (smax unknown, -1: compensated) */
        ok = sc->smax[c] >= 0.0 && cm_rbf_plain_bound(sc->smax[c], sc->fnorm[c], tol) >= 0.0 &&
             cm_rbf_plain_bound(s[c], sc->fnorm[c], tol) >= 0.0;
    return ok;
}

int cm_rbf_iterative_evaluate(const cm_rbf *r, size_t n, const double *p, double *out,
                              int threads, cm_rbf_tick *tick)
{
    r->iter->eval_plain = 0;
    r->iter->eval_combined = 0;
    if (cm_rbf_iterative_evaluate_fast(r, n, p, out, threads, tick)) return 0;
    if (tick && tick->status < 0) return 1;
    /* direct sums: a tick of their own, in point-centre pairs */
    if (tick)
        cm_rbf_tick_restart(tick, (double)((r->ncomp + CM_RBF_SUM_MAX_NC - 1) / CM_RBF_SUM_MAX_NC) *
                                      (double)n * (double)r->m);
    /* sum |w| phi at sampled points: whether plain sums serve, and the span's error bounds */
    double *s = malloc((size_t)r->ncomp * sizeof *s);
    if (s && sampled_abs_sums(r, n, p, CM_RBF_FAST_SAMPLES, s, threads) != 0) free(s), s = NULL;
    const int plain = plain_enough(r, s);
    const int span = cm_rbf_iterative_evaluate_span(r, n, p, s, plain, out, threads, tick);
    free(s);
    if (span >= 0) {
        r->iter->eval_plain = plain;
        return span;
    }
    if (plain) {
        r->iter->eval_plain = 1;
        return cm_rbf_kernel_sum_all_tick(r, r->w, r->ncomp, n, p, n, out, threads, tick);
    }
    for (int g = 0; g < r->ncomp; g += CM_RBF_SUM_MAX_NC) {
        int nc = r->ncomp - g < CM_RBF_SUM_MAX_NC ? r->ncomp - g : CM_RBF_SUM_MAX_NC;
        if (cm_rbf_kernel_sum_acc_tick(r->m, r->c, r->w + (size_t)g * r->m, nc, n, p, n, out + g,
                                       (size_t)r->ncomp, threads, tick))
            return 1;
    }
    return 0;
}


/* The transposed evaluation (cm_rbf_evaluate_transpose): the same sums with the roles
 * swapped, sources at the n points with weights v, targets the m centres. Its result is the
 * right-hand side of a solve, not an output: an error e in it moves the reverse product by
 * A^-1 e, and <A^-1 e, D> = <e, A^-1 D> for any prescribed D, so it acts like a residual of
 * that solve. The treecode (a tree over the points, made for this call) is therefore taken
 * only where its sampled error, x CM_RBF_FAST_SAFETY, is within the smaller of the
 * evaluation's and the solve's tolerance x max |out| (or within the direct sums' own
 * rounding), by the same size rule as the evaluation; direct sums are compensated, as
 * there. */
static int transpose_fast(const cm_rbf *r, size_t n, const double *p, int ncomp,
                          const double *v, double *out, int threads, cm_rbf_tick *tick)
{
    const size_t m = r->m, nc = (size_t)ncomp;
    const size_t ns = m < 64 ? m : 64;
    double *sp = malloc(3 * ns * sizeof *sp), *av = malloc(nc * n * sizeof *av);
    double *ab = malloc(2 * ns * nc * sizeof *ab);
    int ok = sp && av && ab;
    double smax = 0.0, gmax = 0.0;
    if (ok) { /* the scales at a few centres: max |out| and sum_i |v_i| phi_ij */
        for (size_t k = 0; k < ns; ++k)
            for (int d = 0; d < 3; ++d)
                sp[(size_t)d * ns + k] = r->c[(size_t)d * m + (size_t)((double)k * (double)m / (double)ns)];
        for (size_t j = 0; j < nc * n; ++j) av[j] = fabs(v[j]);
        for (size_t g = 0; g < nc; g += CM_RBF_SUM_MAX_NC) {
            int gc = nc - g < CM_RBF_SUM_MAX_NC ? (int)(nc - g) : CM_RBF_SUM_MAX_NC;
            cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, n, p, av + g * n, gc, ns, sp, ns, ab + g,
                              nc, threads);
            cm_rbf_kernel_sum_acc(n, p, v + g * n, gc, ns, sp, ns, ab + ns * nc + g, nc, threads);
        }
        for (size_t i = 0; i < ns * nc; ++i) {
            smax = fmax(smax, ab[i]);
            gmax = fmax(gmax, fabs(ab[ns * nc + i]));
        }
    }
    free(sp), free(av), free(ab);
    if (!ok || !(smax > 0.0)) return 0;
    const double accept = fmax(fmin(r->tun.fast_eval_tol, r->opt.tolerance) * gmax,
                               CM_RBF_PHI_ROUND * DBL_EPSILON * smax);
    const double tau = fmax(accept / (smax * CM_RBF_FAST_SAFETY), CM_RBF_TREE_TOL_MIN);
    int order;
    double theta;
    cm_rbf_tree_params(tau, &order, &theta);
    cm_rbf_tree *t = cm_rbf_tree_create(n, p, order, theta);
    cm_rbf_tree_targets *tg = t ? cm_rbf_tree_targets_create(m, r->c, m) : NULL;
    int fast = tg != NULL;
    if (tick) cm_rbf_tick_restart(tick, (double)((nc + CM_RBF_SUM_MAX_NC - 1) / CM_RBF_SUM_MAX_NC));
    double err = 0.0;
    for (size_t g = 0; fast && g < nc; g += CM_RBF_SUM_MAX_NC) {
        int gc = nc - g < CM_RBF_SUM_MAX_NC ? (int)(nc - g) : CM_RBF_SUM_MAX_NC;
        if (cm_rbf_tree_sum_targets_tick(t, tg, 1, v + g * n, gc, out + g, nc, threads, tick)) {
            fast = 0;
            break;
        }
        double e;
        cm_rbf_tree_check(t, v + g * n, gc, m, r->c, m, out + g, nc, CM_RBF_FAST_SAMPLES, NULL,
                          &e, NULL, threads);
        err = fmax(err, e);
    }
    cm_rbf_tree_targets_destroy(&tg);
    cm_rbf_tree_destroy(&t);
    return fast && CM_RBF_FAST_SAFETY * err <= accept;
}

int cm_rbf_iterative_transpose_fast(const cm_rbf *r, size_t n, const double *p, int nc,
                                    const double *v, double *out, int threads,
                                    cm_rbf_tick *tick)
{
    const int fs = r->opt.fast_sum;
    r->iter->transpose_fast =
        (fs == 1 || (fs < 0 && (double)n * (double)r->m >= CM_RBF_FAST_EVAL_PAIRS)) &&
        transpose_fast(r, n, p, nc, v, out, threads, tick);
    return r->iter->transpose_fast;
}

int cm_rbf_iterative_transpose_was_fast(const cm_rbf *r) { return r->iter ? r->iter->transpose_fast : 0; }

int cm_rbf_iterative_evaluate_transpose(const cm_rbf *r, size_t n, const double *p, int nc,
                                        const double *v, double *out, int threads,
                                        cm_rbf_tick *tick)
{
    if (cm_rbf_iterative_transpose_fast(r, n, p, nc, v, out, threads, tick)) return 0;
    if (tick && tick->status < 0) return 1;
    if (tick)
        cm_rbf_tick_restart(tick, (double)((nc + CM_RBF_SUM_MAX_NC - 1) / CM_RBF_SUM_MAX_NC) *
                                      (double)n * (double)r->m);
    for (int g = 0; g < nc; g += CM_RBF_SUM_MAX_NC) {
        int gc = nc - g < CM_RBF_SUM_MAX_NC ? nc - g : CM_RBF_SUM_MAX_NC;
        if (cm_rbf_kernel_sum_acc_tick(n, p, v + (size_t)g * n, gc, r->m, r->c, r->m, out + g,
                                       (size_t)nc, threads, tick))
            return 1;
    }
    return 0;
}

void cm_rbf_iterative_stats(const cm_rbf *r, cm_rbf_stats *stats)
{
    if (!r->iter) return;
    stats->eval_fast = r->iter->eval_fast;
    stats->eval_plain = r->iter->eval_plain;
    stats->eval_combined = r->iter->eval_combined;
    stats->eval_error = r->iter->eval_error;
    stats->eval_order = r->iter->eval_order;
    stats->eval_theta = r->iter->eval_theta;
}
