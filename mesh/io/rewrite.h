/* Writing a mesh back into the text (or binary) file it was read from, changing only the bytes
 * that hold node coordinates (not public; docs/DESIGN.md, "Writing back into the file a mesh
 * came from"). A reader records, for every file it read, where each node's coordinates are:
 * spans in file order. The writer reads the files again as a stream, copies every byte outside
 * the spans and lets the format write each span anew from the node's new coordinates. A file
 * that changed since it was read is refused.
 *
 * Included files (Abaqus *INCLUDE, Nastran INCLUDE) are written beside the output under the
 * name the including file gives them, so that the written deck reads as the original did; one
 * that would land on its own source is left alone when it holds no coordinates and refused
 * when it does (the original deck would silently change). */
#ifndef CADMORPH_MESH_IO_REWRITE_H
#define CADMORPH_MESH_IO_REWRITE_H

#include "cadmorph/mesh.h"

/* The identity of a file when it was read (size, modification time): writing back into a copy
 * of a file that changed since is refused. */
typedef struct cm_file_stamp {
    int64_t size, sec, nsec;
} cm_file_stamp;

/* path's stamp now; CM_ERR_IO naming the file when it cannot be examined. */
cm_status cm_file_stamp_take(cm_context *ctx, const char *path, cm_file_stamp *stamp);

/* For the formats written back through their own library (CGNS, Exodus II): opens the
 * temporary output beside path (cm_outfile_open) and copies source into it, refusing a source
 * that changed since stamp. The caller rewrites the coordinates in out->tmp through its
 * library, then commits or aborts out. */
cm_status cm_rewrite_copy_open(cm_context *ctx, const char *source, const cm_file_stamp *stamp,
                               const char *path, cm_outfile *out);

typedef struct cm_rewrite_span {
    int64_t offset, length; /* bytes [offset, offset + length) of the file */
    int64_t node;           /* the mesh node whose coordinates they hold */
    int64_t aux;            /* the format's own (a coordinate system, a layout) */
} cm_rewrite_span;

typedef struct cm_rewrite_file {
    char *path;      /* the file as read */
    char *name;      /* NULL for the main file (written to the output path), else the name the
                        including file gives it, relative to the output's directory */
    cm_file_stamp stamp;                 /* its identity when read */
    size_t n_spans, cap_spans;
    cm_rewrite_span *spans; /* in file order, not overlapping */
} cm_rewrite_file;

typedef struct cm_rewrite_source {
    size_t n_files;
    cm_rewrite_file *files; /* files[0] is the main file */
    void *format;           /* the format's own record, for its emit function */
    void (*free_format)(void *format);
} cm_rewrite_source;

/* An empty source (NULL when out of memory), and its destructor (the signature of an origin's
 * free_state, origin.h). */
cm_rewrite_source *cm_rewrite_source_new(void);
void cm_rewrite_source_free(void *source);

/* Adds a file, its identity taken now; *index (may be NULL) receives its index. name: NULL for
 * the main file (the first one added), else as above. */
cm_status cm_rewrite_add_file(cm_context *ctx, cm_rewrite_source *src, const char *path,
                              const char *name, size_t *index);
/* Appends a span to file `file`; spans must come in file order without overlapping. */
cm_status cm_rewrite_add_span(cm_context *ctx, cm_rewrite_source *src, size_t file, int64_t offset,
                              int64_t length, int64_t node, int64_t aux);

/* A growing output buffer (the emit functions' and the OpenFOAM writer's), kept NUL-terminated;
 * fail is set (and stays set) when memory runs out. */
typedef struct cm_rewrite_buf {
    char *d;
    size_t n, cap;
    int fail;
} cm_rewrite_buf;

void cm_rewrite_put(cm_rewrite_buf *b, const void *s, size_t n);
void cm_rewrite_putf(cm_rewrite_buf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Appends to out what span (whose bytes as read are original, span->length of them, followed by
 * a NUL) becomes when its node is at xyz. A refusal (a value the field cannot hold, say) is an
 * error status with a message naming the file and the place. Called on several threads at once
 * (each with its own ctx and out): it may only read src and file. */
typedef cm_status (*cm_rewrite_emit_fn)(cm_context *ctx, const cm_rewrite_source *src,
                                        const cm_rewrite_file *file, const cm_rewrite_span *span,
                                        const char *original, const double xyz[3],
                                        cm_rewrite_buf *out);

/* Writes the mesh's coordinates into copies of the source's files: the main file to path, the
 * included ones beside it. Each goes through a temporary file renamed only when all are
 * written. */
cm_status cm_rewrite_write(cm_context *ctx, const cm_rewrite_source *src, const cm_mesh *mesh,
                           const char *path, cm_rewrite_emit_fn emit);

/* The text of a coordinate: original (n bytes, may be NULL) itself when it reads back (strtod)
 * as exactly v, so that a node that did not move keeps its bytes; else the shortest of %.15g,
 * %.16g, %.17g that reads back as v. Writes a NUL-terminated string into out (cap >= 32) and
 * returns its length. */
int cm_rewrite_number(char *out, size_t cap, double v, const char *original, size_t n);

#endif
