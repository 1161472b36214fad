/* Compensated r^3 kernel sums for the Krylov matvecs of the iterative solver. Why: the
 * preconditioned vectors z = M v of an ill-conditioned r^3 system are large and rough, so
 * A z is a sum with heavy cancellation, and plain summation errs by about
 * eps sum_j |z_j phi_ij|, not eps |A z|. That error is not a linear operator, so FGMRES's
 * residual estimate and the true residual part: on real boundary sets the true residual
 * stalled at 1e-8..1e-9 while the estimate went on to 1e-10 and below (two bodies far apart:
 * 6e-9 while the dense solver reached 5e-14). Here each product is split exactly (FMA) and
 * the sum is carried in two doubles (TwoSum, Knuth/Ogita-Rump-Oishi), so the error is
 * about eps |A z| plus eps^2 sum |z_j phi_ij|. The entries phi_ij themselves are rounded as in
 * rbf_sum.c, the same for every product: a fixed matrix, which Krylov methods do not mind.
 * Where FMA is in hardware (AVX2, AVX-512) the sum runs in a fixed binade instead
 * (rbf_sum_avx512.c says how): the same accuracy at 4 operations per product instead of 10.
 * A cheaper compensation does not do: plain sums over blocks of 8-32 centres added in
 * double-double took FGMRES on the bracket from 10 to 14-15 iterations (RESULTS.md, RBF solvers).
 * Built without FP contraction: the error-free transformations need every rounding where
 * it is written. */
#include "rbf_internal.h"
#include "rbf_sum_isa.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#define NB 8
#define PB CM_RBF_ACC_PB
#define TILE 512
#define FB_J 128 /* more than 4 columns: entries of this many centres x NB points kept */

/* s + e += w f: fixed binade or TwoProd + TwoSum */
static inline __attribute__((always_inline)) void acc_update(const int fixed, double *s,
                                                             double *e, double w, double f)
{
    if (fixed) {
        double t = fma(w, f, *s);
        double d = t - *s; /* exact: one binade */
        *e += fma(w, f, -d);
        *s = t;
    } else {
        double p = w * f;
        double pe = fma(w, f, -p); /* exact: p + pe = w f */
        double t = *s + p;         /* TwoSum(s, p) */
        double bv = t - *s;
        double te = (*s - (t - bv)) + (p - bv);
        *s = t;
        *e += te + pe;
    }
}

/* One tile of compensated sums, rounding errors of the products and of the running sums kept
 * in lo. fixed (a constant after inlining): 0 TwoProd + TwoSum, 10 operations per product; 1
 * the fixed-binade compensation of rbf_sum_avx512.c (which says why it is exact enough), 4
 * operations, hi must start at the binade offsets. */
static inline __attribute__((always_inline)) void tile_acc(const int fixed, const int nc,
                                                           const double *c, size_t ldc,
                                                           const double *w, size_t ldw,
                                                           size_t jn, const double *pt,
                                                           double *hi, double *lo,
                                                           const int keep, double *fb)
{
    const double *restrict cx = c, *restrict cy = c + ldc, *restrict cz = c + 2 * ldc;
    double x[NB], y[NB], z[NB], s[4][NB], e[4][NB];
    for (int l = 0; l < NB; ++l) {
        x[l] = pt[l];
        y[l] = pt[PB + l];
        z[l] = pt[2 * PB + l];
        for (int q = 0; q < nc; ++q) {
            s[q][l] = hi[q * PB + l];
            e[q][l] = lo[q * PB + l];
        }
    }
    for (size_t j = 0; j < jn; ++j) {
        const double xj = cx[j], yj = cy[j], zj = cz[j];
        double wj[4];
        for (int q = 0; q < nc; ++q) wj[q] = w[q * ldw + j];
        for (int l = 0; l < NB; ++l) {
            double dx = x[l] - xj, dy = y[l] - yj, dz = z[l] - zj;
            double r2 = dx * dx + dy * dy + dz * dz;
            double f = r2 * sqrt(r2);
            if (keep) fb[j * NB + l] = f;
            for (int q = 0; q < nc; ++q) acc_update(fixed, &s[q][l], &e[q][l], wj[q], f);
        }
    }
    for (int l = 0; l < NB; ++l)
        for (int q = 0; q < nc; ++q) {
            hi[q * PB + l] = s[q][l];
            lo[q * PB + l] = e[q][l];
        }
}

/* Columns [0, nc) (nc <= 4) over the entries of jn centres left in fb by the first column
 * group: the same updates as tile_acc in the same order of j (the same bits per column). */
