/* Abaqus decks after the last line (abaqus_internal.h): parts that no instance places are
 * dropped, node ids resolved per part with a hash (never an array indexed by id: ids may be
 * anything up to 2^63), every further instance of a part appended as a copy, placements
 * applied, then sets and surfaces become groups:
 * - a node set: point cells (CM_CELL_POINT), one per member, its group's tag (dim 0);
 * - an element set: the tag of its elements. An element in several sets carries the tag of
 *   the smallest of them (fewest elements; the first defined among sets of one size), so that
 *   a subset (a load region inside a part's set of all elements) stays a group of its own;
 * - a surface: its faces as 2-D cells (tri3/quad4, tri6/quad8 of quadratic solids) with the
 *   surface's tag; a node surface as point cells.
 * A part's set is a group per instance, named "instance.set" as the assembly names it. */
#define _POSIX_C_SOURCE 200809L
#include "abaqus_internal.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- an id -> index hash (open addressing; ids are >= 1, 0 marks an empty slot) ---- */

typedef struct abq_hash {
    size_t mask;
    int64_t *key, *val;
    /* ids first, first + 1, ... of values v0, v0 + 1, ... (the usual deck): no table */
    int dense;
    int64_t first, v0, n;
} abq_hash;

/* A map of the n ids at ids (values base + i): dense when they count up by one. */
static int dense_map(abq_hash *h, const int64_t *ids, size_t n, int64_t base)
{
    for (size_t i = 1; i < n; ++i)
        if (ids[i] != ids[0] + (int64_t)i) return 0;
    memset(h, 0, sizeof *h);
    h->dense = 1;
    h->first = n ? ids[0] : 1;
    h->v0 = base;
    h->n = (int64_t)n;
    return 1;
}

static size_t mix(int64_t k)
{
    uint64_t x = (uint64_t)k;
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    x ^= x >> 31;
    return (size_t)x;
}

static int hash_init(abq_hash *h, size_t n)
{
    size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    h->mask = cap - 1;
    h->key = calloc(cap, sizeof *h->key);
    h->val = malloc(cap * sizeof *h->val);
    return h->key && h->val;
}

static void hash_free(abq_hash *h)
{
    free(h->key);
    free(h->val);
    h->key = h->val = NULL;
}

/* 0: inserted; 1: the key was there (its value in *old). */
static int hash_put(abq_hash *h, int64_t k, int64_t v, int64_t *old)
{
    for (size_t i = mix(k) & h->mask;; i = (i + 1) & h->mask) {
        if (h->key[i] == 0) {
            h->key[i] = k;
            h->val[i] = v;
            return 0;
        }
        if (h->key[i] == k) {
            *old = h->val[i];
            return 1;
        }
    }
}

static int64_t hash_get(const abq_hash *h, int64_t k)
{
    if (h->dense) return k >= h->first && k - h->first < h->n ? h->v0 + (k - h->first) : -1;
    if (!h->key) return -1;
    for (size_t i = mix(k) & h->mask;; i = (i + 1) & h->mask) {
        if (h->key[i] == 0) return -1;
        if (h->key[i] == k) return h->val[i];
    }
}

/* Whether the n ids are distinct (NULL: trivially). */
static int distinct(const int64_t *ids, size_t n, int *ok)
{
    abq_hash h;
    if (!hash_init(&h, n)) {
        hash_free(&h);
        return 0;
    }
    *ok = 1;
    int64_t old;
    for (size_t i = 0; i < n && *ok; ++i)
        if (ids[i] < 1 || hash_put(&h, ids[i], (int64_t)i, &old)) *ok = 0;
    hash_free(&h);
    return 1;
}

/* ---- faces of solids, Abaqus's local numbering (1-based), outward ---- */

