/* How the solids of a model meet (cm_cad_check_solids_apart, cm_cad_face_solid,
 * cm_cad_solid_at) on assemblies built with OpenCASCADE by gen_shapes: touching solids are
 * reported as a pair, overlapping and nested ones refused with the reason and the way out. */
#include "cadmorph/cad.h"
#include "test_util.h"

#include <stdio.h>
#include <string.h>

static char work_dir[1024];

static cm_cad_model *read(cm_context *ctx, const char *name)
{
    char p[2048];
    snprintf(p, sizeof p, "%s/cad/%s", work_dir, name);
    cm_cad_model *m = NULL;
    CHECK(cm_cad_read(ctx, p, NULL, &m) == CM_OK);
    return m;
}

static void test_touching(cm_context *ctx)
{
    cm_cad_model *m = read(ctx, "asm_touch.step");
    if (!m) return;
    cm_cad_counts c;
    cm_cad_get_counts(m, &c);
    CHECK(c.solids == 3 && c.faces == 6 + 6 + 3);
    int pair[2] = {7, 7};
    CHECK(cm_cad_check_solids_apart(ctx, m, pair) == CM_OK);
    CHECK(pair[0] == 0 && pair[1] == 1);
    /* without a place for the pair, touching solids are refused naming it */
    CHECK(cm_cad_check_solids_apart(ctx, m, NULL) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "solids 0 and 1 (of 3) touch (share a face)") != NULL);
    int per[3] = {0, 0, 0};
    for (int f = 0; f < c.faces; ++f) {
        int s = -1;
        CHECK(cm_cad_face_solid(ctx, m, f, &s) == CM_OK);
        CHECK(s >= 0 && s < 3);
        if (s >= 0 && s < 3) ++per[s];
    }
    CHECK(per[0] == 6 && per[1] == 6 && per[2] == 3);
    int s = 9;
    CHECK(cm_cad_face_solid(ctx, m, c.faces, &s) == CM_ERR_ARGUMENT);
    const double inside[4][3] = {{0.5, 0.5, 0.5}, {1.5, 0.5, 0.5}, {0.5, 0.5, 1.25}, {3, 3, 3}};
    const int want[4] = {0, 1, 2, -1};
    for (int i = 0; i < 4; ++i) {
        CHECK(cm_cad_solid_at(ctx, m, inside[i], &s) == CM_OK);
        CHECK_MSG(s == want[i], "point %d: solid %d, expected %d", i, s, want[i]);
    }
    /* on the shared face: strictly inside neither */
    const double on[3] = {1, 0.5, 0.5};
    CHECK(cm_cad_solid_at(ctx, m, on, &s) == CM_OK && s == -1);
    cm_cad_destroy(&m);
}

static void test_refused(cm_context *ctx, const char *name, const char *why)
{
    cm_cad_model *m = read(ctx, name);
    if (!m) return;
    int pair[2] = {7, 7};
    CHECK(cm_cad_check_solids_apart(ctx, m, pair) == CM_ERR_UNSUPPORTED);
    const char *msg = cm_context_message(ctx);
    CHECK_MSG(strstr(msg, "solids 0 and 1 (of 2) overlap") && strstr(msg, why) &&
                  strstr(msg, "fuse them") && strstr(msg, "fragment them"),
              "%s: %s", name, msg);
    cm_cad_destroy(&m);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    snprintf(work_dir, sizeof work_dir, "%s", argv[2]);
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_touching(ctx);
    test_refused(ctx, "asm_overlap.step", "they cross: common volume 0.32,");
    test_refused(ctx, "asm_nested.step", "one is inside the other: common volume 1,");
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
