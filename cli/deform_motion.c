/* deform's boundary motion by patch kind (deform_motion.h). */
#include "deform_motion.h"

#include <stdlib.h>
#include <string.h>

cm_status cli_deform_motion_begin(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                                  const cli_patch_motion *pm, double *disp, unsigned char *con,
                                  unsigned char *border, cli_deform_motion *dm)
{
    memset(dm, 0, sizeof *dm);
    if (pm->all_fixed) return CM_OK;
    size_t n = mesh->n_nodes;
    cm_motion_options mo;
    cli_patch_motion_options(pm, &mo);
    cm_status s = cm_boundary_motion_create(ctx, mesh, b, con, &mo, &dm->motion);
    if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
    /* nothing slides and no 2-D pair: the deformation as it always was (no correction) */
    if (s >= 0 && cm_boundary_motion_reduction(dm->motion, NULL, NULL) == CM_MOTION_3D &&
        !cm_boundary_motion_count(dm->motion, CM_MOTION_SLIDE_PLANE) &&
        !cm_boundary_motion_count(dm->motion, CM_MOTION_SLIDE_LINE) &&
        !cm_boundary_motion_count(dm->motion, CM_MOTION_SLIDE_SURFACE)) {
        cli_deform_motion_free(dm);
        return CM_OK;
    }
    if (s >= 0) {
        s = cm_boundary_motion_project(ctx, dm->motion, disp);
        if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
    }
    if (s >= 0 && !(dm->handles = malloc(3 * (n ? n : 1) * sizeof *dm->handles)))
        s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    if (s < 0) {
        cli_deform_motion_free(dm);
        return s;
    }
    memcpy(dm->handles, disp, 3 * n * sizeof *disp);
    for (size_t i = 0; i < n; ++i) {
        cm_motion_kind k = cm_boundary_motion_kind(dm->motion, i);
        if (k == CM_MOTION_PRESCRIBED) con[i] = 1;
        if (k != CM_MOTION_FIXED) border[i] = 0;
    }
    return CM_OK;
}

cm_status cli_deform_motion_end(cm_context *ctx, const cm_mesh *mesh, cli_deform_motion *dm,
                                double *disp)
{
    if (!dm->motion) return CM_OK;
    for (size_t i = 0; i < mesh->n_nodes; ++i)
        if (cm_boundary_motion_kind(dm->motion, i) == CM_MOTION_PRESCRIBED)
            memcpy(disp + 3 * i, dm->handles + 3 * i, 3 * sizeof *disp);
    cm_status s = cm_warp_correct(ctx, mesh, dm->motion, disp, NULL);
    if (s == CM_WARNING) s = CM_OK; /* the out-of-plane warning was given by begin */
    return s;
}

void cli_deform_motion_free(cli_deform_motion *dm)
{
    cm_boundary_motion_destroy(&dm->motion);
    free(dm->handles);
    dm->handles = NULL;
}