static const int tet_faces[4][3] = {{1, 3, 2}, {1, 2, 4}, {2, 3, 4}, {3, 1, 4}};
static const int hex_faces[6][4] = {{1, 4, 3, 2}, {5, 6, 7, 8}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 4, 8, 7}, {4, 1, 5, 8}};
static const int wedge_faces[5][4] = {{1, 3, 2, 0}, {4, 5, 6, 0}, {1, 2, 5, 4}, {2, 3, 6, 5}, {3, 1, 4, 6}};
static const int pyr_faces[5][4] = {{1, 4, 3, 2}, {1, 2, 5, 0}, {2, 3, 5, 0}, {3, 4, 5, 0}, {4, 1, 5, 0}};
/* quadratic: the mid-edge node of corners (a, b) */
static const int tet10_edges[][3] = {{1, 2, 5}, {2, 3, 6}, {3, 1, 7}, {1, 4, 8}, {2, 4, 9}, {3, 4, 10}};
static const int hex20_edges[][3] = {{1, 2, 9},   {2, 3, 10},  {3, 4, 11},  {4, 1, 12},
                                     {5, 6, 13},  {6, 7, 14},  {7, 8, 15},  {8, 5, 16},
                                     {1, 5, 17},  {2, 6, 18},  {3, 7, 19},  {4, 8, 20}};
static const int wedge15_edges[][3] = {{1, 2, 7},   {2, 3, 8},   {3, 1, 9},   {4, 5, 10}, {5, 6, 11},
                                       {6, 4, 12},  {1, 4, 13},  {2, 5, 14},  {3, 6, 15}};

static int mid_of(const int (*edges)[3], int n, int a, int b)
{
    for (int i = 0; i < n; ++i)
        if ((edges[i][0] == a && edges[i][1] == b) || (edges[i][0] == b && edges[i][1] == a)) return edges[i][2];
    return 0;
}

int abq_face_nodes(int n_nodes, int f, int local[8], cm_cell_type *type)
{
    const int *corners = NULL;
    int nc = 0, ne = 0;
    const int (*edges)[3] = NULL;
    switch (n_nodes) {
    case 4: case 10:
        if (f > 4) return 0;
        corners = tet_faces[f - 1], nc = 3;
        if (n_nodes == 10) edges = tet10_edges, ne = 6;
        break;
    case 8: case 20:
        corners = hex_faces[f - 1], nc = 4;
        if (n_nodes == 20) edges = hex20_edges, ne = 12;
        break;
    case 6: case 15:
        if (f > 5) return 0;
        corners = wedge_faces[f - 1], nc = wedge_faces[f - 1][3] ? 4 : 3;
        if (n_nodes == 15) edges = wedge15_edges, ne = 9;
        break;
    case 5:
        if (f > 5) return 0;
        corners = pyr_faces[f - 1], nc = pyr_faces[f - 1][3] ? 4 : 3;
        break;
    default: return 0;
    }
    for (int i = 0; i < nc; ++i) local[i] = corners[i] - 1;
    if (!edges) {
        *type = nc == 3 ? CM_CELL_TRI3 : CM_CELL_QUAD4;
        return nc;
    }
    for (int i = 0; i < nc; ++i) local[nc + i] = mid_of(edges, ne, corners[i], corners[(i + 1) % nc]) - 1;
    *type = nc == 3 ? CM_CELL_TRI6 : CM_CELL_QUAD8;
    return 2 * nc;
}

/* ---- the build ---- */

typedef struct abq_build_state {
    abq_reader *r;
    const char *path;
    abq_hash *nodes, *cells; /* per part: id -> template index */
} abq_build_state;

