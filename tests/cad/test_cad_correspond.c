/* The correspondence of G and G' as graphs (cad/correspond.cpp) on pairs written by gen_shapes
 * with OpenCASCADE: a GTransform edit (non-uniform scale + shear: planes, cylinders and the
 * torus become B-splines), NurbsConvert, elementary surfaces converted to revolutions, a
 * spindle-torus part re-exported through cm_cad_write, the part re-sewn from a shuffled face
 * list, a box rebuilt polygon by polygon (edges run the other way), a row of holes stretched
 * about its centre (only the kept numbering places the holes); all correspond. After
 * cm_cad_match renumbers G', entity i of G' is the counterpart of entity i of G: same points,
 * the same boundary samples of every face, the same point at each arc-length fraction of every
 * edge; and a morph from G onto an identical G' leaves the mesh where it is. A hole added is
 * refused in words. */
#include "cadmorph/cad.h"
#include "cadmorph/morph.h"
#include "cadmorph/tetmesh.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char data_dir[1024], work_dir[1024];

static const char *path_of(const char *name)
{
    static char buf[4][2048];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/cad/%s", work_dir, name);
    return buf[k];
}

static double diag_of(const cm_cad_model *m)
{
    double b[6];
    cm_cad_bbox(m, b);
    return sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) +
                (b[5] - b[2]) * (b[5] - b[2]));
}

static double dist(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* After cm_cad_match, G' (same geometry) indexed by G: vertices, face boundary samples (xyz
 * and, with same_uv, (u,v)), edge points at equal arc-length fractions coincide. Returns the
 * largest distance found, relative to the diagonal. */
static double same_geometry(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                            int same_uv)
{
    const double diag = diag_of(g);
    cm_cad_counts c;
    cm_cad_get_counts(g, &c);
    double worst = 0;
    for (int v = 0; v < c.vertices; ++v) {
        double a[3], b[3];
        CHECK(cm_cad_vertex_point(ctx, g, v, a) == CM_OK && cm_cad_vertex_point(ctx, g2, v, b) == CM_OK);
        worst = fmax(worst, dist(a, b) / diag);
    }
    for (int e = 0; e < c.edges; ++e) {
        cm_cad_edge_info ea, eb;
        CHECK(cm_cad_edge_get_info(ctx, g, e, &ea) == CM_OK);
        CHECK(cm_cad_edge_get_info(ctx, g2, e, &eb) == CM_OK);
        CHECK(ea.degenerate == eb.degenerate);
        CHECK_NEAR(ea.length, eb.length, 1e-7 * diag);
        double s[3] = {0.0, 0.3, 1.0}, ta[3], tb[3], pa[9], pb[9];
        CHECK(cm_cad_edge_s_to_t(ctx, g, e, s, 3, ta) == CM_OK);
        CHECK(cm_cad_edge_s_to_t(ctx, g2, e, s, 3, tb) == CM_OK);
        CHECK(cm_cad_edge_eval(ctx, g, e, ta, 3, pa) == CM_OK);
        CHECK(cm_cad_edge_eval(ctx, g2, e, tb, 3, pb) == CM_OK);
        double sb[3];
        CHECK(cm_cad_edge_t_to_s(ctx, g2, e, tb, 3, sb) == CM_OK);
        for (int i = 0; i < 3; ++i) {
            worst = fmax(worst, dist(pa + 3 * i, pb + 3 * i) / diag);
            CHECK_NEAR(sb[i], s[i], 1e-9);
        }
    }
    for (int f = 0; f < c.faces; ++f) {
        cm_cad_boundary *ba = NULL, *bb = NULL;
        CHECK(cm_cad_face_boundary(ctx, g, f, NULL, 5, &ba) == CM_OK);
        CHECK(cm_cad_face_boundary(ctx, g2, f, NULL, 5, &bb) == CM_OK);
        if (ba && bb) {
            CHECK(ba->n == bb->n);
            for (size_t i = 0; i < ba->n && i < bb->n; ++i) {
                worst = fmax(worst, dist(ba->xyz + 3 * i, bb->xyz + 3 * i) / diag);
                CHECK(ba->edge[i] == bb->edge[i] && ba->wire[i] == bb->wire[i]);
                CHECK_NEAR(ba->s[i], bb->s[i], 1e-9);
                if (same_uv)
                    CHECK_MSG(fabs(ba->uv[2 * i] - bb->uv[2 * i]) + fabs(ba->uv[2 * i + 1] - bb->uv[2 * i + 1]) < 1e-7,
                              "face %d sample %zu: uv (%g, %g) vs (%g, %g)", f, i, ba->uv[2 * i],
                              ba->uv[2 * i + 1], bb->uv[2 * i], bb->uv[2 * i + 1]);
            }
        }
        cm_cad_boundary_destroy(&ba);
        cm_cad_boundary_destroy(&bb);
    }
    return worst;
}

