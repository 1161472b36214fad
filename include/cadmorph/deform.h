/* cadmorph deform: space deformations driven by control points or constrained points.
 * FFD (free-form deformation) on a tensor-product lattice, uniform cubic B-splines
 * [SMB14 §2.1] or Bernstein polynomials of degree n-1 (PyGeM's FFD); DM-FFD (direct
 * manipulation [SMB14 §2.2]): the control displacements that carry given points to given
 * targets in the least-norm / least-squares sense, through an SVD pseudo-inverse with clamped
 * singular values; and one table of the point-set deformations behind `cadmorph deform` and
 * the volume warp (RBF, constrained MLS, shell, DM-FFD). Conventions: core.h.
 *
 * The lattice maps local coordinates u in [0,1]^3 (the valid domain) to space. Its reference
 * (undeformed) form is a parallelepiped x = origin + A u, A = [a0 a1 a2] (columns); control
 * point p = (i, j, k), flat index p = (i n1 + j) n2 + k (C order of an n0 x n1 x n2 array,
 * as PyGeM's mu arrays), sits at origin + A xi_p, xi the Greville abscissae of the basis:
 *  - B-spline, uniform knots (default): t_j = (j - 3)/(n - 3), n - 3 spans on [0,1]; the
 *    abscissae are evenly spaced and reach one spacing outside the domain on each side;
 *  - B-spline, clamped knots: [0,0,0,0, 1/(n-3), ..., 1,1,1,1]; uneven abscissae at the ends;
 *  - Bernstein: xi_i = i/(n - 1), evenly spaced over the box (PyGeM's lattice).
 * With these positions the reference map is exactly affine (linear precision).
 *
 * Deformation in displacement form: d(x) = sum_p dc_p N_p(u(x)), so zero control
 * displacements give d = 0 bitwise. Points whose u lies outside [0,1]^3 by more than 1e-12
 * get d = 0 exactly and are counted; points within 1e-12 of a face are clamped onto it and
 * deform (points on the bounding box move: not PyGeM's bug #272).
 */
#ifndef CADMORPH_DEFORM_H
#define CADMORPH_DEFORM_H

#include "cadmorph/core.h"
#include "cadmorph/mls.h"
#include "cadmorph/rbf.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum cm_ffd_basis {
    CM_FFD_BSPLINE = 0,  /* cubic B-splines (needs n >= 4 per axis): local support 4x4x4 */
    CM_FFD_BERNSTEIN = 1 /* Bernstein of degree n - 1 (n >= 2): global support, PyGeM's */
} cm_ffd_basis;

typedef enum cm_ffd_knots {
    CM_FFD_KNOTS_UNIFORM = 0, /* the paper's */
    CM_FFD_KNOTS_CLAMPED = 1, /* open uniform; at n = 4 the cubic Bernstein basis */
    CM_FFD_KNOTS_CUSTOM = 2   /* given per axis in cm_ffd_desc.knot (adaptive refinement) */
} cm_ffd_knots;

typedef enum cm_ffd_local {
    CM_FFD_LOCAL_AUTO = 0,   /* affine for the reference lattice, Newton for a moved one */
    CM_FFD_LOCAL_AFFINE = 1, /* always u = A^-1 (x - origin) (ignores moved control points) */
    CM_FFD_LOCAL_NEWTON = 2  /* always Newton from the affine guess (the paper's timing) */
} cm_ffd_local;

typedef struct cm_ffd_desc {
    int n[3];           /* control points per axis */
    cm_ffd_basis basis; /* default CM_FFD_BSPLINE */
    cm_ffd_knots knots; /* B-spline only; default uniform */
    double origin[3];   /* the domain corner u = 0 */
    double axes[9];     /* row-major 3x3; column j is the domain edge a_j (u_j from 0 to 1) */
    /* CM_FFD_KNOTS_CUSTOM: n[a] + 4 knots per axis (copied by create), non-decreasing, with
     * t_3 = 0, t_n = 1 and t_3 < t_4 < ... < t_n (no repeated knot inside the domain) */
    const double *knot[3];
} cm_ffd_desc;

/* Defaults: 4x4x4 B-spline with uniform knots on the unit cube. */
CM_API void cm_ffd_desc_init(cm_ffd_desc *desc);

/* A PyGeM box: A = R diag(length), R = Rx Ry Rz of the angles in degrees (right-handed,
 * applied to column vectors), as PyGeM's angles2matrix(z, y, x). axes: row-major 3x3. */
