/* Boundary motion by patch kind in `cadmorph deform --fix-unlisted-boundary` (motion.h;
 * docs/DESIGN.md, "Boundary motion by patch kind"): sliding patches are not fixed, they follow
 * the deformation and are then projected onto their constraints, the interior corrected by a
 * warp of the correction (cm_warp_correct), so that fixed, handle and slide nodes hold
 * exactly; 2-D and wedge meshes get one in-plane motion per pair. A mesh where nothing slides
 * deforms as it always did (no motion, no correction). */
#ifndef CADMORPH_CLI_DEFORM_MOTION_H
#define CADMORPH_CLI_DEFORM_MOTION_H

#include "patch_motion.h"

#include "cadmorph/warp.h"

typedef struct cli_deform_motion {
    cm_boundary_motion *motion; /* NULL: no motion (the options or the mesh ask for none) */
    double *handles;            /* #nodes x 3: the handles' values (restored after deform) */
} cli_deform_motion;

/* Before the deformation: the motion of mesh (b: its boundary) with the handle nodes
 * (con != 0) prescribed; disp (the handles' values) made admissible (a 2-D partner of a
 * handle becomes a handle with its motion: con set); border (the boundary flags that
 * --fix-unlisted-boundary fixes) cleared at the nodes that slide. */
cm_status cli_deform_motion_begin(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                                  const cli_patch_motion *pm, double *disp, unsigned char *con,
                                  unsigned char *border, cli_deform_motion *dm);
/* After it: the handles at their values, fixed nodes at 0, slide nodes projected, the
 * interior corrected. No-op without a motion. */
cm_status cli_deform_motion_end(cm_context *ctx, const cm_mesh *mesh, cli_deform_motion *dm,
                                double *disp);
void cli_deform_motion_free(cli_deform_motion *dm);

#endif
