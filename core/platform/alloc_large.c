/* Large buffers, such as the RBF solvers' (the dense factor, the local factors of the Schwarz
 * preconditioner, its coarse factor and the Krylov bases): 10^8..10^10 bytes at m = 10^5..10^6.
 *
 * Why: the VMs we run on back guest memory on first touch and take freed memory back, so
 * every fresh buffer is faulted in again in every fit. Page by page (4 kB) that cost about
 * 2 s per GB on two threads here (benchmarks/rbf/bench_first_touch.c, Zen 5: 1.6 GB in
 * 2.7-3.4 s); marked for transparent huge pages, 0.6-1.7 s, and almost nothing when the
 * freed huge pages of an earlier fit are still backed. Huge pages also spare the BLAS and
 * the streaming local solves TLB misses. Both calls are hints: where they fail the memory
 * is faulted in as usual. */
#if defined(__linux__) && !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE /* madvise(MADV_HUGEPAGE) */
#endif
#include "cm_platform.h"

#include <stdint.h>
#include <stdlib.h>

#ifdef __linux__
#include <sys/mman.h>
#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23 /* Linux 5.14; older kernels return EINVAL, harmless */
#endif
#endif

void *cm_alloc_large(size_t bytes, int populate)
{
    const size_t huge = (size_t)2 << 20;
    if (bytes < huge) return malloc(bytes ? bytes : 1);
    if (bytes > SIZE_MAX - huge) return NULL;
    bytes = (bytes + huge - 1) / huge * huge; /* aligned_alloc: a multiple of the alignment */
    void *p = aligned_alloc(huge, bytes);
#ifdef __linux__
#ifdef MADV_HUGEPAGE
    if (p) (void)madvise(p, bytes, MADV_HUGEPAGE);
#endif
    if (p && populate) (void)madvise(p, bytes, MADV_POPULATE_WRITE);
#else
    (void)populate;
#endif
    return p;
}
