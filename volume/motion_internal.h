/* The boundary motion's state (motion.h), shared by volume/motion*.c and the whole-mesh warp
 * (warp.c). Not public. Constraints live in the "work space": the mesh's own coordinates,
 * except for an axisymmetric wedge, whose work space is the slab (r, z, w) of
 * docs/DESIGN.md, "Boundary motion by patch kind". */
#ifndef CADMORPH_VOLUME_MOTION_INTERNAL_H
#define CADMORPH_VOLUME_MOTION_INTERNAL_H

#include "cadmorph/motion.h"

#include <stdint.h>

/* A patch a node may slide on by closest point: its initial triangles (motion_surface.c). */
typedef struct cm_motion_surface cm_motion_surface;

struct cm_boundary_motion {
    size_t n;
    uint8_t *kind;     /* #nodes cm_motion_kind */
    double *dir;       /* #nodes x 3, work space: plane normal or line direction (unit) */
    int32_t *surface;  /* #nodes: SLIDE_SURFACE: index into surfaces; NULL if none */
    cm_motion_surface **surfaces;
    size_t n_surfaces;
    int64_t *partner;  /* #nodes, -1 none; NULL unless 2-D or axisymmetric */
    unsigned char *copy; /* #nodes: takes the partner's prescribed value (NULL: none) */
    cm_motion_reduction reduction;
    double axis[6], angle;
    double *slab;      /* axisymmetric: #nodes x 3 work coordinates (r, z, w) */
    double *er;        /* axisymmetric: #nodes x 3 radial unit vectors (axis nodes: any) */
    double *xyz0;      /* #nodes x 3 initial work coordinates (surface slides); borrowed from
                          slab or copied from the mesh */
    size_t count[CM_MOTION_N_KINDS];
    double diag;       /* the mesh's bounding-box diagonal */
};

/* 2-D and wedge recognition (motion_reduce.c): sets reduction, axis, angle, partner, and for
 * a wedge slab and er. empty, wedge: the indices of the sliding empty and wedge groups.
 * flat_tol: distance tolerance of a plane. A mesh that is neither keeps reduction 3-D;
 * CM_ERR_NOMEM is the only error. */
cm_status cm_motion_reduce(cm_context *ctx, cm_boundary_motion *m, const cm_mesh *mesh,
                           const cm_mesh_boundary *b, const int *empty, int n_empty,
                           const int *wedge, int n_wedge, double flat_tol);

/* Translational cyclic pairs (motion_reduce.c): two flat parallel cyclic patches whose nodes
 * match across their normal; each node is paired with its image (partner), so that both
 * sides of the pair get one motion. A mesh already reduced keeps its pairs. */
cm_status cm_motion_pair_cyclic(cm_context *ctx, cm_boundary_motion *m, const cm_mesh *mesh,
                                const int *cyclic, int n_cyclic, double flat_tol);

/* Shared geometry (motion_geom.c): a polygon's area normal (Newell); a unit vector with round-off
 * components made 0; a group's aligned area-weighted normal, 1 if its faces lie in planes of
 * that normal to tol. */
void cm_motion_face_normal(const double *xyz, const int64_t *nodes, int64_t k, double *n);
void cm_motion_snap(double *v);
int cm_motion_group_plane(const cm_mesh *mesh, const double *xyz, int tag, double tol,
                          double *nrm);

/* disp (#nodes x 3, mesh space) to work (work space) and back: the identity unless
 * axisymmetric (work = (dr, dz, 0); back: dr e_r + dz e_axis). to_work returns the largest
 * component dropped at a prescribed node (tangential in a wedge) and that node. */
double cm_motion_to_work(const cm_boundary_motion *m, const double *disp, double *work,
                         size_t *worst);
void cm_motion_from_work(const cm_boundary_motion *m, const double *work, double *disp);
/* cm_boundary_motion_project in work space; *dropped: the largest normal component removed
 * at a prescribed node of a 2-D mesh, *worst its node. */
void cm_motion_project_work(const cm_boundary_motion *m, double *work, double *dropped,
                            size_t *worst);

/* Surfaces (motion_surface.c): a patch's triangles in work coordinates. */
cm_status cm_motion_surface_create(cm_context *ctx, const cm_mesh *mesh, const double *xyz,
                                   int tag, cm_motion_surface **s);
void cm_motion_surface_destroy(cm_motion_surface *s);
/* The closest point of the surface to p (3), written to out (3). */
void cm_motion_surface_closest(const cm_motion_surface *s, const double *p, double *out);

#endif
