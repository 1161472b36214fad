/* cadmorph volume: the RBF space warp that carries boundary motion into the interior of a
 * volume mesh, one interpolant per connected component (paper section 3).
 * Conventions: see core.h.
 */
#ifndef CADMORPH_VOLUME_H
#define CADMORPH_VOLUME_H

#include "cadmorph/mesh.h"
#include "cadmorph/rbf.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cm_warp_options {
    cm_rbf_kernel kernel; /* CM_RBF_TRIHARMONIC (default) or CM_RBF_BIHARMONIC */
} cm_warp_options;

void cm_warp_options_init(cm_warp_options *opt);

/* A factorised warp: the centres are the constrained nodes of each component, so one warp
 * serves every displacement of the same constrained nodes (absolute sweeps). */
typedef struct cm_warp cm_warp;

/* constrained: #nodes flags, non-zero where the displacement is prescribed (the boundary
 * nodes, and any interior node a caller wants to pin). NULL = the boundary nodes of b.
 * Every component must have constrained nodes that are not all coplanar. */
cm_status cm_warp_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                         const unsigned char *constrained, const cm_warp_options *opt,
                         cm_warp **warp);
void cm_warp_destroy(cm_warp **warp);

/* disp: #nodes x 3. On input, read at constrained nodes only; on output, constrained nodes
 * keep their value and every other node of a volume cell gets the warp's displacement. */
cm_status cm_warp_apply(cm_context *ctx, cm_warp *warp, double *disp);

#ifdef __cplusplus
}
#endif
#endif
