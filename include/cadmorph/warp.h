/* cadmorph volume warps: methods that carry a prescribed motion of some nodes (the boundary,
 * and any pinned node) into the rest of a volume mesh, behind one interface, and the
 * displacement table of `cadmorph warp`. Conventions: see core.h.
 *
 * Every method has the same life cycle (DESIGN.md, "The warp interface"):
 *   cm_warp_create  - everything that depends only on the mesh and on which nodes are
 *                     constrained (assembly, factorisation), done once;
 *   cm_warp_apply   - displacements at the constrained nodes in, at every node out; many
 *                     calls on one warp share the factorisation (absolute studies);
 *   cm_warp_destroy.
 * A relative step creates a new warp on the moved mesh. Adding a method is one file in the
 * volume module and one row in its method table; a space deformation is a row of deform.h's
 * table, and its warp row chooses the points (docs/DESIGN.md, "The warp interface").
 */
#ifndef CADMORPH_WARP_H
#define CADMORPH_WARP_H

#include "cadmorph/mesh.h"
#include "cadmorph/mls.h"
#include "cadmorph/motion.h"
#include "cadmorph/optimize.h"
#include "cadmorph/rbf.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum cm_warp_method {
    CM_WARP_RBF = 0,            /* "rbf": triharmonic RBF, phi = r^3 + linear (the method) */
    CM_WARP_RBF_BIHARMONIC = 1, /* "rbf-biharmonic": phi = r + linear (the paper's comparison) */
    /* Staten et al. (IMR 2011)'s comparators, paper section 5: */
    CM_WARP_FEMWARP = 2, /* "femwarp": linear finite-element Laplace warp (Baker 2001) */
    CM_WARP_LBWARP = 3,  /* "lbwarp": log-barrier weighted Laplacian (Shontz, Vavasis 2003) */
    CM_WARP_SIMPLEX = 4, /* "simplex": barycentrics in a Delaunay tet mesh of the constrained
                            nodes (linear-simplex, a generalisation of BMSWEEP) */
    CM_WARP_DMFFD,              /* "dmffd": DM-FFD on a cubic B-spline lattice around the mesh
                                   (least squares: see cm_warp_residual) */
    CM_WARP_MLS,                /* "mls": constrained MLS space deformation (mls.h), approximate */
    CM_WARP_N_METHODS
} cm_warp_method;

/* Short name of a method ("rbf", "rbf-biharmonic", ...), NULL out of range. */
CM_API const char *cm_warp_method_name(cm_warp_method method);
/* The method of a name, or -1 if unknown. */
CM_API int cm_warp_method_from_name(const char *name);
/* The method names joined by '|' ("rbf|rbf-biharmonic|..."), for usage lines. */
CM_API const char *cm_warp_method_list(void);

typedef struct cm_warp_options {
    cm_warp_method method; /* default CM_WARP_RBF */
    /* RBF methods: CM_RBF_SOLVER_AUTO (0, default: dense below a measured size, the
     * iterative solver above; see solves), DENSE, ITERATIVE or PETSC (rbf.h; PETSC makes create and
     * apply collective over the MPI ranks) */
    cm_rbf_solver solver;
    /* RBF methods, iterative solvers: stop when the largest miss at the centres is
     * <= tolerance x the largest prescribed displacement. The warp puts the constrained nodes
     * at their prescribed values anyway, so the tolerance only perturbs the interior, by
     * about tolerance x the motion, most visibly as a step between a wall node and its free
     * neighbour. 0 (default): from the mesh, per component, 1e-3 x h / D within [1e-10,
     * 1e-6], h the shortest distance between a constrained and a free node of one cell, D
     * the constrained nodes' bounding-box diagonal: that step stays within 1e-3 of the
     * thinnest wall cell for motions up to D (cm_warp_tolerance says what was taken;
     * docs/DESIGN.md, "The warp's tolerance"). The dense solver is exact to rounding. */
    double tolerance;
    /* RBF methods, AUTO solver: how many displacement fields the caller expects to apply
     * with this warp over its life (cm_warp_apply_many's k fields counting k), weighed by
     * AUTO's cost model (cm_rbf_options.solves): an absolute study's variants share one warp,
     * so dense wins to more centres than for one apply. 0 or 1 (default): one apply */
    int solves;
    /* RBF methods, iterative solver: cm_warp_apply_many's k fields solved in this many
     * groups, each starting from the solutions of those before it, and evaluated together
     * (cm_rbf_options.warm_groups): an absolute study's batch. 0 or 1 (default): all at once */
    int warm_groups;
    /* DM-FFD: control points per axis of the lattice whose domain is the mesh's bounding box
     * (grown by 1e-3 of its diagonal): 5, 10, 15, 25 in the paper; 0 = 10 */
    int lattice;
    /* DM-FFD: singular values <= clamp x sigma_max are truncated; 0 = 1e-10 */
    double clamp;
    /* MLS: samples k, cubature N, coverage s, gamma_s, gamma_b, ... (mls.h; set to
     * cm_mls_options_init's defaults by cm_warp_options_init) */
    cm_mls_options mls;
} cm_warp_options;

