/* Example: morph a volume mesh of G0.step onto G1.step (same topology, other dimensions) and
 * write it with its quality fields - what `cadmorph morph` does, through the library.
 *
 *   morph_mesh G0.step G1.step M0.vtu M1.vtu
 */
#include <cadmorph/morph.h>
#include <cadmorph/version.h>

#include <stdio.h>

int main(int argc, char **argv)
{
    if (argc != 5) {
        fprintf(stderr, "usage: %s G0.step G1.step M0 M1\n", argv[0]);
        return 1;
    }
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 4;

    cm_morph_options opt;
    cm_morph_options_init(&opt); /* RBF-S surface morph, triharmonic interior warp */
    cm_morph_result *r = NULL;
    cm_status s = cm_morph_run(ctx, argv[1], argv[2], argv[3], NULL, 0, &opt, &r);
    if (s >= 0) s = cm_mesh_write(ctx, r->mesh, argv[4], NULL);
    if (s < 0) {
        fprintf(stderr, "morph_mesh: %s\n", cm_context_message(ctx));
    } else {
        const cm_morph_step *last = &r->steps[r->n_steps - 1];
        printf("cadmorph %s: %zu cells, min scaled Jacobian %.4f, %zu inverted, boundary "
               "%.3g from G1 (diagonal %.3g)\n",
               cm_version(), last->cells, last->min_sj, last->inverted, r->max_dist,
               r->diagonal);
    }
    cm_morph_result_destroy(&r);
    cm_context_destroy(&ctx);
    return s < 0 ? 2 : 0;
}
