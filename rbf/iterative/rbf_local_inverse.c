/* The null-space projected factorisations of local r^3 + linear systems that the Schwarz
 * preconditioner (rbf_schwarz.c) is built from: the factor of a set's projected matrix, its
 * solve, and the leaf rows of a subdomain's inverse (two ways: a plain one and one at about
 * 0.6x the flops). Pure functions of the centres and an index set; the callers own the
 * work space and the BLAS threads (one per subdomain under OpenMP, all for the coarse
 * factor). */
#include "rbf_internal.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <string.h>

/* The null-space projected Cholesky factor of the r^3 system on the n centres idx: in work
 * (n*n + 8n doubles) a = Q' A Q with the Cholesky factor of its trailing n - rk block, and
 * pq = the Householder vectors of P's rank-revealing QR (dgeqp3: a local set on one planar
 * face is coplanar), rank in *rk, tau (4). Returns 0, the failing pivot (> 0), or -1. */
int cm_rbf_projected_factor(const double *cg, size_t m, const size_t *idx, size_t n,
                            double *work, int *rk_out, double *tau)
{
    double *a = work, *xyz = a + n * n, *pq = xyz + 3 * n;
    lapack_int jpvt[4] = {0, 0, 0, 0};
    for (int d = 0; d < 3; ++d)
        for (size_t i = 0; i < n; ++i) xyz[(size_t)d * n + i] = cg[(size_t)d * m + idx[i]];
    for (size_t j = 0; j < n; ++j) {
        const double xj = xyz[j], yj = xyz[n + j], zj = xyz[2 * n + j];
        double *col = a + j * n;
        for (size_t i = 0; i < n; ++i) {
            double dx = xyz[i] - xj, dy = xyz[n + i] - yj, dz = xyz[2 * n + i] - zj;
            double r2 = dx * dx + dy * dy + dz * dz;
            col[i] = r2 * sqrt(r2);
        }
    }
    for (size_t i = 0; i < n; ++i) pq[i] = 1.0;
    memcpy(pq + n, xyz, 3 * n * sizeof *pq);
    const lapack_int ln = (lapack_int)n;
    if (LAPACKE_dgeqp3(LAPACK_COL_MAJOR, ln, 4, pq, ln, jpvt, tau) != 0) return -1;
    int rk = 0;
    const double r00 = fabs(pq[0]);
    while (rk < 4 && fabs(pq[(size_t)rk * n + (size_t)rk]) > 1e-9 * r00) ++rk;
    *rk_out = rk;
    if (LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', ln, ln, rk, pq, ln, tau, a, ln) != 0 ||
        LAPACKE_dormqr(LAPACK_COL_MAJOR, 'R', 'N', ln, ln, rk, pq, ln, tau, a, ln) != 0)
        return -1;
    const lapack_int n2 = (lapack_int)(n - (size_t)rk);
    lapack_int info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', n2, a + (size_t)rk * n + (size_t)rk, ln);
    return info < 0 ? -1 : (int)info;
}

/* x (n x nrhs col-major, ld n) := Q2 (Q2' A Q2)^{-1} Q2' x with the factor of
 * cm_rbf_projected_factor: the weights of the interpolant of data x (linear part annihilated). */
int cm_rbf_projected_solve(const double *work, size_t n, int rk, const double *tau,
                           size_t nrhs, double *x)
{
    const double *a = work, *pq = work + n * n + 3 * n;
    const lapack_int ln = (lapack_int)n, lr = (lapack_int)nrhs;
    if (LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', ln, lr, rk, pq, ln, tau, x, ln) != 0 ||
        LAPACKE_dpotrs_work(LAPACK_COL_MAJOR, 'L', (lapack_int)(n - (size_t)rk), lr,
                       a + (size_t)rk * n + (size_t)rk, ln, x + rk, ln) != 0)
        return -1;
    for (size_t j = 0; j < nrhs; ++j)
        for (int i = 0; i < rk; ++i) x[j * n + (size_t)i] = 0.0;
    if (LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'N', ln, lr, rk, pq, ln, tau, x, ln) != 0)
        return -1;
    return 0;
}

/* g (n x n_in col-major) = Q2 (Q2' A Q2)^{-1} Q2' E, E the first n_in columns of the
 * identity: the weights of the local interpolant of unit data at each leaf centre, which by
 * symmetry are the leaf rows of the local inverse. work: n*n + 8n doubles.
 * Returns 0, or the failing Cholesky pivot (> 0), or -1 for a LAPACK argument error. */
