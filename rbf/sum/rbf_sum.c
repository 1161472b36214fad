/* The two O(m^2) loops of the RBF core: kernel sums (evaluation, A*w, A*V) and assembly of
 * the projected system ([SMB12 §3]). Both are written so that GCC vectorises
 * them at -O3 (points in the inner loop, no reductions), and both are compiled for AVX-512,
 * AVX2+FMA and baseline x86-64, chosen at run time: no global -march flag is needed.
 * The sums take any number of columns per pass: up to 4 in registers, more on the entries
 * the first 4 leave in an L1-resident buffer (tile_many), each entry computed once and each
 * column the same bits alone or in a batch (rbf_sum_avx512.c says how; rbf_internal.h,
 * CM_RBF_SUM_MAX_NC). */
#include "rbf_internal.h"
#include "rbf_sum_isa.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif


#define NB 16      /* points held in registers while streaming the centres */
#define PB CM_RBF_SUM_PB /* points per parallel work item (a multiple of NB) */
#define TILE 512   /* centres per tile: 7 x 512 doubles stay in L1 */
#define FB_J 128   /* more than 4 columns: entries of this many centres x NB points kept */

/* log(r2 + tiny) keeps phi(0) = 0 without a branch: r2 = 0 gives 0 * (-690); merged
 * centres are at least 1e-24 apart in r2, so the shift changes nothing else. */
#define CM_TPS_TINY 1e-300

/* log(x) for positive normal x, branch-free so that it vectorises (libm's log is a call
 * that stops the vectoriser: the thin-plate kernel ran 20x slower than r^3 with it).
 * x = 2^e f with f in [sqrt(1/2), sqrt(2)); log f = 2 atanh(s), s = (f-1)/(f+1), |s| < 0.172,
 * by its series to s^21 (truncation < 1e-17); e ln 2 in two parts. Within 2 ulp of libm. */
static inline __attribute__((always_inline)) double log_positive(double x)
{
    uint64_t bits;
    memcpy(&bits, &x, sizeof bits);
    /* exponent as a double without an int64 -> double conversion: 2^52 + e, minus 2^52 */
    uint64_t ebits = (bits >> 52) | UINT64_C(0x4330000000000000);
    double e;
    memcpy(&e, &ebits, sizeof e);
    e -= 4503599627370496.0 + 1023.0;
    uint64_t fbits = (bits & UINT64_C(0x000FFFFFFFFFFFFF)) | UINT64_C(0x3FF0000000000000);
    double f;
    memcpy(&f, &fbits, sizeof f);
    const int big = f > 1.4142135623730951;
    f = big ? 0.5 * f : f;
    e = big ? e + 1.0 : e;
    const double s = (f - 1.0) / (f + 1.0), z = s * s;
    double p = 1.0 / 21.0;
    p = p * z + 1.0 / 19.0;
    p = p * z + 1.0 / 17.0;
    p = p * z + 1.0 / 15.0;
    p = p * z + 1.0 / 13.0;
    p = p * z + 1.0 / 11.0;
    p = p * z + 1.0 / 9.0;
    p = p * z + 1.0 / 7.0;
    p = p * z + 1.0 / 5.0;
    p = p * z + 1.0 / 3.0;
    const double ln2_hi = 6.93147180369123816490e-01, ln2_lo = 1.90821492927058770002e-10;
    return e * ln2_hi + (e * ln2_lo + (2.0 * s + 2.0 * s * z * p));
}

/* a + w f: by one FMA where the code is built for FMA hardware (hf), else rounded twice. The
 * same spelled-out operation in every loop, so that the compiler's contraction cannot make
 * the columns riding on kept entries (cols_body) round differently from the 4 in registers
 * (tile_body). */
static inline __attribute__((always_inline)) double madd(const int hf, double w, double f,
                                                         double a)
{
    return hf ? fma(w, f, a) : a + w * f;
}

static inline __attribute__((always_inline)) double phi_of_r2(const int kern, double r2)
{
    switch (kern) {
    case CM_RBF_TRIHARMONIC: return r2 * sqrt(r2);
    case CM_RBF_BIHARMONIC: return sqrt(r2);
    default: return 0.5 * r2 * log_positive(r2 + CM_TPS_TINY);
    }
}

