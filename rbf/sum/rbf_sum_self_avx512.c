/* The r^3 self product out = A w, A_ij = |c_i - c_j|^3, by hand for AVX-512, compensated
 * (fixed binade) or plain, each entry computed once for both of its rows. Why: the Krylov
 * products of the iterative solver (iterative/rbf_fgmres.c) and its exact residuals are self
 * products (the targets are the centres), and the kernel sums are bound by the distance and
 * the square root, not by the accumulation (rbf_sum_avx512.c). phi_ij = phi_ji bit for bit,
 * so one evaluation serves w_j phi_ij in row i and w_i phi_ij in row j: per pair of
 * contributions one distance and sqrt instead of two, the accumulation as before. Measured
 * on the model-167 Xeon (RESULTS.md, RBF solvers), 2 threads: compensated
 * 1.3-1.6x, plain 1.4-2.0x the general blocks at 2e4-6e4 centres; the 1.2e5-centre fit's
 * solve 1.43x.
 *
 * How. The centres fall into J tiles of SELF_T. A tile meets every block of 16 centres
 * before it (two vectors held in registers with their running sums) and itself. So that a
 * vector of 8 rows i meets 8 distinct centres j in every lane, each group of 8 of the tile
 * is stored in all 8 lane rotations (rotation r, lane k: centre (k + r) mod 8 of the group;
 * loads instead of permutes, which would take the FMA ports); the contributions to the
 * rows j are summed in rotated vectors beside them and un-rotated once per tile. Inside a
 * tile, groups meet the later groups the same way and their own group in rotations 1..7
 * (every ordered pair once, so the row side alone).
 *
 * Exactness (compensated). Every running sum starts at big_q = 1.5 2^k with 2^k >= 4
 * sum_j |w_qj| dmax^3 (rbf_sum_acc.c: fixed_binade), so it stays in one binade and its
 * offset S - big is a multiple of the binade's ulp below 2^k/4: the partial sums of a row
 * (its row side in each thread, its column side in its tile) add exactly, and the row is
 * the one-pass block's value up to the order in which the rounding remainders are summed
 * (eps^2-small; the same bits in every test so far). Plain sums are added in another order
 * than the general block's, so they differ from it, and between thread counts, by rounding
 * (a few eps sum_j |w_j phi_ij|). Tiles go to threads in a fixed order (static schedule),
 * so a thread count gives the same bits every run.
 *
 * Any number of columns: the first 4 compute the entries of a row block against the tile
 * (kept, 32 KB) and the others run over them 4 at a time, each column with its own updates
 * in its own order (the same bits alone or in a batch). But the tile's rotated weights and
 * column sums grow with the columns and leave the caches: the sums take this product only
 * up to CM_RBF_SELF_MAX_NC columns (rbf_sum_isa.h). */
#include "rbf_sum_isa.h"
#include "rbf_internal.h" /* CM_RBF_SUM_MAX_NC */

#if defined(__x86_64__) && defined(__GNUC__)
#include "rbf_r3_avx512.h"

#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

/* centres per J tile: 32 groups of 8 in 8 rotations, ~120 KB with their sums (128 and 512
 * measured the same at 6e4 centres) */
#define SELF_T 256
#define SELF_G (SELF_T / 8)
#define IB 16 /* rows per register block (two vectors) */

/* s (+ e) += w f: the fixed-binade compensated update (comp) or a plain FMA */
CM_AVX512 CM_INLINE void add(const int comp, __m512d *s, __m512d *e, __m512d w, __m512d f)
{
    if (comp)
        cm_accf(s, e, w, f);
    else
        *s = _mm512_fmadd_pd(w, f, *s);
}

/* The rotated data of a tile: for group g and rotation r, 3 + nc vectors (x, y, z, w_q) at
 * rot + (8 g + r) * RS, RS = 8 (3 + nc); the column sums beside them, 2 nc vectors (s_q,
 * e_q) at jac + (8 g + r) * JS, JS = 16 nc. */
#define RS(nc) (8 * (3 + (nc)))
#define JS(nc) (16 * (nc))

