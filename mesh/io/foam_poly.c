/* The shared polyMesh record (foam_internal.h): created by the reader and the face addressing,
 * held by the origin of a mesh read from a polyMesh (origin.h) and by the metrics. A leaf. */
#include "foam_internal.h"

#include <stdlib.h>

cm_foam_poly *cm_foam_poly_new(void)
{
    cm_foam_poly *p = calloc(1, sizeof *p);
    if (p) {
        p->refs = 1;
        p->label_bytes = 4;
        p->scalar_bytes = 8;
    }
    return p;
}

cm_foam_poly *cm_foam_poly_retain(cm_foam_poly *p)
{
    /* atomic: copies of one mesh may be made and destroyed on several threads */
    if (p) __atomic_add_fetch(&p->refs, 1, __ATOMIC_RELAXED);
    return p;
}

void cm_foam_poly_free(void *p)
{
    cm_foam_poly *q = p;
    cm_foam_poly_release(&q);
}

void cm_foam_poly_release(cm_foam_poly **pp)
{
    if (!pp || !*pp) return;
    cm_foam_poly *p = *pp;
    *pp = NULL;
    if (__atomic_sub_fetch(&p->refs, 1, __ATOMIC_ACQ_REL) > 0) return;
    free(p->dir);
    free(p->face_off);
    free(p->face_nodes);
    free(p->owner);
    free(p->neighbour);
    for (size_t i = 0; i < p->n_patches; ++i) {
        free(p->patches[i].name);
        free(p->patches[i].type);
        free(p->patches[i].dict);
    }
    free(p->patches);
    for (size_t i = 0; i < p->n_zones; ++i) {
        free(p->zones[i].name);
        free(p->zones[i].ids);
        free(p->zones[i].flip);
    }
    free(p->zones);
    free(p->points_head);
    free(p->points_tail);
    free(p->xyz0);
    free(p->case_dir);
    for (size_t i = 0; i < p->n_pieces; ++i) {
        cm_foam_poly_release(&p->pieces[i]);
        free(p->piece_points[i]);
    }
    free(p->pieces);
    free(p->piece_points);
    free(p);
}