/* Adds the contributions of centres [0, jn) to NB points. */
static inline __attribute__((always_inline)) void tile_body(const int hf, const int kern,
                                                            const int dim,
                                                            const int nc, const double *c,
                                                            size_t ldc, const double *w,
                                                            size_t ldw, size_t jn,
                                                            const double *pt, double *acc,
                                                            const int keep, double *fb)
{
    const double *restrict cx = c, *restrict cy = c + ldc, *restrict cz = c + 2 * ldc;
    double x[NB], y[NB], z[NB], a[4][NB];
    for (int l = 0; l < NB; ++l) {
        x[l] = pt[l];
        y[l] = pt[PB + l];
        z[l] = dim == 3 ? pt[2 * PB + l] : 0.0;
        for (int q = 0; q < nc; ++q) a[q][l] = acc[q * PB + l];
    }
    for (size_t j = 0; j < jn; ++j) {
        const double xj = cx[j], yj = cy[j], zj = dim == 3 ? cz[j] : 0.0;
        double wj[4];
        for (int q = 0; q < nc; ++q) wj[q] = w[q * ldw + j];
        for (int l = 0; l < NB; ++l) {
            double dx = x[l] - xj, dy = y[l] - yj;
            double r2 = dx * dx + dy * dy;
            if (dim == 3) {
                double dz = z[l] - zj;
                r2 += dz * dz;
            }
            double f = phi_of_r2(kern, r2);
            if (keep) fb[j * NB + l] = f;
            for (int q = 0; q < nc; ++q) a[q][l] = madd(hf, wj[q], f, a[q][l]);
        }
    }
    for (int l = 0; l < NB; ++l)
        for (int q = 0; q < nc; ++q) acc[q * PB + l] = a[q][l];
}

/* Columns [0, nc) (nc <= 4) over the entries of jn centres that the first column group
 * left in fb: the same multiply-add per entry as tile_body, in the same order of j, so a
 * column's sum is the same bits whatever group it rides in. */
static inline __attribute__((always_inline)) void cols_body(const int hf, const int nc,
                                                            const double *fb,
                                                            const double *w, size_t ldw,
                                                            size_t jn, double *acc)
{
    double a[4][NB];
    for (int l = 0; l < NB; ++l)
        for (int q = 0; q < nc; ++q) a[q][l] = acc[q * PB + l];
    for (size_t j = 0; j < jn; ++j) {
        double wj[4];
        for (int q = 0; q < nc; ++q) wj[q] = w[q * ldw + j];
        for (int l = 0; l < NB; ++l) {
            const double f = fb[j * NB + l];
            for (int q = 0; q < nc; ++q) a[q][l] = madd(hf, wj[q], f, a[q][l]);
        }
    }
    for (int l = 0; l < NB; ++l)
        for (int q = 0; q < nc; ++q) acc[q * PB + l] = a[q][l];
}

/* More than 4 columns: per stretch of FB_J centres the first 4 compute the entries phi_ij
 * (kept in fb, L1-resident) and the others run over them four at a time, so each entry is
 * computed once for all columns. */
static inline __attribute__((always_inline)) void tile_many(const int hf, const int kern,
                                                            const int dim,
                                                            int nc, const double *c, size_t ldc,
                                                            const double *w, size_t ldw,
                                                            size_t jn, const double *pt,
                                                            double *acc, double *fb)
{
    for (size_t j0 = 0; j0 < jn; j0 += FB_J) {
        const size_t jb = jn - j0 < FB_J ? jn - j0 : FB_J;
        tile_body(hf, kern, dim, 4, c + j0, ldc, w + j0, ldw, jb, pt, acc, 1, fb);
        for (int g = 4; g < nc; g += 4) {
            const double *wg = w + (size_t)g * ldw + j0;
            double *ag = acc + (size_t)g * PB;
            switch (nc - g) {
            case 1: cols_body(hf, 1, fb, wg, ldw, jb, ag); break;
            case 2: cols_body(hf, 2, fb, wg, ldw, jb, ag); break;
            case 3: cols_body(hf, 3, fb, wg, ldw, jb, ag); break;
            default: cols_body(hf, 4, fb, wg, ldw, jb, ag); break;
            }
        }
    }
}

