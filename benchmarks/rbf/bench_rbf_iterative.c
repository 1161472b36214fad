/* Iterative vs dense RBF solver on real boundary node sets (bench_rbf_iterative_data.py
 * writes them from `cadmorph morph` output): set-up, solve, evaluation at the interior
 * nodes, iterations, peak memory, and agreement with the dense solver in the same run.
 * usage: `bench_rbf_iterative --help` (the usage string in main).
 * Prints one line of key=value. PREFIX.centres / .values / .interior: raw float64, n x 3. */
#include "blas_reexec.h"
#include "cadmorph/blas.h"
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "rbf_tuning.h" /* the inner coarse solver's counts, the unit product */
#include "sum/rbf_sum_isa.h"   /* the sqrt split of the kernel blocks */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench_util.h"




static void log_stderr(void *user, cm_log_level level, const char *message)
{
    (void)user;
    (void)level;
    fprintf(stderr, "%s\n", message);
}

typedef struct run {
    cm_rbf_stats st;
    double eval_s;
    double fit_cpu_s; /* create + solve */
    double setup_cpu_s; /* create alone */
    double centres_cpu_s; /* evaluation at the m centres: one direct matvec of 3 components
                           * (compensated for iterative fits), the unit of the fit's cost */
    double eval_cpu_s;
    cm_status status;
    double *out; /* (m + ne) x 3: at the centres, then the interior sample */
    int eval_fast;
    double eval_error;
    int eval_order; /* the treecode row the evaluation took */
    double eval_theta;
    int centres_fast; /* the evaluation at the centres (it_exact) took the treecode */
} run;

/* --no-centres: skip the evaluation at the centres (the exactness check), which at m = 1e6
 * is a full direct product */
static int skip_centres = 0;
/* coarse_inner > 0: inner coarse solves and their iterations in all, of the last fit */
static long inner_solves = 0, inner_its = 0;

static void inner_counts(const cm_rbf *rbf)
{
    const cm_rbf_coarse_inner *ci = cm_rbf_schwarz_inner(cm_rbf_iterative_pc(rbf));
    cm_rbf_coarse_inner_stats(ci, &inner_solves, &inner_its);
}

