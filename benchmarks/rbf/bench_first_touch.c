/* First touch of fresh memory, 4 kB pages against transparent huge pages: the probe behind
 * cm_alloc_large (core/platform/alloc_large.c; benchmarks/RESULTS.md, RBF solvers). Allocates
 * MB megabytes on 2 MB boundaries, optionally madvise(MADV_HUGEPAGE) and MADV_POPULATE_WRITE,
 * then writes one byte per 4 kB page from all OpenMP threads. Run it in fresh processes and
 * in varied order: on the VMs we run on, memory freed by the previous process is still
 * backed for a few seconds.
 * usage: bench_first_touch MB HUGE(0|1) POPULATE(0|1) */
#define _DEFAULT_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>

#include <omp.h>

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23
#endif

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: bench_first_touch MB HUGE(0|1) POPULATE(0|1)\n");
        return 2;
    }
    const size_t mb = (size_t)atol(argv[1]), n = mb << 20;
    const int huge = atoi(argv[2]), populate = atoi(argv[3]);
    char *p = NULL;
    if (n == 0 || posix_memalign((void **)&p, (size_t)2 << 20, n) != 0) return 1;
    double t0 = omp_get_wtime();
    if (huge) (void)madvise(p, n, MADV_HUGEPAGE);
    if (populate) (void)madvise(p, n, MADV_POPULATE_WRITE);
    double t1 = omp_get_wtime();
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i += 4096) p[i] = 1;
    double t2 = omp_get_wtime();
    printf("mb=%zu huge=%d populate=%d threads=%d madvise_s=%.3f touch_s=%.3f total_s=%.3f\n", mb,
           huge, populate, omp_get_max_threads(), t1 - t0, t2 - t1, t2 - t0);
    free(p);
    return 0;
}