/* All centres against one block of PB points (pt: dim x PB SoA, acc: nc x PB). Tiles of
 * centres in order, so each point's sum has a fixed order. */
static inline __attribute__((always_inline)) void block_body(const int hf, const int kern,
                                                             const int dim,
                                                             const int nc, int ncm, size_t m,
                                                             const double *c, const double *w,
                                                             const double *pt, double *acc)
{
    double fb[FB_J * NB]; /* nc = 0: more than 4 columns (ncm), tile_many */
    for (size_t t0 = 0; t0 < m; t0 += TILE) {
        size_t jn = m - t0 < TILE ? m - t0 : TILE;
        for (int b = 0; b < PB; b += NB) {
            if (nc == 0)
                tile_many(hf, kern, dim, ncm, c + t0, m, w + t0, m, jn, pt + b, acc + b, fb);
            else tile_body(hf, kern, dim, nc, c + t0, m, w + t0, m, jn, pt + b, acc + b, 0, NULL);
        }
    }
}

/* One instantiation per (kernel, nc <= 4) so that the inner loop has constant trip counts;
 * more columns share the 4-column body's entries (tile_many). */
#define CM_NC_DISPATCH(k, d)                                                                   \
    switch (nc) {                                                                              \
    case 1: block_body(hf, k, d, 1, 1, m, c, w, pt, acc); break;                                   \
    case 2: block_body(hf, k, d, 2, 2, m, c, w, pt, acc); break;                                   \
    case 3: block_body(hf, k, d, 3, 3, m, c, w, pt, acc); break;                                   \
    case 4: block_body(hf, k, d, 4, 4, m, c, w, pt, acc); break;                                   \
    default: block_body(hf, k, d, 0, nc, m, c, w, pt, acc); break;                                 \
    }
#define CM_BLOCK_DISPATCH                                                                      \
    if (kern == 0) CM_NC_DISPATCH(0, 3)                                                        \
    else if (kern == 1) CM_NC_DISPATCH(1, 3)                                                   \
    else CM_NC_DISPATCH(2, 2)

typedef void (*block_fn)(int kern, int nc, size_t m, const double *c, const double *w,
                         const double *pt, double *acc);

static void block_generic(int kern, int nc, size_t m, const double *c, const double *w,
                          const double *pt, double *acc)
{
    const int hf = 0;
    CM_BLOCK_DISPATCH
}

__attribute__((target("avx2,fma"))) static void block_avx2(int kern, int nc, size_t m,
                                                            const double *c, const double *w,
                                                            const double *pt, double *acc)
{
    const int hf = 1;
    CM_BLOCK_DISPATCH
}

__attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma"))) static void
block_avx512(int kern, int nc, size_t m, const double *c, const double *w, const double *pt,
             double *acc)
{
    const int hf = 1;
    CM_BLOCK_DISPATCH
}

/* AVX-512 blocks for r^3 in 3D by hand (rbf_sum_avx512.c), the other kernels as compiled */
static void block_avx512_hand(int kern, int nc, size_t m, const double *c, const double *w,
                              const double *pt, double *acc)
{
    if (kern == (int)CM_RBF_TRIHARMONIC) cm_rbf_r3_block_avx512(nc, m, c, w, pt, acc);
    else block_avx512(kern, nc, m, c, w, pt, acc);
}

int cm_rbf_isa_supported(cm_rbf_isa isa)
{
    switch (isa) {
    case CM_RBF_ISA_AUTO:
    case CM_RBF_ISA_GENERIC: return 1;
    case CM_RBF_ISA_AVX2: return cm_rbf_cpu_avx2();
    default: return cm_rbf_cpu_avx512();
    }
}

cm_rbf_isa cm_rbf_isa_auto(void)
{
    if (cm_rbf_cpu_avx512()) return CM_RBF_ISA_AVX512;
    if (cm_rbf_cpu_avx2()) return CM_RBF_ISA_AVX2;
    return CM_RBF_ISA_GENERIC;
}

