/* Shared by the gmsh .msh reader and writer (not public): gmsh <-> VTK node order inside
 * cells, and a map from the file's sparse node/element tags to 0-based indices. */
#ifndef CADMORPH_MESH_MSH_INTERNAL_H
#define CADMORPH_MESH_MSH_INTERNAL_H

#include "text.h"

/* vtk[i] = gmsh[perm[i]] for the cell's nodes; NULL where both orders agree. */
const int *cm_msh_perm(cm_cell_type type);

/* Tag -> index: a dense table when the tags are compact (the usual case), else an
 * open-addressing hash table. */
typedef struct cm_msh_tagmap {
    int64_t min;      /* dense: tag of slot 0 */
    size_t dense_len; /* > 0: dense mode */
    int64_t *slot;    /* dense: index or -1; hash: pairs (tag, index), tag INT64_MIN if empty */
    size_t hash_cap;  /* hash: number of pairs (power of two) */
} cm_msh_tagmap;

/* Builds the map of tags[0..n). On a repeated tag returns CM_ERR_FORMAT with *dup_at set to
 * the index of the second occurrence (the caller words the message). */
cm_status cm_msh_tagmap_build(cm_context *ctx, const int64_t *tags, size_t n, cm_msh_tagmap *map,
                              size_t *dup_at);
/* Index of tag, or -1. */
int64_t cm_msh_tagmap_find(const cm_msh_tagmap *map, int64_t tag);
void cm_msh_tagmap_free(cm_msh_tagmap *map);

#endif
