/* The morph engine (morph/morpher.c) on gmsh meshes of the surface fixtures: its entry points
 * agree bit for bit (cm_morph_run, cm_morpher_apply, an explicit rebase chain vs --via), a
 * shared factorisation gives what a fresh one gives, morphing a mesh onto the geometry it
 * lies on changes nothing, and a target of another topology is refused. */
#include "cadmorph/morph.h"
#include "surface_fixture.h"

static int same_bits(const double *a, const double *b, size_t n)
{
    return memcmp(a, b, n * sizeof *a) == 0;
}

static double max_diff(const double *a, const double *b, size_t n)
{
    double d = 0;
    for (size_t i = 0; i < n; ++i)
        if (fabs(a[i] - b[i]) > d) d = fabs(a[i] - b[i]);
    return d;
}

/* cm_morph_run's mesh equals the morpher's apply on the same inputs, bit for bit, for both
 * surface methods and both RBF kernels; apply again (shared factorisation) repeats it. */
static void test_entry_points_agree(cm_context *ctx)
{
    cm_cad_model *g0 = fx_model(ctx, "hole_a"), *g1 = fx_model(ctx, "hole_b");
    cm_mesh *m0 = fx_mesh(ctx, "hole_a");
    if (!g0 || !g1 || !m0) return;
    char p0[2048], p1[2048], pm[2048];
    fx_step_path(p0, sizeof p0, "hole_a");
    fx_step_path(p1, sizeof p1, "hole_b");
    fx_mesh_path(pm, sizeof pm, "hole_a");
    size_t n3 = 3 * m0->n_nodes;
    double *xyz = malloc(n3 * sizeof *xyz), *again = malloc(n3 * sizeof *again);
    const cm_surface_method surf[2] = {CM_SURFACE_RBF, CM_SURFACE_PROJECT};
    const cm_warp_method warp[2] = {CM_WARP_RBF, CM_WARP_RBF_BIHARMONIC};
    /* the one-step morph, whatever its cells: the baseline (project) inverts some */
    cm_morph_options one;
    cm_morph_options_init(&one);
    one.steps = 1;
    one.allow_inverted = 1;
    cm_morpher *mp = NULL;
    cm_status s = cm_morpher_create(ctx, g0, m0, &one, &mp);
    CHECK_MSG(s == CM_OK && mp, "%s", cm_context_message(ctx));
    for (int k = 0; mp && k < 3; ++k) {
        cm_morph_options o = one;
        o.method.surface = surf[k == 1];
        o.method.warp.method = warp[k == 2];
        cm_morph_result *r = NULL;
        s = cm_morph_run(ctx, p0, p1, pm, NULL, 0, &o, &r);
        CHECK_MSG(s == CM_OK && r, "%s", cm_context_message(ctx));
        cm_morph_step row;
        s = cm_morpher_apply_method(ctx, mp, g1, &o.method, xyz, &row);
        CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
        if (r) {
            CHECK_MSG(same_bits(r->mesh->xyz, xyz, n3), "method %d: run vs morpher differ by %.3g",
                      k, max_diff(r->mesh->xyz, xyz, n3));
            CHECK(row.inverted == r->steps[0].inverted && row.min_sj == r->steps[0].min_sj);
            CHECK(memcmp(r->sj, cm_morpher_quality(mp), r->mesh->n_cells * sizeof *r->sj) == 0);
        }
        s = cm_morpher_apply_method(ctx, mp, g1, &o.method, again, NULL);
        CHECK(s == CM_OK && same_bits(xyz, again, n3));
        cm_morph_result_destroy(&r);
    }
    /* onto the geometry the mesh lies on: nothing moves (the surface morph is the identity
     * to round-off, the warp of a zero motion is zero) */
    s = cm_morpher_apply(ctx, mp, g0, xyz, NULL);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    double d = max_diff(xyz, m0->xyz, n3) / fx_diagonal(g0);
    CHECK_MSG(d <= 1e-12, "identity morph moved nodes by %.3g x diagonal", d);
    cm_morpher_destroy(&mp);
    cm_morpher_destroy(&mp);
    free(xyz);
    free(again);
    cm_mesh_destroy(&m0);
    cm_cad_destroy(&g0);
    cm_cad_destroy(&g1);
}

/* A relative chain G0 -> G1 -> G0 by hand (apply, rebase, apply) is what cm_morph_run does
 * with --via G1, bit for bit; after it the boundary is back on G0 and the mesh is valid. */
