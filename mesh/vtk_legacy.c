/* Placeholder until implemented: every entry point reports CM_ERR_UNSUPPORTED. */
#include "cadmorph/mesh.h"

cm_status cm_mesh_read_vtk(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    (void)mesh; (void)path;
    return cm_error(ctx, CM_ERR_UNSUPPORTED, "not implemented yet");
}

cm_status cm_mesh_write_vtk(cm_context *ctx, const cm_mesh *mesh, const char *path, const cm_mesh_write_options *opt)
{
    (void)mesh; (void)path; (void)opt;
    return cm_error(ctx, CM_ERR_UNSUPPORTED, "not implemented yet");
}