/* Rows [nv vectors at ic: coordinate d at ic + d ldi, weights q at iw + q ldi, sums at s, e +
 * q lds] against the groups [0, ng) of rot, all rotations: each entry added to the row sums
 * (weights of the rotated centres) and to the rotated column sums (weights of the rows).
 * nsq of the two vectors take vsqrtpd. The compensated passes take it for both: with twice
 * the accumulation per sqrt of the general blocks the FMA pipes are the busier unit even
 * on the Xeon, where the general compensated block is faster with one of its two vectors on
 * sqrt_fma (6e4 centres, 2 threads: 1.63-1.85 s all vsqrtpd against 1.94-2.77 s half on
 * the FMA pipes, same runs). The plain passes follow the general plain block's probed
 * split: half on the FMA pipes where it keeps half there (the Xeon: 1.47-1.65x the general
 * block at 4e4 against 1.30-1.34x all on vsqrtpd), all on vsqrtpd where it keeps 3 of 4. */
CM_AVX512 CM_INLINE void sym_pass(const int comp, const int nsq, const int nv, const int nc,
                                  const int fm, int ncs, int q0, const double *ic,
                                  const double *iw, size_t ldi, double *is, double *ie,
                                  size_t lds, const double *rot, double *jac, int ng, double *fb)
{
    __m512d x[2], y[2], z[2], wi[4][2], s[4][2], e[4][2];
    for (int v = 0; v < nv; ++v) {
        if (fm != 2) {
            x[v] = _mm512_loadu_pd(ic + 8 * v);
            y[v] = _mm512_loadu_pd(ic + ldi + 8 * v);
            z[v] = _mm512_loadu_pd(ic + 2 * ldi + 8 * v);
        }
        for (int q = 0; q < nc; ++q) {
            wi[q][v] = _mm512_loadu_pd(iw + q * ldi + 8 * v);
            s[q][v] = _mm512_loadu_pd(is + q * lds + 8 * v);
            e[q][v] = comp ? _mm512_loadu_pd(ie + q * lds + 8 * v) : _mm512_setzero_pd();
        }
    }
    for (int gr = 0; gr < 8 * ng; ++gr) {
        const double *R = rot + (size_t)gr * RS(ncs), *Rw = R + 24 + 8 * q0;
        double *J = jac + (size_t)gr * JS(ncs) + 16 * q0;
        __m512d js[4], je[4];
        for (int q = 0; q < nc; ++q) {
            js[q] = _mm512_load_pd(J + 16 * q);
            je[q] = comp ? _mm512_load_pd(J + 16 * q + 8) : _mm512_setzero_pd();
        }
        for (int v = 0; v < nv; ++v) {
            __m512d f;
            if (fm == 2) {
                f = _mm512_load_pd(fb + (size_t)(gr * nv + v) * 8);
            } else {
                const __m512d xj = _mm512_load_pd(R), yj = _mm512_load_pd(R + 8);
                const __m512d zj = _mm512_load_pd(R + 16);
                f = cm_r3_of(v >= nsq, x[v], y[v], z[v], xj, yj, zj);
                if (fm == 1) _mm512_store_pd(fb + (size_t)(gr * nv + v) * 8, f);
            }
            for (int q = 0; q < nc; ++q) {
                add(comp, &s[q][v], &e[q][v], _mm512_load_pd(Rw + 8 * q), f);
                add(comp, &js[q], &je[q], wi[q][v], f);
            }
        }
        for (int q = 0; q < nc; ++q) {
            _mm512_store_pd(J + 16 * q, js[q]);
            if (comp) _mm512_store_pd(J + 16 * q + 8, je[q]);
        }
    }
    for (int v = 0; v < nv; ++v)
        for (int q = 0; q < nc; ++q) {
            _mm512_storeu_pd(is + q * lds + 8 * v, s[q][v]);
            if (comp) _mm512_storeu_pd(ie + q * lds + 8 * v, e[q][v]);
        }
}

