/* cadmorph RBF core: scattered-data interpolation with polyharmonic kernels plus a linear
 * polynomial (paper: triharmonic-rbf-mesh-morphing, section 3; 2D variant section 4).
 *
 *   d(x) = sum_j w_j phi(|x - c_j|) + q_0 + q_1 x_1 + ... + q_dim x_dim,  sum_j w_j p(c_j) = 0
 *
 * The factorisation depends only on the centres: create once, then solve for any number of
 * right-hand sides (an absolute sweep changes only the values). Conventions: see core.h.
 */
#ifndef CADMORPH_RBF_H
#define CADMORPH_RBF_H

#include "cadmorph/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum cm_rbf_kernel {
    CM_RBF_TRIHARMONIC = 0, /* phi = r^3, 3D (the method's kernel) */
    CM_RBF_BIHARMONIC = 1,  /* phi = r, 3D (the paper's comparison) */
    CM_RBF_THIN_PLATE = 2   /* phi = r^2 log r, phi(0) = 0, 2D */
} cm_rbf_kernel;

typedef struct cm_rbf cm_rbf;

/* Fits the system for m centres (centres: m x dim row-major; dim 3 for the triharmonic and
 * biharmonic kernels, 2 for thin plate) and keeps its factorisation. Centres closer than
 * 1e-12 x the bounding-box diagonal are merged (their values must then agree, see solve).
 * Errors: CM_ERR_NUMERIC if the centres leave the polynomial block singular (all coplanar
 * in 3D, collinear in 2D) or the factorisation fails (the message has the pivot). */
CM_API cm_status cm_rbf_create(cm_context *ctx, cm_rbf_kernel kernel, int dim, size_t m,
                               const double *centres, cm_rbf **rbf);
CM_API void cm_rbf_destroy(cm_rbf **rbf);

/* Solves for values at the m centres given to create (values: m x ncomp row-major) and keeps
 * the weights in rbf, replacing earlier ones. Merged duplicate centres whose values differ
 * by more than 1e-8 of the largest value are an error naming both indices (smaller
 * differences are round-off, e.g. of projections that put two nodes on one point). */
CM_API cm_status cm_rbf_solve(cm_context *ctx, cm_rbf *rbf, int ncomp, const double *values);

/* Evaluates the current interpolant at n points (points: n x dim) into out (n x ncomp).
 * OpenMP-parallel over points; no n x m matrix is formed. */
CM_API cm_status cm_rbf_evaluate(cm_context *ctx, const cm_rbf *rbf, size_t n, const double *points,
                                 double *out);

/* Centres after merging duplicates. */
CM_API size_t cm_rbf_centre_count(const cm_rbf *rbf);

#ifdef __cplusplus
}
#endif
#endif
