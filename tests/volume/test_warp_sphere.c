/* The warp of a real gmsh mesh (sphere in a box, made by warp_sphere.py setup): reads the mesh
 * and the sphere's displacements, warps as `cadmorph warp` does (boundary and listed nodes
 * constrained) and writes every node's displacement for warp_sphere.py compare (scipy). */
#include "cadmorph/warp.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_warp_sphere DATA_DIR WORK_DIR\n");
        return 2;
    }
    char msh[4096], csv[4096], out[4096];
    snprintf(msh, sizeof msh, "%s/warp/sphere.msh", argv[2]);
    snprintf(csv, sizeof csv, "%s/warp/sphere_disp.csv", argv[2]);
    snprintf(out, sizeof out, "%s/warp/sphere_warp.csv", argv[2]);
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_mesh *m = NULL;
    cm_mesh_boundary *b = NULL;
    cm_warp *w = NULL;
    double *d = NULL;
    unsigned char *mask = NULL;
    cm_status s = cm_mesh_read(ctx, msh, &m);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    if (s >= 0) {
        d = malloc(3 * m->n_nodes * sizeof *d);
        mask = malloc(m->n_nodes);
        s = cm_warp_read_displacements(ctx, csv, m->n_nodes, d, mask);
        CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    }
    if (s >= 0) {
        s = cm_mesh_boundary_create(ctx, m, &b);
        CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    }
    if (s >= 0) {
        CHECK(b->n_components == 1);
        for (size_t i = 0; i < b->n_nodes; ++i)
            mask[b->nodes[i]] = 1;
        double t0 = cm_wtime();
        s = cm_warp_create(ctx, m, b, mask, NULL, &w);
        double t1 = cm_wtime();
        if (s >= 0) s = cm_warp_apply(ctx, w, d);
        CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
        printf("sphere: %zu nodes, %zu boundary nodes: create %.3f s, apply %.3f s\n", m->n_nodes,
               b->n_nodes, t1 - t0, cm_wtime() - t1);
    }
    if (s >= 0) {
        FILE *f = fopen(out, "w");
        CHECK(f != NULL);
        size_t bad = 0;
        if (f) {
            fprintf(f, "node,dx,dy,dz\n");
            for (size_t v = 0; v < m->n_nodes; ++v) {
                bad += !isfinite(d[3 * v]) || !isfinite(d[3 * v + 1]) || !isfinite(d[3 * v + 2]);
                fprintf(f, "%zu,%.17g,%.17g,%.17g\n", v, d[3 * v], d[3 * v + 1], d[3 * v + 2]);
            }
            CHECK(fclose(f) == 0);
        }
        CHECK(bad == 0);
    }
    cm_warp_destroy(&w);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
    free(d);
    free(mask);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
