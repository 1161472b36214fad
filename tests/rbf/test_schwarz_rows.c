/* The dense arithmetic of a Schwarz application (rbf_schwarz_rows.c) against plain references:
 * the local rows (double and float parts, row and column counts off the tiles' 4 x 3) against
 * sums in long double, and the coarse factor's solves against LAPACK's (cm_rbf_projected_solve
 * with the same factor); in both, each column the same bits whatever the columns beside it
 * and the threads. */
#include "rbf_internal.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned seed = 12345u;
static double rnd(void)
{
    seed = seed * 1103515245u + 12345u;
    return (double)((seed >> 8) & 0xffff) / 65535.0 - 0.5;
}

enum { NMAX = 7 };

static void local_rows(void)
{
    /* n = hd + hf off multiples of 4; nin off multiples of 4 */
    const size_t hd = 23, hf = 18, n = hd + hf, nin = 9, ldo = 50;
    double *gd = malloc(nin * hd * sizeof *gd), *x = malloc(n * NMAX * sizeof *x);
    float *gf = malloc(nin * hf * sizeof *gf);
    size_t idx[9];
    for (size_t j = 0; j < nin; ++j) idx[j] = 5 * j + 1; /* scattered rows of out */
    for (size_t i = 0; i < nin * hd; ++i) gd[i] = rnd();
    for (size_t i = 0; i < nin * hf; ++i) gf[i] = (float)rnd();
    for (size_t i = 0; i < n * NMAX; ++i) x[i] = rnd();
    double worst = 0.0;
    int same = 1;
    double *solo = calloc(ldo * NMAX, sizeof *solo);
    for (int c = 0; c < NMAX; ++c) /* each column alone, out starting from 1 */
        for (size_t i = 0; i < ldo; ++i) solo[(size_t)c * ldo + i] = 1.0;
    for (int c = 0; c < NMAX; ++c)
        cm_rbf_local_rows(gd, gf, hd, hf, nin, x + (size_t)c * n, n, 1, solo + (size_t)c * ldo,
                          ldo, idx);
    for (int nc = 1; nc <= NMAX; ++nc) {
        double *out = malloc(ldo * (size_t)nc * sizeof *out);
        for (size_t i = 0; i < ldo * (size_t)nc; ++i) out[i] = 1.0;
        cm_rbf_local_rows(gd, gf, hd, hf, nin, x, n, nc, out, ldo, idx);
        for (int c = 0; c < nc; ++c)
            for (size_t i = 0; i < ldo; ++i) {
                const double o = out[(size_t)c * ldo + i];
                same &= o == solo[(size_t)c * ldo + i];
                size_t j = nin;
                for (size_t q = 0; q < nin; ++q)
                    if (idx[q] == i) j = q;
                if (j == nin) { /* a row no leaf row maps to: untouched */
                    CHECK_MSG(o == 1.0, "row %zu written", i);
                    continue;
                }
                long double s = 1.0L, a = 1.0L;
                for (size_t q = 0; q < hd; ++q) {
                    s += (long double)gd[j * hd + q] * x[(size_t)c * n + q];
                    a += fabsl((long double)gd[j * hd + q] * x[(size_t)c * n + q]);
                }
                for (size_t q = 0; q < hf; ++q) {
                    s += (long double)gf[j * hf + q] * x[(size_t)c * n + hd + q];
                    a += fabsl((long double)gf[j * hf + q] * x[(size_t)c * n + hd + q]);
                }
                worst = fmax(worst, (double)(fabsl((long double)o - s) / a));
            }
        free(out);
    }
    printf("local rows: error %.3g of sum |g x|; columns %s whatever the batch\n", worst,
           same ? "the same bits" : "differ");
    CHECK_MSG(worst <= 1e-14, "%.3g", worst);
    CHECK(same);
    free(gd), free(gf), free(x), free(solo);
}

static void coarse_solves(void)
{
    const size_t n = 150;
    double *cg = malloc(3 * n * sizeof *cg);
    size_t *idx = malloc(n * sizeof *idx);
    for (size_t i = 0; i < 3 * n; ++i) cg[i] = rnd();
    for (size_t i = 0; i < n; ++i) idx[i] = i;
    double *work = malloc((n * n + 8 * n) * sizeof *work), tau[4];
    int rk = 0;
    CHECK(cm_rbf_projected_factor(cg, n, idx, n, work, &rk, tau) == 0 && rk == 4);
    double *b = malloc(n * NMAX * sizeof *b), *ref = malloc(n * NMAX * sizeof *ref);
    double *one = malloc(n * NMAX * sizeof *one), *x = malloc(n * NMAX * sizeof *x);
    for (size_t i = 0; i < n * NMAX; ++i) b[i] = rnd();
    memcpy(ref, b, n * NMAX * sizeof *ref);
    CHECK(cm_rbf_projected_solve(work, n, rk, tau, NMAX, ref) == 0);
    memcpy(one, b, n * NMAX * sizeof *one);
    for (int c = 0; c < NMAX; ++c)
        cm_rbf_projected_solve_cols(work, n, rk, tau, 1, one + (size_t)c * n, 1);
    double worst = 0.0;
    int same = 1;
    for (int threads = 1; threads <= 2; ++threads)
        for (int nc = 1; nc <= NMAX; ++nc) {
            memcpy(x, b, n * (size_t)nc * sizeof *x);
            cm_rbf_projected_solve_cols(work, n, rk, tau, (size_t)nc, x, threads);
            for (int c = 0; c < nc; ++c) {
                double d = 0.0, s = 0.0;
                for (size_t i = 0; i < n; ++i) {
                    same &= x[(size_t)c * n + i] == one[(size_t)c * n + i];
                    d = fmax(d, fabs(x[(size_t)c * n + i] - ref[(size_t)c * n + i]));
                    s = fmax(s, fabs(ref[(size_t)c * n + i]));
                }
                worst = fmax(worst, d / s);
            }
        }
    printf("coarse solves: %.3g of LAPACK's largest; columns %s whatever the batch and "
           "threads\n", worst, same ? "the same bits" : "differ");
    /* two backward-stable solves with the same factor of a system conditioned ~1e6 */
    CHECK_MSG(worst <= 1e-8, "%.3g", worst);
    CHECK(same);
    free(cg), free(idx), free(work), free(b), free(ref), free(one), free(x);
}

int main(void)
{
    local_rows();
    coarse_solves();
    return TEST_REPORT();
}
