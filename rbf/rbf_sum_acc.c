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
 * Built without FP contraction: the error-free transformations need every rounding where
 * it is written. */
#include "rbf_internal.h"

#include <math.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#define NB 8
#define PB 64
#define TILE 512

static inline __attribute__((always_inline)) void tile_acc(const int nc, const double *c,
                                                           size_t ldc, const double *w,
                                                           size_t ldw, size_t jn,
                                                           const double *pt, double *hi,
                                                           double *lo)
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
    for (int l = 0; l < NB; ++l)
        for (int q = 0; q < nc; ++q) {
            hi[q * PB + l] = s[q][l];
            lo[q * PB + l] = e[q][l];
        }
}

static inline __attribute__((always_inline)) void block_acc(const int nc, size_t m,
                                                            const double *c, const double *w,
                                                            const double *pt, double *hi,
                                                            double *lo)
{
    for (size_t t0 = 0; t0 < m; t0 += TILE) {
        size_t jn = m - t0 < TILE ? m - t0 : TILE;
        for (int b = 0; b < PB; b += NB)
            tile_acc(nc, c + t0, m, w + t0, m, jn, pt + b, hi + b, lo + b);
    }
}

#define CM_ACC_DISPATCH                                                                        \
    switch (nc) {                                                                              \
    case 1: block_acc(1, m, c, w, pt, hi, lo); break;                                          \
    case 2: block_acc(2, m, c, w, pt, hi, lo); break;                                          \
    case 3: block_acc(3, m, c, w, pt, hi, lo); break;                                          \
    default: block_acc(4, m, c, w, pt, hi, lo); break;                                         \
    }

typedef void (*acc_fn)(int nc, size_t m, const double *c, const double *w, const double *pt,
                       double *hi, double *lo);

static void acc_generic(int nc, size_t m, const double *c, const double *w, const double *pt,
                        double *hi, double *lo)
{
    CM_ACC_DISPATCH
}

__attribute__((target("avx2,fma"))) static void acc_avx2(int nc, size_t m, const double *c,
                                                          const double *w, const double *pt,
                                                          double *hi, double *lo)
{
    CM_ACC_DISPATCH
}

__attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma"))) static void
acc_avx512(int nc, size_t m, const double *c, const double *w, const double *pt, double *hi,
           double *lo)
{
    CM_ACC_DISPATCH
}

static acc_fn pick_acc(void)
{
#if defined(__x86_64__) && defined(__GNUC__)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
        __builtin_cpu_supports("avx512vl"))
        return acc_avx512;
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return acc_avx2;
#endif
    return acc_generic; /* fma() is exact here too, only slower */
}

void cm_rbf_kernel_sum_acc(size_t m, const double *c, const double *w, int nc, size_t n,
                           const double *p, size_t ldp, double *out, size_t ldo, int threads)
{
    const acc_fn fn = pick_acc();
    const long nblocks = (long)((n + PB - 1) / PB);
    const int parallel = (double)n * (double)m > CM_RBF_PARALLEL_MIN_PAIRS && threads > 1;
#pragma omp parallel for schedule(static) num_threads(threads) if (parallel)
    for (long b = 0; b < nblocks; ++b) {
        double pt[3 * PB], hi[4 * PB], lo[4 * PB];
        const size_t i0 = (size_t)b * PB;
        const size_t cnt = n - i0 < PB ? n - i0 : PB;
        for (int d = 0; d < 3; ++d)
            for (size_t l = 0; l < PB; ++l) {
                size_t i = l < cnt ? i0 + l : i0 + cnt - 1;
                pt[d * PB + l] = p[d * ldp + i];
            }
        memset(hi, 0, sizeof hi);
        memset(lo, 0, sizeof lo);
        fn(nc, m, c, w, pt, hi, lo);
        for (size_t l = 0; l < cnt; ++l)
            for (int q = 0; q < nc; ++q)
                out[(i0 + l) * ldo + (size_t)q] = hi[q * PB + l] + lo[q * PB + l];
    }
}
