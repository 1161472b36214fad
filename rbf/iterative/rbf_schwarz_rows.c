/* The dense arithmetic of one Schwarz application (rbf_schwarz.c): every leaf's rows of its
 * local inverse times all columns of its local data, and the coarse factor's two triangular
 * solves. Both run for a whole batch of right-hand sides, and both keep each column's
 * arithmetic in an order that does not depend on the others (a column's preconditioned
 * vector is the same bits alone or in a batch), which is why they are written here rather
 * than handed to dgemm / dtrsm: OpenBLAS blocks the right-hand sides as it likes.
 *
 * With AVX2 + FMA (chosen at run time) the sums run in 4 lanes along the rows, a tile of 4
 * rows x 3 columns at a time: each loaded row chunk serves 3 columns and each column chunk
 * 4 rows, and a leaf's rows (a few tens of kB) stay in L1 while the tiles walk the columns,
 * so the local inverses (about 100 MB at 2e4 centres) stream from memory once per
 * application instead of once per column. The baseline loops keep the plain order. */
#include "rbf_internal.h"

#include <math.h>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define CM_ROWS_X86 1
#define CM_AVX2_FMA __attribute__((target("avx2,fma")))
#else
#define CM_ROWS_X86 0
#endif

#define ROWS_COLS 8 /* baseline: columns whose independent sums share a row's read */

/* Baseline: one row times nb <= ROWS_COLS columns, in order i = 0, 1, ... per column. */
static void row_plain(const double *gd, const float *gf, size_t hd, size_t hf, const double *x,
                      size_t n, int nb, double *out, size_t ldo)
{
    double acc[ROWS_COLS] = {0};
    for (size_t i = 0; i < hd; ++i) {
        const double gi = gd[i];
        for (int b = 0; b < nb; ++b) acc[b] += gi * x[(size_t)b * n + i];
    }
    for (size_t i = 0; i < hf; ++i) {
        const double gi = (double)gf[i];
        for (int b = 0; b < nb; ++b) acc[b] += gi * x[(size_t)b * n + hd + i];
    }
    for (int b = 0; b < nb; ++b) out[(size_t)b * ldo] += acc[b];
}

static void rows_plain(const double *gd, const float *gf, size_t hd, size_t hf, size_t nin,
                       const double *x, size_t n, int nc, double *out, size_t ldo,
                       const size_t *idx)
{
    for (size_t j = 0; j < nin; ++j)
        for (int c = 0; c < nc; c += ROWS_COLS)
            row_plain(gd + j * hd, gf + j * hf, hd, hf, x + (size_t)c * n, n,
                      nc - c < ROWS_COLS ? nc - c : ROWS_COLS, out + (size_t)c * ldo + idx[j],
                      ldo);
}

#if CM_ROWS_X86
/* The 4 lanes of v added in one fixed order. */
CM_AVX2_FMA static inline double hsum(__m256d v)
{
    __m128d lo = _mm256_castpd256_pd128(v), hi = _mm256_extractf128_pd(v, 1);
    lo = _mm_add_pd(lo, hi);
    return _mm_cvtsd_f64(_mm_add_sd(lo, _mm_unpackhi_pd(lo, lo)));
}

/* Rows g[0..4) times columns x[0..C) (stride n): the double part in lanes i mod 4, then the
 * float part in the same lanes, the lanes summed, then the two tails in order. Each (row,
 * column) sum is the same sequence of operations whatever C and the other rows, hence
 * whatever the batch. always_inline: C is a constant at every call, so the tile is unrolled
 * (12 accumulators, 3 column loads and a row's: the 16 ymm registers). */
CM_AVX2_FMA static inline __attribute__((always_inline)) void
tile(int C, const double *const *gd, const float *const *gf, size_t hd, size_t hf,
     const double *x, size_t n, double res[4][3])
{
    __m256d acc[4][3];
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < C; ++c) acc[r][c] = _mm256_setzero_pd();
    const size_t hd4 = hd & ~(size_t)3, hf4 = hf & ~(size_t)3;
    for (size_t i = 0; i < hd4; i += 4) {
        __m256d xv[3];
        for (int c = 0; c < C; ++c) xv[c] = _mm256_loadu_pd(x + (size_t)c * n + i);
        for (int r = 0; r < 4; ++r) {
            const __m256d g = _mm256_loadu_pd(gd[r] + i);
            for (int c = 0; c < C; ++c) acc[r][c] = _mm256_fmadd_pd(g, xv[c], acc[r][c]);
        }
    }
    for (size_t i = 0; i < hf4; i += 4) {
        __m256d xv[3];
        for (int c = 0; c < C; ++c) xv[c] = _mm256_loadu_pd(x + (size_t)c * n + hd + i);
        for (int r = 0; r < 4; ++r) {
            const __m256d g = _mm256_cvtps_pd(_mm_loadu_ps(gf[r] + i));
            for (int c = 0; c < C; ++c) acc[r][c] = _mm256_fmadd_pd(g, xv[c], acc[r][c]);
        }
    }
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < C; ++c) {
            const double *xc = x + (size_t)c * n;
            double s = hsum(acc[r][c]);
            for (size_t i = hd4; i < hd; ++i) s = fma(gd[r][i], xc[i], s);
            for (size_t i = hf4; i < hf; ++i) s = fma((double)gf[r][i], xc[hd + i], s);
            res[r][c] = s;
        }
}

