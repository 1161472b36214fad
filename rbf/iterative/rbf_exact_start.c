/* Warm starts whose residual is known without a pass (rbf_krylov.h, cm_rbf_exact_starts):
 * the first group's weights in double-double with the products its solve ended on, and for
 * a later column the least-squares combination of those products nearest its data, formed
 * in double-double so that its product is the same combination of theirs, within a bound. */
#include "rbf_krylov.h"

#include <float.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Columns that the pivoted QR of the kept products finds within this share of its largest
 * diagonal of the span of those before them are left out: their coefficients would be large,
 * and so would the bound (a family whose fields are nearly proportional, as the bracket's). */
#define CM_RBF_EXACT_RANK 1e-8

void cm_rbf_exact_starts_free(cm_rbf_exact_starts *es)
{
    if (!es) return;
    free(es->whi);
    free(es->err);
    free(es->qr);
    memset(es, 0, sizeof *es);
}

size_t cm_rbf_exact_starts_bytes(const cm_rbf_exact_starts *es)
{
    return es && es->n > 0 ? (4 * (size_t)es->n * es->m + 2 * (size_t)es->n) * sizeof(double)
                           : 0;
}

int cm_rbf_exact_starts_make(const cm_rbf *r, const krylov *kr, int n, const double *whi,
                             const double *wlo, const double *aw, cm_rbf_exact_starts *es)
{
    const size_t m = r->m, nm = (size_t)n * m;
    memset(es, 0, sizeof *es);
    es->m = m;
    es->diam3 = kr->diam3;
    if (n <= 0 || n > CM_RBF_EXACT_MAX) return -1;
    es->whi = malloc(3 * nm * sizeof *es->whi);
    es->err = malloc(2 * (size_t)n * sizeof *es->err);
    es->qr = malloc(nm * sizeof *es->qr);
    if (!es->whi || !es->err || !es->qr) {
        cm_rbf_exact_starts_free(es);
        return -1;
    }
    es->wlo = es->whi + nm;
    es->aw = es->wlo + nm;
    es->tau = es->err + n;
    memcpy(es->whi, whi, nm * sizeof *whi);
    memcpy(es->wlo, wlo, nm * sizeof *wlo);
    memcpy(es->aw, aw, nm * sizeof *aw);
    /* the solve's own account of its last A w: within cb of the column's scale (a check by
     * the Arnoldi relation, by plain sums), or exact to its rounding (compensated sums, which
     * the checks count exact; a few eps of it here) */
    for (int c = 0; c < n; ++c)
        es->err[c] = kr->col[c].cb * kr->col[c].fnorm +
                     4.0 * DBL_EPSILON * cm_krylov_norm_inf(m, es->aw + (size_t)c * m);
    memcpy(es->qr, es->aw, nm * sizeof *es->qr);
    for (int c = 0; c < n; ++c) cm_krylov_project(r->iter->q1, m, r->k, es->qr + (size_t)c * m);
    lapack_int jpvt[CM_RBF_EXACT_MAX] = {0};
    lapack_int info = LAPACKE_dgeqp3(LAPACK_COL_MAJOR, (lapack_int)m, n, es->qr, (lapack_int)m,
                                     jpvt, es->tau);
    int rank = 0;
    while (info == 0 && rank < n &&
           fabs(es->qr[(size_t)rank * m + (size_t)rank]) > CM_RBF_EXACT_RANK * fabs(es->qr[0]))
        ++rank;
    if (rank == 0) {
        cm_rbf_exact_starts_free(es);
        return -1;
    }
    for (int j = 0; j < rank; ++j) es->col[j] = (int)jpvt[j] - 1;
    es->n = n;
    es->rank = rank;
    return 0;
}

double cm_rbf_exact_start(const cm_rbf *r, const cm_rbf_exact_starts *es, const double *f,
                          double *whi, double *wlo, double *aw)
{
    const size_t m = es->m;
    const int n = es->n;
    double *y = malloc(m * sizeof *y);
    if (!y) return -1.0;
    memcpy(y, f, m * sizeof *y);
    cm_krylov_project(r->iter->q1, m, r->k, y);
    /* over the rank independent columns col[]: c = R^-1 (Q' Pi f)[0..rank), the others 0 */
    const int rank = es->rank;
    if (LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)m, 1, rank, es->qr,
                       (lapack_int)m, es->tau, y, (lapack_int)m) != 0 ||
        LAPACKE_dtrtrs(LAPACK_COL_MAJOR, 'U', 'N', 'N', rank, 1, es->qr, (lapack_int)m, y,
                       (lapack_int)m) != 0) {
        free(y);
        return -1.0;
    }
    double c[CM_RBF_EXACT_MAX] = {0.0}, bound = 0.0;
    for (int j = 0; j < rank; ++j) c[es->col[j]] = y[j];
    for (int j = 0; j < n; ++j) bound += fabs(c[j]) * es->err[j];
    free(y);
    /* whi + wlo = sum c_j (whi_j + wlo_j) in double-double (each term by TwoProduct, their sum
     * by TwoSum), off the exact combination by a few eps^2 sum |c_j whi_j| per entry; aw =
     * sum c_j aw_j in double, off by n eps sum |c_j aw_j|. Both go into the bound, the first
     * through diam^3 >= phi_ij. */
    double dd = 0.0, awe = 0.0;
    for (size_t i = 0; i < m; ++i) {
        double hi = 0.0, lo = 0.0, mag = 0.0, a = 0.0, amag = 0.0;
        for (int j = 0; j < n; ++j) {
            const double x = es->whi[(size_t)j * m + i], p = c[j] * x, pe = fma(c[j], x, -p);
            const double t = hi + p, bv = t - hi;
            lo += ((hi - (t - bv)) + (p - bv)) + pe + c[j] * es->wlo[(size_t)j * m + i];
            hi = t;
            mag += fabs(p);
            const double b = c[j] * es->aw[(size_t)j * m + i];
            a += b;
            amag += fabs(b);
        }
        const double t = hi + lo;
        wlo[i] = lo - (t - hi);
        whi[i] = t;
        aw[i] = a;
        dd += mag;
        awe = fmax(awe, amag);
    }
    const double rd = (2.0 * n + 4.0) * DBL_EPSILON * DBL_EPSILON;
    return bound + rd * es->diam3 * dd + (n + 1.0) * DBL_EPSILON * awe;
}
