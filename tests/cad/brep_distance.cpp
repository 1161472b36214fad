// brep_distance G.step MESH [--compare FIGURE] [--tol T]
//
// An independent measurement of how far a mesh's boundary nodes lie from a CAD model: the
// STEP file is read by OpenCASCADE's own STEPControl_Reader (millimetres, as cadmorph reads by
// default) and every boundary node's distance to the shape comes from
// BRepExtrema_DistShapeShape, which shares no code with cadmorph's sampling, kD-tree or Newton
// projection. Only the mesh is read by cadmorph (cm_mesh_read, cm_mesh_boundary_create).
//
// Prints "max_distance=<d> diagonal=<D> ratio=<d/D> node=<i>". With --compare FIGURE (the
// largest distance a cadmorph command reported for the same nodes and model), exits 1 unless
// |FIGURE - d| <= T x D (T default 1e-9): the reported figure must measure what it says.
#include "cadmorph/core.h"
#include "cadmorph/mesh.h"

#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <Bnd_Box.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Reader.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Vertex.hxx>
#include <gp_Pnt.hxx>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

int main(int argc, char **argv)
{
    if (argc < 3) {
        std::fprintf(stderr, "usage: brep_distance G.step MESH [--compare FIGURE] [--tol T]\n");
        return 2;
    }
    double figure = -1, tol = -1;
    for (int i = 3; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--compare")) figure = std::atof(argv[i + 1]);
        else if (!std::strcmp(argv[i], "--tol")) tol = std::atof(argv[i + 1]);
        else {
            std::fprintf(stderr, "brep_distance: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    Interface_Static::SetCVal("xstep.cascade.unit", "MM");
    STEPControl_Reader reader;
    if (reader.ReadFile(argv[1]) != IFSelect_RetDone || reader.TransferRoots() == 0) {
        std::fprintf(stderr, "brep_distance: cannot read %s\n", argv[1]);
        return 2;
    }
    TopoDS_Shape shape = reader.OneShape();
    Bnd_Box box;
    BRepBndLib::AddOptimal(shape, box, Standard_False, Standard_False);
    double x0, y0, z0, x1, y1, z1;
    box.Get(x0, y0, z0, x1, y1, z1);
    const double diag = std::sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0) +
                                  (z1 - z0) * (z1 - z0));

    cm_context *ctx = nullptr;
    cm_mesh *mesh = nullptr;
    cm_mesh_boundary *b = nullptr;
    if (cm_context_create(&ctx) < 0 || cm_mesh_read(ctx, argv[2], &mesh) < 0 ||
        cm_mesh_boundary_create(ctx, mesh, &b) < 0) {
        std::fprintf(stderr, "brep_distance: %s\n", ctx ? cm_context_message(ctx) : "no context");
        return 2;
    }
    BRepExtrema_DistShapeShape dss;
    dss.LoadS1(shape);
    double worst = 0;
    long worst_node = -1;
    for (size_t i = 0; i < b->n_nodes; ++i) {
        const double *p = mesh->xyz + 3 * b->nodes[i];
        TopoDS_Vertex v = BRepBuilderAPI_MakeVertex(gp_Pnt(p[0], p[1], p[2]));
        dss.LoadS2(v);
        if (!dss.Perform() || !dss.IsDone()) {
            std::fprintf(stderr, "brep_distance: BRepExtrema failed at node %lld\n",
                         (long long)b->nodes[i]);
            return 2;
        }
        if (dss.Value() > worst) worst = dss.Value(), worst_node = (long)b->nodes[i];
    }
    std::printf("max_distance=%.6g diagonal=%.6g ratio=%.3g node=%ld boundary_nodes=%zu\n", worst,
                diag, worst / diag, worst_node, b->n_nodes);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&mesh);
    cm_context_destroy(&ctx);
    if (figure >= 0) {
        tol = (tol < 0 ? 1e-9 : tol) * diag;
        if (std::fabs(figure - worst) > tol) {
            std::printf("MISMATCH: the reported figure %.6g differs from BRepExtrema's %.6g by "
                        "%.3g (> %.3g)\n",
                        figure, worst, std::fabs(figure - worst), tol);
            return 1;
        }
        std::printf("the reported figure %.6g agrees within %.3g\n", figure, tol);
    }
    return 0;
}
