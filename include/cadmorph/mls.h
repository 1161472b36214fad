/* cadmorph MLS space deformation (Sieger, Menzel, Botsch, "Constrained space deformation
 * techniques for design optimization", sections 4-5): a displacement field
 * d(x) = sum_j w_j phi_j(x) over k moving-least-squares shape functions (linear basis,
 * compact cos weight), whose coefficients minimise
 *     gs E_stretch + gb E_bend + gf E_fix
 * with E_stretch = sum_i V_i |grad d(q_i)|^2 and E_bend = sum_i V_i |lap d(q_i)|^2 over N
 * cubature points q_i, and E_fix the squared miss at the constrained nodes (handle H and
 * fixed region F). The k x k normal equations (eq. 14) are sparse: CHOLMOD factors them once
 * per sample set, and every new displacement of the constrained nodes is one solve.
 * The field is an approximation: it meets the constrained nodes up to a residual. By default
 * (keep_constrained) apply gives them their prescribed values all the same and carries the
 * field's miss into the free nodes near them (blend); keep_constrained = 0 is the paper's
 * weighted form, the field's values everywhere (docs/DESIGN.md, "Handles, fixed nodes and
 * the MLS's miss").
 * Conventions: see core.h. */
#ifndef CADMORPH_MLS_H
#define CADMORPH_MLS_H

#include "cadmorph/mesh.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the shape functions on their own ---- */

typedef struct cm_mls_basis cm_mls_basis;

/* centres: k x 3 sample positions (k >= 4). points: n_points x 3; each sample's support radius
 * is chosen so that every point is covered by at least `cover` samples (the paper's s = 5).
 * The arrays are copied. */
CM_API cm_status cm_mls_basis_create(cm_context *ctx, size_t k, const double *centres, size_t n_points,
                              const double *points, int cover, cm_mls_basis **basis);
CM_API void cm_mls_basis_destroy(cm_mls_basis **basis);
/* An upper bound on the samples covering any point: the room cm_mls_basis_eval needs. */
CM_API size_t cm_mls_basis_max_support(const cm_mls_basis *basis);
/* Support radii: k entries. */
CM_API const double *cm_mls_basis_radii(const cm_mls_basis *basis);
/* The shape functions at x: *count samples idx (ascending), phi, grad (count x 3, may be
 * NULL), lap (count, may be NULL). max: room in the arrays, at least
 * cm_mls_basis_max_support. A point no support covers gets *count = 0. */
CM_API cm_status cm_mls_basis_eval(cm_context *ctx, const cm_mls_basis *basis, const double x[3],
                            size_t max, size_t *count, int32_t *idx, double *phi, double *grad,
                            double *lap);

/* ---- the deformation of a mesh ---- */

typedef struct cm_mls_options {
    size_t samples;        /* k; 0: 2 % of the nodes, at least 500 (at most #nodes) */
    double surface_share;  /* volume meshes: share of k on the boundary (0.7) */
    size_t cubature;       /* N; 0: 4 k */
    int cover;             /* s: samples covering every node and cubature point (5) */
    int lloyd;             /* Lloyd iterations (5) */
    double surface_weight; /* Lloyd weight of surface against volume points (2) */
    double stretch;        /* gamma_s (1) */
    double bend;           /* gamma_b (1) */
    double fix;            /* gamma_f (1000) */
    int keep_constrained;  /* apply: constrained nodes keep their prescribed value (1, the
                              default: exact) or get the field's value (0: approximate, the
                              paper's weighted fit) */
    double blend;          /* keep_constrained: the field's miss at the constrained nodes is
                              carried into the free nodes near them and decays over blend x
                              the mean support radius (1.5; 0: off, the miss stays in the
                              first cell layer) */
    uint64_t seed;         /* random sampling (1) */
    double graded;         /* how the samples and cubature points follow the mesh's own
                              resolution: a face / cell piece is drawn with probability
                              proportional to measure^(1 - graded); 0 (default): uniform by
                              measure, farthest points (the paper's); 1: each piece alike,
                              so a mesh refined around a body (a CFD mesh in a wind
                              tunnel) gets its samples where its cells are small (0) */
} cm_mls_options;

