/* Tet meshing of a STEP solid (meshgen/tetmesh.cpp over cad/triangulate.cpp): the bore
 * benchmark model at t = 0, written by gmsh, meshed at two sizes. Invariants: no inverted
 * tet; every boundary node on the analytic bore (a box face or the bore's cylinder, 1e-9);
 * the boundary triangles are exactly the tets' free faces, outward (their divergence-theorem
 * volume equals the tets'); tet volume = BRepGProp volume = 4*4*2 - pi*0.6^2*2 (1e-2 rel.);
 * more nodes for a smaller size; also with the surface kept as OpenCASCADE made it; each
 * boundary triangle's nodes on the CAD face its tag names (1e-9); the same with gmsh. And a STEP without a solid is refused. */
#include "cadmorph/tetmesh.h"
#include "test_mesh.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* distance of p from the bore's boundary: box faces (within the face) or the cylinder */
static double bore_distance(const double *p)
{
    const double r = hypot(p[0], p[1]);
    double d = fabs(r - 0.6);
    if (p[2] < -1e-9 || p[2] > 2 + 1e-9) d = INFINITY; /* beyond the block: on nothing */
    const double box[6] = {fabs(p[0] + 2), fabs(p[0] - 2), fabs(p[1] + 2),
                           fabs(p[1] - 2), fabs(p[2]),     fabs(p[2] - 2)};
    for (int k = 0; k < 6; ++k)
        if (box[k] < d && r >= 0.6 - 1e-9) d = box[k];
    return d;
}

static size_t mesh_and_check(cm_context *ctx, const cm_cad_model *model, double size, int preserve,
                             double cad_volume, int mesher)
{
    cm_tetmesh_options opt;
    cm_tetmesh_options_init(&opt);
    opt.size = size;
    opt.preserve_surface = preserve;
    opt.mesher = mesher;
    cm_mesh *m = NULL;
    cm_status s = cm_tetmesh_create(ctx, model, &opt, &m);
    CHECK_MSG(s == CM_OK, "size %g: %s", size, cm_context_message(ctx));
    if (s < 0) return 0;
    CHECK(cm_mesh_validate(ctx, m, "bore") == CM_OK);

    double *sj = malloc(m->n_cells * sizeof *sj);
    CHECK(cm_mesh_quality(ctx, m, sj) == CM_OK);
    cm_quality_stats all;
    CHECK(cm_quality_summarize(ctx, m, sj, NULL, &all) == CM_OK);
    CHECK_MSG(all.inverted == 0 && all.min > 0, "size %g: %zu inverted, min %g", size, all.inverted,
              all.min);

    double vol = 0, div_vol = 0, worst = 0, worst_tag = 0;
    size_t n_tri = 0, n_tet = 0, bad_tags = 0;
    unsigned char *on_boundary = calloc(m->n_nodes, 1);
    const double origin[3] = {0, 0, 1};
    for (size_t c = 0; c < m->n_cells; ++c) {
        const int64_t *n = m->conn + m->offset[c];
        if (m->type[c] == CM_CELL_TET4) {
            ++n_tet;
            vol += test_tet_volume(&m->xyz[3 * n[0]], &m->xyz[3 * n[1]], &m->xyz[3 * n[2]], &m->xyz[3 * n[3]]);
        } else if (m->type[c] == CM_CELL_TRI3) {
            ++n_tri;
            /* outward triangles: the cones from any point sum to the enclosed volume */
            div_vol += test_tet_volume(origin, &m->xyz[3 * n[0]], &m->xyz[3 * n[1]], &m->xyz[3 * n[2]]);
            for (int k = 0; k < 3; ++k) on_boundary[n[k]] = 1;
            if (m->entity[c] < 1 || m->entity[c] > 7) {
                ++bad_tags;
                continue;
            }
            /* the tag names the CAD face the triangle lies on (what cadmorph morph needs); one
             * triangle in 8 (an unseeded projection costs a grid search) */
            if (n_tri % 8) continue;
            double p[9], d[3];
            for (int k = 0; k < 3; ++k) memcpy(&p[3 * k], &m->xyz[3 * n[k]], sizeof(double) * 3);
            CHECK(cm_cad_project_face(ctx, model, m->entity[c] - 1, p, 3, NULL, NULL, d, NULL) == CM_OK);
            for (int k = 0; k < 3; ++k)
                if (d[k] > worst_tag) worst_tag = d[k];
        }
    }
    size_t n_bnodes = 0;
    for (size_t i = 0; i < m->n_nodes; ++i) {
        if (!on_boundary[i]) continue;
        ++n_bnodes;
        const double d = bore_distance(&m->xyz[3 * i]);
        if (d > worst) worst = d;
    }
    CHECK_MSG(worst <= 1e-9, "size %g: a boundary node is %g off the bore", size, worst);
    CHECK(bad_tags == 0);
    CHECK_MSG(worst_tag <= 1e-9, "%s size %g: a boundary node is %g off the face of its triangle",
              mesher == CM_MESHER_GMSH ? "gmsh" : "TetGen", size, worst_tag);
    CHECK_NEAR(vol, cad_volume, 1e-2 * cad_volume);
    CHECK_NEAR(div_vol, vol, 1e-9 * vol);

    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    if (b) {
        CHECK_MSG(b->n_faces == n_tri, "%zu free tet faces, %zu boundary triangles", b->n_faces, n_tri);
        CHECK(b->n_nodes == n_bnodes);
        CHECK(b->n_components == 1);
    }
    printf("%s size %g%s: %zu nodes, %zu tets, %zu triangles, min SJ %g, volume %.6f, "
           "max boundary distance %g\n", mesher == CM_MESHER_GMSH ? "gmsh" : "TetGen", size, preserve ? " (surface preserved)" : "", m->n_nodes, n_tet, n_tri, all.min, vol, worst);
    const size_t nodes = m->n_nodes;
    cm_mesh_boundary_destroy(&b);
    free(on_boundary);
    free(sj);
    cm_mesh_destroy(&m);
    return nodes;
}

