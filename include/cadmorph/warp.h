/* cadmorph volume warps: the space warp that carries boundary motion into the interior of a
 * volume mesh, one interpolant per connected component (paper section 3), and the
 * displacement table of `cadmorph warp`. Conventions: see core.h.
 */
#ifndef CADMORPH_WARP_H
#define CADMORPH_WARP_H

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
 * Every component with unconstrained nodes must have constrained nodes that are not all
 * coplanar: otherwise the RBF's CM_ERR_NUMERIC, its message prefixed "component <k>".
 * A constrained node shared by components (touching at an edge or vertex) is a centre of
 * each; an unconstrained one follows the lowest-numbered component. Unconstrained nodes of
 * no volume cell are left alone (a CM_LOG_WARNING gives their count). A mesh without
 * volume cells is CM_ERR_UNSUPPORTED. mesh and b are borrowed: the warp keeps copies. */
cm_status cm_warp_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                         const unsigned char *constrained, const cm_warp_options *opt,
                         cm_warp **warp);
void cm_warp_destroy(cm_warp **warp);

/* disp: #nodes x 3. On input, read at constrained nodes only; on output, constrained nodes
 * keep their value and every other node of a volume cell gets the warp's displacement (other
 * entries are not written). Reuses the factorisation: one warp, many calls (not concurrently
 * on the same warp). */
cm_status cm_warp_apply(cm_context *ctx, cm_warp *warp, double *disp);

/* Reads a displacement table (the D.csv of `cadmorph warp`): header `node,dx,dy,dz`, then one
 * row per listed node; node is the 0-based index in the mesh file's node order. Blank lines
 * and a CRLF ending are accepted.
 * disp: #nodes x 3 output, zeroed first, then the listed rows. listed: #nodes output flags,
 * 1 for listed nodes (may be NULL). n_nodes: the mesh's node count.
 * Errors name path:line: CM_ERR_FORMAT for a wrong header, column count, non-numeric or
 * non-finite value, CM_ERR_MISMATCH for a node index out of range or listed twice. */
cm_status cm_warp_read_displacements(cm_context *ctx, const char *path, size_t n_nodes,
                                     double *disp, unsigned char *listed);

#ifdef __cplusplus
}
#endif
#endif
