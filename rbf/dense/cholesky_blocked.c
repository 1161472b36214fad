/* Cholesky factorisation of an SPD matrix in rectangular full packed storage (TRANSR 'N',
 * UPLO 'L'; the layout of LAPACK's dpftrf), panel by panel, so that the caller sees
 * progress during what is, at m = 20k, half a minute of BLAS-3.
 *
 * Why not dpftrf: it is four calls (dpotrf, dtrsm, dsyrk, dpotrf on the two halves) with no
 * way to report in between. Same arithmetic here, split into panels of `block` columns:
 * RFP keeps the first n1 columns of the lower triangle in place (column j, rows j..n-1,
 * leading dimension ld) and the trailing n2 x n2 block A22 as the upper triangle of a
 * square at a22. So:
 *   1. right-looking blocked Cholesky of the tall n x n1 block: per panel dpotrf of its
 *      diagonal block, dtrsm of everything below, then the rank-b update of the rest of the
 *      tall block (dsyrk + dgemm) and of A22 (dsyrk into its upper triangle);
 *   2. right-looking blocked Cholesky U'U of A22 in its upper storage.
 * Every update is BLAS-3 with inner dimension b ~ OpenBLAS's own GEMM_Q blocking, so the
 * memory traffic is that of one big dsyrk, and the footprint stays the packed n(n+1)/2. */
#include "rbf_internal.h"

#include <cblas.h>
#include <lapacke.h>
#include <omp.h>

#define CM_CHOLESKY_BLOCK 256

typedef struct progress {
    cm_context *ctx;
    double done, total;
} progress;

/* Nonzero when the caller asked to stop (cm_context_interrupt). */
static int report(progress *p, double flops)
{
    p->done += flops;
    if (p->done > p->total) p->done = p->total;
    return cm_progress(p->ctx, "rbf factor", p->done, p->total) < 0;
}

int cm_rbf_cholesky_rfp_panels(cm_context *ctx, int n, double *a, int block)
{
    if (n < 0 || !a) return -1;
    if (n == 0) return 0;
    const int b0 = block > 0 ? block : CM_CHOLESKY_BLOCK;
    int n1, n2;
    size_t ld, off1, off2;
    if (n % 2) { /* odd: A11 (n1 = n2 + 1) at a (ld n), A22 upper at a + n */
        n2 = n / 2;
        n1 = n - n2;
        ld = (size_t)n;
        off1 = 0;
        off2 = (size_t)n;
    } else { /* even: A11 at a + 1 (ld n + 1), A22 upper at a */
        n1 = n / 2;
        n2 = n1;
        ld = (size_t)n + 1;
        off1 = 1;
        off2 = 0;
    }
    double *t = a + off1; /* tall n x n1 block: element (i, j) at t[i + j ld], i >= j */
    double *u = a + off2; /* A22: element (i, j), i <= j, at u[i + j ld] */
    const int ild = (int)ld;
    progress pr = {ctx, 0.0, (double)n * n * n / 3.0};
    if (cm_progress(ctx, "rbf factor", 0.0, pr.total) < 0) return CM_RBF_CHOLESKY_INTERRUPTED;

    /* 1. the first n1 columns, with their updates of A22 */
    for (int j = 0; j < n1; j += b0) {
        const int b = n1 - j < b0 ? n1 - j : b0;
        double *d = t + (size_t)j + (size_t)j * ld;
        lapack_int info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', b, d, ild);
        if (info != 0) return info > 0 ? j + (int)info : (int)info;
        const int below = n - j - b; /* rows under the diagonal block, into A21 */
        if (below > 0)
            cblas_dtrsm(CblasColMajor, CblasRight, CblasLower, CblasTrans, CblasNonUnit, below, b,
                        1.0, d, ild, d + b, ild);
        const int rest = n1 - j - b; /* columns of the tall block right of the panel */
        const double *lp = d + b;    /* L(j+b .. n-1, panel) */
        if (rest > 0) {
            double *c = t + (size_t)(j + b) + (size_t)(j + b) * ld;
            cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, rest, b, -1.0, lp, ild, 1.0, c,
                        ild);
            cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, n2, rest, b, -1.0, lp + rest, ild,
                        lp, ild, 1.0, c + rest, ild);
        }
        /* A22 -= L21(:, panel) L21(:, panel)' in its upper storage */
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, n2, b, -1.0, lp + rest, ild, 1.0, u,
                    ild);
        const double nb = b, nr = rest, n2d = n2;
        if (report(&pr, nb * nb * nb / 3.0 + (double)below * nb * nb + nr * nr * nb +
                            2.0 * n2d * nr * nb + n2d * n2d * nb))
            return CM_RBF_CHOLESKY_INTERRUPTED;
    }
    /* 2. A22 = U'U in place (upper), its rows and columns numbered from n1 */
    for (int j = 0; j < n2; j += b0) {
        const int b = n2 - j < b0 ? n2 - j : b0;
        double *d = u + (size_t)j + (size_t)j * ld;
        lapack_int info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'U', b, d, ild);
        if (info != 0) return info > 0 ? n1 + j + (int)info : (int)info;
        const int rest = n2 - j - b;
        if (rest > 0) {
            double *r = d + (size_t)b * ld; /* U(panel, j+b ..) */
            cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, b, rest,
                        1.0, d, ild, r, ild);
            cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, rest, b, -1.0, r, ild, 1.0,
                        r + b, ild);
        }
        const double nb = b, nr = rest;
        if (report(&pr, nb * nb * nb / 3.0 + nr * nb * nb + nr * nr * nb))
            return CM_RBF_CHOLESKY_INTERRUPTED;
    }
    return cm_progress(ctx, "rbf factor", pr.total, pr.total) < 0 ? CM_RBF_CHOLESKY_INTERRUPTED : 0;
}

/* Which of the two runs: on T > 1 BLAS threads and n from CM_LOOKAHEAD_MIN_N, the look-ahead
 * factorisation (cholesky_lookahead.c), which keeps the T cores busy while a panel is
 * factored instead of leaving all but one idle; on one thread, for small n, and inside a
 * parallel region (local factorisations side by side, where the team would be one thread
 * and OpenBLAS's count is the caller's business) the panel-by-panel path. */
int cm_rbf_cholesky_rfp(cm_context *ctx, int n, double *a, int block)
{
    int threads = openblas_get_num_threads();
    /* under ulimit -v, as many callers as have room for their buffers (core/platform/blas_threads.c) */
    if (threads > 1 && n >= CM_LOOKAHEAD_MIN_N && n <= CM_LOOKAHEAD_MAX_N && !omp_in_parallel())
        threads = cm_blas_callers(threads);
    else threads = 1;
    if (threads > 1) return cm_rbf_cholesky_rfp_lookahead(ctx, n, a, block, threads);
    return cm_rbf_cholesky_rfp_panels(ctx, n, a, block);
}