static block_fn pick_block(cm_rbf_isa isa)
{
    if (isa == CM_RBF_ISA_AUTO) isa = cm_rbf_isa_auto();
    switch (isa) {
    case CM_RBF_ISA_AVX512: return block_avx512_hand;
    case CM_RBF_ISA_AVX512_AUTOVEC: return block_avx512;
    case CM_RBF_ISA_AVX2: return block_avx2;
    default: return block_generic;
    }
}

int cm_rbf_threads(const cm_context *ctx)
{
    /* the dense kernels have work for every thread the context allows */
    return cm_context_threads_for(ctx, SIZE_MAX, 1);
}

void cm_rbf_tick_init(cm_rbf_tick *t, cm_context *ctx, const char *stage, double total)
{
    t->ctx = ctx;
    t->stage = stage;
    t->done = 0.0;
    t->total = total;
    t->last = cm_wtime();
    t->reported = 0;
    t->status = CM_OK;
    t->chunk_pairs = CM_RBF_TICK_PAIRS;
    t->tree_chunks = CM_RBF_TICK_TREE_CHUNKS;
}

void cm_rbf_tick_restart(cm_rbf_tick *t, double total)
{
    t->done = 0.0;
    t->total = total;
    t->last = cm_wtime();
    t->reported = 0;
}

int cm_rbf_tick_add(cm_rbf_tick *t, double work)
{
    if (!t) return 0;
    t->done += work;
    if (t->done > t->total) t->done = t->total;
    const double now = cm_wtime();
    /* not after the last chunk: a loop that ends within its first report's time reports
     * nothing, so small sums make no callbacks at all */
    if (t->status == CM_OK && t->done < t->total && now - t->last >= CM_RBF_TICK_SECONDS) {
        t->last = now;
        t->reported = 1;
        t->status = cm_progress(t->ctx, t->stage, t->done, t->total);
    }
    return t->status < 0;
}

cm_status cm_rbf_tick_finish(cm_rbf_tick *t)
{
    if (!t || t->status < 0 || !t->reported) return t ? t->status : CM_OK;
    return t->status = cm_progress(t->ctx, t->stage, t->total, t->total);
}

long cm_rbf_tick_chunk(const cm_rbf_tick *tick, double per_item, long items, int threads)
{
    if (items < 1) return 1;
    if (!tick) return items;
    double per = tick->chunk_pairs / (per_item > 1.0 ? per_item : 1.0);
    /* enough items that a static schedule keeps every thread busy */
    const double least = 8.0 * (threads > 1 ? threads : 1);
    if (per < least) per = least;
    return per >= (double)items ? items : (long)per;
}

void cm_rbf_kernel_sum(cm_rbf_kernel kernel, int dim, size_t m, const double *c,
                       const double *w, int nc, size_t n, const double *p, size_t ldp,
                       double *out, size_t ldo, int threads)
{
    cm_rbf_kernel_sum_isa(CM_RBF_ISA_AUTO, kernel, dim, m, c, w, nc, n, p, ldp, out, ldo,
                          threads);
}

/* Points of blocks [b0, b1) of PB against all centres. work: threads x nc x PB sums for
 * more than 4 columns (NULL: nc <= 4, on the stack). */
static void sum_blocks(block_fn fn, int kern, int dim, size_t m, const double *c,
                       const double *w, int nc, size_t n, const double *p, size_t ldp,
                       double *out, size_t ldo, int threads, int parallel, long b0, long b1,
                       double *work)
{
#pragma omp parallel num_threads(threads) if (parallel)
    {
        double acc4[4 * PB], *acc = acc4;
#ifdef _OPENMP
        if (work) acc = work + (size_t)omp_get_thread_num() * (size_t)nc * PB;
#else
        if (work) acc = work;
#endif
#pragma omp for schedule(static)
    for (long b = b0; b < b1; ++b) {
        double pt[3 * PB];
        const size_t i0 = (size_t)b * PB;
        const size_t cnt = n - i0 < PB ? n - i0 : PB;
        for (int d = 0; d < 3; ++d) {
            for (size_t l = 0; l < PB; ++l) {
                /* pad the last block with its last point; the padding is not written out */
                size_t i = l < cnt ? i0 + l : i0 + cnt - 1;
                pt[d * PB + l] = d < dim ? p[d * ldp + i] : 0.0;
            }
        }
        memset(acc, 0, (size_t)nc * PB * sizeof *acc);
        fn(kern, nc, m, c, w, pt, acc);
        for (size_t l = 0; l < cnt; ++l)
            for (int q = 0; q < nc; ++q) out[(i0 + l) * ldo + (size_t)q] = acc[q * PB + l];
    }
    }
}

