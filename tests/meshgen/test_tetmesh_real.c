/* cm_tetmesh_create on real files and on what goes wrong with them (meshgen/tetmesh.cpp,
 * docs/DESIGN.md, "Meshers"):
 *  - gmsh's mesh is judged by the model's own tolerances: the OpenCASCADE repository's screw
 *    (edge tolerances 3e-4 mm) and a box whose vertices sit 3e-4 off its edges (gen_shapes'
 *    loose_box) are meshed by gmsh, without a fallback, and every boundary node is then on
 *    its CAD face: exactly (1e-9 x diagonal) inside a face, within the tolerance where faces
 *    meet;
 *  - when gmsh cannot mesh the model (here: the file changed since it was read, so gmsh's
 *    geometry is not ours), TetGen does, with one warning saying so; without the fallback the
 *    error names the other mesher;
 *  - the quality judgement (min_sj): a floor no mesh reaches is CM_ERR_REJECTED, nothing
 *    returned, naming the worst tet, and with the fallback both meshers' reasons;
 *  - the estimate is within 3x of the real count: refused at a third of the count, not at
 *    three times it.
 * usage: test_tetmesh_real DATA_DIR WORK_DIR (gen_shapes' output in WORK_DIR/cad) */
#include "cadmorph/tetmesh.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char warning[8192];
static int n_warnings;

static void on_log(void *user, cm_log_level level, const char *msg)
{
    (void)user;
    if (level < CM_LOG_WARNING) return;
    ++n_warnings;
    snprintf(warning, sizeof warning, "%s", msg);
}

static int copy_file(const char *from, const char *to)
{
    FILE *a = fopen(from, "rb"), *b = fopen(to, "wb");
    int ok = a && b;
    char buf[65536];
    size_t n;
    while (ok && (n = fread(buf, 1, sizeof buf, a)) > 0) ok = fwrite(buf, 1, n, b) == n;
    if (a) fclose(a);
    if (b) ok = fclose(b) == 0 && ok;
    return ok;
}

/* every boundary node on its CAD face: inside one face to 1e-9 x diagonal, where faces meet
 * to 4 x the model's tolerance there (and 1e-7 x diagonal) */
static void check_on_faces(cm_context *ctx, const cm_cad_model *model, const cm_mesh *m)
{
    cm_cad_counts counts;
    cm_cad_get_counts(model, &counts);
    double bb[6];
    cm_cad_bbox(model, bb);
    const double diag = cm_bbox_diagonal(bb);
    double *tol = calloc((size_t)counts.faces, sizeof *tol);
    CHECK(cm_cad_face_tolerances(ctx, model, tol, NULL) == CM_OK);
    /* per node: its first face, and whether it has another */
    int *face = malloc(m->n_nodes * sizeof *face), *shared = calloc(m->n_nodes, sizeof *shared);
    for (size_t i = 0; i < m->n_nodes; ++i) face[i] = -1;
    for (size_t c = 0; c < m->n_cells; ++c) {
        if (m->type[c] != CM_CELL_TRI3) continue;
        const int f = m->physical[c] - 1;
        for (int64_t k = m->offset[c]; k < m->offset[c + 1]; ++k) {
            const int64_t v = m->conn[k];
            if (face[v] < 0) face[v] = f;
            else if (face[v] != f) shared[v] = 1;
        }
    }
    size_t checked = 0, bad = 0;
    double worst_inside = 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        if (m->type[c] != CM_CELL_TRI3) continue;
        const int f = m->physical[c] - 1;
        for (int64_t k = m->offset[c]; k < m->offset[c + 1]; ++k) {
            const int64_t v = m->conn[k];
            double d = 0;
            if (cm_cad_project_face(ctx, model, f, &m->xyz[3 * v], 1, NULL, NULL, &d, NULL) < 0) {
                ++bad;
                continue;
            }
            ++checked;
            const double allowed = shared[v] ? fmax(4 * tol[f], 1e-7 * diag) : 1e-9 * diag;
            if (!shared[v] && d > worst_inside) worst_inside = d;
            if (d > allowed) ++bad;
        }
    }
    CHECK(checked > 0);
    CHECK_MSG(bad == 0, "%zu boundary node checks off their face (worst inside a face %.3g)", bad,
              worst_inside);
    free(tol);
    free(face);
    free(shared);
}

static cm_status mesh_it(cm_context *ctx, const cm_cad_model *model, int mesher, int fallback,
                         double size, double min_sj, double max_tets, cm_mesh **m)
{
    cm_tetmesh_options opt;
    cm_tetmesh_options_init(&opt);
    opt.mesher = mesher;
    opt.fallback = fallback;
    opt.size = size;
    opt.min_sj = min_sj;
    opt.max_tets = max_tets;
    /* the optimisation only where the judgement depends on it (the real files): seconds */
    opt.optimize = size == 0;
    n_warnings = 0;
    warning[0] = '\0';
    return cm_tetmesh_create(ctx, model, &opt, m);
}

