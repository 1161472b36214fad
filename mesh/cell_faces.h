/* Faces of volume cells (internal to mesh/): outward-oriented local face tables of the linear
 * types in VTK order, polyhedron faces from the face stream, and the higher-order nodes that
 * lie on a face (mid-edge and mid-face nodes). Used by boundary extraction. */
#ifndef CADMORPH_MESH_CELL_FACES_H
#define CADMORPH_MESH_CELL_FACES_H

#include "cadmorph/mesh.h"

/* Local faces of a standard volume type: face f has size[f] corners node[f][0..size) (local
 * indices, outward). */
typedef struct cm_face_table {
    int n_faces;
    int size[6];
    int node[6][4];
} cm_face_table;

/* Table of a tet/hex/wedge/pyramid type (any order); NULL for polyhedra and dim < 3. */
const cm_face_table *cm_cell_face_table(cm_cell_type type);

/* Faces of cell c: 4 (tet), 6 (hex), 5 (wedge, pyramid), nf (polyhedron), 0 below dim 3. */
int cm_cell_face_count(const cm_mesh *mesh, size_t c);

/* Corner nodes of face f of cell c, oriented outward by the right-hand rule; returns their
 * count, or -1 if the face has more than cap nodes (polyhedra) or f is out of range. */
int cm_cell_face_nodes(const cm_mesh *mesh, size_t c, int f, int64_t *nodes, int cap);

/* Higher-order nodes of cell c that lie on its face f (tet10 mid-edge nodes, hex27 face
 * centres, ...); returns their count (at most 5; 0 for linear types and polyhedra). */
int cm_cell_face_extra_nodes(const cm_mesh *mesh, size_t c, int f, int64_t nodes[5]);

#endif