/* cm_rbf_kernel_sum_isa in chunks of blocks with tick (NULL: one chunk); nonzero when the
 * tick said stop. */
static int sum_isa(cm_rbf_isa isa, cm_rbf_kernel kernel, int dim, size_t m, const double *c,
                   const double *w, int nc, size_t n, const double *p, size_t ldp, double *out,
                   size_t ldo, int threads, cm_rbf_tick *tick)
{
    if (nc > CM_RBF_SUM_MAX_NC) { /* passes of CM_RBF_SUM_MAX_NC: the same bits per column */
        for (int g = 0; g < nc; g += CM_RBF_SUM_MAX_NC)
            if (sum_isa(isa, kernel, dim, m, c, w + (size_t)g * m,
                        nc - g < CM_RBF_SUM_MAX_NC ? nc - g : CM_RBF_SUM_MAX_NC, n, p, ldp,
                        out + g, ldo, threads, tick))
                return 1;
        return 0;
    }
    const block_fn fn = pick_block(isa);
    const long nblocks = (long)((n + PB - 1) / PB);
    const int kern = (int)kernel;
    const int parallel = (double)n * (double)m > CM_RBF_PARALLEL_MIN_PAIRS && threads > 1;
    /* the r^3 self product computes each entry once for both rows (its sums come in parts) */
    if (fn == block_avx512_hand && kernel == CM_RBF_TRIHARMONIC && dim == 3 && p == c &&
        ldp == m && n == m && m >= CM_RBF_SELF_MIN_M && nc <= CM_RBF_SELF_MAX_NC &&
        !cm_rbf_r3_self_avx512(nc, m, c, w, NULL, out, ldo, parallel ? threads : 1))
        return cm_rbf_tick_add(tick, (double)n * (double)m);
    double *work = NULL;
    if (nc > 4) {
        work = malloc((size_t)(parallel ? threads : 1) * (size_t)nc * PB * sizeof *work);
        if (!work) { /* groups of 4 columns: slower, the same bits */
            for (int g = 0; g < nc; g += 4)
                if (sum_isa(isa, kernel, dim, m, c, w + (size_t)g * m, nc - g < 4 ? nc - g : 4,
                            n, p, ldp, out + g, ldo, threads, tick))
                    return 1;
            return 0;
        }
    }
    const long chunk = cm_rbf_tick_chunk(tick, (double)PB * (double)m, nblocks, threads);
    int stop = 0;
    for (long b0 = 0; b0 < nblocks && !stop; b0 += chunk) {
        const long b1 = nblocks - b0 < chunk ? nblocks : b0 + chunk;
        sum_blocks(fn, kern, dim, m, c, w, nc, n, p, ldp, out, ldo, threads, parallel, b0, b1,
                   work);
        const size_t i1 = (size_t)b1 * PB < n ? (size_t)b1 * PB : n;
        stop = cm_rbf_tick_add(tick, (double)(i1 - (size_t)b0 * PB) * (double)m);
    }
    free(work);
    return stop;
}

void cm_rbf_kernel_sum_isa(cm_rbf_isa isa, cm_rbf_kernel kernel, int dim, size_t m,
                           const double *c, const double *w, int nc, size_t n, const double *p,
                           size_t ldp, double *out, size_t ldo, int threads)
{
    sum_isa(isa, kernel, dim, m, c, w, nc, n, p, ldp, out, ldo, threads, NULL);
}

/* ---- assembly of the projected matrix ---- */

/* out[t] = sign * (A - V Z' - Z V')(a, b0 + t) for t < count (centre indices): one stretch
 * of a row or column of the symmetric projected matrix. */
