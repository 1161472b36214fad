/* Structured hex meshes of the benchmark models at t = 0 (issue 6): O-grids whose boundary
 * nodes lie exactly on G(0) (the parameters of models.h at t = 0). */
#ifndef CADMORPH_BENCH_HEXMESH_H
#define CADMORPH_BENCH_HEXMESH_H

#include "cadmorph/mesh.h"

/* bore: an O-grid of the annulus between the bore (radius 0.6) and the block's square
 * section, n_theta cells around (a multiple of 8: the square's corners are nodes), n_r
 * across (graded towards the bore by `grading` per cell, 1 = uniform), n_z along z.
 * Hexes (physical 1) only; their boundary is the bore's surface. */
cm_status cm_hexmesh_bore(cm_context *ctx, int n_theta, int n_r, int n_z, double grading,
                          cm_mesh **mesh);

/* pipe: a butterfly O-grid of the disc (central square of n x n cells, a ring of n_ring cells
 * outside each of its sides) swept along the centreline with cells of about `step` length. */
cm_status cm_hexmesh_pipe(cm_context *ctx, int n, int n_ring, double step, cm_mesh **mesh);

#endif
