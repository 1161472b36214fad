/* Face addressing of any mesh's volume cells, as OpenFOAM wants it: each face once, oriented
 * out of its owner (the lower cell index), internal faces in upper-triangular order (by owner,
 * then neighbour), boundary faces grouped into patches by the physical group of the 2D cells
 * lying on them. Used to write a non-OpenFOAM mesh as a polyMesh and for checkMesh's metrics. */
#define _POSIX_C_SOURCE 200809L
#include "foam_internal.h"

#include "../cell_faces.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_FACE = 256 };

typedef struct face_rec {
    int64_t owner, nei; /* cell indices among volume cells; nei -1 on the boundary */
    int64_t off;        /* into the node pool */
    int n;
    int patch;          /* boundary: index into the patch list */
} face_rec;

typedef struct builder {
    face_rec *f;
    size_t nf, capf;
    int64_t *pool;      /* face nodes as the owner sees them (outward) */
    size_t npool, cappool;
    int64_t *sorted;    /* the same nodes sorted: the key */
    size_t *slot;       /* open-addressing table of face indices + 1 */
    size_t cap_slot;
} builder;

static uint64_t key_hash(const int64_t *k, int n)
{
    uint64_t h = 1469598103934665603ull;
    for (int i = 0; i < n; ++i) {
        h ^= (uint64_t)k[i];
        h *= 1099511628211ull;
        h ^= h >> 29;
    }
    return h;
}

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return x < y ? -1 : x > y;
}

/* Finds the face with these sorted nodes; returns its index or -1. *where: the free slot. */
static int64_t lookup(const builder *b, const int64_t *key, int n, size_t *where)
{
    size_t i = (size_t)(key_hash(key, n) & (b->cap_slot - 1));
    for (;;) {
        size_t s = b->slot[i];
        if (!s) {
            *where = i;
            return -1;
        }
        const face_rec *r = &b->f[s - 1];
        if (r->n == n && !memcmp(b->sorted + r->off, key, (size_t)n * sizeof *key)) return (int64_t)(s - 1);
        i = (i + 1) & (b->cap_slot - 1);
    }
}

static int grow_pool(builder *b, size_t extra)
{
    if (b->npool + extra <= b->cappool) return 1;
    size_t nc = 2 * b->cappool + extra;
    int64_t *p = realloc(b->pool, nc * sizeof *p);
    if (!p) return 0;
    b->pool = p;
    int64_t *q = realloc(b->sorted, nc * sizeof *q);
    if (!q) return 0;
    b->sorted = q;
    b->cappool = nc;
    return 1;
}

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

