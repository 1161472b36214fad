/* Shared by the mesh readers and writers (not public): whole-file reading, a line-aware
 * text cursor, and output through a temporary file that is renamed only on success. */
#ifndef CADMORPH_MESH_IO_INTERNAL_H
#define CADMORPH_MESH_IO_INTERNAL_H

#include "cadmorph/mesh.h"

#include <stdio.h>

/* Reads a whole file; data is NUL-terminated (size excludes the NUL). Caller frees data. */
cm_status cm_io_read_file(cm_context *ctx, const char *path, char **data, size_t *size);

/* A cursor over text held in memory; line counts from 1. */
typedef struct cm_text {
    const char *path;
    const char *data;
    size_t size;
    size_t pos;
    long line;
} cm_text;

void cm_text_init(cm_text *t, const char *path, const char *data, size_t size);
/* Skips spaces, tabs and newlines (counting lines). Returns 0 at end of data. */
int cm_text_skip_space(cm_text *t);
/* Next whitespace-separated token: *tok points into data, *len its length; 0 at end. */
int cm_text_token(cm_text *t, const char **tok, size_t *len);
/* Next token parsed as integer / double; on failure sets a message naming path:line and
 * `what` (e.g. "node count") and returns CM_ERR_FORMAT. */
cm_status cm_text_int(cm_context *ctx, cm_text *t, const char *what, int64_t *v);
cm_status cm_text_double(cm_context *ctx, cm_text *t, const char *what, double *v);
/* Moves to the start of the next line. */
void cm_text_next_line(cm_text *t);

/* Output through path + ".tmp.XXXXXX" renamed onto path by cm_outfile_commit. */
typedef struct cm_outfile {
    FILE *f;
    char *path;
    char *tmp;
} cm_outfile;

cm_status cm_outfile_open(cm_context *ctx, const char *path, cm_outfile *out);
/* Flushes, closes and renames; on any error removes the temporary file. */
cm_status cm_outfile_commit(cm_context *ctx, cm_outfile *out);
/* Closes and removes the temporary file (after an error). Safe to call twice. */
void cm_outfile_abort(cm_outfile *out);

/* True on a little-endian host (binary formats are written little-endian). */
int cm_host_little_endian(void);

#endif