CM_AVX2_FMA static void rows_avx2(const double *gd, const float *gf, size_t hd, size_t hf,
                                  size_t nin, const double *x, size_t n, int nc, double *out,
                                  size_t ldo, const size_t *idx)
{
    for (size_t j0 = 0; j0 < nin; j0 += 4) {
        const int R = nin - j0 < 4 ? (int)(nin - j0) : 4;
        const double *g[4];
        const float *f[4];
        for (int r = 0; r < 4; ++r) { /* rows past R repeat the last one, unused */
            const size_t j = j0 + (size_t)(r < R ? r : R - 1);
            g[r] = gd + j * hd;
            f[r] = gf + j * hf;
        }
        for (int c0 = 0; c0 < nc; c0 += 3) {
            const int C = nc - c0 < 3 ? nc - c0 : 3;
            const double *xc = x + (size_t)c0 * n;
            double res[4][3];
            /* each width spelt out, so that the tile is unrolled with its constants (a last
             * block of fewer than 4 rows repeats its last row: a few idle sums per leaf) */
            if (C == 3) tile(3, g, f, hd, hf, xc, n, res);
            else if (C == 2) tile(2, g, f, hd, hf, xc, n, res);
            else tile(1, g, f, hd, hf, xc, n, res);
            for (int r = 0; r < R; ++r)
                for (int c = 0; c < C; ++c) out[(size_t)(c0 + c) * ldo + idx[j0 + (size_t)r]] += res[r][c];
        }
    }
}
#endif

void cm_rbf_local_rows(const double *gd, const float *gf, size_t hd, size_t hf, size_t nin,
                       const double *x, size_t n, int nc, double *out, size_t ldo,
                       const size_t *idx)
{
#if CM_ROWS_X86
    if (cm_rbf_isa_supported(CM_RBF_ISA_AVX2)) {
        rows_avx2(gd, gf, hd, hf, nin, x, n, nc, out, ldo, idx);
        return;
    }
#endif
    rows_plain(gd, gf, hd, hf, nin, x, n, nc, out, ldo, idx);
}

/* Columns of the coarse solve processed together (independent sums in flight, the factor
 * read once for them). */
#define PSOLVE_COLS 4

/* H_a x = x - tau_a v_a (v_a' x) (v_a: 1 at a, pq below it) for the nb columns of x */
static void reflect(const double *pq, size_t n, int a, double tau, double *x, int nb)
{
    const double *v = pq + (size_t)a * n;
    for (int b = 0; b < nb; ++b) {
        double *xb = x + (size_t)b * n, s = xb[a];
        for (size_t i = (size_t)a + 1; i < n; ++i) s += v[i] * xb[i];
        s *= tau;
        xb[a] -= s;
        for (size_t i = (size_t)a + 1; i < n; ++i) xb[i] -= s * v[i];
    }
}

/* L L' y = y for nb columns (L: n2 x n2 lower, leading dimension ld): L z = y by columns of
 * L, then L' y = z by dot products with them. */
static void chol_solve_plain(const double *l, size_t ld, size_t n2, double *const *y, int nb)
{
    for (size_t j = 0; j < n2; ++j) {
        const double *lj = l + j * ld;
        for (int b = 0; b < nb; ++b) {
            double *yb = y[b];
            const double t = yb[j] / lj[j];
            yb[j] = t;
            for (size_t i = j + 1; i < n2; ++i) yb[i] -= lj[i] * t;
        }
    }
    for (size_t jj = n2; jj-- > 0;) {
        const double *lj = l + jj * ld;
        double acc[PSOLVE_COLS];
        for (int b = 0; b < nb; ++b) acc[b] = y[b][jj];
        for (size_t i = jj + 1; i < n2; ++i) {
            const double li = lj[i];
            for (int b = 0; b < nb; ++b) acc[b] -= li * y[b][i];
        }
        for (int b = 0; b < nb; ++b) y[b][jj] = acc[b] / lj[jj];
    }
}