cm_status cm_foam_build(cm_context *ctx, const cm_mesh *mesh, cm_foam_poly **out)
{
    *out = NULL;
    builder b = {0};
    cm_foam_poly *p = cm_foam_poly_new();
    int64_t *cell_of = NULL;
    int *tags = NULL;
    order_rec *ord = NULL;
    size_t ntags = 0;
    cm_status s = CM_OK;
    size_t total = 0;
    int64_t nvol = 0;
    if (!p) goto nomem;
    for (size_t c = 0; c < mesh->n_cells; ++c)
        if (cm_cell_type_info((cm_cell_type)mesh->type[c])->dim == 3) {
            total += (size_t)cm_cell_face_count(mesh, c);
            ++nvol;
        }
    if (nvol == 0) {
        cm_foam_poly_release(&p);
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: an OpenFOAM polyMesh needs volume cells; the mesh has none");
    }
    b.cap_slot = 16;
    while (b.cap_slot < 2 * total + 16) b.cap_slot *= 2;
    b.slot = calloc(b.cap_slot, sizeof *b.slot);
    b.capf = total + 1;
    b.f = malloc(b.capf * sizeof *b.f);
    if (!b.slot || !b.f || !grow_pool(&b, total * 4 + 16)) goto nomem;
    int64_t cell = 0;
    int64_t nodes[MAX_FACE];
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (cm_cell_type_info((cm_cell_type)mesh->type[c])->dim != 3) continue;
        const int nfc = cm_cell_face_count(mesh, c);
        for (int k = 0; k < nfc; ++k) {
            int n = cm_cell_face_nodes(mesh, c, k, nodes, MAX_FACE);
            if (n < 3) {
                s = cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_write: cell %zu: face %d has %s nodes for a polyMesh", c, k,
                             n < 0 ? "too many" : "fewer than 3");
                goto fail;
            }
            if (!grow_pool(&b, (size_t)n)) goto nomem;
            int64_t *key = b.sorted + b.npool;
            memcpy(key, nodes, (size_t)n * sizeof *key);
            qsort(key, (size_t)n, sizeof *key, cmp_i64);
            size_t where = 0;
            int64_t hit = lookup(&b, key, n, &where);
            if (hit >= 0) {
                face_rec *r = &b.f[hit];
                if (r->nei >= 0) {
                    s = cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_write: cell %zu: a face shared by three or more cells cannot be written as a polyMesh", c);
                    goto fail;
                }
                r->nei = cell;
                continue;
            }
            face_rec *r = &b.f[b.nf];
            r->owner = cell;
            r->nei = -1;
            r->off = (int64_t)b.npool;
            r->n = n;
            r->patch = -1;
            memcpy(b.pool + b.npool, nodes, (size_t)n * sizeof *nodes);
            b.npool += (size_t)n;
            b.slot[where] = ++b.nf;
        }
        ++cell;
    }
    /* patches: the physical tag of a 2D cell on each boundary face */
    tags = malloc((mesh->n_groups + mesh->n_cells + 1) * sizeof *tags);
    if (!tags) goto nomem;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (cm_cell_type_info((cm_cell_type)mesh->type[c])->dim != 2) continue;
        cm_cell_type lt = cm_cell_type_info((cm_cell_type)mesh->type[c])->linear;
        int n = lt == CM_CELL_POLYGON ? (int)(mesh->offset[c + 1] - mesh->offset[c]) : cm_cell_type_info(lt)->nodes;
        if (n < 3 || n > MAX_FACE) continue;
        memcpy(nodes, mesh->conn + mesh->offset[c], (size_t)n * sizeof *nodes);
        qsort(nodes, (size_t)n, sizeof *nodes, cmp_i64);
        size_t where;
        int64_t hit = lookup(&b, nodes, n, &where);
        if (hit < 0 || b.f[hit].nei >= 0 || b.f[hit].patch >= 0) continue;
        int tag = mesh->physical[c], t = 0;
        while ((size_t)t < ntags && tags[t] != tag) ++t;
        if ((size_t)t == ntags) tags[ntags++] = tag;
        b.f[hit].patch = t;
    }
    int unassigned = 0;
    for (size_t i = 0; i < b.nf; ++i)
        if (b.f[i].nei < 0 && b.f[i].patch < 0) {
            b.f[i].patch = (int)ntags;
            unassigned = 1;
        }
    /* order: internal (owner, neighbour), then boundary (patch, owner) */
    ord = malloc((b.nf ? b.nf : 1) * sizeof *ord);
    if (!ord) goto nomem;
    size_t nint = 0;
    for (size_t i = 0; i < b.nf; ++i)
        if (b.f[i].nei >= 0) ord[nint++] = (order_rec){b.f[i].owner, b.f[i].nei, i};
    size_t nb = nint;
    for (size_t i = 0; i < b.nf; ++i)
        if (b.f[i].nei < 0) ord[nb++] = (order_rec){(int64_t)1 << 62 | b.f[i].patch, b.f[i].owner, i};
    qsort(ord, nint, sizeof *ord, cmp_order);
    qsort(ord + nint, b.nf - nint, sizeof *ord, cmp_order);
    p->n_points = (int64_t)mesh->n_nodes;
    p->n_cells = nvol;
    p->n_faces = (int64_t)b.nf;
    p->n_internal = (int64_t)nint;
    p->face_off = malloc((b.nf + 1) * sizeof *p->face_off);
    p->face_nodes = malloc((b.npool ? b.npool : 1) * sizeof *p->face_nodes);
    p->owner = malloc((b.nf ? b.nf : 1) * sizeof *p->owner);
    p->neighbour = malloc((nint ? nint : 1) * sizeof *p->neighbour);
    size_t npatch = ntags + (size_t)unassigned;
    p->patches = calloc(npatch ? npatch : 1, sizeof *p->patches);
    if (!p->face_off || !p->face_nodes || !p->owner || !p->neighbour || !p->patches) goto nomem;
    p->n_patches = npatch;
    int64_t at = 0;
    p->face_off[0] = 0;
    for (size_t i = 0; i < b.nf; ++i) {
        const face_rec *r = &b.f[ord[i].face];
        memcpy(p->face_nodes + at, b.pool + r->off, (size_t)r->n * sizeof *p->face_nodes);
        at += r->n;
        p->face_off[i + 1] = at;
        p->owner[i] = r->owner;
        if (i < nint) p->neighbour[i] = r->nei;
    }
    for (size_t t = 0; t < npatch; ++t) {
        cm_foam_patch *pt = &p->patches[t];
        pt->name = t < ntags ? name_of_group(mesh, tags[t]) : strdup("defaultFaces");
        pt->type = strdup(t < ntags ? "patch" : "wall");
        pt->n = 0;
        pt->start = -1;
        if (!pt->name || !pt->type) goto nomem;
    }
    if (!unique_names(p->patches, npatch)) goto nomem;
    for (size_t i = nint; i < b.nf; ++i) {
        cm_foam_patch *pt = &p->patches[b.f[ord[i].face].patch];
        if (pt->start < 0) pt->start = (int64_t)i;
        ++pt->n;
    }
    free(b.f);
    free(b.pool);
    free(b.sorted);
    free(b.slot);
    free(tags);
    free(ord);
    free(cell_of);
    *out = p;
    return CM_OK;
nomem:
    s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory building the face addressing");
fail:
    free(b.f);
    free(b.pool);
    free(b.sorted);
    free(b.slot);
    free(tags);
    free(ord);
    free(cell_of);
    cm_foam_poly_release(&p);
    return s;
}

cm_status cm_foam_of_mesh(cm_context *ctx, const cm_mesh *mesh, cm_foam_poly **out)
{
    *out = NULL;
    if (mesh->foam && (size_t)mesh->foam->n_points == mesh->n_nodes &&
        (size_t)mesh->foam->n_cells == cm_mesh_count_dim(mesh, 3)) {
        *out = cm_foam_poly_retain(mesh->foam);
        return CM_OK;
    }
    return cm_foam_build(ctx, mesh, out);
}