CM_API void cm_warp_options_init(cm_warp_options *opt);

typedef struct cm_warp cm_warp;

/* constrained: #nodes flags, non-zero where the displacement is prescribed (the boundary
 * nodes, and any interior node a caller wants to pin). NULL = the boundary nodes of b.
 * RBF methods: one interpolant per connected component of volume cells, centred at its
 * constrained nodes; a component whose constrained nodes are all coplanar is the RBF's
 * CM_ERR_NUMERIC, its message prefixed "component <k>". A constrained node shared by
 * components (touching at an edge or vertex) is a centre of each; an unconstrained one
 * follows the lowest-numbered component. Unconstrained nodes of no volume cell are left
 * alone (a CM_LOG_WARNING gives their count). A mesh without volume cells is
 * CM_ERR_UNSUPPORTED. mesh, b and constrained are borrowed for the call: the warp keeps
 * what it needs.
 * FEMWARP, LBWARP, simplex: one system (one Delaunay mesh) for all components; a component
 * with free nodes but no constrained node is CM_ERR_NUMERIC; FEMWARP takes linear cells only
 * (tet4, hex8, wedge6, pyr5, polyhedra; others CM_ERR_UNSUPPORTED); simplex needs constrained
 * nodes that are not all coplanar (CM_ERR_NUMERIC). */
CM_API cm_status cm_warp_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                         const unsigned char *constrained, const cm_warp_options *opt,
                         cm_warp **warp);
CM_API void cm_warp_destroy(cm_warp **warp);

/* disp: #nodes x 3. On input, read at constrained nodes only; on output, constrained nodes
 * keep their value and every other node of a volume cell gets the warp's displacement (other
 * entries are not written). One warp, many calls (not concurrently on the same warp). */
CM_API cm_status cm_warp_apply(cm_context *ctx, cm_warp *warp, double *disp);

/* The forward product for k displacement fields in one call: disp holds k blocks of
 * #nodes x 3 (block j at disp + 3 #nodes j, each laid out as cm_warp_apply's disp), each
 * transformed as cm_warp_apply would. rbf, rbf-biharmonic: per component one solve and one
 * evaluation of 3k columns (cm_deform_apply_many), which share the kernel passes; equal to k
 * applies to rounding (dense) or to the iterative solver's tolerance. The other methods
 * apply block by block. cm_warp_residual: the largest over the blocks. Memory: 3k values per
 * point of the largest component besides disp, so k up to tens; the caller chooses k.
 * Stops with CM_ERR_INTERRUPTED as apply does (blocks then partly written). */
CM_API cm_status cm_warp_apply_many(cm_context *ctx, cm_warp *warp, size_t k, double *disp);

/* The reverse product of apply, for adjoint gradients (docs/DESIGN.md, "Gradients"). For the
 * methods whose apply is linear in the prescribed displacement D (rbf, rbf-biharmonic,
 * femwarp, lbwarp, simplex; dmffd, whose truncated pseudo-inverse is fixed by create; mls,
 * whose constraints are a quadratic penalty), apply computes J D: D itself at the constrained
 * nodes, J_f D at the other nodes it writes. This computes the transpose: out = J^T v, that
 * is <v, apply(D)> = <out, D> for every D.
 * v: #nodes x 3, read at the nodes apply writes (constrained nodes, and unconstrained nodes
 * of volume cells; mls: every node). out: #nodes x 3, written everywhere: at a constrained
 * node v there plus what the other nodes' v sends back to it through the warp (mls with
 * keep_constrained = 0: only the latter), 0 at every other node. The
 * three components in one call, with the factorisation (or preconditioner) of create; v and
 * out must not overlap. An iterative RBF solve is exact to the warp's tolerance, like apply:
 * as a gradient, <out, D> for a smooth D, to about that tolerance; entry by entry, to the
 * tolerance times the growth of the RBF weights (docs/DESIGN.md, "Gradients").
 * CM_ERR_UNSUPPORTED for a method whose apply is not linear in D (the message says why). */
CM_API cm_status cm_warp_apply_transpose(cm_context *ctx, cm_warp *warp, const double *v,
                                         double *out);

