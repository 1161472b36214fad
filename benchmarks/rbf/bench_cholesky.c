/* The dense factorisation alone: LAPACK's dpftrf against cadmorph's panel-by-panel RFP
 * Cholesky (rbf/dense/cholesky_blocked.c) and its look-ahead variant on THREADS OpenMP threads of
 * one-thread BLAS (rbf/dense/cholesky_lookahead.c) on the same SPD matrix, alternating in one
 * process, at the OpenBLAS core and thread count of this run; with the Cholesky bound n^3/3
 * at the best dgemm rate measured in the same process.
 * usage: bench_cholesky THREADS REPS N...   (one line of key=value per n; `blocked` is the
 * panel-by-panel path, `lookahead` the other, `chosen` says which cm_rbf_cholesky_rfp takes)
 * BLOCKS=b1,b2,... (environment): also the panel-by-panel factorisation with these blocks;
 * LA_BLOCKS=b1,b2,...: also the look-ahead factorisation with these blocks;
 * MODEL=1 [MODEL_BLOCK=b]: the look-ahead's schedule model (below);
 * cpu_s: best CPU seconds of the process (dpftrf/blocked/lookahead; spinning workers count);
 * FULL=1: also dpotrf on full storage, unpacked from and packed back into RFP (dtfttr,
 * dtrttf; timed with the copies and without), the alternative for small n. */
#include "blas_reexec.h"
#include "rbf_internal.h"
#include "bench_util.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* MODEL=1: the look-ahead factorisation once more per repetition with its tasks timed by
 * their thread's CPU clock (the library's trace hook, cm_lookahead_trace_hook), and its
 * schedule replayed on THREADS idle cores: each step's look-ahead task on one thread, its
 * chunks in order on whichever thread is free first (the dynamic schedule), a barrier per
 * step. On a machine that other jobs load, wall time says how busy the machine was; this
 * says what the schedule costs, against the bound at THREADS x the one-thread dgemm rate
 * by the same CPU clock. */
typedef struct trace_rec {
    int step, kind;
    double s;
} trace_rec;
#define TRACE_MAX (1 << 18)
static trace_rec trace_recs[TRACE_MAX];
static int trace_count;

static void trace_record(int step, int kind, double cpu_seconds)
{
    int i = __atomic_fetch_add(&trace_count, 1, __ATOMIC_RELAXED);
    if (i < TRACE_MAX) trace_recs[i] = (trace_rec){step, kind, cpu_seconds};
}

/* The replayed makespan on `threads` cores and the sum of the task times (one core). */
static double trace_la; /* of the last model: the look-ahead tasks' share of busy */
static void trace_model(int threads, double *makespan, double *busy)
{
    const int count = trace_count < TRACE_MAX ? trace_count : TRACE_MAX;
    int steps = 0;
    for (int i = 0; i < count; ++i)
        if (trace_recs[i].step + 1 > steps) steps = trace_recs[i].step + 1;
    *makespan = *busy = trace_la = 0.0;
    for (int i = 0; i < count; ++i) {
        *busy += trace_recs[i].s;
        if (trace_recs[i].kind == 0) trace_la += trace_recs[i].s;
        if (trace_recs[i].step < 0) *makespan += trace_recs[i].s;
    }
    double *chunk = malloc((CM_LOOKAHEAD_MAX_CHUNKS + 1) * sizeof *chunk);
    for (int k = 0; k < steps; ++k) {
        double la = 0.0, free_at[64] = {0};
        int nchunks = 0;
        for (int q = 0; q <= CM_LOOKAHEAD_MAX_CHUNKS; ++q) chunk[q] = -1.0;
        for (int i = 0; i < count; ++i) {
            if (trace_recs[i].step != k) continue;
            if (trace_recs[i].kind == 0) la = trace_recs[i].s;
            else if (trace_recs[i].kind - 1 <= CM_LOOKAHEAD_MAX_CHUNKS) {
                chunk[trace_recs[i].kind - 1] = trace_recs[i].s;
                if (trace_recs[i].kind > nchunks) nchunks = trace_recs[i].kind;
            }
        }
        const int t = threads < 64 ? threads : 64;
        free_at[0] = la;
        for (int q = 0; q < nchunks; ++q) {
            int best = 0;
            for (int j = 1; j < t; ++j)
                if (free_at[j] < free_at[best]) best = j;
            free_at[best] += chunk[q] > 0.0 ? chunk[q] : 0.0;
        }
        double end = 0.0;
        for (int j = 0; j < t; ++j) end = fmax(end, free_at[j]);
        *makespan += end;
    }
    free(chunk);
}

