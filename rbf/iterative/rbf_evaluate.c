/* Evaluation of an iterative fit: compensated direct sums, plain ones where the solve's
 * tolerance allows them, or the r^3 treecode where n x m is large and a sampled check shows
 * its error within fast_eval_tol x max |data| (rbf_evaluate_tree.c); warm columns through the
 * span of others (rbf_evaluate_span.c). */
#include "rbf_iter.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

/* the points at which sum_j |w_j| phi_ij, the scale of the treecode's bound, is sampled */
#define CM_RBF_FAST_SMAX_SAMPLES 64

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

/* the largest of nc values */
static double largest(const double *s, size_t nc)
{
    double smax = 0.0;
    for (size_t c = 0; c < nc; ++c) smax = fmax(smax, s[c]);
    return smax;
}

int cm_rbf_iterative_evaluate_fast(const cm_rbf *r, size_t n, const double *p, double *out,
                                   int threads, cm_rbf_tick *tick)
{
    const size_t nc = (size_t)r->ncomp;
    r->iter->eval_fast = 0; /* eval_error stays that of the last evaluation that tried */
    if (!cm_rbf_iterative_takes_fast(r, n)) return 0;
    double *s = malloc(nc * sizeof *s);
    const int ok = s && sampled_abs_sums(r, n, p, CM_RBF_FAST_SMAX_SAMPLES, s, threads) == 0;
    const double smax = ok ? largest(s, nc) : 0.0;
    free(s);
    return ok && cm_rbf_iterative_sum_fast(r, r->w, nc, smax, n, p, out, threads, tick);
}

/* 1 if the solve's sums of |w| phi at the centres allow plain sums of every column (the
 * centres first: the sampled points cost more) */
static int plain_at_centres(const cm_rbf *r)
{
    const cm_rbf_scales *sc = &r->iter->scales;
    int ok = sc->n == (size_t)r->ncomp;
    for (size_t c = 0; ok && c < sc->n; ++c) /* (smax unknown, -1: compensated) */
        ok = sc->smax[c] >= 0.0 &&
             cm_rbf_plain_bound(sc->smax[c], sc->fnorm[c], r->opt.tolerance) >= 0.0;
    return ok;
}

/* 1 if plain direct sums of the fit's weights at the n points p are within its tolerance
 * (see the top of the file), given s (their sampled sums of |w| phi, NULL: unknown). */
static int plain_enough(const cm_rbf *r, const double *s)
{
    const cm_rbf_scales *sc = &r->iter->scales;
    const size_t nc = (size_t)r->ncomp;
    int ok = s && plain_at_centres(r);
    for (size_t c = 0; ok && c < nc; ++c)
        ok = cm_rbf_plain_bound(s[c], sc->fnorm[c], r->opt.tolerance) >= 0.0;
    return ok;
}

/* 1 if a column's solve started warm: the evaluation through the span may combine it */
static int any_warm(const cm_rbf *r)
{
    const cm_rbf_scales *sc = &r->iter->scales;
    for (size_t c = 0; sc->n == (size_t)r->ncomp && c < sc->n; ++c)
        if (sc->start[c] >= 0.0) return 1;
    return 0;
}

/* sum |w| phi of the fit's columns at ns sampled points, malloc'ed (NULL: out of memory) */
static double *sampled(const cm_rbf *r, size_t n, const double *p, size_t ns, int threads)
{
    double *s = malloc((size_t)r->ncomp * sizeof *s);
    if (s && sampled_abs_sums(r, n, p, ns, s, threads) != 0) free(s), s = NULL;
    return s;
}

int cm_rbf_iterative_evaluate(const cm_rbf *r, size_t n, const double *p, double *out,
                              int threads, cm_rbf_tick *tick)
{
    cm_rbf_iter *it = r->iter;
    const size_t nc = (size_t)r->ncomp;
    it->eval_plain = 0;
    it->eval_combined = 0;
    it->eval_fast = 0; /* eval_error stays that of the last evaluation that tried */
    /* sum |w| phi at sampled points: the treecode's scale, or whether plain sums serve; and
     * the span's error bounds (none of them: a compensated evaluation of cold columns) */
    const int fast = cm_rbf_iterative_takes_fast(r, n);
    double *s = fast || any_warm(r) || plain_at_centres(r)
                    ? sampled(r, n, p, fast ? CM_RBF_FAST_SMAX_SAMPLES : CM_RBF_FAST_SAMPLES,
                              threads)
                    : NULL;
    int kind = fast ? CM_RBF_SUMS_FAST : plain_enough(r, s) ? CM_RBF_SUMS_PLAIN
                                                            : CM_RBF_SUMS_COMPENSATED;
    int done = cm_rbf_iterative_evaluate_span(r, n, p, s, kind, out, threads, tick);
    if (done < 0 && fast && s &&
        cm_rbf_iterative_sum_fast(r, r->w, nc, largest(s, nc), n, p, out, threads, tick))
        done = 0;
    free(s);
    if (done >= 0) {
        it->eval_plain = kind == CM_RBF_SUMS_PLAIN;
        return done;
    }
    if (tick && tick->status < 0) return 1;
    if (fast) { /* the treecode failed its check: plain direct sums if they serve */
        s = sampled(r, n, p, CM_RBF_FAST_SAMPLES, threads);
        kind = plain_enough(r, s) ? CM_RBF_SUMS_PLAIN : CM_RBF_SUMS_COMPENSATED;
        free(s);
    }
    /* direct sums: a tick of their own, in point-centre pairs */
    if (tick) cm_rbf_tick_restart(tick, (double)cm_rbf_sum_passes(nc) * (double)n * (double)r->m);
    it->eval_plain = kind == CM_RBF_SUMS_PLAIN;
    return cm_rbf_iterative_sum_direct(r, r->w, nc, n, p, it->eval_plain, out, threads, tick);
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
    if (tick) cm_rbf_tick_restart(tick, (double)cm_rbf_sum_passes(nc));
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
        cm_rbf_tick_restart(tick, (double)cm_rbf_sum_passes(nc) *
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
