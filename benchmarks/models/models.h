/* Parametric benchmark models G(t), t in [0, 1] (issue 6): bore, pipe, bracket. The values
 * are fixed by the issue; every t gives the same topology in the same face/edge/vertex order.
 * Lengths are in millimetre (the STEP unit written). */
#ifndef CADMORPH_BENCH_MODELS_H
#define CADMORPH_BENCH_MODELS_H

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
void cm_model_bore_at(double t, cm_model_bore *p);
void cm_model_pipe_at(double t, cm_model_pipe *p);
void cm_model_bracket_at(double t, cm_model_bracket *p);

/* Writes model ("bore", "pipe", "bracket") at t as STEP (AP214, mm). Returns 0 on success,
 * -1 for an unknown model or t outside [0, 1], -2 if OpenCASCADE failed (cm_model_error()
 * says what). */
int cm_model_write_step(const char *model, double t, const char *path);

/* Topology signature of model at t, for checking that G(t) keeps its topology: counts
 * (solids, faces, edges, vertices) and, in MapShapes order, each face's surface type and
 * each edge's curve type and vertex indices, written as text into buf (size bytes).
 * Returns the length written (truncated to size - 1), or -1 on error. Also the solid's
 * volume (BRepGProp) in *volume if not NULL. */
int cm_model_signature(const char *model, double t, char *buf, int size, double *volume);

/* The last error message of this thread's calls ("" if none). */
const char *cm_model_error(void);

#ifdef __cplusplus
}
#endif
#endif
