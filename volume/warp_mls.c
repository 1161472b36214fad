/* The MLS warp method: deform.h's mls deformation, one constrained MLS space deformation
 * (mls.h) over the whole mesh, every component at once, with the options of
 * cm_warp_options.mls. Approximate: the constrained nodes keep their prescribed displacement
 * and the apply reports how far the field missed them.
 * Reverse product (docs/DESIGN.md, "Gradients"): the constrained MLS is linear in the
 * prescribed displacement (a penalty, not a hard constraint: eq. 14's right-hand side is
 * linear in it, its matrix, Phi and the residual blend depend only on the positions), so
 * J^T v is deform.h's transposed MLS: one solve with the kept factor. */
#include "warp_method.h"

#include "cadmorph/deform.h"

#include <stdlib.h>

static cm_status mls_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                            const unsigned char *constrained, const cm_warp_options *opt,
                            void **state)
{
    (void)b;
    cm_deform_options o;
    cm_deform_options_init(&o);
    o.method = CM_DEFORM_MLS;
    /* the defaults (gamma_f = 1000): on the pipe hex a stiffer penalty (1e4 ... 1e7) meets the
     * boundary closer but leaves a worse first cell layer (benchmarks/RESULTS.md) */
    o.mls = opt->mls;
    cm_deform *d = NULL;
    cm_status s = cm_deform_create(ctx, &o, mesh->n_nodes, mesh->xyz, constrained, mesh, &d);
    if (s < 0) return cm_error_prefix(ctx, s, "cm_warp_create");
    *state = d;
    return s;
}

static cm_status mls_apply(cm_context *ctx, void *state, double *disp, double *residual)
{
    cm_status s = cm_deform_apply(ctx, state, disp, residual);
    if (s < 0) return cm_error_prefix(ctx, s, "cm_warp_apply");
    cm_deform_stats d;
    cm_deform_get_stats(state, &d);
    const cm_mls_stats *st = &d.mls;
    cm_log(ctx, CM_LOG_DEBUG,
           "warp mls: %zu samples, %zu cubature points, %zu constrained nodes, %zu blended; "
           "residual %.3g; sample %.3f s, basis %.3f s, factor %.3f s, apply %.3f s",
           st->samples, st->cubature, st->constrained, st->blend_nodes, *residual, st->t_sample,
           st->t_basis, st->t_factor, st->t_apply);
    return s;
}

static void mls_destroy(void *state)
{
    cm_deform *d = state;
    cm_deform_destroy(&d);
}

/* MLS writes every node (warp.h: v is read where apply writes), so deform.h's J^T v over all
 * nodes is the warp's */
static cm_status mls_apply_transpose(cm_context *ctx, void *state, const double *v, double *out)
{
    cm_status s = cm_deform_apply_transpose(ctx, state, v, out);
    return s < 0 ? cm_error_prefix(ctx, s, "cm_warp_apply_transpose") : s;
}

const cm_warp_method_ops cm_warp_mls = {
    "mls", mls_create, mls_apply, mls_destroy, NULL, mls_apply_transpose, NULL, NULL};