static inline __attribute__((always_inline)) void cols_acc(const int fixed, const int nc,
                                                           const double *fb, const double *w,
                                                           size_t ldw, size_t jn, double *hi,
                                                           double *lo)
{
    double s[4][NB], e[4][NB];
    for (int l = 0; l < NB; ++l)
        for (int q = 0; q < nc; ++q) {
            s[q][l] = hi[q * PB + l];
            e[q][l] = lo[q * PB + l];
        }
    for (size_t j = 0; j < jn; ++j) {
        double wj[4];
        for (int q = 0; q < nc; ++q) wj[q] = w[q * ldw + j];
        for (int l = 0; l < NB; ++l) {
            const double f = fb[j * NB + l];
            for (int q = 0; q < nc; ++q) acc_update(fixed, &s[q][l], &e[q][l], wj[q], f);
        }
    }
    for (int l = 0; l < NB; ++l)
        for (int q = 0; q < nc; ++q) {
            hi[q * PB + l] = s[q][l];
            lo[q * PB + l] = e[q][l];
        }
}

/* nc = 0: more than 4 columns (ncm): per stretch of FB_J centres the first 4 compute the
 * entries into fb and the others run over them, so each entry is computed once. */
static inline __attribute__((always_inline)) void block_acc(const int fixed, const int nc,
                                                            int ncm, size_t m, const double *c,
                                                            const double *w, const double *pt,
                                                            double *hi, double *lo)
{
    double fb[FB_J * NB];
    for (size_t t0 = 0; t0 < m; t0 += TILE) {
        size_t jn = m - t0 < TILE ? m - t0 : TILE;
        for (int b = 0; b < PB; b += NB) {
            if (nc) {
                tile_acc(fixed, nc, c + t0, m, w + t0, m, jn, pt + b, hi + b, lo + b, 0, NULL);
                continue;
            }
            for (size_t j0 = t0; j0 < t0 + jn; j0 += FB_J) {
                const size_t jb = t0 + jn - j0 < FB_J ? t0 + jn - j0 : FB_J;
                tile_acc(fixed, 4, c + j0, m, w + j0, m, jb, pt + b, hi + b, lo + b, 1, fb);
                for (int g = 4; g < ncm; g += 4) {
                    const double *wg = w + (size_t)g * m + j0;
                    double *hg = hi + (size_t)g * PB + b, *lg = lo + (size_t)g * PB + b;
                    switch (ncm - g) {
                    case 1: cols_acc(fixed, 1, fb, wg, m, jb, hg, lg); break;
                    case 2: cols_acc(fixed, 2, fb, wg, m, jb, hg, lg); break;
                    case 3: cols_acc(fixed, 3, fb, wg, m, jb, hg, lg); break;
                    default: cols_acc(fixed, 4, fb, wg, m, jb, hg, lg); break;
                    }
                }
            }
        }
    }
}

/* block_acc for nc = 1..4 as constants; more columns share the first 4's entries */
#define CM_ACC_DISPATCH(fixed)                                                                 \
    switch (nc) {                                                                              \
    case 1: block_acc(fixed, 1, 1, m, c, w, pt, hi, lo); break;                                \
    case 2: block_acc(fixed, 2, 2, m, c, w, pt, hi, lo); break;                                \
    case 3: block_acc(fixed, 3, 3, m, c, w, pt, hi, lo); break;                                \
    case 4: block_acc(fixed, 4, 4, m, c, w, pt, hi, lo); break;                                \
    default: block_acc(fixed, 0, nc, m, c, w, pt, hi, lo); break;                              \
    }

__attribute__((target("avx2,fma"))) static void accf_avx2(int nc, size_t m, const double *c,
                                                           const double *w, const double *pt,
                                                           double *hi, double *lo)
{
    CM_ACC_DISPATCH(1)
}

typedef void (*acc_fn)(int nc, size_t m, const double *c, const double *w, const double *pt,
                       double *hi, double *lo);

static void acc_generic(int nc, size_t m, const double *c, const double *w, const double *pt,
                        double *hi, double *lo)
{
    CM_ACC_DISPATCH(0)
}

__attribute__((target("avx2,fma"))) static void acc_avx2(int nc, size_t m, const double *c,
                                                          const double *w, const double *pt,
                                                          double *hi, double *lo)
{
    CM_ACC_DISPATCH(0)
}

__attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma"))) static void
acc_avx512(int nc, size_t m, const double *c, const double *w, const double *pt, double *hi,
           double *lo)
{
    CM_ACC_DISPATCH(0)
}

