/* The library side of bench_overhead.py: what examples/morph_family.c does for one target,
 * each stage timed with cm_wtime - read G0 and G1, read M0, cm_morpher_create, REPEAT calls
 * of cm_morpher_apply onto G1, then M1 written (a copy of M0 with the morphed points).
 *
 *   bench_morph G0.step G1.step M0 M1 REPEAT THREADS
 *
 * Prints one line: "read_cad S read_mesh S create S apply S,S,... apply_cpu S,S,... write S
 * blas CORE" (apply_cpu: the process's CPU seconds of each apply, every thread).
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime under -std=c11 */
#include <cadmorph/blas.h>
#include <cadmorph/morph.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(int argc, char **argv)
{
    if (argc != 7) {
        fprintf(stderr, "usage: %s G0.step G1.step M0 M1 REPEAT THREADS\n", argv[0]);
        return 1;
    }
    int repeat = atoi(argv[5]);
    cm_context *ctx = NULL;
    if (repeat < 1 || cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, atoi(argv[6]));
    cm_cad_model *g0 = NULL, *g1 = NULL;
    cm_mesh *m0 = NULL, *out = NULL;
    cm_morpher *morpher = NULL;
    double *xyz = NULL, t[4], *t_apply = calloc(2 * (size_t)repeat, sizeof *t_apply);
    double *c_apply = t_apply ? t_apply + repeat : NULL;

    t[0] = cm_wtime();
    cm_status s = cm_cad_read(ctx, argv[1], NULL, &g0);
    if (s >= 0) s = cm_cad_read(ctx, argv[2], NULL, &g1);
    t[0] = cm_wtime() - t[0];
    t[1] = cm_wtime();
    if (s >= 0) s = cm_mesh_read(ctx, argv[3], &m0);
    t[1] = cm_wtime() - t[1];
    t[2] = cm_wtime();
    if (s >= 0) s = cm_morpher_create(ctx, g0, m0, NULL, &morpher);
    t[2] = cm_wtime() - t[2];
    if (s >= 0 && (!t_apply || !(xyz = malloc(3 * m0->n_nodes * sizeof *xyz)))) s = CM_ERR_NOMEM;
    for (int i = 0; s >= 0 && i < repeat; ++i) {
        cm_morph_step row;
        c_apply[i] = cpu_seconds();
        t_apply[i] = cm_wtime();
        s = cm_morpher_apply(ctx, morpher, g1, xyz, &row);
        t_apply[i] = cm_wtime() - t_apply[i];
        c_apply[i] = cpu_seconds() - c_apply[i];
    }
    t[3] = cm_wtime();
    if (s >= 0) s = cm_mesh_copy(ctx, m0, &out);
    if (s >= 0) {
        memcpy(out->xyz, xyz, 3 * m0->n_nodes * sizeof *xyz);
        s = cm_mesh_write(ctx, out, argv[4], NULL);
    }
    t[3] = cm_wtime() - t[3];
    if (s < 0) {
        fprintf(stderr, "bench_morph: %s\n", cm_context_message(ctx));
    } else {
        cm_blas_summary b;
        cm_blas_info(ctx, &b);
        printf("read_cad %.6f read_mesh %.6f create %.6f apply ", t[0], t[1], t[2]);
        for (int i = 0; i < repeat; ++i)
            printf("%s%.6f", i ? "," : "", t_apply[i]);
        printf(" apply_cpu ");
        for (int i = 0; i < repeat; ++i)
            printf("%s%.6f", i ? "," : "", c_apply[i]);
        printf(" write %.6f blas %s\n", t[3], b.core);
    }
    free(t_apply);
    free(xyz);
    cm_morpher_destroy(&morpher);
    cm_mesh_destroy(&out);
    cm_mesh_destroy(&m0);
    cm_cad_destroy(&g1);
    cm_cad_destroy(&g0);
    cm_context_destroy(&ctx);
    return s < 0 ? 2 : 0;
}
