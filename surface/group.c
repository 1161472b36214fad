/* Nodes grouped by the CAD entity they lie on, so that the per-entity work of the surface
 * morph is linear in the node count rather than nodes x entities. */
#include "surface_internal.h"

#include <stdlib.h>

cm_status cm_surface_group(cm_context *ctx, const cm_surface_nodes *s, cm_surface_kind kind,
                           int n_entities, size_t **first, size_t **idx)
{
    size_t ne = n_entities > 0 ? (size_t)n_entities : 0;
    *first = calloc(ne + 1, sizeof **first);
    *idx = malloc((s->n ? s->n : 1) * sizeof **idx);
    if (!*first || !*idx) {
        free(*first);
        free(*idx);
        *first = NULL;
        *idx = NULL;
        return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_group: out of memory");
    }
    size_t *f = *first, *x = *idx;
    for (size_t i = 0; i < s->n; ++i)
        if (s->kind[i] == kind && s->entity[i] >= 0 && (size_t)s->entity[i] < ne)
            f[s->entity[i] + 1]++;
    for (size_t e = 0; e < ne; ++e)
        f[e + 1] += f[e];
    for (size_t i = 0; i < s->n; ++i)
        if (s->kind[i] == kind && s->entity[i] >= 0 && (size_t)s->entity[i] < ne)
            x[f[s->entity[i]]++] = i;
    /* the fill advanced each start to the next group's: shift back */
    for (size_t e = ne; e > 0; --e)
        f[e] = f[e - 1];
    f[0] = 0;
    return CM_OK;
}
