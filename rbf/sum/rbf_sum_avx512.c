/* Hand-written AVX-512 blocks of the r^3 kernel sums (plain and compensated), chosen at run
 * time by rbf_sum.c and rbf_sum_acc.c on CPUs with AVX-512 F/DQ/VL (and, through the strided
 * entry points, by the treecode's products in rbf_treecode.c); other CPUs keep the
 * compiler-vectorised loops there. Why by hand: the compiler cannot balance the sqrt unit
 * against the FMA pipes (plain sums), and the compensated sums need a different algorithm
 * (the fixed binade below). Measured on Zen 5 (benchmarks/rbf/bench_kernel.c, RESULTS.md,
 * RBF solvers): plain 3.3e9 -> 3.8-4.0e9, compensated 1.2e9 -> 2.4-2.6e9 pairs per CPU-second.
 *
 * The square root is the bottleneck (in a register-resident test on Zen 5: all vsqrtpd
 * 3.46e9 pairs/s, all rsqrt14 + Newton 2.37e9). So of the vectors of points held in
 * registers some take vsqrtpd and the others compute sqrt on the FMA pipes instead: rsqrt14
 * (14 bits), two Goldschmidt steps and a final Newton correction with an FMA residual
 * (Markstein's scheme). In a test of 1.6e7 arguments over 40 binades that sequence returned
 * the correctly rounded sqrt every time (one Goldschmidt step fewer errs by 1 ulp in 0.6 %),
 * so the entries phi_ij are the same whichever unit computed them, as the "fixed matrix"
 * argument of rbf_sum_acc.c needs, and the split changes only the time.
 *
 * The best split is a property of the core, not of the ISA: vsqrtpd on 8 doubles is several
 * times slower on a Sapphire-Rapids-class Xeon than on Zen 5. Measured (bench_kernel, 1
 * thread, 3 weight vectors; RESULTS.md, RBF solvers): Zen 5 plain best with 3 of
 * 4 vectors through vsqrtpd, fixed-binade compensated with 2 of 2; the Xeon plain 2 of 4
 * (1.83e9 against 1.24e9 with 3 of 4), compensated 1 of 2 (1.30e9 against 0.93e9). So each
 * block is built for both splits and split_probe times them once per process (~11 ms).
 *
 * Many columns (weight vectors; a study's variants x components). The entry phi_ij is the
 * cost (distance, square root), a column only one FMA per entry (plain; 4 operations
 * compensated). Up to 4 columns ride in registers beside the points; more: per stretch of
 * FB_J centres the first 4 columns compute the entries and leave them in an L1-resident
 * buffer, and the others run over it in register-sized groups (PLAIN_CG, ACC_CG), so each
 * entry is computed once per pass for all columns. Every column does the same operation per
 * entry in the same order of j in both ways, and the sqrt units return the same bits, so a
 * column's sum does not depend on how many ride along (tests/rbf/test_rbf_sum_batch.c).
 * Measured per column against the FMA bound: benchmarks/RESULTS.md, Study, "Kernel cost per
 * column".
 *
 * Built with -ffp-contract=off: the error-free transformations of the compensated block
 * need every rounding where it is written. */
#include "rbf_sum_isa.h"
#include "rbf_internal.h" /* cm_rbf_thread_seconds, cm_rbf_probe_data */

#if defined(__x86_64__) && defined(__GNUC__)
#include "rbf_r3_avx512.h"
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <string.h>

#define NV 4       /* vectors of 8 points held in registers */
#define TILE 512   /* centres per tile: 3 + 4 rows of 512 doubles stay in L1 */
/* more than 4 columns: the entries of FB_J centres against the register block kept in an
 * L1-resident buffer (16 KB plain, 8 KB compensated) for the further column groups */
#define FB_J 64
#define FBW (8 * NV)     /* doubles per centre in the plain block's buffer */
#define PLAIN_CG 6       /* further columns per group, plain: 6 x 4 accumulators + 4 entries */
#define ACC_FBW (8 * ACC_NV)
#define ACC_CG 4         /* compensated: 4 x 2 x 2 accumulators + 2 entries + temporaries */
#define ACC_NV 2   /* compensated (both kinds): vectors of points held in registers (2 accumulators each) */
/* the candidate splits, vectors through vsqrtpd (the others through sqrt_fma): the two
 * measured best, on Zen 5 (the first) and on the Xeon (the second) */
