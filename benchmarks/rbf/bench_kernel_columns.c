/* Kernel cost per column: the r^3 kernel sums of nc weight columns in one pass (rbf/sum:
 * each entry phi_ij computed once, each further column one FMA per pair on the register
 * blocks), per column against nc, beside the FMA-bound limit of this machine measured in
 * the same run: independent FMAs on the widest vectors the kernel uses (AVX-512 where AUTO
 * takes the hand-written blocks, else AVX2), on every thread; one FMA lane per pair and
 * column gives the bound in pairs x columns per CPU-second.
 * Sums timed, each by CPU seconds of the process (getrusage: both threads count), AUTO code:
 *   plain      cm_rbf_kernel_sum, m random centres, n separate random targets
 *   comp       cm_rbf_kernel_sum_acc at the same targets (the compensated sums)
 *   self       cm_rbf_kernel_sum at the m centres themselves (the Krylov products: the
 *              symmetric self product on AVX-512), pairs m^2
 *   self_comp  cm_rbf_kernel_sum_acc at the centres
 *   tree_eval  the treecode at nt separate targets (cm_rbf_tree_sum_targets, order and theta
 *              for 1e-9), pairs counted as the direct sum's m nt
 * usage: bench_kernel_columns M N NT THREADS REPS NC,...
 *   e.g. bench_kernel_columns 100000 20000 500000 2 1 1,3,12,30,60
 * One line of key=value per sum and nc. */
#include "rbf_internal.h"
#include "sum/rbf_sum_isa.h"
#include "sum/rbf_treecode.h"

#include <immintrin.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"

#define FMA_CHAINS 16

/* FMA lanes per CPU-second on threads threads: FMA_CHAINS independent chains per thread */
__attribute__((target("avx512f"))) static double fma_lanes_avx512(int threads, long iters)
{
    double sink = 0.0;
    const double t0 = bench_cpu_seconds();
#pragma omp parallel num_threads(threads) reduction(+ : sink)
    {
        __m512d a[FMA_CHAINS];
        const __m512d b = _mm512_set1_pd(0.999999), d = _mm512_set1_pd(1e-7);
        for (int k = 0; k < FMA_CHAINS; ++k) a[k] = _mm512_set1_pd(1.0 + k);
        for (long i = 0; i < iters; ++i)
            for (int k = 0; k < FMA_CHAINS; ++k) a[k] = _mm512_fmadd_pd(a[k], b, d);
        for (int k = 0; k < FMA_CHAINS; ++k) sink += _mm512_reduce_add_pd(a[k]);
    }
    const double t = bench_cpu_seconds() - t0;
    if (sink == 42.0) printf("#\n"); /* keep the loop */
    return (double)threads * (double)iters * FMA_CHAINS * 8.0 / t;
}

__attribute__((target("avx2,fma"))) static double fma_lanes_avx2(int threads, long iters)
{
    double sink = 0.0;
    const double t0 = bench_cpu_seconds();
#pragma omp parallel num_threads(threads) reduction(+ : sink)
    {
        __m256d a[FMA_CHAINS];
        const __m256d b = _mm256_set1_pd(0.999999), d = _mm256_set1_pd(1e-7);
        for (int k = 0; k < FMA_CHAINS; ++k) a[k] = _mm256_set1_pd(1.0 + k);
        for (long i = 0; i < iters; ++i)
            for (int k = 0; k < FMA_CHAINS; ++k) a[k] = _mm256_fmadd_pd(a[k], b, d);
        double v[4];
        for (int k = 0; k < FMA_CHAINS; ++k) {
            _mm256_storeu_pd(v, a[k]);
            sink += v[0] + v[1] + v[2] + v[3];
        }
    }
    const double t = bench_cpu_seconds() - t0;
    if (sink == 42.0) printf("#\n");
    return (double)threads * (double)iters * FMA_CHAINS * 4.0 / t;
}

static int parse_list(const char *s, long *out, int max)
{
    int k = 0;
    while (*s && k < max) {
        char *end;
        out[k++] = strtol(s, &end, 10);
        if (end == s) return -1;
        s = *end == ',' ? end + 1 : end;
    }
    return k;
}

