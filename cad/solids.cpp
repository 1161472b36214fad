// Solids that touch, overlap or nest: several solids in one STEP file are meshed together, and
// TetGen cannot take two solids that share or cross faces (its error path crashes), so they
// are found here first, with OpenCASCADE's exact distance between the solids.
#include "cad_internal.hxx"

#include <BRepBndLib.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <Bnd_Box.hxx>
#include <TopExp.hxx>

#include <cmath>

extern "C" cm_status cm_cad_check_solids_apart(cm_context *ctx, const cm_cad_model *model)
{
    const char *fn = "cm_cad_check_solids_apart";
    if (!model) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: model is NULL", fn);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        TopTools_IndexedMapOfShape solids;
        TopExp::MapShapes(model->shape, TopAbs_SOLID, solids);
        const int n = solids.Extent();
        if (n < 2) return CM_OK;
        const double *b = model->bbox;
        const double diag = std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) +
                                      (b[5] - b[2]) * (b[5] - b[2]));
        const double tol = 1e-6 * diag;
        std::vector<Bnd_Box> box(n);
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
                                    fn, i + 1, j + 1);
                if (dss.InnerSolution() || dss.Value() <= tol)
                    return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                    "%s: solids %d and %d (of %d) %s: fuse them into one solid or "
                                    "mesh them separately",
                                    model->path.c_str(), i + 1, j + 1, n,
                                    dss.InnerSolution() ? "overlap (one is inside the other)"
                                                        : "touch or overlap");
            }
        return CM_OK;
    });
}
