/* Times the stages of `cadmorph quality` and of boundary extraction on one mesh file:
 * read, scaled Jacobian of every cell, summary (percentiles), boundary + components.
 * usage: bench_quality MESH [THREADS] - built and run by bench_quality.sh. */
#include "cadmorph/mesh.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

/* process CPU seconds (all threads): on a shared machine wall time also counts waiting */
static double cpu(void) { return (double)clock() / CLOCKS_PER_SEC; }

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_quality MESH [THREADS]\n");
        return 1;
    }
    cm_context *ctx = NULL;
    cm_mesh *mesh = NULL;
    cm_mesh_boundary *b = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 4;
    if (argc > 2) cm_context_set_threads(ctx, atoi(argv[2]));
    double t0 = cm_wtime();
    cm_status s = cm_mesh_read(ctx, argv[1], &mesh);
    double t_read = cm_wtime() - t0;
    if (s < 0) {
        fprintf(stderr, "%s\n", cm_context_message(ctx));
        return 2;
    }
    double *sj = malloc(mesh->n_cells * sizeof *sj);
    cm_quality_stats all;
    /* best of 3: the machine is shared */
    double t_q = 1e30, t_sum = 1e30, t_b = 1e30, c_q = 1e30, c_sum = 1e30, c_b = 1e30;
    for (int rep = 0; rep < 3; ++rep) {
        t0 = cm_wtime();
        double u0 = cpu();
        cm_mesh_quality(ctx, mesh, sj);
        double t1 = cm_wtime(), u1 = cpu();
        cm_quality_summarize(ctx, mesh, sj, NULL, &all);
        double t2 = cm_wtime(), u2 = cpu();
        cm_mesh_boundary_destroy(&b);
        s = cm_mesh_boundary_create(ctx, mesh, &b);
        double t3 = cm_wtime(), u3 = cpu();
        if (t1 - t0 < t_q) t_q = t1 - t0;
        if (t2 - t1 < t_sum) t_sum = t2 - t1;
        if (t3 - t2 < t_b) t_b = t3 - t2;
        if (u1 - u0 < c_q) c_q = u1 - u0;
        if (u2 - u1 < c_sum) c_sum = u2 - u1;
        if (u3 - u2 < c_b) c_b = u3 - u2;
    }
    printf("mesh %s: %zu nodes, %zu cells, %zu volume cells\n", argv[1], mesh->n_nodes, mesh->n_cells,
           cm_mesh_count_dim(mesh, 3));
    printf("threads %d\n", argc > 2 ? atoi(argv[2]) : 0);
    printf("read           %.3f s\n", t_read);
    printf("stage          wall (best of 3)   cpu (best of 3)\n");
    printf("quality        %.3f s            %.3f s\n", t_q, c_q);
    printf("summarize      %.3f s            %.3f s\n", t_sum, c_sum);
    printf("boundary       %.3f s            %.3f s: %zu faces, %zu nodes, %zu components (status %d)\n", t_b, c_b,
           b ? b->n_faces : 0, b ? b->n_nodes : 0, b ? b->n_components : 0, (int)s);
    printf("min_scaled_jacobian=%.6g mean_scaled_jacobian=%.6g inverted=%zu cells=%zu\n", all.min, all.mean,
           all.inverted, all.count);
    cm_mesh_boundary_destroy(&b);
    free(sj);
    cm_mesh_destroy(&mesh);
    cm_context_destroy(&ctx);
    return 0;
}
