/* The RFP Cholesky of cholesky_blocked.c on T OpenMP threads that each call single-threaded
 * BLAS, with a look-ahead of one panel, for the n where OpenBLAS's own threading leaves a
 * core idle.
 *
 * Why: at n = 5,000 on 2 threads dpftrf and the panel-by-panel factorisation both took
 * 1.25 x the bound n^3/3 at the dgemm rate, against 1.15 on one thread: every panel step
 * (dpotrf of b x b, dtrsm of the column below) runs while the second core waits, and the
 * trailing updates are too small for OpenBLAS to split well. Here the columns are cut into
 * the same kind of blocks as in cholesky_blocked.c (the first n1 columns, then the n2 of
 * A22, in widths of `block`), and step k applies the factored panel k to everything on its
 * right: one thread first updates block k+1 and factors it (dpotrf + dtrsm), the next
 * panel, while the other threads take the rest of the update in tasks of a few hundred
 * columns (dynamic schedule, see make_tasks), and that thread joins them when its panel is
 * done. So the panel work of step k+1 hides behind the updates of step k, and no thread
 * waits except at the one barrier per step.
 *
 * Same arithmetic as dpftrf in another order (every update is panel k applied to a set of
 * columns, by dsyrk on the diagonal and dgemm off it), same storage, and the result does not
 * depend on which thread ran which task: the tasks are cut from n, the block and the step
 * alone, and a one-thread BLAS call computes the same bits whoever makes it, so the factor is
 * the same on every T. */
#include "rbf_internal.h"

#include <cblas.h>
#include <lapacke.h>
#include <omp.h>

#define CM_LOOKAHEAD_BLOCK 192

#include <time.h>

/* The task trace (rbf_internal.h): every task timed by its thread's CPU clock while a
 * benchmark has set the hook (a schedule model that the other jobs on a shared machine do
 * not disturb); one test of a NULL pointer per task otherwise. */
void (*cm_lookahead_trace_hook)(int step, int kind, double cpu_seconds);
static double trace_clock(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
#define TRACE_START() const double trace_t0 = cm_lookahead_trace_hook ? trace_clock() : 0.0
#define TRACE_END(step, kind)                                                             \
    do {                                                                                  \
        if (cm_lookahead_trace_hook)                                                      \
            cm_lookahead_trace_hook(step, kind, trace_clock() - trace_t0);                \
    } while (0)
#ifndef CM_LOOKAHEAD_MIN_CHUNK
#define CM_LOOKAHEAD_MIN_CHUNK 256
#endif
#ifndef CM_LOOKAHEAD_TRSM_LEAF
#define CM_LOOKAHEAD_TRSM_LEAF 64
#endif

/* The logical n x n lower triangle in RFP (TRANSR 'N', UPLO 'L'): columns j < n1 stored
 * down column j of t (element (i, j) at t[i + j ld], i >= j, rows to n-1), columns j >= n1
 * as the upper triangle of A22 at u (element (i, j), i >= j >= n1, at
 * u[(j - n1) + (i - n1) ld]), so a block of A22's logical columns is a block of u's rows. */
typedef struct rfp {
    int n, n1, ld, b, nb1, nblocks;
    double *t, *u;
} rfp;

static void block_range(const rfp *r, int q, int *c0, int *c1)
{
    if (q < r->nb1) {
        *c0 = q * r->b;
        *c1 = *c0 + r->b < r->n1 ? *c0 + r->b : r->n1;
    } else {
        *c0 = r->n1 + (q - r->nb1) * r->b;
        *c1 = *c0 + r->b < r->n ? *c0 + r->b : r->n;
    }
}

static double *at_t(const rfp *r, int i, int j)
{
    return r->t + (size_t)i + (size_t)j * r->ld;
}
/* u's element (p, q) in A22's own numbering */
static double *at_u(const rfp *r, int p, int q)
{
    return r->u + (size_t)p + (size_t)q * r->ld;
}

/* B (m x nb) := B L^-T, L lower nb x nb: the dtrsm of a tall panel, split in halves down to
 * CM_LOOKAHEAD_TRSM_LEAF columns so that most of it runs as dgemm. Why: one-thread dtrsm of
 * 3000 x 192 ran at 42 GF/s on Zen 5 against dgemm's 90, and the panels' dtrsm is ~6 % of
 * the flops; the split is the usual recursive formulation, same arithmetic to rounding. */
static void trsm_rlt(int m, int nb, const double *l, int ldl, double *b, int ldb)
{
    if (nb <= CM_LOOKAHEAD_TRSM_LEAF) {
        cblas_dtrsm(CblasColMajor, CblasRight, CblasLower, CblasTrans, CblasNonUnit, m, nb, 1.0, l,
                    ldl, b, ldb);
        return;
    }
    const int h = (nb / 2 + 7) / 8 * 8; /* halves on multiples of 8: the kernels' unroll */
    double *b2 = b + (size_t)h * ldb;
    trsm_rlt(m, h, l, ldl, b, ldb);
    cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, m, nb - h, h, -1.0, b, ldb, l + h, ldl,
                1.0, b2, ldb);
    trsm_rlt(m, nb - h, l + h + (size_t)h * ldl, ldl, b2, ldb);
}

