/* Timing of .vtu / .vtk I/O on a ~1M-tet mesh built in code (label slow): prints write and
 * read seconds per variant and checks the read-back mesh is identical. The goal is a binary
 * zlib-compressed .vtu read in about a second on the 2-core machine. */
#define _POSIX_C_SOURCE 200809L
#include "test_vtk_common.h"

#include <stdlib.h>
#include <sys/stat.h>

/* n^3 cubes, each split into 6 tets around the main diagonal (Kuhn), jittered nodes. */
static cm_mesh *kuhn_mesh(cm_context *ctx, int n)
{
    cm_mesh *m = NULL;
    if (cm_mesh_create(ctx, &m) != CM_OK) return NULL;
    const int p = n + 1;
    cm_mesh_resize_nodes(ctx, m, (size_t)p * p * p, 0);
    unsigned seed = 1;
    for (int k = 0, i = 0; k < p; ++k)
        for (int j = 0; j < p; ++j)
            for (int l = 0; l < p; ++l, ++i) {
                seed = seed * 1664525u + 1013904223u;
                double e = ((double)(seed >> 8) / (1 << 24) - 0.5) * 0.1 / n;
                m->xyz[3 * i] = (double)l / n + e;
                m->xyz[3 * i + 1] = (double)j / n - e;
                m->xyz[3 * i + 2] = (double)k / n + 0.5 * e;
            }
    cm_mesh_reserve_cells(ctx, m, (size_t)6 * n * n * n, (size_t)24 * n * n * n);
    static const int tets[6][4] = {{0, 1, 3, 7}, {0, 1, 7, 5}, {0, 2, 7, 3}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 7, 6}};
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int l = 0; l < n; ++l) {
                int64_t c[8];
                for (int b = 0; b < 8; ++b)
                    c[b] = (int64_t)(k + (b >> 2)) * p * p + (int64_t)(j + ((b >> 1) & 1)) * p + (l + (b & 1));
                for (int t = 0; t < 6; ++t) {
                    int64_t v[4] = {c[tets[t][0]], c[tets[t][1]], c[tets[t][2]], c[tets[t][3]]};
                    cm_mesh_add_cell(ctx, m, CM_CELL_TET4, v, 4, 1, 1, 0);
                }
            }
    double *sj = NULL;
    cm_mesh_add_field(ctx, m, "scaled_jacobian", CM_FIELD_CELL, 1, &sj);
    for (size_t c = 0; sj && c < m->n_cells; ++c) sj[c] = 0.5 + 1e-7 * (double)(c % 1000);
    return m;
}

static void timed(cm_context *ctx, const cm_mesh *m, const char *dir, const char *name, int binary,
                  int compress, int appended, double *read_s)
{
    char p[2100];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    cm_mesh_write_options o;
    cm_mesh_write_options_init(&o);
    o.binary = binary;
    o.compress = compress;
    o.appended = appended;
    double t0 = cm_wtime();
    cm_status s = cm_mesh_write(ctx, m, p, &o);
    double t1 = cm_wtime();
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    cm_mesh *r = NULL;
    double t2 = cm_wtime();
    s = cm_mesh_read(ctx, p, &r);
    double t3 = cm_wtime();
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (r) CHECK(mesh_same(m, r, CMP_FIELDS | CMP_TAGS, name));
    struct stat st;
    stat(p, &st);
    printf("%-24s %zu tets  write %.2f s  read %.2f s  %.1f MB\n", name, m->n_cells, t1 - t0, t3 - t2,
           (double)st.st_size / 1e6);
    if (read_s) *read_s = t3 - t2;
    cm_mesh_destroy(&r);
    if (!getenv("KEEP")) remove(p); /* KEEP=1 leaves the files for profiling */
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/vtk", argv[2]);
    mkdir(dir, 0777);
    cm_mesh *m = kuhn_mesh(ctx, 55); /* 998,250 tets, 175,616 nodes */
    CHECK(m && m->n_cells > 990000);
    if (m) {
        double t = 0;
        timed(ctx, m, dir, "perf_inline_zlib.vtu", 1, 1, 0, &t);
        /* a loose bound: the machine is shared; the figure printed above is the measurement */
        CHECK_MSG(t < 6.0, "reading a 1M-tet compressed .vtu took %.2f s", t);
        timed(ctx, m, dir, "perf_appended_zlib.vtu", 1, 1, 1, NULL);
        timed(ctx, m, dir, "perf_appended_raw.vtu", 1, 0, 1, NULL);
        timed(ctx, m, dir, "perf_inline_raw.vtu", 1, 0, 0, NULL);
        timed(ctx, m, dir, "perf_binary.vtk", 1, 0, 0, NULL);
    }
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
