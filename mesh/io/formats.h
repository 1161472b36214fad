/* The per-format readers and writers (not public) and the registry of formats: only the
 * dispatcher (io.c) calls them, so that every mesh read goes through cm_mesh_validate. Adding
 * a format is one file here (its reader and writer, declared below) and one row in the
 * registry table in io.c. */
#ifndef CADMORPH_MESH_IO_FORMATS_H
#define CADMORPH_MESH_IO_FORMATS_H

#include "cadmorph/mesh.h"
#include "origin.h"

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
cm_status cm_mesh_read_cgns(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_cgns(cm_context *ctx, const cm_mesh *mesh, const char *path,
                             const cm_mesh_write_options *opt);
cm_status cm_mesh_read_foam(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_foam(cm_context *ctx, const cm_mesh *mesh, const char *path,
                             const cm_mesh_write_options *opt);
/* Fluent writes back into the file a mesh was read from only; any other mesh is refused. */
cm_status cm_mesh_read_fluent(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_fluent(cm_context *ctx, const cm_mesh *mesh, const char *path,
                               const cm_mesh_write_options *opt);
/* Whether the first bytes of a .msh are a Fluent file's rather than gmsh's. */
int cm_fluent_sniff(const char *head, size_t n);
cm_status cm_mesh_read_su2(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_su2(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt);
cm_status cm_mesh_read_nastran(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_nastran(cm_context *ctx, const cm_mesh *mesh, const char *path,
                                const cm_mesh_write_options *opt);
/* Whether a file's first bytes look like Nastran bulk data (for .dat, a generic name). */
int cm_nastran_sniff(const char *head, size_t n);
cm_status cm_mesh_read_abaqus(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_abaqus(cm_context *ctx, const cm_mesh *mesh, const char *path,
                               const cm_mesh_write_options *opt);
cm_status cm_mesh_read_exodus(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write_exodus(cm_context *ctx, const cm_mesh *mesh, const char *path,
                               const cm_mesh_write_options *opt);

/* ---- the registry ---- */

typedef cm_status (*cm_mesh_read_fn)(cm_context *ctx, const char *path, cm_mesh **mesh);
typedef cm_status (*cm_mesh_write_fn)(cm_context *ctx, const cm_mesh *mesh, const char *path,
                                      const cm_mesh_write_options *opt);

/* What a format holds (a description for listings and tests; the writers decide). */
enum {
    CM_MESH_IO_VOLUME = 1u << 0,  /* 3D cells */
    CM_MESH_IO_SURFACE = 1u << 1, /* 2D cells (and lines) */
    CM_MESH_IO_FIELDS = 1u << 2,  /* node fields */
    CM_MESH_IO_GROUPS = 1u << 3   /* physical groups (tags, and names where the format has them) */
};

typedef struct cm_mesh_format_row {
    cm_mesh_format format;
    const char *name;
    /* Recognised by extension: lower-case names without the dot, space-separated, matched
     * case-insensitively against the text after the last '.' of the last path component. */
    const char *extensions;
    /* Or by the path itself (a directory format): claims is asked first, for every path, and
     * described names the path in the list of formats. NULL for a file format. */
    int (*claims)(const char *path);
    const char *described;
    cm_mesh_read_fn read;
    cm_mesh_write_fn write;
    unsigned holds; /* CM_MESH_IO_* */
    /* For an extension that two formats share (Fluent's and gmsh's .msh): whether the first
     * bytes of a file (n of them, NUL-terminated) are this format's. The row without a test
     * is the default: it reads what no test claims and writes new files. NULL for a format
     * whose extensions are its own. */
    int (*sniff)(const char *head, size_t n);
} cm_mesh_format_row;

/* The rows, in the order cm_mesh_format_list names them; the row of a format, NULL for
 * CM_FORMAT_UNKNOWN. */
extern const cm_mesh_format_row cm_mesh_format_rows[];
extern const size_t cm_mesh_format_row_count;
const cm_mesh_format_row *cm_mesh_format_row_of(cm_mesh_format format);
/* The format a path's extension names (CM_FORMAT_UNKNOWN for none or another), without asking
 * the directory formats or the file's content: the default row of a shared extension. */
cm_mesh_format cm_mesh_format_of_extension(const char *path);

#endif
