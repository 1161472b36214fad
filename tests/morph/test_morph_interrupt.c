/* Stopping the morph engine on request (cm_context_interrupt, docs/DESIGN.md "progress") on
 * the built-in bore (its STEP at t = 0 and 1, its hex O-grid): cm_morpher_create stopped at a
 * progress point gives no morpher; cm_morpher_apply stopped at its first, middle and last
 * point returns CM_ERR_INTERRUPTED and the same morpher then applies to the bits of an
 * uninterrupted apply and of a fresh morpher; a request made before the call stops it at the
 * first point; cm_context_clear drops one; a rebase stopped leaves the morpher refusing to
 * apply until it is re-based.
 * usage: test_morph_interrupt DATA WORK */
#include "cadmorph/models.h"
#include "cadmorph/morph.h"
#include "test_stopper.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

static void test_morpher(cm_context *ctx, stopper *st, const cm_cad_model *g0,
                         const cm_cad_model *g1, const cm_mesh *m)
{
    const size_t n3 = 3 * m->n_nodes;
    double *want = malloc(n3 * sizeof *want), *got = malloc(n3 * sizeof *got);
    cm_morpher *mp = NULL;
    arm(st, 0);
    cm_status s = cm_morpher_create(ctx, g0, m, NULL, &mp);
    CHECK_MSG(s >= 0 && mp, "create: %s", cm_context_message(ctx));
    const int create_calls = st->calls;
    if (mp) s = cm_morpher_apply(ctx, mp, g1, want, NULL);
    CHECK_MSG(s >= 0, "apply: %s", cm_context_message(ctx));
    /* the points of an apply onto a target already sampled (the first one samples it) */
    arm(st, 0);
    if (mp) s = cm_morpher_apply(ctx, mp, g1, got, NULL);
    CHECK_MSG(s >= 0 && !memcmp(got, want, n3 * sizeof *got), "second apply: %s",
              cm_context_message(ctx));
    const int apply_calls = st->calls;
    printf("morpher: %d progress points in create, %d in apply\n", create_calls, apply_calls);
    CHECK(create_calls >= 2 && apply_calls >= 3);

    const int cat[3] = {1, (create_calls + 1) / 2, create_calls};
    for (int k = 0; k < 3; ++k) {
        cm_morpher *m2 = (cm_morpher *)1;
        arm(st, cat[k]);
        s = cm_morpher_create(ctx, g0, m, NULL, &m2);
        if (s >= 0 && st->calls < cat[k]) { /* points by time: fewer in this run */
            cm_context_clear(ctx);
            cm_morpher_destroy(&m2);
            continue;
        }
        CHECK_MSG(interrupted(ctx, s) && !m2, "create stopped at %d (%s): status %d, %s", cat[k],
                  st->stage, (int)s, cm_context_message(ctx));
        CHECK_MSG(st->calls == cat[k], "%d progress calls after the stop", st->calls - cat[k]);
    }

    const int aat[3] = {1, (apply_calls + 1) / 2, apply_calls};
    for (int k = 0; mp && k < 3; ++k) {
        arm(st, aat[k]);
        s = cm_morpher_apply(ctx, mp, g1, got, NULL);
        if (s >= 0 && st->calls < aat[k]) {
            cm_context_clear(ctx);
            continue;
        }
        CHECK_MSG(interrupted(ctx, s), "apply stopped at %d (%s): status %d, %s", aat[k],
                  st->stage, (int)s, cm_context_message(ctx));
        CHECK_MSG(st->calls == aat[k], "%d progress calls after the stop", st->calls - aat[k]);
        printf("apply stopped at point %d (%s): %s\n", aat[k], st->stage, cm_context_message(ctx));
        arm(st, 0);
        s = cm_morpher_apply(ctx, mp, g1, got, NULL);
        CHECK_MSG(s >= 0 && !memcmp(got, want, n3 * sizeof *got),
                  "apply after one stopped at %d differs (status %d)", aat[k], (int)s);
    }

    /* asked before the call: it stops at its first point and leaves nothing pending */
    arm(st, 0);
    cm_context_interrupt(ctx);
    s = mp ? cm_morpher_apply(ctx, mp, g1, got, NULL) : CM_ERR_ARGUMENT;
    CHECK_MSG(interrupted(ctx, s) && st->calls == 1, "early request: status %d, %d calls", (int)s,
              st->calls);
    cm_context_interrupt(ctx);
    cm_context_clear(ctx);
    cm_morpher *fresh = NULL;
    s = cm_morpher_create(ctx, g0, m, NULL, &fresh);
    if (s >= 0) s = cm_morpher_apply(ctx, fresh, g1, got, NULL);
    CHECK_MSG(s >= 0 && !memcmp(got, want, n3 * sizeof *got), "fresh morpher: status %d, %s",
              (int)s, cm_context_message(ctx));
    cm_morpher_destroy(&fresh);
    cm_morpher_destroy(&mp);
    free(want);
    free(got);
}

