/* The warp's reverse product against its forward product (RESULTS.md, "Gradients"): for one
 * mesh and each method, one warp is created on M0 (assembly, factorisation or preconditioner),
 * then one untimed round (first touch of the scratch, CHOLMOD's solve workspace, treecodes),
 * then `reps` rounds of apply (J D, bench_warp's smooth boundary motion) and apply_transpose
 * (J^T v, a smooth field at every node) alternating in one process, so that the machine's
 * load falls on both alike; the figure is the ratio of the medians. dot_gap checks on the
 * figures' own data that the two are transposes: |<v, J D> - <J^T v, D>| / sum |v J D|.
 * usage: bench_warp_vjp MESH [reps=5] [threads=2] [methods=rbf] [solver=auto|dense|iterative]
 * One line of key=value pairs per method. BENCH_VERBOSE=1: the library's log on stderr (the
 * RBF warp's per-component split of solve and sums). */
#define _POSIX_C_SOURCE 200809L
#include "bench_motion.h"
#include "blas_reexec.h"
#include "cadmorph/mesh.h"
#include "cadmorph/warp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu_seconds(void)
{
    struct timespec ts;
    return clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts)
               ? 0
               : (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *t, int n)
{
    qsort(t, (size_t)n, sizeof *t, cmp_double);
    return n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]);
}

static void log_stderr(void *user, cm_log_level level, const char *message)
{
    (void)user;
    (void)level;
    fprintf(stderr, "  %s\n", message);
}

static int run(cm_context *ctx, const cm_mesh *m, const cm_mesh_boundary *b, const char *path,
               cm_warp_method method, cm_rbf_solver solver, int reps)
{
    size_t nn = m->n_nodes, n3 = 3 * nn;
    const bench_box box = bench_box_of(m);
    double *d0 = calloc(n3, sizeof *d0), *d = malloc(n3 * sizeof *d);
    double *v = malloc(n3 * sizeof *v), *out = malloc(n3 * sizeof *out);
    bench_smooth_motion(m, b, &box, d0);
    for (size_t i = 0; i < nn; ++i) { /* a smooth sensitivity field at every node */
        double u[3];
        bench_unit(&box, m->xyz + 3 * i, u);
        for (int k = 0; k < 3; ++k)
            v[3 * i + k] = cos(2.0 * u[k] + u[(k + 1) % 3]) + 0.3 * u[(k + 2) % 3];
    }
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = method;
    opt.solver = solver;
    cm_warp *w = NULL;
    double t0 = cm_wtime();
    cm_status s = cm_warp_create(ctx, m, b, NULL, &opt, &w);
    double t_create = cm_wtime() - t0;
    double *ta = malloc((size_t)reps * sizeof *ta), *tt = malloc((size_t)reps * sizeof *tt);
    double *ca = malloc((size_t)reps * sizeof *ca), *ct = malloc((size_t)reps * sizeof *ct);
    /* the untimed round */
    memcpy(d, d0, n3 * sizeof *d);
    if (s >= 0) s = cm_warp_apply(ctx, w, d);
    if (s >= 0) s = cm_warp_apply_transpose(ctx, w, v, out);
    for (int r = 0; r < reps && s >= 0; ++r) {
        memcpy(d, d0, n3 * sizeof *d);
        double a = cm_wtime(), ac = cpu_seconds();
        s = cm_warp_apply(ctx, w, d);
        ta[r] = cm_wtime() - a, ca[r] = cpu_seconds() - ac;
        if (s < 0) break;
        a = cm_wtime(), ac = cpu_seconds();
        s = cm_warp_apply_transpose(ctx, w, v, out);
        tt[r] = cm_wtime() - a, ct[r] = cpu_seconds() - ac;
    }
    if (s < 0) {
        fprintf(stderr, "bench_warp_vjp: %s: %s\n", cm_warp_method_name(method),
                cm_context_message(ctx));
    } else {
        /* <V, J D> against <J^T V, D> (D is d0: zero off the boundary) */
        double lhs = 0, rhs = 0, scale = 0;
        for (size_t i = 0; i < n3; ++i) {
            lhs += v[i] * d[i];
            rhs += out[i] * d0[i];
            scale += fabs(v[i] * d[i]);
        }
        double apply_s = median(ta, reps), vjp_s = median(tt, reps);
        double apply_cpu = median(ca, reps), vjp_cpu = median(ct, reps);
        printf("mesh=%s nodes=%zu constrained=%zu components=%zu method=%s solver=%s "
               "create_s=%.3f apply_s=%.5f vjp_s=%.5f ratio=%.3f apply_cpu=%.5f vjp_cpu=%.5f "
               "cpu_ratio=%.3f dot_gap=%.1e reps=%d\n",
               path, nn, b->n_nodes, b->n_components, cm_warp_method_name(method),
               solver == CM_RBF_SOLVER_DENSE       ? "dense"
               : solver == CM_RBF_SOLVER_ITERATIVE ? "iterative"
                                                   : "auto",
               t_create, apply_s, vjp_s,
               vjp_s / apply_s, apply_cpu, vjp_cpu, vjp_cpu / apply_cpu, fabs(lhs - rhs) / scale,
               reps);
        fflush(stdout);
    }
    cm_warp_destroy(&w);
    free(d0), free(d), free(v), free(out), free(ta), free(tt), free(ca), free(ct);
    return s < 0 ? 2 : 0;
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core, as cadmorph */
    if (argc < 2) {
        fprintf(stderr, "usage: bench_warp_vjp MESH [reps=5] [threads=2] [methods=rbf] "
                        "[solver=auto|dense|iterative]\n");
        return 1;
    }
    int reps = argc > 2 ? atoi(argv[2]) : 5, threads = argc > 3 ? atoi(argv[3]) : 2;
    if (reps < 1) reps = 1;
    char methods[256];
    snprintf(methods, sizeof methods, "%s", argc > 4 ? argv[4] : "rbf");
    const char *sname = argc > 5 ? argv[5] : "auto";
    cm_rbf_solver solver = !strcmp(sname, "dense")       ? CM_RBF_SOLVER_DENSE
                           : !strcmp(sname, "iterative") ? CM_RBF_SOLVER_ITERATIVE
                                                         : CM_RBF_SOLVER_AUTO;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_context_set_threads(ctx, threads);
    if (getenv("BENCH_VERBOSE")) cm_context_set_log(ctx, log_stderr, NULL);
    cm_mesh *m = NULL;
    cm_mesh_boundary *b = NULL;
    cm_status s = cm_mesh_read(ctx, argv[1], &m);
    if (s >= 0) s = cm_mesh_boundary_create(ctx, m, &b);
    if (s < 0) {
        fprintf(stderr, "bench_warp_vjp: %s\n", cm_context_message(ctx));
        return 2;
    }
    int rc = 0;
    for (char *tok = strtok(methods, ","); tok; tok = strtok(NULL, ",")) {
        int mth = cm_warp_method_from_name(tok);
        if (mth < 0) {
            fprintf(stderr, "bench_warp_vjp: unknown method '%s' (%s)\n", tok,
                    cm_warp_method_list());
            rc = 1;
            break;
        }
        if (run(ctx, m, b, argv[1], (cm_warp_method)mth, solver, reps)) rc = 2;
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    return rc;
}
