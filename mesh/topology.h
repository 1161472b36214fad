/* Face topology of a mesh's volume cells (internal to cm_mesh): the one place where the faces
 * of cells are matched by their node sets. Boundary extraction (boundary.c) and OpenFOAM's
 * face addressing (io/foam_build.c) both start from it and only order the result their way.
 *
 * Every face of every 3D cell is an instance; instance i of cell c is local face
 * i - inst_off[c] of c (cell_faces.h: outward for a cell of positive volume), so instances run
 * in cell order, then in the cell's local face order. Instances with the same node set (the
 * same sorted list of node indices, length included) are one face. A face's instances are
 * linked in ascending order into a cycle (mate); its first instance gives its owner and its
 * orientation, the second its neighbour. Faces are numbered in the order of their first
 * instance, which makes every result independent of the thread count.
 *
 * Indices are 32-bit: the instance arrays dominate the memory (and, through page faults, the
 * time) of a boundary extraction, and 2^31 nodes or faces is far beyond what a morph handles;
 * larger meshes are refused (CM_TOPOLOGY_TOO_LARGE). */
#ifndef CADMORPH_MESH_TOPOLOGY_H
#define CADMORPH_MESH_TOPOLOGY_H

#include "cadmorph/mesh.h"

#include <stdint.h>

typedef int32_t cm_topo_idx;
#define CM_TOPO_IDX_MAX INT32_MAX

/* Faces with more nodes than this are refused whatever the caller's limit (keys live on the
 * stack). */
#define CM_TOPOLOGY_MAX_FACE_NODES 1024

/* The key of one instance (opaque outside topology.c). */
typedef struct cm_topo_key cm_topo_key;

typedef struct cm_topology {
    size_t n_cells, n_nodes;
    size_t n_inst;
    int64_t *inst_off;      /* #cells + 1: first instance of each cell (no instances below 3D) */
    cm_topo_idx *inst_cell; /* #instances: the cell of each instance */
    cm_topo_idx *mate;      /* #instances: the next instance of the same face (a cycle in
                               ascending order), -1 for a face of one cell */
    size_t n_nonmanifold;   /* faces of 3 or more instances */
    int max_face_nodes;
    /* unique faces: filled by cm_topology_faces only (boundary extraction does without) */
    size_t n_faces;
    cm_topo_idx *face_inst; /* #faces: first instance, ascending */
    cm_topo_idx *owner;     /* #faces: cell of the first instance */
    cm_topo_idx *neighbour; /* #faces: cell of the second instance, -1 on the boundary */
    /* the lookup by node set: keys bucketed by their smallest node */
    int64_t *bucket_off;    /* #nodes + 1 */
    cm_topo_key *bucket;    /* #instances */
} cm_topology;

/* Why a build failed: callers word the message (each keeps its own, as before the two face
 * matchers became this one). */
typedef enum cm_topology_fault {
    CM_TOPOLOGY_OK = 0,
    CM_TOPOLOGY_NOMEM,     /* counted: the allocation was of the instance arrays (n_inst set) */
    CM_TOPOLOGY_TOO_LARGE, /* n_nodes, n_cells or n_inst beyond CM_TOPO_IDX_MAX */
    CM_TOPOLOGY_BAD_FACE,  /* cell, face: n < 3 nodes, or n = -1 for more than the limit */
    CM_TOPOLOGY_BAD_NODE   /* cell, face: node out of range */
} cm_topology_fault;

typedef struct cm_topology_problem {
    cm_topology_fault what;
    int counted;           /* NOMEM: 1 if n_inst says how many instances were being allocated */
    size_t cell;
    int face, n;
    int64_t node;
    size_t n_nodes, n_cells, n_inst;
} cm_topology_problem;

/* Matches the faces of mesh's 3D cells. max_face_nodes (at most CM_TOPOLOGY_MAX_FACE_NODES)
 * bounds the nodes of one face. threads: OpenMP threads (the result does not depend on them).
 * On CM_OK t holds every instance matched. On a BAD_FACE / BAD_NODE problem (the first in
 * instance order) t is still built over the instances before the offending one, so a caller
 * that reports faults in instance order can tell which came first; t must be freed in every
 * case. Sets no message: why says what failed. */
cm_status cm_topology_build(const cm_mesh *mesh, int max_face_nodes, int threads, cm_topology *t,
                            cm_topology_problem *why);
void cm_topology_free(cm_topology *t);

/* Numbers the unique faces (face_inst, owner, neighbour, n_faces). CM_ERR_NOMEM or CM_OK;
 * sets no message. */
cm_status cm_topology_faces(cm_topology *t);

/* The face (index into face_inst; cm_topology_faces first) with exactly these nodes in any
 * order, or -1. nodes[0..n) is sorted in place. */
int64_t cm_topology_find(const cm_topology *t, const cm_mesh *mesh, int64_t *nodes, int n);

/* The first instance, in instance order, that is the third (or later) of its face, or -1. */
int64_t cm_topology_first_overshared(const cm_topology *t);

#endif
