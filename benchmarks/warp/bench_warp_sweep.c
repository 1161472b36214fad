/* Staten-style comparison [SKM11] of the interior-warp methods on the benchmark models,
 * through the morph engine: M0 (a mesh of G(0)) onto G(k/steps), k = 1..steps, absolute
 * (one morpher, each method factorised once) and relative (rebased after every step). Every
 * method except "rbf" gets the CAD-aware surface morph (RBF-S), so the volume methods are
 * compared on the same boundary; "rbf" is the RBF of [SKM11]: closest-point surface + RBF.
 * usage: bench_warp_sweep MODEL M0.msh STEPS WORK [methods] [threads] [modes]
 *   methods: comma list of rbf-s, rbf, rbf-s-biharmonic, femwarp, lbwarp, simplex
 *   modes: absolute,relative (default both)
 * One line per step: key=value pairs (benchmarks/warp/bench_warp_sweep_table.py). */
#include "blas_reexec.h"
#include "cadmorph/cad.h"
#include "cadmorph/morph.h"
#include "cadmorph/models.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int parse_method(const char *name, cm_morph_method *m)
{
    cm_morph_method_init(m);
    if (!strcmp(name, "rbf-s")) return 0;
    if (!strcmp(name, "rbf")) {
        m->surface = CM_SURFACE_PROJECT;
        return 0;
    }
    /* rbf-s-<kernel>: the surface morph with the RBF warp of that kernel */
    char warp[64];
    snprintf(warp, sizeof warp, "%s%s", strncmp(name, "rbf-s-", 6) ? "" : "rbf-",
             strncmp(name, "rbf-s-", 6) ? name : name + 6);
    int w = cm_warp_method_from_name(warp);
    if (w < 0) return -1;
    m->warp.method = (cm_warp_method)w;
    return 0;
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core, as cadmorph */
    if (argc < 5) {
        fprintf(stderr,
                "usage: bench_warp_sweep MODEL M0.msh STEPS WORK [methods] [threads] [modes]\n");
        return 1;
    }
    const char *model = argv[1], *work = argv[4];
    int steps = atoi(argv[3]), threads = argc > 6 ? atoi(argv[6]) : 2;
    char methods[256];
    snprintf(methods, sizeof methods, "%s", argc > 5 ? argv[5] : "rbf-s,femwarp,lbwarp,simplex");
    const char *modes = argc > 7 ? argv[7] : "absolute,relative";
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_context_set_threads(ctx, threads);
    cm_cad_model **g = calloc((size_t)steps + 1, sizeof *g);
    cm_mesh *m0 = NULL;
    cm_status s = cm_mesh_read(ctx, argv[2], &m0);
    for (int k = 0; k <= steps && s >= 0; ++k) {
        char path[4096];
        snprintf(path, sizeof path, "%s/%s_G_%.4f.step", work, model, (double)k / steps);
        if (cm_model_write_step(ctx, model, (double)k / steps, path) < 0) {
            fprintf(stderr, "bench_warp_sweep: %s\n", cm_context_message(ctx));
            return 2;
        }
        s = cm_cad_read(ctx, path, NULL, &g[k]);
    }
    if (s < 0) {
        fprintf(stderr, "bench_warp_sweep: %s\n", cm_context_message(ctx));
        return 2;
    }
    double *xyz = malloc(3 * m0->n_nodes * sizeof *xyz);
    int rc = 0, nm = 0;
    const char *name[16];
    cm_morph_method method[16];
    for (char *tok = strtok(methods, ","); tok && nm < 16; tok = strtok(NULL, ",")) {
        if (parse_method(tok, &method[nm]) < 0) {
            fprintf(stderr, "bench_warp_sweep: unknown method '%s'\n", tok);
            return 1;
        }
        name[nm++] = tok;
    }
    /* steps outer, methods inner: the morpher keeps the locator of the last target, so G(t)
     * is sampled once per step for all methods (absolute); relative: one morpher per method */
    for (int rel = 0; rel < 2; ++rel) {
        if (!strstr(modes, rel ? "relative" : "absolute")) continue;
        cm_morpher *mp[16] = {NULL};
        int alive[16];
        /* the sweeps of [SKM11]: the plain one-step morph, whose inverted cells are measured */
        cm_morph_options mo;
        cm_morph_options_init(&mo);
        mo.steps = 1;
        mo.allow_inverted = 1;
        for (int i = 0; i < nm; ++i) {
            alive[i] = (rel || i == 0) ? cm_morpher_create(ctx, g[0], m0, &mo, &mp[i]) >= 0 : 1;
            if (!alive[i]) fprintf(stderr, "bench_warp_sweep: %s\n", cm_context_message(ctx));
        }
        for (int k = 1; k <= steps; ++k)
            for (int i = 0; i < nm; ++i) {
                cm_morpher *p = mp[rel ? i : 0];
                if (!alive[i] || !p) continue;
                cm_morph_step row;
                memset(&row, 0, sizeof row);
                s = cm_morpher_apply_method(ctx, p, g[k], &method[i], xyz, &row);
                if (s >= 0) {
                    printf("model=%s mesh=%s mode=%s method=%s step=%d t=%.2f min_sj=%.4f "
                           "inverted=%zu cells=%zu surface_s=%.4f solve_s=%.4f evaluate_s=%.4f "
                           "max_dist=%.3g\n",
                           model, argv[2], rel ? "relative" : "absolute", name[i], k,
                           (double)k / steps, row.min_sj, row.inverted, row.cells, row.t_surface,
                           row.t_volume_solve, row.t_evaluation, row.max_dist);
                    fflush(stdout);
                    if (rel) s = cm_morpher_rebase(ctx, p, g[k], xyz);
                }
                if (s < 0) {
                    /* a series can stop (a collapsed mesh makes the next warp singular) */
                    printf("model=%s mesh=%s mode=%s method=%s step=%d stopped=\"%s\"\n", model,
                           argv[2], rel ? "relative" : "absolute", name[i], k,
                           cm_context_message(ctx));
                    alive[i] = 0;
                    rc = 3;
                }
            }
        for (int i = 0; i < nm; ++i)
            cm_morpher_destroy(&mp[i]);
    }
    free(xyz);
    for (int k = 0; k <= steps; ++k)
        cm_cad_destroy(&g[k]);
    free(g);
    cm_mesh_destroy(&m0);
    cm_context_destroy(&ctx);
    return rc;
}
