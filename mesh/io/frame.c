/* The frame every reader and writer shares: reading a file whole for a parser, and the
 * writers' default options. A leaf below the dispatcher (io.c), which calls the formats. */
#include "formats.h"

#include <stdlib.h>

cm_status cm_mesh_read_whole(cm_context *ctx, const char *fn, const char *path,
                             cm_mesh_parse_fn parse, cm_mesh **mesh)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL argument", fn);
    *mesh = NULL;
    char *data = NULL;
    size_t size = 0;
    cm_status s = cm_file_read(ctx, path, &data, &size);
    if (s != CM_OK) return s;
    cm_mesh *m = NULL;
    s = cm_mesh_create(ctx, &m);
    if (s == CM_OK) s = parse(ctx, path, data, size, m);
    free(data);
    if (s != CM_OK) {
        cm_mesh_destroy(&m);
        return s;
    }
    *mesh = m;
    return CM_OK;
}

void cm_mesh_write_options_init(cm_mesh_write_options *opt)
{
    if (!opt) return;
    opt->msh_version = 41;
    opt->binary = 1;
    opt->compress = 1;
    opt->appended = 0;
}
