/* OpenBLAS threads sized to the address space (blas.h, point 2): OpenBLAS 0.3.21 gives every
 * thread that runs BLAS a 128 MB buffer and retries a failed allocation forever, so a
 * thread count it cannot back is a hang, not an error. Before raising the count (or making
 * the first BLAS call) we check that the buffers fit under RLIMIT_AS by mapping that much
 * address space once and releasing it.
 *
 * The state is process-wide because OpenBLAS's is: its buffers and workers, once created,
 * live until exit. A mutex keeps two contexts from racing on it. */
#if defined(__linux__) && !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE /* MAP_ANONYMOUS, MAP_NORESERVE */
#endif
#include "cadmorph/blas.h"
#include "cm_platform.h"

#include <cblas.h>
#include <pthread.h>
#include <stdio.h>
#include <sys/mman.h>
#include <sys/resource.h>

/* 0.3.21's BUFFER_SIZE (32 << 22) plus its page alignment and header, rounded up; measured
 * here as 128 MB of VmSize per thread. */
#define CM_BLAS_BUFFER_BYTES ((size_t)132 << 20)
/* What else a new thread takes: its stack (RLIMIT_STACK, 8 MB by default) and a malloc
 * arena (64 MB reserved on first use) when OpenBLAS falls back to malloc. */
#define CM_BLAS_ARENA_BYTES ((size_t)64 << 20)
/* Left free for the caller's own allocations right after the check. */
#define CM_BLAS_MARGIN_BYTES ((size_t)16 << 20)

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static int known;        /* the fields below were initialised */
static int main_held;    /* the calling threads' buffer: assumed taken after our first call */
static int workers_held; /* OpenBLAS workers that exist (each with its buffer) */

static size_t stack_bytes(void)
{
    struct rlimit rl;
    size_t s = (size_t)8 << 20;
    if (getrlimit(RLIMIT_STACK, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY &&
        rl.rlim_cur < ((rlim_t)1 << 30))
        s = (size_t)rl.rlim_cur;
    return s;
}

/* Address space the process maps now (VmSize), 0 if unknown. */
static size_t mapped_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long pages = 0;
    if (!f) return 0;
    if (fscanf(f, "%lu", &pages) != 1) pages = 0;
    fclose(f);
    return (size_t)pages * 4096u;
}

/* Whether `bytes` more of address space can be mapped now. */
static int fits(size_t bytes)
{
    if (bytes == 0) return 1;
    void *p = mmap(NULL, bytes, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (p == MAP_FAILED) return 0;
    munmap(p, bytes);
    return 1;
}

/* Address space needed to run BLAS on t threads, given what OpenBLAS already holds. */
static size_t need_for(int t)
{
    size_t need = main_held ? 0 : CM_BLAS_BUFFER_BYTES;
    int extra = t - 1 - workers_held;
    if (extra > 0)
        need += (size_t)extra * (CM_BLAS_BUFFER_BYTES + CM_BLAS_ARENA_BYTES + stack_bytes());
    return need + CM_BLAS_MARGIN_BYTES;
}

cm_status cm_blas_threads(cm_context *ctx, const char *who, int want, int *got)
{
    if (want < 1) want = 1;
    pthread_mutex_lock(&lock);
    if (!known) {
        /* without OPENBLAS_NUM_THREADS=1 at load, OpenBLAS started its workers already */
        int n = openblas_get_num_threads();
        workers_held = n > 1 ? n - 1 : 0;
        known = 1;
    }
    struct rlimit rl;
    int limited = getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY;
    int t = want;
    /* one thread whose buffer OpenBLAS already holds needs nothing new */
    if (limited)
        while (t > 1 || (t == 1 && !main_held)) {
            if (fits(need_for(t))) break;
            --t;
        }
    if (t < 1) {
        size_t lim = limited ? (size_t)rl.rlim_cur : 0, used = mapped_bytes();
        pthread_mutex_unlock(&lock);
        if (got) *got = 0;
        return cm_error(ctx, CM_ERR_NOMEM,
                        "%s: out of memory: OpenBLAS needs %zu MB of address space for its "
                        "buffer, and the address-space limit (ulimit -v) of %zu MB leaves %zu MB",
                        who, need_for(1) >> 20, lim >> 20, used < lim ? (lim - used) >> 20 : 0);
    }
    main_held = 1;
    if (t - 1 > workers_held) workers_held = t - 1;
    openblas_set_num_threads(t);
    pthread_mutex_unlock(&lock);
    if (t < want)
        cm_log(ctx, CM_LOG_DEBUG,
               "%s: OpenBLAS on %d of %d threads: the address-space limit (ulimit -v) leaves "
               "no room for more of its 128 MB buffers",
               who, t, want);
    if (got) *got = t;
    return CM_OK;
}

/* OpenMP threads that call one-thread BLAS side by side (the RBF module's look-ahead Cholesky): besides
 * OpenBLAS's own workers, each such thread gets its own 128 MB buffer on its first call,
 * and keeps it (libgomp's threads live on). Granted once, a count stays granted. */
static int callers_held; /* threads besides the calling one known to hold a buffer */

int cm_blas_callers(int want)
{
    if (want <= 1) return want < 1 ? 1 : want;
    struct rlimit rl;
    if (getrlimit(RLIMIT_AS, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY) return want;
    pthread_mutex_lock(&lock);
    int t = want;
    while (t > 1 + callers_held) {
        size_t need = (size_t)(t - 1 - callers_held) *
                          (CM_BLAS_BUFFER_BYTES + CM_BLAS_ARENA_BYTES + stack_bytes()) +
                      CM_BLAS_MARGIN_BYTES;
        if (fits(need)) break;
        --t;
    }
    if (t - 1 > callers_held) callers_held = t - 1;
    pthread_mutex_unlock(&lock);
    return t;
}

cm_status cm_blas_reserve(cm_context *ctx, const char *who)
{
    return cm_blas_threads(ctx, who ? who : "cm_blas_reserve", openblas_get_num_threads(),
                               NULL);
}