#define PLAIN_SQRT_A 3 /* of NV */
#define PLAIN_SQRT_B 2
#define ACC_SQRT_A 2   /* of ACC_NV, in the fixed-binade block */
#define ACC_SQRT_B 1

/* Centres [0, jn) of a tile (coordinate d at c + d * ldc, component q's weights at
 * w + q * ldw) against nv * 8 points at pt (coordinate d at pt + d * ldp, sums at acc + q *
 * ldp), nsq of the NV vectors through vsqrtpd. nv = NV in the direct sums; the treecode's
 * batches end with a tail of nv < NV vectors, all through vsqrtpd. nv, nsq, nc and (in the
 * direct sums) the strides are constants after inlining. */
CM_AVX512 CM_INLINE void tile_plain(const int nv, const int nsq, const int nc, const double *c,
                                    size_t ldc,
                                    const double *w, size_t ldw, size_t jn, const double *pt,
                                    size_t ldp, double *acc, const int keep, double *fb)
{
    const double *restrict cx = c, *restrict cy = c + ldc, *restrict cz = c + 2 * ldc;
    __m512d x[NV], y[NV], z[NV], a[4][NV];
    for (int v = 0; v < nv; ++v) {
        x[v] = _mm512_loadu_pd(pt + 8 * v);
        y[v] = _mm512_loadu_pd(pt + ldp + 8 * v);
        z[v] = _mm512_loadu_pd(pt + 2 * ldp + 8 * v);
        for (int q = 0; q < nc; ++q) a[q][v] = _mm512_loadu_pd(acc + q * ldp + 8 * v);
    }
    for (size_t j = 0; j < jn; ++j) {
        const __m512d xj = _mm512_set1_pd(cx[j]), yj = _mm512_set1_pd(cy[j]);
        const __m512d zj = _mm512_set1_pd(cz[j]);
        __m512d wj[4];
        for (int q = 0; q < nc; ++q) wj[q] = _mm512_set1_pd(w[q * ldw + j]);
        for (int v = 0; v < nv; ++v) {
            const __m512d f = cm_r3_of(nv == NV && v >= nsq, x[v], y[v], z[v], xj, yj, zj);
            if (keep) _mm512_store_pd(fb + j * FBW + 8 * v, f);
            for (int q = 0; q < nc; ++q) a[q][v] = _mm512_fmadd_pd(wj[q], f, a[q][v]);
        }
    }
    for (int v = 0; v < nv; ++v)
        for (int q = 0; q < nc; ++q) _mm512_storeu_pd(acc + q * ldp + 8 * v, a[q][v]);
}

/* Columns [0, nc) (nc <= PLAIN_CG, a constant) of a stretch of jn centres whose entries
 * the first column group left in fb (fb[j FBW + 8 v]): one FMA per entry and column, the
 * same as tile_plain's, in the same order of j, so a column's sum does not depend on the
 * group it rides in. */
CM_AVX512 CM_INLINE void cols_plain(const int nv, const int nc, const double *fb, size_t jn,
                                    const double *w, size_t ldw, size_t ldp, double *acc)
{
    __m512d a[PLAIN_CG][NV];
    for (int v = 0; v < nv; ++v)
        for (int q = 0; q < nc; ++q) a[q][v] = _mm512_loadu_pd(acc + q * ldp + 8 * v);
    for (size_t j = 0; j < jn; ++j) {
        __m512d f[NV];
        for (int v = 0; v < nv; ++v) f[v] = _mm512_load_pd(fb + j * FBW + 8 * v);
        for (int q = 0; q < nc; ++q) {
            const __m512d wj = _mm512_set1_pd(w[q * ldw + j]);
            for (int v = 0; v < nv; ++v) a[q][v] = _mm512_fmadd_pd(wj, f[v], a[q][v]);
        }
    }
    for (int v = 0; v < nv; ++v)
        for (int q = 0; q < nc; ++q) _mm512_storeu_pd(acc + q * ldp + 8 * v, a[q][v]);
}