static void fit(cm_context *ctx, const cm_rbf_options *o, const cm_rbf_tuning *tun, size_t m, const double *x,
                const double *v, size_t ne, const double *p, run *r)
{
    cm_rbf *rbf = NULL;
    r->out = malloc((m + ne) * 3 * sizeof *r->out);
    double c0 = bench_cpu_seconds();
    r->status = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, o, tun, &rbf);
    r->setup_cpu_s = bench_cpu_seconds() - c0;
    if (r->status >= 0) r->status = cm_rbf_solve(ctx, rbf, 3, v);
    r->fit_cpu_s = bench_cpu_seconds() - c0;
    if (r->status >= 0) {
        double t0 = cm_wtime();
        c0 = bench_cpu_seconds();
        cm_status solved = r->status; /* keep a solve's warning (stagnation, max_iterations) */
        r->status = cm_rbf_evaluate(ctx, rbf, ne, p, r->out + m * 3);
        r->eval_s = cm_wtime() - t0;
        r->eval_cpu_s = bench_cpu_seconds() - c0;
        cm_rbf_stats es;
        cm_rbf_get_stats(rbf, &es);
        r->eval_fast = es.eval_fast;
        r->eval_error = es.eval_error;
        r->eval_order = es.eval_order;
        r->eval_theta = es.eval_theta;
        if (r->status >= 0 && skip_centres) {
            cm_rbf_get_stats(rbf, &r->st);
            inner_counts(rbf);
            cm_rbf_destroy(&rbf);
            return;
        }
        if (r->status >= 0) r->status = cm_rbf_evaluate(ctx, rbf, m, x, r->out);
        cm_rbf_get_stats(rbf, &es);
        r->centres_fast = es.eval_fast;
        /* the unit of fit_in_matvecs: one compensated direct product with the weights, timed
         * by itself (the evaluation above may take the treecode since it accepts the direct
         * sums' own rounding) */
        double *unit = r->status >= 0 ? malloc(rbf->m * 3 * sizeof *unit) : NULL;
        c0 = bench_cpu_seconds();
        if (unit)
            cm_rbf_kernel_sum_acc(rbf->m, rbf->c, rbf->w, 3, rbf->m, rbf->c, rbf->m, unit, 3,
                                  cm_rbf_threads(ctx));
        r->centres_cpu_s = bench_cpu_seconds() - c0;
        free(unit);
        if (r->status == CM_OK) r->status = solved;
    }
    if (r->status < 0) fprintf(stderr, "error: %s\n", cm_context_message(ctx));
    cm_rbf_get_stats(rbf, &r->st);
    if (rbf) inner_counts(rbf);
    cm_rbf_destroy(&rbf);
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core, as cadmorph */
    static const char usage[] =
        "usage: bench_rbf_iterative PREFIX [--dense] [--no-iterative] [--threads N] [--leaf N]\n"
        "       [--local N] [--coarse N] [--float | --local-float 0|1|2] [--tol T] [--maxit N]\n"
        "       [--restart N] [--eval N] [--verbose] [--fast 0|1|-1] [--fast-tol T]\n"
        "       [--fast-refine N] [--fast-eval-tol T] [--no-centres] [--relax 0|1]\n"
        "       [--coarse-inner N] [--coarse-inner-tol T] [--thin-reach R] [--thin-cell C]\n"
        "       [--thin-max N] [--post 0|1|2] [--overlap H] [--local-max N] [--coarse-grow 0|1]\n"
        "       [--coarse-max N]\n"
        "Iterative (and with --dense, dense) RBF fit of PREFIX.centres / .values, evaluated at\n"
        "the first N of PREFIX.interior (--eval N; raw float64, n x 3, as written by\n"
        "bench_rbf_iterative_data.py); prints one line of key=value (RESULTS.md, RBF solvers).\n";
    if (argc < 2 || !strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2;
    }
    const char *prefix = argv[1];
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    int dense = 0, iterative = 1, threads = 0, verbose = 0;
    long neval = -1;
    for (int i = 2; i < argc; ++i) {
        const char *a = argv[i], *b = i + 1 < argc ? argv[i + 1] : "0";
        if (!strcmp(a, "--dense")) dense = 1;
        else if (!strcmp(a, "--no-iterative")) iterative = 0;
        else if (!strcmp(a, "--float")) tun.local_float = 1;
        else if (!strcmp(a, "--local-float")) tun.local_float = atoi(b), ++i;
        else if (!strcmp(a, "--verbose")) verbose = 1;
        else if (!strcmp(a, "--no-centres")) skip_centres = 1;
        else if (!strcmp(a, "--threads")) threads = atoi(b), ++i;
        else if (!strcmp(a, "--leaf")) tun.leaf_size = atoi(b), ++i;
        else if (!strcmp(a, "--local")) tun.local_size = atoi(b), ++i;
        else if (!strcmp(a, "--coarse")) tun.coarse_size = atoi(b), ++i;
        else if (!strcmp(a, "--post")) tun.coarse_post = atoi(b), ++i;
        else if (!strcmp(a, "--overlap")) tun.overlap = atof(b), ++i;
        else if (!strcmp(a, "--local-max")) tun.local_max = atoi(b), ++i;
        else if (!strcmp(a, "--thin-reach")) tun.thin_reach = atof(b), ++i;
        else if (!strcmp(a, "--thin-cell")) tun.thin_cell = atof(b), ++i;
        else if (!strcmp(a, "--thin-max")) tun.thin_max = atoi(b), ++i;
        else if (!strcmp(a, "--coarse-grow")) tun.coarse_grow = atoi(b), ++i;
        else if (!strcmp(a, "--coarse-max")) tun.coarse_max = atoi(b), ++i;
        else if (!strcmp(a, "--restart")) o.restart = atoi(b), ++i;
        else if (!strcmp(a, "--tol")) o.tolerance = atof(b), ++i;
        else if (!strcmp(a, "--maxit")) o.max_iterations = atoi(b), ++i;
        else if (!strcmp(a, "--eval")) neval = atol(b), ++i;
        else if (!strcmp(a, "--fast")) o.fast_sum = atoi(b), ++i;
        else if (!strcmp(a, "--fast-tol")) tun.fast_tol = atof(b), ++i;
        else if (!strcmp(a, "--fast-refine")) tun.fast_refine = atoi(b), ++i;
        else if (!strcmp(a, "--fast-eval-tol")) tun.fast_eval_tol = atof(b), ++i;
        else if (!strcmp(a, "--relax")) tun.relax = atoi(b), ++i;
        else if (!strcmp(a, "--coarse-inner")) tun.coarse_inner = atoi(b), ++i;
        else if (!strcmp(a, "--coarse-inner-tol")) tun.coarse_inner_tol = atof(b), ++i;
        else {
            fprintf(stderr, "unknown option %s\n", a);
            return 1;
        }
    }
    size_t m = 0, mv = 0, ni = 0;
    double *x = bench_read_xyz(prefix, "centres", &m), *v = bench_read_xyz(prefix, "values", &mv);
    double *p = bench_read_xyz(prefix, "interior", &ni);
    if (!x || !v || mv != m) {
        fprintf(stderr, "cannot read %s.centres / .values\n", prefix);
        return 1;
    }
    size_t ne = neval >= 0 && (size_t)neval < ni ? (size_t)neval : ni;
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, threads);
    if (verbose) cm_context_set_log(ctx, log_stderr, NULL);
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < 3 * m; ++i) lo = fmin(lo, v[i]), hi = fmax(hi, v[i]);
    const double range = hi - lo;

    run it = {0}, dn = {0};
    cm_blas_summary blas;
    cm_blas_info(NULL, &blas);
    int sq_plain = 0, sq_acc = 0;
    cm_rbf_sqrt_split(&sq_plain, &sq_acc); /* of the AVX-512 kernel blocks, probed */
    printf("set=%s m=%zu interior=%zu core=%s sqrt_split=%d/%d", prefix, m, ne, blas.core,
           sq_plain, sq_acc);
    if (iterative) {
        o.solver = CM_RBF_SOLVER_ITERATIVE;
        fit(ctx, &o, &tun, m, x, v, ne, p, &it);
        double exact = 0.0;
        for (size_t i = 0; !skip_centres && i < 3 * m; ++i) exact = fmax(exact, fabs(it.out[i] - v[i]));
        printf(" it_status=%d leaf=%d local=%d coarse=%d post=%d subdomains=%d it_setup_s=%.2f "
               "it_solve_s=%.2f it_eval_s=%.2f iterations=%d matvecs=%d it_residual=%.3g "
               "it_floor=%.3g at_floor=%d it_exact=%.3g it_mem_mb=%.1f it_rss_mb=%.0f "
               "it_fit_cpu_s=%.1f it_eval_cpu_s=%.1f overlap=%g local_max=%d it_setup_cpu_s=%.1f "
               "matvec_cpu_s=%.2f fit_in_matvecs=%.1f local_float=%d",
               it.status, tun.leaf_size, tun.local_size, it.st.coarse_size, tun.coarse_post,
               it.st.subdomains,
               it.st.setup_seconds, it.st.solve_seconds, it.eval_s, it.st.iterations,
               it.st.matvecs, it.st.residual, it.st.floor, it.st.floor_limited, exact / range,
               (double)it.st.memory_bytes / 1e6, bench_peak_rss_mb(), it.fit_cpu_s, it.eval_cpu_s,
               tun.overlap, tun.local_max, it.setup_cpu_s, it.centres_cpu_s,
               it.centres_cpu_s > 0.0 ? it.fit_cpu_s / it.centres_cpu_s : 0.0, tun.local_float);
        printf(" fast_sum=%d fast_tol=%g refinements=%d fast_direct=%d fast_residual=%.3g "
               "fast_bound=%.3g eval_fast=%d eval_error=%.3g eval_row=%d:%.2f centres_fast=%d",
               it.st.fast_sum, tun.fast_tol, it.st.refinements, it.st.fast_direct,
               it.st.fast_residual, it.st.fast_bound, it.eval_fast, it.eval_error,
               it.eval_order, it.eval_theta, it.centres_fast);
        printf(" relax=%d mv_comp=%d mv_plain=%d mv_fast=%d", tun.relax, it.st.matvecs_compensated,
               it.st.matvecs_plain, it.st.matvecs_fast);
        printf(" coarse_inner=%d coarse_inner_tol=%g inner_solves=%ld inner_its=%ld",
               tun.coarse_inner, tun.coarse_inner_tol, inner_solves, inner_its);
        printf(" thin_reach=%g thin_cell=%g thin_max=%d", tun.thin_reach, tun.thin_cell,
               tun.thin_max);
    }
    if (dense) {
        o.solver = CM_RBF_SOLVER_DENSE;
        fit(ctx, &o, &tun, m, x, v, ne, p, &dn);
        double dex = 0.0;
        for (size_t i = 0; dn.status >= 0 && i < 3 * m; ++i) dex = fmax(dex, fabs(dn.out[i] - v[i]));
        printf(" dense_status=%d dense_setup_s=%.2f dense_solve_s=%.2f dense_eval_s=%.2f "
               "dense_residual=%.3g dense_exact=%.3g dense_rss_mb=%.0f dense_fit_cpu_s=%.1f",
               dn.status, dn.st.setup_seconds, dn.st.solve_seconds, dn.eval_s, dn.st.residual,
               dex / range, bench_peak_rss_mb(), dn.fit_cpu_s);
        if (iterative && it.status >= 0 && dn.status >= 0) {
            double d = 0.0;
            for (size_t i = 0; i < 3 * (m + ne); ++i) d = fmax(d, fabs(it.out[i] - dn.out[i]));
            double ti = it.st.setup_seconds + it.st.solve_seconds;
            double td = dn.st.setup_seconds + dn.st.solve_seconds;
            printf(" agreement=%.3g speedup=%.2f cpu_speedup=%.2f", d / range, td / ti,
                   dn.fit_cpu_s / it.fit_cpu_s);
        }
    }
    printf(" range=%.6g\n", range);
    free(it.out), free(dn.out), free(x), free(v), free(p);
    cm_context_destroy(&ctx);
    return 0;
}