CM_API void cm_ffd_box_axes(const double length[3], const double angle_deg[3], double axes[9]);

/* A B-spline lattice (uniform knots) whose valid domain is the box bb = {xmin, ymin, zmin,
 * xmax, ymax, zmax} grown by margin x its diagonal on every side, n control points per axis:
 * the "DM-FFD-n lattice enclosing the mesh". */
CM_API void cm_ffd_desc_enclosing(cm_ffd_desc *desc, const double bb[6], double margin, int n);

typedef struct cm_ffd cm_ffd;

/* CM_ERR_ARGUMENT for n below the basis' minimum, a singular or non-finite axis matrix, or
 * more than 2^31 control points. */
CM_API cm_status cm_ffd_create(cm_context *ctx, const cm_ffd_desc *desc, cm_ffd **ffd);
CM_API void cm_ffd_destroy(cm_ffd **ffd);

CM_API size_t cm_ffd_control_count(const cm_ffd *ffd);
/* Reference (or, after cm_ffd_set_control_points, moved) control positions: #ctrl x 3. */
CM_API void cm_ffd_control_points(const cm_ffd *ffd, double *xyz);
/* A pre-deformed lattice: control positions xyz (#ctrl x 3; NULL restores the reference).
 * Local coordinates then need Newton's method (CM_FFD_LOCAL_AUTO switches to it). */
CM_API cm_status cm_ffd_set_control_points(cm_context *ctx, cm_ffd *ffd, const double *xyz);
CM_API void cm_ffd_set_local(cm_ffd *ffd, cm_ffd_local mode);

typedef struct cm_ffd_stats {
    size_t inside, outside; /* points in / out of the lattice */
    size_t failed;          /* Newton did not converge or met a singular Jacobian (folded) */
    int max_iterations;     /* Newton steps of the worst point (0 on the affine path) */
} cm_ffd_stats;

/* Local coordinates of n points (x: n x 3) into u (n x 3) and inside (n flags: 1 inside, 0
 * outside, 2 failed; may be NULL). Newton (moved lattice): damped steps from the affine
 * guess, stops at |F| <= 1e-13 x lattice diagonal or |du| <= 1e-15, at most 30 steps.
 * OpenMP over points. Returns CM_WARNING (message: how many) if any point failed. */
CM_API cm_status cm_ffd_local_coords(cm_context *ctx, const cm_ffd *ffd, size_t n, const double *x,
                              double *u, unsigned char *inside, cm_ffd_stats *stats);

/* Tensor-product basis at local coordinates u in [0,1]^3: the non-zero N_p into idx/w
 * (capacity: cm_ffd_support_size), returns their count. */
CM_API size_t cm_ffd_support_size(const cm_ffd *ffd);
CM_API size_t cm_ffd_basis_eval(const cm_ffd *ffd, const double u[3], int64_t *idx, double *w);

/* FFD displacements: d (n x 3) = sum_p dc_p N_p(u(x_i)) for the points x (n x 3), dc:
 * #ctrl x 3 control displacements. Outside points get 0, failed ones 0 as well (counted,
 * CM_WARNING). stats may be NULL. */
CM_API cm_status cm_ffd_deform(cm_context *ctx, const cm_ffd *ffd, const double *dc, size_t n,
                        const double *x, double *d, cm_ffd_stats *stats);

/* The transpose of cm_ffd_deform in dc, for reverse products: gdc (#ctrl x 3, overwritten) =
 * sum_i N_p(u(x_i)) v_i over the points inside the lattice (v: n x 3); outside and failed
 * points send nothing, as they get 0 from cm_ffd_deform (failed ones counted, CM_WARNING).
 * stats may be NULL. */
CM_API cm_status cm_ffd_deform_transpose(cm_context *ctx, const cm_ffd *ffd, size_t n,
                                         const double *x, const double *v, double *gdc,
                                         cm_ffd_stats *stats);

/* ---- DM-FFD ---- */

typedef struct cm_dmffd_options {
    double eps; /* singular values <= eps * sigma_max are clamped; default 1e-10 */
    int floor;  /* 0: truncate (1/sigma -> 0, the default); 1: floor (1/max(sigma, tau)) */
} cm_dmffd_options;

CM_API void cm_dmffd_options_init(cm_dmffd_options *opt);

