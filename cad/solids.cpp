// How the solids of a model meet. Several solids in one STEP file are meshed together: solids
// apart are meshed each on its own, solids that touch (share a face or part of one: an
// assembly) as one conformal mesh by gmsh (meshgen/tetmesh_assembly.cpp), and solids that
// overlap are refused, since no mesh can give a point to two materials. Distance first
// (OpenCASCADE's exact BRepExtrema, cheap for pairs apart), the common volume (a Boolean
// Common) only for pairs at distance 0, which it splits into touching and overlapping.
#include "cad_internal.hxx"

#include <BRepAlgoAPI_Common.hxx>
#include <BRepBndLib.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepGProp.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <TopExp.hxx>

#include <algorithm>
#include <cmath>

namespace {

double solid_volume(const TopoDS_Shape &s)
{
    GProp_GProps props;
    BRepGProp::VolumeProperties(s, props);
    return std::fabs(props.Mass());
}

double model_diagonal(const cm_cad_model *model)
{
    const double *b = model->bbox;
    return std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) +
                     (b[5] - b[2]) * (b[5] - b[2]));
}

}  // namespace

extern "C" cm_status cm_cad_check_solids_apart(cm_context *ctx, const cm_cad_model *model,
                                               int *touching)
{
    const char *fn = "cm_cad_check_solids_apart";
    if (touching) touching[0] = touching[1] = -1;
    if (!model) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: model is NULL", fn);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        TopTools_IndexedMapOfShape solids;
        TopExp::MapShapes(model->shape, TopAbs_SOLID, solids);
        const int n = solids.Extent();
        if (n < 2) return CM_OK;
        const double tol = 1e-6 * model_diagonal(model);
        std::vector<Bnd_Box> box(n);
        std::vector<double> volume(n, -1);
        for (int i = 0; i < n; ++i) {
            BRepBndLib::Add(solids(i + 1), box[i]);
            box[i].Enlarge(tol);
        }
        // all pairs whose boxes meet: files with thousands of separate solids are not what
        // cadmorph meshes, and the box test is cheap next to the distance
        for (int i = 0; i < n; ++i)
            for (int j = i + 1; j < n; ++j) {
                if (box[i].IsOut(box[j])) continue;
                BRepExtrema_DistShapeShape dss(solids(i + 1), solids(j + 1));
                if (!dss.IsDone())
                    return cm_error(ctx, CM_ERR_CAD,
                                    "%s: OpenCASCADE cannot measure the distance of solids %d and %d",
                                    fn, i, j);
                // a solid inside the other is at its distance from the other's faces, with
                // InnerSolution set: overlap whatever the distance
                if (!dss.InnerSolution() && dss.Value() > tol) continue;
                for (int k : {i, j})
                    if (volume[k] < 0) volume[k] = solid_volume(solids(k + 1));
                const double smaller = std::min(volume[i], volume[j]);
                BRepAlgoAPI_Common common(solids(i + 1), solids(j + 1));
                if (!common.IsDone() || common.HasErrors())
                    return cm_error(ctx, CM_ERR_CAD,
                                    "%s: solids %d and %d (of %d) meet, and OpenCASCADE cannot "
                                    "compute their common volume to tell whether they touch or "
                                    "overlap: fuse them into one solid, or fragment them in the CAD",
                                    model->path.c_str(), i, j, n);
                const double shared = solid_volume(common.Shape());
                // a shared face leaves a Common of no volume, up to the Boolean's fuzz: a
                // millionth of the smaller solid is far below any real overlap
                if (!(shared > 1e-6 * smaller)) {
                    if (touching && touching[0] < 0) touching[0] = i, touching[1] = j;
                    if (!touching)
                        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                        "%s: solids %d and %d (of %d) touch (share a face): "
                                        "mesh them as an assembly (cm_tetmesh_create with gmsh)",
                                        model->path.c_str(), i, j, n);
                    continue;
                }
                const bool nested = shared >= (1 - 1e-6) * smaller;
                return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                "%s: solids %d and %d (of %d) overlap (%s: common volume %.4g, "
                                "%.3g%% of the smaller): a mesh cannot give a point to two "
                                "solids; fuse them into one solid (Boolean union), or fragment "
                                "them in the CAD (BooleanFragments) into solids that only touch",
                                model->path.c_str(), i, j, n,
                                nested ? "one is inside the other" : "they cross", shared,
                                100 * shared / smaller);
            }
        return CM_OK;
    });
}

extern "C" cm_status cm_cad_face_solid(cm_context *ctx, const cm_cad_model *model, int face,
                                       int *solid)
{
    const char *fn = "cm_cad_face_solid";
    if (!model || !solid) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL model or output", fn);
    *solid = -1;
    if (face < 0 || face >= model->counts.faces)
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: face %d out of range (%d faces)", fn, face,
                        model->counts.faces);
    const int shell = model->face_shell[face];
    *solid = shell >= 0 ? model->shell_solid[shell] : -1;
    return CM_OK;
}

extern "C" cm_status cm_cad_solid_at(cm_context *ctx, const cm_cad_model *model,
                                     const double *xyz, int *solid)
{
    const char *fn = "cm_cad_solid_at";
    if (!model || !xyz || !solid) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL input", fn);
    *solid = -1;
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        TopTools_IndexedMapOfShape solids;
        TopExp::MapShapes(model->shape, TopAbs_SOLID, solids);
        const double tol = 1e-7 * model_diagonal(model);
        for (int i = 0; i < solids.Extent(); ++i) {
            BRepClass3d_SolidClassifier c(solids(i + 1), gp_Pnt(xyz[0], xyz[1], xyz[2]), tol);
            if (c.State() == TopAbs_IN) {
                *solid = i;
                break;
            }
        }
        return CM_OK;
    });
}
