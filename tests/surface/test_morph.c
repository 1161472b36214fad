/* The morph pipeline (surface/morph_pipeline.c) end to end on gmsh meshes of the STEP pairs:
 * identity keeps the mesh, a rigid motion of G moves it rigidly, the edits of a bore, a plate
 * with two holes, a cylinder and a sphere give no inverted cell, boundary nodes on G', and
 * the RBF surface morph at least as good as closest-point projection; increments agree.
 * Also the bore pair of tests/data/cad (tests/data/cad/gen_fixtures.py). */
#include "surface_fixture.h"
#include "cadmorph/morph.h"

static cm_morph_result *run(cm_context *ctx, const char *from, const char *to, const char *mesh,
                            cm_surface_method method, int steps)
{
    char g0[2048], g1[2048], m[2048];
    fx_step_path(g0, sizeof g0, from);
    fx_step_path(g1, sizeof g1, to);
    fx_mesh_path(m, sizeof m, mesh);
    cm_morph_options o;
    cm_morph_options_init(&o);
    o.method.surface = method;
    o.steps = steps;
    o.allow_inverted = 1; /* the baseline's inverted cells are measured, not refused */
    cm_morph_result *r = NULL;
    cm_status s = cm_morph_run(ctx, g0, g1, m, NULL, 0, &o, &r);
    CHECK_MSG(s == CM_OK, "%s -> %s: %s", from, to, cm_context_message(ctx));
    if (s < 0) return NULL;
    CHECK(r && r->mesh && r->sj && r->n_steps == steps);
    CHECK(cm_mesh_find_field(r->mesh, "displacement", CM_FIELD_NODE) != NULL);
    return r;
}

/* Largest distance of the morphed nodes from motion(M0 nodes), and of the displacement field
 * from the nodes' motion. */
static double motion_error(cm_context *ctx, const char *mesh, const cm_morph_result *r,
                           void (*motion)(const double *, double *), double *field_error)
{
    cm_mesh *m0 = fx_mesh(ctx, mesh);
    if (!m0) return INFINITY;
    CHECK(m0->n_nodes == r->mesh->n_nodes);
    const cm_field *f = cm_mesh_find_field(r->mesh, "displacement", CM_FIELD_NODE);
    double worst = 0, fe = 0;
    for (size_t i = 0; i < m0->n_nodes && i < r->mesh->n_nodes; ++i) {
        double y[3], *p = r->mesh->xyz + 3 * i, *x = m0->xyz + 3 * i;
        if (motion)
            motion(x, y);
        else
            memcpy(y, x, sizeof y);
        double d = fx_dist(y, p);
        if (d > worst) worst = d;
        if (f) {
            double q[3] = {x[0] + f->data[3 * i], x[1] + f->data[3 * i + 1],
                           x[2] + f->data[3 * i + 2]};
            double e = fx_dist(q, p);
            if (e > fe) fe = e;
        }
    }
    cm_mesh_destroy(&m0);
    *field_error = fe;
    return worst;
}

static void test_identity_and_rigid(cm_context *ctx)
{
    cm_morph_result *r = run(ctx, "hole_a", "hole_a", "hole_a", CM_SURFACE_RBF, 1);
    if (r) {
        double fe, e = motion_error(ctx, "hole_a", r, NULL, &fe);
        CHECK_MSG(e <= 1e-12 * r->diagonal, "identity moved a node by %g", e);
        CHECK(fe <= 1e-12 * r->diagonal);
    }
    cm_morph_result_destroy(&r);
    CHECK(r == NULL);
    r = run(ctx, "hole_a", "hole_rigid", "hole_a", CM_SURFACE_RBF, 1);
    if (r) {
        double fe, e = motion_error(ctx, "hole_a", r, fx_rigid, &fe);
        CHECK_MSG(e <= 1e-9 * r->diagonal, "rigid motion: a node is %g off (diagonal %g)", e,
                  r->diagonal);
        CHECK(fe <= 1e-12 * r->diagonal);
        CHECK(r->steps[0].inverted == 0);
    }
    cm_morph_result_destroy(&r);
    /* an affine edit is reproduced in the interior too (linear polynomial of both warps) */
    r = run(ctx, "cyl_a", "cyl_b", "cyl_a", CM_SURFACE_RBF, 1);
    if (r) {
        double fe, e = motion_error(ctx, "cyl_a", r, fx_cylinder, &fe);
        CHECK_MSG(e <= 1e-9 * r->diagonal, "cylinder scaling: a node is %g off", e);
    }
    cm_morph_result_destroy(&r);
}

