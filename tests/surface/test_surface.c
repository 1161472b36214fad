/* Classification and surface morph (surface/classify.c, surface/morph_surface.c) on gmsh
 * meshes of gmsh-written STEP pairs: every node's parameters evaluate back to it, identity
 * keeps it, rigid / affine edits move it by their closed form, morphed nodes lie on their
 * entity of G', and meshes of other models or in another unit are refused. */
#include "surface_fixture.h"

typedef struct setup {
    cm_cad_model *g;
    cm_cad_locator *loc;
    cm_mesh *mesh;
    cm_mesh_boundary *b;
    cm_surface_nodes *nodes;
    double diag;
} setup;

static cm_status setup_create(cm_context *ctx, const char *model, const char *mesh, setup *s)
{
    memset(s, 0, sizeof *s);
    s->g = fx_model(ctx, model);
    s->mesh = fx_mesh(ctx, mesh);
    if (!s->g || !s->mesh) return CM_ERR_IO;
    s->diag = fx_diagonal(s->g);
    CHECK(cm_mesh_boundary_create(ctx, s->mesh, &s->b) == CM_OK);
    double hmin = 0;
    CHECK(cm_surface_edge_lengths(ctx, s->mesh, s->b, NULL, &hmin) == CM_OK);
    CHECK(hmin > 0);
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    so.h = hmin / 4;
    so.max_samples = 4000000;
    CHECK(cm_cad_locator_create(ctx, s->g, &so, &s->loc) >= 0);
    return cm_surface_classify(ctx, s->g, s->loc, s->mesh, s->b, NULL, &s->nodes);
}

static void setup_destroy(setup *s)
{
    cm_surface_nodes_destroy(&s->nodes);
    cm_cad_locator_destroy(&s->loc);
    cm_mesh_boundary_destroy(&s->b);
    cm_mesh_destroy(&s->mesh);
    cm_cad_destroy(&s->g);
}

/* Where a node's classification says it is, on model m. */
static void evaluate(cm_context *ctx, const cm_cad_model *m, const cm_surface_nodes *n, size_t i,
                     double *p)
{
    if (n->kind[i] == CM_SURFACE_ON_VERTEX)
        CHECK(cm_cad_vertex_point(ctx, m, n->entity[i], p) == CM_OK);
    else if (n->kind[i] == CM_SURFACE_ON_EDGE)
        CHECK(cm_cad_edge_eval(ctx, m, n->entity[i], n->param + 2 * i, 1, p) == CM_OK);
    else
        CHECK(cm_cad_face_eval(ctx, m, n->entity[i], n->param + 2 * i, 1, p, NULL) == CM_OK);
}

static void test_classify(cm_context *ctx, const char *model)
{
    setup s;
    cm_status st = setup_create(ctx, model, model, &s);
    CHECK_MSG(st == CM_OK, "%s: %s", model, cm_context_message(ctx));
    if (st != CM_OK) {
        setup_destroy(&s);
        return;
    }
    const cm_surface_nodes *n = s.nodes;
    cm_cad_counts c;
    cm_cad_get_counts(s.g, &c);
    CHECK(n->n == s.b->n_nodes);
    /* gmsh puts one node on each CAD vertex; edges and faces have nodes of their own */
    CHECK_MSG(n->count[0] == (size_t)c.vertices, "%s: %zu vertex nodes, %d vertices", model,
              n->count[0], c.vertices);
    CHECK(n->count[1] > 0 && n->count[2] > 0);
    CHECK(n->count[0] + n->count[1] + n->count[2] == n->n);
    double worst = 0;
    for (size_t i = 0; i < n->n; ++i) {
        double p[3];
        evaluate(ctx, s.g, n, i, p);
        double d = fx_dist(p, n->xyz + 3 * i);
        if (d > worst) worst = d;
        if (n->kind[i] == CM_SURFACE_ON_EDGE)
            CHECK(n->param[2 * i + 1] >= -1e-12 && n->param[2 * i + 1] <= 1 + 1e-12);
    }
    CHECK_MSG(worst <= 1e-9 * s.diag, "%s: parameters off the node by %g", model, worst);

    /* identity: G -> G keeps every boundary node to 1e-12 x diagonal */
    double *xyz = malloc(3 * n->n * sizeof *xyz);
    cm_surface_morph_stats ms;
    CHECK(cm_surface_morph(ctx, s.g, s.g, n, NULL, xyz, &ms) == CM_OK);
    worst = 0;
    for (size_t i = 0; i < n->n; ++i) {
        double d = fx_dist(xyz + 3 * i, n->xyz + 3 * i);
        if (d > worst) worst = d;
    }
    CHECK_MSG(worst <= 1e-12 * s.diag, "%s: identity moved a node by %g", model, worst);
    CHECK(ms.outside == 0 && ms.faces_warped > 0);
    free(xyz);
    setup_destroy(&s);
}

