/* Design velocities (morph.h, docs/DESIGN.md "Gradients"): the boundary positions of the
 * surface morph onto a target without a volume morph, differences of them, and the warp's
 * forward and reverse products with the morpher's shared factorisation. The absolute morph
 * of one increment is X(G') = X_M + J (B(G') - B_M), linear in the boundary motion, so its
 * derivative along a parameter is J applied to the derivative of the boundary positions. */
#include "morpher_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static cm_status usable(cm_context *ctx, const cm_morpher *mp, const char *fn)
{
    if (!mp->nodes)
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: the last cm_morpher_rebase failed; rebase "
                        "again first", fn);
    return CM_OK;
}

cm_status cm_morpher_boundary(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target,
                              double *out_xyz)
{
    if (!mp || !target || !out_xyz)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_boundary: NULL input");
    cm_status s = usable(ctx, mp, "cm_morpher_boundary");
    if (s < 0) return s;
    if (target != mp->g) {
        s = cm_cad_compare(ctx, mp->g, target, 5);
        if (s < 0) return cm_error_prefix(ctx, s, "the target does not correspond to G");
    }
    s = cm_morpher_surface_positions(ctx, mp, target, mp->opt.method.surface, mp->bnew);
    if (s < 0) return s;
    const cm_surface_nodes *nd = mp->nodes;
    memcpy(out_xyz, mp->mesh->xyz, 3 * mp->mesh->n_nodes * sizeof *out_xyz);
    for (size_t i = 0; i < nd->n; ++i)
        memcpy(out_xyz + 3 * nd->node[i], mp->bnew + 3 * i, 3 * sizeof *out_xyz);
    return s;
}

cm_status cm_morpher_warp_forward(cm_context *ctx, cm_morpher *mp, double *disp)
{
    return cm_morpher_warp_forward_many(ctx, mp, 1, disp);
}

cm_status cm_morpher_warp_forward_many(cm_context *ctx, cm_morpher *mp, size_t k, double *disp)
{
    if (!mp || !disp) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_warp_forward: NULL input");
    cm_status s = usable(ctx, mp, "cm_morpher_warp_forward");
    if (s < 0) return s;
    const cm_warp_options *wo = &mp->opt.method.warp;
    /* for a method that is not linear, a difference quotient carried by apply would not be
     * the derivative of the morph */
    if (!cm_warp_method_is_linear(wo->method))
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "warp method %s is not linear in the boundary motion: its apply is no "
                        "forward product",
                        cm_warp_method_name(wo->method));
    cm_warp *w = NULL;
    double t = 0;
    s = cm_morpher_shared_warp(ctx, mp, wo, &w, &t);
    if (s < 0) return s;
    return k == 1 ? cm_warp_apply(ctx, w, disp) : cm_warp_apply_many(ctx, w, k, disp);
}

cm_status cm_morpher_warp_transpose(cm_context *ctx, cm_morpher *mp, const double *v, double *out)
{
    if (!mp || !v || !out)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_warp_transpose: NULL input");
    cm_status s = usable(ctx, mp, "cm_morpher_warp_transpose");
    if (s < 0) return s;
    cm_warp *w = NULL;
    double t = 0;
    s = cm_morpher_shared_warp(ctx, mp, &mp->opt.method.warp, &w, &t);
    if (s < 0) return s;
    return cm_warp_apply_transpose(ctx, w, v, out);
}

cm_status cm_morpher_velocity(cm_context *ctx, cm_morpher *mp, const double *plus, double dp_plus,
                              const double *minus, double dp_minus, int interior, double *out)
{
    if (!mp || !plus || !out)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_velocity: NULL input");
    const double dp = dp_plus - dp_minus;
    if (!isfinite(dp) || dp == 0)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_morpher_velocity: the two parameter values must differ (got %g and %g)",
                        dp_plus, dp_minus);
    cm_status s = usable(ctx, mp, "cm_morpher_velocity");
    if (s < 0) return s;
    if (!minus) minus = mp->mesh->xyz;
    const cm_surface_nodes *nd = mp->nodes;
    memset(out, 0, 3 * mp->mesh->n_nodes * sizeof *out);
    /* boundary nodes on G: the difference quotient; off G (kept fixed) and interior: 0 */
    for (size_t i = 0; i < nd->n; ++i) {
        const int64_t k = nd->node[i];
        for (int c = 0; c < 3; ++c)
            out[3 * k + c] = (plus[3 * k + c] - minus[3 * k + c]) / dp;
    }
    return interior ? cm_morpher_warp_forward(ctx, mp, out) : CM_OK;
}

const unsigned char *cm_morpher_boundary_flags(const cm_morpher *mp)
{
    return mp ? mp->fixed : NULL;
}
