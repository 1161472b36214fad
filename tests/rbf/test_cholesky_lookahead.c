/* The look-ahead RFP Cholesky (rbf/dense/cholesky_lookahead.c) against LAPACK's dpftrf on random
 * SPD matrices on 1, 2 and 3 threads: the factors agree to round-off and A - LL' is at
 * round-off; odd and even n, n below a block, blocks that straddle the two halves of the RFP
 * layout, many update chunks per step; the failing pivot of an indefinite matrix (info as
 * dpftrf's); progress monotonic up to its total; OpenBLAS's thread count restored; and which
 * path cm_rbf_cholesky_rfp takes. */
#if defined(__linux__) && !defined(_DEFAULT_SOURCE)
#define _DEFAULT_SOURCE /* fork, waitpid, setrlimit */
#endif
#include "rbf_internal.h"
#include "cholesky_test_util.h"
#include "test_util.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cblas.h>
#include <lapacke.h>
#include <stdlib.h>
#include <string.h>

static uint64_t rng = 0x9E3779B97F4A7C15ULL;

/* Full n x n col-major SPD B B'/n + I (by dsyrk: the large sizes stay fast), with -1e3 on the
 * diagonal at `bad` if >= 0, so that the leading minor of order bad + 1 is the first that
 * fails. Both triangles filled. */
static double *spd(int n, int bad)
{
    double *b = malloc((size_t)n * n * sizeof *b), *a = calloc((size_t)n * n, sizeof *a);
    for (size_t i = 0; i < (size_t)n * n; ++i)
        b[i] = chol_urand(&rng);
    openblas_set_num_threads(1);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, n, n, 1.0 / n, b, n, 0.0, a, n);
    for (int j = 0; j < n; ++j) {
        a[j + (size_t)j * n] += 1.0;
        for (int i = j + 1; i < n; ++i)
            a[j + (size_t)i * n] = a[i + (size_t)j * n];
    }
    if (bad >= 0) a[bad + (size_t)bad * n] = -1e3;
    free(b);
    return a;
}

/* max |A - L L'| over the lower triangle / max |A|, L from the RFP factor f */
static double residual(int n, const double *full, const double *f)
{
    double *l = calloc((size_t)n * n, sizeof *l), *r = malloc((size_t)n * n * sizeof *r);
    LAPACKE_dtfttr(LAPACK_COL_MAJOR, 'N', 'L', n, f, l, n);
    for (int j = 0; j < n; ++j) /* dtfttr leaves the strict upper part alone: zero it */
        for (int i = 0; i < j; ++i)
            l[i + (size_t)j * n] = 0.0;
    memcpy(r, full, (size_t)n * n * sizeof *r);
    cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, n, n, -1.0, l, n, 1.0, r, n);
    double worst = 0.0, big = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = j; i < n; ++i) {
            worst = fmax(worst, fabs(r[i + (size_t)j * n]));
            big = fmax(big, fabs(full[i + (size_t)j * n]));
        }
    free(l), free(r);
    return worst / big;
}

static double max_rel_diff(size_t len, const double *a, const double *ref)
{
    double diff = 0.0, big = 0.0;
    for (size_t i = 0; i < len; ++i) {
        diff = fmax(diff, fabs(a[i] - ref[i]));
        big = fmax(big, fabs(ref[i]));
    }
    return diff / big;
}

