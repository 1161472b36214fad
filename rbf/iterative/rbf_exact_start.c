/* Warm starts whose residual is known without a pass (rbf_krylov.h, cm_rbf_exact_starts):
 * the first group's weights in double-double with the products its solve ended on, and for
 * a later column the least-squares combination of those products nearest its data, formed
 * in double-double so that its product is the same combination of theirs, within a bound. */
#include "rbf_krylov.h"

#include <cblas.h>
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
    /* per unit of its coefficient, what a column adds to a start's error: the solve's own
     * account of its last A w, within cb of the column's scale (a check by the Arnoldi
     * relation, by plain sums) or exact to its rounding (compensated sums, which the checks
     * count exact; a few eps of it here); the rounding of the start's double-double weights
     * (cm_rbf_combine_dd: a few eps^2 |w_j| per entry, summed through diam^3 >= phi_ij); and
     * that of its product, the combination of the aw_j in double (n eps |aw_j|) */
    const double rd = (2.0 * n + 4.0) * DBL_EPSILON * DBL_EPSILON;
    for (int c = 0; c < n; ++c) {
        const double ainf = cm_krylov_norm_inf(m, es->aw + (size_t)c * m);
        es->err[c] = kr->col[c].cb * kr->col[c].fnorm + (n + 5.0) * DBL_EPSILON * ainf +
                     rd * kr->diam3 * cblas_dasum((int)m, es->whi + (size_t)c * m, 1);
    }
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
                          double *y, double *whi, double *wlo, double *aw)
{
    const size_t m = es->m;
    const int n = es->n;
    memcpy(y, f, m * sizeof *y);
    cm_krylov_project(r->iter->q1, m, r->k, y);
    /* over the rank independent columns col[]: c = R^-1 (Q' Pi f)[0..rank), the others 0 */
    const int rank = es->rank;
    if (LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)m, 1, rank, es->qr,
                       (lapack_int)m, es->tau, y, (lapack_int)m) != 0 ||
        LAPACKE_dtrtrs(LAPACK_COL_MAJOR, 'U', 'N', 'N', rank, 1, es->qr, (lapack_int)m, y,
                       (lapack_int)m) != 0)
        return -1.0;
    double c[CM_RBF_EXACT_MAX] = {0.0}, bound = 0.0;
    for (int j = 0; j < rank; ++j) c[es->col[j]] = y[j];
    for (int j = 0; j < n; ++j) bound += fabs(c[j]) * es->err[j];
    cm_rbf_combine_dd(m, n, es->whi, es->wlo, c, whi, wlo);
    cblas_dgemv(CblasColMajor, CblasNoTrans, (int)m, n, 1.0, es->aw, (int)m, c, 1, 0.0, aw, 1);
    return bound;
}