static double thread_cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* dgemm flops per second at n = 2000, best of 3: by wall clock at OpenBLAS's thread count,
 * or (cpu1) on one thread per CPU-second of the calling thread (the count restored after) */
static double dgemm_rate_of(int cpu1)
{
    const int n = 2000, saved = openblas_get_num_threads();
    if (cpu1) openblas_set_num_threads(1);
    double *a = malloc(sizeof(double) * n * n), *b = malloc(sizeof(double) * n * n);
    double *c = malloc(sizeof(double) * n * n);
    for (long i = 0; i < (long)n * n; ++i) a[i] = 1.0 / (1 + i % 7), b[i] = 0.5, c[i] = 0.0;
    double best = 0.0;
    for (int r = 0; r < 3; ++r) {
        double t = cpu1 ? thread_cpu() : cm_wtime();
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, n, n, n, 1.0, a, n, b, n, 0.0, c, n);
        best = fmax(best, 2.0 * n * (double)n * n / ((cpu1 ? thread_cpu() : cm_wtime()) - t));
    }
    free(a), free(b), free(c);
    if (cpu1) openblas_set_num_threads(saved);
    return best;
}

/* b1,b2,... from the environment variable `name` into out (at most 8) */
static int parse_blocks(const char *name, long *out)
{
    int count = 0;
    for (const char *e = getenv(name); e && *e && count < 8;) {
        char *end;
        long v = strtol(e, &end, 10);
        if (end == e) break;
        out[count++] = v;
        e = *end == ',' ? end + 1 : end;
    }
    return count;
}

