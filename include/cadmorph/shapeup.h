/* cadmorph shape constraints in the MLS deformation (Sieger, Menzel, Botsch, "Constrained
 * space deformation techniques for design optimization", section 6; Bouaziz et al.,
 * "Shape-Up", 2012): projections of a point set onto the nearest planar, circular,
 * cylindrical, similar (feature line) or congruent (rigid) set, and the Shape-Up alternation
 * that adds gamma_c sum_t |C_t (x - P_t(x))|^2 to the MLS energy (eq. 17).
 * Conventions: see core.h. Point arrays are n x 3 row-major doubles. */
#ifndef CADMORPH_SHAPEUP_H
#define CADMORPH_SHAPEUP_H

#include "cadmorph/mls.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- projections (each with its own least-squares fit) ---- */

/* The least-squares plane of x (n >= 3; total least squares through the centroid):
 * p the orthogonal projections (may alias x), fit (may be NULL) = centroid[3], unit normal[3]. */
CM_API cm_status cm_shape_project_plane(cm_context *ctx, size_t n, const double *x, double *p,
                                        double fit[6]);

/* The geometric least-squares circle in the least-squares plane (n >= 3): points go to the
 * plane, then radially onto the circle. fit (may be NULL) = centre[3], unit normal[3], radius. */
CM_API cm_status cm_shape_project_circle(cm_context *ctx, size_t n, const double *x, double *p,
                                         double fit[7]);

/* The geometric least-squares cylinder (n >= 5): the axis direction minimising Eberly's
 * algebraic error over the hemisphere ("Least squares fitting of data by cylinders"),
 * refined by Levenberg-Marquardt on the distances to the axis minus the radius; points move
 * radially onto it. guess: a previous fit (point on axis[3], unit axis[3], radius) to start
 * from instead of the search, or NULL. fit (may be NULL) receives the same 7 numbers. */
CM_API cm_status cm_shape_project_cylinder(cm_context *ctx, size_t n, const double *x,
                                           const double *guess, double *p, double fit[7]);

/* The geometric least-squares cone (n >= 6; one nappe): the axis direction minimising the
 * algebraic error of circles whose radius grows linearly along it (the cylinder's search),
 * refined by Levenberg-Marquardt on the distances to the cone; points move to the nearest
 * point of their generator (the apex for points behind it). guess: a previous fit (apex[3],
 * unit axis[3] into the nappe, half-angle in (0, pi/2)) to start from, or NULL. fit (may be
 * NULL) receives the same 7 numbers. */
CM_API cm_status cm_shape_project_cone(cm_context *ctx, size_t n, const double *x,
                                       const double *guess, double *p, double fit[7]);

/* The least-squares match of a reference shape ref onto x (n >= 1, same order): a rotation
 * and a translation (scale = 0, rigid), plus a uniform scale (scale = 1, conformal: feature
 * lines); Kabsch/Umeyama with LAPACK's SVD, no reflection. p = s R (ref - mean ref) + mean x. */
CM_API cm_status cm_shape_project_similar(cm_context *ctx, size_t n, const double *ref,
                                          const double *x, int scale, double *p);

/* ---- Shape-Up in the MLS deformation ---- */

typedef enum cm_shape_type {
    CM_SHAPE_PLANE = 0,
    CM_SHAPE_CIRCLE,
    CM_SHAPE_CYLINDER,
    CM_SHAPE_LINE,  /* feature line: conformal match of the initial polyline */
    CM_SHAPE_RIGID,
    CM_SHAPE_CONE
} cm_shape_type;

/* "plane", "circle", "cylinder", "line", "rigid", "cone"; NULL for an unknown type. */
CM_API const char *cm_shape_type_name(cm_shape_type t);
/* The type of a name; CM_ERR_ARGUMENT for an unknown one. */
CM_API cm_status cm_shape_type_parse(cm_context *ctx, const char *name, cm_shape_type *t);

