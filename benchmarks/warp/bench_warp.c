/* Warp methods side by side: for one mesh, each method in a forked child (so that
 * each gets its own peak RSS) creates its warp on M0 (assembly + factorisation) and applies
 * it to the same smooth boundary motion `steps` times, as an absolute study does.
 * BENCH_VERBOSE=1 in the environment shows the library's log (stage timings) on stderr.
 * usage: bench_warp MESH [steps=20] [threads=2] [methods=rbf,rbf-biharmonic,femwarp,lbwarp,simplex]
 * One line per method: key=value pairs (RESULTS.md, "Warp methods"). */
#include "bench_motion.h"
#include "blas_reexec.h"
#include "cadmorph/mesh.h"
#include "cadmorph/warp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

static double peak_mb(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss / 1024.0;
}

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

/* The child: everything for one method, one result line; returns the exit code. */
static int run(const char *path, cm_warp_method method, int steps, int threads)
{
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_context_set_threads(ctx, threads);
    if (getenv("BENCH_VERBOSE")) cm_context_set_log(ctx, log_stderr, NULL);
    cm_mesh *m = NULL;
    cm_mesh_boundary *b = NULL;
    cm_warp *w = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    if (s >= 0) s = cm_mesh_boundary_create(ctx, m, &b);
    if (s < 0) {
        fprintf(stderr, "bench_warp: %s\n", cm_context_message(ctx));
        return 2;
    }
    size_t nn = m->n_nodes;
    const bench_box box = bench_box_of(m);
    double *d0 = calloc(3 * nn, sizeof *d0), *d = malloc(3 * nn * sizeof *d);
    bench_smooth_motion(m, b, &box, d0);
    double base = peak_mb();
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = method;
    double t0 = cm_wtime();
    s = cm_warp_create(ctx, m, b, NULL, &opt, &w);
    double t_create = cm_wtime() - t0;
    if (s < 0) {
        fprintf(stderr, "bench_warp: %s: %s\n", cm_warp_method_name(method),
                cm_context_message(ctx));
        return 2;
    }
    double *t = malloc((size_t)steps * sizeof *t);
    for (int k = 0; k < steps && s >= 0; ++k) {
        /* step k of an absolute study: (k+1)/steps of the motion */
        for (size_t i = 0; i < 3 * nn; ++i)
            d[i] = d0[i] * (k + 1) / steps;
        double t1 = cm_wtime();
        s = cm_warp_apply(ctx, w, d);
        t[k] = cm_wtime() - t1;
    }
    if (s < 0) {
        fprintf(stderr, "bench_warp: %s\n", cm_context_message(ctx));
        return 2;
    }
    double sum = 0;
    for (int k = 0; k < steps; ++k)
        sum += t[k];
    double first = t[0];
    qsort(t, (size_t)steps, sizeof *t, cmp_double);
    /* quality of the last (full) step */
    for (size_t i = 0; i < 3 * nn; ++i)
        m->xyz[i] += d[i];
    double *sj = malloc((m->n_cells ? m->n_cells : 1) * sizeof *sj);
    cm_quality_stats all = {0};
    cm_mesh_quality(ctx, m, sj);
    cm_quality_summarize(ctx, m, sj, NULL, &all);
    size_t cells = cm_mesh_count_dim(m, 3);
    printf("mesh=%s method=%s nodes=%zu cells=%zu boundary=%zu threads=%d create_s=%.4f "
           "apply_first_s=%.4f apply_median_s=%.4f one_step_s=%.4f study_%d_over_one=%.2f "
           "fallback=%zu rss_base_mb=%.0f rss_peak_mb=%.0f min_sj=%.4f inverted=%zu\n",
           path, cm_warp_method_name(method), nn, cells, b->n_nodes, threads, t_create, first,
           t[steps / 2], t_create + first, steps, (t_create + sum) / (t_create + first),
           cm_warp_fallback_nodes(w), base, peak_mb(), all.min, all.inverted);
    fflush(stdout);
    return 0;
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core, as cadmorph */
    if (argc < 2) {
        fprintf(stderr, "usage: bench_warp MESH [steps] [threads] [methods]\n");
        return 1;
    }
    int steps = argc > 2 ? atoi(argv[2]) : 20, threads = argc > 3 ? atoi(argv[3]) : 2;
    char methods[256];
    snprintf(methods, sizeof methods, "%s",
             argc > 4 ? argv[4] : "rbf,rbf-biharmonic,femwarp,lbwarp,simplex");
    if (steps < 1) steps = 1;
    int rc = 0;
    for (char *tok = strtok(methods, ","); tok; tok = strtok(NULL, ",")) {
        int mth = cm_warp_method_from_name(tok);
        if (mth < 0) {
            fprintf(stderr, "bench_warp: unknown method '%s' (%s)\n", tok, cm_warp_method_list());
            return 1;
        }
        fflush(stdout);
        pid_t pid = fork();
        if (pid == 0) _exit(run(argv[1], (cm_warp_method)mth, steps, threads));
        int status = 0;
        waitpid(pid, &status, 0);
        if (!WIFEXITED(status) || WEXITSTATUS(status)) rc = 2;
    }
    return rc;
}
