/* The record of the file a mesh was read from (origin.h). */
#include "origin.h"

#include <stdlib.h>

cm_status cm_mesh_set_origin(cm_context *ctx, cm_mesh *m, cm_mesh_format format, void *state,
                             void (*free_state)(void *state))
{
    cm_mesh_origin_release(&m->origin);
    cm_mesh_origin *o = calloc(1, sizeof *o);
    if (!o) {
        if (free_state) free_state(state);
        return cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    }
    o->refs = 1;
    o->format = format;
    o->n_nodes = m->n_nodes;
    o->n_cells = m->n_cells;
    o->state = state;
    o->free_state = free_state;
    m->origin = o;
    return CM_OK;
}

void *cm_mesh_origin_state(const cm_mesh *m, cm_mesh_format format)
{
    const cm_mesh_origin *o = m ? m->origin : NULL;
    if (!o || o->format != format || o->n_nodes != m->n_nodes || o->n_cells != m->n_cells) return NULL;
    return o->state;
}

cm_mesh_format cm_mesh_origin_format(const cm_mesh *m)
{
    return m && m->origin ? m->origin->format : CM_FORMAT_UNKNOWN;
}

cm_mesh_origin *cm_mesh_origin_retain(cm_mesh_origin *o)
{
    /* atomic: copies of one mesh may be made and destroyed on several threads */
    if (o) __atomic_add_fetch(&o->refs, 1, __ATOMIC_RELAXED);
    return o;
}

void cm_mesh_origin_release(cm_mesh_origin **oo)
{
    if (!oo || !*oo) return;
    cm_mesh_origin *o = *oo;
    *oo = NULL;
    if (__atomic_sub_fetch(&o->refs, 1, __ATOMIC_ACQ_REL) > 0) return;
    if (o->free_state) o->free_state(o->state);
    free(o);
}