/* More than 4 columns on nv vectors of points: per stretch of FB_J centres the first 4
 * columns compute the entries (into fb, L1-resident) and the others run over them in
 * groups of PLAIN_CG, so each entry phi_ij is computed once for all columns. */
CM_AVX512 CM_INLINE void tile_plain_many(const int nv, const int nsq, int nc, const double *c,
                                         size_t ldc, const double *w, size_t ldw, size_t jn,
                                         const double *pt, size_t ldp, double *acc, double *fb)
{
    for (size_t j0 = 0; j0 < jn; j0 += FB_J) {
        const size_t jb = jn - j0 < FB_J ? jn - j0 : FB_J;
        tile_plain(nv, nsq, 4, c + j0, ldc, w + j0, ldw, jb, pt, ldp, acc, 1, fb);
        for (int g = 4; g < nc; g += PLAIN_CG) {
            const double *wg = w + (size_t)g * ldw + j0;
            double *ag = acc + (size_t)g * ldp;
            switch (nc - g >= PLAIN_CG ? PLAIN_CG : nc - g) {
            case 1: cols_plain(nv, 1, fb, jb, wg, ldw, ldp, ag); break;
            case 2: cols_plain(nv, 2, fb, jb, wg, ldw, ldp, ag); break;
            case 3: cols_plain(nv, 3, fb, jb, wg, ldw, ldp, ag); break;
            case 4: cols_plain(nv, 4, fb, jb, wg, ldw, ldp, ag); break;
            case 5: cols_plain(nv, 5, fb, jb, wg, ldw, ldp, ag); break;
            default: cols_plain(nv, PLAIN_CG, fb, jb, wg, ldw, ldp, ag); break;
            }
        }
    }
}

/* All m centres, tile by tile, against npt points (rounded up to a multiple of 8: pt and
 * acc must hold that many). One body for the direct sums (npt = ldp = CM_RBF_SUM_PB,
 * ldc = ldw = m) and the treecode (any strides), so both run the same kernel. */
CM_AVX512 CM_INLINE void block_plain(const int nsq, const int nc, int ncm, size_t m,
                                     const double *c, size_t ldc, const double *w, size_t ldw,
                                     size_t npt, const double *pt, size_t ldp, double *acc)
{
    double fb[FB_J * FBW] __attribute__((aligned(64))); /* used for more than 4 columns */
    for (size_t t0 = 0; t0 < m; t0 += TILE) {
        const size_t jn = m - t0 < TILE ? m - t0 : TILE;
        for (size_t b = 0; b < npt; b += 8 * NV) {
            const size_t left = (npt - b + 7) / 8;
            const double *cb = c + t0, *wb = w + t0, *pb = pt + b;
            double *ab = acc + b;
            /* nc = 0 here means "more than 4" (tile_plain_many, ncm columns) */
            if (nc == 0) switch (left >= NV ? NV : (int)left) {
            case 1: tile_plain_many(1, nsq, ncm, cb, ldc, wb, ldw, jn, pb, ldp, ab, fb); break;
            case 2: tile_plain_many(2, nsq, ncm, cb, ldc, wb, ldw, jn, pb, ldp, ab, fb); break;
            case 3: tile_plain_many(3, nsq, ncm, cb, ldc, wb, ldw, jn, pb, ldp, ab, fb); break;
            default: tile_plain_many(NV, nsq, ncm, cb, ldc, wb, ldw, jn, pb, ldp, ab, fb); break;
            }
            else switch (left >= NV ? NV : (int)left) {
            case 1: tile_plain(1, nsq, nc, cb, ldc, wb, ldw, jn, pb, ldp, ab, 0, NULL); break;
            case 2: tile_plain(2, nsq, nc, cb, ldc, wb, ldw, jn, pb, ldp, ab, 0, NULL); break;
            case 3: tile_plain(3, nsq, nc, cb, ldc, wb, ldw, jn, pb, ldp, ab, 0, NULL); break;
            default: tile_plain(NV, nsq, nc, cb, ldc, wb, ldw, jn, pb, ldp, ab, 0, NULL); break;
            }
        }
    }
}

