/* Shared by the surface sources (not public): nodes grouped by the entity they lie on. */
#ifndef CADMORPH_SURFACE_INTERNAL_H
#define CADMORPH_SURFACE_INTERNAL_H

#include "cadmorph/surface.h"

/* The nodes of `kind`, grouped by entity (counting sort, ascending node order inside each
 * group): entity e's nodes are idx[first[e] .. first[e+1]). first: n_entities + 1 entries.
 * Both arrays are allocated here; free() them. */
cm_status cm_surface_group(cm_context *ctx, const cm_surface_nodes *nodes, cm_surface_kind kind,
                           int n_entities, size_t **first, size_t **idx);

#endif