CM_API void cm_mls_options_init(cm_mls_options *opt);

typedef struct cm_mls cm_mls;

/* Samples the mesh (its 2D cells for a surface mesh; its volume cells and their boundary
 * faces for a volume mesh), builds the shape functions at every node and at the cubature
 * points, assembles and factors eq. 14. constrained: #nodes, 0 for a free node, else the
 * node's constraint group (1..255, e.g. 1 fixed region F, 2 handle H); at least one node.
 * The energies are normalised so that the weights do not depend on the mesh's size: the
 * stretch term by L^2 / V, the bend term by L^4 / V (L the mean support radius: the
 * subspace's resolution; V the total cubature volume), the fix term of each node by 1 / the size of its group (so a small
 * handle weighs as much as a large fixed region). mesh is borrowed. */
CM_API cm_status cm_mls_create(cm_context *ctx, const cm_mesh *mesh, const unsigned char *constrained,
                        const cm_mls_options *opt, cm_mls **mls);
CM_API void cm_mls_destroy(cm_mls **mls);

/* disp: #nodes x 3, read at the constrained nodes, written at every node (constrained ones
 * as keep_constrained says). residual: the largest |d(x_i) - prescribed_i| over constrained
 * nodes (may be NULL). One factorisation, any number of calls (not concurrently). */
CM_API cm_status cm_mls_apply(cm_context *ctx, cm_mls *mls, double *disp, double *residual);

/* The reverse product of apply (docs/DESIGN.md, "Gradients"): apply is linear in the
 * prescribed values (the right-hand side of eq. 14 is, the factor, Phi and the blend's
 * weights depend only on the positions), so out = J^T v, <v, apply(D)> = <out, D> for every
 * D. v: #nodes x 3, read everywhere; out: #nodes x 3, written everywhere (0 at free nodes).
 * One solve with the kept factor, all three components at once. Not concurrently with apply
 * on one MLS. */
CM_API cm_status cm_mls_apply_transpose(cm_context *ctx, cm_mls *mls, const double *v, double *out);

typedef struct cm_mls_stats {
    size_t samples, surface_samples, cubature, constrained;
    size_t phi_nonzeros;    /* shape-function values stored for the nodes */
    size_t factor_nonzeros; /* entries of the Cholesky factor */
    size_t blend_nodes;     /* free nodes the residual blend reaches (options.blend) */
    double t_sample, t_basis, t_factor, t_apply; /* seconds (t_apply: the last call) */
    double c_sample, c_basis, c_factor, c_apply; /* the same as CPU seconds of the process */
} cm_mls_stats;

CM_API void cm_mls_get_stats(const cm_mls *mls, cm_mls_stats *stats);
/* The samples (k x 3). */
CM_API const double *cm_mls_samples(const cm_mls *mls, size_t *k);

/* ---- surfaces ---- */

/* Mean curvature H_i = |lap x_i| / 2 of the 2D cells of mesh (cotangent Laplace-Beltrami,
 * barycentric areas; quads and polygons fanned into triangles): H #nodes output, 0 at
 * boundary vertices and vertices of no face. boundary: #nodes output flags of vertices on an
 * edge used by one face (may be NULL). */
CM_API cm_status cm_mls_mean_curvature(cm_context *ctx, const cm_mesh *mesh, double *H,
                                unsigned char *boundary);

/* The mesh-based shell of section 3 (eq. 10), the ground truth of the MLS subspace: the
 * piecewise-linear displacement of the 2D cells minimising
 *   stretch sum_t A_t |grad d|^2 + bend sum_i A_i |lap d_i|^2
 *   + fix sum_{constrained} A_i |d_i - disp_i|^2
 * (cotangent operators, barycentric areas A_i; weights as in the paper, not normalised).
 * disp: #nodes x 3, read at the constrained nodes, written at every node. Every connected
 * part of the surface needs a constrained node (else CM_ERR_NUMERIC). */
CM_API cm_status cm_mls_shell(cm_context *ctx, const cm_mesh *mesh, const unsigned char *constrained,
                       double stretch, double bend, double fix, double *disp);

#ifdef __cplusplus
}
#endif
#endif
