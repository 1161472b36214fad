/* The surface morph's per-study cache (cm_surface_morph_cached, docs/DESIGN.md "Surface
 * morph across targets"): the faces' thin-plate systems factorised once on G give the same
 * positions, bit for bit, as a fresh morph, for one target, for targets in a row through one
 * cache, after the sampling options or G and its nodes change under the cache, and through a
 * morpher that applies several targets in a row. And the one-pass projection of each node
 * onto its own entity (cm_cad_project_each, the distance check's) against the projections
 * entity by entity. */
#include "surface_fixture.h"

#include "cadmorph/morph.h"

typedef struct setup {
    cm_cad_model *g;
    cm_cad_locator *loc;
    cm_mesh *mesh;
    cm_mesh_boundary *b;
    cm_surface_nodes *nodes;
} setup;

static int setup_create(cm_context *ctx, const char *model, setup *s)
{
    memset(s, 0, sizeof *s);
    s->g = fx_model(ctx, model);
    s->mesh = fx_mesh(ctx, model);
    if (!s->g || !s->mesh) return 0;
    CHECK(cm_mesh_boundary_create(ctx, s->mesh, &s->b) == CM_OK);
    double hmin = 0;
    CHECK(cm_surface_edge_lengths(ctx, s->mesh, s->b, NULL, &hmin) == CM_OK);
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    so.h = hmin / 4;
    so.max_samples = 4000000;
    CHECK(cm_cad_locator_create(ctx, s->g, &so, &s->loc) >= 0);
    return cm_surface_classify(ctx, s->g, s->loc, s->mesh, s->b, NULL, &s->nodes) == CM_OK;
}

static void setup_destroy(setup *s)
{
    cm_surface_nodes_destroy(&s->nodes);
    cm_cad_locator_destroy(&s->loc);
    cm_mesh_boundary_destroy(&s->b);
    cm_mesh_destroy(&s->mesh);
    cm_cad_destroy(&s->g);
}

/* The morph of s onto g2 through cache (NULL: fresh) equals a fresh one bit for bit, with
 * the same status and statistics. */
static void same_as_fresh(cm_context *ctx, cm_surface_morph_cache *cache, const setup *s,
                          const cm_cad_model *g2, const cm_surface_morph_options *o,
                          const char *what)
{
    size_t n = s->nodes->n;
    double *a = malloc(3 * n * sizeof *a), *b = malloc(3 * n * sizeof *b);
    cm_surface_morph_stats sa, sb;
    cm_status ra = cm_surface_morph(ctx, s->g, g2, s->nodes, o, a, &sa);
    cm_status rb = cm_surface_morph_cached(ctx, cache, s->g, g2, s->nodes, o, b, &sb);
    CHECK_MSG(ra >= 0 && ra == rb, "%s: status %d fresh, %d cached: %s", what, ra, rb,
              cm_context_message(ctx));
    CHECK_MSG(!memcmp(a, b, 3 * n * sizeof *a), "%s: cached positions differ", what);
    CHECK_MSG(sa.faces_warped == sb.faces_warped && sa.outside == sb.outside &&
                  sa.faces_affine == sb.faces_affine && sa.edges_affine == sb.edges_affine,
              "%s: statistics differ", what);
    CHECK_MSG(sa.faces_warped > 0, "%s: no face warped", what);
    free(a);
    free(b);
}

static void test_targets(cm_context *ctx)
{
    setup s, s2;
    CHECK(setup_create(ctx, "hole_a", &s));
    CHECK(setup_create(ctx, "holes2_a", &s2));
    cm_cad_model *hb = fx_model(ctx, "hole_b"), *hr = fx_model(ctx, "hole_rigid"),
                 *h2b = fx_model(ctx, "holes2_b");
    if (!s.nodes || !s2.nodes || !hb || !hr || !h2b) goto done;
    cm_surface_morph_cache *cache = NULL;
    CHECK(cm_surface_morph_cache_create(ctx, &cache) == CM_OK);
    cm_surface_morph_options o;
    cm_surface_morph_options_init(&o);
    /* an empty cache, then targets in a row through the filled one (hole_rigid is an
     * affine edit: its faces take the affine path on the same cached samples) */
    same_as_fresh(ctx, cache, &s, hb, &o, "hole_b, empty cache");
    same_as_fresh(ctx, cache, &s, hr, &o, "hole_rigid after hole_b");
    same_as_fresh(ctx, cache, &s, hb, &o, "hole_b again");
    same_as_fresh(ctx, NULL, &s, hb, &o, "no cache");
    /* other sampling options: the cache's samples and factors no longer fit, it refills */
    o.max_per_edge = 40;
    same_as_fresh(ctx, cache, &s, hb, &o, "hole_b, fewer samples per edge");
    cm_surface_morph_options_init(&o);
    /* another G and its nodes through the same cache, then back */
    same_as_fresh(ctx, cache, &s2, h2b, &o, "holes2_b through hole_a's cache");
    same_as_fresh(ctx, cache, &s, hr, &o, "hole_rigid after holes2");
    /* identity: G onto itself */
    same_as_fresh(ctx, cache, &s, s.g, &o, "identity");
    cm_surface_morph_cache_clear(cache);
    same_as_fresh(ctx, cache, &s, hb, &o, "hole_b after clear");
    cm_surface_morph_cache_destroy(&cache);
    CHECK(cache == NULL);
    cm_surface_morph_cache_destroy(&cache); /* NULL is fine */
done:
    cm_cad_destroy(&hb);
    cm_cad_destroy(&hr);
    cm_cad_destroy(&h2b);
    setup_destroy(&s);
    setup_destroy(&s2);
}

