/* Placeholder until implemented: every entry point reports CM_ERR_UNSUPPORTED. */
#include "cadmorph/mesh.h"

cm_status cm_mesh_read_msh(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    (void)mesh; (void)path;
    return cm_error(ctx, CM_ERR_UNSUPPORTED, "not implemented yet");
}