#if CM_ROWS_X86
/* The same in 4 lanes: the updates of the first solve along each column of L (each element
 * in the same order as above, fused), the dot products of the second in lanes i mod 4. */
CM_AVX2_FMA static void chol_solve_avx2(const double *l, size_t ld, size_t n2, double *const *y,
                                        int nb)
{
    for (size_t j = 0; j < n2; ++j) {
        const double *lj = l + j * ld;
        double t[PSOLVE_COLS];
        __m256d tv[PSOLVE_COLS];
        for (int b = 0; b < nb; ++b) {
            t[b] = y[b][j] / lj[j];
            y[b][j] = t[b];
            tv[b] = _mm256_set1_pd(t[b]);
        }
        size_t i = j + 1;
        for (; i + 4 <= n2; i += 4) {
            const __m256d lv = _mm256_loadu_pd(lj + i);
            for (int b = 0; b < nb; ++b)
                _mm256_storeu_pd(y[b] + i,
                                 _mm256_fnmadd_pd(lv, tv[b], _mm256_loadu_pd(y[b] + i)));
        }
        for (; i < n2; ++i)
            for (int b = 0; b < nb; ++b) y[b][i] = fma(-lj[i], t[b], y[b][i]);
    }
    for (size_t jj = n2; jj-- > 0;) {
        const double *lj = l + jj * ld;
        __m256d acc[PSOLVE_COLS];
        for (int b = 0; b < nb; ++b) acc[b] = _mm256_setzero_pd();
        const size_t i0 = jj + 1, e = i0 + ((n2 - i0) & ~(size_t)3);
        for (size_t i = i0; i < e; i += 4) {
            const __m256d lv = _mm256_loadu_pd(lj + i);
            for (int b = 0; b < nb; ++b)
                acc[b] = _mm256_fmadd_pd(lv, _mm256_loadu_pd(y[b] + i), acc[b]);
        }
        for (int b = 0; b < nb; ++b) {
            double s = hsum(acc[b]);
            for (size_t i = e; i < n2; ++i) s = fma(lj[i], y[b][i], s);
            y[b][jj] = (y[b][jj] - s) / lj[jj];
        }
    }
}
#endif

void cm_rbf_projected_solve_cols(const double *work, size_t n, int rk, const double *tau,
                                 size_t nrhs, double *x, int threads)
{
    const double *a = work, *pq = work + n * n + 3 * n;
    const size_t n2 = n - (size_t)rk;
    const double *l = a + (size_t)rk * n + (size_t)rk; /* n2 x n2 lower, ld n */
    /* blocks of up to PSOLVE_COLS columns, at least one per thread while there are columns
     * enough: a block's size changes no column's arithmetic */
    const size_t nt = threads > 1 ? (size_t)threads : 1;
    size_t bs = (nrhs + nt - 1) / nt;
    bs = bs < 1 ? 1 : bs > PSOLVE_COLS ? PSOLVE_COLS : bs;
    const long nblk = (long)((nrhs + bs - 1) / bs);
    void (*chol_solve)(const double *, size_t, size_t, double *const *, int) = chol_solve_plain;
#if CM_ROWS_X86
    if (cm_rbf_isa_supported(CM_RBF_ISA_AVX2)) chol_solve = chol_solve_avx2;
#endif
#pragma omp parallel for num_threads(threads) if (threads > 1 && nblk > 1) schedule(dynamic, 1)
    for (long q = 0; q < nblk; ++q) {
        const size_t c0 = (size_t)q * bs;
        const int nb = nrhs - c0 < bs ? (int)(nrhs - c0) : (int)bs;
        double *xc = x + c0 * n;
        for (int h = 0; h < rk; ++h) reflect(pq, n, h, tau[h], xc, nb); /* Q' x */
        double *y[PSOLVE_COLS];
        for (int b = 0; b < nb; ++b) {
            y[b] = xc + (size_t)b * n + (size_t)rk;
            for (int i = 0; i < rk; ++i) xc[(size_t)b * n + (size_t)i] = 0.0;
        }
        chol_solve(l, n, n2, y, nb);
        for (int h = rk; h-- > 0;) reflect(pq, n, h, tau[h], xc, nb); /* Q x */
    }
}