/* sym_pass for all ncs columns: up to 4 in registers computing the entries; more: the first
 * 4 compute them (kept in fb) and the others, 4 at a time, run over them, each column with
 * the same updates in the same order as alone. iw, is, ie: column 0's. */
CM_AVX512 CM_INLINE void sym_all(const int comp, const int nsq, const int nv, int ncs,
                                 const double *ic, const double *iw, size_t ldi, double *is,
                                 double *ie, size_t lds, const double *rot, double *jac, int ng,
                                 double *fb)
{
#define CM_SYM(g, fm, q0)                                                                      \
    sym_pass(comp, nsq, nv, g, fm, ncs, q0, ic, iw + (size_t)(q0) * ldi, ldi,                  \
             is + (size_t)(q0) * lds, ie + (size_t)(q0) * lds, lds, rot, jac, ng, fb)
    switch (ncs) {
    case 1: CM_SYM(1, 0, 0); return;
    case 2: CM_SYM(2, 0, 0); return;
    case 3: CM_SYM(3, 0, 0); return;
    case 4: CM_SYM(4, 0, 0); return;
    default: CM_SYM(4, 1, 0); break;
    }
    for (int g = 4; g < ncs; g += 4) switch (ncs - g) {
        case 1: CM_SYM(1, 2, g); break;
        case 2: CM_SYM(2, 2, g); break;
        case 3: CM_SYM(3, 2, g); break;
        default: CM_SYM(4, 2, g); break;
        }
#undef CM_SYM
}

/* Group g of a tile against itself, rotations 1..7 (every ordered pair of distinct lanes
 * once): the row side only, columns [q0, q0 + nc) of ncs (the entries recomputed per
 * group of columns: 7 vectors a group, a small share). */
CM_AVX512 CM_INLINE void own_group(const int comp, const int nc, int ncs, int q0,
                                   const double *rot, double *is, double *ie, size_t lds)
{
    const __m512d x = _mm512_load_pd(rot), y = _mm512_load_pd(rot + 8);
    const __m512d z = _mm512_load_pd(rot + 16);
    __m512d s[4], e[4];
    for (int q = 0; q < nc; ++q) {
        s[q] = _mm512_loadu_pd(is + q * lds);
        e[q] = _mm512_loadu_pd(ie + q * lds);
    }
    for (int r = 1; r < 8; ++r) {
        const double *R = rot + (size_t)r * RS(ncs);
        const __m512d f =
            cm_r3_of(0, x, y, z, _mm512_load_pd(R), _mm512_load_pd(R + 8), _mm512_load_pd(R + 16));
        for (int q = 0; q < nc; ++q)
            add(comp, &s[q], &e[q], _mm512_load_pd(R + 24 + 8 * (q0 + q)), f);
    }
    for (int q = 0; q < nc; ++q) {
        _mm512_storeu_pd(is + q * lds, s[q]);
        _mm512_storeu_pd(ie + q * lds, e[q]);
    }
}

CM_AVX512 CM_INLINE void own_all(const int comp, int ncs, const double *rot, double *is,
                                 double *ie, size_t lds)
{
    for (int g = 0; g < ncs; g += 4) {
        double *sg = is + (size_t)g * lds, *eg = ie + (size_t)g * lds;
        switch (ncs - g >= 4 ? 4 : ncs - g) {
        case 1: own_group(comp, 1, ncs, g, rot, sg, eg, lds); break;
        case 2: own_group(comp, 2, ncs, g, rot, sg, eg, lds); break;
        case 3: own_group(comp, 3, ncs, g, rot, sg, eg, lds); break;
        default: own_group(comp, 4, ncs, g, rot, sg, eg, lds); break;
        }
    }
}

/* One J tile [j0, j0 + jn): its rotations (a tail group padded with copies of the last
 * centre at weight 0, which adds exact zeros), the blocks of rows before it, its own
 * pairs, and its column sums un-rotated into the offsets cs - big and remainders ce (the
 * tile's own entries of those arrays, stride lds). is, ie: this thread's row sums. */
