/* Placeholder until implemented. */
#include "cadmorph/mesh.h"

cm_status cm_mesh_boundary_create(cm_context *ctx, const cm_mesh *mesh, cm_mesh_boundary **b)
{
    (void)mesh;
    *b = NULL;
    return cm_error(ctx, CM_ERR_UNSUPPORTED, "not implemented yet");
}

void cm_mesh_boundary_destroy(cm_mesh_boundary **b) { (void)b; }