CM_AVX512 CM_INLINE void dispatch_plain(const int nsq, int nc, size_t m, const double *c,
                                        size_t ldc, const double *w, size_t ldw, size_t npt,
                                        const double *pt, size_t ldp, double *acc)
{
    switch (nc) {
    case 1: block_plain(nsq, 1, 1, m, c, ldc, w, ldw, npt, pt, ldp, acc); break;
    case 2: block_plain(nsq, 2, 2, m, c, ldc, w, ldw, npt, pt, ldp, acc); break;
    case 3: block_plain(nsq, 3, 3, m, c, ldc, w, ldw, npt, pt, ldp, acc); break;
    case 4: block_plain(nsq, 4, 4, m, c, ldc, w, ldw, npt, pt, ldp, acc); break;
    default: block_plain(nsq, 0, nc, m, c, ldc, w, ldw, npt, pt, ldp, acc); break;
    }
}

/* the direct sums' block (constant strides) under either split */
CM_AVX512 static void plain_split(int alt, int nc, size_t m, const double *c, const double *w,
                                  const double *pt, double *acc)
{
    const size_t PB = CM_RBF_SUM_PB;
    if (alt) dispatch_plain(PLAIN_SQRT_B, nc, m, c, m, w, m, PB, pt, PB, acc);
    else dispatch_plain(PLAIN_SQRT_A, nc, m, c, m, w, m, PB, pt, PB, acc);
}

/* ---- compensated sums: s + e += w * f exactly to first order ----
 * fixed = 0: TwoProd by FMA and TwoSum, 10 operations per product (the add pipes are busy
 * with TwoSum, so every vector takes vsqrtpd). fixed = 1: the fixed binade below. fixed is a
 * constant after inlining, so each exported block has one inner loop.
 * The fixed binade (4 operations per product instead of 10): the running sum S = big + partial sum stays in one binade [2^k, 2^(k+1)) when big = 1.5 2^k
 * and 2^k >= 4 max |partial sum| (the caller's bound), so all its values are multiples of
 * one ulp u: T = fma(w, f, S) rounds w f + S once, T - S is exact (Sterbenz), and
 * w f - (T - S), the rounding error (|.| <= u/2), is formed by one more FMA with a relative
 * error of eps. Those remainders are summed plainly into E. So S - big + E has the error
 * eps |result| + about eps u m^(1/2..1) (u ~ eps 4 bound), second order like TwoSum's, at
 * fma, sub, fmsub, add per product where TwoProd + TwoSum take 10 (the vector operation
 * count was the limit: TwoSum ran at 0.4x the plain sum's throughput). This is the binned
 * summation of the reproducible-BLAS literature (Demmel and Nguyen) with a single bin. */
/* s + e += w f: fixed binade (cm_accf) or TwoProd + TwoSum */
CM_AVX512 CM_INLINE void acc_update(const int fixed, __m512d *s, __m512d *e, __m512d w,
                                    __m512d f)
{
    if (fixed) {
        cm_accf(s, e, w, f);
    } else {
        const __m512d p = _mm512_mul_pd(w, f);
        const __m512d pe = _mm512_fmsub_pd(w, f, p); /* p + pe = w f exactly */
        const __m512d t = _mm512_add_pd(*s, p);
        const __m512d bv = _mm512_sub_pd(t, *s);
        const __m512d te =
            _mm512_add_pd(_mm512_sub_pd(*s, _mm512_sub_pd(t, bv)), _mm512_sub_pd(p, bv));
        *s = t;
        *e = _mm512_add_pd(*e, _mm512_add_pd(te, pe));
    }
}