/* B (nb x m) := U^-T B, U upper nb x nb: the same for a panel of A22 (rows of u). */
static void trsm_lut(int nb, int m, const double *u, int ldu, double *b, int ldb)
{
    if (nb <= CM_LOOKAHEAD_TRSM_LEAF) {
        cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, nb, m, 1.0, u,
                    ldu, b, ldb);
        return;
    }
    const int h = (nb / 2 + 7) / 8 * 8;
    trsm_lut(h, m, u, ldu, b, ldb);
    cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, nb - h, m, h, -1.0, u + (size_t)h * ldu,
                ldu, b, ldb, 1.0, b + h, ldb);
    trsm_lut(nb - h, m, u + h + (size_t)h * ldu, ldu, b + h, ldb);
}

/* Factors block q (its columns already updated by every panel on its left): dpotrf of the
 * diagonal block, dtrsm of the rest of its columns. Returns 0 or dpftrf's info (1-based
 * column of the failing leading minor). */
static int factor_block(const rfp *r, int q)
{
    int c0, c1;
    block_range(r, q, &c0, &c1);
    const int bw = c1 - c0, rest = r->n - c1;
    lapack_int info;
    if (q < r->nb1) {
        double *d = at_t(r, c0, c0);
        info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', bw, d, r->ld);
        if (info == 0 && rest > 0) trsm_rlt(rest, bw, d, r->ld, d + bw, r->ld);
    } else {
        const int p0 = c0 - r->n1;
        double *d = at_u(r, p0, p0);
        info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'U', bw, d, r->ld);
        if (info == 0 && rest > 0) trsm_lut(bw, rest, d, r->ld, d + (size_t)bw * r->ld, r->ld);
    }
    return info > 0 ? c0 + (int)info : (int)info;
}

/* Columns c0..c1-1 (right of panel k; may straddle n1) -= (panel k) (panel k)' restricted to
 * them: dsyrk on the diagonal block, dgemm below (tall part) or right of it (A22's rows). */
static void update_range(const rfp *r, int k, int c0, int c1)
{
    int p0, p1;
    block_range(r, k, &p0, &p1);
    const int bk = p1 - p0, ld = r->ld;
    if (k < r->nb1 && c0 < r->n1) { /* columns of the tall part: down the columns */
        const int e = c1 < r->n1 ? c1 : r->n1, bw = e - c0, rest = r->n - e;
        const double *x = at_t(r, c0, p0); /* L(c0..e-1, panel) */
        cblas_dsyrk(CblasColMajor, CblasLower, CblasNoTrans, bw, bk, -1.0, x, ld, 1.0,
                    at_t(r, c0, c0), ld);
        if (rest > 0)
            cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, rest, bw, bk, -1.0, at_t(r, e, p0),
                        ld, x, ld, 1.0, at_t(r, e, c0), ld);
        c0 = e;
    }
    if (c0 >= c1) return;
    /* columns of A22 = rows s0..s1-1 of u, and everything right of them */
    const int s0 = c0 - r->n1, s1 = c1 - r->n1, bw = c1 - c0, rest = r->n - c1;
    if (k < r->nb1) { /* L(c0.., panel) down the tall part's panel columns */
        const double *x = at_t(r, c0, p0);
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, bw, bk, -1.0, x, ld, 1.0,
                    at_u(r, s0, s0), ld);
        if (rest > 0)
            cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, bw, rest, bk, -1.0, x, ld,
                        at_t(r, c1, p0), ld, 1.0, at_u(r, s0, s1), ld);
    } else { /* a panel of A22: rows k0.. of u */
        const int k0 = p0 - r->n1;
        const double *x = at_u(r, k0, s0);
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, bw, bk, -1.0, x, ld, 1.0,
                    at_u(r, s0, s0), ld);
        if (rest > 0)
            cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, bw, rest, bk, -1.0, x, ld,
                        at_u(r, k0, s1), ld, 1.0, at_u(r, s0, s1), ld);
    }
}

