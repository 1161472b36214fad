/* The cost of design velocities against one morph (docs/DESIGN.md, "Gradients"), in one
 * process, side by side: the morph of M0 onto one variant from scratch (morpher create:
 * sampling and classification; apply: surface morph, factorisation, warp apply, quality,
 * distance to G') against the velocities of every parameter of a design table from scratch
 * (create, then cm_design_velocity: two surface morphs per central parameter, the
 * factorisation once, one forward product each), and the velocities after the morph on the
 * same morpher (the factorisation shared).
 * usage: bench_design_velocity G0.step M0 T.csv TARGET.step [threads] [repeats]
 * Each of the three is run `repeats` times (default 3), alternating, and the fastest run of
 * each is reported (a shared machine slows single runs). One line of key=value pairs:
 * benchmarks/gradients/bench_design_velocity.md. */
#include "blas_reexec.h"
#include "cadmorph/study.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double cpu(void) { return (double)clock() / CLOCKS_PER_SEC; }

static int fail(cm_context *ctx, const char *what)
{
    fprintf(stderr, "bench_design_velocity: %s: %s\n", what, cm_context_message(ctx));
    return 1;
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core, as cadmorph */
    if (argc < 5) {
        fprintf(stderr, "usage: bench_design_velocity G0.step M0 T.csv TARGET.step [threads]\n");
        return 1;
    }
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, argc > 5 ? atoi(argv[5]) : 0);
    cm_cad_model *g0 = NULL, *g1 = NULL;
    cm_mesh *m0 = NULL;
    cm_design_table *t = NULL;
    size_t base = 0;
    if (cm_cad_read(ctx, argv[1], NULL, &g0) < 0) return fail(ctx, argv[1]);
    if (cm_mesh_read(ctx, argv[2], &m0) < 0) return fail(ctx, argv[2]);
    if (cm_design_table_read(ctx, argv[3], &t) < 0 || cm_design_table_find(ctx, t, argv[1], &base) < 0)
        return fail(ctx, argv[3]);
    if (cm_cad_read(ctx, argv[4], NULL, &g1) < 0 || cm_cad_match(ctx, g0, g1, 5, NULL) < 0)
        return fail(ctx, argv[4]);
    double *xyz = malloc(3 * m0->n_nodes * sizeof *xyz);
    cm_morph_options o;
    cm_morph_options_init(&o);
    o.steps = 1; /* the one-increment morph, whose derivative the velocities are (morph.h) */

    const int repeats = argc > 6 && atoi(argv[6]) > 0 ? atoi(argv[6]) : 3;
    double w_create = INFINITY, w_morph = INFINITY, c_morph = INFINITY, solve = 0;
    double w_after = INFINITY, c_after = INFINITY, w_vel = INFINITY, c_vel = INFINITY;
    cm_morpher *mp = NULL;
    cm_design_velocities *v = NULL;
    size_t np = 0;
    for (int rep = 0; rep < repeats; ++rep) {
        /* one morph from scratch */
        double w0 = cm_wtime(), c0 = cpu();
        if (cm_morpher_create(ctx, g0, m0, &o, &mp) < 0) return fail(ctx, "create");
        const double wc = cm_wtime() - w0;
        cm_morph_step row;
        if (cm_morpher_apply(ctx, mp, g1, xyz, &row) < 0) return fail(ctx, "apply");
        if (cm_wtime() - w0 < w_morph)
            w_morph = cm_wtime() - w0, w_create = wc, solve = row.t_volume_solve;
        c_morph = fmin(c_morph, cpu() - c0);
        /* the velocities after it: the factorisation is the morph's */
        w0 = cm_wtime(), c0 = cpu();
        if (cm_design_velocity(ctx, mp, g0, t, base, NULL, 1, &v) < 0) return fail(ctx, "velocity");
        w_after = fmin(w_after, cm_wtime() - w0), c_after = fmin(c_after, cpu() - c0);
        np = 0;
        for (size_t j = 0; j < v->n_parameters; ++j)
            np += v->diff[j].scheme != CM_DESIGN_NONE;
        cm_design_velocities_destroy(&v);
        cm_morpher_destroy(&mp);
        /* the velocities from scratch (the last run's morpher and stage times are kept) */
        w0 = cm_wtime(), c0 = cpu();
        if (cm_morpher_create(ctx, g0, m0, &o, &mp) < 0) return fail(ctx, "create");
        if (cm_design_velocity(ctx, mp, g0, t, base, NULL, 1, &v) < 0) return fail(ctx, "velocity");
        w_vel = fmin(w_vel, cm_wtime() - w0), c_vel = fmin(c_vel, cpu() - c0);
        if (rep + 1 < repeats) {
            cm_design_velocities_destroy(&v);
            cm_morpher_destroy(&mp);
        }
    }
    const cm_morpher_info *info = cm_morpher_get_info(mp);
    printf("nodes=%zu boundary_nodes=%zu P=%zu surface_morphs=%zu morph_s=%.3f morph_cpu=%.3f "
           "create_s=%.3f solve_s=%.3f velocities_s=%.3f velocities_cpu=%.3f ratio=%.3f "
           "target=%.2f after_morph_s=%.3f after_cpu=%.3f after_ratio=%.3f read_s=%.3f "
           "surface_s=%.3f warp_s=%.3f\n",
           info->nodes, info->boundary_nodes, np, v->surface_morphs, w_morph, c_morph, w_create,
           solve, w_vel, c_vel, w_vel / w_morph, 1 + 0.3 * (double)np, w_after,
           c_after, w_after / w_morph, v->t_read, v->t_surface, v->t_warp);
    cm_design_velocities_destroy(&v);
    cm_morpher_destroy(&mp);
    free(xyz);
    cm_design_table_destroy(&t);
    cm_mesh_destroy(&m0);
    cm_cad_destroy(&g1);
    cm_cad_destroy(&g0);
    cm_context_destroy(&ctx);
    return 0;
}
