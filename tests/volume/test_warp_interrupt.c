/* Stopping long calls on request (cm_context_interrupt, docs/DESIGN.md "progress"): the
 * warps (rbf dense and iterative, femwarp, lbwarp) and the interior optimisation on a hex
 * O-grid of the built-in bore return CM_ERR_INTERRUPTED when the progress callback asks on
 * its k-th call, create gives no object, and the same warp applied again after an
 * interrupted apply gives the bits of a fresh one; a request made before a call stops it at
 * its first progress point, cm_context_clear drops it; an interrupted optimisation leaves the
 * mesh as it was. */
#include "cadmorph/models.h"
#include "cadmorph/optimize.h"
#include "cadmorph/warp.h"
#include "test_stopper.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A smooth motion of the boundary nodes (zero elsewhere). */
static void boundary_motion(const cm_mesh *m, const cm_mesh_boundary *b, double *disp)
{
    memset(disp, 0, 3 * m->n_nodes * sizeof *disp);
    for (size_t i = 0; i < b->n_nodes; ++i) {
        const double *x = m->xyz + 3 * b->nodes[i];
        double *d = disp + 3 * b->nodes[i];
        d[0] = 0.02 * x[1] * x[2];
        d[1] = 0.03 * sin(x[0]);
        d[2] = 0.01 * x[0] * x[1];
    }
}

static void test_method(cm_context *ctx, stopper *st, const cm_mesh *m, const cm_mesh_boundary *b,
                        cm_warp_method method, cm_rbf_solver solver, const char *name)
{
    cm_warp_options o;
    cm_warp_options_init(&o);
    o.method = method;
    o.solver = solver;
    if (solver == CM_RBF_SOLVER_ITERATIVE) o.tolerance = 1e-8;
    const size_t n3 = 3 * m->n_nodes;
    double *want = malloc(n3 * sizeof *want), *got = malloc(n3 * sizeof *got);

    /* how many progress points a create and an apply pass */
    arm(st, 0);
    cm_warp *w = NULL;
    cm_status s = cm_warp_create(ctx, m, b, NULL, &o, &w);
    CHECK_MSG(s >= 0 && w, "%s: %s", name, cm_context_message(ctx));
    const int create_calls = st->calls;
    arm(st, 0);
    boundary_motion(m, b, want);
    if (w) s = cm_warp_apply(ctx, w, want);
    CHECK_MSG(s >= 0, "%s: %s", name, cm_context_message(ctx));
    const int apply_calls = st->calls;
    CHECK_MSG(create_calls >= 1, "%s: create reported no progress", name);
    printf("%s: %d progress points in create, %d in apply\n", name, create_calls, apply_calls);

    /* create stopped at its first, middle and last point: no object */
    const int at[3] = {1, (create_calls + 1) / 2, create_calls};
    for (int k = 0; k < 3; ++k) {
        cm_warp *w2 = (cm_warp *)1;
        arm(st, at[k]);
        s = cm_warp_create(ctx, m, b, NULL, &o, &w2);
        if (s >= 0 && st->calls < at[k]) {
            /* the local solves report from the caller's thread only, as many times as it
             * takes subdomains: fewer points in this run, the request still pending */
            CHECK(!strcmp(name, "rbf iterative"));
            cm_context_clear(ctx);
            cm_warp_destroy(&w2);
            continue;
        }
        CHECK_MSG(interrupted(ctx, s) && w2 == NULL, "%s: create stopped at %d (%s): status %d, %s",
                  name, at[k], st->stage, (int)s, cm_context_message(ctx));
        CHECK_MSG(st->calls == at[k], "%s: %d more progress calls after the stop at %d", name,
                  st->calls - at[k], at[k]);
    }

    /* apply stopped, then applied again on the same warp: the bits of the first apply */
    for (int k = 1; w && k <= apply_calls; ++k) {
        arm(st, k);
        boundary_motion(m, b, got);
        s = cm_warp_apply(ctx, w, got);
        /* points that report by time (chunks of a sum) may be fewer in this run: then the
         * request is still pending and is dropped */
        CHECK_MSG(interrupted(ctx, s) || (s >= 0 && st->calls < k),
                  "%s: apply stopped at %d (%s): status %d", name, k, st->stage, (int)s);
        cm_context_clear(ctx);
        arm(st, 0);
        boundary_motion(m, b, got);
        s = cm_warp_apply(ctx, w, got);
        /* the iterative RBF solve starts warm from the weights of the last completed solve
         * (cm_rbf_options warm_start), so a repeated apply is the first one's to the solver's
         * tolerance, not its bits (the weights it starts from are those an interrupted
         * apply left untouched); every other warp repeats the bits */
        double diff = 0.0, range = 0.0;
        for (size_t i = 0; i < n3; ++i)
            diff = fmax(diff, fabs(got[i] - want[i])), range = fmax(range, fabs(want[i]));
        const int same = !strcmp(name, "rbf iterative") ? diff <= 1e-8 * range
                                                        : !memcmp(got, want, n3 * sizeof *got);
        CHECK_MSG(s >= 0 && same, "%s: apply after an interrupted one differs (status %d, by "
                  "%.3g of %.3g)", name, (int)s, diff, range);
    }

    /* asked before the call: stopped at the first point; cleared: runs */
    arm(st, 0);
    cm_context_interrupt(ctx);
    cm_warp *w3 = NULL;
    s = cm_warp_create(ctx, m, b, NULL, &o, &w3);
    CHECK_MSG(interrupted(ctx, s) && !w3 && st->calls == 1, "%s: early request: status %d, %d calls",
              name, (int)s, st->calls);
    cm_context_interrupt(ctx);
    cm_context_clear(ctx);
    s = cm_warp_create(ctx, m, b, NULL, &o, &w3);
    CHECK_MSG(s >= 0 && w3, "%s: after cm_context_clear: %s", name, cm_context_message(ctx));
    if (w3) {
        boundary_motion(m, b, got);
        s = cm_warp_apply(ctx, w3, got);
        CHECK_MSG(s >= 0 && !memcmp(got, want, n3 * sizeof *got), "%s: fresh warp differs", name);
    }
    cm_warp_destroy(&w3);
    cm_warp_destroy(&w);
    free(want);
    free(got);
}

