/* The per-format readers and writers (not public): only the dispatcher (io.c) calls them,
 * so that every mesh read goes through cm_mesh_validate. Adding a format is one file here
 * and one case in io.c. */
#ifndef CADMORPH_MESH_IO_FORMATS_H
#define CADMORPH_MESH_IO_FORMATS_H

#include "cadmorph/mesh.h"

/* The frame of a reader that parses a file held in memory: reads path whole, gives parse the
 * bytes and an empty mesh, and returns the mesh in *mesh (destroyed on failure, *mesh NULL).
 * fn names the reader in the message for NULL arguments. */
typedef cm_status (*cm_mesh_parse_fn)(cm_context *ctx, const char *path, const char *data,
                                      size_t size, cm_mesh *m);
cm_status cm_mesh_read_whole(cm_context *ctx, const char *fn, const char *path,
                             cm_mesh_parse_fn parse, cm_mesh **mesh);

cm_status cm_mesh_read_msh(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_msh(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt);
cm_status cm_mesh_read_vtu(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_vtu(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt);
cm_status cm_mesh_read_vtk(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_vtk(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt);
cm_status cm_mesh_read_medit(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_medit(cm_context *ctx, const cm_mesh *mesh, const char *path,
                              const cm_mesh_write_options *opt);
cm_status cm_mesh_read_obj(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_obj(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt);
cm_status cm_mesh_read_off(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_off(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt);
cm_status cm_mesh_read_stl(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_stl(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt);
cm_status cm_mesh_read_foam(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_foam(cm_context *ctx, const cm_mesh *mesh, const char *path,
                             const cm_mesh_write_options *opt);

#endif