CM_AVX512 CM_INLINE void tile_acc(const int fixed, const int nsq, const int nv, const int nc,
                                  const double *c, size_t ldc, const double *w, size_t ldw,
                                  size_t jn, const double *pt, size_t ldp, double *hi,
                                  double *lo, const int keep, double *fb)
{
    const double *restrict cx = c, *restrict cy = c + ldc, *restrict cz = c + 2 * ldc;
    __m512d x[ACC_NV], y[ACC_NV], z[ACC_NV], s[4][ACC_NV], e[4][ACC_NV];
    for (int v = 0; v < nv; ++v) {
        x[v] = _mm512_loadu_pd(pt + 8 * v);
        y[v] = _mm512_loadu_pd(pt + ldp + 8 * v);
        z[v] = _mm512_loadu_pd(pt + 2 * ldp + 8 * v);
        for (int q = 0; q < nc; ++q) {
            s[q][v] = _mm512_loadu_pd(hi + q * ldp + 8 * v);
            e[q][v] = _mm512_loadu_pd(lo + q * ldp + 8 * v);
        }
    }
    for (size_t j = 0; j < jn; ++j) {
        const __m512d xj = _mm512_set1_pd(cx[j]), yj = _mm512_set1_pd(cy[j]);
        const __m512d zj = _mm512_set1_pd(cz[j]);
        __m512d wj[4];
        for (int q = 0; q < nc; ++q) wj[q] = _mm512_set1_pd(w[q * ldw + j]);
        for (int v = 0; v < nv; ++v) {
            const __m512d f = cm_r3_of(fixed && v >= nsq, x[v], y[v], z[v], xj, yj, zj);
            if (keep) _mm512_store_pd(fb + j * ACC_FBW + 8 * v, f);
            for (int q = 0; q < nc; ++q) acc_update(fixed, &s[q][v], &e[q][v], wj[q], f);
        }
    }
    for (int v = 0; v < nv; ++v)
        for (int q = 0; q < nc; ++q) {
            _mm512_storeu_pd(hi + q * ldp + 8 * v, s[q][v]);
            _mm512_storeu_pd(lo + q * ldp + 8 * v, e[q][v]);
        }
}

/* as cols_plain for the compensated blocks: columns [0, nc), nc <= ACC_CG */
CM_AVX512 CM_INLINE void cols_acc(const int fixed, const int nv, const int nc, const double *fb,
                                  size_t jn, const double *w, size_t ldw, size_t ldp, double *hi,
                                  double *lo)
{
    __m512d s[ACC_CG][ACC_NV], e[ACC_CG][ACC_NV];
    for (int v = 0; v < nv; ++v)
        for (int q = 0; q < nc; ++q) {
            s[q][v] = _mm512_loadu_pd(hi + q * ldp + 8 * v);
            e[q][v] = _mm512_loadu_pd(lo + q * ldp + 8 * v);
        }
    for (size_t j = 0; j < jn; ++j) {
        __m512d f[ACC_NV];
        for (int v = 0; v < nv; ++v) f[v] = _mm512_load_pd(fb + j * ACC_FBW + 8 * v);
        for (int q = 0; q < nc; ++q) {
            const __m512d wj = _mm512_set1_pd(w[q * ldw + j]);
            for (int v = 0; v < nv; ++v) acc_update(fixed, &s[q][v], &e[q][v], wj, f[v]);
        }
    }
    for (int v = 0; v < nv; ++v)
        for (int q = 0; q < nc; ++q) {
            _mm512_storeu_pd(hi + q * ldp + 8 * v, s[q][v]);
            _mm512_storeu_pd(lo + q * ldp + 8 * v, e[q][v]);
        }
}

/* as tile_plain_many for the compensated blocks */
CM_AVX512 CM_INLINE void tile_acc_many(const int fixed, const int nsq, const int nv, int nc,
                                       const double *c, size_t ldc, const double *w, size_t ldw,
                                       size_t jn, const double *pt, size_t ldp, double *hi,
                                       double *lo, double *fb)
{
    for (size_t j0 = 0; j0 < jn; j0 += FB_J) {
        const size_t jb = jn - j0 < FB_J ? jn - j0 : FB_J;
        tile_acc(fixed, nsq, nv, 4, c + j0, ldc, w + j0, ldw, jb, pt, ldp, hi, lo, 1, fb);
        for (int g = 4; g < nc; g += ACC_CG) {
            const double *wg = w + (size_t)g * ldw + j0;
            double *hg = hi + (size_t)g * ldp, *lg = lo + (size_t)g * ldp;
            switch (nc - g >= ACC_CG ? ACC_CG : nc - g) {
            case 1: cols_acc(fixed, nv, 1, fb, jb, wg, ldw, ldp, hg, lg); break;
            case 2: cols_acc(fixed, nv, 2, fb, jb, wg, ldw, ldp, hg, lg); break;
            case 3: cols_acc(fixed, nv, 3, fb, jb, wg, ldw, ldp, hg, lg); break;
            default: cols_acc(fixed, nv, ACC_CG, fb, jb, wg, ldw, ldp, hg, lg); break;
            }
        }
    }
}