typedef struct cm_dmffd_info {
    size_t handles;         /* m */
    size_t active;          /* control points in the support of some handle (SVD columns) */
    size_t rank;            /* singular values kept (not clamped) */
    size_t clamped;         /* singular values clamped */
    double sigma_max, sigma_min;
    double residual;        /* last solve: |Phi C - H|_inf / |H|_inf (0 if H = 0) */
    double residual_abs;    /* last solve: |Phi C - H|_inf */
    double max_control;     /* last solve: max |dc_p| (Euclidean) */
} cm_dmffd_info;

typedef struct cm_dmffd cm_dmffd;

/* Phi (m handles x control points) at the handle positions (handles: m x 3) and its SVD
 * (LAPACKE dgesdd, dgesvd if it does not converge) after dropping the columns that no handle
 * touches. The lattice is borrowed and must outlive the DM-FFD. A handle outside the lattice
 * (or failed in Newton) is CM_ERR_ARGUMENT naming it. */
CM_API cm_status cm_dmffd_create(cm_context *ctx, const cm_ffd *ffd, size_t m, const double *handles,
                          const cm_dmffd_options *opt, cm_dmffd **dm);
CM_API void cm_dmffd_destroy(cm_dmffd **dm);

/* C = Phi^+ H: h (m x 3) handle displacements in, dc (#ctrl x 3) control displacements out
 * (exactly 0 for control points no handle touches). Least norm when under-determined, least
 * squares when over-determined; the residual goes into the info. */
CM_API cm_status cm_dmffd_solve(cm_context *ctx, cm_dmffd *dm, const double *h, double *dc);

/* The transpose of cm_dmffd_solve, for reverse products: gh (m x 3) = (Phi^+)^T gdc, gdc:
 * #ctrl x 3 (control points no handle touches do not enter, as solve gives them 0). Phi^+
 * is the truncated pseudo-inverse of create, fixed by the handle positions and eps: solve
 * is linear in h, and this is its exact transpose. The info is left as it is. */
CM_API cm_status cm_dmffd_solve_transpose(cm_context *ctx, const cm_dmffd *dm, const double *gdc,
                                          double *gh);

CM_API void cm_dmffd_get_info(const cm_dmffd *dm, cm_dmffd_info *info);

/* Eqs. 9-10: B = M Phi^+ (k x m row-major, *b allocated, the caller frees) for the points x
 * (k x 3), so that the displacements of x for any handle displacements H are B H. Points
 * outside the lattice get zero rows. */
CM_API cm_status cm_dmffd_precompute(cm_context *ctx, const cm_dmffd *dm, size_t k, const double *x,
                              double **b);

/* ---- PyGeM parameter files ---- */

/* A PyGeM .prm file (configparser): [Box info] n control points, box length, box origin,
 * rotation angle (degrees) per axis; [Parameters weights] parameter x|y|z lines "i j k mu".
 * mu: n0 n1 n2 x 3 (index (i n1 + j) n2 + k), normalised by the box lengths in the box frame,
 * as PyGeM: the physical displacement is R diag(length) mu. */
typedef struct cm_ffd_prm {
    int n[3];
    double length[3], origin[3], angle[3];
    double *mu;
} cm_ffd_prm;

/* Errors name path:line: CM_ERR_IO (missing file: unlike PyGeM, nothing is written),
 * CM_ERR_FORMAT (missing key or section, a value that is not a number, an index out of
 * range, fewer than 4 numbers on a weight line). */
CM_API cm_status cm_ffd_prm_read(cm_context *ctx, const char *path, cm_ffd_prm *prm);
CM_API void cm_ffd_prm_free(cm_ffd_prm *prm);

/* The lattice of a .prm: the box as the domain (origin, R diag(length)), n per axis, the
 * given basis (Bernstein: PyGeM's map; B-spline: uniform knots on the box as the domain).
 * dc (may be NULL): #ctrl x 3 physical control displacements R diag(length) mu. */
CM_API void cm_ffd_prm_desc(const cm_ffd_prm *prm, cm_ffd_basis basis, cm_ffd_desc *desc, double *dc);

/* The control-displacement table of `cadmorph ffd`: header `i,j,k,dx,dy,dz`, one row per
 * moved control point (0-based lattice indices), physical displacements in the world frame.
 * dc: #ctrl x 3 output (zeroed first); listed: #ctrl flags (may be NULL). Errors name
 * path:line: CM_ERR_FORMAT (header, column count, number), CM_ERR_MISMATCH (index outside
 * the n[0] x n[1] x n[2] lattice, a point listed twice). */