int cm_rbf_local_inverse(const double *cg, size_t m, const size_t *idx, size_t n, size_t n_in,
                         double *work, double *g)
{
    double tau[4];
    int rk = 0;
    int info = cm_rbf_projected_factor(cg, m, idx, n, work, &rk, tau);
    if (info != 0) return info;
    memset(g, 0, n * n_in * sizeof *g);
    for (size_t j = 0; j < n_in; ++j) g[j * n + j] = 1.0;
    return cm_rbf_projected_solve(work, n, rk, tau, n_in, g);
}

/* local_inverse at about 0.6x the flops, for a local set with more overlap centres than
 * polynomial terms (else -2: use local_inverse). Why it is cheaper: the projection is rank
 * rk <= 4, so with the leaf ordered last, Q2'E is the trailing identity block plus a rank-rk
 * term, and S^{-1} [0; I] (S = Q2' A Q2 = L L') needs only the inverse of L's trailing leaf
 * block (dpotri) and one triangular solve with the overlap block L11, instead of dpotrs on
 * n_in full columns; the two-sided projection is one rank-2rk update of the lower triangle
 * (dsyr2k, Q = I - V T V') instead of two dormqr passes over the whole matrix. Same matrix
 * as local_inverse up to rounding. work: n*n + 24n doubles; g as local_inverse. */
int cm_rbf_local_inverse_fast(const double *cg, size_t m, const size_t *idx, size_t n,
                              size_t n_in, double *work, double *g)
{
    const size_t no = n - n_in; /* overlap centres: first in this order, the leaf last */
    double *a = work, *xyz = a + n * n, *pq = xyz + 3 * n, *vx = pq + 4 * n, *y = vx + 4 * n;
    double *wv = y + 4 * n, *xs = wv + 4 * n;
    for (int d = 0; d < 3; ++d)
        for (size_t i = 0; i < n; ++i) {
            size_t c = i < no ? idx[n_in + i] : idx[i - no];
            xyz[(size_t)d * n + i] = cg[(size_t)d * m + c];
        }
    for (size_t j = 0; j < n; ++j) { /* lower triangle only */
        const double xj = xyz[j], yj = xyz[n + j], zj = xyz[2 * n + j];
        double *col = a + j * n;
        for (size_t i = j; i < n; ++i) {
            double dx = xyz[i] - xj, dy = xyz[n + i] - yj, dz = xyz[2 * n + i] - zj;
            double r2 = dx * dx + dy * dy + dz * dz;
            col[i] = r2 * sqrt(r2);
        }
    }
    for (size_t i = 0; i < n; ++i) pq[i] = 1.0;
    memcpy(pq + n, xyz, 3 * n * sizeof *pq);
    lapack_int jpvt[4] = {0, 0, 0, 0};
    double tau[4], t[16], mx[16];
    const lapack_int ln = (lapack_int)n;
    if (LAPACKE_dgeqp3(LAPACK_COL_MAJOR, ln, 4, pq, ln, jpvt, tau) != 0) return -1;
    int rk = 0;
    const double r00 = fabs(pq[0]);
    while (rk < 4 && fabs(pq[(size_t)rk * n + (size_t)rk]) > 1e-9 * r00) ++rk;
    if (no < (size_t)rk + 1 || n_in == 0) return -2;
    const size_t nn = n - (size_t)rk, s = no - (size_t)rk; /* S is nn x nn: s overlap, n_in leaf */
    for (int c = 0; c < rk; ++c)
        for (size_t i = 0; i < n; ++i)
            vx[(size_t)c * n + i] = i < (size_t)c ? 0.0 : i == (size_t)c ? 1.0 : pq[(size_t)c * n + i];
    if (LAPACKE_dlarft_work(LAPACK_COL_MAJOR, 'F', 'C', ln, rk, vx, ln, tau, t, rk) != 0) return -1;
    /* Q'AQ = A - V Z' - Z V', Z = A V T - V (T'V'A V T) / 2 */
    cblas_dsymm(CblasColMajor, CblasLeft, CblasLower, (int)n, rk, 1.0, a, (int)n, vx, (int)n,
                0.0, y, (int)n);
    cblas_dtrmm(CblasColMajor, CblasRight, CblasUpper, CblasNoTrans, CblasNonUnit, (int)n, rk,
                1.0, t, rk, y, (int)n);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, rk, rk, (int)n, 1.0, vx, (int)n, y,
                (int)n, 0.0, mx, rk);
    cblas_dtrmm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, rk, rk, 1.0, t,
                rk, mx, rk);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)n, rk, rk, -0.5, vx, (int)n, mx,
                rk, 1.0, y, (int)n);
    cblas_dsyr2k(CblasColMajor, CblasLower, CblasNoTrans, (int)n, rk, -1.0, vx, (int)n, y,
                 (int)n, 1.0, a, (int)n);
    double *L = a + (size_t)rk * n + (size_t)rk; /* S = L L', leading dimension n */
    lapack_int info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', (lapack_int)nn, L, ln);
    if (info != 0) return info < 0 ? -1 : (int)info;
    /* Q2'E = E2 - V2 xs: E2 the unit columns at rows s.. of S's space, V2 = rows rk.. of V,
     * xs = T' V_leaf' (rk x n_in) */
    for (size_t j = 0; j < n_in; ++j)
        for (int c = 0; c < rk; ++c) xs[(size_t)c + (size_t)rk * j] = vx[(size_t)c * n + no + j];
    cblas_dtrmm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, rk, (int)n_in,
                1.0, t, rk, xs, rk);
    /* wv = S^{-1} V2 */
    for (int c = 0; c < rk; ++c)
        memcpy(wv + (size_t)c * n, vx + (size_t)c * n + rk, nn * sizeof *wv);
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, (int)nn, rk,
                1.0, L, (int)n, wv, (int)n);
    cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasTrans, CblasNonUnit, (int)nn, rk, 1.0,
                L, (int)n, wv, (int)n);
    /* X = S^{-1} E2 - wv xs into rows rk.. of g: S^{-1} E2 = [-L11^{-T} L21' x2; x2] with
     * x2 = (L22 L22')^{-1} */
    double *gx = g + rk, *x2 = g + no, *L22 = L + s * n + s;
    for (size_t j = 0; j < n_in; ++j)
        for (size_t i = j; i < n_in; ++i) x2[j * n + i] = L22[j * n + i];
    info = LAPACKE_dpotri_work(LAPACK_COL_MAJOR, 'L', (lapack_int)n_in, x2, ln);
    if (info != 0) return info < 0 ? -1 : (int)(s + (size_t)info);
    for (size_t j = 0; j < n_in; ++j)
        for (size_t i = 0; i < j; ++i) x2[j * n + i] = x2[i * n + j];
    if (s > 0) {
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)s, (int)n_in, (int)n_in, -1.0,
                    L + s, (int)n, x2, (int)n, 0.0, gx, (int)n);
        cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasTrans, CblasNonUnit, (int)s,
                    (int)n_in, 1.0, L, (int)n, gx, (int)n);
    }
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)nn, (int)n_in, rk, -1.0, wv,
                (int)n, xs, rk, 1.0, gx, (int)n);
    /* G E = Q [0; X] = g - V T (V' g) */
    for (size_t j = 0; j < n_in; ++j)
        for (int i = 0; i < rk; ++i) g[j * n + (size_t)i] = 0.0;
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, rk, (int)n_in, (int)n, 1.0, vx, (int)n,
                g, (int)n, 0.0, xs, rk);
    cblas_dtrmm(CblasColMajor, CblasLeft, CblasUpper, CblasNoTrans, CblasNonUnit, rk, (int)n_in,
                1.0, t, rk, xs, rk);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)n, (int)n_in, rk, -1.0, vx,
                (int)n, xs, rk, 1.0, g, (int)n);
    /* back to idx order (leaf first): rotate every column by n_in */
    for (size_t j = 0; j < n_in; ++j) {
        double *col = g + j * n;
        memcpy(y, col, no * sizeof *y);
        memmove(col, col + no, n_in * sizeof *col);
        memcpy(col + n_in, y, no * sizeof *col);
    }
    return 0;
}