/* as block_plain: one body for the direct sums (npt = ldp = CM_RBF_ACC_PB) and the
 * treecode's compensated products (any strides; a tail of one vector); nsq of the ACC_NV
 * vectors through vsqrtpd in the fixed-binade block (the TwoSum block keeps the FMA pipes
 * busy, so all of its vectors take vsqrtpd) */
CM_AVX512 CM_INLINE void block_acc(const int fixed, const int nsq, const int nc, int ncm,
                                   size_t m, const double *c, size_t ldc, const double *w,
                                   size_t ldw, size_t npt, const double *pt, size_t ldp,
                                   double *hi, double *lo)
{
    double fb[FB_J * ACC_FBW] __attribute__((aligned(64))); /* used for more than 4 columns */
    for (size_t t0 = 0; t0 < m; t0 += TILE) {
        const size_t jn = m - t0 < TILE ? m - t0 : TILE;
        for (size_t b = 0; b < npt; b += 8 * ACC_NV) {
            const double *cb = c + t0, *wb = w + t0, *pb = pt + b;
            double *hb = hi + b, *lb = lo + b;
            /* nc = 0: more than 4 columns (ncm) */
            if (nc == 0 && npt - b > 8 * (ACC_NV - 1))
                tile_acc_many(fixed, nsq, ACC_NV, ncm, cb, ldc, wb, ldw, jn, pb, ldp, hb, lb, fb);
            else if (nc == 0)
                tile_acc_many(fixed, nsq, 1, ncm, cb, ldc, wb, ldw, jn, pb, ldp, hb, lb, fb);
            else if (npt - b > 8 * (ACC_NV - 1))
                tile_acc(fixed, nsq, ACC_NV, nc, cb, ldc, wb, ldw, jn, pb, ldp, hb, lb, 0, NULL);
            else
                tile_acc(fixed, nsq, 1, nc, cb, ldc, wb, ldw, jn, pb, ldp, hb, lb, 0, NULL);
        }
    }
}

CM_AVX512 CM_INLINE void dispatch_acc(const int fixed, const int nsq, int nc, size_t m,
                                      const double *c, size_t ldc, const double *w, size_t ldw,
                                      size_t npt, const double *pt, size_t ldp, double *hi,
                                      double *lo)
{
    switch (nc) {
    case 1: block_acc(fixed, nsq, 1, 1, m, c, ldc, w, ldw, npt, pt, ldp, hi, lo); break;
    case 2: block_acc(fixed, nsq, 2, 2, m, c, ldc, w, ldw, npt, pt, ldp, hi, lo); break;
    case 3: block_acc(fixed, nsq, 3, 3, m, c, ldc, w, ldw, npt, pt, ldp, hi, lo); break;
    case 4: block_acc(fixed, nsq, 4, 4, m, c, ldc, w, ldw, npt, pt, ldp, hi, lo); break;
    default: block_acc(fixed, nsq, 0, nc, m, c, ldc, w, ldw, npt, pt, ldp, hi, lo); break;
    }
}

/* the fixed-binade block of the direct sums under either split */
CM_AVX512 static void accf_split(int alt, int nc, size_t m, const double *c, const double *w,
                                 const double *pt, double *hi, double *lo)
{
    const size_t PB = CM_RBF_ACC_PB;
    if (alt) dispatch_acc(1, ACC_SQRT_B, nc, m, c, m, w, m, PB, pt, PB, hi, lo);
    else dispatch_acc(1, ACC_SQRT_A, nc, m, c, m, w, m, PB, pt, PB, hi, lo);
}

