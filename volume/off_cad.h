/* Boundary nodes off G kept fixed (CM_OFF_CAD_FIXED): the check that they are whole boundary
 * components of their own. Private to the morph engine. */
#ifndef CM_VOLUME_OFF_CAD_H
#define CM_VOLUME_OFF_CAD_H

#include "cadmorph/mesh.h"
#include "cadmorph/surface.h"

/* The boundary of b split into components (nodes connected through boundary faces); each
 * must be wholly on G (in nodes) or wholly off it (in nodes->off): else CM_ERR_MISMATCH
 * naming the component, its counts and its farthest off node. *n_components: the components
 * off G. */
cm_status cm_morph_off_cad_check(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                                 const cm_surface_nodes *nodes, size_t *n_components);

#endif
