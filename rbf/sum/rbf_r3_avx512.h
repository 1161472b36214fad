/* The AVX-512 operations the hand-written r^3 blocks share (rbf_sum_avx512.c, whose header
 * comment says why they are written this way, and the symmetric self product of
 * rbf_sum_self_avx512.c): the square root on the FMA pipes, |p - c|^3 of one vector, and the
 * fixed-binade compensated update. Both files must compute phi_ij with the same operations,
 * so that a self product and a general one agree bit for bit in the entries. Not a public
 * header; include only where __x86_64__ and GCC/Clang are defined. */
#ifndef CADMORPH_RBF_R3_AVX512_H
#define CADMORPH_RBF_R3_AVX512_H

#include <immintrin.h>

#define CM_AVX512 __attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma")))
#define CM_INLINE static inline __attribute__((always_inline))

/* sqrt(x) for x >= 0 without the sqrt unit: rsqrt14 (14 bits), two Goldschmidt steps and a
 * final Newton correction with an FMA residual (Markstein), which returned the correctly
 * rounded sqrt for every one of 1.6e7 test arguments over 40 binades, so the sqrt unit and
 * this give the same phi_ij. x = 0 (a point on a centre) would give rsqrt14 = inf and
 * 0 * inf = NaN, so the seed is taken at max(x, 1e-300): then s = x * y = 0 and every step
 * keeps 0; for 0 < x < 1e-300 the result is wrong, but x^(3/2) < 1e-450 underflows to 0
 * anyway, and that is all the callers use it for. */
CM_AVX512 CM_INLINE __m512d cm_sqrt_fma(__m512d x)
{
    const __m512d half = _mm512_set1_pd(0.5);
    __m512d y = _mm512_rsqrt14_pd(_mm512_max_pd(x, _mm512_set1_pd(1e-300)));
    __m512d s = _mm512_mul_pd(x, y), h = _mm512_mul_pd(half, y); /* s ~ sqrt x, h ~ 1/(2 s) */
    __m512d r = _mm512_fnmadd_pd(s, h, half);
    s = _mm512_fmadd_pd(s, r, s);
    h = _mm512_fmadd_pd(h, r, h);
    r = _mm512_fnmadd_pd(s, h, half);
    s = _mm512_fmadd_pd(s, r, s);
    h = _mm512_fmadd_pd(h, r, h);
    __m512d d = _mm512_fnmadd_pd(s, s, x); /* x - s^2, exact by the FMA */
    return _mm512_fmadd_pd(d, h, s);
}

/* |p - c_j|^3 for one vector of a register block, its sqrt by vsqrtpd or (on_fma) sqrt_fma.
 * Symmetric in its arguments bit for bit: (a - b)^2 = (b - a)^2. */
CM_AVX512 CM_INLINE __m512d cm_r3_of(int on_fma, __m512d x, __m512d y, __m512d z, __m512d xj,
                                     __m512d yj, __m512d zj)
{
    __m512d dx = _mm512_sub_pd(x, xj), dy = _mm512_sub_pd(y, yj), dz = _mm512_sub_pd(z, zj);
    __m512d r2 = _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx)));
    __m512d r = on_fma ? cm_sqrt_fma(r2) : _mm512_sqrt_pd(r2);
    return _mm512_mul_pd(r2, r);
}

/* s + e += w f in the fixed binade of s (rbf_sum_avx512.c): t - s is exact, the rounding
 * remainder w f - (t - s) is formed by one FMA and summed plainly into e. */
CM_AVX512 CM_INLINE void cm_accf(__m512d *s, __m512d *e, __m512d w, __m512d f)
{
    const __m512d t = _mm512_fmadd_pd(w, f, *s);
    const __m512d d = _mm512_sub_pd(t, *s); /* exact: same binade */
    *e = _mm512_add_pd(*e, _mm512_fmsub_pd(w, f, d));
    *s = t;
}

#endif
