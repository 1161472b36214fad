/* The two constraint formulations of [CMLS §6.1] side by side on a planarity constraint
 * covering a whole plate (the worst case of the mean-centred C): entries of C, of the factor
 * update Phi^T C^T and of the constrained factor, the update's time and the alternations'.
 * usage: bench_shapeup_sparse N K [dense] [update]   (an N x N quad plate, K MLS samples;
 * update: CHOLMOD's rank update of the MLS factor instead of a reordered factorisation) */
#include "cadmorph/shapeup.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu(void)
{
    return (double)clock() / CLOCKS_PER_SEC;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: bench_shapeup_sparse N K [dense]\n");
        return 1;
    }
    int n = atoi(argv[1]), dense = 0, update = 0;
    for (int i = 3; i < argc; ++i)
        dense |= !strcmp(argv[i], "dense"), update |= !strcmp(argv[i], "update");
    size_t k = (size_t)atol(argv[2]);
    cm_context *ctx = NULL;
    cm_mesh *m = NULL;
    if (cm_context_create(&ctx) || cm_mesh_create(ctx, &m)) return 4;
    size_t nn = (size_t)(n + 1) * (n + 1);
    cm_mesh_resize_nodes(ctx, m, nn, 0);
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            double *p = m->xyz + 3 * ((size_t)j * (n + 1) + i);
            p[0] = (double)i / n, p[1] = (double)j / n, p[2] = 0;
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            int64_t c[4] = {j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
                            (j + 1) * (n + 1) + i};
            cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, c, 4, 0, 0, 0);
        }
    unsigned char *con = calloc(nn, 1);
    double *d = calloc(nn * 3, sizeof *d);
    int64_t *all = malloc(nn * sizeof *all);
    for (size_t i = 0; i < nn; ++i) {
        all[i] = (int64_t)i;
        double x = m->xyz[3 * i], y = m->xyz[3 * i + 1];
        if (x < 1e-12) con[i] = 1;
        /* the right edge: lifted more at one corner than the other: a twist that a plane
         * cannot follow exactly, so the constraint does work */
        if (x > 1 - 1e-12) con[i] = 2, d[3 * i + 2] = 0.1 + 0.2 * y;
    }
    cm_mls_options o;
    cm_mls_options_init(&o);
    o.stretch = 0, o.samples = k;
    cm_mls *mls = NULL;
    double c0 = cpu();
    cm_status s = cm_mls_create(ctx, m, con, &o, &mls);
    double c1 = cpu();
    if (s < 0) {
        fprintf(stderr, "%s\n", cm_context_message(ctx));
        return 4;
    }
    cm_mls_stats st;
    cm_mls_get_stats(mls, &st);
    cm_shape_set set = {CM_SHAPE_PLANE, nn, all};
    cm_shapeup_options so;
    cm_shapeup_options_init(&so);
    so.sparse = !dense;
    so.reorder = !update;
    so.max_iterations = 20000;
    cm_shapeup *su = NULL;
    double c2 = cpu();
    s = cm_shapeup_create(ctx, mls, m, 1, &set, &so, &su);
    double c3 = cpu();
    if (s < 0) {
        fprintf(stderr, "%s\n", cm_context_message(ctx));
        return 4;
    }
    double r0, r1;
    cm_shapeup_report rep;
    s = cm_shapeup_apply(ctx, su, d, &r0, &r1, &rep);
    double c4 = cpu();
    printf("formulation,factor,nodes,samples,C_nnz,update_nnz,mls_factor_nnz,factor_nnz,mls_cpu_s,"
           "update_cpu_s,iterations,converged,iterate_cpu_s,per_iteration_ms,residual_before,"
           "residual_after\n");
    printf("%s,%s,%zu,%zu,%zu,%zu,%zu,%zu,%.3f,%.3f,%d,%d,%.3f,%.3f,%.3g,%.3g\n",
           dense ? "mean-centred" : "sparse", update ? "rank-update" : "reordered", nn, st.samples, rep.c_nonzeros, rep.update_nonzeros,
           rep.mls_factor_nonzeros ? rep.mls_factor_nonzeros : st.factor_nonzeros, rep.factor_nonzeros, c1 - c0, c3 - c2, rep.iterations,
           rep.converged, c4 - c3, 1e3 * (c4 - c3) / (rep.iterations ? rep.iterations : 1), r0, r1);
    cm_shapeup_destroy(&su);
    cm_mls_destroy(&mls);
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    free(con), free(d), free(all);
    return s < 0 ? 4 : 0;
}
