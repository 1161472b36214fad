/* Boundary faces and nodes of the volume cells of a mesh, connected components of cells that
 * share a face, and the checks that go with them (non-manifold faces, duplicate cells). The
 * faces come from the topology builder (topology.h): a boundary face is an instance without a
 * mate, taken in instance order (cell order, then the cell's local faces) and oriented as its
 * cell sees it (outward). */
#include "cell_faces.h"
#include "topology.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define CM_BOUNDARY_PARALLEL_MIN 20000

typedef cm_topo_idx cm_idx;

static cm_idx uf_find(cm_idx *parent, cm_idx x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]]; /* path halving */
        x = parent[x];
    }
    return x;
}

static void uf_union(cm_idx *parent, cm_idx a, cm_idx b)
{
    a = uf_find(parent, a);
    b = uf_find(parent, b);
    if (a == b) return;
    /* the smaller index becomes the root: components are then numbered by first cell */
    if (a < b) parent[b] = a;
    else parent[a] = b;
}

static int same_node_set(const cm_mesh *mesh, size_t a, size_t b)
{
    int64_t sa[64], sb[64];
    const int na = cm_mesh_cell_nodes(mesh, a, sa, 64), nb = cm_mesh_cell_nodes(mesh, b, sb, 64);
    if (na < 0 || nb < 0 || na != nb) return 0;
    return memcmp(sa, sb, (size_t)na * sizeof *sa) == 0;
}

void cm_mesh_boundary_destroy(cm_mesh_boundary **b)
{
    if (!b || !*b) return;
    free((*b)->face_offset);
    free((*b)->face_nodes);
    free((*b)->face_cell);
    free((*b)->nodes);
    free((*b)->cell_component);
    free(*b);
    *b = NULL;
}

/* What the analysis adds to the topology: union-find parents and the boundary node marks. */
typedef struct work {
    cm_topology t;
    cm_idx *parent;
    unsigned char *mark;
} work;

static void work_free(work *w)
{
    cm_topology_free(&w->t);
    free(w->parent);
    free(w->mark);
}

/* The messages of a failed face matching. */
static cm_status topology_error(cm_context *ctx, const cm_topology_problem *why)
{
    switch (why->what) {
    case CM_TOPOLOGY_TOO_LARGE:
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_mesh_boundary_create: %zu nodes, %zu cells, %zu faces: more than 2^31-1", why->n_nodes,
                        why->n_cells, why->n_inst);
    case CM_TOPOLOGY_BAD_FACE:
        if (why->n < 0)
            return cm_error(ctx, CM_ERR_UNSUPPORTED,
                            "cm_mesh_boundary_create: cell %zu: face %d has more than %d nodes", why->cell,
                            why->face, CM_TOPOLOGY_MAX_FACE_NODES);
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_boundary_create: cell %zu: face %d has %d nodes", why->cell,
                        why->face, why->n);
    case CM_TOPOLOGY_BAD_NODE:
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_boundary_create: cell %zu: node %lld out of range (%zu nodes)",
                        why->cell, (long long)why->node, why->n_nodes);
    default:
        if (why->counted)
            return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory (%zu faces)", why->n_inst);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    }
}

/* Components by union-find over matched faces; duplicates among the cells that share
 * their first face (a copy shares every face, so looking at one suffices). */
static cm_status components(cm_context *ctx, const cm_mesh *mesh, work *w, size_t ni, int threads,
                            cm_mesh_boundary *b)
{
    const size_t nc = mesh->n_cells;
    w->parent = malloc((nc ? nc : 1) * sizeof *w->parent);
    b->cell_component = malloc((nc ? nc : 1) * sizeof *b->cell_component);
    if (!w->parent || !b->cell_component)
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    for (size_t c = 0; c < nc; ++c) w->parent[c] = (cm_idx)c;
    for (size_t i = 0; i < ni; ++i)
        if (w->t.mate[i] > (cm_idx)i) uf_union(w->parent, w->t.inst_cell[i], w->t.inst_cell[w->t.mate[i]]);
    int next = 0;
    for (size_t c = 0; c < nc; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!info || info->dim < 3) {
            b->cell_component[c] = -1;
            continue;
        }
        const cm_idx r = uf_find(w->parent, (cm_idx)c);
        /* roots are the smallest cell of their component, so they are labelled first */
        b->cell_component[c] = r == (cm_idx)c ? next++ : b->cell_component[r];
    }
    b->n_components = (size_t)next;

    size_t dup = 0;
    const long long nn = (long long)nc;