static void check_size(int n, int block)
{
    double *full = spd(n, -1);
    const size_t len = (size_t)n * (n + 1) / 2;
    double *ref = malloc(len * sizeof *ref), *got = malloc(len * sizeof *got);
    double *one = malloc(len * sizeof *one), *orig = malloc(len * sizeof *orig);
    CHECK(LAPACKE_dtrttf(LAPACK_COL_MAJOR, 'N', 'L', n, full, n, orig) == 0);
    memcpy(ref, orig, len * sizeof *ref);
    openblas_set_num_threads(1);
    CHECK(LAPACKE_dpftrf(LAPACK_COL_MAJOR, 'N', 'L', n, ref) == 0);
    const double res_ref = residual(n, full, ref);
    for (int threads = 1; threads <= 3; ++threads) {
        cm_context *ctx = NULL;
        cm_context_create(&ctx);
        calls c = {0, 1, 1, 0.0, 0.0};
        cm_context_set_progress(ctx, on_progress, &c);
        memcpy(got, orig, len * sizeof *got);
        openblas_set_num_threads(2); /* the caller's count, to be restored */
        int info = cm_rbf_cholesky_rfp_lookahead(ctx, n, got, block, threads);
        CHECK_MSG(info == 0, "n %d block %d threads %d: info %d", n, block, threads, info);
        CHECK_MSG(openblas_get_num_threads() == 2, "n %d threads %d: OpenBLAS left on %d", n,
                  threads, openblas_get_num_threads());
        /* the same arithmetic in another order: round-off of a well-conditioned factor */
        double d = max_rel_diff(len, got, ref);
        CHECK_MSG(d <= 1e-12, "n %d block %d threads %d: factor differs from dpftrf's by %.3g", n,
                  block, threads, d);
        double res = residual(n, full, got);
        CHECK_MSG(res <= 1e-13 && res <= 10.0 * res_ref + 1e-15,
                  "n %d block %d threads %d: |A - LL'| %.3g (dpftrf %.3g)", n, block, threads, res,
                  res_ref);
        /* the cuts of every step depend on n and the block only: the same factor on any
         * thread count, up to the round-off OpenBLAS might add (none seen) */
        if (threads == 1)
            memcpy(one, got, len * sizeof *one);
        else {
            double dt = max_rel_diff(len, got, one);
            CHECK_MSG(dt <= 1e-15, "n %d block %d: %d threads vs 1 differ by %.3g", n, block,
                      threads, dt);
        }
        const int bs = block > 0 ? block : 192; /* cholesky_lookahead.c's default */
        const int blocks = (n - n / 2 + bs - 1) / bs + (n / 2 + bs - 1) / bs;
        CHECK_MSG(c.count >= blocks + 1, "n %d block %d: %d progress calls, %d blocks", n, block,
                  c.count, blocks);
        CHECK(c.monotonic && c.stage_ok);
        CHECK_NEAR(c.last, c.total, 0.0);
        CHECK(c.total > 0.0);
        cm_context_destroy(&ctx);
    }
    free(full), free(ref), free(got), free(one), free(orig);
}

/* An indefinite matrix: the same failing leading minor as dpftrf on every thread count. */
static void check_pivot(int n, int bad, int block)
{
    double *full = spd(n, bad);
    const size_t len = (size_t)n * (n + 1) / 2;
    double *ref = malloc(len * sizeof *ref), *got = malloc(len * sizeof *got);
    double *orig = malloc(len * sizeof *orig);
    LAPACKE_dtrttf(LAPACK_COL_MAJOR, 'N', 'L', n, full, n, orig);
    memcpy(ref, orig, len * sizeof *ref);
    int want = LAPACKE_dpftrf(LAPACK_COL_MAJOR, 'N', 'L', n, ref);
    CHECK_MSG(want == bad + 1, "n %d bad %d: dpftrf %d", n, bad, want);
    for (int threads = 1; threads <= 2; ++threads) {
        memcpy(got, orig, len * sizeof *got);
        int info = cm_rbf_cholesky_rfp_lookahead(NULL, n, got, block, threads);
        CHECK_MSG(info == want, "n %d bad %d block %d threads %d: dpftrf %d, look-ahead %d", n, bad,
                  block, threads, want, info);
    }
    free(full), free(ref), free(got), free(orig);
}

/* cm_rbf_cholesky_rfp: the look-ahead path on 2 BLAS threads inside its range (the same bits
 * as calling it directly), the panel path on one, and the count restored either way. */
