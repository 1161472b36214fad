/* cadmorph kD-tree: exact nearest neighbours of 3D points (FLANN, one kd-tree, unlimited
 * checks), used to find the CAD sample closest to a mesh node. Conventions: see core.h. */
#ifndef CADMORPH_KDTREE_H
#define CADMORPH_KDTREE_H

#include "cadmorph/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cm_kdtree cm_kdtree;

/* Builds the tree on n points. xyz: n x 3 double (copied; the tree does not keep it).
 * n must be at least 1 and below 2^31 (FLANN indexes with int). */
CM_API cm_status cm_kdtree_create(cm_context *ctx, const double *xyz, size_t n, cm_kdtree **tree);
/* The same on points the caller keeps alive and unchanged until the tree is destroyed (not
 * copied: a locator's millions of samples are stored once). */
CM_API cm_status cm_kdtree_create_borrowed(cm_context *ctx, const double *xyz, size_t n,
                                           cm_kdtree **tree);
CM_API void cm_kdtree_destroy(cm_kdtree **tree);

/* Number of points in the tree. */
CM_API size_t cm_kdtree_size(const cm_kdtree *tree);

/* The k nearest points of each of the m queries, nearest first (exact).
 * query: m x 3 double; index: m x k, 0-based; dist2: m x k squared distances (may be NULL).
 * k must be between 1 and the tree size. Uses the context's threads. */
CM_API cm_status cm_kdtree_nearest(cm_context *ctx, const cm_kdtree *tree, const double *query,
                                   size_t m, int k, int64_t *index, double *dist2);

#ifdef __cplusplus
}
#endif
#endif