static acc_fn pick_acc(cm_rbf_isa isa)
{
    if (isa == CM_RBF_ISA_AUTO) isa = cm_rbf_isa_auto();
    switch (isa) {
    case CM_RBF_ISA_AVX512: return cm_rbf_r3_acc_block_avx512;
    case CM_RBF_ISA_AVX512_AUTOVEC: return acc_avx512;
    case CM_RBF_ISA_AVX2: return acc_avx2;
    default: return acc_generic; /* fma() is exact here too, only slower */
    }
}

void cm_rbf_kernel_sum_acc(size_t m, const double *c, const double *w, int nc, size_t n,
                           const double *p, size_t ldp, double *out, size_t ldo, int threads)
{
    cm_rbf_kernel_sum_acc_isa(CM_RBF_ISA_AUTO, m, c, w, nc, n, p, ldp, out, ldo, threads);
}

/* The fixed-binade offsets of rbf_sum_avx512.c: big[q] = 1.5 * 2^k with 2^k >= 4 B_q, where
 * B_q = sum_j |w_qj| * dmax^3 bounds every partial sum (dmax: the diagonal of the box around
 * the centres and the points). Returns how many columns have one; a column whose B_q is not
 * finite or so small that the binade's ulp would be subnormal runs the TwoSum blocks. */
static int fixed_binade(size_t m, const double *c, const double *w, int nc, size_t n,
                        const double *p, size_t ldp, double *big)
{
    double d2 = 0.0;
    for (int d = 0; d < 3; ++d) {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t j = 0; j < m; ++j) lo = fmin(lo, c[d * m + j]), hi = fmax(hi, c[d * m + j]);
        for (size_t i = 0; i < n; ++i)
            lo = fmin(lo, p[d * ldp + i]), hi = fmax(hi, p[d * ldp + i]);
        d2 += (hi - lo) * (hi - lo);
    }
    const double phimax = d2 * sqrt(d2);
    int ok = 0;
    for (int q = 0; q < nc; ++q) {
        double sw = 0.0;
        for (size_t j = 0; j < m; ++j) sw += fabs(w[(size_t)q * m + j]);
        /* 4.01: the bound is a float sum itself; the margin covers its rounding */
        const double bound = 4.01 * sw * phimax;
        big[q] = 0.0;
        if (!(bound < 1e300)) continue;
        if (bound < 1e-280) {
            if (bound > 0.0) continue; /* tiny but not zero: keep TwoSum */
            big[q] = 1.5;              /* all weights zero: any binade is exact */
            ++ok;
            continue;
        }
        int e;
        frexp(bound, &e); /* bound < 2^e */
        big[q] = 1.5 * ldexp(1.0, e);
        ++ok;
    }
    return ok;
}

/* Points of blocks [b0, b1) of PB against all centres. */
static void acc_blocks(acc_fn fn, const double *big, size_t m, const double *c, const double *w,
                       int nc, size_t n, const double *p, size_t ldp, double *out, size_t ldo,
                       int threads, int parallel, long b0, long b1, double *work)
{
#pragma omp parallel num_threads(threads) if (parallel)
    {
        double hi4[4 * PB], lo4[4 * PB], *hi = hi4, *lo = lo4;
        if (work) { /* more than 4 columns: this thread's 2 nc PB */
#ifdef _OPENMP
            hi = work + (size_t)omp_get_thread_num() * 2 * (size_t)nc * PB;
#else
            hi = work;
#endif
            lo = hi + (size_t)nc * PB;
        }
#pragma omp for schedule(static)
    for (long b = b0; b < b1; ++b) {
        double pt[3 * PB];
        const size_t i0 = (size_t)b * PB;
        const size_t cnt = n - i0 < PB ? n - i0 : PB;
        for (int d = 0; d < 3; ++d)
            for (size_t l = 0; l < PB; ++l) {
                size_t i = l < cnt ? i0 + l : i0 + cnt - 1;
                pt[d * PB + l] = p[d * ldp + i];
            }
        for (int q = 0; q < nc; ++q)
            for (int l = 0; l < PB; ++l) hi[q * PB + l] = big[q];
        memset(lo, 0, (size_t)nc * PB * sizeof *lo);
        fn(nc, m, c, w, pt, hi, lo);
        /* hi - big is exact (same binade); 0 when the TwoSum blocks ran */
        for (size_t l = 0; l < cnt; ++l)
            for (int q = 0; q < nc; ++q)
                out[(i0 + l) * ldo + (size_t)q] = (hi[q * PB + l] - big[q]) + lo[q * PB + l];
    }
    }
}

/* cm_rbf_kernel_sum_acc_isa in chunks of blocks with tick (NULL: one chunk); the binade is
 * that of all n points, so the chunks give the bits of one pass. */