static cm_status fail(abq_build_state *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static cm_status fail(abq_build_state *b, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return cm_error(b->r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %s", b->path, msg);
}

static int kept(const abq_reader *r, size_t p)
{
    return p == 0 || r->parts[p].n_inst > 0;
}

/* Drops the templates of parts no instance places (their ids are not resolved yet: conn
 * still holds ids, so nothing but the ranges moves). */
static cm_status drop_unplaced(abq_build_state *b)
{
    abq_reader *r = b->r;
    cm_mesh *m = r->m;
    int any = 0;
    for (size_t p = 1; p < r->n_parts; ++p) any |= !kept(r, p) && r->parts[p].used;
    if (!any) return CM_OK;
    int64_t *map = malloc((m->n_nodes ? m->n_nodes : 1) * sizeof *map);
    if (!map) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    for (size_t i = 0; i < m->n_nodes; ++i) map[i] = 0;
    for (size_t p = 1; p < r->n_parts; ++p)
        if (!kept(r, p))
            for (size_t i = r->parts[p].node0; i < r->parts[p].node1; ++i) map[i] = -1;
    size_t nn = 0;
    for (size_t i = 0; i < m->n_nodes; ++i) {
        if (map[i] < 0) continue;
        memmove(m->xyz + 3 * nn, m->xyz + 3 * i, 3 * sizeof(double));
        m->node_tag[nn] = m->node_tag[i];
        map[i] = (int64_t)nn++;
    }
    /* cells: whole ranges of the dropped parts go */
    unsigned char *gone = calloc(m->n_cells ? m->n_cells : 1, 1);
    if (!gone) {
        free(map);
        return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    }
    for (size_t p = 1; p < r->n_parts; ++p)
        if (!kept(r, p)) memset(gone + r->parts[p].cell0, 1, r->parts[p].cell1 - r->parts[p].cell0);
    size_t nc = 0;
    int64_t at = 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        if (gone[c]) continue;
        const int64_t o = m->offset[c], n = m->offset[c + 1] - o;
        memmove(m->conn + at, m->conn + o, (size_t)n * sizeof(int64_t));
        m->type[nc] = m->type[c];
        m->physical[nc] = m->physical[c];
        m->entity[nc] = m->entity[c];
        if (m->cell_tag) m->cell_tag[nc] = m->cell_tag[c];
        m->offset[nc] = at;
        at += n;
        m->offset[++nc] = at;
    }
    free(gone);
    /* the ranges of the parts kept, in their new places */
    size_t nshift = 0, cshift = 0;
    for (size_t p = 1; p < r->n_parts; ++p) {
        abq_part *q = &r->parts[p];
        const size_t nl = q->node1 - q->node0, cl = q->cell1 - q->cell0;
        if (!kept(r, p)) {
            nshift += nl, cshift += cl;
            q->node0 = q->node1 = q->cell0 = q->cell1 = 0;
            continue;
        }
        q->node0 -= nshift, q->node1 -= nshift, q->cell0 -= cshift, q->cell1 -= cshift;
    }
    r->parts[0].node0 -= nshift, r->parts[0].node1 -= nshift;
    r->parts[0].cell0 -= cshift, r->parts[0].cell1 -= cshift;
    m->n_nodes = m->cap_nodes = nn;
    m->n_cells = nc;
    /* the coordinates of dropped nodes stay in the deck as they are: no span */
    for (size_t fi = 0; fi < r->src->n_files; ++fi) {
        cm_rewrite_file *f = &r->src->files[fi];
        size_t k = 0;
        for (size_t i = 0; i < f->n_spans; ++i)
            if (map[f->spans[i].node] >= 0) {
                f->spans[k] = f->spans[i];
                f->spans[k++].node = map[f->spans[i].node];
            }
        f->n_spans = k;
    }
    free(map);
    return CM_OK;
}

/* Node and element ids of each kept scope hashed; element node ids made node indices. */
static cm_status resolve(abq_build_state *b)
{
    abq_reader *r = b->r;
    cm_mesh *m = r->m;
    int64_t old;
    for (size_t p = 0; p < r->n_parts; ++p) {
        const abq_part *q = &r->parts[p];
        if (!kept(r, p)) continue;
        const char *what = p ? q->name : "the model";
        const int dn = dense_map(&b->nodes[p], m->node_tag + q->node0, q->node1 - q->node0, (int64_t)q->node0);
        const int dc = q->cell1 == q->cell0 ||
                       dense_map(&b->cells[p], m->cell_tag + q->cell0, q->cell1 - q->cell0, (int64_t)q->cell0);
        if ((!dn && !hash_init(&b->nodes[p], q->node1 - q->node0)) || (!dc && !hash_init(&b->cells[p], q->cell1 - q->cell0)))
            return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        for (size_t i = q->node0; !dn && i < q->node1; ++i)
            if (hash_put(&b->nodes[p], m->node_tag[i], (int64_t)i, &old))
                return fail(b, "node %lld of %s is defined twice", (long long)m->node_tag[i], what);
        for (size_t c = q->cell0; c < q->cell1; ++c) {
            if (!dc && hash_put(&b->cells[p], m->cell_tag[c], (int64_t)c, &old))
                return fail(b, "element %lld of %s is defined twice", (long long)m->cell_tag[c], what);
            for (int64_t k = m->offset[c]; k < m->offset[c + 1]; ++k) {
                const int64_t i = hash_get(&b->nodes[p], m->conn[k]);
                if (i < 0)
                    return fail(b, "element %lld of %s: node %lld is not defined", (long long)m->cell_tag[c], what,
                                (long long)m->conn[k]);
                m->conn[k] = i;
            }
        }
    }
    return CM_OK;
}

static void apply(const abq_xform *x, double *p)
{
    const double v[3] = {p[0], p[1], p[2]};
    for (int i = 0; i < 3; ++i) p[i] = x->r[3 * i] * v[0] + x->r[3 * i + 1] * v[1] + x->r[3 * i + 2] * v[2] + x->c[i];
}

/* Every instance after a part's first: its nodes and cells appended as copies of the
 * template; then the placements applied. */
static cm_status place(abq_build_state *b)
{
    abq_reader *r = b->r;
    cm_mesh *m = r->m;
    cm_status s = CM_OK;
    for (size_t p = 1; p < r->n_parts; ++p) r->parts[p].n_inst = 0; /* counted again as placed */
    for (size_t k = 0; s == CM_OK && k < r->n_insts; ++k) {
        abq_inst *in = &r->insts[k];
        abq_part *q = &r->parts[in->part];
        if (q->n_inst++ == 0) {
            in->node_base = q->node0;
            in->cell_base = q->cell0;
            continue;
        }
        const size_t nn = q->node1 - q->node0, base = m->n_nodes;
        s = cm_mesh_resize_nodes(r->ctx, m, base + nn, 1);
        if (s != CM_OK) break;
        memcpy(m->xyz + 3 * base, m->xyz + 3 * q->node0, 3 * nn * sizeof(double));
        memcpy(m->node_tag + base, m->node_tag + q->node0, nn * sizeof(int64_t));
        in->node_base = base;
        in->cell_base = m->n_cells;
        const int64_t shift = (int64_t)base - (int64_t)q->node0;
        for (size_t c = q->cell0; s == CM_OK && c < q->cell1; ++c) {
            const int64_t o = m->offset[c], n = m->offset[c + 1] - o;
            int64_t v[27];
            for (int64_t j = 0; j < n; ++j) v[j] = m->conn[o + j] + shift;
            s = cm_mesh_add_cell(r->ctx, m, (cm_cell_type)m->type[c], v, (size_t)n, 0, 0, m->cell_tag[c]);
        }
    }
    for (size_t k = 0; s == CM_OK && k < r->n_insts; ++k) {
        const abq_inst *in = &r->insts[k];
        if (!in->moved) continue;
        const abq_part *q = &r->parts[in->part];
        for (size_t i = 0; i < q->node1 - q->node0; ++i) apply(&in->x, m->xyz + 3 * (in->node_base + i));
    }
    return s;
}

/* The instance whose placement a span of a template node goes through (-1: none moves it):
 * its part's first. */
static cm_status mark_spans(abq_build_state *b)
{
    abq_reader *r = b->r;
    const size_t n = r->m->n_nodes;
    int64_t *first = malloc((n ? n : 1) * sizeof *first);
    if (!first) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    for (size_t i = 0; i < n; ++i) first[i] = -1;
    for (size_t k = r->n_insts; k-- > 0;) {
        const abq_part *q = &r->parts[r->insts[k].part];
        if (!r->insts[k].moved) continue;
        if (r->insts[k].node_base != q->node0) continue; /* a copy: its nodes have no span */
        for (size_t i = q->node0; i < q->node1; ++i) first[i] = (int64_t)k;
    }
    for (size_t fi = 0; fi < r->src->n_files; ++fi) {
        cm_rewrite_file *f = &r->src->files[fi];
        for (size_t i = 0; i < f->n_spans; ++i) f->spans[i].aux = first[f->spans[i].node];
    }
    free(first);
    return CM_OK;
}

/* ---- groups ---- */

typedef struct abq_group {
    int tag, dim;
    size_t n;
    int64_t *cells; /* an element set's cells */
} abq_group;

static cm_status add_group(abq_build_state *b, int dim, int tag, const char *inst, const char *name)
{
    char full[600];
    if (inst) snprintf(full, sizeof full, "%s.%s", inst, name);
    else snprintf(full, sizeof full, "%s", name);
    return cm_mesh_add_group(b->r->ctx, b->r->m, dim, tag, full);
}

/* Member i of set s, seen from instance k of its part (-1: the set's scope): its node or
 * cell index, -1 when the id is not defined. */
static int64_t member(abq_build_state *b, const abq_set *s, size_t i, int64_t k, int cell)
{
    abq_reader *r = b->r;
    int64_t inst = s->inst[i] >= 0 ? s->inst[i] : k;
    int part = inst >= 0 ? r->insts[inst].part : s->part;
    const abq_hash *h = cell ? &b->cells[part] : &b->nodes[part];
    const int64_t t = hash_get(h, s->id[i]);
    if (t < 0 || inst < 0 || part == 0) return t;
    const abq_part *q = &r->parts[part];
    const abq_inst *in = &r->insts[inst];
    return cell ? t - (int64_t)q->cell0 + (int64_t)in->cell_base : t - (int64_t)q->node0 + (int64_t)in->node_base;
}

static cm_status one_set(abq_build_state *b, const abq_set *s, int64_t k, int *tag, int *stamp, int64_t *cstamp,
                         abq_group *g)
{
    abq_reader *r = b->r;
    cm_mesh *m = r->m;
    cm_status st = CM_OK;
    const int t = ++*tag;
    const char *inst = k >= 0 ? r->insts[k].name : NULL;
    const int nodal = s->kind == ABQ_NSET || (s->kind == ABQ_SURFACE && s->n && s->face[0] == 0);
    int dim = nodal ? 0 : s->kind == ABQ_SURFACE ? 2 : 0;
    g->tag = t;
    for (size_t i = 0; st == CM_OK && i < s->n; ++i) {
        const int64_t x = member(b, s, i, k, !nodal);
        if (x < 0) {
            const int skipped = !nodal && r->parts[s->inst[i] >= 0 ? r->insts[s->inst[i]].part : s->part].skipped;
            if (skipped) continue; /* an element of a type cadmorph does not read */
            return fail(b, "%s %s: %s %lld is not defined", s->kind == ABQ_NSET ? "*NSET" : s->kind == ABQ_ELSET ? "*ELSET" : "*SURFACE",
                        s->name, nodal ? "node" : "element", (long long)s->id[i]);
        }
        if (nodal) {
            if (stamp[x] == t) continue;
            stamp[x] = t;
            st = cm_mesh_add_cell(r->ctx, m, CM_CELL_POINT, &x, 1, t, 0, 0);
        } else if (s->kind == ABQ_ELSET) {
            if (cstamp[x] == t) continue;
            cstamp[x] = t;
            const int d = cm_cell_type_info((cm_cell_type)m->type[x])->dim;
            if (d > dim) dim = d;
            if (!(g->n & (g->n + 1)) || !g->cells) { /* n + 1 a power of 2: full */
                int64_t *cells = realloc(g->cells, (2 * g->n + 2) * sizeof *cells);
                if (!cells) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
                g->cells = cells;
            }
            g->cells[g->n++] = x;
        } else {
            /* a face of a solid, or a shell's side */
            const cm_cell_type ty = (cm_cell_type)m->type[x];
            const int64_t *v = m->conn + m->offset[x];
            const int nv = (int)(m->offset[x + 1] - m->offset[x]);
            const int face = s->face[i];
            int64_t fn[9];
            int local[8];
            cm_cell_type ft;
            int n = 0;
            if (cm_cell_type_info(ty)->dim == 3 && face <= 6) {
                n = abq_face_nodes(nv, face, local, &ft);
                /* Abaqus order from VTK order: the wedges' permutation is its own inverse */
                abq_type at;
                const int wedge = ty == CM_CELL_WEDGE6 || ty == CM_CELL_WEDGE15;
                if (wedge) abq_element_type(nv == 6 ? "C3D6" : "C3D15", &at);
                for (int j = 0; j < n; ++j) fn[j] = v[wedge ? at.perm[local[j]] : local[j]];
            } else if (cm_cell_type_info(ty)->dim == 2 && face >= 7) {
                static const int rev3[] = {0, 2, 1}, rev4[] = {0, 3, 2, 1}, rev6[] = {0, 2, 1, 5, 4, 3},
                                 rev8[] = {0, 3, 2, 1, 7, 6, 5, 4};
                const int *rev = nv == 3 ? rev3 : nv == 4 ? rev4 : nv == 6 ? rev6 : nv == 8 ? rev8 : NULL;
                n = nv <= 9 ? nv : 0;
                ft = ty;
                for (int j = 0; j < n; ++j) fn[j] = v[face == 8 && rev ? rev[j] : j];
            }
            if (n == 0)
                return fail(b, "*SURFACE %s: element %lld (%s) has no face %s%d", s->name, (long long)s->id[i],
                            cm_cell_type_info(ty)->name, face <= 6 ? "S" : "", face <= 6 ? face : 0);
            st = cm_mesh_add_cell(r->ctx, m, ft, fn, (size_t)n, t, 0, 0);
        }
    }
    if (st == CM_OK) st = add_group(b, s->kind == ABQ_ELSET && dim == 0 ? 3 : dim, t, inst, s->name);
    g->dim = dim;
    return st;
}

static int by_size(const void *a, const void *b)
{
    const abq_group *x = a, *y = b;
    /* larger first; among equal sizes the later defined (larger tag) first */
    if (x->n != y->n) return x->n < y->n ? 1 : -1;
    return x->tag < y->tag ? 1 : -1;
}

static cm_status groups(abq_build_state *b)
{
    abq_reader *r = b->r;
    cm_mesh *m = r->m;
    const size_t n_el = m->n_cells;
    int *stamp = calloc(m->n_nodes ? m->n_nodes : 1, sizeof *stamp);
    int64_t *cstamp = calloc(n_el ? n_el : 1, sizeof *cstamp);
    size_t ng = 0, capg = 0;
    abq_group *gs = NULL;
    cm_status s = stamp && cstamp ? CM_OK : cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    int tag = 0;
    for (size_t i = 0; s == CM_OK && i < r->n_sets; ++i) {
        const abq_set *set = &r->sets[i];
        if (set->part != 0 && !kept(r, (size_t)set->part)) continue;
        for (size_t k = 0; s == CM_OK && k < (set->part ? r->n_insts : 1); ++k) {
            if (set->part && r->insts[k].part != set->part) continue;
            if (ng == capg) {
                capg = capg ? 2 * capg : 16;
                abq_group *g = realloc(gs, capg * sizeof *g);
                if (!g) {
                    s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
                    break;
                }
                gs = g;
            }
            memset(&gs[ng], 0, sizeof *gs);
            s = one_set(b, set, set->part ? (int64_t)k : -1, &tag, stamp, cstamp, &gs[ng]);
            ++ng;
        }
    }
    /* element sets: the smallest set's tag wins (the largest assigned first) */
    if (s == CM_OK) {
        if (ng > 1) qsort(gs, ng, sizeof *gs, by_size);
        for (size_t g = 0; g < ng; ++g)
            for (size_t i = 0; i < gs[g].n; ++i) m->physical[gs[g].cells[i]] = gs[g].tag;
    }
    for (size_t g = 0; g < ng; ++g) free(gs[g].cells);
    free(gs);
    free(stamp);
    free(cstamp);
    return s;
}

void abq_record_free(void *record)
{
    abq_record *rec = record;
    if (!rec) return;
    for (size_t k = 0; rec->insts && k < rec->n_insts; ++k) free(rec->insts[k].name);
    free(rec->insts);
    free(rec->part_nodes);
    free(rec);
}

static cm_status make_record(abq_build_state *b, abq_record **out)
{
    abq_reader *r = b->r;
    abq_record *rec = calloc(1, sizeof *rec);
    if (rec) {
        rec->insts = calloc(r->n_insts ? r->n_insts : 1, sizeof *rec->insts);
        rec->part_nodes = calloc(r->n_parts, sizeof *rec->part_nodes);
    }
    if (!rec || !rec->insts || !rec->part_nodes) {
        abq_record_free(rec);
        return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    }
    rec->n_insts = r->n_insts;
    for (size_t k = 0; k < r->n_insts; ++k) {
        rec->insts[k] = r->insts[k];
        rec->insts[k].name = NULL;
        const size_t l = strlen(r->insts[k].name) + 1;
        if ((rec->insts[k].name = malloc(l)) == NULL) {
            abq_record_free(rec);
            return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        }
        memcpy(rec->insts[k].name, r->insts[k].name, l);
    }
    rec->n_parts = r->n_parts;
    for (size_t p = 0; p < r->n_parts; ++p) rec->part_nodes[p] = r->parts[p].node1 - r->parts[p].node0;
    *out = rec;
    return CM_OK;
}

cm_status abq_build(abq_reader *r, const char *path)
{
    abq_build_state b = {r, path, NULL, NULL};
    cm_mesh *m = r->m;
    cm_status s = CM_OK;
    if (m->n_nodes == 0) return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: no *NODE data", path);
    if (!m->cell_tag && m->n_cells) return cm_error(r->ctx, CM_ERR_INTERNAL, "cm_mesh_read: %s: element ids lost", path);
    b.nodes = calloc(r->n_parts, sizeof *b.nodes);
    b.cells = calloc(r->n_parts, sizeof *b.cells);
    if (!b.nodes || !b.cells) s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    if (s == CM_OK) s = drop_unplaced(&b);
    if (s == CM_OK && m->n_nodes == 0) s = fail(&b, "no instance places a part with nodes");
    if (s == CM_OK) s = resolve(&b);
    if (s == CM_OK) s = place(&b);
    if (s == CM_OK) s = mark_spans(&b);
    const size_t elements = m->n_cells;
    if (s == CM_OK) s = groups(&b);
    for (size_t p = 0; b.nodes && b.cells && p < r->n_parts; ++p) {
        hash_free(&b.nodes[p]);
        hash_free(&b.cells[p]);
    }
    free(b.nodes);
    free(b.cells);
    /* ids repeated by instances (or parts) cannot be the mesh's ids: index + 1 then (a deck
     * without parts has its ids checked already, and the cells' too when no group added any) */
    int ok = 1;
    const int one_scope = r->n_parts == 1 && r->n_insts == 0;
    if (s == CM_OK && !one_scope && !distinct(m->node_tag, m->n_nodes, &ok)) s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    if (s == CM_OK && !ok) {
        free(m->node_tag);
        m->node_tag = NULL;
    }
    ok = 1;
    if (s == CM_OK && m->cell_tag && !(one_scope && m->n_cells == elements) && !distinct(m->cell_tag, m->n_cells, &ok)) s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    if (s == CM_OK && m->cell_tag && !ok) {
        free(m->cell_tag);
        m->cell_tag = NULL;
    }
    abq_record *rec = NULL;
    if (s == CM_OK) s = make_record(&b, &rec);
    if (s == CM_OK) {
        r->src->format = rec;
        r->src->free_format = abq_record_free;
        s = cm_mesh_set_origin(r->ctx, m, CM_FORMAT_ABAQUS, r->src, cm_rewrite_source_free);
        r->src = NULL; /* the origin's now (freed with it on failure) */
    }
    if (s == CM_OK && r->skipped)
        return cm_error(r->ctx, CM_WARNING, "%s: %zu elements of types cadmorph does not read (%s, ...) skipped; "
                                            "written back, the deck keeps them", path, r->skipped, r->skipped_type);
    return s;
}
