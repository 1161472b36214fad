/* Helpers shared by the shape fits (shape_fit.c) and the RANSAC refits (ransac.c). Not a
 * public header. */
#ifndef CM_SHAPE_INTERNAL_H
#define CM_SHAPE_INTERNAL_H

/* Gaussian elimination with partial pivoting on a small n x n row-major system (a
 * destroyed, b: the right-hand side in, the solution out). Returns 0 if it is singular to
 * rounding: a pivot below 1e-13 x the largest entry. Why not an exact zero test: it passes
 * systems that are singular but for rounding, e.g. the circle through collinear points,
 * which then gets a radius of ~1e16 x their extent; whether it did depended on the LAPACK
 * kernels' rounding in the plane fit (Zen 4 passed where the Xeon did not). */
int cm_shape_solve_small(int n, double *a, double *b);

#endif
