/* Fluent mesh and case files (not public): the parse of the sections (fluent_read.c), the
 * volume cells built from the faces (fluent_build.c) and the write back into the file
 * (fluent_write.c). The layout is the Fluent file format's (its user's guide, appendix "Case
 * and Data File Formats"): sections "(index ...)", numbers in headers hexadecimal, binary
 * sections 20xx (single precision) and 30xx (double precision) closed by
 * "End of Binary Section xxxx)"; integers in binary sections are 32-bit, little-endian. */
#ifndef CADMORPH_MESH_IO_FLUENT_INTERNAL_H
#define CADMORPH_MESH_IO_FLUENT_INTERNAL_H

#include "cadmorph/mesh.h"

#include <stdint.h>

/* A zone: a cell zone (12), a face zone (13), or the name (39/45) of either. */
typedef struct cm_fluent_zone {
    int64_t id, first, last;
    int kind;       /* 12 cells, 13 faces */
    int64_t type;   /* the bc-type of a face zone, the cell type of a cell zone */
    char name[128]; /* from (39 ...)/(45 ...), "" without */
} cm_fluent_zone;

/* What the parse collects: nodes (0-based by id - 1), faces (their nodes 0-based, c0/c1
 * 1-based with 0 for none), zones. where[f]: the place a face was read (a line, or for a
 * binary section minus one minus the byte offset), for messages. */
typedef struct cm_fluent_faces {
    size_t n, cap, n_conn, cap_conn;
    int64_t *offset; /* n + 1 */
    int64_t *nodes;
    int64_t *c0, *c1, *where;
    int *zone; /* index into the zones */
} cm_fluent_faces;

typedef struct cm_fluent_parsed {
    const char *path;
    const char *data;
    size_t size;
    int dim;
    int64_t n_nodes, n_cells_declared;
    cm_fluent_faces faces;
    size_t n_zones, cap_zones;
    cm_fluent_zone *zones;
} cm_fluent_parsed;

/* "FILE:LINE" of byte at in the file's text (the line counted on demand). */
long cm_fluent_line_of(const cm_fluent_parsed *p, size_t at);
/* The place of face f for messages: "line N" or "byte N". */
void cm_fluent_where(const cm_fluent_parsed *p, size_t f, char *out, size_t cap);

/* The volume cells (typed where the faces make a tet, hex, wedge or pyramid, polyhedra
 * otherwise), the boundary faces as 2-D cells, the zones as groups. */
cm_status cm_fluent_build(cm_context *ctx, cm_fluent_parsed *p, cm_mesh *m);


#endif