/* G -> G2 with both methods: nodes on the matching entity of G2 (projected independently,
 * per entity), edge nodes keep s under rbf; closed form `motion` when given. */
static void test_morph(cm_context *ctx, const char *from, const char *to,
                       void (*motion)(const double *, double *))
{
    setup s;
    cm_status st = setup_create(ctx, from, from, &s);
    CHECK_MSG(st == CM_OK, "%s: %s", from, cm_context_message(ctx));
    cm_cad_model *g2 = fx_model(ctx, to);
    if (st != CM_OK || !g2) {
        cm_cad_destroy(&g2);
        setup_destroy(&s);
        return;
    }
    CHECK(cm_cad_compare(ctx, s.g, g2, 5) == CM_OK);
    const cm_surface_nodes *n = s.nodes;
    double *xyz = malloc(3 * n->n * sizeof *xyz), diag2 = fx_diagonal(g2);
    for (int method = 0; method < 2; ++method) {
        cm_surface_morph_options o;
        cm_surface_morph_options_init(&o);
        o.method = method ? CM_SURFACE_PROJECT : CM_SURFACE_RBF;
        cm_surface_morph_stats ms;
        st = cm_surface_morph(ctx, s.g, g2, n, &o, xyz, &ms);
        CHECK_MSG(st == CM_OK, "%s -> %s: %s", from, to, cm_context_message(ctx));
        double off = 0, ds = 0, closed = 0;
        for (size_t i = 0; i < n->n; ++i) {
            const double *p = xyz + 3 * i;
            double d = 0;
            int e = n->entity[i];
            if (n->kind[i] == CM_SURFACE_ON_VERTEX) {
                double v[3];
                cm_cad_vertex_point(ctx, g2, e, v);
                d = fx_dist(p, v);
            } else if (n->kind[i] == CM_SURFACE_ON_EDGE) {
                double t, s2;
                CHECK(cm_cad_project_edge(ctx, g2, e, p, 1, &t, &d) == CM_OK);
                CHECK(cm_cad_edge_t_to_s(ctx, g2, e, &t, 1, &s2) == CM_OK);
                /* closed edges: s = 0 and 1 are the same point */
                double gap = fabs(s2 - n->param[2 * i + 1]);
                if (gap > 0.5) gap = 1 - gap;
                if (method == 0 && gap > ds) ds = gap;
            } else {
                CHECK(cm_cad_project_face(ctx, g2, e, p, 1, NULL, NULL, &d, NULL) == CM_OK);
            }
            if (d > off) off = d;
            if (motion && method == 0) {
                double y[3];
                motion(n->xyz + 3 * i, y);
                double c = fx_dist(y, p);
                if (c > closed) closed = c;
            }
        }
        CHECK_MSG(off <= 1e-9 * diag2, "%s -> %s (%s): a node is %g off its entity of G'", from, to,
                  method ? "project" : "rbf", off);
        CHECK_MSG(ds <= 1e-9, "%s -> %s: edge nodes moved along the edge by s = %g", from, to, ds);
        CHECK_MSG(closed <= 1e-9 * diag2, "%s -> %s: %g from the closed form", from, to, closed);
        if (method == 0) CHECK_MSG(ms.outside == 0, "%s -> %s: %zu outside", from, to, ms.outside);
    }
    /* the largest distance to G' as the pipeline measures it, through a locator on G' */
    cm_cad_locator *l2 = NULL;
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    CHECK(cm_cad_locator_create(ctx, g2, &so, &l2) >= 0);
    double md = -1;
    CHECK(cm_surface_max_distance(ctx, l2, xyz, n->n, &md, NULL) == CM_OK);
    CHECK_MSG(md >= 0 && md <= 1e-9 * diag2, "%s -> %s: max distance %g", from, to, md);
    cm_cad_locator_destroy(&l2);
    free(xyz);
    cm_cad_destroy(&g2);
    setup_destroy(&s);
}