/* A_ij = 1 / (1 + |i - j|) + n [i = j]: diagonally dominant, so SPD, and cheap to fill. */
static void fill_rfp(int n, double *a)
{
    const int n2 = n / 2, n1 = n - n2;
    const size_t ld = n % 2 ? (size_t)n : (size_t)n + 1;
    double *t = a + (n % 2 ? 0 : 1), *u = a + (n % 2 ? (size_t)n : 0);
    for (int j = 0; j < n; ++j)
        for (int i = j; i < n; ++i) {
            double v = 1.0 / (1.0 + (i - j)) + (i == j ? n : 0.0);
            if (j < n1) t[(size_t)i + (size_t)j * ld] = v;
            else u[(size_t)(j - n1) + (size_t)(i - n1) * ld] = v;
        }
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core, as cadmorph */
    if (argc < 4) {
        fprintf(stderr, "usage: %s THREADS REPS N...\n", argv[0]);
        return 1;
    }
    const int threads = atoi(argv[1]), reps = atoi(argv[2]) > 0 ? atoi(argv[2]) : 1;
    int got = 0;
    if (cm_blas_threads(NULL, "bench_cholesky", threads > 0 ? threads : 2, &got) != CM_OK)
        return 2;
    for (int k = 3; k < argc; ++k) {
        const int n = atoi(argv[k]);
        const size_t len = (size_t)n * (n + 1) / 2;
        double *a = malloc(len * sizeof *a), *b = malloc(len * sizeof *b);
        double *l = malloc(len * sizeof *l);
        if (!a || !b || !l) return 2;
        long blocks[8], la_blocks[8];
        const int nblocks = parse_blocks("BLOCKS", blocks);
        const int nla = parse_blocks("LA_BLOCKS", la_blocks);
        double best_la_b[8];
        for (int q = 0; q < 8; ++q) best_la_b[q] = INFINITY;
        const int full = getenv("FULL") && atoi(getenv("FULL"));
        double best_b[8], best_full = INFINITY, best_full_only = INFINITY;
        for (int q = 0; q < 8; ++q) best_b[q] = INFINITY;
        double *f = full ? malloc((size_t)n * n * sizeof *f) : NULL;
        if (full && !f) return 2;
        double rate = 0.0, best_ref = INFINITY, best_blk = INFINITY, best_la = INFINITY;
        double cpu_ref = INFINITY, cpu_blk = INFINITY, cpu_la = INFINITY;
        const int model = getenv("MODEL") && atoi(getenv("MODEL"));
        const int model_block = getenv("MODEL_BLOCK") ? atoi(getenv("MODEL_BLOCK")) : 0;
        double rate1 = 0.0, best_model = INFINITY, best_busy = INFINITY, best_la_cpu = 0.0;
        int info_ref = 0, info_blk = 0, info_la = 0;
        for (int r = 0; r < reps; ++r) {
            rate = fmax(rate, dgemm_rate_of(0));
            fill_rfp(n, a);
            double t0 = cm_wtime(), u0 = bench_cpu_seconds();
            info_ref = LAPACKE_dpftrf_work(LAPACK_COL_MAJOR, 'N', 'L', n, a);
            double t1 = cm_wtime(), u1 = bench_cpu_seconds();
            fill_rfp(n, b);
            double t2 = cm_wtime(), u2 = bench_cpu_seconds();
            info_blk = cm_rbf_cholesky_rfp_panels(NULL, n, b, 0);
            double t3 = cm_wtime(), u3 = bench_cpu_seconds();
            fill_rfp(n, l);
            double t4 = cm_wtime(), u4 = bench_cpu_seconds();
            info_la = cm_rbf_cholesky_rfp_lookahead(NULL, n, l, 0, got);
            double t5 = cm_wtime(), u5 = bench_cpu_seconds();
            cpu_ref = fmin(cpu_ref, u1 - u0);
            cpu_blk = fmin(cpu_blk, u3 - u2);
            cpu_la = fmin(cpu_la, u5 - u4);
            best_ref = fmin(best_ref, t1 - t0);
            best_blk = fmin(best_blk, t3 - t2);
            best_la = fmin(best_la, t5 - t4);
            if (model) {
                rate1 = fmax(rate1, dgemm_rate_of(1));
                fill_rfp(n, l);
                trace_count = 0;
                cm_lookahead_trace_hook = trace_record;
                cm_rbf_cholesky_rfp_lookahead(NULL, n, l, model_block, got);
                cm_lookahead_trace_hook = NULL;
                double ms, busy;
                trace_model(got, &ms, &busy);
                best_model = fmin(best_model, ms);
                if (busy < best_busy) best_busy = busy, best_la_cpu = trace_la;
            }
            for (int q = 0; q < nblocks; ++q) {
                fill_rfp(n, b);
                double s0 = cm_wtime();
                cm_rbf_cholesky_rfp_panels(NULL, n, b, (int)blocks[q]);
                best_b[q] = fmin(best_b[q], cm_wtime() - s0);
            }
            for (int q = 0; q < nla; ++q) {
                fill_rfp(n, l);
                double s0 = cm_wtime();
                cm_rbf_cholesky_rfp_lookahead(NULL, n, l, (int)la_blocks[q], got);
                best_la_b[q] = fmin(best_la_b[q], cm_wtime() - s0);
            }
            if (full) {
                fill_rfp(n, b);
                double s0 = cm_wtime();
                LAPACKE_dtfttr_work(LAPACK_COL_MAJOR, 'N', 'L', n, b, f, n);
                double s1 = cm_wtime();
                LAPACKE_dpotrf_work(LAPACK_COL_MAJOR, 'L', n, f, n);
                double s2 = cm_wtime();
                LAPACKE_dtrttf_work(LAPACK_COL_MAJOR, 'N', 'L', n, f, n, b);
                double s3 = cm_wtime();
                best_full = fmin(best_full, s3 - s0);
                best_full_only = fmin(best_full_only, s2 - s1);
            }
        }
        rate = fmax(rate, dgemm_rate_of(0));
        char load[64] = "?";
        FILE *lf = fopen("/proc/loadavg", "r");
        if (lf) {
            if (!fgets(load, sizeof load, lf)) load[0] = '\0';
            fclose(lf);
            for (char *s = load, *sp = NULL; *s; ++s) /* the 1-minute average only */
                if (*s == ' ' || *s == '\n') { sp = s; *sp = '\0'; break; }
        }
        double diff = 0.0, diff_la = 0.0, big = 0.0;
        for (size_t i = 0; i < len; ++i) {
            diff = fmax(diff, fabs(a[i] - b[i]));
            diff_la = fmax(diff_la, fabs(a[i] - l[i]));
            big = fmax(big, fabs(a[i]));
        }
        const double bound = (double)n * n * n / 3.0 / rate;
        printf("n=%d core=%s blas_threads=%d reps=%d dgemm_gflops=%.1f bound_s=%.3f "
               "dpftrf_s=%.3f dpftrf_over_bound=%.3f blocked_s=%.3f blocked_over_bound=%.3f "
               "blocked_over_dpftrf=%.3f lookahead_s=%.3f lookahead_over_bound=%.3f "
               "lookahead_over_dpftrf=%.3f cpu_s=%.3f/%.3f/%.3f chosen=%s max_diff_rel=%.2g/%.2g "
               "info=%d/%d/%d load=%s\n",
               n, openblas_get_corename(), got, reps, rate * 1e-9, bound, best_ref,
               best_ref / bound, best_blk, best_blk / bound, best_blk / best_ref, best_la,
               best_la / bound, best_la / best_ref, cpu_ref, cpu_blk, cpu_la,
               got > 1 && n >= CM_LOOKAHEAD_MIN_N && n <= CM_LOOKAHEAD_MAX_N ? "lookahead"
                                                                            : "blocked",
               diff / big, diff_la / big, info_ref, info_blk, info_la, load);
        if (model) {
            const double mbound = (double)n * n * n / 3.0 / (rate1 * got);
            printf("n=%d model threads=%d block=%d dgemm1_cpu_gflops=%.1f model_bound_s=%.3f "
                   "model_s=%.3f model_over_bound=%.3f busy_cpu_s=%.3f busy_over_1thread_bound=%.3f "
                   "lookahead_tasks_cpu_s=%.3f\n",
                   n, got, model_block, rate1 * 1e-9, mbound, best_model, best_model / mbound,
                   best_busy, best_busy / (mbound * got), best_la_cpu);
        }
        for (int q = 0; q < nblocks; ++q)
            printf("n=%d block=%ld blocked_s=%.3f blocked_over_bound=%.3f\n", n, blocks[q],
                   best_b[q], best_b[q] / bound);
        for (int q = 0; q < nla; ++q)
            printf("n=%d la_block=%ld lookahead_s=%.3f lookahead_over_bound=%.3f\n", n,
                   la_blocks[q], best_la_b[q], best_la_b[q] / bound);
        if (full)
            printf("n=%d full_dpotrf_s=%.3f full_over_bound=%.3f with_copies_s=%.3f "
                   "with_copies_over_bound=%.3f\n",
                   n, best_full_only, best_full_only / bound, best_full, best_full / bound);
        fflush(stdout);
        free(a), free(b), free(l), free(f);
    }
    return 0;
}
