/* Throughput of the r^3 kernel sums (rbf/sum/rbf_sum.c plain, rbf/sum/rbf_sum_acc.c compensated) in
 * pairs per CPU-second (getrusage: user + system of the process, so 2 threads count both),
 * each instruction-set variant side by side in one process, alternating, on the same data:
 * m random centres in the unit cube, n random points, 3 weight vectors uniform in [-1, 1].
 * Accuracy against a long-double reference on the first 64 points: max |out - ref| over
 * sum_j |w_j phi_ij| (what the plain sum can promise) and over |ref| (what the compensated
 * sum should reach).
 * Then the self product (targets = the m centres, as in the Krylov products): the general
 * AVX-512 blocks on a copy of the centres against the symmetric self product
 * (rbf/sum/rbf_sum_self_avx512.c, taken when the targets are the centres), pairs = m^2,
 * accuracy on the first 64 centres.
 * usage: bench_kernel N REPS THREADS,... M,...      e.g. bench_kernel 10000 3 1,2 10000,100000
 * (one line of key=value per m, threads, variant and sum) */
#include "blas_reexec.h"
#include "rbf_internal.h"
#include "sum/rbf_sum_isa.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench_util.h"



#define NREF 64
#define NC 3

/* plain_sqrt / acc_sqrt: the vsqrtpd split forced on the hand-written blocks (0: the one
 * the process probed, rbf_sum_isa.h) */
static const struct {
    cm_rbf_isa isa;
    const char *name;
    int plain_sqrt, acc_sqrt;
} variants[] = {
    {CM_RBF_ISA_AVX512_AUTOVEC, "avx512_autovec", 0, 0}, /* before: GCC's vectorisation */
    {CM_RBF_ISA_AVX512, "avx512", 0, 0},                 /* after: rbf_sum_avx512.c */
    {CM_RBF_ISA_AVX512, "avx512_split_3_2", 3, 2},       /* the Zen 5 split */
    {CM_RBF_ISA_AVX512, "avx512_split_2_1", 2, 1},       /* the Sapphire-Rapids-class split */
    {CM_RBF_ISA_AVX2, "avx2", 0, 0},
};
#define NVAR (int)(sizeof variants / sizeof variants[0])

static int parse_list(const char *s, long *out, int max)
{
    int k = 0;
    while (*s && k < max) {
        char *end;
        out[k++] = strtol(s, &end, 10);
        s = *end == ',' ? end + 1 : end;
        if (end == s && *s) return -1;
    }
    return k;
}

/* the long-double sums at the first NREF points p (stride ldp) and their sum_j |w_j phi_ij| */
static void reference(size_t m, const double *c, const double *w, const double *p, size_t ldp,
                      long double *ref, long double *absum)
{
    for (size_t i = 0; i < NREF; ++i)
        for (int q = 0; q < NC; ++q) {
            long double s = 0.0L, a = 0.0L;
            for (size_t j = 0; j < m; ++j) {
                long double dx = (long double)p[i] - c[j];
                long double dy = (long double)p[ldp + i] - c[m + j];
                long double dz = (long double)p[2 * ldp + i] - c[2 * m + j];
                long double r2 = dx * dx + dy * dy + dz * dz, f = r2 * sqrtl(r2);
                s += f * w[q * m + j];
                a += fabsl(f * w[q * m + j]);
            }
            ref[q * NREF + i] = s;
            absum[q * NREF + i] = a;
        }
}

/* max error of out (stride NC) on those points, over sum_j |w_j phi_ij| (what the plain sum
 * can promise) and over |ref| (what the compensated sum should reach) */
static void ref_errors(const double *out, const long double *ref, const long double *absum,
                       double *err_abs, double *err_rel)
{
    double ea = 0.0, er = 0.0;
    for (int i = 0; i < NREF; ++i)
        for (int q = 0; q < NC; ++q) {
            long double d = fabsl((long double)out[i * NC + q] - ref[q * NREF + i]);
            ea = fmax(ea, (double)(d / absum[q * NREF + i]));
            er = fmax(er, (double)(d / fabsl(ref[q * NREF + i])));
        }
    *err_abs = ea, *err_rel = er;
}

