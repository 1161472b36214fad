/* Evaluation of an iterative fit through the span of some of its columns (rbf_iter.h,
 * cm_rbf_iterative_evaluate_span). A column whose solve started from the history's
 * combination (a warm start: cm_rbf_history) has weights w_c = W_B a_c + res_c, W_B a basis
 * of the same solve's other columns, a_c by least squares; the evaluation is linear in the
 * weights, so its values are the basis' values combined by a_c plus the sums of res_c alone.
 * A study's batch is solved in warm groups (docs/DESIGN.md, "Studies in batches"), so three
 * quarters of its columns start warm. Where the sums are plain (a loose tolerance, as a
 * study's 1e-6) or by the treecode, the basis is every column that took a Krylov step, so a
 * column that took none (its start met the tolerance) is the history's combination of them:
 * res_c is rounding and is not summed at all. Where they are compensated (the default
 * tolerance, at which every warm column takes a few steps), the basis is the columns that
 * started from zero, and res_c, the warm columns' steps and their starts' share of the
 * earlier groups' steps, about 1e-8 of w_c, is summed plainly: its rounding is far below the
 * tolerance where w_c's needs compensated sums. A column is taken so only where both parts'
 * error bounds stay within what the direct sums would promise for it. */
#include "rbf_iter.h"

#include <cblas.h>
#include <float.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The combination's rounding bound may reach this multiple of the direct sums' own bound on a
 * column: both count every term at its worst, and the combination's exceeds the direct one's
 * by the subadditivity of sum |w| phi alone (sum_b |a_b| S(w_b) >= S(w_c - res_c)) */
#define CM_RBF_SPAN_GROWTH 4.0
/* basis columns whose pivot falls below this fraction of the first are left out of the
 * basis (dependent up to rounding: a zero displacement component, a repeated variant) */
#define CM_RBF_SPAN_RANK 1e-12

/* how a column is evaluated: summed, combined, combined with its rest summed */
enum { SPAN_DIRECT, SPAN_ONLY, SPAN_RES };