static inline __attribute__((always_inline)) void stretch_body(const int kern, const int dim,
                                                               size_t m, const double *c,
                                                               const double *v, const double *z,
                                                               double sign, size_t a, size_t b0,
                                                               size_t count, double *out0)
{
    const double *restrict cx = c, *restrict cy = c + m, *restrict cz = c + 2 * m;
    const double xa = cx[a], ya = cy[a], za = dim == 3 ? cz[a] : 0.0;
    /* the k = dim + 1 columns of V and Z spelled out: a loop over them here would stop
     * GCC from vectorising the loop over b */
    const double *restrict v0 = v, *restrict v1 = v + m, *restrict v2 = v + 2 * m;
    const double *restrict v3 = dim == 3 ? v + 3 * m : v;
    const double *restrict z0 = z, *restrict z1 = z + m, *restrict z2 = z + 2 * m;
    const double *restrict z3 = dim == 3 ? z + 3 * m : z;
    const double v0a = v0[a], v1a = v1[a], v2a = v2[a], v3a = v3[a];
    const double z0a = z0[a], z1a = z1[a], z2a = z2[a], z3a = z3[a];
    double *restrict out = out0 - b0;
    /* out never overlaps the inputs; without this GCC gives up on more than 10 run-time
     * alias checks and leaves the loop scalar */
#pragma GCC ivdep
    for (size_t b = b0; b < b0 + count; ++b) {
        double dx = cx[b] - xa, dy = cy[b] - ya;
        double r2 = dx * dx + dy * dy;
        if (dim == 3) {
            double dz = cz[b] - za;
            r2 += dz * dz;
        }
        double e = phi_of_r2(kern, r2);
        e -= v0[b] * z0a + z0[b] * v0a;
        e -= v1[b] * z1a + z1[b] * v1a;
        e -= v2[b] * z2a + z2[b] * v2a;
        if (dim == 3) e -= v3[b] * z3a + z3[b] * v3a;
        out[b] = sign * e;
    }
}

#define CM_STRETCH_DISPATCH                                                                    \
    switch (kern) {                                                                            \
    case 0: stretch_body(0, 3, m, c, v, z, sign, a, b0, count, out); break;                   \
    case 1: stretch_body(1, 3, m, c, v, z, sign, a, b0, count, out); break;                   \
    default: stretch_body(2, 2, m, c, v, z, sign, a, b0, count, out); break;                  \
    }

typedef void (*stretch_fn)(int kern, size_t m, const double *c, const double *v,
                           const double *z, double sign, size_t a, size_t b0, size_t count,
                           double *out);

static void stretch_generic(int kern, size_t m, const double *c, const double *v,
                            const double *z, double sign, size_t a, size_t b0, size_t count,
                            double *out)
{
    CM_STRETCH_DISPATCH
}

__attribute__((target("avx2,fma"))) static void
stretch_avx2(int kern, size_t m, const double *c, const double *v, const double *z, double sign,
             size_t a, size_t b0, size_t count, double *out)
{
    CM_STRETCH_DISPATCH
}

__attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma"))) static void
stretch_avx512(int kern, size_t m, const double *c, const double *v, const double *z,
               double sign, size_t a, size_t b0, size_t count, double *out)
{
    CM_STRETCH_DISPATCH
}

static stretch_fn pick_stretch(void)
{
#if defined(__x86_64__) && defined(__GNUC__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
        __builtin_cpu_supports("avx512vl"))
        return stretch_avx512;
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return stretch_avx2;
#endif
    return stretch_generic;
}

/* Rectangular full packed storage (LAPACK's RFP, TRANSR = 'N', UPLO = 'L') of the n x n
 * lower triangle: half the memory of full storage, and dpftrf factors it with the same
 * BLAS-3 calls as dpotrf. Column col of the RFP array (n even: n/2 columns of n + 1;
 * n odd: (n + 1)/2 columns of n) holds a stretch of row (half + head - 1) of the trailing
 * triangle (head entries, head = col + 1 for n even, col for n odd), then column col of the
 * leading block from the diagonal down. Every RFP column has the same length, so a static
 * schedule over them is balanced. */
