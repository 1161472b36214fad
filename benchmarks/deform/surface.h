/* Surface helpers of the deform benchmarks: an icosphere built in code and the discrete mean
 * curvature H = |Delta x| / 2 with the cotangent Laplace-Beltrami operator (paper Fig. 9). */
#ifndef CADMORPH_BENCH_DEFORM_SURFACE_H
#define CADMORPH_BENCH_DEFORM_SURFACE_H

#include <stddef.h>
#include <stdint.h>

typedef struct bench_surface {
    size_t nv, nt;
    double *xyz;  /* nv x 3 */
    int64_t *tri; /* nt x 3 */
} bench_surface;

/* Icosahedron subdivided `level` times, on the sphere of radius r around c. */
int bench_icosphere(int level, const double c[3], double r, bench_surface *s);
void bench_surface_free(bench_surface *s);

/* h: nv mean curvature of the surface with vertex positions xyz (nv x 3; s->tri used):
 * H_i = |sum_j (cot a_ij + cot b_ij)(x_j - x_i)| / (4 A_i), A_i the barycentric area. */
void bench_mean_curvature(const bench_surface *s, const double *xyz, double *h);

#endif