static void update_block(const rfp *r, int k, int q)
{
    int c0, c1;
    block_range(r, q, &c0, &c1);
    update_range(r, k, c0, c1);
}

/* Columns j0..j1-1 of u (logical rows n1+j0..), rows s..j1-1 of them, -= the part of
 * (panel k) (panel k)' there: dgemm for the rectangle above row j0, dsyrk for the triangle.
 * Why A22 by u's columns and not by its rows (the logical columns): the rectangle is then
 * tall (rows s..j0) and narrow, the shape OpenBLAS's dgemm runs at ~92 GF/s on one Zen 5
 * core, against ~82 for the short-wide update of a block of u's rows. */
static void update_a22_cols(const rfp *r, int k, int s, int j0, int j1)
{
    int p0, p1;
    block_range(r, k, &p0, &p1);
    const int bk = p1 - p0, ld = r->ld, w = j1 - j0, above = j0 - s, n1 = r->n1;
    if (k < r->nb1) { /* L(n1 + q, panel) = t(n1 + q, p0..) */
        const double *y = at_t(r, n1 + j0, p0);
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasNoTrans, w, bk, -1.0, y, ld, 1.0,
                    at_u(r, j0, j0), ld);
        if (above > 0)
            cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, above, w, bk, -1.0,
                        at_t(r, n1 + s, p0), ld, y, ld, 1.0, at_u(r, s, j0), ld);
    } else { /* L(n1 + q, panel) = u(k0.., q) */
        const int k0 = p0 - n1;
        const double *y = at_u(r, k0, j0);
        cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, w, bk, -1.0, y, ld, 1.0, at_u(r, j0, j0),
                    ld);
        if (above > 0)
            cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, above, w, bk, -1.0, at_u(r, k0, s),
                        ld, y, ld, 1.0, at_u(r, s, j0), ld);
    }
}

/* One task of a step's trailing update: columns [a, b) of the tall part (kind 0) or columns
 * [a, b) of u from row s (kind 1). */
typedef struct task {
    int kind, a, b, s;
} task;

/* Entries updated in columns c..e-1 of the tall part (column j: n - j of them) */
static double tall_work(int n, int c, int e)
{
    return (double)(e - c) * n - ((double)e * (e - 1) - (double)c * (c - 1)) / 2.0;
}
/* ... and in columns c..e-1 of u from row s (column q: q - s + 1) */
static double a22_work(int s, int c, int e)
{
    return ((double)e * (e + 1) - (double)c * (c + 1)) / 2.0 - (double)(e - c) * s;
}

/* Cuts a step's trailing update (tall columns [a, n1), then u's columns [s, n2) from row s)
 * into tasks, the costliest first: each a quarter of the work left in its part (guided), at
 * least CM_LOOKAHEAD_MIN_CHUNK columns, u's columns cut from the right where they are
 * longest. Why not one block per task: a dgemm of 192 columns repacks its tall operand on
 * every call and ran ~8 % slower than one of >= 768; why not T equal parts: the thread that
 * factors the next panel has less time left, and the small last tasks even the threads out
 * whatever the panel cost. The cuts depend on n, the block and the step only, not on T or
 * timing, so neither does the factor. Returns the count. */
static int make_tasks(int n, int n1, int a, int s, task *out, int max)
{
    const int n2 = n - n1, mc = CM_LOOKAHEAD_MIN_CHUNK;
    int count = 0;
    while (a < n1 && count < max) {
        const double want = tall_work(n, a, n1) / 4.0;
        int lo = a + 1, hi = n1; /* smallest e with tall_work(a, e) >= want */
        while (lo < hi) {
            int mid = lo + (hi - lo) / 2;
            if (tall_work(n, a, mid) >= want)
                hi = mid;
            else
                lo = mid + 1;
        }
        int e = lo < a + mc ? a + mc : lo;
        if (e > n1 - mc / 2 || count == max / 2 - 1) e = n1;
        out[count++] = (task){0, a, e, 0};
        a = e;
    }
    int b = n2;
    while (b > s && count < max) {
        const double want = a22_work(s, s, b) / 4.0;
        int lo = s, hi = b - 1; /* largest e with a22_work(e, b) >= want */
        while (lo < hi) {
            int mid = lo + (hi - lo + 1) / 2;
            if (a22_work(s, mid, b) >= want)
                lo = mid;
            else
                hi = mid - 1;
        }
        int e = lo > b - mc ? b - mc : lo;
        if (e < s + mc / 2 || count == max - 1) e = s;
        out[count++] = (task){1, e, b, s};
        b = e;
    }
    return count;
}

