/* Node bookkeeping shared by the mesh-based warps (FEMWARP, LBWARP, linear-simplex): which
 * nodes are free, which fixed, and the distinct nodes of a cell. */
#include "warp_method.h"

#include <stdlib.h>

int cm_warp_is_volume_cell(const cm_mesh *mesh, size_t c)
{
    const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
    return info && info->dim == 3;
}

size_t cm_warp_cell_nodes(const cm_mesh *mesh, size_t c, int64_t *out)
{
    const int64_t *conn = mesh->conn;
    int64_t b = mesh->offset[c], e = mesh->offset[c + 1];
    if (mesh->type[c] != CM_CELL_POLYHEDRON) {
        for (int64_t p = b; p < e; ++p)
            out[p - b] = conn[p];
        return (size_t)(e - b);
    }
    /* face stream: nf, then per face its node count and nodes; polyhedra are small, so a
     * linear scan deduplicates */
    size_t n = 0;
    int64_t p = b + 1;
    for (int64_t f = 0; f < conn[b] && p < e; ++f) {
        int64_t k = conn[p++];
        for (int64_t i = 0; i < k && p < e; ++i, ++p) {
            size_t j = 0;
            while (j < n && out[j] != conn[p])
                ++j;
            if (j == n) out[n++] = conn[p];
        }
    }
    return n;
}

void cm_warp_nodes_destroy(cm_warp_nodes **nodes)
{
    if (!nodes || !*nodes) return;
    free((*nodes)->free_index);
    free((*nodes)->fixed_index);
    free((*nodes)->free_nodes);
    free((*nodes)->fixed_nodes);
    free((*nodes)->loose_nodes);
    free(*nodes);
    *nodes = NULL;
}

cm_status cm_warp_nodes_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                               const unsigned char *constrained, cm_warp_nodes **nodes)
{
    *nodes = NULL;
    size_t nn = mesh->n_nodes, nc = b->n_components;
    cm_warp_nodes *w = calloc(1, sizeof *w);
    unsigned char *in_cell = calloc(nn ? nn : 1, 1);
    /* per component: 1 has a free node, 2 has a constrained node */
    unsigned char *comp = calloc(nc ? nc : 1, 1);
    int64_t *buf = NULL;
    size_t cap = 0;
    if (!w || !in_cell || !comp) goto nomem;
    w->n_nodes = nn;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (!cm_warp_is_volume_cell(mesh, c)) continue;
        size_t len = (size_t)(mesh->offset[c + 1] - mesh->offset[c]);
        if (len > cap) {
            free(buf);
            cap = 2 * len;
            if (!(buf = malloc(cap * sizeof *buf))) goto nomem;
        }
        size_t k = cm_warp_cell_nodes(mesh, c, buf);
        int kc = b->cell_component[c];
        for (size_t i = 0; i < k; ++i) {
            in_cell[buf[i]] = 1;
            if (kc >= 0 && (size_t)kc < nc) comp[kc] |= constrained[buf[i]] ? 2 : 1;
        }
    }
    for (size_t k = 0; k < nc; ++k)
        if (comp[k] == 1) {
            free(in_cell);
            free(comp);
            free(buf);
            cm_warp_nodes_destroy(&w);
            return cm_error(ctx, CM_ERR_NUMERIC,
                            "cm_warp_create: component %zu: no constrained node", k);
        }
    size_t stray = 0;
    for (size_t v = 0; v < nn; ++v) {
        if (in_cell[v]) {
            if (constrained[v])
                ++w->n_fixed;
            else
                ++w->n_free;
        } else if (!constrained[v]) {
            ++stray;
        } else {
            ++w->n_loose;
        }
    }
    w->free_index = malloc((nn ? nn : 1) * sizeof *w->free_index);
    w->fixed_index = malloc((nn ? nn : 1) * sizeof *w->fixed_index);
    w->free_nodes = malloc((w->n_free ? w->n_free : 1) * sizeof *w->free_nodes);
    w->fixed_nodes = malloc((w->n_fixed ? w->n_fixed : 1) * sizeof *w->fixed_nodes);
    w->loose_nodes = malloc((w->n_loose ? w->n_loose : 1) * sizeof *w->loose_nodes);
    if (!w->free_index || !w->fixed_index || !w->free_nodes || !w->fixed_nodes || !w->loose_nodes)
        goto nomem;
    size_t nf = 0, nx = 0, nl = 0;
    for (size_t v = 0; v < nn; ++v) {
        w->free_index[v] = w->fixed_index[v] = -1;
        if (!in_cell[v]) {
            if (constrained[v]) w->loose_nodes[nl++] = (int64_t)v;
            continue;
        }
        if (constrained[v]) {
            w->fixed_index[v] = (int64_t)nx;
            w->fixed_nodes[nx++] = (int64_t)v;
        } else {
            w->free_index[v] = (int64_t)nf;
            w->free_nodes[nf++] = (int64_t)v;
        }
    }
    if (stray)
        cm_log(ctx, CM_LOG_WARNING,
               "cm_warp_create: %zu unconstrained nodes belong to no volume cell; they are left "
               "where they are",
               stray);
    free(in_cell);
    free(comp);
    free(buf);
    *nodes = w;
    return CM_OK;
nomem:
    free(in_cell);
    free(comp);
    free(buf);
    cm_warp_nodes_destroy(&w);
    return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
}

void cm_warp_nodes_add_identity(const cm_warp_nodes *nodes, const double *v, double *out)
{
    for (size_t j = 0; j < nodes->n_fixed; ++j)
        for (int k = 0; k < 3; ++k)
            out[3 * nodes->fixed_nodes[j] + k] += v[3 * nodes->fixed_nodes[j] + k];
    for (size_t j = 0; j < nodes->n_loose; ++j)
        for (int k = 0; k < 3; ++k)
            out[3 * nodes->loose_nodes[j] + k] += v[3 * nodes->loose_nodes[j] + k];
}