/* A morpher keeps the cache across applies: its second target equals a fresh morpher's. */
static void test_morpher(cm_context *ctx)
{
    cm_cad_model *g = fx_model(ctx, "hole_a"), *hb = fx_model(ctx, "hole_b"),
                 *hr = fx_model(ctx, "hole_rigid");
    cm_mesh *mesh = fx_mesh(ctx, "hole_a");
    cm_morpher *m1 = NULL, *m2 = NULL;
    if (!g || !hb || !hr || !mesh) goto done;
    CHECK(cm_morpher_create(ctx, g, mesh, NULL, &m1) >= 0);
    CHECK(cm_morpher_create(ctx, g, mesh, NULL, &m2) >= 0);
    if (!m1 || !m2) goto done;
    size_t n = 3 * mesh->n_nodes;
    double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    CHECK(cm_morpher_apply(ctx, m1, hb, a, NULL) >= 0);
    CHECK(cm_morpher_apply(ctx, m1, hr, a, NULL) >= 0);
    CHECK(cm_morpher_apply(ctx, m2, hr, b, NULL) >= 0);
    CHECK_MSG(!memcmp(a, b, n * sizeof *a), "morpher: the second target differs from a fresh one");
    /* a rebase on the morphed mesh re-classifies: the cache must not serve the old nodes */
    CHECK(cm_morpher_rebase(ctx, m1, hr, a) >= 0);
    CHECK(cm_morpher_apply(ctx, m1, hb, a, NULL) >= 0);
    cm_morpher *m3 = NULL;
    cm_mesh *moved = NULL;
    CHECK(cm_mesh_copy(ctx, mesh, &moved) == CM_OK);
    if (moved) memcpy(moved->xyz, b, n * sizeof *b);
    CHECK(moved && cm_morpher_create(ctx, hr, moved, NULL, &m3) >= 0);
    if (m3) {
        CHECK(cm_morpher_apply(ctx, m3, hb, b, NULL) >= 0);
        CHECK_MSG(!memcmp(a, b, n * sizeof *a), "morpher: after a rebase, differs from fresh");
    }
    cm_morpher_destroy(&m3);
    cm_mesh_destroy(&moved);
    free(a);
    free(b);
done:
    cm_morpher_destroy(&m1);
    cm_morpher_destroy(&m2);
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&g);
    cm_cad_destroy(&hb);
    cm_cad_destroy(&hr);
}

/* cm_cad_project_each gives the distances of cm_cad_project_edge / _face per entity, bit for
 * bit, seeded and unseeded; it refuses an entity out of range. */
static void test_project_each(cm_context *ctx)
{
    setup s;
    CHECK(setup_create(ctx, "holes2_a", &s));
    cm_cad_model *g2 = fx_model(ctx, "holes2_b");
    if (!s.nodes || !g2) goto done;
    const cm_surface_nodes *nd = s.nodes;
    size_t n = nd->n;
    double *xyz = malloc(3 * n * sizeof *xyz), *a = malloc(n * sizeof *a),
           *b = malloc(n * sizeof *b);
    int *kind = malloc(2 * n * sizeof *kind), *ent = kind + n;
    CHECK(cm_surface_morph(ctx, s.g, g2, nd, NULL, xyz, NULL) >= 0);
    for (size_t i = 0; i < n; ++i) {
        kind[i] = (int)nd->kind[i], ent[i] = nd->entity[i];
        xyz[3 * i] += 1e-3 * (double)(i % 7); /* some nodes off their entity */
    }
    for (int seeded = 0; seeded < 2; ++seeded) {
        for (size_t i = 0; i < n; ++i)
            a[i] = b[i] = -1;
        CHECK(cm_cad_project_each(ctx, g2, n, kind, ent, xyz, seeded ? nd->param : NULL, b) ==
              CM_OK);
        size_t projected = 0;
        for (size_t i = 0; i < n; ++i) {
            if (kind[i] == 1) {
                CHECK(cm_cad_project_edge(ctx, g2, ent[i], xyz + 3 * i, 1, NULL, a + i) == CM_OK);
            } else if (kind[i] == 2) {
                CHECK(cm_cad_project_face(ctx, g2, ent[i], xyz + 3 * i, 1,
                                          seeded ? nd->param + 2 * i : NULL, NULL, a + i,
                                          NULL) == CM_OK);
            }
            projected += kind[i] == 1 || kind[i] == 2;
        }
        CHECK(projected > 100);
        CHECK_MSG(!memcmp(a, b, n * sizeof *a), "cm_cad_project_each (seeded %d) differs", seeded);
    }
    ent[n - 1] = 1000000;
    kind[n - 1] = 2;
    CHECK(cm_cad_project_each(ctx, g2, n, kind, ent, xyz, NULL, b) == CM_ERR_ARGUMENT);
    free(xyz);
    free(a);
    free(b);
    free(kind);
done:
    cm_cad_destroy(&g2);
    setup_destroy(&s);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    fx_data = argv[1];
    fx_work = argv[2];
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_targets(ctx);
    test_morpher(ctx);
    test_project_each(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
