/* Face addressing of any mesh's volume cells, as OpenFOAM wants it: each face once, oriented
 * out of its owner (the lower cell index), internal faces in upper-triangular order (by owner,
 * then neighbour), boundary faces grouped into patches by the physical group of the 2D cells
 * lying on them. Used to write a non-OpenFOAM mesh as a polyMesh and for checkMesh's metrics.
 * The faces are matched by the topology builder (topology.h); this file only orders them. */
#define _POSIX_C_SOURCE 200809L
#include "foam_internal.h"
#include "origin.h"

#include "cell_faces.h"
#include "topology.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Faces of more nodes are refused for a polyMesh (the boundary extraction allows up to
 * CM_TOPOLOGY_MAX_FACE_NODES). */
enum { MAX_FACE = 256 };

typedef struct order_rec {
    int64_t a, b;
    size_t face;
} order_rec;

static int cmp_order(const void *x, const void *y)
{
    const order_rec *p = x, *q = y;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    return p->face < q->face ? -1 : p->face > q->face;
}

/* A patch name OpenFOAM reads as one word: letters, digits and _ - . : + kept, anything else
 * (white space, quotes, brackets, ';', '/', non-ASCII) becomes '_'; unnamed groups "patchN". */
static char *name_of_group(const cm_mesh *m, int tag)
{
    const char *src = NULL;
    for (size_t i = 0; i < m->n_groups && !src; ++i)
        if (m->groups[i].dim == 2 && m->groups[i].tag == tag && m->groups[i].name && m->groups[i].name[0])
            src = m->groups[i].name;
    char buf[64];
    if (!src) {
        snprintf(buf, sizeof buf, "patch%d", tag);
        return strdup(buf);
    }
    size_t n = strlen(src);
    char *d = malloc(n + 2);
    if (!d) return NULL;
    size_t k = 0;
    if (!((src[0] >= 'a' && src[0] <= 'z') || (src[0] >= 'A' && src[0] <= 'Z') || src[0] == '_')) d[k++] = '_';
    for (size_t i = 0; i < n; ++i) {
        char c = src[i];
        int ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                 c == '-' || c == '.' || c == ':' || c == '+';
        d[k++] = ok ? c : '_';
    }
    d[k] = '\0';
    return d;
}

/* Makes patch names unique (two groups may sanitise to the same word). */
static int unique_names(cm_foam_patch *pt, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < i; ++j)
            if (!strcmp(pt[i].name, pt[j].name)) {
                size_t l = strlen(pt[i].name);
                char *r = realloc(pt[i].name, l + 24);
                if (!r) return 0;
                snprintf(r + l, 24, "_%zu", i);
                pt[i].name = r;
                j = (size_t)-1; /* check again from the start */
            }
    return 1;
}

/* The faults of the face matching, reported as the polyMesh writer always has: in instance
 * order (cell order, then local face), the first face of three cells or the first face with
 * too few or too many nodes, whichever comes first. Two faults only this writer meets through
 * the shared builder: a node out of range (unchecked here before: such a mesh gave a polyMesh
 * with labels past its points), and more than 2^31-1 nodes, cells or faces (the builder's
 * 32-bit indices; far beyond what fits in memory here anyway). */
static cm_status topology_fault(cm_context *ctx, const cm_topology *t, const cm_topology_problem *why)
{
    const int64_t third = cm_topology_first_overshared(t);
    if (third >= 0)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cell %zu: a face shared by three or more cells cannot be written as a polyMesh",
                        (size_t)t->inst_cell[third]);
    switch (why->what) {
    case CM_TOPOLOGY_BAD_FACE:
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cell %zu: face %d has %s nodes for a polyMesh",
                        why->cell, why->face, why->n < 0 ? "too many" : "fewer than 3");
    case CM_TOPOLOGY_BAD_NODE:
        return cm_error(ctx, CM_ERR_FORMAT, "cell %zu: node %lld out of range (%zu nodes)", why->cell,
                        (long long)why->node, why->n_nodes);
    case CM_TOPOLOGY_TOO_LARGE:
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%zu nodes, %zu cells, %zu faces: more than 2^31-1",
                        why->n_nodes, why->n_cells, why->n_inst);
    default: return CM_OK;
    }
}