/* Interior nodes pushed about: the optimiser has sweeps to do; stopped, the mesh is as given. */
static void test_optimize(cm_context *ctx, stopper *st, const cm_mesh *m0, const cm_mesh_boundary *b)
{
    cm_mesh *m = NULL;
    if (cm_mesh_copy(ctx, m0, &m) < 0) return;
    unsigned char *fixed = calloc(m->n_nodes, 1);
    for (size_t i = 0; i < b->n_nodes; ++i) fixed[b->nodes[i]] = 1;
    uint64_t seed = 12345;
    for (size_t v = 0; v < m->n_nodes; ++v) {
        if (fixed[v]) continue;
        for (int d = 0; d < 3; ++d) {
            seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
            m->xyz[3 * v + d] += 0.12 * ((double)(seed >> 11) / 9007199254740992.0 - 0.5);
        }
    }
    const size_t n3 = 3 * m->n_nodes;
    double *before = malloc(n3 * sizeof *before), *want = malloc(n3 * sizeof *want);
    memcpy(before, m->xyz, n3 * sizeof *before);
    cm_optimize_options o;
    cm_optimize_options_init(&o);
    o.sweeps = 4;
    cm_optimize_stats stats;
    arm(st, 0);
    cm_status s = cm_mesh_optimize(ctx, m, fixed, &o, &stats);
    CHECK_MSG(s >= 0 && stats.moves > 0, "optimize: %s (%zu moves)", cm_context_message(ctx),
              stats.moves);
    const int calls = st->calls;
    printf("optimize: %d progress points, %zu moves in %d sweeps\n", calls, stats.moves,
           stats.sweeps);
    memcpy(want, m->xyz, n3 * sizeof *want);
    const int at[3] = {1, (calls + 1) / 2, calls};
    for (int j = 0; j < 3; ++j) {
        const int k = at[j];
        memcpy(m->xyz, before, n3 * sizeof *before);
        arm(st, k);
        s = cm_mesh_optimize(ctx, m, fixed, &o, &stats);
        /* the points between colours come by time: fewer in this run is no failure */
        if (s >= 0 && st->calls < k) {
            cm_context_clear(ctx);
            continue;
        }
        CHECK_MSG(interrupted(ctx, s), "optimize stopped at %d: status %d", k, (int)s);
        CHECK_MSG(!memcmp(m->xyz, before, n3 * sizeof *before),
                  "optimize stopped at %d left moved nodes", k);
    }
    arm(st, 0);
    s = cm_mesh_optimize(ctx, m, fixed, &o, &stats);
    CHECK_MSG(s >= 0 && !memcmp(m->xyz, want, n3 * sizeof *want),
              "optimize after interrupted ones differs");
    free(before);
    free(want);
    free(fixed);
    cm_mesh_destroy(&m);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    stopper st = {ctx, 0, 0, ""};
    cm_context_set_progress(ctx, on_progress, &st);
    cm_mesh *m = NULL;
    cm_mesh_boundary *b = NULL;
    cm_status s = cm_hexmesh_bore(ctx, 32, 6, 8, 1.05, &m);
    if (s >= 0) s = cm_mesh_boundary_create(ctx, m, &b);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    if (s >= 0) {
        printf("bore O-grid: %zu nodes, %zu boundary nodes\n", m->n_nodes, b->n_nodes);
        double t = cm_wtime();
        test_method(ctx, &st, m, b, CM_WARP_RBF, CM_RBF_SOLVER_DENSE, "rbf dense");
        test_method(ctx, &st, m, b, CM_WARP_RBF, CM_RBF_SOLVER_ITERATIVE, "rbf iterative");
        printf("rbf: %.2f s\n", cm_wtime() - t);
        t = cm_wtime();
        test_method(ctx, &st, m, b, CM_WARP_FEMWARP, CM_RBF_SOLVER_AUTO, "femwarp");
        test_method(ctx, &st, m, b, CM_WARP_LBWARP, CM_RBF_SOLVER_AUTO, "lbwarp");
        printf("femwarp, lbwarp: %.2f s\n", cm_wtime() - t);
        t = cm_wtime();
        test_optimize(ctx, &st, m, b);
        printf("optimize: %.2f s\n", cm_wtime() - t);
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
