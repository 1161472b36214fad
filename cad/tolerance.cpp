// The model's own tolerances (BRep_Tool::Tolerance of faces, edges and vertices): how far the
// geometry of one entity may be from that of its neighbours in the file as written. A mesh
// made from the same file by another kernel (gmsh) can be judged only to these.
#include "cad_internal.hxx"

#include <BRep_Tool.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Vertex.hxx>

#include <algorithm>

extern "C" cm_status cm_cad_face_tolerances(cm_context *ctx, const cm_cad_model *model,
                                            double *tol, double *largest)
{
    const char *fn = "cm_cad_face_tolerances";
    if (!model || !tol) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL model or output", fn);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        double all = 0;
        for (int f = 0; f < model->counts.faces; ++f) {
            const TopoDS_Face face = model->face(f);
            double t = BRep_Tool::Tolerance(face);
            for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next())
                t = std::max(t, BRep_Tool::Tolerance(TopoDS::Edge(e.Current())));
            for (TopExp_Explorer v(face, TopAbs_VERTEX); v.More(); v.Next())
                t = std::max(t, BRep_Tool::Tolerance(TopoDS::Vertex(v.Current())));
            tol[f] = t;
            all = std::max(all, t);
        }
        if (largest) *largest = all;
        return CM_OK;
    });
}