/* A rebase stopped at its first point: apply refuses until a rebase succeeds, then the chain
 * G0 -> G1 -> G0 gives the bits of an uninterrupted one. */
static void test_rebase(cm_context *ctx, stopper *st, const cm_cad_model *g0,
                        const cm_cad_model *g1, const cm_mesh *m)
{
    const size_t n3 = 3 * m->n_nodes;
    double *mid = malloc(n3 * sizeof *mid), *want = malloc(n3 * sizeof *want);
    double *got = malloc(n3 * sizeof *got);
    cm_morpher *a = NULL, *b = NULL;
    arm(st, 0);
    cm_status s = cm_morpher_create(ctx, g0, m, NULL, &a);
    if (s >= 0) s = cm_morpher_create(ctx, g0, m, NULL, &b);
    if (s >= 0) s = cm_morpher_apply(ctx, a, g1, mid, NULL);
    if (s >= 0) s = cm_morpher_rebase(ctx, a, g1, mid);
    if (s >= 0) s = cm_morpher_apply(ctx, a, g0, want, NULL);
    if (s >= 0) s = cm_morpher_apply(ctx, b, g1, mid, NULL);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    if (s >= 0) {
        arm(st, 1);
        s = cm_morpher_rebase(ctx, b, g1, mid);
        CHECK_MSG(interrupted(ctx, s), "rebase stopped at 1: status %d", (int)s);
        arm(st, 0);
        s = cm_morpher_apply(ctx, b, g0, got, NULL);
        CHECK_MSG(s == CM_ERR_ARGUMENT, "apply after a stopped rebase: status %d", (int)s);
        s = cm_morpher_rebase(ctx, b, g1, mid);
        if (s >= 0) s = cm_morpher_apply(ctx, b, g0, got, NULL);
        CHECK_MSG(s >= 0 && !memcmp(got, want, n3 * sizeof *got),
                  "chain after a stopped rebase differs: status %d, %s", (int)s,
                  cm_context_message(ctx));
    }
    cm_morpher_destroy(&a);
    cm_morpher_destroy(&b);
    free(mid);
    free(want);
    free(got);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s DATA WORK\n", argv[0]);
        return 2;
    }
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    stopper st = {ctx, 0, 0, ""};
    char p0[4096], p1[4096];
    snprintf(p0, sizeof p0, "%s/interrupt_bore_0.step", argv[2]);
    snprintf(p1, sizeof p1, "%s/interrupt_bore_1.step", argv[2]);
    cm_cad_model *g0 = NULL, *g1 = NULL;
    cm_mesh *m = NULL;
    cm_status s = cm_model_write_step(ctx, "bore", 0, p0);
    if (s >= 0) s = cm_model_write_step(ctx, "bore", 1, p1);
    if (s >= 0) s = cm_cad_read(ctx, p0, NULL, &g0);
    if (s >= 0) s = cm_cad_read(ctx, p1, NULL, &g1);
    if (s >= 0) s = cm_hexmesh_bore(ctx, 32, 4, 6, 1.05, &m);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    cm_context_set_progress(ctx, on_progress, &st);
    if (s >= 0) test_morpher(ctx, &st, g0, g1, m);
    if (s >= 0) test_rebase(ctx, &st, g0, g1, m);
    cm_mesh_destroy(&m);
    cm_cad_destroy(&g0);
    cm_cad_destroy(&g1);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