static void check_dispatch(int n)
{
    const size_t len = (size_t)n * (n + 1) / 2;
    double *full = malloc((size_t)n * n * sizeof *full);
    double *orig = malloc(len * sizeof *orig), *a = malloc(len * sizeof *a);
    double *b = malloc(len * sizeof *b);
    /* 1 / (1 + |i - j|) + n [i = j]: diagonally dominant, and cheap at n = 4000 */
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            full[i + (size_t)j * n] = 1.0 / (1.0 + abs(i - j)) + (i == j ? n : 0.0);
    LAPACKE_dtrttf(LAPACK_COL_MAJOR, 'N', 'L', n, full, n, orig);
    const int in_range = n >= CM_LOOKAHEAD_MIN_N && n <= CM_LOOKAHEAD_MAX_N;
    for (int threads = 1; threads <= 2; ++threads) {
        memcpy(a, orig, len * sizeof *a);
        memcpy(b, orig, len * sizeof *b);
        openblas_set_num_threads(threads);
        CHECK(cm_rbf_cholesky_rfp(NULL, n, a, 0) == 0);
        CHECK(openblas_get_num_threads() == threads);
        if (threads > 1 && in_range)
            cm_rbf_cholesky_rfp_lookahead(NULL, n, b, 0, threads);
        else
            cm_rbf_cholesky_rfp_panels(NULL, n, b, 0);
        CHECK(openblas_get_num_threads() == threads);
        CHECK_MSG(memcmp(a, b, len * sizeof *a) == 0, "n %d threads %d: not the expected path", n,
                  threads);
    }
    free(full), free(orig), free(a), free(b);
}

/* Under an address-space limit with no room for a second OpenBLAS buffer the look-ahead is
 * not taken (its second thread's first BLAS call would spin forever in OpenBLAS's
 * allocation): cm_blas_callers says 1. In a child, which the limit must not outlive. */
static void check_ulimit(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long pages = 0;
    if (!f || fscanf(f, "%lu", &pages) != 1) {
        if (f) fclose(f);
        return; /* not Linux: nothing to check */
    }
    fclose(f);
    CHECK(cm_blas_callers(2) == 2); /* no limit here */
    pid_t pid = fork();
    if (pid == 0) {
        /* 100 MB more than mapped now: less than one more 128 MB buffer */
        struct rlimit rl;
        getrlimit(RLIMIT_AS, &rl);
        rl.rlim_cur = (rlim_t)pages * 4096u + ((rlim_t)100 << 20);
        if (setrlimit(RLIMIT_AS, &rl) != 0) _exit(4);
        _exit(cm_blas_callers(2) == 1 ? 0 : 5);
    }
    int status = 0;
    CHECK(pid > 0 && waitpid(pid, &status, 0) == pid);
    CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "child: status %d", status);
}

int main(void)
{
    const int sizes[] = {1, 2, 3, 7, 16, 33, 64, 65, 100, 129, 301, 513};
    for (size_t i = 0; i < sizeof sizes / sizeof *sizes; ++i) {
        check_size(sizes[i], 16);
        check_size(sizes[i], 7);
    }
    check_size(150, 0);  /* n below the default block: one block a half */
    check_size(1200, 0); /* default block; steps with several chunks of >= 256 columns */
    check_size(1201, 48);
    check_size(997, 100);      /* the last block of each half narrower */
    check_pivot(200, 0, 16);   /* first column */
    check_pivot(200, 37, 16);  /* inside the first half */
    check_pivot(200, 48, 16);  /* first column of a block (the look-ahead's panel) */
    check_pivot(201, 101, 16); /* first column of A22 */
    check_pivot(201, 150, 16); /* inside A22 */
    check_pivot(201, 200, 16); /* last pivot */
    check_pivot(1001, 700, 0);
    CHECK(cm_rbf_cholesky_rfp_lookahead(NULL, 0, &(double){1.0}, 0, 2) == 0);
    CHECK(cm_rbf_cholesky_rfp_lookahead(NULL, -1, &(double){1.0}, 0, 2) < 0);
    check_dispatch(CM_LOOKAHEAD_MIN_N - 1);
    check_dispatch(CM_LOOKAHEAD_MIN_N);
    check_ulimit();
    return TEST_REPORT();
}
