/* Constraint sets from the CAD model (surface/cad_sets.c) on the gmsh mesh of hole_a (a
 * 10 x 8 x 4 block, six planes, a through bore of radius 2 with two circles) and of cone_a: each set is
 * exactly the boundary nodes within 1e-6 x diagonal of its face (trimmed projection) or
 * circle edge - checked by projecting every boundary node, not by the classification the
 * code uses -, the filter by type and id, and the errors. */
#include "surface_fixture.h"

static int in_set(const cm_surface_set *s, int64_t node)
{
    size_t lo = 0, hi = s->n; /* nodes ascend */
    while (lo < hi) {
        size_t m = (lo + hi) / 2;
        if (s->nodes[m] < node) lo = m + 1;
        else hi = m;
    }
    return lo < s->n && s->nodes[lo] == node;
}

/* The boundary nodes within tol of the set's entity, against the set. */
static void check_exact(cm_context *ctx, const cm_cad_model *g, const cm_mesh *mesh,
                        const cm_mesh_boundary *b, const cm_surface_set *s, double tol)
{
    size_t n = b->n_nodes, wrong = 0, near = 0;
    double *xyz = malloc(3 * n * sizeof *xyz), *dist = malloc(n * sizeof *dist);
    double *t = malloc(n * sizeof *t);
    for (size_t i = 0; i < n; ++i)
        memcpy(xyz + 3 * i, mesh->xyz + 3 * b->nodes[i], 3 * sizeof *xyz);
    cm_status st = s->type == CM_SURFACE_SET_CIRCLE
                       ? cm_cad_project_edge(ctx, g, s->entity, xyz, n, t, dist)
                       : cm_cad_project_face(ctx, g, s->entity, xyz, n, NULL, NULL, dist, NULL);
    CHECK_MSG(st == CM_OK, "%s", cm_context_message(ctx));
    for (size_t i = 0; st == CM_OK && i < n; ++i) {
        int close = dist[i] <= tol;
        near += close;
        wrong += close != in_set(s, b->nodes[i]);
    }
    CHECK_MSG(wrong == 0, "set of entity %d (type %d): %zu of %zu boundary nodes disagree",
              s->entity, (int)s->type, wrong, n);
    CHECK(near == s->n);
    free(xyz), free(dist), free(t);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    fx_data = argv[1];
    fx_work = argv[2];
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_cad_model *g = fx_model(ctx, "hole_a");
    cm_mesh *mesh = fx_mesh(ctx, "hole_a");
    if (!g || !mesh) return 1;
    double tol = 1e-6 * fx_diagonal(g);
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, mesh, &b) == CM_OK);

    /* all sets: six planes, the bore, its two circles */
    cm_surface_sets *sets = NULL;
    cm_status st = cm_surface_cad_sets(ctx, g, mesh, NULL, &sets);
    CHECK_MSG(st == CM_OK, "%s", cm_context_message(ctx));
    if (st == CM_OK) {
        int count[4] = {0, 0, 0, 0};
        for (size_t i = 0; i < sets->n; ++i) {
            count[sets->set[i].type]++;
            for (size_t k = 1; k < sets->set[i].n; ++k)
                CHECK(sets->set[i].nodes[k - 1] < sets->set[i].nodes[k]);
            check_exact(ctx, g, mesh, b, &sets->set[i], tol);
        }
        CHECK_MSG(count[0] == 6 && count[1] == 1 && count[2] == 2 && count[3] == 0,
                  "%d planes %d cylinders %d circles %d cones", count[0], count[1], count[2],
                  count[3]);
        /* the circles' nodes are in the bore's set and in a cap plane's */
        for (size_t i = 0; i < sets->n; ++i) {
            if (sets->set[i].type != CM_SURFACE_SET_CIRCLE) continue;
            for (size_t j = 0; j < sets->n; ++j)
                if (sets->set[j].type == CM_SURFACE_SET_CYLINDER)
                    for (size_t k = 0; k < sets->set[i].n; ++k)
                        CHECK(in_set(&sets->set[j], sets->set[i].nodes[k]));
        }
    }
    cm_surface_sets_destroy(&sets);
    CHECK(sets == NULL);

    /* by type: circles only; by id: the bore face (0-based 6) and nothing else */
    cm_surface_set_filter f = {0, 0, 1, 0, 0, 0, NULL, NULL};
    CHECK(cm_surface_cad_sets(ctx, g, mesh, &f, &sets) == CM_OK);
    CHECK(sets && sets->n == 2 && sets->set[0].type == CM_SURFACE_SET_CIRCLE);
    cm_surface_sets_destroy(&sets);
    const int bore[] = {6};
    f = (cm_surface_set_filter){0, 0, 0, 0, 1, 0, bore, NULL};
    CHECK(cm_surface_cad_sets(ctx, g, mesh, &f, &sets) == CM_OK);
    CHECK(sets && sets->n == 1 && sets->set[0].type == CM_SURFACE_SET_CYLINDER &&
          sets->set[0].entity == 6);
    cm_surface_sets_destroy(&sets);

    /* errors: an edge that is a line, an id out of range, a surface mesh */
    const int line[] = {0}, far[] = {99};
    f = (cm_surface_set_filter){0, 0, 0, 0, 0, 1, NULL, line};
    CHECK(cm_surface_cad_sets(ctx, g, mesh, &f, &sets) == CM_ERR_UNSUPPORTED && !sets);
    CHECK(strstr(cm_context_message(ctx), "not a circle") != NULL);
    f = (cm_surface_set_filter){0, 0, 0, 0, 1, 0, far, NULL};
    CHECK(cm_surface_cad_sets(ctx, g, mesh, &f, &sets) == CM_ERR_MISMATCH && !sets);
    cm_mesh *surf = NULL; /* the boundary faces alone */
    CHECK(cm_mesh_create(ctx, &surf) == CM_OK);
    if (surf && cm_mesh_resize_nodes(ctx, surf, mesh->n_nodes, 0) == CM_OK) {
        memcpy(surf->xyz, mesh->xyz, 3 * mesh->n_nodes * sizeof *surf->xyz);
        for (size_t i = 0; i < b->n_faces; ++i)
            if (b->face_offset[i + 1] - b->face_offset[i] == 3)
                CHECK(cm_mesh_add_cell(ctx, surf, CM_CELL_TRI3, b->face_nodes + b->face_offset[i],
                                       3, 0, 0, 0) == CM_OK);
        CHECK(cm_surface_cad_sets(ctx, g, surf, NULL, &sets) == CM_ERR_UNSUPPORTED && !sets);
    }
    cm_mesh_destroy(&surf);

    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&g);

    /* cone_a: its conical face's set is exactly the nodes on that face; cones only by type */
    g = fx_model(ctx, "cone_a");
    mesh = fx_mesh(ctx, "cone_a");
    if (g && mesh) {
        CHECK(cm_mesh_boundary_create(ctx, mesh, &b) == CM_OK);
        f = (cm_surface_set_filter){0, 0, 0, 1, 0, 0, NULL, NULL};
        st = cm_surface_cad_sets(ctx, g, mesh, &f, &sets);
        CHECK_MSG(st == CM_OK, "%s", cm_context_message(ctx));
        CHECK(sets && sets->n >= 1);
        for (size_t i = 0; sets && i < sets->n; ++i) {
            CHECK(sets->set[i].type == CM_SURFACE_SET_CONE);
            check_exact(ctx, g, mesh, b, &sets->set[i], 1e-6 * fx_diagonal(g));
        }
        cm_surface_sets_destroy(&sets);
        cm_mesh_boundary_destroy(&b);
    }
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&g);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