/* Columns [c0, c1) of the RFP array. */
static void assemble_cols(stretch_fn fn, int kern, size_t m, const double *c, size_t kk,
                          const double *v, const double *z, double sign, double *rfp,
                          size_t n, int threads, int parallel, long c0, long c1)
{
    const int even = n % 2 == 0;
    const size_t half = even ? n / 2 : (n + 1) / 2, lda = even ? n + 1 : n;
#pragma omp parallel for schedule(static) num_threads(threads) if (parallel)
    for (long lc = c0; lc < c1; ++lc) {
        const size_t col = (size_t)lc, head = even ? col + 1 : col;
        double *out = rfp + col * lda;
        if (head > 0) fn(kern, m, c, v, z, sign, kk + half + head - 1, kk + half, head, out);
        fn(kern, m, c, v, z, sign, kk + col, kk + col, n - col, out + head);
    }
}

int cm_rbf_assemble_projected_tick(cm_rbf_kernel kernel, int dim, size_t m, const double *c,
                                   int k, const double *v, const double *z, double sign,
                                   double *rfp, int threads, cm_rbf_tick *tick)
{
    const stretch_fn fn = pick_stretch();
    const size_t n = m - (size_t)k, kk = (size_t)k;
    const size_t half = n % 2 == 0 ? n / 2 : (n + 1) / 2, lda = n % 2 == 0 ? n + 1 : n;
    (void)dim;
    const int parallel = (double)n * (double)n > 2.0 * CM_RBF_PARALLEL_MIN_PAIRS && threads > 1;
    /* chunks of columns, lda entries (kernel evaluations) each */
    const long chunk = cm_rbf_tick_chunk(tick, (double)lda, (long)half, threads);
    for (long c0 = 0; c0 < (long)half; c0 += chunk) {
        const long c1 = (long)half - c0 < chunk ? (long)half : c0 + chunk;
        assemble_cols(fn, (int)kernel, m, c, kk, v, z, sign, rfp, n, threads, parallel, c0, c1);
        if (cm_rbf_tick_add(tick, (double)(c1 - c0) * (double)lda)) return 1;
    }
    return 0;
}

void cm_rbf_assemble_projected(cm_rbf_kernel kernel, int dim, size_t m, const double *c,
                               int k, const double *v, const double *z, double sign,
                               double *rfp, int threads)
{
    cm_rbf_assemble_projected_tick(kernel, dim, m, c, k, v, z, sign, rfp, threads, NULL);
}

const char *cm_rbf_kernel_name(cm_rbf_kernel k)
{
    switch (k) {
    case CM_RBF_TRIHARMONIC: return "triharmonic";
    case CM_RBF_BIHARMONIC: return "biharmonic";
    case CM_RBF_THIN_PLATE: return "thin-plate";
    }
    return "unknown";
}

/* Kernel sums for any number of components, all in one pass (passes of CM_RBF_SUM_MAX_NC). */
void cm_rbf_kernel_sum_all(const cm_rbf *r, const double *w, int ncomp, size_t n,
                           const double *p, size_t ldp, double *out, int threads)
{
    cm_rbf_kernel_sum_all_tick(r, w, ncomp, n, p, ldp, out, threads, NULL);
}

int cm_rbf_kernel_sum_all_tick(const cm_rbf *r, const double *w, int ncomp, size_t n,
                               const double *p, size_t ldp, double *out, int threads,
                               cm_rbf_tick *tick)
{
    for (int g = 0; g < ncomp; g += CM_RBF_SUM_MAX_NC) {
        int nc = ncomp - g < CM_RBF_SUM_MAX_NC ? ncomp - g : CM_RBF_SUM_MAX_NC;
        if (sum_isa(CM_RBF_ISA_AUTO, r->kernel, r->dim, r->m, r->c, w + (size_t)g * r->m, nc, n,
                    p, ldp, out + g, (size_t)ncomp, threads, tick))
            return 1;
    }
    return 0;
}

int cm_rbf_kernel_sum_tick(cm_rbf_kernel kernel, int dim, size_t m, const double *c,
                           const double *w, int nc, size_t n, const double *p, size_t ldp,
                           double *out, size_t ldo, int threads, cm_rbf_tick *tick)
{
    return sum_isa(CM_RBF_ISA_AUTO, kernel, dim, m, c, w, nc, n, p, ldp, out, ldo, threads, tick);
}