CM_API cm_status cm_ffd_read_displacements(cm_context *ctx, const char *path, const int n[3],
                                    double *dc, unsigned char *listed);

/* ---- one table of point-set deformations (the handle metaphor) ----
 * A deformation carries the prescribed displacements of some points (the constrained ones: a
 * handle region H and a fixed region F, or a mesh's boundary) to the other points. Every
 * method has the life cycle of the warp interface (docs/DESIGN.md, "The warp interface"):
 * create does what depends only on the points and on which of them are constrained (the
 * factorisation, the SVD, the sampling), apply maps prescribed displacements to the free points,
 * any number of times on one deformation. `cadmorph deform` and the volume warp's rbf, dmffd
 * and mls methods (warp.h) go through this table. */

typedef enum cm_deform_method {
    CM_DEFORM_RBF = 0,   /* "rbf": one polyharmonic RBF (rbf.h) through the constrained points,
                            exact (residual 0); needs no cells */
    CM_DEFORM_MLS = 1,   /* "mls": the constrained MLS space deformation (mls.h) over the cells
                            of a mesh [CMLS §4-5]: a weighted fit, exact at the constrained
                            points by default (mls.keep_constrained) */
    CM_DEFORM_SHELL = 2, /* "shell": the mesh-based shell of a surface mesh (cm_mls_shell), the
                            MLS subspace's ground truth [CMLS §3]; solved anew by every apply */
    CM_DEFORM_DMFFD = 3, /* "dmffd": DM-FFD on a cubic B-spline lattice enclosing the points,
                            least squares [SMB14 §2.2]; needs no cells */
    CM_DEFORM_N_METHODS
} cm_deform_method;

/* Short name of a method ("rbf", "mls", "shell", "dmffd"), NULL out of range. */
CM_API const char *cm_deform_method_name(cm_deform_method method);
/* The method of a name, or -1 if unknown. */
CM_API int cm_deform_method_from_name(const char *name);

typedef struct cm_deform_options {
    cm_deform_method method; /* default CM_DEFORM_RBF */
    /* rbf: the kernel (CM_RBF_TRIHARMONIC, the default, or CM_RBF_BIHARMONIC), the solver
     * (rbf.h; default CM_RBF_SOLVER_AUTO) and the iterative solver's tolerance (0: the RBF's
     * default) */
    cm_rbf_kernel kernel;
    cm_rbf_solver solver;
    double tolerance;
    /* rbf, AUTO solver: displacement fields the caller expects to apply on this deformation
     * over its life (cm_deform_apply_many's k counting k; cm_rbf_options.solves); 0 or 1
     * (default): one */
    int solves;
    /* rbf, iterative solver: cm_deform_apply_many's k fields solved in this many groups,
     * each starting from the solutions of those before it (cm_rbf_options.warm_groups); 0 or
     * 1 (default): all at once */
    int warm_groups;
    /* dmffd: control points per axis (4..200; 0 = 10) of the lattice whose domain is the
     * points' bounding box grown by 1e-3 of its diagonal; singular values <= clamp x sigma_max
     * are truncated (0 = 1e-10) */
    int lattice;
    double clamp;
    /* mls: all of them (cm_mls_options_init's defaults); shell: stretch, bend and fix weigh
     * its energies */
    cm_mls_options mls;
} cm_deform_options;

CM_API void cm_deform_options_init(cm_deform_options *opt);

typedef struct cm_deform cm_deform;

/* n points xyz (n x 3). constrained: n entries, 0 for a free point, else the point's
 * constraint group (1..255; the MLS weighs groups apart, e.g. F = 1 and H = 2; the other
 * methods only ask non-zero). rbf and dmffd need only the points (mesh may be NULL; the
 * arrays are copied). mls and shell need the mesh whose nodes the points are (n =
 * mesh->n_nodes; xyz is not read and may be NULL); shell needs its 2D cells and borrows mesh
 * until destroy. opt NULL: the defaults. Errors: the method's (coplanar constrained points
 * are the RBF's CM_ERR_NUMERIC), without a prefix: the caller knows what it was doing;
 * CM_ERR_ARGUMENT for a dmffd lattice outside 4..200 or without a constrained point, or mls
 * and shell without a mesh. No free point (every point constrained): rbf, dmffd and mls with
 * keep_constrained build nothing (their result is the prescribed values; an info message
 * says so, cm_deform_stats.prescribed_only is 1) and cm_deform_get_mls gives NULL. */
