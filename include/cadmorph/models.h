/* cadmorph built-in models: the parametric families G(t), t in [0, 1], of `cadmorph sweep`
 * and `cadmorph demo`: bore and pipe after [SKM11], and a bracket. The values are fixed (the
 * recorded sweeps and studies depend on them); every t gives the same topology in the same
 * face/edge/vertex order. Lengths are in millimetre (the STEP unit written). Conventions: see
 * core.h.
 *
 * Two libraries implement this header, each inside its module's rules: the solids and their
 * STEP export are OpenCASCADE code (the cad module); the structured hex meshes of G(0) are mesh
 * code (the study module): docs/DESIGN.md, "Modules". */
#ifndef CADMORPH_MODELS_H
#define CADMORPH_MODELS_H

#include "cadmorph/core.h"
#include "cadmorph/mesh.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* bore: block [-2,2] x [-2,2] x [0,2] with a through-bore along z at its centre, tilted about
 * the x axis through the block centre (0, 0, 1). */
typedef struct cm_model_bore {
    double radius;     /* 0.6 -> 1.0 */
    double tilt_deg;   /* 0 -> 25, rotation about +x */
} cm_model_bore;

/* pipe: solid rod of radius 0.5 along a centreline that starts at the origin heading +x
 * (inlet), bends towards +y about the axis through (inlet, bend_radius, 0) parallel to z,
 * then runs straight (outlet). */
typedef struct cm_model_pipe {
    double radius;          /* 0.5 */
    double inlet;           /* 2 */
    double bend_radius;     /* 2 -> 1.5 */
    double bend_deg;        /* 90 -> 135 */
    double outlet;          /* 2 -> 4 */
} cm_model_pipe;

/* bracket: L profile in the xy plane (outer corner at the origin, legs along +x and +y, leg
 * width 1), extruded 3 along z; fillet on the inner vertical edge at (1, 1); one through-hole
 * per leg at mid-height, its axis across the leg. */
typedef struct cm_model_bracket {
    double leg, width, height;   /* 5, 1, 3 */
    double fillet;               /* 0.5 -> 1.0 */
    double hole_radius;          /* 0.4 -> 0.6 (both holes) */
    double hole1_x;              /* hole of the x leg: 3 -> 3.5 from the outer corner */
    double hole2_y;              /* hole of the y leg: 3 */
} cm_model_bracket;

/* Parameters at t (linear interpolation between the values at t = 0 and t = 1). */
CM_API void cm_model_bore_at(double t, cm_model_bore *p);
CM_API void cm_model_pipe_at(double t, cm_model_pipe *p);
CM_API void cm_model_bracket_at(double t, cm_model_bracket *p);

/* Non-zero if name is a built-in model ("bore", "pipe", "bracket"). */
CM_API int cm_model_known(const char *name);
/* The model names joined by ", " ("bore, pipe, bracket"), for messages. */
CM_API const char *cm_model_list(void);

/* Writes model at t as STEP (AP214, mm). Errors: CM_ERR_ARGUMENT for an unknown model or t
 * outside [0, 1], CM_ERR_IO when path cannot be written, CM_ERR_CAD when OpenCASCADE fails.
 * Process-wide effect: removes the stdout printer of OpenCASCADE's default messenger (as
 * cm_cad_read does). */
CM_API cm_status cm_model_write_step(cm_context *ctx, const char *model, double t, const char *path);

/* Topology signature of model at t, for checking that G(t) keeps its topology: counts
 * (solids, faces, edges, vertices) and, in MapShapes order, each face's surface type and
 * each edge's curve type and vertex indices, written as text into buf (size bytes, truncated
 * to size - 1). Also the solid's volume (BRepGProp) in *volume if not NULL. Errors as
 * cm_model_write_step. */
CM_API cm_status cm_model_signature(cm_context *ctx, const char *model, double t, char *buf,
                             size_t size, double *volume);

/* ---- structured hex meshes of G(0) ----
 * O-grids whose boundary nodes lie exactly on G(0) (the parameters above at t = 0). */

/* bore: an O-grid of the annulus between the bore (radius 0.6) and the block's square
 * section, n_theta cells around (a multiple of 8: the square's corners are nodes), n_r
 * across (graded towards the bore by `grading` per cell, 1 = uniform), n_z along z.
 * Hexes (physical 1) only; their boundary is the bore's surface. */
CM_API cm_status cm_hexmesh_bore(cm_context *ctx, int n_theta, int n_r, int n_z, double grading,
                          cm_mesh **mesh);

/* pipe: a butterfly O-grid of the disc (central square of n x n cells, a ring of n_ring cells
 * outside each of its sides) swept along the centreline with cells of about `step` length. */
CM_API cm_status cm_hexmesh_pipe(cm_context *ctx, int n, int n_ring, double step, cm_mesh **mesh);

#ifdef __cplusplus
}
#endif
#endif
