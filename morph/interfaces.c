/* The interfaces of an assembly mesh join the boundary the morph works on: a triangle the
 * mesh lists between two tets of different physical groups (the faces two touching solids
 * share, docs/DESIGN.md "Assemblies") lies on CAD faces like the outer boundary, so its nodes
 * are classified on G and moved onto G' by the surface morph instead of following the
 * interior warp (which would leave them off the edited interface). The nodes stay shared:
 * the mesh stays conformal. */
#include "morpher_internal.h"

#include <stdlib.h>
#include <string.h>

typedef struct key {
    int64_t v[3];   /* sorted nodes */
    int64_t cell;   /* tet, or -1 - triangle */
} key;

static int key_cmp(const void *a, const void *b)
{
    const key *x = a, *y = b;
    for (int k = 0; k < 3; ++k)
        if (x->v[k] != y->v[k]) return x->v[k] < y->v[k] ? -1 : 1;
    return x->cell < y->cell ? -1 : x->cell > y->cell;
}

static void sort3(int64_t *v)
{
    int64_t t;
    if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
    if (v[1] > v[2]) t = v[1], v[1] = v[2], v[2] = t;
    if (v[0] > v[1]) t = v[0], v[0] = v[1], v[1] = t;
}

static int cmp_node(const void *a, const void *b)
{
    const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

cm_status cm_morph_add_interfaces(cm_context *ctx, const cm_mesh *mesh, cm_mesh_boundary *b,
                                  size_t *n_added)
{
    *n_added = 0;
    size_t ntri = 0, ntet = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        ntri += mesh->type[c] == CM_CELL_TRI3;
        ntet += mesh->type[c] == CM_CELL_TET4;
    }
    if (!ntri || !ntet || !mesh->physical) return CM_OK;
    key *keys = malloc((ntri + 4 * ntet) * sizeof *keys);
    if (!keys) return cm_error(ctx, CM_ERR_NOMEM, "morph: out of memory for the interfaces");
    size_t n = 0;
    static const int face[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const int64_t *v = mesh->conn + mesh->offset[c];
        if (mesh->type[c] == CM_CELL_TRI3) {
            key k = {{v[0], v[1], v[2]}, -1 - (int64_t)c};
            sort3(k.v);
            keys[n++] = k;
        } else if (mesh->type[c] == CM_CELL_TET4) {
            for (int f = 0; f < 4; ++f) {
                key k = {{v[face[f][0]], v[face[f][1]], v[face[f][2]]}, (int64_t)c};
                sort3(k.v);
                keys[n++] = k;
            }
        }
    }
    qsort(keys, n, sizeof *keys, key_cmp);
    /* runs of equal faces: triangles first (cell < 0), then the tets */
    int64_t *added = NULL; /* face nodes, 3 per interface face, then its tet */
    size_t n_faces = 0, cap = 0;
    cm_status s = CM_OK;
    for (size_t i = 0; i < n && s == CM_OK;) {
        size_t j = i;
        while (j < n && !memcmp(keys[j].v, keys[i].v, sizeof keys[i].v)) ++j;
        size_t t = i;
        while (t < j && keys[t].cell < 0) ++t;
        if (t > i && j - t == 2 &&
            mesh->physical[keys[t].cell] != mesh->physical[keys[t + 1].cell]) {
            if (n_faces == cap) {
                cap = cap ? 2 * cap : 64;
                int64_t *p = realloc(added, 4 * cap * sizeof *added);
                if (!p) s = cm_error(ctx, CM_ERR_NOMEM, "morph: out of memory for the interfaces");
                else added = p;
            }
            if (s == CM_OK) {
                memcpy(added + 4 * n_faces, keys[i].v, sizeof keys[i].v);
                added[4 * n_faces + 3] = keys[t].cell;
                ++n_faces;
            }
        }
        i = j;
    }
    free(keys);
    if (s != CM_OK || !n_faces) {
        free(added);
        return s;
    }
    /* the faces appended (their orientation is not used: lengths, components), the nodes
     * merged into the sorted list */
    const size_t nf = b->n_faces + n_faces, nc = (size_t)b->face_offset[b->n_faces] + 3 * n_faces;
    int64_t *off = realloc(b->face_offset, (nf + 1) * sizeof *off);
    if (off) b->face_offset = off;
    int64_t *fn = off ? realloc(b->face_nodes, nc * sizeof *fn) : NULL;
    if (fn) b->face_nodes = fn;
    int64_t *fc = fn ? realloc(b->face_cell, nf * sizeof *fc) : NULL;
    if (fc) b->face_cell = fc;
    int64_t *nodes = fc ? malloc((b->n_nodes + 3 * n_faces) * sizeof *nodes) : NULL;
    if (!nodes) {
        free(added);
        return cm_error(ctx, CM_ERR_NOMEM, "morph: out of memory for the interfaces");
    }
    for (size_t f = 0; f < n_faces; ++f) {
        const size_t g = b->n_faces + f;
        memcpy(b->face_nodes + b->face_offset[g], added + 4 * f, 3 * sizeof *added);
        b->face_offset[g + 1] = b->face_offset[g] + 3;
        b->face_cell[g] = added[4 * f + 3];
    }
    memcpy(nodes, b->nodes, b->n_nodes * sizeof *nodes);
    size_t m = b->n_nodes;
    for (size_t f = 0; f < n_faces; ++f)
        for (int k = 0; k < 3; ++k) nodes[m++] = added[4 * f + k];
    qsort(nodes, m, sizeof *nodes, cmp_node);
    size_t u = 0;
    for (size_t i = 0; i < m; ++i)
        if (!u || nodes[i] != nodes[u - 1]) nodes[u++] = nodes[i];
    free(b->nodes);
    b->nodes = nodes;
    b->n_nodes = u;
    b->n_faces = nf;
    *n_added = n_faces;
    free(added);
    return CM_OK;
}
