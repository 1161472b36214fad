/* The reverse product of the RBF warp against its forward product: on one mesh, one warp
 * (create once), one round untimed, then `reps` rounds of one cm_warp_apply of a smooth boundary motion and one
 * cm_warp_apply_transpose of a smooth field at every node, alternating in one process so
 * that the machine's load falls on both alike; the median of each and their ratio.
 * usage: bench_rbf_vjp MESH [reps=3] [threads=2] [solver=auto|dense|iterative]
 * One line of key=value pairs (RESULTS.md, "Gradients"). BENCH_VERBOSE=1: the library's log
 * (per component: the solve's and the evaluation's seconds) on stderr. */
#include "blas_reexec.h"
#include "cadmorph/mesh.h"
#include "cadmorph/warp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void log_stderr(void *user, cm_log_level level, const char *message)
{
    (void)user;
    (void)level;
    fprintf(stderr, "  %s\n", message);
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core, as cadmorph */
    if (argc < 2) {
        fprintf(stderr, "usage: bench_rbf_vjp MESH [reps=3] [threads=2] [solver=auto|dense|iterative]\n");
        return 2;
    }
    const int reps = argc > 2 ? atoi(argv[2]) : 3, threads = argc > 3 ? atoi(argv[3]) : 2;
    const char *sname = argc > 4 ? argv[4] : "auto";
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_context_set_threads(ctx, threads);
    if (getenv("BENCH_VERBOSE")) cm_context_set_log(ctx, log_stderr, NULL);
    cm_mesh *m = NULL;
    cm_mesh_boundary *b = NULL;
    cm_warp *w = NULL;
    cm_status s = cm_mesh_read(ctx, argv[1], &m);
    if (s >= 0) s = cm_mesh_boundary_create(ctx, m, &b);
    if (s < 0) {
        fprintf(stderr, "bench_rbf_vjp: %s\n", cm_context_message(ctx));
        return 2;
    }
    const size_t nn = m->n_nodes;
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (size_t v = 0; v < nn; ++v)
        for (int d = 0; d < 3; ++d) {
            lo[d] = fmin(lo[d], m->xyz[3 * v + d]);
            hi[d] = fmax(hi[d], m->xyz[3 * v + d]);
        }
    /* bench_warp's smooth motion (3 % of the diagonal), and a smooth sensitivity field */
    double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    double *d0 = calloc(3 * nn, sizeof *d0), *d = malloc(3 * nn * sizeof *d);
    double *v = malloc(3 * nn * sizeof *v), *out = malloc(3 * nn * sizeof *out);
    for (size_t i = 0; i < nn; ++i) {
        const double *x = m->xyz + 3 * i;
        double u[3];
        for (int k = 0; k < 3; ++k) u[k] = (x[k] - lo[k]) / (hi[k] - lo[k] > 0 ? hi[k] - lo[k] : 1);
        for (int k = 0; k < 3; ++k) v[3 * i + k] = cos(2.0 * u[k] + u[(k + 1) % 3]) + 0.3 * u[(k + 2) % 3];
    }
    for (size_t i = 0; i < b->n_nodes; ++i) {
        const double *x = m->xyz + 3 * b->nodes[i];
        double u[3];
        for (int k = 0; k < 3; ++k) u[k] = (x[k] - lo[k]) / (hi[k] - lo[k] > 0 ? hi[k] - lo[k] : 1);
        double *o = d0 + 3 * b->nodes[i];
        o[0] = 0.03 * diag * sin(3.14159265358979323846 * u[1]) * u[2];
        o[1] = 0.03 * diag * sin(3.14159265358979323846 * u[2]) * u[0];
        o[2] = 0.03 * diag * sin(3.14159265358979323846 * u[0]) * u[1];
    }
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.solver = !strcmp(sname, "dense")       ? CM_RBF_SOLVER_DENSE
                 : !strcmp(sname, "iterative") ? CM_RBF_SOLVER_ITERATIVE
                                               : CM_RBF_SOLVER_AUTO;
    double t0 = cm_wtime();
    s = cm_warp_create(ctx, m, b, NULL, &opt, &w);
    const double t_create = cm_wtime() - t0;
    if (s < 0) {
        fprintf(stderr, "bench_rbf_vjp: %s\n", cm_context_message(ctx));
        return 2;
    }
    double *ta = malloc((size_t)reps * sizeof *ta), *tt = malloc((size_t)reps * sizeof *tt);
    long double lhs = 0.0L, rhs = 0.0L;
    /* a round before the timed ones: first touch of the scratch, the treecodes made once */
    memcpy(d, d0, 3 * nn * sizeof *d);
    s = cm_warp_apply(ctx, w, d);
    if (s >= 0) s = cm_warp_apply_transpose(ctx, w, v, out);
    for (int r = 0; r < reps && s >= 0; ++r) {
        memcpy(d, d0, 3 * nn * sizeof *d);
        t0 = cm_wtime();
        s = cm_warp_apply(ctx, w, d);
        ta[r] = cm_wtime() - t0;
        t0 = cm_wtime();
        if (s >= 0) s = cm_warp_apply_transpose(ctx, w, v, out);
        tt[r] = cm_wtime() - t0;
    }
    if (s < 0) {
        fprintf(stderr, "bench_rbf_vjp: %s\n", cm_context_message(ctx));
        return 2;
    }
    /* the dot-product test on the figures' own data: <v, J d> = <J^T v, d> */
    for (size_t i = 0; i < 3 * nn; ++i) {
        lhs += (long double)v[i] * d[i];
        rhs += (long double)out[i] * d0[i];
    }
    qsort(ta, (size_t)reps, sizeof *ta, cmp_double);
    qsort(tt, (size_t)reps, sizeof *tt, cmp_double);
    const double a = ta[reps / 2], t = tt[reps / 2];
    printf("mesh=%s nodes=%zu boundary=%zu components=%zu solver=%s threads=%d create_s=%.3f "
           "apply_s=%.4f vjp_s=%.4f ratio=%.3f apply_min_s=%.4f vjp_min_s=%.4f dot_gap=%.2g\n",
           argv[1], nn, b->n_nodes, b->n_components, sname, threads, t_create, a, t, t / a,
           ta[0], tt[0], fabs((double)(lhs - rhs)) / fabs((double)lhs));
    cm_warp_destroy(&w);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    free(d0), free(d), free(v), free(out), free(ta), free(tt);
    return 0;
}
