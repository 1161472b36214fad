/* The panel-by-panel RFP Cholesky (rbf/dense/cholesky_blocked.c) against LAPACK's dpftrf on random
 * SPD matrices: odd and even n, n below, at and off multiples of the block; the pivot of an
 * indefinite matrix; progress monotonic up to its total. */
#include "rbf_internal.h"
#include "cholesky_test_util.h"
#include "test_util.h"

#include <lapacke.h>
#include <stdlib.h>
#include <string.h>

static uint64_t rng = 0x2545F4914F6CDD1DULL;

/* Full n x n col-major SPD matrix B B'/n + I (+ shift on the diagonal at `bad`, if >= 0). */
static double *spd(int n, int bad)
{
    double *b = malloc((size_t)n * n * sizeof *b), *a = calloc((size_t)n * n, sizeof *a);
    for (size_t i = 0; i < (size_t)n * n; ++i) b[i] = chol_urand(&rng);
    for (int j = 0; j < n; ++j)
        for (int i = j; i < n; ++i) {
            double s = 0.0;
            for (int k = 0; k < n; ++k) s += b[i + (size_t)k * n] * b[j + (size_t)k * n];
            a[i + (size_t)j * n] = a[j + (size_t)i * n] = s / n + (i == j ? 1.0 : 0.0);
        }
    if (bad >= 0) a[bad + (size_t)bad * n] = -1e3; /* leading minor of order bad+1 fails */
    free(b);
    return a;
}

static void check_size(int n, int block)
{
    double *full = spd(n, -1);
    size_t len = (size_t)n * (n + 1) / 2;
    double *ref = malloc(len * sizeof *ref), *got = malloc(len * sizeof *got);
    CHECK(LAPACKE_dtrttf(LAPACK_COL_MAJOR, 'N', 'L', n, full, n, ref) == 0);
    memcpy(got, ref, len * sizeof *got);
    CHECK(LAPACKE_dpftrf(LAPACK_COL_MAJOR, 'N', 'L', n, ref) == 0);

    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    calls c = {0, 1, 1, 0.0, 0.0};
    cm_context_set_progress(ctx, on_progress, &c);
    int info = cm_rbf_cholesky_rfp(ctx, n, got, block);
    CHECK_MSG(info == 0, "n %d block %d: info %d", n, block, info);
    double diff = 0.0, big = 0.0;
    for (size_t i = 0; i < len; ++i) {
        diff = fmax(diff, fabs(got[i] - ref[i]));
        big = fmax(big, fabs(ref[i]));
    }
    /* same arithmetic in another order: round-off of a well-conditioned factor */
    CHECK_MSG(diff <= 1e-12 * big, "n %d block %d: max diff %.3g of %.3g", n, block, diff, big);
    /* one call at 0, one per panel, one at the end */
    const int bs = block > 0 ? block : 256; /* the default of cholesky_blocked.c */
    int panels = (n / 2 + bs - 1) / bs + (n - n / 2 + bs - 1) / bs;
    CHECK_MSG(c.count >= panels + 1, "n %d block %d: %d progress calls, %d panels", n, block,
              c.count, panels);
    CHECK(c.monotonic);
    CHECK(c.stage_ok);
    CHECK_NEAR(c.last, c.total, 0.0);
    CHECK(c.total > 0.0);
    cm_context_destroy(&ctx);
    free(full), free(ref), free(got);
}

/* An indefinite matrix: both report the same failing leading minor. */
static void check_pivot(int n, int bad, int block)
{
    double *full = spd(n, bad);
    size_t len = (size_t)n * (n + 1) / 2;
    double *ref = malloc(len * sizeof *ref), *got = malloc(len * sizeof *got);
    LAPACKE_dtrttf(LAPACK_COL_MAJOR, 'N', 'L', n, full, n, ref);
    memcpy(got, ref, len * sizeof *got);
    int want = LAPACKE_dpftrf(LAPACK_COL_MAJOR, 'N', 'L', n, ref);
    int info = cm_rbf_cholesky_rfp(NULL, n, got, block);
    CHECK_MSG(want == bad + 1 && info == want, "n %d bad %d: dpftrf %d, blocked %d", n, bad, want,
              info);
    free(full), free(ref), free(got);
}

/* The call site: cm_rbf_create reports the factorisation panel by panel. */
static void check_create(void)
{
    const size_t m = 1500;
    double *c = malloc(m * 3 * sizeof *c);
    for (size_t i = 0; i < 3 * m; ++i) c[i] = chol_urand(&rng);
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    calls k = {0, 1, 1, 0.0, 0.0};
    cm_context_set_progress(ctx, on_progress, &k);
    cm_rbf *rbf = NULL;
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &rbf) == CM_OK);
    /* n = m - 4 = 1496: 3 + 3 panels of 256, plus the calls at 0 and at the end */
    CHECK_MSG(k.count >= 7, "%d progress calls", k.count);
    CHECK(k.monotonic && k.stage_ok);
    CHECK_NEAR(k.last, k.total, 0.0);
    cm_rbf_destroy(&rbf);
    cm_context_destroy(&ctx);
    free(c);
}

int main(void)
{
    const int sizes[] = {1, 2, 3, 7, 16, 33, 64, 65, 100, 127, 128, 129, 301, 512, 513};
    for (size_t i = 0; i < sizeof sizes / sizeof *sizes; ++i) {
        check_size(sizes[i], 16);
        check_size(sizes[i], 7);
    }
    check_size(1000, 0);   /* the default block: 2 panels a half */
    check_size(1001, 0);
    check_size(777, 100);
    check_pivot(200, 0, 16);    /* first column */
    check_pivot(200, 37, 16);   /* inside the first half */
    check_pivot(201, 150, 16);  /* inside A22 */
    check_pivot(201, 200, 16);  /* last pivot */
    CHECK(cm_rbf_cholesky_rfp(NULL, 0, &(double){1.0}, 0) == 0);
    check_create();
    return TEST_REPORT();
}
