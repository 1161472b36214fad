/* The sums of an evaluation of an iterative fit for any set of columns (rbf_iter.h): direct
 * ones (cm_rbf_iterative_sum_direct), or the r^3 treecode (cm_rbf_iterative_sum_fast) where
 * n x m is large, its row chosen for the error it must be shown within, after a pilot that
 * may pick a cheaper row, and its result checked against compensated direct sums at sampled
 * points. */
#include "rbf_iter.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

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
 * (bracket, 211k points: 3 %). */
#define CM_RBF_PILOT_GAIN 1e2
#define CM_RBF_PILOT_BATCHES 32
#define CM_RBF_PILOT_PER 16

/* The columns an evaluation's sums take: nc of m weights each (the fit's, or a part of them
 * and what else the evaluation through the span sums) */
typedef struct {
    const double *w;
    size_t nc;
} weights;

/* The treecode sums of the columns at the targets of every stride-th batch (1: all),
 * reported to tick (NULL: none) in whole sums. */
static int tree_sum_all(const cm_rbf *r, weights wc, const cm_rbf_tree *t,
                        const cm_rbf_tree_targets *tg, size_t stride, double *out, int threads,
                        cm_rbf_tick *tick)
{
    for (size_t g = 0; g < wc.nc; g += CM_RBF_SUM_MAX_NC) {
        int gc = wc.nc - g < CM_RBF_SUM_MAX_NC ? (int)(wc.nc - g) : CM_RBF_SUM_MAX_NC;
        if (cm_rbf_tree_sum_targets_tick(t, tg, stride, wc.w + g * r->m, gc, out + g, wc.nc,
                                         threads, tick))
            return -1;
    }
    return 0;
}

/* The largest error of the fast sums out (n x nc) against compensated direct sums at
 * `samples` of the targets (the indices idx, or NULL: spread over them), over the columns. */
static double check_all(const cm_rbf *r, weights wc, const cm_rbf_tree *t, size_t n,
                        const double *p, const double *out, size_t samples, const size_t *idx,
                        int threads)
{
    double err = 0.0;
    for (size_t g = 0; g < wc.nc; g += CM_RBF_SUM_MAX_NC) {
        int gc = wc.nc - g < CM_RBF_SUM_MAX_NC ? (int)(wc.nc - g) : CM_RBF_SUM_MAX_NC;
        double e;
        cm_rbf_tree_check(t, wc.w + g * r->m, gc, n, p, n, out + g, wc.nc, samples, idx, &e,
                          NULL, threads);
        err = fmax(err, e);
    }
    return err;
}

/* 1 if the treecode t passes the pilot: its largest error at the pilot's points, x
 * CM_RBF_FAST_SAFETY, is within accept. out: n x nc scratch. */
static int pilot_passes(const cm_rbf *r, weights wc, const cm_rbf_tree *t,
                        const cm_rbf_tree_targets *tg, size_t n, const double *p, double accept,
                        double *out, int threads)
{
    size_t *idx = malloc(CM_RBF_PILOT_BATCHES * CM_RBF_PILOT_PER * sizeof *idx), stride = 1;
    if (!idx) return 0;
    const size_t np =
        cm_rbf_tree_targets_pilot(tg, CM_RBF_PILOT_BATCHES, CM_RBF_PILOT_PER, idx, &stride);
    const int pass = tree_sum_all(r, wc, t, tg, stride, out, threads, NULL) == 0 &&
                     CM_RBF_FAST_SAFETY * check_all(r, wc, t, n, p, out, np, idx, threads) <=
                         accept;
    free(idx);
    return pass;
}

double cm_rbf_iterative_fast_accept(const cm_rbf *r, double smax)
{
    const double target = r->tun.fast_eval_tol * r->iter->scales.fmax;
    /* what the direct fallback itself can promise (see above) */
    return target > 0.0 ? fmax(target, CM_RBF_PHI_ROUND * DBL_EPSILON * smax) : 0.0;
}

int cm_rbf_iterative_sum_fast(const cm_rbf *r, const double *w, size_t nc, double smax,
                              size_t n, const double *p, double *out, int threads,
                              cm_rbf_tick *tick)
{
    cm_rbf_iter *it = r->iter;
    const weights wc = {w, nc};
    const double accept = cm_rbf_iterative_fast_accept(r, smax);
    it->eval_fast = 0;
    it->eval_error = 0.0;
    if (!(accept > 0.0)) return 0;
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
        coarse = t && pilot_passes(r, wc, t, tg, n, p, accept, out, threads);
    }
    for (;; coarse = 0) {
        const int o = coarse ? order_c : order;
        const double th = coarse ? theta_c : theta;
        const cm_rbf_tree *t = cm_rbf_iterative_tree(r, o, th);
        if (tick) /* in whole sums; a second row starts over */
            cm_rbf_tick_restart(tick, (double)cm_rbf_sum_passes(nc));
        if (!t || tree_sum_all(r, wc, t, tg, 1, out, threads, tick)) break;
        const double err = check_all(r, wc, t, n, p, out, CM_RBF_FAST_SAMPLES, NULL, threads);
        it->eval_error = CM_RBF_FAST_SAFETY * err / it->scales.fmax;
        it->eval_fast = CM_RBF_FAST_SAFETY * err <= accept;
        it->eval_order = o;
        it->eval_theta = th;
        if (it->eval_fast || !coarse) break;
    }
    cm_rbf_tree_targets_destroy(&tg);
    return it->eval_fast;
}

int cm_rbf_iterative_takes_fast(const cm_rbf *r, size_t n)
{
    const int fs = r->opt.fast_sum;
    return fs == 1 || (fs < 0 && (double)n * (double)r->m >= CM_RBF_FAST_EVAL_PAIRS);
}

int cm_rbf_iterative_sum_direct(const cm_rbf *r, const double *w, size_t nc, size_t n,
                                const double *p, int plain, double *out, int threads,
                                cm_rbf_tick *tick)
{
    if (nc == 0) return 0;
    if (plain) return cm_rbf_kernel_sum_all_tick(r, w, (int)nc, n, p, n, out, threads, tick);
    for (size_t g = 0; g < nc; g += CM_RBF_SUM_MAX_NC) {
        const int gc = nc - g < CM_RBF_SUM_MAX_NC ? (int)(nc - g) : CM_RBF_SUM_MAX_NC;
        if (cm_rbf_kernel_sum_acc_tick(r->m, r->c, w + g * r->m, gc, n, p, n, out + g, nc,
                                       threads, tick))
            return 1;
    }
    return 0;
}