cm_status cm_foam_build(cm_context *ctx, const cm_mesh *mesh, cm_foam_poly **out)
{
    *out = NULL;
    cm_topology t = {0};
    cm_foam_poly *p = cm_foam_poly_new();
    int64_t *cell_of = NULL; /* mesh cell -> index among the volume cells */
    int *patch = NULL;       /* per face: index into the patch list (boundary), -1 */
    int *tags = NULL;
    order_rec *ord = NULL;
    size_t ntags = 0;
    cm_status s = CM_OK;
    int64_t nvol = 0;
    if (!p) goto nomem;
    for (size_t c = 0; c < mesh->n_cells; ++c)
        if (cm_cell_type_info((cm_cell_type)mesh->type[c])->dim == 3) ++nvol;
    if (nvol == 0) {
        cm_foam_poly_release(&p);
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "an OpenFOAM polyMesh needs volume cells; the mesh has none");
    }
    cm_topology_problem why;
    s = cm_topology_build(mesh, MAX_FACE, cm_context_threads_for(ctx, mesh->n_cells, 1), &t, &why);
    if (why.what == CM_TOPOLOGY_NOMEM) goto nomem;
    if (why.what == CM_TOPOLOGY_TOO_LARGE) {
        s = topology_fault(ctx, &t, &why);
        goto fail;
    }
    if (cm_topology_faces(&t) != CM_OK) goto nomem;
    if (s != CM_OK || cm_topology_first_overshared(&t) >= 0) {
        s = topology_fault(ctx, &t, &why);
        goto fail;
    }
    const size_t nf = t.n_faces;
    cell_of = malloc((mesh->n_cells ? mesh->n_cells : 1) * sizeof *cell_of);
    patch = malloc((nf ? nf : 1) * sizeof *patch);
    if (!cell_of || !patch) goto nomem;
    int64_t cell = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c)
        cell_of[c] = cm_cell_type_info((cm_cell_type)mesh->type[c])->dim == 3 ? cell++ : -1;
    for (size_t f = 0; f < nf; ++f) patch[f] = -1;
    /* patches: the physical tag of a 2D cell on each boundary face */
    int64_t nodes[MAX_FACE];
    tags = malloc((mesh->n_groups + mesh->n_cells + 1) * sizeof *tags);
    if (!tags) goto nomem;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (cm_cell_type_info((cm_cell_type)mesh->type[c])->dim != 2) continue;
        cm_cell_type lt = cm_cell_type_info((cm_cell_type)mesh->type[c])->linear;
        int n = lt == CM_CELL_POLYGON ? (int)(mesh->offset[c + 1] - mesh->offset[c]) : cm_cell_type_info(lt)->nodes;
        if (n < 3 || n > MAX_FACE) continue;
        memcpy(nodes, mesh->conn + mesh->offset[c], (size_t)n * sizeof *nodes);
        const int64_t hit = cm_topology_find(&t, mesh, nodes, n);
        if (hit < 0 || t.neighbour[hit] >= 0 || patch[hit] >= 0) continue;
        int tag = mesh->physical[c], k = 0;
        while ((size_t)k < ntags && tags[k] != tag) ++k;
        if ((size_t)k == ntags) tags[ntags++] = tag;
        patch[hit] = k;
    }
    int unassigned = 0;
    for (size_t i = 0; i < nf; ++i)
        if (t.neighbour[i] < 0 && patch[i] < 0) {
            patch[i] = (int)ntags;
            unassigned = 1;
        }
    /* order: internal (owner, neighbour), then boundary (patch, owner); faces are numbered in
     * the order of their first instance, which breaks ties as before */
    ord = malloc((nf ? nf : 1) * sizeof *ord);
    if (!ord) goto nomem;
    size_t nint = 0, npool = 0;
    for (size_t i = 0; i < nf; ++i) {
        const cm_topo_idx own = t.owner[i], inst = t.face_inst[i];
        npool += (size_t)cm_cell_face_nodes(mesh, (size_t)own, (int)(inst - t.inst_off[own]), nodes, MAX_FACE);
        if (t.neighbour[i] >= 0) ord[nint++] = (order_rec){cell_of[own], cell_of[t.neighbour[i]], i};
    }
    size_t nb = nint;
    for (size_t i = 0; i < nf; ++i)
        if (t.neighbour[i] < 0) ord[nb++] = (order_rec){(int64_t)1 << 62 | patch[i], cell_of[t.owner[i]], i};
    qsort(ord, nint, sizeof *ord, cmp_order);
    qsort(ord + nint, nf - nint, sizeof *ord, cmp_order);
    p->n_points = (int64_t)mesh->n_nodes;
    p->n_cells = nvol;
    p->n_faces = (int64_t)nf;
    p->n_internal = (int64_t)nint;
    p->face_off = malloc((nf + 1) * sizeof *p->face_off);
    p->face_nodes = malloc((npool ? npool : 1) * sizeof *p->face_nodes);
    p->owner = malloc((nf ? nf : 1) * sizeof *p->owner);
    p->neighbour = malloc((nint ? nint : 1) * sizeof *p->neighbour);
    size_t npatch = ntags + (size_t)unassigned;
    p->patches = calloc(npatch ? npatch : 1, sizeof *p->patches);
    if (!p->face_off || !p->face_nodes || !p->owner || !p->neighbour || !p->patches) goto nomem;
    p->n_patches = npatch;
    int64_t at = 0;
    p->face_off[0] = 0;
    for (size_t i = 0; i < nf; ++i) {
        const size_t f = ord[i].face;
        const cm_topo_idx own = t.owner[f], inst = t.face_inst[f];
        /* as the owner sees the face: outward */
        at += cm_cell_face_nodes(mesh, (size_t)own, (int)(inst - t.inst_off[own]), p->face_nodes + at, MAX_FACE);
        p->face_off[i + 1] = at;
        p->owner[i] = cell_of[own];
        if (i < nint) p->neighbour[i] = cell_of[t.neighbour[f]];
    }
    for (size_t k = 0; k < npatch; ++k) {
        cm_foam_patch *pt = &p->patches[k];
        pt->name = k < ntags ? name_of_group(mesh, tags[k]) : strdup("defaultFaces");
        pt->type = strdup(k < ntags ? "patch" : "wall");
        pt->n = 0;
        pt->start = -1;
        if (!pt->name || !pt->type) goto nomem;
    }
    if (!unique_names(p->patches, npatch)) goto nomem;
    for (size_t i = nint; i < nf; ++i) {
        cm_foam_patch *pt = &p->patches[patch[ord[i].face]];
        if (pt->start < 0) pt->start = (int64_t)i;
        ++pt->n;
    }
    cm_topology_free(&t);
    free(patch);
    free(tags);
    free(ord);
    free(cell_of);
    *out = p;
    return CM_OK;
nomem:
    s = cm_error(ctx, CM_ERR_NOMEM, "out of memory building the face addressing");
fail:
    cm_topology_free(&t);
    free(patch);
    free(tags);
    free(ord);
    free(cell_of);
    cm_foam_poly_release(&p);
    return s;
}

cm_status cm_foam_of_mesh(cm_context *ctx, const cm_mesh *mesh, cm_foam_poly **out)
{
    *out = NULL;
    cm_foam_poly *own = cm_mesh_origin_state(mesh, CM_FORMAT_FOAM);
    if (own) {
        *out = cm_foam_poly_retain(own);
        return CM_OK;
    }
    return cm_foam_build(ctx, mesh, out);
}
