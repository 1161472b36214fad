/* Timing of binary msh 4.1 write and read for about a million tets (label slow): a structured
 * grid of cubes split into 6 tets each; the read must give back the same mesh. */
#include "cadmorph/mesh.h"
#include "test_util.h"

#include <string.h>

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    cm_context *ctx = NULL;
    cm_mesh *m = NULL, *b = NULL;
    if (cm_context_create(&ctx) != CM_OK || cm_mesh_create(ctx, &m) != CM_OK) return 1;
    const int n = 56; /* 56^3 cubes x 6 = 1.05M tets */
    const int p = n + 1;
    CHECK(cm_mesh_resize_nodes(ctx, m, (size_t)p * p * p, 0) == CM_OK);
    for (int k = 0; k < p; ++k)
        for (int j = 0; j < p; ++j)
            for (int i = 0; i < p; ++i) {
                double *x = m->xyz + 3 * ((size_t)(k * p + j) * p + i);
                x[0] = i / (double)n;
                x[1] = j / (double)n;
                x[2] = k / (double)n;
            }
    CHECK(cm_mesh_reserve_cells(ctx, m, (size_t)6 * n * n * n, (size_t)24 * n * n * n) == CM_OK);
    /* Kuhn split of the cube along its 0-6 diagonal */
    static const int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                int64_t c[8];
                int64_t o = (int64_t)(k * p + j) * p + i;
                c[0] = o, c[1] = o + 1, c[2] = o + p + 1, c[3] = o + p;
                for (int q = 0; q < 4; ++q) c[4 + q] = c[q] + (int64_t)p * p;
                for (int t = 0; t < 6; ++t) {
                    int64_t v[4] = {c[kuhn[t][0]], c[kuhn[t][1]], c[kuhn[t][2]], c[kuhn[t][3]]};
                    cm_mesh_add_cell(ctx, m, CM_CELL_TET4, v, 4, 1, 1, 0);
                }
            }
    char path[1024];
    snprintf(path, sizeof path, "%s/msh_perf_1M.msh", argv[2]);
    cm_mesh_write_options opt;
    cm_mesh_write_options_init(&opt);
    opt.msh_version = 41;
    opt.binary = 1;
    double t0 = cm_wtime();
    cm_status s = cm_mesh_write(ctx, m, path, &opt);
    double t1 = cm_wtime();
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    s = cm_mesh_read_msh(ctx, path, &b);
    double t2 = cm_wtime();
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    printf("msh 4.1 binary, %zu nodes, %zu tets: write %.3f s, read %.3f s\n", m->n_nodes, m->n_cells,
           t1 - t0, t2 - t1);
    if (b) {
        CHECK(b->n_nodes == m->n_nodes && b->n_cells == m->n_cells);
        CHECK(b->n_cells == m->n_cells &&
              memcmp(b->conn, m->conn, (size_t)m->offset[m->n_cells] * sizeof(int64_t)) == 0);
    }
    /* generous for a shared 2-core machine; typical figures are printed above */
    CHECK(t1 - t0 < 3.0 && t2 - t1 < 3.0);
    if (argc < 4) remove(path); /* a third argument keeps the file for profiling */
    cm_mesh_destroy(&b);
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
