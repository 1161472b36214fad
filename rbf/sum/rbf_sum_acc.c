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
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#define NB 8
#define PB CM_RBF_ACC_PB
#define TILE 512

/* One tile of compensated sums, rounding errors of the products and of the running sums kept
 * in lo. fixed (a constant after inlining): 0 TwoProd + TwoSum, 10 operations per product; 1
 * the fixed-binade compensation of rbf_sum_avx512.c (which says why it is exact enough), 4
 * operations, hi must start at the binade offsets. */
static inline __attribute__((always_inline)) void tile_acc(const int fixed, const int nc,
                                                           const double *c, size_t ldc,
                                                           const double *w, size_t ldw,
                                                           size_t jn, const double *pt,
                                                           double *hi, double *lo)
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
            for (int q = 0; q < nc; ++q) {
                if (fixed) {
                    double t = fma(wj[q], f, s[q][l]);
                    double d = t - s[q][l]; /* exact: one binade */
                    e[q][l] += fma(wj[q], f, -d);
                    s[q][l] = t;
                } else {
                    double p = wj[q] * f;
                    double pe = fma(wj[q], f, -p); /* exact: p + pe = wj f */
                    double t = s[q][l] + p;        /* TwoSum(s, p) */
                    double bv = t - s[q][l];
                    double te = (s[q][l] - (t - bv)) + (p - bv);
                    s[q][l] = t;
                    e[q][l] += te + pe;
                }
            }
        }
    }
    for (int l = 0; l < NB; ++l)
        for (int q = 0; q < nc; ++q) {
            hi[q * PB + l] = s[q][l];
            lo[q * PB + l] = e[q][l];
        }
}

static inline __attribute__((always_inline)) void block_acc(const int fixed, const int nc,
                                                            size_t m, const double *c,
                                                            const double *w, const double *pt,
                                                            double *hi, double *lo)
{
    for (size_t t0 = 0; t0 < m; t0 += TILE) {
        size_t jn = m - t0 < TILE ? m - t0 : TILE;
        for (int b = 0; b < PB; b += NB)
            tile_acc(fixed, nc, c + t0, m, w + t0, m, jn, pt + b, hi + b, lo + b);
    }
}

/* block_acc for nc = 1..4 as constants */
#define CM_ACC_DISPATCH(fixed)                                                                 \
    switch (nc) {                                                                              \
    case 1: block_acc(fixed, 1, m, c, w, pt, hi, lo); break;                                   \
    case 2: block_acc(fixed, 2, m, c, w, pt, hi, lo); break;                                   \
    case 3: block_acc(fixed, 3, m, c, w, pt, hi, lo); break;                                   \
    default: block_acc(fixed, 4, m, c, w, pt, hi, lo); break;                                  \
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
 * the centres and the points). 0 if some B_q is not finite or so small that the binade's
 * ulp would be subnormal: then the TwoSum blocks run. */
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
    for (int q = 0; q < nc; ++q) {
        double sw = 0.0;
        for (size_t j = 0; j < m; ++j) sw += fabs(w[(size_t)q * m + j]);
        /* 4.01: the bound is a float sum itself; the margin covers its rounding */
        const double bound = 4.01 * sw * phimax;
        if (!(bound < 1e300)) return 0;
        if (bound < 1e-280) {
            if (bound > 0.0) return 0; /* tiny but not zero: keep TwoSum */
            big[q] = 1.5;              /* all weights zero: any binade is exact */
            continue;
        }
        int e;
        frexp(bound, &e); /* bound < 2^e */
        big[q] = 1.5 * ldexp(1.0, e);
    }
    return 1;
}

/* Points of blocks [b0, b1) of PB against all centres. */
static void acc_blocks(acc_fn fn, const double *big, size_t m, const double *c, const double *w,
                       int nc, size_t n, const double *p, size_t ldp, double *out, size_t ldo,
                       int threads, int parallel, long b0, long b1)
{
#pragma omp parallel for schedule(static) num_threads(threads) if (parallel)
    for (long b = b0; b < b1; ++b) {
        double pt[3 * PB], hi[4 * PB], lo[4 * PB];
        const size_t i0 = (size_t)b * PB;
        const size_t cnt = n - i0 < PB ? n - i0 : PB;
        for (int d = 0; d < 3; ++d)
            for (size_t l = 0; l < PB; ++l) {
                size_t i = l < cnt ? i0 + l : i0 + cnt - 1;
                pt[d * PB + l] = p[d * ldp + i];
            }
        for (int q = 0; q < 4; ++q)
            for (int l = 0; l < PB; ++l) hi[q * PB + l] = big[q];
        memset(lo, 0, sizeof lo);
        fn(nc, m, c, w, pt, hi, lo);
        /* hi - big is exact (same binade); 0 when the TwoSum blocks ran */
        for (size_t l = 0; l < cnt; ++l)
            for (int q = 0; q < nc; ++q)
                out[(i0 + l) * ldo + (size_t)q] = (hi[q * PB + l] - big[q]) + lo[q * PB + l];
    }
}

/* cm_rbf_kernel_sum_acc_isa in chunks of blocks with tick (NULL: one chunk); the binade is
 * that of all n points, so the chunks give the bits of one pass. */
static int acc_isa(cm_rbf_isa isa, size_t m, const double *c, const double *w, int nc,
                   size_t n, const double *p, size_t ldp, double *out, size_t ldo, int threads,
                   cm_rbf_tick *tick)
{
    if (isa == CM_RBF_ISA_AUTO) isa = cm_rbf_isa_auto();
    acc_fn fn = pick_acc(isa);
    double big[4] = {0.0, 0.0, 0.0, 0.0};
    /* the fixed binade where FMA is in hardware (AVX512_AUTOVEC stays the TwoSum loops: it
     * is the reference that benchmarks compare with) */
    if ((isa == CM_RBF_ISA_AVX512 || isa == CM_RBF_ISA_AVX2) &&
        fixed_binade(m, c, w, nc, n, p, ldp, big))
        fn = isa == CM_RBF_ISA_AVX512 ? cm_rbf_r3_accf_block_avx512 : accf_avx2;
    const int parallel = (double)n * (double)m > CM_RBF_PARALLEL_MIN_PAIRS && threads > 1;
    /* the self product (the Krylov products) computes each entry once for both rows */
    if (fn == cm_rbf_r3_accf_block_avx512 && p == c && ldp == m && n == m &&
        m >= CM_RBF_SELF_MIN_M &&
        !cm_rbf_r3_self_avx512(nc, m, c, w, big, out, ldo, parallel ? threads : 1))
        return cm_rbf_tick_add(tick, (double)n * (double)m);
    const long nblocks = (long)((n + PB - 1) / PB);
    const long chunk = cm_rbf_tick_chunk(tick, (double)PB * (double)m, nblocks, threads);
    for (long b0 = 0; b0 < nblocks; b0 += chunk) {
        const long b1 = nblocks - b0 < chunk ? nblocks : b0 + chunk;
        acc_blocks(fn, big, m, c, w, nc, n, p, ldp, out, ldo, threads, parallel, b0, b1);
        const size_t i1 = (size_t)b1 * PB < n ? (size_t)b1 * PB : n;
        if (cm_rbf_tick_add(tick, (double)(i1 - (size_t)b0 * PB) * (double)m)) return 1;
    }
    return 0;
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