/* q (n x 4 col-major) = orthonormal basis of the linear polynomials on the n centres idx (the
 * same rank-revealing QR as cm_rbf_projected_factor; columns past the rank zero). work: 8n. */
int cm_rbf_poly_basis(const double *cg, size_t m, const size_t *idx, size_t n, double *work,
                      double *q)
{
    double *pq = work;
    lapack_int jpvt[4] = {0, 0, 0, 0};
    double tau[4];
    for (size_t i = 0; i < n; ++i) pq[i] = 1.0;
    for (int d = 0; d < 3; ++d)
        for (size_t i = 0; i < n; ++i) pq[(size_t)(d + 1) * n + i] = cg[(size_t)d * m + idx[i]];
    const lapack_int ln = (lapack_int)n;
    if (LAPACKE_dgeqp3(LAPACK_COL_MAJOR, ln, 4, pq, ln, jpvt, tau) != 0) return -1;
    int rk = 0;
    const double r00 = fabs(pq[0]);
    while (rk < 4 && fabs(pq[(size_t)rk * n + (size_t)rk]) > 1e-9 * r00) ++rk;
    if (LAPACKE_dorgqr(LAPACK_COL_MAJOR, ln, rk, rk, pq, ln, tau) != 0) return -1;
    memset(q, 0, 4 * n * sizeof *q);
    memcpy(q, pq, (size_t)rk * n * sizeof *q);
    return 0;
}
