/* Example: one mesh of G0 morphed onto a family of target geometries (a design table), each
 * absolute from G0. The morpher classifies the mesh on G0 and factorises the interior warp
 * once; every target then costs a surface morph and an evaluation. The morpher borrows the
 * targets: they stay alive until it is destroyed (morph.h).
 *
 *   morph_family G0.step M0.vtu OUTDIR G1.step [G2.step ...]   -> OUTDIR/variant_<i>.vtu
 */
#include <cadmorph/morph.h>

#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    if (argc < 5) {
        fprintf(stderr, "usage: %s G0.step M0 OUTDIR G1.step [G2.step ...]\n", argv[0]);
        return 1;
    }
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 4;
    cm_cad_model *g0 = NULL;
    cm_mesh *m0 = NULL, *out = NULL;
    cm_morpher *morpher = NULL;
    double *xyz = NULL;
    int failed = 0, n_targets = argc - 4;
    cm_cad_model **g = calloc((size_t)n_targets, sizeof *g);

    cm_status s = cm_cad_read(ctx, argv[1], NULL, &g0);
    if (s >= 0) s = cm_mesh_read(ctx, argv[2], &m0);
    if (s >= 0) s = cm_morpher_create(ctx, g0, m0, NULL, &morpher);
    if (s >= 0) s = cm_mesh_copy(ctx, m0, &out);
    if (s >= 0 && (!g || !(xyz = malloc(3 * m0->n_nodes * sizeof *xyz)))) s = CM_ERR_NOMEM;
    if (s < 0) {
        fprintf(stderr, "morph_family: %s\n", cm_context_message(ctx));
        failed = 1;
    }
    for (int i = 0; s >= 0 && i < n_targets; ++i) {
        /* a target that does not correspond to G0 is reported and skipped */
        cm_morph_step row;
        cm_status t = cm_cad_read(ctx, argv[4 + i], NULL, &g[i]);
        if (t >= 0) t = cm_morpher_apply(ctx, morpher, g[i], xyz, &row);
        if (t >= 0) {
            char path[4096];
            snprintf(path, sizeof path, "%s/variant_%d.vtu", argv[3], i + 1);
            for (size_t k = 0; k < 3 * m0->n_nodes; ++k)
                out->xyz[k] = xyz[k];
            t = cm_mesh_write(ctx, out, path, NULL);
        }
        if (t < 0) {
            printf("%s: %s\n", argv[4 + i], cm_context_message(ctx));
            failed = 1;
        } else {
            printf("%s: min scaled Jacobian %.4f, %zu inverted, boundary %.3g from it, "
                   "solve %.3f s, evaluation %.3f s\n",
                   argv[4 + i], row.min_sj, row.inverted, row.max_dist, row.t_volume_solve,
                   row.t_evaluation);
        }
    }
    free(xyz);
    cm_morpher_destroy(&morpher);
    for (int i = 0; g && i < n_targets; ++i)
        cm_cad_destroy(&g[i]);
    free(g);
    cm_mesh_destroy(&out);
    cm_mesh_destroy(&m0);
    cm_cad_destroy(&g0);
    cm_context_destroy(&ctx);
    return failed ? 2 : 0;
}
