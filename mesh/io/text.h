/* Shared by the text mesh readers (not public): a line-aware text cursor. Whole-file
 * reading and atomic output are in core.h (cm_file_read, cm_outfile). */
#ifndef CADMORPH_MESH_IO_TEXT_H
#define CADMORPH_MESH_IO_TEXT_H

#include "cadmorph/mesh.h"

#include <stdio.h>

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
/* A decimal integer filling [b, e) exactly: an optional sign and digits, refused (0) on
 * anything else or on overflow; 1 with *v set. */
int cm_text_parse_int(const char *b, const char *e, int64_t *v);
/* Next token parsed as integer / double; on failure sets a message naming path:line and
 * `what` (e.g. "node count") and returns CM_ERR_FORMAT. */
cm_status cm_text_int(cm_context *ctx, cm_text *t, const char *what, int64_t *v);
cm_status cm_text_double(cm_context *ctx, cm_text *t, const char *what, double *v);
/* Moves to the start of the next line. */
void cm_text_next_line(cm_text *t);

#endif
