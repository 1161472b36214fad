/* cadmorph boundary motion by patch kind: how each node of a volume mesh may move in a morph
 * (fixed, prescribed, sliding on a plane, a line or a surface, or free), from the kinds of the
 * patches its boundary faces belong to (cm_patch_kind, mesh.h) and the user's choice; the
 * recognition of one-cell-thick 2-D meshes and axisymmetric wedges, which are morphed exactly
 * as 2-D (docs/DESIGN.md, "Boundary motion by patch kind"). Conventions: see core.h.
 *
 * Defaults: symmetry, empty, wedge and cyclic patches slide (each on its plane; a patch that
 * is not flat on its initial surface, by closest point); plain patches are fixed unless a node
 * is prescribed; processor patches are no boundary. A node on several patches: prescribed
 * beats fixed beats slide; two slide planes make it slide on their common line; three or
 * more non-parallel planes fix it. */
#ifndef CADMORPH_MOTION_H
#define CADMORPH_MOTION_H

#include "cadmorph/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum cm_motion_kind {
    CM_MOTION_FREE = 0,          /* interior (or only on processor patches): the warp moves it */
    CM_MOTION_FIXED = 1,         /* stays where it is */
    CM_MOTION_PRESCRIBED = 2,    /* moves by its given displacement */
    CM_MOTION_SLIDE_PLANE = 3,   /* moves within the plane through it (normal motion zero) */
    CM_MOTION_SLIDE_LINE = 4,    /* moves along the line through it (two slide planes meet) */
    CM_MOTION_SLIDE_SURFACE = 5, /* stays on its patch's initial surface (closest point) */
    CM_MOTION_N_KINDS
} cm_motion_kind;

/* Short name of a kind ("free", "fixed", "prescribed", "plane", "line", "surface"). */
CM_API const char *cm_motion_kind_name(cm_motion_kind kind);

typedef enum cm_motion_reduction {
    CM_MOTION_3D = 0,           /* no reduction */
    CM_MOTION_2D = 1,           /* one cell thick between two parallel empty planes */
    CM_MOTION_AXISYMMETRIC = 2, /* a wedge between two wedge planes through an axis */
} cm_motion_reduction;

typedef struct cm_motion_options {
    /* patch names (groups of dimension 2) that slide even if plain, and that are fixed even
     * if their kind slides; a name the mesh does not have is CM_ERR_ARGUMENT naming the
     * mesh's patches; a name in both lists likewise */
    const char *const *slide;
    size_t n_slide;
    const char *const *fixed;
    size_t n_fixed;
    /* 1: no slides and no 2-D/wedge reduction, every boundary node fixed unless prescribed
     * (the motion before patch kinds) */
    int all_fixed;
    /* 1: no 2-D/wedge reduction (slides still hold) */
    int no_reduction;
} cm_motion_options;

CM_API void cm_motion_options_init(cm_motion_options *opt);

typedef struct cm_boundary_motion cm_boundary_motion;

/* mesh, b (cm_mesh_boundary_create of mesh): borrowed for the call. prescribed: #nodes flags
 * (may be NULL: none), non-zero where the caller gives the displacement (boundary or
 * interior nodes). The kinds of the boundary nodes come from the 2-D cells carrying a
 * patch's physical tag; a boundary node on no patch face is fixed. A slide patch that could
 * not be used (its surface could not be built) is fixed, with a CM_LOG_WARNING. */
CM_API cm_status cm_boundary_motion_create(cm_context *ctx, const cm_mesh *mesh,
                                           const cm_mesh_boundary *b,
                                           const unsigned char *prescribed,
                                           const cm_motion_options *opt,
                                           cm_boundary_motion **motion);
CM_API void cm_boundary_motion_destroy(cm_boundary_motion **motion);

/* The kind of a node (CM_MOTION_FREE out of range). In a 2-D or axisymmetric mesh, the kind
 * of a pair: a node whose partner is prescribed is prescribed too (it takes that motion). */
CM_API cm_motion_kind cm_boundary_motion_kind(const cm_boundary_motion *motion, size_t node);
/* Nodes of a kind. */
CM_API size_t cm_boundary_motion_count(const cm_boundary_motion *motion, cm_motion_kind kind);
/* The reduction recognised (CM_MOTION_3D unless the mesh is 2-D or a wedge). axis: NULL or 6
 * doubles, written for CM_MOTION_2D (0 0 0 and the unit normal of the planes) and
 * CM_MOTION_AXISYMMETRIC (a point of the axis and its unit direction); angle: NULL or the
 * wedge's opening angle in radians (0 otherwise). */
CM_API cm_motion_reduction cm_boundary_motion_reduction(const cm_boundary_motion *motion,
                                                        double *axis, double *angle);
/* 2-D and axisymmetric: the node's partner on the other plane, -1 for none (axis nodes, or
 * no reduction). */
CM_API int64_t cm_boundary_motion_partner(const cm_boundary_motion *motion, size_t node);

/* Makes a displacement field (#nodes x 3) admissible: fixed nodes 0; prescribed nodes keep
 * their value without its component out of the 2-D plane (or, in a wedge, its tangential
 * component: a CM_WARNING names the first such node and the largest); a node whose partner
 * is prescribed and itself not takes the partner's value; slide nodes are projected onto
 * their constraint (plane, line, closest point of the surface); a 2-D or axisymmetric pair
 * gets one in-plane motion (the mean). Free nodes are left alone. */
CM_API cm_status cm_boundary_motion_project(cm_context *ctx, const cm_boundary_motion *motion,
                                            double *disp);

#ifdef __cplusplus
}
#endif
#endif