#pragma omp parallel for schedule(static) num_threads(threads) if (nn > CM_BOUNDARY_PARALLEL_MIN) reduction(+ : dup)
    for (long long c = 0; c < nn; ++c) {
        const cm_idx i0 = (cm_idx)w->t.inst_off[c];
        if (w->t.inst_off[c + 1] == i0 || w->t.mate[i0] < 0) continue;
        const cm_idx i1 = i0 + 1 < w->t.inst_off[c + 1] ? i0 + 1 : i0;
        for (cm_idx j = w->t.mate[i0]; j != i0; j = w->t.mate[j]) {
            const cm_idx d = w->t.inst_cell[j];
            if (d >= c) continue;
            /* a copy shares every face: cheap test on the second face before the node sets */
            int shares = i1 == i0;
            for (cm_idx q = w->t.mate[i1]; !shares && q >= 0 && q != i1; q = w->t.mate[q]) shares = w->t.inst_cell[q] == d;
            if (shares && same_node_set(mesh, (size_t)c, (size_t)d)) {
                ++dup;
                break;
            }
        }
    }
    b->n_duplicate = dup;
    return CM_OK;
}

/* The boundary: faces of one cell, in instance order, and the nodes on them. */
static cm_status collect_boundary(cm_context *ctx, const cm_mesh *mesh, work *w, size_t ni,
                                  cm_mesh_boundary *b)
{
    size_t nb = 0, nb_nodes = 0;
    int64_t nodes[CM_TOPOLOGY_MAX_FACE_NODES];
    for (size_t i = 0; i < ni; ++i) {
        if (w->t.mate[i] != -1) continue;
        const size_t c = (size_t)w->t.inst_cell[i];
        ++nb;
        nb_nodes += (size_t)cm_cell_face_nodes(mesh, c, (int)((int64_t)i - w->t.inst_off[c]), nodes,
                                               CM_TOPOLOGY_MAX_FACE_NODES);
    }
    b->n_faces = nb;
    b->face_offset = malloc((nb + 1) * sizeof *b->face_offset);
    b->face_nodes = malloc((nb_nodes ? nb_nodes : 1) * sizeof *b->face_nodes);
    b->face_cell = malloc((nb ? nb : 1) * sizeof *b->face_cell);
    w->mark = calloc(mesh->n_nodes ? mesh->n_nodes : 1, 1);
    if (!b->face_offset || !b->face_nodes || !b->face_cell || !w->mark)
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory (%zu faces)", nb);
    b->face_offset[0] = 0;
    size_t f = 0;
    for (size_t i = 0; i < ni; ++i) {
        if (w->t.mate[i] != -1) continue;
        const size_t c = (size_t)w->t.inst_cell[i];
        const int local = (int)((int64_t)i - w->t.inst_off[c]);
        const int n = cm_cell_face_nodes(mesh, c, local, b->face_nodes + b->face_offset[f],
                                         CM_TOPOLOGY_MAX_FACE_NODES);
        for (int k = 0; k < n; ++k) w->mark[b->face_nodes[b->face_offset[f] + k]] = 1;
        int64_t extra[5];
        const int ne = cm_cell_face_extra_nodes(mesh, c, local, extra);
        for (int k = 0; k < ne; ++k)
            if (extra[k] >= 0 && (size_t)extra[k] < mesh->n_nodes) w->mark[extra[k]] = 1;
        b->face_cell[f] = (int64_t)c;
        b->face_offset[f + 1] = b->face_offset[f] + n;
        ++f;
    }
    size_t m = 0;
    for (size_t v = 0; v < mesh->n_nodes; ++v) m += w->mark[v];
    b->n_nodes = m;
    b->nodes = malloc((m ? m : 1) * sizeof *b->nodes);
    if (!b->nodes) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    m = 0;
    for (size_t v = 0; v < mesh->n_nodes; ++v)
        if (w->mark[v]) b->nodes[m++] = (int64_t)v;
    return CM_OK;
}

cm_status cm_mesh_boundary_create(cm_context *ctx, const cm_mesh *mesh, cm_mesh_boundary **out)
{
    if (!out) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_boundary_create: output is NULL");
    *out = NULL;
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_boundary_create: mesh is NULL");
    cm_mesh_boundary *b = calloc(1, sizeof *b);
    if (!b) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    int threads = cm_context_threads_for(ctx, mesh->n_cells, 1);

    work w = {0};
    cm_topology_problem why;
    cm_status s = cm_topology_build(mesh, CM_TOPOLOGY_MAX_FACE_NODES, threads, &w.t, &why);
    if (s != CM_OK) s = topology_error(ctx, &why);
    const size_t ni = w.t.n_inst;
    b->n_nonmanifold = w.t.n_nonmanifold;
    if (s == CM_OK) s = components(ctx, mesh, &w, ni, threads, b);
    if (s == CM_OK) s = collect_boundary(ctx, mesh, &w, ni, b);
    work_free(&w);
    if (s != CM_OK) {
        cm_mesh_boundary_destroy(&b);
        return s;
    }
    *out = b;
    if (b->n_nonmanifold || b->n_duplicate)
        return cm_error(ctx, CM_WARNING,
                        "cm_mesh_boundary_create: %zu non-manifold faces (shared by 3 or more cells), "
                        "%zu duplicate cells (same nodes as an earlier cell)",
                        b->n_nonmanifold, b->n_duplicate);
    return CM_OK;
}
