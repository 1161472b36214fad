/* The RFP Cholesky of cholesky_blocked.c on T OpenMP threads that each call single-threaded
 * BLAS, with a look-ahead of one panel, for the n where OpenBLAS's own threading leaves a
 * core idle.
 *
 * Why: at n = 5,000 on 2 threads dpftrf and the panel-by-panel factorisation both took
 * 1.25 x the bound n^3/3 at the dgemm rate, against 1.15 on one thread: every panel step
 * (dpotrf of b x b, dtrsm of the column below) runs while the second core waits, and the
 * trailing updates are too small for OpenBLAS to split well. Here the columns are cut into
 * the same blocks as in cholesky_blocked.c (the first n1 columns, then the n2 of A22, in
 * widths of `block`), and step k applies the factored panel k to every block on its right:
 * one thread first updates block k+1 and factors it (dpotrf + dtrsm), the next panel, while
 * the other threads take the remaining blocks' updates one at a time (dynamic schedule), and
 * that thread joins them when its panel is done. So the panel work of step k+1 hides behind
 * the updates of step k, and no thread waits except at the one barrier per step.
 *
 * Same arithmetic as dpftrf in another order (every update is panel k applied to one block,
 * by dsyrk on its diagonal block and dgemm below or right of it), same storage, and the
 * result does not depend on which thread ran which block: a BLAS call on one thread computes
 * the same bits whoever calls it, so the factor is the same for every T. */
#include "rbf_internal.h"

#include <cblas.h>
#include <lapacke.h>
#include <omp.h>

#define CM_LOOKAHEAD_BLOCK 192
#ifndef CM_LOOKAHEAD_MIN_CHUNK
#define CM_LOOKAHEAD_MIN_CHUNK 256
#endif
#define CM_LOOKAHEAD_MAX_CHUNKS 64

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

static double *at_t(const rfp *r, int i, int j) { return r->t + (size_t)i + (size_t)j * r->ld; }
/* u's element (p, q) in A22's own numbering */
static double *at_u(const rfp *r, int p, int q) { return r->u + (size_t)p + (size_t)q * r->ld; }

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
        if (info == 0 && rest > 0)
            cblas_dtrsm(CblasColMajor, CblasRight, CblasLower, CblasTrans, CblasNonUnit, rest, bw,
                        1.0, d, r->ld, d + bw, r->ld);
    } else {
        const int p0 = c0 - r->n1;
        double *d = at_u(r, p0, p0);
        info = LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'U', bw, d, r->ld);
        if (info == 0 && rest > 0)
            cblas_dtrsm(CblasColMajor, CblasLeft, CblasUpper, CblasTrans, CblasNonUnit, bw, rest,
                        1.0, d, r->ld, d + (size_t)bw * r->ld, r->ld);
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
            cblas_dgemm(CblasColMajor, CblasNoTrans, CblasTrans, rest, bw, bk, -1.0,
                        at_t(r, e, p0), ld, x, ld, 1.0, at_t(r, e, c0), ld);
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

/* Work of updating columns c..e-1 (each column j: n - j entries, bk flops each) */
static double col_work(int n, int c, int e)
{
    return (double)(e - c) * n - ((double)e * (e - 1) - (double)c * (c - 1)) / 2.0;
}

/* Cuts the columns s..n-1 of a step's update into chunks, widest work first: each a
 * quarter of the work left (guided), at least CM_LOOKAHEAD_MIN_CHUNK columns. Why not one
 * block per task: a dgemm of N = 192 columns repacks its tall operand for every call and
 * ran ~8 % slower than N >= 768; why not T equal parts: the thread that factors the next
 * panel has less time left, and the small last chunks even the threads out whatever the
 * panel cost. The cuts depend on n and s only, not on T or timing, so the factor does not
 * depend on the thread count. Returns the count; cut[0] = s, cut[count] = n. */
static int chunks(int n, int s, int *cut, int max)
{
    int count = 0;
    cut[0] = s;
    while (s < n && count < max - 1) {
        const double want = col_work(n, s, n) / 4.0;
        int lo = s + 1, hi = n; /* smallest e with col_work(s, e) >= want */
        while (lo < hi) {
            int mid = lo + (hi - lo) / 2;
            if (col_work(n, s, mid) >= want) hi = mid;
            else lo = mid + 1;
        }
        int e = lo < s + CM_LOOKAHEAD_MIN_CHUNK ? s + CM_LOOKAHEAD_MIN_CHUNK : lo;
        if (e > n - CM_LOOKAHEAD_MIN_CHUNK / 2 || count == max - 2) e = n;
        cut[++count] = e;
        s = e;
    }
    return count;
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
    cm_progress(ctx, "rbf factor", 0.0, total);
    /* one thread per BLAS call: OpenBLAS's count is process-wide, so set it around the
     * whole factorisation (the caller's count is restored below) */
    const int saved = openblas_get_num_threads();
    openblas_set_num_threads(1);
    int info = factor_block(&r, 0);
    int failed = info != 0; /* read and written atomically inside the team */
    if (!failed) {
#pragma omp parallel num_threads(threads) shared(info, failed, done)
        for (int k = 0; k < r.nblocks; ++k) {
            /* A thread that saw a failure still passes every barrier, so none waits forever */
            int stop;
#pragma omp atomic read
            stop = failed;
#pragma omp single nowait
            if (!stop && k + 1 < r.nblocks) {
                update_block(&r, k, k + 1);
                int e = factor_block(&r, k + 1);
                if (e != 0) {
                    info = e;
#pragma omp atomic write
                    failed = 1;
                }
            }
            int cut[CM_LOOKAHEAD_MAX_CHUNKS + 1], count = 0;
            if (k + 2 < r.nblocks) {
                int s0, s1;
                block_range(&r, k + 2, &s0, &s1);
                count = chunks(n, s0, cut, CM_LOOKAHEAD_MAX_CHUNKS);
            }
#pragma omp for schedule(dynamic, 1)
            for (int q = 0; q < count; ++q)
                if (!stop) update_range(&r, k, cut[q], cut[q + 1]);
            /* the barrier above ends step k: panel k+1 is factored, every block updated */
#pragma omp master
            if (!stop) {
                done += step_flops(&r, k);
                cm_progress(ctx, "rbf factor", done < total ? done : total, total);
            }
        }
    }
    openblas_set_num_threads(saved);
    if (info == 0) cm_progress(ctx, "rbf factor", total, total);
    return info;
}
