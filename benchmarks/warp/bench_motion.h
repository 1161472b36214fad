/* The boundary motion of the warp benchmarks (bench_warp, bench_warp_vjp): smooth, not affine,
 * 3 % of the mesh's bounding-box diagonal, so that every method's figures are for one motion. */
#ifndef CADMORPH_BENCH_MOTION_H
#define CADMORPH_BENCH_MOTION_H

#include "cadmorph/mesh.h"

#include <math.h>

/* The mesh's bounding box, and the coordinates of node i in it scaled to [0, 1] (u). */
typedef struct bench_box {
    double lo[3], hi[3], diag;
} bench_box;

static inline bench_box bench_box_of(const cm_mesh *m)
{
    bench_box b = {{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}, 0};
    for (size_t v = 0; v < m->n_nodes; ++v)
        for (int d = 0; d < 3; ++d) {
            b.lo[d] = fmin(b.lo[d], m->xyz[3 * v + d]);
            b.hi[d] = fmax(b.hi[d], m->xyz[3 * v + d]);
        }
    for (int d = 0; d < 3; ++d) b.diag += (b.hi[d] - b.lo[d]) * (b.hi[d] - b.lo[d]);
    b.diag = sqrt(b.diag);
    return b;
}

static inline void bench_unit(const bench_box *b, const double *x, double u[3])
{
    for (int k = 0; k < 3; ++k)
        u[k] = (x[k] - b->lo[k]) / (b->hi[k] - b->lo[k] > 0 ? b->hi[k] - b->lo[k] : 1);
}

/* d0 (#nodes x 3, zeroed by the caller): the motion at the boundary nodes of bd. */
static inline void bench_smooth_motion(const cm_mesh *m, const cm_mesh_boundary *bd,
                                       const bench_box *b, double *d0)
{
    for (size_t i = 0; i < bd->n_nodes; ++i) {
        double u[3];
        bench_unit(b, m->xyz + 3 * bd->nodes[i], u);
        double *o = d0 + 3 * bd->nodes[i];
        o[0] = 0.03 * b->diag * sin(3.14159265358979323846 * u[1]) * u[2];
        o[1] = 0.03 * b->diag * sin(3.14159265358979323846 * u[2]) * u[0];
        o[2] = 0.03 * b->diag * sin(3.14159265358979323846 * u[0]) * u[1];
    }
}

#endif
