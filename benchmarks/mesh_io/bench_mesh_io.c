/* Write and read time of every mesh format on a ~1M-tet mesh (a structured grid of cubes,
 * Kuhn-split into 6 tets each), with a bit-exact round-trip check of what was read.
 * usage: bench_mesh_io WORK_DIR [N]   (N cubes per side, default 55: 998,250 tets) */
#include "cadmorph/mesh.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static cm_mesh *kuhn_grid(cm_context *ctx, int n)
{
    static const int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                   {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    const int p = n + 1;
    cm_mesh *m = NULL;
    if (cm_mesh_create(ctx, &m) != CM_OK ||
        cm_mesh_resize_nodes(ctx, m, (size_t)p * p * p, 0) != CM_OK ||
        cm_mesh_reserve_cells(ctx, m, (size_t)6 * n * n * n, (size_t)24 * n * n * n) != CM_OK) {
        cm_mesh_destroy(&m);
        return NULL;
    }
    for (int k = 0; k < p; ++k)
        for (int j = 0; j < p; ++j)
            for (int i = 0; i < p; ++i) {
                double *x = m->xyz + 3 * ((size_t)(k * p + j) * p + i);
                x[0] = i / (double)n, x[1] = j / (double)n, x[2] = k / (double)n;
            }
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                int64_t c[8], o = (int64_t)(k * p + j) * p + i;
                c[0] = o, c[1] = o + 1, c[2] = o + p + 1, c[3] = o + p;
                for (int q = 0; q < 4; ++q) c[4 + q] = c[q] + (int64_t)p * p;
                for (int t = 0; t < 6; ++t) {
                    int64_t v[4] = {c[kuhn[t][0]], c[kuhn[t][1]], c[kuhn[t][2]], c[kuhn[t][3]]};
                    cm_mesh_add_cell(ctx, m, CM_CELL_TET4, v, 4, 1, 1, 0);
                }
            }
    double *sj = NULL;
    if (cm_mesh_add_field(ctx, m, "scaled_jacobian", CM_FIELD_CELL, 1, &sj) == CM_OK)
        cm_mesh_quality(ctx, m, sj);
    return m;
}

static int same(const cm_mesh *a, const cm_mesh *b)
{
    return a->n_nodes == b->n_nodes && a->n_cells == b->n_cells &&
           memcmp(a->xyz, b->xyz, 3 * a->n_nodes * sizeof(double)) == 0 &&
           memcmp(a->conn, b->conn, (size_t)a->offset[a->n_cells] * sizeof(int64_t)) == 0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_mesh_io WORK_DIR [N]\n");
        return 1;
    }
    int n = argc > 2 ? atoi(argv[2]) : 55;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_mesh *m = kuhn_grid(ctx, n);
    if (!m) return 1;
    printf("%zu nodes, %zu tets\n%-22s %8s %8s %9s\n", m->n_nodes, m->n_cells, "format", "write_s",
           "read_s", "size_MB");
    static const struct {
        const char *name;
        int version, binary, compress, appended;
    } v[] = {{"msh41_binary.msh", 41, 1, 0, 0}, {"msh22_binary.msh", 22, 1, 0, 0},
             {"msh41_ascii.msh", 41, 0, 0, 0},  {"inline_zlib.vtu", 41, 1, 1, 0},
             {"appended_raw.vtu", 41, 1, 0, 1}, {"legacy_binary.vtk", 41, 1, 0, 0},
             {"medit.mesh", 41, 0, 0, 0}};
    int bad = 0;
    for (size_t i = 0; i < sizeof v / sizeof *v; ++i) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", argv[1], v[i].name);
        cm_mesh_write_options o;
        cm_mesh_write_options_init(&o);
        o.msh_version = v[i].version, o.binary = v[i].binary;
        o.compress = v[i].compress, o.appended = v[i].appended;
        cm_mesh *r = NULL;
        double t0 = cm_wtime();
        cm_status s = cm_mesh_write(ctx, m, path, &o);
        double t1 = cm_wtime();
        if (s >= 0) s = cm_mesh_read(ctx, path, &r);
        double t2 = cm_wtime();
        struct stat st = {0};
        stat(path, &st);
        int ok = s >= 0 && r && same(m, r);
        bad += !ok;
        printf("%-22s %8.3f %8.3f %9.1f%s\n", v[i].name, t1 - t0, t2 - t1, st.st_size / 1e6,
               ok ? "" : "  ROUND TRIP FAILED");
        if (s < 0) fprintf(stderr, "%s\n", cm_context_message(ctx));
        cm_mesh_destroy(&r);
        remove(path);
    }
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    return bad != 0;
}
