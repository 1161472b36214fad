/* cm_mesh_apply_displacement (mesh.h): the node motion, the "displacement" field and the
 * quality that `cadmorph deform`, `ffd`, `optimize`, `warp` and the morph result write. */
#include "cadmorph/mesh.h"

#include <string.h>

cm_status cm_mesh_apply_displacement(cm_context *ctx, cm_mesh *mesh, const double *disp,
                                     unsigned flags, double **sj)
{
    if (sj) *sj = NULL;
    if (!mesh || !disp)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_apply_displacement: NULL input");
    size_t n = mesh->n_nodes;
    if (flags & CM_DISPLACEMENT_MOVE)
        for (size_t i = 0; i < 3 * n; ++i)
            mesh->xyz[i] += disp[i];
    double *field = NULL, *q = NULL;
    cm_status s = cm_mesh_add_field(ctx, mesh, "displacement", CM_FIELD_NODE, 3, &field);
    if (s < 0) return s;
    memcpy(field, disp, 3 * n * sizeof *field);
    if (!(flags & CM_DISPLACEMENT_QUALITY)) return CM_OK;
    s = cm_mesh_add_field(ctx, mesh, "scaled_jacobian", CM_FIELD_CELL, 1, &q);
    if (s >= 0) s = cm_mesh_quality(ctx, mesh, q);
    if (s >= 0 && sj) *sj = q;
    return s;
}
