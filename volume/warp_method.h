/* What one interior-warp method implements (not public; the table is in warp.c). A method
 * keeps its own state behind a void pointer; cm_warp wraps it with the method's row. */
#ifndef CADMORPH_VOLUME_WARP_METHOD_H
#define CADMORPH_VOLUME_WARP_METHOD_H

#include "cadmorph/warp.h"

typedef struct cm_warp_method_ops {
    const char *name; /* as on the command line */
    /* constrained is never NULL here (warp.c defaults it to the boundary nodes). */
    cm_status (*create)(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                        const unsigned char *constrained, const cm_warp_options *opt,
                        void **state);
    /* disp as in cm_warp_apply; *residual: the largest miss at the constrained nodes. */
    cm_status (*apply)(cm_context *ctx, void *state, double *disp, double *residual);
    void (*destroy)(void *state);
    /* Nodes the method could not treat by its rule and gave its documented fallback (may be
     * NULL: none ever). */
    size_t (*fallback_nodes)(const void *state);
    /* cm_warp_apply_transpose: out (#nodes x 3) is zeroed by warp.c; the method adds J^T v
     * at the constrained nodes. NULL: the method's apply is not linear in disp. */
    cm_status (*apply_transpose)(cm_context *ctx, void *state, const double *v, double *out);
    /* cm_warp_apply_many: k blocks of #nodes x 3 at once; *residual the largest over them.
     * NULL: warp.c calls apply block by block. */
    cm_status (*apply_many)(cm_context *ctx, void *state, size_t k, double *disp,
                            double *residual);
    /* cm_warp_tolerance (NULL: the method has none: 0). The last member, so that the
     * positional initialisers of the rows only grow at their end. */
    double (*tolerance)(const void *state);
} cm_warp_method_ops;

/* The RBF methods (warp_rbf.c). */
extern const cm_warp_method_ops cm_warp_rbf_triharmonic;
extern const cm_warp_method_ops cm_warp_rbf_biharmonic;
/* DM-FFD (warp_dmffd.c). */
extern const cm_warp_method_ops cm_warp_dmffd;
/* Staten et al.'s comparators (paper section 5): warp_femwarp.c, warp_lbwarp.c,
 * warp_simplex.cpp. */
extern const cm_warp_method_ops cm_warp_femwarp;
extern const cm_warp_method_ops cm_warp_lbwarp;
extern const cm_warp_method_ops cm_warp_simplex;
/* The MLS space deformation (warp_mls.c over deform/mls.h). */
extern const cm_warp_method_ops cm_warp_mls;

/* LBWARP's log-barrier weights of one node (warp_lbwarp.c): d, n x 3, the offsets x_j - x_i
 * of its neighbours; w, n outputs; lambda, mu the Lagrange multipliers of the reproduction
 * and the sum constraint (w_j = 1 / (mu + lambda . d_j)). Returns 0, or -1 when x_i is not
 * strictly inside the hull of the x_j (w is then the uniform fallback 1/n). */
int cm_lbwarp_weights(const double *d, size_t n, double *w, double lambda[3], double *mu);

/* The linear-simplex location (warp_simplex.cpp): TetGen's Delaunay tetrahedralisation of
 * pts (n_pts x 3), and for each query point (n_query x 3) the corners (n_query x 4, indices
 * into pts) and barycentric coordinates (n_query x 4) of the tet containing it. A query
 * outside every tet gets the tet with the largest smallest coordinate (the least
 * extrapolation), its coordinates used as they are (some negative); n_outside counts them. */
cm_status cm_simplex_locate(cm_context *ctx, const double *pts, size_t n_pts, const double *query,
                            size_t n_query, int64_t *corner, double *bary, size_t *n_outside);

/* ---- shared by the mesh-based methods (warp_nodes.c) ---- */

/* The nodes of volume cells split into free (unconstrained) and fixed (constrained) ones,
 * each numbered in ascending node order. Unconstrained nodes of no volume cell are in
 * neither (a CM_LOG_WARNING gives their count, as for the RBF). A component of b with free
 * nodes but no constrained node is CM_ERR_NUMERIC (nothing defines its motion). */
typedef struct cm_warp_nodes {
    size_t n_nodes, n_free, n_fixed;
    int64_t *free_index;  /* #nodes: index among the free nodes, -1 for the others */
    int64_t *fixed_index; /* #nodes: index among the fixed nodes, -1 for the others */
    int64_t *free_nodes;  /* n_free node ids, ascending */
    int64_t *fixed_nodes; /* n_fixed node ids, ascending */
    /* constrained nodes of no volume cell: apply leaves them as they are, so the warp is the
     * identity there and its transpose hands v back */
    size_t n_loose;
    int64_t *loose_nodes;
} cm_warp_nodes;

cm_status cm_warp_nodes_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                               const unsigned char *constrained, cm_warp_nodes **nodes);
void cm_warp_nodes_destroy(cm_warp_nodes **nodes);

/* The part of J^T v that every mesh-based method shares: apply keeps the prescribed value
 * at every constrained node (fixed and loose), so out += v there. */
void cm_warp_nodes_add_identity(const cm_warp_nodes *nodes, const double *v, double *out);

/* Whether cell c is a volume cell (dimension 3). */
int cm_warp_is_volume_cell(const cm_mesh *mesh, size_t c);

/* The distinct nodes of cell c (a polyhedron's face stream lists a node once per face) into
 * out (room for mesh->offset[c+1] - offset[c] entries); returns their count. */
size_t cm_warp_cell_nodes(const cm_mesh *mesh, size_t c, int64_t *out);

#endif
