/* Writing a mesh back into the Fluent file it was read from (rewrite.h): only the numbers of
 * the node sections change (ASCII: each coordinate's text, keeping the separators; binary:
 * the floats or doubles of each node), every other byte is copied. cadmorph writes no new
 * Fluent files: a mesh not read from one is refused (a .msh path goes to gmsh's writer). */
#define _POSIX_C_SOURCE 200809L
#include "fluent_internal.h"
#include "formats.h"
#include "rewrite.h"

#include <math.h>
#include <string.h>

/* span->aux: 0 for text, else the bytes of one binary coordinate (4 or 8) */
static cm_status emit(cm_context *ctx, const cm_rewrite_source *src, const cm_rewrite_file *file,
                      const cm_rewrite_span *span, const char *original, const double xyz[3], cm_rewrite_buf *out)
{
    (void)src;
    for (int k = 0; k < 3; ++k)
        if (!isfinite(xyz[k]))
            return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: node %lld has a coordinate that is not finite",
                            file->path, (long long)span->node + 1);
    if (span->aux == 8) {
        cm_rewrite_put(out, (const char *)xyz, 24);
        return CM_OK;
    }
    if (span->aux == 4) {
        for (int k = 0; k < 3; ++k) {
            const float f = (float)xyz[k];
            if (!isfinite(f))
                return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: node %lld: %g does not fit the file's single precision",
                                file->path, (long long)span->node + 1, xyz[k]);
            cm_rewrite_put(out, (const char *)&f, 4);
        }
        return CM_OK;
    }
    /* text: the three numbers with the blanks between them as they were */
    const char *p = original, *end = original + span->length;
    for (int k = 0; k < 3; ++k) {
        const char *b = p;
        while (p < end && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')) ++p;
        cm_rewrite_put(out, b, (size_t)(p - b));
        const char *t = p;
        while (p < end && !(*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')) ++p;
        char num[40];
        const int n = cm_rewrite_number(num, sizeof num, xyz[k], t, (size_t)(p - t));
        cm_rewrite_put(out, num, (size_t)n);
    }
    return CM_OK;
}

cm_status cm_mesh_write_fluent(cm_context *ctx, const cm_mesh *mesh, const char *path,
                               const cm_mesh_write_options *opt)
{
    (void)opt;
    const cm_rewrite_source *src = cm_mesh_origin_state(mesh, CM_FORMAT_FLUENT);
    if (!src)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_mesh_write: %s: cadmorph writes Fluent files only back into the file a mesh was read from "
                        "(node coordinates only), and this mesh was %s",
                        path, cm_mesh_origin_format(mesh) == CM_FORMAT_FLUENT
                                  ? "read from one but its nodes or cells changed since; write it as .vtu or another format"
                                  : "not read from a Fluent file; write it as .msh (gmsh) or another format");
    return cm_rewrite_write(ctx, src, mesh, path, emit);
}