/* G vs G': they correspond; after cm_cad_match the compare (identity numbering) accepts. */
static void check_pair(cm_context *ctx, const char *a, const char *b, int expect_renumbered,
                       int expect_type_changes, int identical, int same_uv)
{
    cm_cad_model *g = NULL, *g2 = NULL;
    CHECK(cm_cad_read(ctx, path_of(a), NULL, &g) == CM_OK);
    CHECK(cm_cad_read(ctx, path_of(b), NULL, &g2) == CM_OK);
    if (!g || !g2) goto done;
    cm_cad_correspondence *c = NULL;
    cm_status s = cm_cad_correspond(ctx, g, g2, 5, &c);
    CHECK_MSG(s == CM_OK && c, "%s vs %s: %s", a, b, cm_context_message(ctx));
    if (!c) goto done;
    CHECK_MSG(c->renumbered == expect_renumbered || expect_renumbered < 0, "%s vs %s: renumbered %d",
              a, b, c->renumbered);
    CHECK_MSG((c->face_type_changes + c->edge_type_changes > 0) == expect_type_changes,
              "%s vs %s: %d face and %d edge type changes", a, b, c->face_type_changes,
              c->edge_type_changes);
    int flips = 0;
    for (int e = 0; e < c->counts.edges; ++e) flips += c->edge_flipped[e];
    /* a permutation of each kind */
    cm_cad_counts n2;
    cm_cad_get_counts(g2, &n2);
    int *seen = calloc((size_t)(n2.faces + n2.edges + n2.vertices), sizeof *seen);
    for (int f = 0; seen && f < c->counts.faces; ++f) seen[c->face[f]]++;
    for (int e = 0; seen && e < c->counts.edges; ++e) seen[n2.faces + c->edge[e]]++;
    for (int v = 0; seen && v < c->counts.vertices; ++v) seen[n2.faces + n2.edges + c->vertex[v]]++;
    for (int i = 0; seen && i < n2.faces + n2.edges + n2.vertices; ++i) CHECK(seen[i] == 1);
    free(seen);
    if (identical) {
        /* before renumbering: the counterparts are at the same places */
        for (int v = 0; v < c->counts.vertices; ++v) {
            double p[3], q[3];
            cm_cad_vertex_point(ctx, g, v, p);
            cm_cad_vertex_point(ctx, g2, c->vertex[v], q);
            CHECK_MSG(dist(p, q) <= 1e-9 * diag_of(g), "%s: vertex %d -> %d: %g apart", b, v,
                      c->vertex[v], dist(p, q));
        }
    }
    cm_cad_correspondence_destroy(&c);
    CHECK(c == NULL);
    if (expect_renumbered == 1) {
        CHECK(cm_cad_compare(ctx, g, g2, 5) == CM_ERR_MISMATCH);
        CHECK_MSG(strstr(cm_context_message(ctx), "cm_cad_match"), "%s", cm_context_message(ctx));
    }
    s = cm_cad_match(ctx, g, g2, 5, NULL);
    CHECK_MSG(s == CM_OK, "match %s vs %s: %s", a, b, cm_context_message(ctx));
    s = cm_cad_compare(ctx, g, g2, 5);
    CHECK_MSG(s == CM_OK, "compare after match %s vs %s: %s", a, b, cm_context_message(ctx));
    if (identical) {
        double w = same_geometry(ctx, g, g2, same_uv);
        CHECK_MSG(w <= 1e-9, "%s vs %s renumbered: entities %g x diagonal apart", a, b, w);
    }
    printf("%s vs %s: corresponds%s, %d edges flipped\n", a, b,
           expect_renumbered == 1 ? " after renumbering" : "", flips);
done:
    cm_cad_destroy(&g);
    cm_cad_destroy(&g2);
}