/* ---- the split of this CPU ---- */

static int split_plain_alt, split_acc_alt; /* 1: the B split is faster here */
static pthread_once_t split_once = PTHREAD_ONCE_INIT;
static _Atomic int split_forced; /* cm_rbf_sqrt_split_force: 1 + plain_alt + 2 acc_alt */

/* Times both splits of both blocks on four tiles of centres against one work item of
 * points, interleaved, best of REPS by the thread's CPU clock (a loaded machine delays the
 * probe but does not bias it), after one untimed round. Each timing is 4 calls of 0.26-0.52M
 * pairs, 0.4-0.8 ms; ~11 ms in all, once per process. Shorter probes (one tile, 0.1 ms a
 * timing, no warm-up) measured the faster split at only 1.05-1.1x the other on the Xeon,
 * where long runs give 1.4x, and once picked the slower one on a quiet machine. */
static void split_probe(void)
{
    enum { NPROBE = 4 * TILE, REPS = 4, CALLS = 4 };
    static double c[3 * NPROBE], w[3 * NPROBE], pt[3 * CM_RBF_SUM_PB], acc[4 * CM_RBF_SUM_PB];
    static double pa[3 * CM_RBF_ACC_PB], hi[4 * CM_RBF_ACC_PB], lo[4 * CM_RBF_ACC_PB];
    cm_rbf_probe_data(NPROBE, c, w, CM_RBF_SUM_PB, pt);
    cm_rbf_probe_data(0, NULL, NULL, CM_RBF_ACC_PB, pa);
    double best[2][2] = {{INFINITY, INFINITY}, {INFINITY, INFINITY}}; /* [block][alt] */
    for (int r = 0; r <= REPS; ++r) /* round 0 untimed */
        for (int alt = 0; alt < 2; ++alt) {
            memset(acc, 0, sizeof acc);
            double t = cm_rbf_thread_seconds();
            for (int k = 0; k < CALLS; ++k) plain_split(alt, 3, NPROBE, c, w, pt, acc);
            if (r) best[0][alt] = fmin(best[0][alt], cm_rbf_thread_seconds() - t);
            for (int i = 0; i < 4 * CM_RBF_ACC_PB; ++i) hi[i] = 0x1.8p40, lo[i] = 0.0;
            t = cm_rbf_thread_seconds();
            for (int k = 0; k < CALLS; ++k) accf_split(alt, 3, NPROBE, c, w, pa, hi, lo);
            if (r) best[1][alt] = fmin(best[1][alt], cm_rbf_thread_seconds() - t);
        }
    split_plain_alt = best[0][1] < best[0][0];
    split_acc_alt = best[1][1] < best[1][0];
}

static void split_get(int *plain_alt, int *acc_alt)
{
    const int f = atomic_load_explicit(&split_forced, memory_order_relaxed);
    if (f) {
        *plain_alt = (f - 1) & 1, *acc_alt = (f - 1) >> 1;
        return;
    }
    pthread_once(&split_once, split_probe);
    *plain_alt = split_plain_alt, *acc_alt = split_acc_alt;
}

void cm_rbf_sqrt_split(int *plain_sqrt, int *acc_sqrt)
{
    int pa, aa;
    split_get(&pa, &aa);
    *plain_sqrt = pa ? PLAIN_SQRT_B : PLAIN_SQRT_A;
    *acc_sqrt = aa ? ACC_SQRT_B : ACC_SQRT_A;
}

int cm_rbf_sqrt_split_force(int plain_sqrt, int acc_sqrt)
{
    if (plain_sqrt == 0 && acc_sqrt == 0) {
        atomic_store(&split_forced, 0);
        return 0;
    }
    if ((plain_sqrt != PLAIN_SQRT_A && plain_sqrt != PLAIN_SQRT_B) ||
        (acc_sqrt != ACC_SQRT_A && acc_sqrt != ACC_SQRT_B))
        return -1;
    atomic_store(&split_forced, 1 + (plain_sqrt == PLAIN_SQRT_B) + 2 * (acc_sqrt == ACC_SQRT_B));
    return 0;
}

