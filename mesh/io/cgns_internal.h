/* CGNS files (ADF or HDF5, through the CGNS library's mid-level API for reading and its cgio
 * layer for writing coordinates back): what the reader (cgns_read.c) keeps of a file for the
 * writer (cgns_write.c). Not public. */
#ifndef CADMORPH_MESH_IO_CGNS_INTERNAL_H
#define CADMORPH_MESH_IO_CGNS_INTERNAL_H

#include "cadmorph/mesh.h"
#include "rewrite.h"

#include <stddef.h>
#include <stdint.h>

/* One unstructured zone as read: where its coordinates are in the tree, their stored types,
 * and which mesh node each of its vertices became (zones' coincident vertices merged). */
typedef struct cm_cgns_zone {
    char path[80];       /* "/Base/Zone" (names are at most 32 characters) */
    int64_t n_vertices;
    int n_coords;        /* 2 (CoordinateX, CoordinateY) or 3 */
    int single[3];       /* CoordinateX/Y/Z stored as RealSingle (else RealDouble) */
    int64_t *node;       /* #n_vertices: the mesh node of each vertex */
} cm_cgns_zone;

typedef struct cm_cgns_state {
    char *path;          /* the file read: written back by copying it */
    cm_file_stamp stamp; /* its identity when read (a changed file is not written back) */
    size_t n_zones;
    cm_cgns_zone *zones;
} cm_cgns_state;

void cm_cgns_state_free(void *state);

/* The CGNS library keeps open files in global tables: every use goes through this lock. */
void cm_cgns_lock(void);
void cm_cgns_unlock(void);

/* Whether the file's first bytes are an HDF5 or an ADF file's (the library is not asked to
 * open anything else: it is not hardened against arbitrary bytes). */
int cm_cgns_magic_ok(const char *path);

#endif
