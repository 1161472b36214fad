/* cadmorph interior optimisation: moves free (interior) nodes of a volume mesh to raise its
 * worst cells, and untangles inverted ones, without touching the boundary.
 * Conventions: see core.h.
 *
 * The measure is Knupp's inverse mean ratio of each corner Jacobian S = A W^-1 (A: the three
 * edges at a corner, W: the same corner of the ideal cell), ||S||_F^2 / (3 h(det S)^(2/3)),
 * with h(s) = (s + sqrt(s^2 + 4 delta^2)) / 2 (Escobar et al. 2003), delta > 0 only around
 * a node with an inverted corner, so that the same objective untangles and smooths. Nodes
 * are optimised one at a time (damped Newton), in colours of nodes that share no cell, so
 * the result does not depend on the thread count. A move is kept only if it does not lower
 * the minimum scaled Jacobian of the node's cells.
 */
#ifndef CADMORPH_OPTIMIZE_H
#define CADMORPH_OPTIMIZE_H

#include "cadmorph/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cm_optimize_options {
    int sweeps;       /* passes over the selected nodes (default 6); stops early when a pass
                         moves nothing */
    double target_sj; /* cells with a scaled Jacobian below this are worked on, with every
                         cell that shares a node with them (default 0.3) */
    int newton;       /* Newton iterations per node and pass (default 4) */
} cm_optimize_options;

CM_API void cm_optimize_options_init(cm_optimize_options *opt);

typedef struct cm_optimize_stats {
    double min_sj_before, min_sj_after;
    size_t inverted_before, inverted_after;
    size_t nodes_selected; /* free nodes the passes worked on */
    size_t moves;          /* node moves kept, over all passes */
    int sweeps;            /* passes made */
} cm_optimize_stats;

/* Optimises mesh->xyz in place. fixed: #nodes flags, non-zero = never moved; NULL = the
 * boundary nodes. Nodes of cells other than tet4, hex8, wedge6 and pyr5 (higher order,
 * polyhedra) are never moved either. stats and opt may be NULL. Errors: CM_ERR_NOMEM,
 * CM_ERR_UNSUPPORTED for a mesh without volume cells, CM_ERR_INTERRUPTED (core.h; the mesh
 * is then as it was given). */
CM_API cm_status cm_mesh_optimize(cm_context *ctx, cm_mesh *mesh, const unsigned char *fixed,
                           const cm_optimize_options *opt, cm_optimize_stats *stats);

/* The corner measure of one linear cell (tet4, hex8, wedge6, pyr5; xyz: its nodes x 3):
 * the mean of the inverse mean ratios of its corners with delta = 0, 1 for the ideal cell,
 * +inf when a corner is inverted or flat. NAN for other types. For tests and reports. */
CM_API double cm_optimize_cell_measure(cm_cell_type type, const double *xyz);

#ifdef __cplusplus
}
#endif
#endif