CM_AVX512 void cm_rbf_r3_block_avx512(int nc, size_t m, const double *c, const double *w,
                                      const double *pt, double *acc)
{
    int pa, aa;
    split_get(&pa, &aa);
    plain_split(pa, nc, m, c, w, pt, acc);
}

CM_AVX512 void cm_rbf_r3_strided_avx512(int nc, size_t m, const double *c, size_t ldc,
                                        const double *w, size_t ldw, size_t npt,
                                        const double *pt, size_t ldp, double *acc)
{
    int pa, aa;
    split_get(&pa, &aa);
    if (pa) dispatch_plain(PLAIN_SQRT_B, nc, m, c, ldc, w, ldw, npt, pt, ldp, acc);
    else dispatch_plain(PLAIN_SQRT_A, nc, m, c, ldc, w, ldw, npt, pt, ldp, acc);
}

CM_AVX512 void cm_rbf_r3_acc_block_avx512(int nc, size_t m, const double *c, const double *w,
                                          const double *pt, double *hi, double *lo)
{
    dispatch_acc(0, ACC_NV, nc, m, c, m, w, m, CM_RBF_ACC_PB, pt, CM_RBF_ACC_PB, hi, lo);
}

CM_AVX512 void cm_rbf_r3_acc_strided_avx512(int nc, size_t m, const double *c, size_t ldc,
                                            const double *w, size_t ldw, size_t npt,
                                            const double *pt, size_t ldp, double *hi,
                                            double *lo)
{
    dispatch_acc(0, ACC_NV, nc, m, c, ldc, w, ldw, npt, pt, ldp, hi, lo);
}

CM_AVX512 void cm_rbf_r3_accf_block_avx512(int nc, size_t m, const double *c, const double *w,
                                           const double *pt, double *hi, double *lo)
{
    int pa, aa;
    split_get(&pa, &aa);
    accf_split(aa, nc, m, c, w, pt, hi, lo);
}

int cm_rbf_cpu_avx512(void)
{
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512vl");
}

int cm_rbf_cpu_avx2(void)
{
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}

#else /* not x86-64 GCC/Clang: the generic loops only */

void cm_rbf_r3_block_avx512(int nc, size_t m, const double *c, const double *w,
                            const double *pt, double *acc)
{
    (void)nc, (void)m, (void)c, (void)w, (void)pt, (void)acc;
}

void cm_rbf_r3_strided_avx512(int nc, size_t m, const double *c, size_t ldc, const double *w,
                              size_t ldw, size_t npt, const double *pt, size_t ldp, double *acc)
{
    (void)nc, (void)m, (void)c, (void)ldc, (void)w, (void)ldw, (void)npt, (void)pt, (void)ldp;
    (void)acc;
}

void cm_rbf_r3_acc_block_avx512(int nc, size_t m, const double *c, const double *w,
                                const double *pt, double *hi, double *lo)
{
    (void)nc, (void)m, (void)c, (void)w, (void)pt, (void)hi, (void)lo;
}

void cm_rbf_r3_accf_block_avx512(int nc, size_t m, const double *c, const double *w,
                                 const double *pt, double *hi, double *lo)
{
    (void)nc, (void)m, (void)c, (void)w, (void)pt, (void)hi, (void)lo;
}

void cm_rbf_r3_acc_strided_avx512(int nc, size_t m, const double *c, size_t ldc,
                                  const double *w, size_t ldw, size_t npt, const double *pt,
                                  size_t ldp, double *hi, double *lo)
{
    (void)nc, (void)m, (void)c, (void)ldc, (void)w, (void)ldw, (void)npt, (void)pt;
    (void)ldp, (void)hi, (void)lo;
}

void cm_rbf_sqrt_split(int *plain_sqrt, int *acc_sqrt) { *plain_sqrt = *acc_sqrt = 0; }
int cm_rbf_sqrt_split_force(int plain_sqrt, int acc_sqrt)
{
    return plain_sqrt == 0 && acc_sqrt == 0 ? 0 : -1;
}
int cm_rbf_cpu_avx512(void) { return 0; }
int cm_rbf_cpu_avx2(void) { return 0; }

#endif
