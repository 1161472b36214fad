/* Many right-hand sides in one iterative RBF solve, and warm starts, on real boundary node
 * sets of one mesh (bench_rbf_iterative_data.py writes them: the same centres, one set of
 * displacements per target). usage: `bench_rbf_columns --help`.
 * Columns: the sets' components in order (3 per set); past those, a real column plus 0.3 x
 * another of the same component, so that every column is a displacement field of the mesh.
 * Prints one line of key=value per run. */
#include "blas_reexec.h"
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "rbf_tuning.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench_util.h"

#define MAX_SETS 64

/* f (m x K row-major): column c as above, from vals[s] (m x 3 each, S sets) */
static void make_columns(size_t m, int S, double *const *vals, int K, double *f)
{
    const int real = 3 * S;
    for (int c = 0; c < K; ++c) {
        const int a = c % real, e = a % 3;
        const int b = c >= real ? 3 * (((c / real) * 7 + a / 3 + 1) % S) + e : -1;
        for (size_t i = 0; i < m; ++i) {
            double v = vals[a / 3][3 * i + (size_t)e];
            if (b >= 0) v += 0.3 * vals[b / 3][3 * i + (size_t)e];
            f[i * (size_t)K + (size_t)c] = v;
        }
    }
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core, as cadmorph */
    static const char usage[] =
        "usage: bench_rbf_columns PREFIX [PREFIX...] [--columns K[,K...]] [--sequence]\n"
        "       [--threads N] [--tol T] [--column-scale S] [--budget BYTES]\n"
        "Iterative RBF solves on the sets PREFIX.centres / .values (raw float64, n x 3, all\n"
        "with the same centres): --columns: one solve of K columns per K (default 3,15,30,60),\n"
        "solve CPU s per column; --sequence: each set's 3 columns after the previous set's,\n"
        "from zero and warm from the earlier sets' solutions (iterations and CPU s of both).\n"
        "--column-scale, --budget: the tuning knobs column_scale and krylov_budget\n"
        "(rbf_tuning.h).\n";
    if (argc < 2 || !strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    const char *prefix[MAX_SETS];
    int S = 0, threads = 2, sequence = 0, nk = 0, ks[32];
    double tol = 1e-10;
    cm_rbf_tuning tun;
    cm_rbf_tuning_init(&tun);
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *b = i + 1 < argc ? argv[i + 1] : "0";
        if (!strcmp(a, "--threads")) threads = atoi(b), ++i;
        else if (!strcmp(a, "--tol")) tol = atof(b), ++i;
        else if (!strcmp(a, "--sequence")) sequence = 1;
        else if (!strcmp(a, "--column-scale")) tun.column_scale = atof(b), ++i;
        else if (!strcmp(a, "--budget")) tun.krylov_budget = atof(b), ++i;
        else if (!strcmp(a, "--columns")) {
            for (const char *p = b; *p && nk < 32;) {
                ks[nk++] = atoi(p);
                p = strchr(p, ',');
                if (!p) break;
                ++p;
            }
            ++i;
        } else if (a[0] == '-' && a[1] == '-') {
            fprintf(stderr, "bench_rbf_columns: unknown option %s\n", a);
            return 2;
        } else if (S < MAX_SETS) prefix[S++] = a;
    }
    if (nk == 0 && !sequence) {
        static const int def[4] = {3, 15, 30, 60};
        memcpy(ks, def, sizeof def);
        nk = 4;
    }
    size_t m = 0;
    double *x = bench_read_xyz(prefix[0], "centres", &m), *vals[MAX_SETS];
    for (int s = 0; s < S; ++s) {
        size_t n = 0;
        vals[s] = bench_read_xyz(prefix[s], "values", &n);
        if (!vals[s] || n != m) {
            fprintf(stderr, "bench_rbf_columns: %s.values: not %zu x 3\n", prefix[s], m);
            return 1;
        }
    }
    if (!x || m == 0) {
        fprintf(stderr, "bench_rbf_columns: cannot read %s.centres\n", prefix[0]);
        return 1;
    }
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, threads);
    cm_rbf_options o;
    cm_rbf_options_init(&o);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    o.tolerance = tol;
    o.warm_start = 0;
    cm_rbf *r = NULL;
    double c0 = bench_cpu_seconds();
    cm_status st = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r);
    if (st != CM_OK) {
        fprintf(stderr, "bench_rbf_columns: %s\n", cm_context_message(ctx));
        return 1;
    }
    printf("m=%zu sets=%d threads=%d column_scale=%g setup_cpu_s=%.2f\n", m, S, threads,
           tun.column_scale, bench_cpu_seconds() - c0);
    fflush(stdout);
    for (int q = 0; q < nk; ++q) {
        const int K = ks[q];
        double *f = malloc(m * (size_t)K * sizeof *f);
        make_columns(m, S, vals, K, f);
        c0 = bench_cpu_seconds();
        const double t0 = cm_wtime();
        st = cm_rbf_solve(ctx, r, K, f);
        const double cpu = bench_cpu_seconds() - c0, wall = cm_wtime() - t0;
        cm_rbf_stats rs;
        cm_rbf_get_stats(r, &rs);
        int lo = 1 << 30;
        for (int c = 0; c < K; ++c) {
            const int it = cm_rbf_iterative_column_iterations(r, (size_t)c);
            lo = it < lo ? it : lo;
        }
        printf("columns=%d status=%d solve_cpu_s=%.2f wall_s=%.2f cpu_per_column_s=%.3f "
               "iterations=%d min_iterations=%d matvecs=%d (comp %d plain %d fast %d) "
               "residual=%.3g groups=%d memory_mb=%.0f\n",
               K, (int)st, cpu, wall, cpu / K, rs.iterations, lo, rs.matvecs,
               rs.matvecs_compensated, rs.matvecs_plain, rs.matvecs_fast, rs.residual,
               rs.column_groups, (double)rs.memory_bytes / 1e6);
        fflush(stdout);
        free(f);
    }
    if (sequence) {
        /* each set after the previous one: warm (from the fit's history, which holds the warm
         * solves of the sets before), then from zero (not kept: warm_start 0) */
        double tw = 0.0, tc = 0.0;
        int iw = 0, ic = 0;
        for (int s = 0; s < S; ++s) {
            cm_rbf_stats sw, sc;
            r->opt.warm_start = 1;
            c0 = bench_cpu_seconds();
            cm_status a = cm_rbf_solve(ctx, r, 3, vals[s]);
            const double cw = bench_cpu_seconds() - c0;
            cm_rbf_get_stats(r, &sw);
            r->opt.warm_start = 0;
            c0 = bench_cpu_seconds();
            cm_status b = cm_rbf_solve(ctx, r, 3, vals[s]);
            const double cc = bench_cpu_seconds() - c0;
            cm_rbf_get_stats(r, &sc);
            printf("set=%s status=%d/%d iterations_cold=%d iterations_warm=%d warm_columns=%d "
                   "warm_basis=%d warm_residual=%.3g cpu_cold_s=%.2f cpu_warm_s=%.2f "
                   "residual_warm=%.3g\n",
                   prefix[s], (int)b, (int)a, sc.iterations, sw.iterations, sw.warm_columns,
                   sw.warm_basis, sw.warm_residual, cc, cw, sw.residual);
            fflush(stdout);
            if (s > 0) tw += cw, tc += cc, iw += sw.iterations, ic += sc.iterations;
        }
        printf("sequence: sets 2..%d iterations cold=%d warm=%d, cpu_s cold=%.2f warm=%.2f\n",
               S, ic, iw, tc, tw);
    }
    cm_rbf_destroy(&r);
    for (int s = 0; s < S; ++s) free(vals[s]);
    free(x);
    cm_context_destroy(&ctx);
    return 0;
}