CM_API cm_status cm_deform_create(cm_context *ctx, const cm_deform_options *opt, size_t n,
                                  const double *xyz, const unsigned char *constrained,
                                  const cm_mesh *mesh, cm_deform **def);
CM_API void cm_deform_destroy(cm_deform **def);

/* disp: n x 3, read at the constrained points. rbf and dmffd write the free points and leave
 * the constrained ones as they are (dmffd: least squares, so its field misses them by the
 * residual); mls writes every point (the constrained ones as options.mls.keep_constrained
 * says), shell every point. residual (may be NULL): the largest miss at the constrained points
 * (rbf: 0, exact; dmffd: |Phi C - H|_inf; mls: cm_mls_apply's; shell: not measured, 0).
 * A CM_WARNING of the method (dmffd: points Newton could not locate) is returned after the
 * work is done. Not concurrently on one deformation. */
CM_API cm_status cm_deform_apply(cm_context *ctx, cm_deform *def, double *disp, double *residual);

/* k fields at once: disp holds k blocks of n x 3 (block j at disp + 3 n j, each as disp of
 * cm_deform_apply), each transformed as cm_deform_apply would. rbf: one solve and one
 * evaluation of 3k columns, which share the kernel passes (each block scaled to a largest
 * constrained value of 1 for them: the same tolerance per block as its own apply, to the
 * iterative solver's tolerance; dense: to rounding); the other methods: apply per block.
 * residual (may be NULL): the largest over the blocks. A CM_WARNING of a block is returned
 * after every block is done. Memory (rbf): 3k (constrained + free) values besides disp. */
CM_API cm_status cm_deform_apply_many(cm_context *ctx, cm_deform *def, size_t k, double *disp,
                                      double *residual);

/* The reverse product of apply, for adjoint gradients (docs/DESIGN.md, "Gradients"), for a
 * method whose apply is linear in the constrained values D: apply maps D to J D (D at the
 * constrained points, J_f D at the free ones); this computes out = J^T v, so that
 * <v, apply(D)> = <out, D>. v: n x 3, read at every point; out: n x 3, written everywhere:
 * v plus J_f^T v_free at the constrained points, 0 at the free ones (mls with
 * keep_constrained = 0, whose apply gives the constrained points the field's value: J^T v
 * of that map). rbf: one solve with the factorisation or preconditioner of create
 * (cm_rbf_evaluate_transpose); its iterative solve is exact to the tolerance, as apply's.
 * dmffd: the transposed FFD and pseudo-inverse (cm_ffd_deform_transpose,
 * cm_dmffd_solve_transpose: the truncation is fixed by create, so apply is linear); mls:
 * cm_mls_apply_transpose (its constraints are a penalty: linear). shell:
 * CM_ERR_UNSUPPORTED. v and out must not overlap. Not concurrently on one deformation. */
CM_API cm_status cm_deform_apply_transpose(cm_context *ctx, cm_deform *def, const double *v,
                                           double *out);

typedef struct cm_deform_stats {
    cm_deform_method method;
    size_t constrained, free;   /* the points, split */
    double residual;            /* the last apply's */
    double t_solve, t_evaluate; /* the last apply, seconds: the fit to the constrained values
                                   (rbf: cm_rbf_solve; dmffd: C = Phi^+ H) and the evaluation
                                   at the free points; mls and shell: all of it in t_solve */
    cm_rbf_stats rbf;           /* rbf: cm_rbf_get_stats (zero for the others) */
    cm_dmffd_info dmffd;        /* dmffd: cm_dmffd_get_info */
    int lattice;                /* dmffd: control points per axis */
    size_t control_points;      /* dmffd: of the lattice */
    cm_mls_stats mls;           /* mls: cm_mls_get_stats */
    int prescribed_only;        /* 1: no free point and the method gives the constrained ones
                                   their prescribed values (rbf, dmffd, mls with
                                   keep_constrained): create built nothing, apply returns disp
                                   unchanged (residual 0) */
} cm_deform_stats;

CM_API void cm_deform_get_stats(const cm_deform *def, cm_deform_stats *stats);

/* The MLS behind an mls deformation (NULL for the other methods), for work on its factor
 * beyond apply: shape constraints (shapeup.h). */
CM_API cm_mls *cm_deform_get_mls(cm_deform *def);

#ifdef __cplusplus
}
#endif
#endif