/* A parameter warp from too few boundary samples (2 per edge: the bore is a chord) sends
 * nodes into the grown bore of G': they are reported - count, worst node - and put on the
 * closest point of their face, so every node is still on G'. */
static void test_outside(cm_context *ctx)
{
    setup s;
    cm_status st = setup_create(ctx, "hole_a", "hole_a", &s);
    cm_cad_model *g2 = fx_model(ctx, "hole_b");
    if (st == CM_OK && g2) {
        const cm_surface_nodes *n = s.nodes;
        double *xyz = malloc(3 * n->n * sizeof *xyz);
        cm_surface_morph_options o;
        cm_surface_morph_options_init(&o);
        o.min_per_edge = o.max_per_edge = 2;
        cm_surface_morph_stats ms;
        st = cm_surface_morph(ctx, s.g, g2, n, &o, xyz, &ms);
        CHECK_MSG(st == CM_WARNING && ms.outside > 0 && ms.worst_outside_node >= 0,
                  "status %d, %zu outside: %s", (int)st, ms.outside, cm_context_message(ctx));
        CHECK_MSG(strstr(cm_context_message(ctx), "face nodes left the trimmed domain") != NULL,
                  "%s", cm_context_message(ctx));
        cm_cad_locator *l2 = NULL;
        CHECK(cm_cad_locator_create(ctx, g2, NULL, &l2) >= 0);
        double md = -1;
        CHECK(cm_surface_max_distance(ctx, l2, xyz, n->n, &md, NULL) == CM_OK);
        CHECK_MSG(md >= 0 && md <= 1e-9 * fx_diagonal(g2), "max distance %g", md);
        cm_cad_locator_destroy(&l2);
        free(xyz);
    }
    cm_cad_destroy(&g2);
    setup_destroy(&s);
}

static void test_mismatch(cm_context *ctx)
{
    setup s;
    /* a mesh of another model: off G, count and worst node in the message */
    cm_status st = setup_create(ctx, "hole_a", "cyl_a", &s);
    CHECK(st == CM_ERR_MISMATCH && s.nodes == NULL);
    CHECK_MSG(strstr(cm_context_message(ctx), "boundary nodes are off the CAD model (worst: node "),
              "%s", cm_context_message(ctx));
    setup_destroy(&s);
    /* the same mesh in metres against the model in millimetres */
    st = setup_create(ctx, "hole_a", "hole_a_metres", &s);
    CHECK(st == CM_ERR_MISMATCH);
    CHECK_MSG(
        strstr(cm_context_message(ctx),
               "1000x smaller than the model: a unit mismatch? (mesh in m: read the CAD in m)"),
        "%s", cm_context_message(ctx));
    setup_destroy(&s);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    fx_data = argv[1];
    fx_work = argv[2];
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    const char *models[] = {"hole_a", "holes2_a", "cyl_a", "sphere_a"};
    for (int i = 0; i < 4; ++i)
        test_classify(ctx, models[i]);
    test_morph(ctx, "hole_a", "hole_rigid", fx_rigid);
    test_morph(ctx, "cyl_a", "cyl_b", fx_cylinder);
    test_morph(ctx, "sphere_a", "sphere_b", fx_sphere);
    test_morph(ctx, "hole_a", "hole_b", NULL);
    test_morph(ctx, "holes2_a", "holes2_b", NULL);
    test_morph(ctx, "cone_a", "cone_b", NULL);
    test_morph(ctx, "torus_a", "torus_b", NULL);
    test_outside(ctx);
    test_mismatch(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