CM_AVX512 CM_INLINE void tile(const int comp, const int nsq, int nc, size_t m,
                              const double *c, const double *w, const double *big, size_t j0,
                              size_t jn, double *rot, double *jac, double *is, double *ie,
                              size_t lds, double *cs, double *ce, double *fb)
{
    const int ng = (int)((jn + 7) / 8);
    for (int g = 0; g < ng; ++g)
        for (int r = 0; r < 8; ++r) {
            double *R = rot + (size_t)(8 * g + r) * RS(nc), *J = jac + (size_t)(8 * g + r) * JS(nc);
            for (int k = 0; k < 8; ++k) {
                const size_t l = (size_t)(8 * g + ((k + r) & 7));
                const size_t j = j0 + (l < jn ? l : jn - 1);
                for (int d = 0; d < 3; ++d)
                    R[8 * d + k] = c[d * m + j];
                for (int q = 0; q < nc; ++q) {
                    R[24 + 8 * q + k] = l < jn ? w[q * m + j] : 0.0;
                    J[16 * q + k] = big[q];
                    J[16 * q + 8 + k] = 0.0;
                }
            }
        }
    /* the tile's own pairs: group g (its rotation 0 holds it in order) against the later
     * groups and itself; rows of the padding lanes land beyond m in is, ie (lds >= tiles'
     * end) and are never read */
    for (int g = 0; g < ng; ++g) {
        const double *R0 = rot + (size_t)8 * g * RS(nc);
        double *rs = is + j0 + 8 * (size_t)g, *re = ie + j0 + 8 * (size_t)g;
        if (g + 1 < ng)
            sym_all(comp, nsq, 1, nc, R0, R0 + 24, 8, rs, re, lds,
                    rot + (size_t)8 * (g + 1) * RS(nc), jac + (size_t)8 * (g + 1) * JS(nc),
                    ng - g - 1, fb);
        own_all(comp, nc, R0, rs, re, lds);
    }
    for (size_t i0 = 0; i0 < j0; i0 += IB)
        sym_all(comp, nsq, 2, nc, c + i0, w + i0, m, is + i0, ie + i0, lds, rot, jac, ng, fb);
    for (int g = 0; g < ng; ++g)
        for (int k = 0; k < 8 && 8 * (size_t)g + (size_t)k < jn; ++k)
            for (int q = 0; q < nc; ++q) {
                double off = 0.0, rem = 0.0;
                for (int r = 0; r < 8; ++r) {
                    const double *J = jac + (size_t)(8 * g + r) * JS(nc) + 16 * q;
                    off += J[(k - r) & 7] - big[q]; /* exact: multiples of one ulp */
                    rem += J[8 + ((k - r) & 7)];
                }
                cs[q * lds + j0 + 8 * (size_t)g + (size_t)k] = off;
                ce[q * lds + j0 + 8 * (size_t)g + (size_t)k] = rem;
            }
}

/* All tiles on threads. mode: 0 plain with one of the two vectors on the FMA pipes, 1
 * plain all on vsqrtpd, 2 compensated. Thread t's row sums at rows + t per (s, then e, nc
 * lds each), its tile scratch at scratch + t tsz; cols: the column sums of all tiles. */
CM_AVX512 static void run_tiles(int mode, int nc, size_t m, const double *c, const double *w,
                                const double *big, size_t lds, size_t per, double *rows,
                                double *cols, size_t tsz, double *scratch, int threads)
{
    const long nt = (long)((m + SELF_T - 1) / SELF_T);
#pragma omp parallel num_threads(threads)
    {
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        double *is = rows + (size_t)t * per, *ie = is + (size_t)nc * lds;
        double *rot = scratch + (size_t)t * tsz, *jac = rot + (size_t)8 * SELF_G * RS(nc);
        double *fb = jac + (size_t)8 * SELF_G * JS(nc); /* the entries, more than 4 columns */
        /* the last tiles meet the most rows: dealt first, round robin (a fixed order) */
#pragma omp for schedule(static, 1)
        for (long k = 0; k < nt; ++k) {
            const size_t j0 = (size_t)(nt - 1 - k) * SELF_T;
            const size_t jn = m - j0 < SELF_T ? m - j0 : SELF_T;
            double *cs = cols, *ce = cols + (size_t)nc * lds;
#define CM_SELF_TILE(a, q) tile(a, q, nc, m, c, w, big, j0, jn, rot, jac, is, ie, lds, cs, ce, fb)
            if (mode == 0) CM_SELF_TILE(0, 1);
            else if (mode == 1) CM_SELF_TILE(0, 2);
            else CM_SELF_TILE(1, 2);
#undef CM_SELF_TILE
        }
    }
}

