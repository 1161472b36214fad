/* Shared by the surface sources (not public): nodes grouped by the entity they lie on. */
#ifndef CADMORPH_SURFACE_INTERNAL_H
#define CADMORPH_SURFACE_INTERNAL_H

#include "cadmorph/surface.h"

/* The nodes of `kind`, grouped by entity (counting sort, ascending node order inside each
 * group): entity e's nodes are idx[first[e] .. first[e+1]). first: n_entities + 1 entries.
 * Both arrays are allocated here; free() them. */
cm_status cm_surface_group(cm_context *ctx, const cm_surface_nodes *nodes, cm_surface_kind kind,
                           int n_entities, size_t **first, size_t **idx);

/* An affine map x -> A x + b (surface/affine.c): m row-major 3 x 4, A then b. valid when the
 * vertices of G map onto those of G' within tol (residual: the largest miss). */
typedef struct cm_surface_affine {
    double m[3][4];
    double residual, tol;
    int valid;
} cm_surface_affine;

void cm_surface_affine_apply(const cm_surface_affine *a, const double *x, double *y);
/* Least-squares fit of G' vertices against G vertices; a->valid says whether every vertex is
 * reproduced within tol. Fewer than 4 or coplanar vertices: cm_surface_affine_fit_samples. */
cm_status cm_surface_affine_fit(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                                double tol, cm_surface_affine *a);
/* The map from the volume moments and points over every edge and face of G (surface/
 * affine_fit.c), xv, yv: the nv vertices of G and G' (n x 3). a->valid when every vertex,
 * edge point and face point of G maps within tol of its entity of G' (a->residual: the
 * largest miss) and the volumes agree. */
cm_status cm_surface_affine_fit_samples(cm_context *ctx, const cm_cad_model *g,
                                        const cm_cad_model *g2, const double *xv,
                                        const double *yv, int nv, double tol,
                                        cm_surface_affine *a);
/* *is_image = 1 when n points spread over edge e of G map within a->tol of edge e of G'. */
cm_status cm_surface_affine_edge(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                                 const cm_surface_affine *a, int e, int n, int *is_image);

#endif
