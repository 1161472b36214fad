/* What the once-per-process timing probes share: the thread's CPU clock and a fixed test
 * problem. A leaf: the probes of the kernel sums (rbf_sum_avx512.c) and of AUTO's rates
 * (iterative/rbf_auto_probe.c) both use it, and it uses neither. */
#include "rbf_internal.h"

#include <math.h>
#include <time.h>

/* CPU time of the calling thread: on a loaded machine a wall-clock probe of a few ms is
 * often preempted (measured at load 11: dgemm 16 GF/s by wall clock, 60 by thread CPU
 * time), and the probe runs on this thread alone (one BLAS thread, threads = 1) */
double cm_rbf_thread_seconds(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return cm_wtime();
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cm_rbf_probe_data(size_t m, double *c, double *w, size_t n, double *p)
{
    /* a fixed low-discrepancy sequence over the unit cube, weights of alternating sign */
    for (size_t j = 0; j < m; ++j)
        for (int k = 0; k < 3; ++k) {
            c[k * m + j] = fmod(0.5 + (double)j * (0.7548776662 + 0.1 * k), 1.0);
            w[k * m + j] = (j % 2 ? -1.0 : 1.0) * (1.0 + 0.001 * k);
        }
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) p[k * n + i] = fmod(0.25 + (double)i * (0.5698402910 + 0.1 * k), 1.0);
}