int cm_rbf_r3_self_avx512(int nc, size_t m, const double *c, const double *w, const double *big,
                          double *out, size_t ldo, int threads)
{
    if (threads < 1) threads = 1;
    if (nc > CM_RBF_SUM_MAX_NC) { /* passes of CM_RBF_SUM_MAX_NC: the same bits per column */
        for (int g = 0; g < nc; g += CM_RBF_SUM_MAX_NC)
            if (cm_rbf_r3_self_avx512(nc - g < CM_RBF_SUM_MAX_NC ? nc - g : CM_RBF_SUM_MAX_NC, m,
                                      c, w + (size_t)g * m, big ? big + g : NULL, out + g, ldo,
                                      threads))
                return 1; /* (only the first pass can fail: sizes only shrink) */
        return 0;
    }
    double zero[CM_RBF_SUM_MAX_NC] = {0.0};
    const int comp = big != NULL;
    if (!comp) big = zero;
    const size_t lds = (m + SELF_T - 1) / SELF_T * SELF_T;
    const size_t per = (size_t)2 * nc * lds;                   /* a thread's row sums s, e */
    /* its tile's rotations and sums, and the entries of a row block (2 vectors) */
    const size_t tsz = (size_t)8 * SELF_G * (RS(nc) + JS(nc)) + (size_t)2 * 8 * 8 * SELF_G;
    double *rows = malloc(((size_t)threads * per + per) * sizeof(double));
    double *scratch = aligned_alloc(64, (size_t)threads * tsz * sizeof(double));
    if (!rows || !scratch) {
        free(rows);
        free(scratch);
        return 1;
    }
    double *cols = rows + (size_t)threads * per;
    for (int t = 0; t < threads; ++t)
        for (int q = 0; q < nc; ++q) {
            double *s = rows + (size_t)t * per + (size_t)q * lds;
            for (size_t i = 0; i < lds; ++i)
                s[i] = big[q];
            memset(s + (size_t)nc * lds, 0, lds * sizeof(double));
        }
    int plain_sqrt, acc_sqrt;
    cm_rbf_sqrt_split(&plain_sqrt, &acc_sqrt);
    const int mode = comp ? 2 : plain_sqrt == 3 ? 1 : 0;
    run_tiles(mode, nc, m, c, w, big, lds, per, rows, cols, tsz, scratch, threads);
    /* every row: the column side of its tile plus the row sides of all threads, offsets
     * (exact) then remainders */
    for (size_t i = 0; i < m; ++i)
        for (int q = 0; q < nc; ++q) {
            double off = cols[(size_t)q * lds + i], rem = cols[(size_t)(nc + q) * lds + i];
            for (int t = 0; t < threads; ++t) {
                const double *s = rows + (size_t)t * per;
                off += s[(size_t)q * lds + i] - big[q];
                rem += s[(size_t)(nc + q) * lds + i];
            }
            out[i * ldo + (size_t)q] = off + rem;
        }
    free(rows);
    free(scratch);
    return 0;
}

#else /* not x86-64 GCC/Clang: the callers keep the general sums */

int cm_rbf_r3_self_avx512(int nc, size_t m, const double *c, const double *w, const double *big,
                          double *out, size_t ldo, int threads)
{
    (void)nc, (void)m, (void)c, (void)w, (void)big, (void)out, (void)ldo, (void)threads;
    return 1;
}

#endif