int main(int argc, char **argv)
{
    if (argc < 7) {
        fprintf(stderr, "usage: %s M N NT THREADS REPS NC,...\n", argv[0]);
        return 1;
    }
    const size_t m = strtoul(argv[1], NULL, 10), n = strtoul(argv[2], NULL, 10);
    const size_t nt = strtoul(argv[3], NULL, 10);
    const int threads = atoi(argv[4]) > 0 ? atoi(argv[4]) : 1;
    const int reps = atoi(argv[5]) > 0 ? atoi(argv[5]) : 1;
    long ncs[16];
    const int nnc = parse_list(argv[6], ncs, 16);
    if (m < 1 || n < 1 || nnc < 1) return 1;
    long ncmax = 0;
    for (int k = 0; k < nnc; ++k) ncmax = ncs[k] > ncmax ? ncs[k] : ncmax;
    const size_t big = m > n ? (m > nt ? m : nt) : (n > nt ? n : nt);
    double *c = malloc(3 * m * sizeof *c), *p = malloc(3 * n * sizeof *p);
    double *pt = nt ? malloc(3 * nt * sizeof *pt) : NULL;
    double *w = malloc((size_t)ncmax * m * sizeof *w);
    double *out = malloc((size_t)ncmax * big * sizeof *out);
    if (!c || !p || (nt && !pt) || !w || !out) return 2;
    for (size_t i = 0; i < 3 * m; ++i) c[i] = bench_urand();
    for (size_t i = 0; i < 3 * n; ++i) p[i] = bench_urand();
    for (size_t i = 0; i < 3 * nt; ++i) pt[i] = bench_urand();
    for (size_t i = 0; i < (size_t)ncmax * m; ++i) w[i] = 2.0 * bench_urand() - 1.0;

    const int avx512 = cm_rbf_isa_auto() == CM_RBF_ISA_AVX512;
    const double bound = avx512 ? fma_lanes_avx512(threads, 200000000L / FMA_CHAINS)
                                : fma_lanes_avx2(threads, 200000000L / FMA_CHAINS);
    printf("# bench_kernel_columns: m=%zu n=%zu nt=%zu threads=%d reps=%d (best of) AUTO=%d\n",
           m, n, nt, threads, reps, (int)cm_rbf_isa_auto());
    printf("fma_bound vectors=%s threads=%d pair_columns_per_cpu_s=%.4g\n",
           avx512 ? "zmm" : "ymm", threads, bound);
    fflush(stdout);

    int order;
    double theta;
    cm_rbf_tree_params(1e-9, &order, &theta);
    cm_rbf_tree *tree = nt ? cm_rbf_tree_create(m, c, order, theta) : NULL;
    cm_rbf_tree_targets *tg = tree ? cm_rbf_tree_targets_create(nt, pt, nt) : NULL;
    static const char *const name[5] = {"plain", "comp", "self", "self_comp", "tree_eval"};
    double per1[5] = {0, 0, 0, 0, 0};
    for (int s = 0; s < 5; ++s) {
        if (s == 4 && !tg) continue;
        const double pairs = s == 4 ? (double)m * (double)nt
                             : s >= 2 ? (double)m * (double)m : (double)m * (double)n;
        for (int k = 0; k < nnc; ++k) {
            const int nc = (int)ncs[k];
            double best = INFINITY, wall = 0.0;
            for (int r = 0; r < reps; ++r) {
                const double t0 = bench_cpu_seconds(), w0 = cm_wtime();
                switch (s) {
                case 0:
                    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, w, nc, n, p, n, out,
                                      (size_t)nc, threads);
                    break;
                case 1:
                    cm_rbf_kernel_sum_acc(m, c, w, nc, n, p, n, out, (size_t)nc, threads);
                    break;
                case 2:
                    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, w, nc, m, c, m, out,
                                      (size_t)nc, threads);
                    break;
                case 3:
                    cm_rbf_kernel_sum_acc(m, c, w, nc, m, c, m, out, (size_t)nc, threads);
                    break;
                default:
                    if (cm_rbf_tree_sum_targets(tree, tg, 1, w, nc, out, (size_t)nc, threads))
                        return 2;
                    break;
                }
                const double t = bench_cpu_seconds() - t0;
                if (t < best) best = t, wall = cm_wtime() - w0;
            }
            const double per_col = best / nc;
            if (nc == 1) per1[s] = per_col;
            const double rate = pairs * nc / best;
            printf("sum=%s nc=%d cpu_s=%.3f wall_s=%.3f cpu_s_per_col_per_1e10_pairs=%.4f "
                   "pair_columns_per_cpu_s=%.4g of_fma_bound=%.3f per_col_over_nc1=%s%.3f\n",
                   name[s], nc, best, wall, per_col * 1e10 / pairs, rate, rate / bound,
                   per1[s] > 0.0 ? "" : "n/a ", per1[s] > 0.0 ? per_col / per1[s] : 0.0);
            fflush(stdout);
        }
    }
    cm_rbf_tree_targets_destroy(&tg);
    cm_rbf_tree_destroy(&tree);
    free(c), free(p), free(pt), free(w), free(out);
    return 0;
}