static void test_relative_chain(cm_context *ctx)
{
    cm_cad_model *g0 = fx_model(ctx, "hole_a"), *g1 = fx_model(ctx, "hole_b");
    cm_mesh *m0 = fx_mesh(ctx, "hole_a");
    if (!g0 || !g1 || !m0) return;
    char p0[2048], p1[2048], pm[2048];
    fx_step_path(p0, sizeof p0, "hole_a");
    fx_step_path(p1, sizeof p1, "hole_b");
    fx_mesh_path(pm, sizeof pm, "hole_a");
    size_t n3 = 3 * m0->n_nodes;
    double *xyz = malloc(n3 * sizeof *xyz);
    cm_morpher *mp = NULL;
    cm_morph_step row[2];
    cm_status s = cm_morpher_create(ctx, g0, m0, NULL, &mp);
    if (s >= 0) s = cm_morpher_apply(ctx, mp, g1, xyz, &row[0]);
    if (s >= 0) s = cm_morpher_rebase(ctx, mp, g1, xyz);
    if (s >= 0) s = cm_morpher_apply(ctx, mp, g0, xyz, &row[1]);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    const char *via[1] = {p1};
    cm_morph_result *r = NULL;
    s = cm_morph_run(ctx, p0, p0, pm, via, 1, NULL, &r);
    CHECK_MSG(s == CM_OK && r && r->n_steps == 2, "%s", cm_context_message(ctx));
    if (r) {
        CHECK_MSG(same_bits(r->mesh->xyz, xyz, n3), "chain vs --via differ by %.3g",
                  max_diff(r->mesh->xyz, xyz, n3));
        CHECK(r->steps[1].inverted == 0 && r->steps[0].inverted == 0);
        CHECK_MSG(r->max_dist <= 1e-9 * r->diagonal, "back on G0 to %.3g", r->max_dist);
        printf("relative chain: min SJ %.4f -> %.4f, boundary on G0 to %.3g x diagonal\n",
               r->steps[0].min_sj, r->steps[1].min_sj, r->max_dist / r->diagonal);
    }
    cm_morph_result_destroy(&r);
    cm_morpher_destroy(&mp);
    free(xyz);
    cm_mesh_destroy(&m0);
    cm_cad_destroy(&g0);
    cm_cad_destroy(&g1);
}

/* Another topology is refused with the differences; bad arguments are caller errors. */
static void test_errors(cm_context *ctx)
{
    cm_cad_model *g0 = fx_model(ctx, "hole_a"), *other = fx_model(ctx, "holes2_a");
    cm_mesh *m0 = fx_mesh(ctx, "hole_a");
    if (!g0 || !other || !m0) return;
    double *xyz = malloc(3 * m0->n_nodes * sizeof *xyz);
    cm_morpher *mp = NULL;
    CHECK(cm_morpher_create(ctx, g0, m0, NULL, &mp) == CM_OK);
    cm_status s = cm_morpher_apply(ctx, mp, other, xyz, NULL);
    CHECK_MSG(s == CM_ERR_MISMATCH && strstr(cm_context_message(ctx), "does not correspond"),
              "status %d: %s", (int)s, cm_context_message(ctx));
    CHECK(cm_morpher_apply(ctx, mp, NULL, xyz, NULL) == CM_ERR_ARGUMENT);
    cm_morph_method bad;
    cm_morph_method_init(&bad);
    bad.warp.method = CM_WARP_N_METHODS;
    CHECK(cm_morpher_apply_method(ctx, mp, g0, &bad, xyz, NULL) == CM_ERR_ARGUMENT);
    cm_morpher_destroy(&mp);
    /* a mesh of another model */
    s = cm_morpher_create(ctx, other, m0, NULL, &mp);
    CHECK_MSG(s == CM_ERR_MISMATCH && mp == NULL, "status %d: %s", (int)s,
              cm_context_message(ctx));
    cm_morph_options o;
    cm_morph_options_init(&o);
    /* the guarded morph is the default: adaptive steps, no inverted result unless asked */
    CHECK(o.steps == CM_MORPH_STEPS_AUTO && o.allow_inverted == 0 && o.escalate == 1 &&
          o.min_sj == 0);
    o.steps = -1;
    CHECK(cm_morpher_create(ctx, g0, m0, &o, &mp) == CM_ERR_ARGUMENT && mp == NULL);
    free(xyz);
    cm_mesh_destroy(&m0);
    cm_cad_destroy(&g0);
    cm_cad_destroy(&other);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    fx_data = argv[1];
    fx_work = argv[2];
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_entry_points_agree(ctx);
    test_relative_chain(ctx);
    test_errors(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
