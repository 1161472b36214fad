/* The two triangular solves with an RFP Cholesky factor (dpftrs's job) on T OpenMP threads of
 * one-thread BLAS: for the few right-hand sides of an RBF solve they read the whole factor
 * twice and are memory-bound, and one core's share of the memory bandwidth is not the
 * machine's: at m = 5,000 the single-threaded dpftrs was the largest part of the solve.
 *
 * Blocks of CM_SOLVE_BLOCK columns, column-oriented in both directions so that every update
 * reads whole columns or whole rows of a block of the factor once: one thread solves the
 * diagonal block (dtrsm of bw x nrhs), then all of them apply its solution to the rest of the
 * right-hand side, each to its own contiguous range of rows (dgemm of rows x nrhs x bw).
 * Same storage and layout as cholesky_lookahead.c: L11 and L21 down the first n1 columns at
 * t, L22 = U' with U upper at u. */
#include "rbf_internal.h"

#include <cblas.h>
#include <lapacke.h>
#include <omp.h>

#define CM_SOLVE_BLOCK 256
/* below this many rows an update is one call: splitting it costs more than it saves */
#define CM_SOLVE_MIN_ROWS 256
/* dpftrs below this n: the factor fits in the caches and the barriers would dominate */
#define CM_SOLVE_MIN_N 1500

/* Rows [lo, hi) of the update split evenly over the team; this thread's part in *a, *b. */
static void my_rows(int lo, int hi, int *a, int *b)
{
    const int t = omp_get_num_threads(), id = omp_get_thread_num(), len = hi - lo;
    if (len < CM_SOLVE_MIN_ROWS * t) { /* one thread does it all */
        *a = id == 0 ? lo : hi;
        *b = hi;
        return;
    }
    *a = lo + (int)((long)len * id / t);
    *b = lo + (int)((long)len * (id + 1) / t);
}

int cm_rbf_rfp_solve(int n, int nrhs, const double *a, double *b, int ldb, int threads)
{
    if (n < 0 || nrhs < 0 || !a || !b || ldb < (n > 1 ? n : 1)) return -1;
    if (n == 0 || nrhs == 0) return 0;
    if (threads < 2 || n < CM_SOLVE_MIN_N || omp_in_parallel())
        return (int)LAPACKE_dpftrs_work(LAPACK_COL_MAJOR, 'N', 'L', n, nrhs, a, b, ldb);
    const int n2 = n / 2, n1 = n - n2, ld = n % 2 ? n : n + 1;
    const double *t = n % 2 ? a : a + 1, *u = n % 2 ? a + n : a;
    const int bs = CM_SOLVE_BLOCK;
    double *b2 = b + n1; /* the rows of A22 */
#define T(i, j) (t + (size_t)(i) + (size_t)(j) * (size_t)ld)
#define U(i, j) (u + (size_t)(i) + (size_t)(j) * (size_t)ld)
    const int saved = openblas_get_num_threads();
    openblas_set_num_threads(1);
#pragma omp parallel num_threads(threads)
    {
        int r0, r1;
        /* 1. L11 y1 = b1, and b2 -= L21 y1 with it: column blocks of the tall part */
        for (int c0 = 0; c0 < n1; c0 += bs) {
            const int bw = n1 - c0 < bs ? n1 - c0 : bs;
#pragma omp single
            cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasNoTrans, CblasNonUnit, bw, nrhs,
                        1.0, T(c0, c0), ld, b + c0, ldb);
            my_rows(c0 + bw, n, &r0, &r1);
            if (r1 > r0)
                cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, r1 - r0, nrhs, bw, -1.0,
                            T(r0, c0), ld, b + c0, ldb, 1.0, b + r0, ldb);
#pragma omp barrier
        }
        /* 2. U' y2 = b2: row blocks of U, each applied to the rows after it */
        for (int s0 = 0; s0 < n2; s0 += bs) {
            const int bw = n2 - s0 < bs ? n2 - s0 : bs;
#pragma omp single
            cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, bw, nrhs,
                        1.0, U(s0, s0), ld, b2 + s0, ldb);
            my_rows(s0 + bw, n2, &r0, &r1);
            if (r1 > r0)
                cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, r1 - r0, nrhs, bw, -1.0,
                            U(s0, r0), ld, b2 + s0, ldb, 1.0, b2 + r0, ldb);
#pragma omp barrier
        }
        /* 3. U x2 = y2: column blocks of U from the last, each applied to the rows before */
        for (int s0 = (n2 - 1) / bs * bs; s0 >= 0; s0 -= bs) {
            const int bw = n2 - s0 < bs ? n2 - s0 : bs;
#pragma omp single
            cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasNoTrans, CblasNonUnit, bw,
                        nrhs, 1.0, U(s0, s0), ld, b2 + s0, ldb);
            my_rows(0, s0, &r0, &r1);
            if (r1 > r0)
                cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, r1 - r0, nrhs, bw, -1.0,
                            U(r0, s0), ld, b2 + s0, ldb, 1.0, b2 + r0, ldb);
#pragma omp barrier
        }
        /* 4. b1 -= L21' x2, each thread its columns of L21 */
        my_rows(0, n1, &r0, &r1);
        if (r1 > r0 && n2 > 0)
            cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, r1 - r0, nrhs, n2, -1.0,
                        T(n1, r0), ld, b2, ldb, 1.0, b + r0, ldb);
#pragma omp barrier
        /* 5. L11' x1 = b1: row blocks of L11 from the last, each applied to the rows before */
        for (int c0 = (n1 - 1) / bs * bs; c0 >= 0; c0 -= bs) {
            const int bw = n1 - c0 < bs ? n1 - c0 : bs;
#pragma omp single
            cblas_dtrsm(CblasColMajor, CblasLeft, CblasLower, CblasTrans, CblasNonUnit, bw, nrhs,
                        1.0, T(c0, c0), ld, b + c0, ldb);
            my_rows(0, c0, &r0, &r1);
            if (r1 > r0)
                cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, r1 - r0, nrhs, bw, -1.0,
                            T(c0, r0), ld, b + c0, ldb, 1.0, b + r0, ldb);
#pragma omp barrier
        }
    }
#undef T
#undef U
    openblas_set_num_threads(saved);
    return 0;
}
