/* Meshes built in code for the tests: the one block mesher (structured hex blocks and
 * Kuhn-split tet blocks, conforming, with jittered interior nodes, appended to a mesh so
 * blocks can be combined) and the one signed tet volume. */
#ifndef CADMORPH_TEST_MESH_H
#define CADMORPH_TEST_MESH_H

#include "cadmorph/mesh.h"
#include "test_rng.h"

#include <stdlib.h>
#include <string.h>

/* Deterministic uniform [-1, 1) (tests must not depend on libc's rand). */
static inline double test_rand(uint64_t *state) { return test_rng_range(state, -1.0, 1.0); }

typedef struct test_block {
    int nx, ny, nz; /* cells per direction */
    double origin[3], h[3];
    int tets;      /* 0: hex8 cells, 1: 6 tets per hex (Kuhn) */
    double jitter; /* interior nodes moved by up to jitter x h (random) */
} test_block;

/* Signed volume of tet (a, b, c, d), positive when d is on the side of (a, b, c) that the
 * right-hand rule points to (VTK's positive tet). */
static inline double test_tet_volume(const double *a, const double *b, const double *c,
                                     const double *d)
{
    double u[3], v[3], w[3];
    for (int i = 0; i < 3; ++i)
        u[i] = b[i] - a[i], v[i] = c[i] - a[i], w[i] = d[i] - a[i];
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
            u[2] * (v[0] * w[1] - v[1] * w[0])) /
           6.0;
}

/* The same for tet t (4 node indices into xyz, #nodes x 3). */
static inline double test_tet_volume_at(const double *xyz, const int64_t *t)
{
    return test_tet_volume(xyz + 3 * t[0], xyz + 3 * t[1], xyz + 3 * t[2], xyz + 3 * t[3]);
}

/* Appends the block's nodes and cells; returns the index of its first node (or -1). */
static inline int64_t test_add_block(cm_context *ctx, cm_mesh *m, const test_block *b,
                                     uint64_t *seed)
{
    size_t first = m->n_nodes;
    size_t n = (size_t)(b->nx + 1) * (b->ny + 1) * (b->nz + 1);
    if (cm_mesh_resize_nodes(ctx, m, first + n, 0) != CM_OK) return -1;
#define NODE(i, j, k)                                                                              \
    ((int64_t)first + (i) + (int64_t)(b->nx + 1) * ((j) + (int64_t)(b->ny + 1) * (k)))
    for (int k = 0; k <= b->nz; ++k)
        for (int j = 0; j <= b->ny; ++j)
            for (int i = 0; i <= b->nx; ++i) {
                double *p = m->xyz + 3 * NODE(i, j, k);
                int ijk[3] = {i, j, k}, nn[3] = {b->nx, b->ny, b->nz};
                int inside = i > 0 && j > 0 && k > 0 && i < b->nx && j < b->ny && k < b->nz;
                for (int d = 0; d < 3; ++d) {
                    p[d] = b->origin[d] + b->h[d] * ijk[d];
                    (void)nn;
                    if (inside) p[d] += b->jitter * b->h[d] * test_rand(seed);
                }
            }
    for (int k = 0; k < b->nz; ++k)
        for (int j = 0; j < b->ny; ++j)
            for (int i = 0; i < b->nx; ++i) {
                /* VTK hex order: bottom face counter-clockwise, then top */
                int64_t h[8] = {NODE(i, j, k),
                                NODE(i + 1, j, k),
                                NODE(i + 1, j + 1, k),
                                NODE(i, j + 1, k),
                                NODE(i, j, k + 1),
                                NODE(i + 1, j, k + 1),
                                NODE(i + 1, j + 1, k + 1),
                                NODE(i, j + 1, k + 1)};
                if (!b->tets) {
                    if (cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, h, 8, 0, 0, 0) != CM_OK) return -1;
                    continue;
                }
                /* Kuhn: walk from corner (0,0,0) to (1,1,1) one axis at a time, in each of the
                 * 6 axis orders; neighbours split shared faces the same way. */
                static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                               {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
                for (int p = 0; p < 6; ++p) {
                    int c[3] = {0, 0, 0};
                    int64_t t[4];
                    t[0] = NODE(i, j, k);
                    for (int s = 0; s < 3; ++s) {
                        c[perm[p][s]] = 1;
                        t[s + 1] = NODE(i + c[0], j + c[1], k + c[2]);
                    }
                    if (test_tet_volume_at(m->xyz, t) < 0) {
                        int64_t x = t[2];
                        t[2] = t[3];
                        t[3] = x;
                    }
                    if (cm_mesh_add_cell(ctx, m, CM_CELL_TET4, t, 4, 0, 0, 0) != CM_OK) return -1;
                }
            }
#undef NODE
    return (int64_t)first;
}

/* The hex mesh h (hex8 cells only) with every hex written as a polyhedron (VTK face stream,
 * outward faces), on the same nodes; NULL if out of memory. */
static inline cm_mesh *test_hexes_as_polyhedra(cm_context *ctx, const cm_mesh *h)
{
    static const int face[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                   {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    cm_mesh *m = NULL;
    if (cm_mesh_create(ctx, &m) < 0 || cm_mesh_resize_nodes(ctx, m, h->n_nodes, 0) < 0) {
        cm_mesh_destroy(&m);
        return NULL;
    }
    memcpy(m->xyz, h->xyz, 3 * h->n_nodes * sizeof *m->xyz);
    for (size_t c = 0; c < h->n_cells; ++c) {
        const int64_t *n = h->conn + h->offset[c];
        int64_t s[31], p = 0;
        s[p++] = 6;
        for (int f = 0; f < 6; ++f) {
            s[p++] = 4;
            for (int k = 0; k < 4; ++k)
                s[p++] = n[face[f][k]];
        }
        cm_mesh_add_cell(ctx, m, CM_CELL_POLYHEDRON, s, (size_t)p, 0, 0, 0);
    }
    return m;
}

#endif
