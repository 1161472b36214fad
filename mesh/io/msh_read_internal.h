/* Shared by the parts of the gmsh .msh reader (not public): the reader state and value
 * readers that take an ASCII token or raw little-endian bytes and word errors with the
 * file's line (ASCII) or byte offset (binary). */
#ifndef CADMORPH_MESH_MSH_READ_INTERNAL_H
#define CADMORPH_MESH_MSH_READ_INTERNAL_H

#include "msh_internal.h"

/* An entity's first physical tag, sorted by (dim, tag) for lookup from element blocks. */
typedef struct cm_msh_entity_key {
    int dim, tag, physical;
} cm_msh_entity_key;

typedef struct cm_msh_reader {
    cm_context *ctx;
    cm_text t;
    int version; /* 22 or 41 */
    int binary;
    int dsize;   /* bytes of a size_t (binary 4.1); 4 for 2.2 */
    cm_mesh *m;
    int have_nodes, have_elements;
    cm_msh_tagmap nodes, cells;
    int cells_mapped;
    cm_msh_entity_key *ents;
    size_t n_ents;
} cm_msh_reader;

/* Sets "path:line: message" (bin = 0) or "path: byte <at>: message" and returns code. */
cm_status cm_msh_err(cm_msh_reader *r, cm_status code, int bin, size_t at, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
/* "expected <what>, got '<token>'" (tok NULL: end of file) at the current line, or at the
 * current byte when bin. */
cm_status cm_msh_expected(cm_msh_reader *r, int bin, const char *what, const char *tok, size_t len);

/* The values (msh_read_values.c). bin: read raw bytes (int: 4, size: dsize, double: 8); else
 * the next ASCII token. */
cm_status cm_msh_int(cm_msh_reader *r, int bin, const char *what, int64_t *v);
cm_status cm_msh_size(cm_msh_reader *r, int bin, const char *what, int64_t *v);
cm_status cm_msh_double(cm_msh_reader *r, int bin, const char *what, double *v);
/* A double that must be finite. */
cm_status cm_msh_coord(cm_msh_reader *r, int bin, const char *what, double *v);
/* A non-negative count of items that take at least min_bytes each in the rest of the file. */
cm_status cm_msh_count(cm_msh_reader *r, int bin, const char *what, size_t min_bytes, int64_t *v);
/* The next token must be word. */
cm_status cm_msh_expect(cm_msh_reader *r, int bin, const char *word);
/* A quoted (or bare) string; caller frees *out. */
cm_status cm_msh_string(cm_msh_reader *r, const char *what, char **out);
/* Moves past the newline that ends a header line, where binary data starts. */
void cm_msh_to_binary(cm_msh_reader *r);
/* n raw bytes (NULL, message set, if the file is shorter). */
const unsigned char *cm_msh_bytes(cm_msh_reader *r, size_t n, const char *what);
/* Unsigned dsize-byte value; -1 above INT64_MAX. */
int64_t cm_msh_get_size(const unsigned char *p, int dsize);

/* Section bodies (the reader stands after the section's opening line). */
cm_status cm_msh_read_entities41(cm_msh_reader *r);
cm_status cm_msh_read_nodes41(cm_msh_reader *r);
cm_status cm_msh_read_elements41(cm_msh_reader *r);
cm_status cm_msh_read_nodes22(cm_msh_reader *r);
cm_status cm_msh_read_elements22(cm_msh_reader *r);
/* Maps element tags to cells (once); a tag used twice is a format error, whether or not
 * $ElementData follows: our writers repeat the tags, and gmsh refuses such files. */
cm_status cm_msh_map_cells(cm_msh_reader *r);
cm_status cm_msh_read_data(cm_msh_reader *r, cm_field_location where);
/* Builds r->nodes from the node tags read (after $Nodes). */
cm_status cm_msh_map_nodes(cm_msh_reader *r);

#endif