/* The re-export of a model through cm_cad_write, read back. */
static void reexport(cm_context *ctx, const char *a, const char *b)
{
    cm_cad_model *g = NULL;
    CHECK(cm_cad_read(ctx, path_of(a), NULL, &g) == CM_OK);
    if (g) CHECK_MSG(cm_cad_write(ctx, g, path_of(b)) == CM_OK, "%s", cm_context_message(ctx));
    cm_cad_destroy(&g);
}

static void test_pairs(cm_context *ctx)
{
    /* renumbered, flipped: the same geometry, so the same points and (u,v) */
    check_pair(ctx, "part.step", "part_renumbered.step", 1, 0, 1, 1);
    check_pair(ctx, "block.step", "block_rebuilt.step", 1, 0, 1, 0);
    /* type changes; the numbering may keep or move wire starts */
    check_pair(ctx, "part.step", "part_gtrsf.step", -1, 1, 0, 0);
    check_pair(ctx, "part.step", "part_nurbs.step", -1, 1, 1, 0);
    check_pair(ctx, "part.step", "part_revolution.step", -1, 1, 1, 0);
    /* a parametric edit: every hole moves nearer to another's old place; the numbering holds */
    check_pair(ctx, "row_a.step", "row_b.step", 0, 0, 0, 0);
    reexport(ctx, "spindle.step", "spindle_again.step");
    check_pair(ctx, "spindle.step", "spindle_again.step", -1, 0, 1, 0);
    reexport(ctx, "part.step", "part_again.step");
    check_pair(ctx, "part.step", "part_again.step", -1, 0, 1, 1);

    /* at least one edge of the rebuilt box runs the other way: the test covers flips */
    cm_cad_model *g = NULL, *g2 = NULL;
    cm_cad_correspondence *c = NULL;
    CHECK(cm_cad_read(ctx, path_of("block.step"), NULL, &g) == CM_OK);
    CHECK(cm_cad_read(ctx, path_of("block_rebuilt.step"), NULL, &g2) == CM_OK);
    CHECK(g && g2 && cm_cad_correspond(ctx, g, g2, 5, &c) == CM_OK && c);
    int flips = 0;
    for (int e = 0; c && e < c->counts.edges; ++e) flips += c->edge_flipped[e];
    CHECK_MSG(flips > 0, "block_rebuilt: no flipped edge");
    cm_cad_correspondence_destroy(&c);
    cm_cad_destroy(&g);
    cm_cad_destroy(&g2);
}

static void test_hole(cm_context *ctx)
{
    cm_cad_model *g = NULL, *g2 = NULL;
    cm_cad_correspondence *c = (cm_cad_correspondence *)1;
    CHECK(cm_cad_read(ctx, path_of("part.step"), NULL, &g) == CM_OK);
    CHECK(cm_cad_read(ctx, path_of("part_hole.step"), NULL, &g2) == CM_OK);
    if (g && g2) {
        CHECK(cm_cad_correspond(ctx, g, g2, 5, &c) == CM_ERR_MISMATCH && c == NULL);
        const char *m = cm_context_message(ctx);
        CHECK_MSG(strstr(m, "has no counterpart: G' has a hole there") &&
                      strstr(m, "faces: 9 in G, 10 in G'") && strstr(m, "(plane, 5 edges"),
                  "%s", m);
        CHECK(cm_cad_match(ctx, g, g2, 5, NULL) == CM_ERR_MISMATCH);
    }
    cm_cad_destroy(&g);
    cm_cad_destroy(&g2);
}