static size_t tets_of(const cm_mesh *m) { return m ? cm_mesh_count_dim(m, 3) : 0; }

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    char path[4096], path2[4096], work[4096];
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_context_set_log(ctx, on_log, NULL);
    cm_context_set_threads(ctx, 1);

    /* the screw and the loose box: gmsh alone, accepted, its nodes put on our faces */
    const char *gmsh_files[2] = {"occt/screw.step", NULL};
    snprintf(work, sizeof work, "%s/cad/loose_box.step", argv[2]);
    for (int k = 0; k < 2; ++k) {
        if (k == 0) snprintf(path, sizeof path, "%s/%s", argv[1], gmsh_files[0]);
        else snprintf(path, sizeof path, "%s", work);
        cm_cad_model *model = NULL;
        CHECK_MSG(cm_cad_read(ctx, path, NULL, &model) >= 0, "%s", cm_context_message(ctx));
        if (!model) continue;
        double largest = 0;
        cm_cad_counts counts;
        cm_cad_get_counts(model, &counts);
        double *tol = calloc((size_t)counts.faces, sizeof *tol);
        CHECK(cm_cad_face_tolerances(ctx, model, tol, &largest) == CM_OK);
        /* the files' tolerances are what the old 1e-7 x diagonal check refused */
        CHECK_MSG(largest >= 1e-4, "%s: largest tolerance %g", path, largest);
        free(tol);
        cm_mesh *m = NULL;
        const cm_status s = mesh_it(ctx, model, CM_MESHER_GMSH, 0, 0, 0, 0, &m);
        CHECK_MSG(s == CM_OK, "%s: %s", path, cm_context_message(ctx));
        CHECK_MSG(n_warnings == 0, "%s: %s", path, warning);
        if (m) {
            CHECK(cm_mesh_validate(ctx, m, "gmsh") == CM_OK);
            check_on_faces(ctx, model, m);
        }
        cm_mesh_destroy(&m);
        cm_cad_destroy(&model);
    }

    /* the fallback: the file is overwritten by another geometry after it was read */
    snprintf(path, sizeof path, "%s/cad/bore_a.step", argv[1]);
    snprintf(path2, sizeof path2, "%s/cad/bore_b.step", argv[1]);
    snprintf(work, sizeof work, "%s/tetmesh_real_changed.step", argv[2]);
    CHECK(copy_file(path, work));
    cm_cad_model *model = NULL;
    CHECK_MSG(cm_cad_read(ctx, work, NULL, &model) >= 0, "%s", cm_context_message(ctx));
    CHECK(copy_file(path2, work));
    if (model) {
        cm_mesh *m = NULL;
        cm_status s = mesh_it(ctx, model, CM_MESHER_GMSH, 1, 0.8, 0, 0, &m);
        CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
        CHECK_MSG(n_warnings == 1, "%d warnings: %s", n_warnings, warning);
        CHECK_MSG(strstr(warning, "gmsh could not mesh it (") && strstr(warning, "); meshed with TetGen"),
                  "%s", warning);
        CHECK(tets_of(m) > 0);
        cm_mesh_destroy(&m);
        s = mesh_it(ctx, model, CM_MESHER_GMSH, 0, 0.8, 0, 0, &m);
        CHECK_MSG(s == CM_ERR_MISMATCH && m == NULL, "%d: %s", (int)s, cm_context_message(ctx));
        CHECK_MSG(strstr(cm_context_message(ctx), "(the other mesher: --mesher tetgen)"), "%s",
                  cm_context_message(ctx));
        cm_cad_destroy(&model);
    }

    /* the judgement: a floor no tet mesh reaches */
    snprintf(path, sizeof path, "%s/models/bore_0.step", argv[1]);
    CHECK_MSG(cm_cad_read(ctx, path, NULL, &model) >= 0, "%s", cm_context_message(ctx));
    if (model) {
        cm_mesh *m = NULL;
        cm_status s = mesh_it(ctx, model, CM_MESHER_TETGEN, 0, 0.8, 0.99, 0, &m);
        CHECK_MSG(s == CM_ERR_REJECTED && m == NULL, "%d: %s", (int)s, cm_context_message(ctx));
        CHECK_MSG(strstr(cm_context_message(ctx), "TetGen's mesh has ") &&
                      strstr(cm_context_message(ctx), "floor 0.99 or flat after the optimisation; the worst, tet "),
                  "%s", cm_context_message(ctx));
        s = mesh_it(ctx, model, CM_MESHER_TETGEN, 1, 0.8, 0.99, 0, &m);
        CHECK_MSG(s == CM_ERR_REJECTED && m == NULL, "%d: %s", (int)s, cm_context_message(ctx));
        CHECK_MSG(strstr(cm_context_message(ctx), "no mesh: TetGen: TetGen's mesh has ") &&
                      strstr(cm_context_message(ctx), "; gmsh: gmsh's mesh has "),
                  "%s", cm_context_message(ctx));

        /* the estimate within 3x, both meshers (gmsh's from its own surface mesh) */
        for (int mesher = 0; mesher < 2; ++mesher) {
            s = mesh_it(ctx, model, mesher, 0, 0.6, -INFINITY, INFINITY, &m);
            CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
            const size_t n = tets_of(m);
            cm_mesh_destroy(&m);
            s = mesh_it(ctx, model, mesher, 0, 0.6, -INFINITY, n / 3.0, &m);
            CHECK_MSG(s == CM_ERR_NOMEM, "mesher %d, %zu tets: %d %s", mesher, n, (int)s,
                      cm_context_message(ctx));
            s = mesh_it(ctx, model, mesher, 0, 0.6, -INFINITY, 3.0 * n, &m);
            CHECK_MSG(s == CM_OK, "mesher %d, %zu tets: %s", mesher, n, cm_context_message(ctx));
            cm_mesh_destroy(&m);
        }
        cm_cad_destroy(&model);
    }
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