/* The self product: general blocks (targets a copy of the centres) against the symmetric
 * one (the centres themselves), alternating, best of reps, plain and compensated. */
static void self_product(size_t m, const double *c, const double *w, int threads, int reps)
{
    double *copy = malloc(3 * m * sizeof *copy), *out = malloc(NC * m * sizeof *out);
    long double ref[NC * NREF], absum[NC * NREF];
    if (!copy || !out) exit(2);
    memcpy(copy, c, 3 * m * sizeof *copy);
    reference(m, c, w, c, m, ref, absum);
    static const char *const name[2] = {"avx512_general_at_centres", "avx512_self"};
    double best[2][2], wall[2][2], ea[2][2], er[2][2];
    for (int k = 0; k < 4; ++k) best[k / 2][k % 2] = INFINITY;
    for (int r = 0; r < reps; ++r)
        for (int v = 0; v < 2; ++v)
            for (int s = 0; s < 2; ++s) {
                const double *pt = v ? c : copy;
                double t0 = bench_cpu_seconds(), w0 = cm_wtime();
                if (s == 0)
                    cm_rbf_kernel_sum_isa(CM_RBF_ISA_AVX512, CM_RBF_TRIHARMONIC, 3, m, c, w, NC,
                                          m, pt, m, out, NC, threads);
                else
                    cm_rbf_kernel_sum_acc_isa(CM_RBF_ISA_AVX512, m, c, w, NC, m, pt, m, out, NC,
                                              threads);
                double t = bench_cpu_seconds() - t0, tw = cm_wtime() - w0;
                if (t < best[v][s]) best[v][s] = t, wall[v][s] = tw;
                if (r == 0) ref_errors(out, ref, absum, &ea[v][s], &er[v][s]);
            }
    for (int v = 0; v < 2; ++v)
        for (int s = 0; s < 2; ++s)
            printf("m=%zu n=%zu threads=%d variant=%s sum=%s cpu_s=%.3f wall_s=%.3f "
                   "pairs_per_cpu_s=%.3g pairs_per_s=%.3g err_over_sum_abs=%.2g "
                   "err_over_ref=%.2g\n",
                   m, m, threads, name[v], s ? "compensated" : "plain", best[v][s], wall[v][s],
                   (double)m * (double)m / best[v][s], (double)m * (double)m / wall[v][s],
                   ea[v][s], er[v][s]);
    for (int s = 0; s < 2; ++s)
        printf("m=%zu threads=%d sum=%s self_over_general_cpu=%.2f\n", m, threads,
               s ? "compensated" : "plain", best[0][s] / best[1][s]);
    free(copy), free(out);
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core for the dgemm probe */
    if (argc < 5) {
        fprintf(stderr, "usage: %s N REPS THREADS,... M,...\n", argv[0]);
        return 1;
    }
    const size_t n = strtoul(argv[1], NULL, 10);
    const int reps = atoi(argv[2]) > 0 ? atoi(argv[2]) : 1;
    long th[8], ms[16];
    const int nth = parse_list(argv[3], th, 8), nm = parse_list(argv[4], ms, 16);
    if (n < NREF || nth < 1 || nm < 1) return 1;
    size_t mmax = 0;
    for (int k = 0; k < nm; ++k) mmax = (size_t)ms[k] > mmax ? (size_t)ms[k] : mmax;
    double *c = malloc(3 * mmax * sizeof *c), *w = malloc(NC * mmax * sizeof *w);
    double *p = malloc(3 * n * sizeof *p), *out = malloc(NC * n * sizeof *out);
    long double *ref = malloc(NC * NREF * sizeof *ref), *absum = malloc(NC * NREF * sizeof *absum);
    if (!c || !w || !p || !out || !ref || !absum) return 2;
    for (size_t i = 0; i < 3 * n; ++i) p[i] = bench_urand();

    int split_plain = 0, split_acc = 0;
    cm_rbf_sqrt_split(&split_plain, &split_acc);
    printf("# bench_kernel: n=%zu points, %d weight vectors, reps=%d (best of), AUTO=%d, "
           "probed sqrt split: plain %d of 4, compensated %d of 2 through vsqrtpd\n",
           n, NC, reps, (int)cm_rbf_isa_auto(), split_plain, split_acc);
    for (int km = 0; km < nm; ++km) {
        const size_t m = (size_t)ms[km];
        for (size_t i = 0; i < 3 * m; ++i) c[i] = bench_urand();
        for (size_t i = 0; i < NC * m; ++i) w[i] = 2.0 * bench_urand() - 1.0;
        reference(m, c, w, p, n, ref, absum);
        for (int kt = 0; kt < nth; ++kt) {
            const int threads = (int)th[kt];
            double best[NVAR][2], wall[NVAR][2], err_abs[NVAR][2], err_rel[NVAR][2];
            for (int v = 0; v < NVAR; ++v)
                for (int s = 0; s < 2; ++s) best[v][s] = INFINITY;
            /* alternate the variants rep by rep so that a change of load hits all of them */
            for (int r = 0; r < reps; ++r)
                for (int v = 0; v < NVAR; ++v) {
                    if (!cm_rbf_isa_supported(variants[v].isa)) continue;
                    cm_rbf_sqrt_split_force(variants[v].plain_sqrt, variants[v].acc_sqrt);
                    for (int s = 0; s < 2; ++s) {
                        double t0 = bench_cpu_seconds(), w0 = cm_wtime();
                        if (s == 0)
                            cm_rbf_kernel_sum_isa(variants[v].isa, CM_RBF_TRIHARMONIC, 3, m, c,
                                                  w, NC, n, p, n, out, NC, threads);
                        else
                            cm_rbf_kernel_sum_acc_isa(variants[v].isa, m, c, w, NC, n, p, n,
                                                      out, NC, threads);
                        double t = bench_cpu_seconds() - t0, tw = cm_wtime() - w0;
                        if (t < best[v][s]) best[v][s] = t, wall[v][s] = tw;
                        ref_errors(out, ref, absum, &err_abs[v][s], &err_rel[v][s]);
                    }
                }
            cm_rbf_sqrt_split_force(0, 0);
            if (cm_rbf_isa_supported(CM_RBF_ISA_AVX512)) self_product(m, c, w, threads, reps);
            for (int v = 0; v < NVAR; ++v)
                for (int s = 0; s < 2; ++s) {
                    if (!cm_rbf_isa_supported(variants[v].isa)) continue;
                    printf("m=%zu n=%zu threads=%d variant=%s sum=%s cpu_s=%.3f wall_s=%.3f "
                           "pairs_per_cpu_s=%.3g pairs_per_s=%.3g err_over_sum_abs=%.2g "
                           "err_over_ref=%.2g\n",
                           m, n, threads, variants[v].name, s ? "compensated" : "plain",
                           best[v][s], wall[v][s], (double)n * (double)m / best[v][s],
                           (double)n * (double)m / wall[v][s], err_abs[v][s], err_rel[v][s]);
                }
            fflush(stdout);
        }
    }
    /* what AUTO's cost model sees in this process (one thread, as cm_rbf_create sets it) */
    cm_blas_threads(NULL, "bench_kernel", 1, NULL);
    double g, kp, ka;
    cm_rbf_auto_rates(&g, &kp, &ka);
    printf("auto_probe dgemm_gflops=%.1f plain_pairs_per_s=%.3g compensated_pairs_per_s=%.3g\n",
           g * 1e-9, kp, ka);
    for (size_t m = 2500; m <= 40000; m *= 2) {
        double d, it;
        int measured = cm_rbf_auto_costs(m, 1, &d, &it);
        printf("auto_model m=%zu dense_s=%.2f iterative_s=%.2f choice=%s rates=%s\n", m, d, it,
               cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, m, 1) ? "dense" : "iterative",
               measured ? "measured" : "fallback");
    }
    free(c), free(w), free(p), free(out), free(ref), free(absum);
    return 0;
}
