/* The rates that AUTO's cost model (cm_rbf_auto_dense, rbf_auto.c) weighs: dgemm flops
 * per second and r^3 kernel pairs per second, plain and compensated, of one thread, timed
 * once per process on small problems (about 10 ms in all). Why measured, not constants: the
 * crossover of the two solvers moves with the BLAS core (Haswell's dgemm runs at half the
 * rate of the AVX-512 kernels here) and with the kernel-sum code (AVX2 or AVX-512 blocks),
 * and the dense/iterative balance follows the ratio of the two rates. */
#include "rbf_internal.h"

#include <cblas.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>

static double rate_gemm, rate_plain, rate_acc;
static pthread_once_t probe_once = PTHREAD_ONCE_INIT;

#define PROBE_GEMM 384  /* n of the n x n x n dgemm: large enough for OpenBLAS's full rate */
#define PROBE_M 2048    /* centres of the kernel-sum probe */
#define PROBE_N 256     /* points */

static void probe(void)
{
    const int n = PROBE_GEMM;
    double *a = malloc(3 * (size_t)n * n * sizeof *a);
    double *c = malloc((size_t)(6 * PROBE_M + 3 * PROBE_N + 3 * PROBE_N) * sizeof *c);
    if (!a || !c) {
        free(a), free(c);
        return; /* the rates stay 0: the caller falls back to its constants */
    }
    double *b = a + (size_t)n * n, *d = b + (size_t)n * n;
    for (size_t i = 0; i < (size_t)n * n; ++i) a[i] = 1.0 / (1.0 + (double)(i % 13)), b[i] = 0.5;
    double best = INFINITY;
    for (int r = 0; r < 4; ++r) {
        const double t = cm_rbf_thread_seconds();
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, n, n, n, 1.0, a, n, b, n, 0.0, d,
                    n);
        best = fmin(best, cm_rbf_thread_seconds() - t);
    }
    if (best > 0.0) rate_gemm = 2.0 * n * (double)n * n / best;

    double *w = c + 3 * PROBE_M, *p = w + 3 * PROBE_M, *out = p + 3 * PROBE_N;
    cm_rbf_probe_data(PROBE_M, c, w, PROBE_N, p);
    const double pairs = (double)PROBE_M * PROBE_N;
    double bp = INFINITY, ba = INFINITY;
    for (int r = 0; r < 4; ++r) {
        double t = cm_rbf_thread_seconds();
        cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, PROBE_M, c, w, 3, PROBE_N, p, PROBE_N, out, 3, 1);
        bp = fmin(bp, cm_rbf_thread_seconds() - t);
        t = cm_rbf_thread_seconds();
        cm_rbf_kernel_sum_acc(PROBE_M, c, w, 3, PROBE_N, p, PROBE_N, out, 3, 1);
        ba = fmin(ba, cm_rbf_thread_seconds() - t);
    }
    if (bp > 0.0) rate_plain = pairs / bp;
    if (ba > 0.0) rate_acc = pairs / ba;
    free(a), free(c);
}

void cm_rbf_auto_rates(double *gemm, double *plain, double *acc)
{
    pthread_once(&probe_once, probe);
    *gemm = rate_gemm, *plain = rate_plain, *acc = rate_acc;
}
