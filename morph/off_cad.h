/* Boundary nodes off G kept fixed (CM_OFF_CAD_FIXED): the check that they are whole boundary
 * components of their own. Private to the morph engine. */
#ifndef CM_MORPH_OFF_CAD_H
#define CM_MORPH_OFF_CAD_H

#include "cadmorph/mesh.h"
#include "cadmorph/surface.h"

/* Nodes on G that share a boundary face with a node off G: where a body touches the fixed
 * surface (a car standing on the tunnel's floor). Each may move only within the fixed
 * surface around it: along its plane when the fixed faces around it are flat (normal set),
 * not at all when they are not (normal 0 0 0). */
typedef struct cm_off_cad_contact {
    size_t n;
    size_t *index;  /* n: index into nodes->node (and the surface morph's arrays) */
    double *normal; /* n x 3: unit normal of the flat fixed surface around it, or 0 */
    double *tol;    /* n: allowed move off that surface (1e-3 x its shortest boundary edge) */
} cm_off_cad_contact;

void cm_off_cad_contact_free(cm_off_cad_contact *c);

/* The boundary of b split into components (nodes connected through boundary faces). A
 * component wholly off G (in nodes->off) is counted in *n_components; one wholly on G is
 * the morph's usual business; one partly on G gets its contact nodes into *contact (the morph
 * then checks with cm_morph_off_cad_contact_check that the edit keeps them on the fixed
 * surface). *n_partial: the components partly on G. */
cm_status cm_morph_off_cad_check(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                                 const cm_surface_nodes *nodes, size_t *n_components,
                                 size_t *n_partial, cm_off_cad_contact *contact);

/* bnew: nodes->n x 3, the boundary nodes' new positions: CM_ERR_MISMATCH naming the first
 * contact node that the edit moves off the fixed surface (and by how much). */
cm_status cm_morph_off_cad_contact_check(cm_context *ctx, const cm_mesh *mesh,
                                         const cm_surface_nodes *nodes,
                                         const cm_off_cad_contact *contact, const double *bnew);

#endif
