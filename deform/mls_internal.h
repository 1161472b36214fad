/* Private pieces of the MLS space deformation (mls.h): a uniform grid over points for
 * nearest-sample queries, the support grid of the shape functions, and the sampling. */
#ifndef CADMORPH_DEFORM_MLS_INTERNAL_H
#define CADMORPH_DEFORM_MLS_INTERNAL_H

#include "cadmorph/mls.h"
#include "cadmorph/shapeup.h"

#include <stdint.h>

/* Points bucketed by a uniform grid (cells of size h over their bounding box). */
typedef struct mls_grid {
    double lo[3], h;
    int n[3];
    int32_t *start; /* #cells + 1 */
    int32_t *items; /* point indices, ascending within a cell */
    const double *xyz;
    size_t n_points;
} mls_grid;

/* target: points per cell (about). */
cm_status mls_grid_build(cm_context *ctx, mls_grid *g, size_t n, const double *xyz,
                         double target);
void mls_grid_free(mls_grid *g);
/* The s nearest points of x (fewer if the grid has fewer): idx and dist ascending by
 * distance; returns the count. */
int mls_grid_nearest(const mls_grid *g, const double x[3], int s, int32_t *idx, double *dist);

/* The shape functions: samples with a support radius each, and a grid whose cells list every
 * sample whose support box overlaps them (ascending). */
struct cm_mls_basis {
    size_t k;
    double *c;     /* k x 3 */
    double *sigma; /* k */
    double lo[3], h;
    int n[3];
    int32_t *start, *items;
    int max_list; /* longest cell list: an upper bound on the samples covering a point */
};

/* How many samples cover x: the count mls_basis_eval returns, without evaluating. */
int mls_basis_count(const cm_mls_basis *b, const double x[3]);
/* Shape functions at x into caller scratch of max_list entries; grad/lap may be NULL.
 * Returns the count (0: no sample covers x). */
int mls_basis_eval(const cm_mls_basis *b, const double x[3], int32_t *idx, double *phi,
                   double *grad, double *lap);

/* Samples of a mesh (section 4-5): dense random points on its surface (2D cells, or the
 * boundary faces of a volume mesh) and in its volume cells. */
typedef struct mls_dense {
    size_t n_s, n_v;      /* surface, volume points */
    double *xyz;          /* (n_s + n_v) x 3: surface points first */
    double *measure;      /* n_s + n_v: the area / volume each point stands for (their sum
                             is about the total); uniform (total / count) when graded = 0 */
    double area, volume;  /* total measures */
} mls_dense;

/* graded in [0, 1]: a face / cell piece is drawn with probability proportional to
 * measure^(1 - graded): 0 uniform by measure (the paper's), 1 each mesh simplex alike (the
 * points follow the mesh's resolution). */
cm_status mls_dense_create(cm_context *ctx, const cm_mesh *mesh, size_t n_surface,
                           size_t n_volume, double graded, uint64_t seed, mls_dense *d);
void mls_dense_free(mls_dense *d);

/* k points out of dense points [first, first + n): farthest-point subset (from a seeded
 * random start) into out (k x 3). */
cm_status mls_farthest(cm_context *ctx, const double *xyz, size_t n, size_t k, uint64_t seed,
                       double *out);
/* Lloyd relaxation of k centres over n weighted points (weight[i], NULL = 1); mass: k output
 * (sum of the weights of the points closest to each centre, may be NULL). */
cm_status mls_lloyd(cm_context *ctx, const double *xyz, const double *weight, size_t n,
                    int iterations, size_t k, double *centres, double *mass);

/* What the Shape-Up alternation (shapeup.c) reads of a cm_mls: Phi at the nodes (CSR), the
 * constrained nodes and their fix weights, and the CHOLMOD factor of eq. 14 (a
 * cholmod_factor *, to be copied, never changed). */
typedef struct mls_view {
    size_t n_nodes, k;
    const int64_t *row;
    const int32_t *col;
    const double *val;
    size_t n_con;
    const int64_t *con;
    const double *wf;
    const unsigned char *is_con;
    int keep_constrained;
    void *factor;
    const struct mls_blend *blend; /* keep_constrained: the miss's way into the free nodes */
} mls_view;

void mls_view_get(cm_mls *m, mls_view *v);

/* The residual blend (mls_blend.c): for the n free nodes within `radius` of a constrained
 * node, width weights each (CSR with fixed-width rows) onto the constrained nodes (col: the
 * index in the constrained list). */
typedef struct mls_blend mls_blend;
struct mls_blend {
    size_t n;
    int width;
    int64_t *node, *row;
    int32_t *col;
    double *val;
};

cm_status mls_blend_create(cm_context *ctx, size_t n, const double *xyz, const unsigned char *is_con,
                           size_t n_con, const int64_t *con, double radius, mls_blend *b);
void mls_blend_free(mls_blend *b);
/* disp[node] += sum val r[col] (r: n_con x 3). */
void mls_blend_apply(const mls_blend *b, const double *r, double *disp, int threads);

/* The snap of the Shape-Up alternation (shapeup_snap.c): the sets (n_sets, type, off, nodes,
 * ref: as cm_shapeup keeps them) and p, the projections of the positions ref + disp, every
 * set's own fit (used for the sets that are not planes). */
typedef struct shapeup_snap_in {
    const mls_view *v;
    size_t n_sets;
    const cm_shape_type *type;
    const size_t *off;
    const int64_t *nodes;
    const double *ref, *p;
    double diag;
} shapeup_snap_in;
/* Moves the set nodes of disp (#nodes x 3) onto their shapes: a plane through the set's
 * constrained nodes where they span one (keep_constrained), else its least-squares plane; a
 * node of several planes onto their intersection; other shapes onto p. Constrained nodes
 * stay when keep_constrained. *move: the largest move. */
cm_status shapeup_snap(cm_context *ctx, const shapeup_snap_in *in, double *disp, double *move);

#endif