static cm_morph_result *morph(cm_context *ctx, const char *a, const char *b, const char *mesh)
{
    cm_morph_options o;
    cm_morph_options_init(&o);
    o.max_samples = 300000; /* a coarser locator: the Newton projections do the rest */
    o.target_h_scale = 4;
    cm_morph_result *r = NULL;
    cm_status s = cm_morph_run(ctx, path_of(a), path_of(b), path_of(mesh), NULL, 0, &o, &r);
    CHECK_MSG(s >= 0 && r, "morph %s -> %s: %s", a, b, cm_context_message(ctx));
    return r;
}

/* A morph from G onto the renumbered G' of the same geometry leaves every node where the
 * morph from G onto G itself puts it (in place, unless TetGen's boundary nodes sit off an edge
 * curve by the model's tolerance: the spindle's seam is a circle, its surface a B-spline
 * revolution); with in_place, also where it was. */
static void test_morph_in_place(cm_context *ctx, const char *a, const char *b, const char *mesh,
                                int in_place)
{
    cm_cad_model *g = NULL;
    cm_mesh *m = NULL;
    CHECK(cm_cad_read(ctx, path_of(a), NULL, &g) == CM_OK);
    if (!g) return;
    cm_tetmesh_options to;
    cm_tetmesh_options_init(&to);
    to.size = diag_of(g) / 8;
    cm_status s = cm_tetmesh_create(ctx, g, &to, &m);
    CHECK_MSG(s >= 0 && m, "mesh %s: %s", a, cm_context_message(ctx));
    if (m) CHECK(cm_mesh_write(ctx, m, path_of(mesh), NULL) == CM_OK);
    cm_morph_result *r = m ? morph(ctx, a, b, mesh) : NULL, *id = m ? morph(ctx, a, a, mesh) : NULL;
    if (r && id && m) {
        double worst = 0, worst_id = 0, diag = diag_of(g);
        CHECK(r->mesh->n_nodes == m->n_nodes && id->mesh->n_nodes == m->n_nodes);
        for (size_t i = 0; i < m->n_nodes && i < r->mesh->n_nodes; ++i) {
            worst = fmax(worst, dist(m->xyz + 3 * i, r->mesh->xyz + 3 * i));
            worst_id = fmax(worst_id, dist(id->mesh->xyz + 3 * i, r->mesh->xyz + 3 * i));
        }
        printf("morph %s -> %s: %zu nodes, largest move %.3g (%.3g x diagonal), %.3g x diagonal "
               "from the morph onto G itself\n",
               a, b, m->n_nodes, worst, worst / diag, worst_id / diag);
        CHECK_MSG(worst_id <= 1e-9 * diag, "%s -> %s: %g x diagonal from G -> G", a, b, worst_id / diag);
        if (in_place)
            CHECK_MSG(worst <= 1e-9 * diag, "%s -> %s moved a node by %g x diagonal", a, b,
                      worst / diag);
    }
    cm_morph_result_destroy(&r);
    cm_morph_result_destroy(&id);
    cm_mesh_destroy(&m);
    cm_cad_destroy(&g);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    snprintf(data_dir, sizeof data_dir, "%s", argv[1]);
    snprintf(work_dir, sizeof work_dir, "%s", argv[2]);
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_pairs(ctx);
    test_hole(ctx);
    test_morph_in_place(ctx, "part.step", "part_renumbered.step", "part_m.vtu", 1);
    test_morph_in_place(ctx, "block.step", "block_rebuilt.step", "block_m.vtu", 1);
    test_morph_in_place(ctx, "spindle.step", "spindle_again.step", "spindle_m.vtu", 0);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