static void test_edit(cm_context *ctx, const char *from, const char *to, const char *mesh)
{
    cm_morph_result *rbf = run(ctx, from, to, mesh, CM_SURFACE_RBF, 1);
    cm_morph_result *prj = run(ctx, from, to, mesh, CM_SURFACE_PROJECT, 1);
    cm_morph_result *inc = run(ctx, from, to, mesh, CM_SURFACE_RBF, 3);
    if (rbf && prj && inc) {
        const cm_morph_step *a = &rbf->steps[0], *b = &prj->steps[0], *c = &inc->steps[2];
        CHECK_MSG(a->inverted == 0, "%s -> %s: %zu inverted", from, to, a->inverted);
        CHECK_MSG(rbf->max_dist <= 1e-9 * rbf->diagonal, "%s -> %s: boundary %g off G'", from, to,
                  rbf->max_dist);
        CHECK(prj->max_dist <= 1e-9 * prj->diagonal);
        CHECK_MSG(a->min_sj >= b->min_sj, "%s -> %s: rbf min SJ %g < project %g", from, to,
                  a->min_sj, b->min_sj);
        CHECK(rbf->surface.outside == 0 && rbf->surface.faces_warped > 0);
        CHECK(rbf->counts[0] > 0 && rbf->counts[1] > 0 && rbf->counts[2] > 0);
        /* increments end on the same boundary, with no inverted cell on the way */
        CHECK(c->inverted == 0 && inc->max_dist <= 1e-9 * inc->diagonal);
        for (int k = 0; k < 3; ++k) {
            CHECK(inc->steps[k].step == k + 1 && inc->steps[k].inverted == 0);
            CHECK(inc->steps[k].t_volume_solve >= 0 && inc->steps[k].t_evaluation >= 0);
        }
        CHECK(inc->steps[0].max_dist > inc->steps[2].max_dist);
        cm_mesh_boundary *bd = NULL;
        CHECK(cm_mesh_boundary_create(ctx, rbf->mesh, &bd) == CM_OK);
        double worst = 0;
        for (size_t i = 0; bd && i < bd->n_nodes; ++i) {
            double d =
                fx_dist(rbf->mesh->xyz + 3 * bd->nodes[i], inc->mesh->xyz + 3 * bd->nodes[i]);
            if (d > worst) worst = d;
        }
        CHECK_MSG(worst <= 1e-12 * rbf->diagonal, "steps 3 vs 1: boundary differs by %g", worst);
        cm_mesh_boundary_destroy(&bd);
        printf("%s -> %s: min SJ rbf %.4f project %.4f (3 steps %.4f), max distance to G' %.2g\n",
               from, to, a->min_sj, b->min_sj, c->min_sj, rbf->max_dist);
    }
    cm_morph_result_destroy(&rbf);
    cm_morph_result_destroy(&prj);
    cm_morph_result_destroy(&inc);
}

static void test_errors(cm_context *ctx)
{
    char g0[2048], g1[2048], m[2048];
    cm_morph_result *r = NULL;
    fx_step_path(g0, sizeof g0, "hole_a");
    fx_step_path(g1, sizeof g1, "holes2_a");
    fx_mesh_path(m, sizeof m, "hole_a");
    CHECK(cm_morph_run(ctx, g0, g1, m, NULL, 0, NULL, &r) == CM_ERR_MISMATCH && r == NULL);
    CHECK_MSG(strstr(cm_context_message(ctx), "do not correspond: ") &&
                  strstr(cm_context_message(ctx), "faces: 7 in G, 8 in G'"),
              "%s", cm_context_message(ctx));
    fx_step_path(g1, sizeof g1, "hole_b");
    fx_mesh_path(m, sizeof m, "cyl_a");
    CHECK(cm_morph_run(ctx, g0, g1, m, NULL, 0, NULL, &r) == CM_ERR_MISMATCH && r == NULL);
    CHECK_MSG(strstr(cm_context_message(ctx), "is not a mesh of"), "%s", cm_context_message(ctx));
    fx_mesh_path(m, sizeof m, "hole_a_metres");
    CHECK(cm_morph_run(ctx, g0, g1, m, NULL, 0, NULL, &r) == CM_ERR_MISMATCH && r == NULL);
    CHECK_MSG(strstr(cm_context_message(ctx), "unit mismatch"), "%s", cm_context_message(ctx));
    /* the same mesh is fine once the CAD is read in metres */
    cm_morph_options o;
    cm_morph_options_init(&o);
    o.cad_unit = "m";
    CHECK_MSG(cm_morph_run(ctx, g0, g1, m, NULL, 0, &o, &r) == CM_OK && r, "%s", cm_context_message(ctx));
    if (r) CHECK(r->steps[0].inverted == 0 && r->max_dist <= 1e-9 * r->diagonal);
    cm_morph_result_destroy(&r);
    o.steps = -1;
    CHECK(cm_morph_run(ctx, g0, g1, m, NULL, 0, &o, &r) == CM_ERR_ARGUMENT && r == NULL);

    /* a sample cap below what h needs: h grows, the run says so and still ends on G' */
    fx_mesh_path(m, sizeof m, "hole_a");
    cm_morph_options_init(&o);
    o.max_samples = 3000;
    CHECK(cm_morph_run(ctx, g0, g1, m, NULL, 0, &o, &r) == CM_WARNING && r);
    CHECK_MSG(strstr(cm_context_message(ctx), "over the cap of 3000"), "%s",
              cm_context_message(ctx));
    if (r) {
        CHECK(r->h > 0.2);
        CHECK(r->steps[0].inverted == 0 && r->max_dist <= 1e-9 * r->diagonal);
    }
    cm_morph_result_destroy(&r);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    fx_data = argv[1];
    fx_work = argv[2];
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_identity_and_rigid(ctx);
    test_edit(ctx, "hole_a", "hole_b", "hole_a");
    test_edit(ctx, "holes2_a", "holes2_b", "holes2_a");
    test_edit(ctx, "cyl_a", "cyl_b", "cyl_a");
    test_edit(ctx, "sphere_a", "sphere_b", "sphere_a");
    test_edit(ctx, "cone_a", "cone_b", "cone_a");
    test_edit(ctx, "torus_a", "torus_b", "torus_a");
    /* the bore of the CAD tests: bore, boss with a seam, sphere cap */
    test_edit(ctx, "../cad/bore_a", "../cad/bore_b", "bore_a");
    test_errors(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
