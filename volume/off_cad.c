/* Off-CAD boundary nodes kept fixed: a wind tunnel around a body is a boundary component of
 * its own, none of whose nodes is on the body's CAD model. A component with some nodes on G
 * and some off is not that: it is a mesh that is partly not of G (a missing face, a tolerance
 * too tight for a snapped surface) and fixing its off nodes would tear it, so it is refused. */
#include "off_cad.h"

#include <stdlib.h>

static int64_t find(int64_t *parent, int64_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]]; /* path halving */
        i = parent[i];
    }
    return i;
}

cm_status cm_morph_off_cad_check(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                                 const cm_surface_nodes *nodes, size_t *n_components)
{
    *n_components = 0;
    if (!nodes->n_off) return CM_OK;
    size_t nn = mesh->n_nodes;
    /* parent over mesh nodes (only boundary ones are used); state: 1 on G, 2 off G */
    int64_t *parent = malloc((nn ? nn : 1) * sizeof *parent);
    unsigned char *state = calloc(nn ? nn : 1, 1);
    size_t *on = calloc(nn ? nn : 1, sizeof *on), *off = calloc(nn ? nn : 1, sizeof *off);
    int64_t *far = malloc((nn ? nn : 1) * sizeof *far); /* per root: farthest off node (index) */
    if (!parent || !state || !on || !off || !far) {
        free(parent), free(state), free(on), free(off), free(far);
        return cm_error(ctx, CM_ERR_NOMEM, "off-CAD check: out of memory for %zu nodes", nn);
    }
    for (size_t i = 0; i < nn; ++i)
        parent[i] = (int64_t)i, far[i] = -1;
    for (size_t f = 0; f < b->n_faces; ++f) {
        int64_t a = b->face_offset[f], e = b->face_offset[f + 1];
        for (int64_t k = a + 1; k < e; ++k) {
            int64_t p = find(parent, b->face_nodes[a]), q = find(parent, b->face_nodes[k]);
            if (p != q) parent[q] = p;
        }
    }
    for (size_t i = 0; i < nodes->n; ++i)
        state[nodes->node[i]] = 1;
    for (size_t i = 0; i < nodes->n_off; ++i)
        state[nodes->off[i]] = 2;
    for (size_t i = 0; i < nodes->n; ++i)
        ++on[find(parent, nodes->node[i])];
    for (size_t i = 0; i < nodes->n_off; ++i) {
        int64_t r = find(parent, nodes->off[i]);
        ++off[r];
        if (far[r] < 0 || nodes->off_dist[i] > nodes->off_dist[far[r]]) far[r] = (int64_t)i;
    }
    /* components in the order of their smallest boundary node (b->nodes is ascending) */
    cm_status s = CM_OK;
    size_t comp = 0;
    for (size_t j = 0; j < b->n_nodes && s == CM_OK; ++j) {
        int64_t r = find(parent, b->nodes[j]);
        if (state[r] & 4) continue; /* seen */
        state[r] |= 4;
        ++comp;
        if (off[r] && !on[r]) ++*n_components;
        if (off[r] && on[r]) {
            size_t w = (size_t)far[r];
            s = cm_error(ctx, CM_ERR_MISMATCH,
                         "boundary component %zu (from node %lld) is partly on the CAD model: "
                         "%zu nodes on it, %zu off (farthest: node %lld at distance %.6g); "
                         "--off-cad fixed keeps only whole components off the model fixed",
                         comp, (long long)b->nodes[j], on[r], off[r], (long long)nodes->off[w],
                         nodes->off_dist[w]);
        }
    }
    free(parent), free(state), free(on), free(off), free(far);
    return s;
}
