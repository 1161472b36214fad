// Volume moments of a model's solids (BRepGProp): volume, centroid and centred second
// moments. Under an affine map x -> A x + b they transform covariantly (V' = |det A| V,
// c' = A c + b, S' = A S A^T), which the surface morph uses to find an affine edit that the
// vertices alone cannot determine (docs/DESIGN.md, "Affine edits").
#include "cad_internal.hxx"

#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <gp_Mat.hxx>

#include <cmath>

extern "C" cm_status cm_cad_volume_moments(cm_context *ctx, const cm_cad_model *model,
                                           double *volume, double *centroid, double *second)
{
    const char *fn = "cm_cad_volume_moments";
    if (!model || !volume || !centroid || !second)
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL model or output", fn);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        if (model->counts.solids == 0)
            return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: the model has no solid", fn);
        GProp_GProps props;
        // adaptive integration, with a bound on the relative error per face (the default
        // Gauss rule has none)
        BRepGProp::VolumeProperties(model->shape, props, 1e-7, Standard_True);
        const double v = props.Mass();
        if (!(std::fabs(v) > 0) || !std::isfinite(v))
            return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: the solids enclose no volume", fn);
        const gp_Pnt c = props.CentreOfMass();
        // MatrixOfInertia is central: I = int(|r|^2 E - r r^T), so int(r r^T) = tr(I)/2 E - I
        const gp_Mat in = props.MatrixOfInertia();
        const double half_trace = (in(1, 1) + in(2, 2) + in(3, 3)) / 2;
        *volume = std::fabs(v);
        centroid[0] = c.X(), centroid[1] = c.Y(), centroid[2] = c.Z();
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                second[3 * i + j] = ((i == j ? half_trace : 0) - in(i + 1, j + 1)) / v;
        return CM_OK;
    });
}