static void run_task(const rfp *r, int k, const task *t)
{
    if (t->kind == 0)
        update_range(r, k, t->a, t->b);
    else
        update_a22_cols(r, k, t->s, t->a, t->b);
}

/* Flops of step k: factoring panel k and applying it to every block on its right (the
 * counts of cholesky_blocked.c's report, so the totals of both paths agree). */
static double step_flops(const rfp *r, int k)
{
    int p0, p1;
    block_range(r, k, &p0, &p1);
    const double bk = p1 - p0;
    double f = bk * bk * bk / 3.0 + (double)(r->n - p1) * bk * bk;
    for (int q = k + 1; q < r->nblocks; ++q) {
        int c0, c1;
        block_range(r, q, &c0, &c1);
        const double bw = c1 - c0;
        f += bw * bw * bk + 2.0 * (double)(r->n - c1) * bw * bk;
    }
    return f;
}

int cm_rbf_cholesky_rfp_lookahead(cm_context *ctx, int n, double *a, int block, int threads)
{
    if (n < 0 || !a) return -1;
    if (n == 0) return 0;
    rfp r;
    r.n = n;
    r.b = block > 0 ? block : CM_LOOKAHEAD_BLOCK;
    const int n2 = n / 2;
    r.n1 = n - n2;
    if (n % 2) { /* odd: A11 (n1 = n2 + 1) at a (ld n), A22 upper at a + n */
        r.ld = n;
        r.t = a;
        r.u = a + n;
    } else { /* even: A11 at a + 1 (ld n + 1), A22 upper at a */
        r.ld = n + 1;
        r.t = a + 1;
        r.u = a;
    }
    r.nb1 = (r.n1 + r.b - 1) / r.b;
    r.nblocks = r.nb1 + (n2 + r.b - 1) / r.b;
    if (threads < 1) threads = 1;

    const double total = (double)n * n * n / 3.0;
    double done = 0.0;
    if (cm_progress(ctx, "rbf factor", 0.0, total) < 0) return CM_RBF_CHOLESKY_INTERRUPTED;
    /* one thread per BLAS call: OpenBLAS's count is process-wide, so set it around the
     * whole factorisation (the caller's count is restored below) */
    const int saved = openblas_get_num_threads();
    openblas_set_num_threads(1);
    TRACE_START();
    int info = factor_block(&r, 0);
    TRACE_END(-1, 0);
    int failed = info != 0; /* read and written atomically inside the team */
    int interrupted = 0;     /* written by the master thread only */
    if (!failed) {
#pragma omp parallel num_threads(threads) shared(info, failed, done, interrupted)
        for (int k = 0; k < r.nblocks; ++k) {
            /* A thread that saw a failure still passes every barrier, so none waits forever */
            int stop;
#pragma omp atomic read
            stop = failed;
#pragma omp single nowait
            if (!stop && k + 1 < r.nblocks) {
                TRACE_START();
                update_block(&r, k, k + 1);
                int e = factor_block(&r, k + 1);
                TRACE_END(k, 0);
                if (e != 0) {
                    info = e;
#pragma omp atomic write
                    failed = 1;
                }
            }
            task tasks[CM_LOOKAHEAD_MAX_CHUNKS];
            int count = 0;
            if (k + 2 < r.nblocks) { /* everything right of block k+1 */
                int s0, s1;
                block_range(&r, k + 2, &s0, &s1);
                count = make_tasks(n, r.n1, s0, s0 > r.n1 ? s0 - r.n1 : 0, tasks,
                                   CM_LOOKAHEAD_MAX_CHUNKS);
            }
#pragma omp for schedule(dynamic, 1)
            for (int q = 0; q < count; ++q)
                if (!stop) {
                    TRACE_START();
                    run_task(&r, k, &tasks[q]);
                    TRACE_END(k, 1 + q);
                }
                /* the barrier above ends step k: panel k+1 is factored, every block updated */
#pragma omp master
            if (!stop) {
                done += step_flops(&r, k);
                /* the caller asked to stop: the team stops as on a failed panel */
                if (cm_progress(ctx, "rbf factor", done < total ? done : total, total) < 0) {
                    interrupted = 1;
#pragma omp atomic write
                    failed = 1;
                }
            }
        }
    }
    openblas_set_num_threads(saved);
    if (info == 0 && interrupted) return CM_RBF_CHOLESKY_INTERRUPTED;
    if (info == 0 && cm_progress(ctx, "rbf factor", total, total) < 0)
        return CM_RBF_CHOLESKY_INTERRUPTED;
    return info;
}
