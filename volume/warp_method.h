/* What one interior-warp method implements (not public; the table is in warp.c). A method
 * keeps its own state behind a void pointer; cm_warp wraps it with the method's row. */
#ifndef CADMORPH_VOLUME_WARP_METHOD_H
#define CADMORPH_VOLUME_WARP_METHOD_H

#include "cadmorph/warp.h"

typedef struct cm_warp_method_ops {
    const char *name; /* as on the command line */
    /* constrained is never NULL here (warp.c defaults it to the boundary nodes). */
    cm_status (*create)(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                        const unsigned char *constrained, const cm_warp_options *opt,
                        void **state);
    /* disp as in cm_warp_apply; *residual: the largest miss at the constrained nodes. */
    cm_status (*apply)(cm_context *ctx, void *state, double *disp, double *residual);
    void (*destroy)(void *state);
} cm_warp_method_ops;

/* The RBF methods (warp_rbf.c). */
extern const cm_warp_method_ops cm_warp_rbf_triharmonic;
extern const cm_warp_method_ops cm_warp_rbf_biharmonic;
/* DM-FFD (warp_dmffd.c). */
extern const cm_warp_method_ops cm_warp_dmffd;

#endif