int main(int argc, char **argv)
{
    if (argc < 2) return 2;
    char path[4096];
    cm_context *ctx = NULL;
    cm_context_create(&ctx);

    snprintf(path, sizeof path, "%s/models/bore_0.step", argv[1]);
    cm_cad_model *model = NULL;
    cm_status s = cm_cad_read(ctx, path, NULL, &model);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    if (s >= 0) {
        double cad_volume = 0;
        CHECK(cm_cad_volume(ctx, model, &cad_volume) == CM_OK);
        CHECK_NEAR(cad_volume, 32.0 - M_PI * 0.36 * 2.0, 1e-9 * 32.0);

        /* the surface alone: watertight, one node per CAD vertex first */
        cm_cad_triangulation *t = NULL;
        cm_cad_triangulate_options topt;
        cm_cad_triangulate_options_init(&topt);
        topt.size = 0.4;
        CHECK(cm_cad_triangulate(ctx, model, &topt, &t) == CM_OK);
        if (t) {
            CHECK(t->n_open_edges == 0);
            CHECK(t->n_nodes > 10 && t->node_dim[0] == 0 && t->node_dim[9] == 0 && t->node_dim[10] != 0);
        }
        cm_cad_triangulation_destroy(&t);

        const size_t coarse = mesh_and_check(ctx, model, 0.4, 0, cad_volume, CM_MESHER_TETGEN);
        const size_t fine = mesh_and_check(ctx, model, 0.25, 0, cad_volume, CM_MESHER_TETGEN);
        /* OpenCASCADE's own surface nodes, unrefined by TetGen */
        mesh_and_check(ctx, model, 0.25, 1, cad_volume, CM_MESHER_TETGEN);
        /* (0.4 / 0.25)^3 = 4.1 times the nodes in theory; ask for 1.5 */
        CHECK_MSG(fine > 1.5 * coarse, "%zu nodes at size 0.25, %zu at 0.4", fine, coarse);
        /* gmsh, after the OpenMP loops above (optimisation, quality): its child must not
         * wait for the parent's thread pool */
        const size_t gcoarse = mesh_and_check(ctx, model, 0.4, 0, cad_volume, CM_MESHER_GMSH);
        const size_t gfine = mesh_and_check(ctx, model, 0.25, 0, cad_volume, CM_MESHER_GMSH);
        CHECK_MSG(gfine > 1.5 * gcoarse, "gmsh: %zu nodes at size 0.25, %zu at 0.4", gfine, gcoarse);
    }
    cm_cad_destroy(&model);

    /* a face without a solid */
    snprintf(path, sizeof path, "%s/models/sheet.step", argv[1]);
    s = cm_cad_read(ctx, path, NULL, &model);
    CHECK(s >= 0);
    if (s >= 0) {
        cm_mesh *m = (cm_mesh *)1;
        s = cm_tetmesh_create(ctx, model, NULL, &m);
        CHECK(s == CM_ERR_UNSUPPORTED && m == NULL);
        CHECK(strstr(cm_context_message(ctx), "no solid") != NULL);
    }
    cm_cad_destroy(&model);
    cm_mesh *m = (cm_mesh *)1;
    CHECK(cm_tetmesh_create(ctx, NULL, NULL, &m) == CM_ERR_ARGUMENT && m == NULL);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