int cm_rbf_iterative_evaluate_span(const cm_rbf *r, size_t n, const double *p, const double *s,
                                   int kind, double *out, int threads, cm_rbf_tick *tick)
{
    const cm_rbf_scales *sc = &r->iter->scales;
    const size_t m = r->m, nc = (size_t)r->ncomp;
    r->iter->eval_combined = 0;
    if (sc->n != nc || !s) return -1;
    /* the basis: the columns that started from zero, and with plain sums or the treecode
     * those that took steps (summing one costs what summing its rest would) */
    const int one = kind != CM_RBF_SUMS_COMPENSATED; /* the sums of the basis and the rests
                                                        in one pass */
    unsigned char *basis = malloc(nc);
    if (!basis) return -1;
    size_t nb = 0;
    for (size_t c = 0; c < nc; ++c) {
        basis[c] = sc->start[c] < 0.0 || (one && sc->start[c] > 0.0);
        nb += basis[c];
    }
    const size_t nw = nc - nb;
    if (nb == 0 || nw == 0) {
        free(basis);
        return -1;
    }
    int ret = -1;
    size_t *col = malloc(nc * sizeof *col); /* the basis, then the others */
    int *how = calloc(nc, sizeof *how);
    lapack_int *piv = calloc(nb, sizeof *piv);
    double *wb = malloc(m * nb * sizeof *wb), *x = malloc(m * nw * sizeof *x);
    double *tau = malloc(nb * sizeof *tau), *a = calloc(nb * nw, sizeof *a);
    double *outd = NULL, *outr = NULL, *outk = NULL, *wr = NULL, *coef = NULL;
    if (!col || !how || !piv || !wb || !x || !tau || !a) goto done;
    for (size_t c = 0, ib = 0, iw = nb; c < nc; ++c) col[basis[c] ? ib++ : iw++] = c;
    for (size_t b = 0; b < nb; ++b) memcpy(wb + b * m, r->w + col[b] * m, m * sizeof *wb);
    for (size_t j = 0; j < nw; ++j) memcpy(x + j * m, r->w + col[nb + j] * m, m * sizeof *x);
    /* a_c = argmin |w_c - W_B a|: W_B P = Q R, pivoted so that a dependent basis column is
     * left out rather than amplifying the others */
    if (LAPACKE_dgeqp3(LAPACK_COL_MAJOR, (lapack_int)m, (lapack_int)nb, wb, (lapack_int)m, piv,
                       tau) != 0)
        goto done;
    size_t rank = 0;
    while (rank < nb && fabs(wb[rank * m + rank]) > CM_RBF_SPAN_RANK * fabs(wb[0])) ++rank;
    if (rank == 0 || LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)m, (lapack_int)nw,
                                    (lapack_int)rank, wb, (lapack_int)m, tau, x,
                                    (lapack_int)m) != 0)
        goto done;
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasNoTrans, CblasNonUnit, (int)rank,
                (int)nw, 1.0, wb, (int)m, x, (int)m);
    for (size_t j = 0; j < nw; ++j) /* a: nb x nw, row b for the basis column col[b] */
        for (size_t i = 0; i < rank; ++i) a[(size_t)(piv[i] - 1) * nw + j] = x[j * m + i];
    /* res = W_C - W_B a */
    for (size_t b = 0; b < nb; ++b) memcpy(wb + b * m, r->w + col[b] * m, m * sizeof *wb);
    for (size_t j = 0; j < nw; ++j) memcpy(x + j * m, r->w + col[nb + j] * m, m * sizeof *x);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, (int)m, (int)nw, (int)nb, -1.0, wb,
                (int)m, a, (int)nw, 1.0, x, (int)m);
    /* each other column: combined alone, combined with its rest summed, or summed. The
     * sums' error bounds: plain and compensated ones relative to the column's sum |w| phi,
     * the treecode's what its check accepts, the same for every column (its scale the
     * largest sum |w| phi of all, as for the fit's own columns) */
    double smax = 0.0;
    for (size_t c = 0; c < nc; ++c) smax = fmax(smax, s[c]);
    const double err = kind == CM_RBF_SUMS_PLAIN ? CM_RBF_PLAIN_ERR
                       : kind == CM_RBF_SUMS_COMPENSATED ? CM_RBF_PHI_ROUND * DBL_EPSILON
                                                         : 0.0;
    const double accept = kind == CM_RBF_SUMS_FAST ? cm_rbf_iterative_fast_accept(r, smax) : 0.0;
    const double dia3 = cm_rbf_diam3(r, n, p);
    size_t nd = nb, nr = 0;
    for (size_t j = 0; j < nw; ++j) {
        const size_t c = col[nb + j];
        double comb = 0.0;
        for (size_t b = 0; b < nb; ++b) comb += fabs(a[b * nw + j]) * (err * s[col[b]] + accept);
        const double rest = dia3 * cblas_dasum((int)m, x + j * m, 1);
        const double rest_err = kind == CM_RBF_SUMS_FAST ? accept : CM_RBF_PLAIN_ERR * rest;
        const double bound = fmax(CM_RBF_PLAIN_RES_SHARE * r->opt.tolerance * sc->fnorm[c],
                                  CM_RBF_SPAN_GROWTH * (err * s[c] + accept));
        how[c] = comb + rest <= bound       ? SPAN_ONLY
                 : comb + rest_err <= bound ? SPAN_RES
                                            : SPAN_DIRECT;
        nd += how[c] == SPAN_DIRECT;
        nr += how[c] == SPAN_RES;
    }
    if (nd == nc) goto done; /* nothing gains */
    /* the direct columns (the basis first) and the rests: in one plain or treecode pass, or
     * the direct ones compensated and the rests plain (a pass costs its pairs' distances
     * before its columns: bore, 47,661 nodes x 20,642 centres, plain sums of 15 columns 0.3 s,
     * of 60 columns 1.0 s) */
    const size_t nk = nc - nd, ns = nd + nr;
    const size_t ldd = one ? ns : nd, ldr = one ? ns : nr;
    outd = malloc(n * ns * sizeof *outd);
    outk = malloc(n * nk * sizeof *outk);
    outr = one || !nr ? NULL : malloc(n * nr * sizeof *outr);
    wr = malloc(m * ns * sizeof *wr);
    coef = malloc(nb * nk * sizeof *coef);
    if (!outd || !outk || (!one && nr && !outr) || !wr || !coef) goto done;
    size_t v = 0;
    for (size_t u = 0; u < nc; ++u)
        if (how[col[u]] == SPAN_DIRECT) memcpy(wr + v++ * m, r->w + col[u] * m, m * sizeof *wr);
    for (size_t j = 0; j < nw; ++j)
        if (how[col[nb + j]] == SPAN_RES) memcpy(wr + v++ * m, x + j * m, m * sizeof *wr);
    ret = 1;
    const int fast = kind == CM_RBF_SUMS_FAST &&
                     cm_rbf_iterative_sum_fast(r, wr, ns, smax, n, p, outd, threads, tick);
    if (tick && tick->status < 0) goto done;
    /* direct sums (after a treecode that failed its check, a rare case: compensated) */
    if (!fast) {
        if (tick) /* in point-centre pairs, per pass of up to CM_RBF_SUM_MAX_NC columns */
            cm_rbf_tick_restart(tick, (double)(one ? cm_rbf_sum_passes(ns)
                                                    : cm_rbf_sum_passes(nd) + cm_rbf_sum_passes(nr)) *
                                          (double)n * (double)m);
        if (one ? cm_rbf_iterative_sum_direct(r, wr, ns, n, p, kind == CM_RBF_SUMS_PLAIN, outd,
                                              threads, tick)
                : cm_rbf_iterative_sum_direct(r, wr, nd, n, p, 0, outd, threads, tick) ||
                      cm_rbf_iterative_sum_direct(r, wr + nd * m, nr, n, p, 1, outr, threads,
                                                  tick))
            goto done;
    }
    const double *rests = one ? outd + nd : outr;
    /* the combined columns' coefficients, nb x nk, over the basis columns' values */
    for (size_t j = 0, u = 0; j < nw; ++j)
        if (how[col[nb + j]] != SPAN_DIRECT) {
            for (size_t b = 0; b < nb; ++b) coef[b * nk + u] = a[b * nw + j];
            ++u;
        }
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, (int)n, (int)nk, (int)nb, 1.0, outd,
                (int)ldd, coef, (int)nk, 0.0, outk, (int)nk);
    /* into out, column by column */
    size_t id = 0, ik = 0, ir = 0;
    for (size_t u = 0; u < nc; ++u) {
        const size_t c = col[u];
        const int kc = how[c];
        for (size_t i = 0; i < n; ++i) {
            double *o = out + i * nc + c;
            if (kc == SPAN_DIRECT) *o = outd[i * ldd + id];
            else {
                *o = outk[i * nk + ik];
                if (kc == SPAN_RES) *o += rests[i * ldr + ir];
            }
        }
        id += kc == SPAN_DIRECT;
        ik += kc != SPAN_DIRECT;
        ir += kc == SPAN_RES;
    }
    r->iter->eval_combined = (int)nk;
    ret = 0;
done:
    free(basis), free(col), free(how), free(piv), free(wb), free(x), free(tau), free(a);
    free(outd), free(outk), free(outr), free(wr), free(coef);
    return ret;
}
