/* Mesh file dispatch by extension and the helpers every reader and writer shares. */
#define _POSIX_C_SOURCE 200809L
#include "formats.h"
#include "foam_internal.h"

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* The format a file name's extension names (CM_FORMAT_UNKNOWN for none or another). */
static cm_mesh_format format_of_extension(const char *path)
{
    const char *dot = path ? strrchr(path, '.') : NULL;
    if (!dot || strchr(dot, '/')) return CM_FORMAT_UNKNOWN;
    char ext[8] = {0};
    if (strlen(dot + 1) >= sizeof ext) return CM_FORMAT_UNKNOWN;
    for (size_t i = 0; dot[1 + i]; ++i) ext[i] = (char)tolower((unsigned char)dot[1 + i]);
    if (!strcmp(ext, "msh")) return CM_FORMAT_MSH;
    if (!strcmp(ext, "vtu")) return CM_FORMAT_VTU;
    if (!strcmp(ext, "vtk")) return CM_FORMAT_VTK;
    if (!strcmp(ext, "mesh")) return CM_FORMAT_MEDIT;
    if (!strcmp(ext, "obj")) return CM_FORMAT_OBJ;
    if (!strcmp(ext, "off")) return CM_FORMAT_OFF;
    if (!strcmp(ext, "stl")) return CM_FORMAT_STL;
    return CM_FORMAT_UNKNOWN;
}

/* An OpenFOAM case or polyMesh directory: a trailing '/', or (unless the name ends in a mesh
 * file extension) an existing directory, a last component named polyMesh, or one without an
 * extension that is not an existing file. */
int cm_foam_is_path(const char *path)
{
    if (!path || !*path) return 0;
    size_t l = strlen(path);
    if (path[l - 1] == '/') return 1;
    /* a name with a file format's extension stays that format, even if it is a directory */
    if (format_of_extension(path) != CM_FORMAT_UNKNOWN) return 0;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    struct stat st;
    if (stat(path, &st) == 0) return S_ISDIR(st.st_mode);
    return strcmp(base, "polyMesh") == 0 || strchr(base, '.') == NULL;
}

cm_mesh_format cm_mesh_format_from_path(const char *path)
{
    return cm_foam_is_path(path) ? CM_FORMAT_FOAM : format_of_extension(path);
}

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

const char *cm_mesh_format_list(void)
{
    return ".msh .vtu .vtk .mesh .obj .off .stl, or an OpenFOAM case directory";
}

void cm_mesh_write_options_init(cm_mesh_write_options *opt)
{
    if (!opt) return;
    opt->msh_version = 41;
    opt->binary = 1;
    opt->compress = 1;
    opt->appended = 0;
}

static cm_status unknown_extension(cm_context *ctx, const char *fn, const char *path)
{
    return cm_error(ctx, CM_ERR_UNSUPPORTED,
                    "%s: %s: unknown mesh extension (expected one of %s)", fn,
                    path ? path : "(null)", cm_mesh_format_list());
}

cm_status cm_mesh_read(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read: mesh is NULL");
    *mesh = NULL;
    cm_status s;
    switch (cm_mesh_format_from_path(path)) {
    case CM_FORMAT_MSH: s = cm_mesh_read_msh(ctx, path, mesh); break;
    case CM_FORMAT_VTU: s = cm_mesh_read_vtu(ctx, path, mesh); break;
    case CM_FORMAT_VTK: s = cm_mesh_read_vtk(ctx, path, mesh); break;
    case CM_FORMAT_MEDIT: s = cm_mesh_read_medit(ctx, path, mesh); break;
    case CM_FORMAT_OBJ: s = cm_mesh_read_obj(ctx, path, mesh); break;
    case CM_FORMAT_OFF: s = cm_mesh_read_off(ctx, path, mesh); break;
    case CM_FORMAT_STL: s = cm_mesh_read_stl(ctx, path, mesh); break;
    case CM_FORMAT_FOAM: s = cm_mesh_read_foam(ctx, path, mesh); break;
    default: return unknown_extension(ctx, "cm_mesh_read", path);
    }
    if (s < 0) return s;
    /* Every reader's output goes through the same checks, so no reader can let an out-of-range
     * index or a NaN through to the algorithms. */
    cm_status v = cm_mesh_validate(ctx, *mesh, path);
    if (v != CM_OK) {
        cm_mesh_destroy(mesh);
        return v;
    }
    return s;
}

cm_status cm_mesh_write(cm_context *ctx, const cm_mesh *mesh, const char *path,
                        const cm_mesh_write_options *opt)
{
    cm_mesh_write_options defaults;
    cm_mesh_write_options_init(&defaults);
    if (!opt) opt = &defaults;
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: mesh is NULL");
    switch (cm_mesh_format_from_path(path)) {
    case CM_FORMAT_MSH: return cm_mesh_write_msh(ctx, mesh, path, opt);
    case CM_FORMAT_VTU: return cm_mesh_write_vtu(ctx, mesh, path, opt);
    case CM_FORMAT_VTK: return cm_mesh_write_vtk(ctx, mesh, path, opt);
    case CM_FORMAT_MEDIT: return cm_mesh_write_medit(ctx, mesh, path, opt);
    case CM_FORMAT_OBJ: return cm_mesh_write_obj(ctx, mesh, path, opt);
    case CM_FORMAT_OFF: return cm_mesh_write_off(ctx, mesh, path, opt);
    case CM_FORMAT_STL: return cm_mesh_write_stl(ctx, mesh, path, opt);
    case CM_FORMAT_FOAM: return cm_mesh_write_foam(ctx, mesh, path, opt);
    default: return unknown_extension(ctx, "cm_mesh_write", path);
    }
}