/* 1 when the method's apply is linear in the prescribed displacement (it then has
 * cm_warp_apply_transpose: every method today), 0 otherwise or out of range. */
CM_API int cm_warp_method_is_linear(cm_warp_method method);

/* The method of a warp. */
CM_API cm_warp_method cm_warp_get_method(const cm_warp *warp);

/* Largest |displacement - prescribed| at the constrained nodes after the last apply: 0 for
 * methods that interpolate exactly (RBF, FEMWARP); what approximating methods (DM-FFD, MLS)
 * miss by. */
CM_API double cm_warp_residual(const cm_warp *warp);

/* The tolerance the warp's iterative RBF solves stop at (cm_warp_options.tolerance, or the
 * one from the mesh; with several components the tightest): 0 for the other methods. */
CM_API double cm_warp_tolerance(const cm_warp *warp);

/* Nodes the method could not treat by its own rule and gave its documented fallback: LBWARP,
 * nodes without positive log-barrier weights (outside the convex hull of their neighbours);
 * simplex, nodes outside every Delaunay tet. 0 for the other methods. */
CM_API size_t cm_warp_fallback_nodes(const cm_warp *warp);

/* ---- warping a whole mesh: what `cadmorph warp` does ---- */

typedef struct cm_warp_mesh_stats {
    size_t boundary_nodes, constrained_nodes, components;
    double t_create, t_apply, t_optimize; /* seconds */
    double residual;                      /* cm_warp_residual */
    size_t optimized_moves;               /* node moves kept by the optimisation */
    size_t fallback_nodes;                /* cm_warp_fallback_nodes (summed over passes) */
    size_t slide_nodes;                   /* nodes that slid (motion.h) */
} cm_warp_mesh_stats;

/* Moves mesh by disp (#nodes x 3; read at the boundary nodes and at listed nodes, the rest
 * computed by the warp).
 * motion NULL: the boundary nodes and the listed ones (listed: #nodes flags, may be NULL) are
 * constrained to disp.
 * motion (motion.h, created on this mesh with its prescribed flags; listed is then ignored):
 * fixed nodes stay, prescribed ones move by disp, slide nodes slide (a first warp with them
 * free, its motion projected onto their constraints, a second warp with them held there:
 * skipped where no node is free), 2-D pairs get one motion; a wedge is warped in its slab
 * (r, z, w) and mapped back (docs/DESIGN.md, "Boundary motion by patch kind"). Without
 * slides, the same warp as motion NULL with the fixed nodes' disp 0.
 * On return mesh->xyz is moved, and the mesh carries a per-node "displacement" and a
 * per-cell "scaled_jacobian" field (sj, may be NULL: that field's data). disp is overwritten
 * with the displacement of every node. optimize: NULL, or the options of an interior
 * optimisation of the warped mesh (constrained and slide nodes never move). stats may be
 * NULL. */
CM_API cm_status cm_warp_mesh(cm_context *ctx, cm_mesh *mesh, double *disp,
                              const unsigned char *listed, const cm_boundary_motion *motion,
                              const cm_warp_options *opt, const cm_optimize_options *optimize,
                              double **sj, cm_warp_mesh_stats *stats);

/* Makes a displacement field of every node (#nodes x 3, e.g. a space deformation's) hold a
 * boundary motion (motion.h, created on this mesh): the fixed nodes get 0, the prescribed ones
 * keep their value in disp (the caller puts the prescribed values there), the slide nodes are
 * projected onto their constraints and 2-D/wedge pairs get one motion
 * (cm_boundary_motion_project); what that changed at those nodes is carried into the free
 * nodes by a warp (opt: NULL = rbf) held at them, so that the interior follows. No warp where
 * no free node is in a volume cell or nothing changed. */
CM_API cm_status cm_warp_correct(cm_context *ctx, const cm_mesh *mesh,
                                 const cm_boundary_motion *motion, double *disp,
                                 const cm_warp_options *opt);

/* Reads a displacement table (the D.csv of `cadmorph warp`): header `node,dx,dy,dz`, then one
 * row per listed node; node is the 0-based index in the mesh file's node order. Blank lines
 * and a CRLF ending are accepted.
 * disp: #nodes x 3 output, zeroed first, then the listed rows. listed: #nodes output flags,
 * 1 for listed nodes (may be NULL). n_nodes: the mesh's node count.
 * Errors name path:line: CM_ERR_FORMAT for a wrong header, column count, non-numeric or
 * non-finite value, CM_ERR_MISMATCH for a node index out of range or listed twice. */
CM_API cm_status cm_warp_read_displacements(cm_context *ctx, const char *path, size_t n_nodes,
                                     double *disp, unsigned char *listed);

#ifdef __cplusplus
}
#endif
#endif