typedef struct cm_shape_set {
    cm_shape_type type;
    size_t n;
    const int64_t *nodes; /* n node indices, 0-based, distinct; borrowed for create */
} cm_shape_set;

typedef struct cm_shapeup_options {
    double weight;      /* gamma_c (10), divided by each set's size as the fix weights are */
    int max_iterations; /* cap on local/global alternations (10000) */
    double tolerance;   /* stop when no set node moves more than tolerance x the bounding-box
                           diagonal in one alternation (1e-9) */
    int sparse;         /* 1: section 6.1, subtract one point of each set (sparse C);
                           0: mean-centring (dense n_t x n_t blocks) */
    int reorder;        /* 1: factor MLS matrix + gamma_c Phi^T C^T C Phi afresh with its own
                           fill-reducing ordering (default); 0: CHOLMOD's rank update of the MLS
                           factor in the MLS ordering (cheaper for small sets, more fill for
                           large ones) */
    int anderson;       /* > 0: Anderson acceleration with this many past iterates (at most 64;
                           0: the plain alternation, default) */
    int snap;           /* 1: after the alternation and the blend of the constrained nodes'
                           miss, the set nodes go onto their shapes, so that the result holds
                           them to rounding: a plane through the set's constrained nodes
                           where they span one (with keep_constrained they stay where they
                           are prescribed), else its least-squares plane; a node of several
                           plane sets onto their intersection, of other sets the last one's
                           projection; 0: the field everywhere (default) */
} cm_shapeup_options;

CM_API void cm_shapeup_options_init(cm_shapeup_options *opt);

typedef struct cm_shapeup cm_shapeup;

/* Factors MLS normal equations + gamma_c Phi^T C^T C Phi once (from the MLS factor: see
 * reorder). mls and mesh (the one mls was built on) are borrowed and must outlive the
 * object; sets are copied. A set needs at least 3 nodes (5 for a cylinder, 6 for a cone). */
CM_API cm_status cm_shapeup_create(cm_context *ctx, cm_mls *mls, const cm_mesh *mesh,
                                   size_t n_sets, const cm_shape_set *sets,
                                   const cm_shapeup_options *opt, cm_shapeup **su);
CM_API void cm_shapeup_destroy(cm_shapeup **su);

typedef struct cm_shapeup_report {
    int iterations;      /* alternations done */
    int converged;       /* 1 if the tolerance was met before the cap */
    double last_move;    /* largest move of a set node in the last alternation */
    double fix_residual; /* largest miss at the MLS constrained nodes */
    double snap_move;    /* snap: the largest move of a set node onto its projection */
    size_t c_nonzeros;   /* entries of C */
    size_t update_nonzeros; /* entries of Phi^T C^T (the columns of the factor update) */
    size_t factor_nonzeros; /* entries of the constrained factor */
    size_t mls_factor_nonzeros; /* entries of the MLS factor's L (reorder only; else 0) */
    double t_factor, t_iterate; /* seconds: the update at create, the last apply's loop */
} cm_shapeup_report;

/* disp as cm_mls_apply: #nodes x 3, read at the MLS constrained nodes, written at every node.
 * With keep_constrained the constrained nodes keep their prescribed values and the field's
 * miss there is blended into the free nodes, as cm_mls_apply does; at the nodes of a plane
 * set only the blend's part along the set's plane (of the alternation's positions), so that
 * the blend does not undo the constraint beside a handle.
 * residual: n_sets output (may be NULL): the largest distance of a set's node from the
 * projection of its set, before (residual0, the unconstrained deformation; may be NULL) and
 * after (snap: of the result written into disp). CM_WARNING if the cap was reached before
 * the tolerance. */
CM_API cm_status cm_shapeup_apply(cm_context *ctx, cm_shapeup *su, double *disp,
                                  double *residual0, double *residual, cm_shapeup_report *rep);

#ifdef __cplusplus
}
#endif
#endif