static int acc_isa(cm_rbf_isa isa, size_t m, const double *c, const double *w, int nc,
                   size_t n, const double *p, size_t ldp, double *out, size_t ldo, int threads,
                   cm_rbf_tick *tick)
{
    if (nc > CM_RBF_SUM_MAX_NC) { /* passes of CM_RBF_SUM_MAX_NC: the same bits per column */
        for (int g = 0; g < nc; g += CM_RBF_SUM_MAX_NC)
            if (acc_isa(isa, m, c, w + (size_t)g * m,
                        nc - g < CM_RBF_SUM_MAX_NC ? nc - g : CM_RBF_SUM_MAX_NC, n, p, ldp,
                        out + g, ldo, threads, tick))
                return 1;
        return 0;
    }
    if (isa == CM_RBF_ISA_AUTO) isa = cm_rbf_isa_auto();
    acc_fn fn = pick_acc(isa);
    /* the binade of a column is its own (fixed_binade), whatever columns ride along */
    double big[CM_RBF_SUM_MAX_NC] = {0.0};
    /* the fixed binade where FMA is in hardware (AVX512_AUTOVEC stays the TwoSum loops: it
     * is the reference that benchmarks compare with) */
    if (isa == CM_RBF_ISA_AVX512 || isa == CM_RBF_ISA_AVX2) {
        const int ok = fixed_binade(m, c, w, nc, n, p, ldp, big);
        if (ok == nc) fn = isa == CM_RBF_ISA_AVX512 ? cm_rbf_r3_accf_block_avx512 : accf_avx2;
        else if (ok > 0) { /* some columns TwoSum, some not: each its own (rare) */
            for (int q = 0; q < nc; ++q)
                if (acc_isa(isa, m, c, w + (size_t)q * m, 1, n, p, ldp, out + q, ldo, threads,
                            tick))
                    return 1;
            return 0;
        } else memset(big, 0, sizeof big);
    }
    const int parallel = (double)n * (double)m > CM_RBF_PARALLEL_MIN_PAIRS && threads > 1;
    /* the self product (the Krylov products) computes each entry once for both rows */
    if (fn == cm_rbf_r3_accf_block_avx512 && p == c && ldp == m && n == m &&
        m >= CM_RBF_SELF_MIN_M && nc <= CM_RBF_SELF_MAX_NC &&
        !cm_rbf_r3_self_avx512(nc, m, c, w, big, out, ldo, parallel ? threads : 1))
        return cm_rbf_tick_add(tick, (double)n * (double)m);
    double *work = NULL;
    if (nc > 4) {
        work = malloc((size_t)(parallel ? threads : 1) * 2 * (size_t)nc * PB * sizeof *work);
        if (!work) { /* groups of 4 columns: slower, the same bits */
            for (int g = 0; g < nc; g += 4)
                if (acc_isa(isa, m, c, w + (size_t)g * m, nc - g < 4 ? nc - g : 4, n, p, ldp,
                            out + g, ldo, threads, tick))
                    return 1;
            return 0;
        }
    }
    const long nblocks = (long)((n + PB - 1) / PB);
    const long chunk = cm_rbf_tick_chunk(tick, (double)PB * (double)m, nblocks, threads);
    int stop = 0;
    for (long b0 = 0; b0 < nblocks && !stop; b0 += chunk) {
        const long b1 = nblocks - b0 < chunk ? nblocks : b0 + chunk;
        acc_blocks(fn, big, m, c, w, nc, n, p, ldp, out, ldo, threads, parallel, b0, b1, work);
        const size_t i1 = (size_t)b1 * PB < n ? (size_t)b1 * PB : n;
        stop = cm_rbf_tick_add(tick, (double)(i1 - (size_t)b0 * PB) * (double)m);
    }
    free(work);
    return stop;
}

void cm_rbf_kernel_sum_acc_isa(cm_rbf_isa isa, size_t m, const double *c, const double *w,
                               int nc, size_t n, const double *p, size_t ldp, double *out,
                               size_t ldo, int threads)
{
    acc_isa(isa, m, c, w, nc, n, p, ldp, out, ldo, threads, NULL);
}

int cm_rbf_kernel_sum_acc_tick(size_t m, const double *c, const double *w, int nc, size_t n,
                               const double *p, size_t ldp, double *out, size_t ldo,
                               int threads, cm_rbf_tick *tick)
{
    return acc_isa(CM_RBF_ISA_AUTO, m, c, w, nc, n, p, ldp, out, ldo, threads, tick);
}
