/* What a mesh read from a file keeps of that file beyond the mesh (not public): the record a
 * format's reader hangs on cm_mesh.origin (OpenFOAM's face addressing, the places of the
 * coordinates in a text file, a CGNS file's zones), so that its writer can write the mesh back
 * changing only coordinates (docs/DESIGN.md, "Writing back into the file a mesh came from").
 * Shared by copies of the mesh (reference counted), released by cm_mesh_destroy. A leaf: the
 * mesh container uses it without depending on any reader. */
#ifndef CADMORPH_MESH_IO_ORIGIN_H
#define CADMORPH_MESH_IO_ORIGIN_H

#include "cadmorph/mesh.h"

typedef struct cm_mesh_origin {
    int refs;                       /* atomic count: read-only after the read */
    cm_mesh_format format;          /* the reader that made it */
    size_t n_nodes, n_cells;        /* the mesh as read: a write in place needs the same */
    void *state;                    /* the format's record */
    void (*free_state)(void *state);
} cm_mesh_origin;

/* Hangs state on m as its origin (refs 1), replacing any earlier one. On failure (out of
 * memory) state is freed with free_state and the mesh has no origin. n_nodes and n_cells are
 * taken from m now: call it when the mesh is complete. */
cm_status cm_mesh_set_origin(cm_context *ctx, cm_mesh *m, cm_mesh_format format, void *state,
                             void (*free_state)(void *state));
/* The format's record of the file m was read from, or NULL when m was not read from that
 * format or no longer has the nodes and cells it was read with. */
void *cm_mesh_origin_state(const cm_mesh *m, cm_mesh_format format);
/* The format m was read from (CM_FORMAT_UNKNOWN for a mesh built in memory). */
cm_mesh_format cm_mesh_origin_format(const cm_mesh *m);

cm_mesh_origin *cm_mesh_origin_retain(cm_mesh_origin *o);
void cm_mesh_origin_release(cm_mesh_origin **o);

#endif
