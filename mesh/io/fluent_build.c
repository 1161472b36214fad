/* The mesh of a Fluent file from its faces (fluent_internal.h): each cell is closed by the
 * faces that name it as c0 or c1. A face's right-hand normal points toward c0, so a face is
 * outward for c1 as written and reversed for c0. Cells whose faces make a tet, hex, wedge or
 * pyramid become that type in VTK node order (checked face by face against the type's
 * table), every other cell a polyhedron (outward face stream, mesh.h). Boundary face zones
 * (every bc-type but interior) become 2-D cells, oriented outward; zones become groups. */
#include "cell_faces.h"
#include "fluent_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { BC_INTERIOR = 2 };

long cm_fluent_line_of(const cm_fluent_parsed *p, size_t at)
{
    long line = 1;
    for (size_t i = 0; i < at && i < p->size; ++i) line += p->data[i] == '\n';
    return line;
}

void cm_fluent_where(const cm_fluent_parsed *p, size_t f, char *out, size_t cap)
{
    const int64_t w = p->faces.where[f];
    if (w >= 0) snprintf(out, cap, "%s:%ld", p->path, cm_fluent_line_of(p, (size_t)w));
    else snprintf(out, cap, "%s: byte %lld", p->path, (long long)(-1 - w));
}

typedef struct cell_face {
    const int64_t *nodes;
    int n;
    int reversed;
} cell_face;

static int64_t node_at(const cell_face *f, int k)
{
    return f->reversed ? f->nodes[f->n - 1 - k] : f->nodes[k];
}

static int contains(const int64_t *set, int n, int64_t v)
{
    for (int i = 0; i < n; ++i)
        if (set[i] == v) return 1;
    return 0;
}

/* The unique neighbour of x along the faces' edges that is not in base; -1 if none or several. */
static int64_t across(const cell_face *f, int nf, const int64_t *base, int nb, int64_t x)
{
    int64_t found = -1;
    for (int i = 0; i < nf; ++i)
        for (int k = 0; k < f[i].n; ++k) {
            const int64_t u = f[i].nodes[k], v = f[i].nodes[(k + 1) % f[i].n];
            const int64_t other = u == x ? v : v == x ? u : -1;
            if (other < 0 || contains(base, nb, other)) continue;
            if (found >= 0 && found != other) return -1;
            found = other;
        }
    return found;
}

/* The cell's nodes in VTK order if its faces make a tet, hex, wedge or pyramid: *type and
 * out[], returns 1; 0 for a polyhedron. */
static int typed_cell(const cell_face *f, int nf, cm_cell_type *type, int64_t out[8])
{
    int tri = 0, quad = 0;
    for (int i = 0; i < nf; ++i) {
        tri += f[i].n == 3;
        quad += f[i].n == 4;
    }
    int nb, nn;
    if (nf == 4 && tri == 4) *type = CM_CELL_TET4, nb = 3, nn = 4;
    else if (nf == 6 && quad == 6) *type = CM_CELL_HEX8, nb = 4, nn = 8;
    else if (nf == 5 && tri == 2 && quad == 3) *type = CM_CELL_WEDGE6, nb = 3, nn = 6;
    else if (nf == 5 && tri == 4 && quad == 1) *type = CM_CELL_PYR5, nb = 4, nn = 5;
    else return 0;
    const cm_face_table *t = cm_cell_face_table(*type);
    int bf = -1; /* the table's face of the base corners 0 .. nb-1 */
    for (int i = 0; i < t->n_faces && bf < 0; ++i) {
        int low = t->size[i] == nb;
        for (int k = 0; low && k < nb; ++k) low = t->node[i][k] < nb;
        if (low) bf = i;
    }
    int gb = -1; /* a given face of the base's size */
    for (int i = 0; i < nf && gb < 0; ++i)
        if (f[i].n == nb) gb = i;
    if (bf < 0 || gb < 0) return 0;
    int64_t base[4];
    for (int k = 0; k < nb; ++k) {
        base[k] = node_at(&f[gb], k);
        out[t->node[bf][k]] = base[k];
    }
    if (nn - nb == 1) { /* the apex: the one node off the base */
        int64_t apex = -1;
        for (int i = 0; i < nf; ++i)
            for (int k = 0; k < f[i].n; ++k) {
                const int64_t v = f[i].nodes[k];
                if (contains(base, nb, v)) continue;
                if (apex >= 0 && apex != v) return 0;
                apex = v;
            }
        if (apex < 0) return 0;
        out[nb] = apex;
    } else {
        for (int k = 0; k < nb; ++k)
            if ((out[nb + k] = across(f, nf, base, nb, out[k])) < 0) return 0;
    }
    for (int i = 0; i < nn; ++i)
        for (int j = 0; j < i; ++j)
            if (out[i] == out[j]) return 0;
    /* every face of the type is one of the given faces, in the same turning sense */
    unsigned used = 0;
    for (int i = 0; i < t->n_faces; ++i) {
        int64_t want[4];
        for (int k = 0; k < t->size[i]; ++k) want[k] = out[t->node[i][k]];
        int hit = 0;
        for (int g = 0; g < nf && !hit; ++g) {
            if ((used >> g & 1) || f[g].n != t->size[i]) continue;
            for (int r = 0; r < f[g].n && !hit; ++r) {
                int same = 1;
                for (int k = 0; same && k < f[g].n; ++k) same = node_at(&f[g], (r + k) % f[g].n) == want[k];
                if (same) {
                    hit = 1;
                    used |= 1u << g;
                }
            }
        }
        if (!hit) return 0;
    }
    return 1;
}

static const char *zone_name(const cm_fluent_zone *z, char *buf, size_t cap)
{
    if (z->name[0]) return z->name;
    snprintf(buf, cap, "zone-%lld", (long long)z->id);
    return buf;
}

static int has_group(const cm_mesh *m, int dim, int tag)
{
    for (size_t i = 0; i < m->n_groups; ++i)
        if (m->groups[i].dim == dim && m->groups[i].tag == tag) return 1;
    return 0;
}

static cm_status face_error(cm_context *ctx, const cm_fluent_parsed *p, size_t f, const char *what, long long v)
{
    char where[600];
    cm_fluent_where(p, f, where, sizeof where);
    return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: face %s %llx (hexadecimal)", where, what, v);
}

cm_status cm_fluent_build(cm_context *ctx, cm_fluent_parsed *p, cm_mesh *m)
{
    const cm_fluent_faces *F = &p->faces;
    if (F->n == 0) return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: no faces (a Fluent mesh holds its cells as faces)", p->path);
    int64_t n_cells = p->n_cells_declared;
    for (size_t z = 0; z < p->n_zones; ++z)
        if (p->zones[z].kind == 12) {
            if (p->n_cells_declared && p->zones[z].last > p->n_cells_declared)
                return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: cell zone %lld ends at cell %llx, beyond the %llx cells declared",
                                p->path, (long long)p->zones[z].id, (long long)p->zones[z].last, (long long)p->n_cells_declared);
            if (!p->n_cells_declared && p->zones[z].last > n_cells) n_cells = p->zones[z].last;
        }
    if (n_cells == 0)
        for (size_t f = 0; f < F->n; ++f) n_cells = F->c0[f] > n_cells ? F->c0[f] : F->c1[f] > n_cells ? F->c1[f] : n_cells;
    /* each cell needs faces, each face serves two cells at most: a bound before allocating */
    if ((uint64_t)n_cells > 2 * (uint64_t)F->n)
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %lld cells, but only %zu faces to close them", p->path,
                        (long long)n_cells, F->n);
    for (size_t f = 0; f < F->n; ++f) {
        if (F->c0[f] < 1 || F->c0[f] > n_cells) return face_error(ctx, p, f, "names a missing cell c0", (long long)F->c0[f]);
        if (F->c1[f] > n_cells) return face_error(ctx, p, f, "names a missing cell c1", (long long)F->c1[f]);
        if (F->c1[f] == F->c0[f]) return face_error(ctx, p, f, "has the same cell on both sides:", (long long)F->c0[f]);
        for (int64_t k = F->offset[f]; k < F->offset[f + 1]; ++k)
            if (F->nodes[k] < 0 || F->nodes[k] >= p->n_nodes) return face_error(ctx, p, f, "names a missing node", (long long)F->nodes[k] + 1);
    }
    const size_t nc = (size_t)n_cells;
    int64_t *start = calloc(nc + 1, sizeof *start);
    size_t *list = malloc(2 * F->n * sizeof *list);
    int *phys = calloc(nc, sizeof *phys);
    cell_face *cf = NULL;
    int64_t *stream = NULL;
    cm_status s = start && list && phys ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", p->path);
    if (s == CM_OK) {
        for (size_t f = 0; f < F->n; ++f) {
            ++start[F->c0[f]]; /* cell c (1-based) counted at start[c]: its faces start at start[c - 1] */
            if (F->c1[f]) ++start[F->c1[f]];
        }
        for (size_t c = 0; c < nc; ++c) start[c + 1] += start[c];
        int64_t *pos = malloc((nc + 1) * sizeof *pos);
        if (!pos) {
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", p->path);
        } else {
            memcpy(pos, start, (nc + 1) * sizeof *pos);
            for (size_t f = 0; f < F->n; ++f) {
                list[pos[F->c0[f] - 1]++] = 2 * f;
                if (F->c1[f]) list[pos[F->c1[f] - 1]++] = 2 * f + 1;
            }
            free(pos);
        }
        for (size_t z = 0; z < p->n_zones; ++z)
            if (p->zones[z].kind == 12)
                for (int64_t c = p->zones[z].first; c <= p->zones[z].last && c <= n_cells; ++c) phys[c - 1] = (int)p->zones[z].id;
        if (s == CM_OK) s = cm_mesh_reserve_cells(ctx, m, nc + F->n, F->n_conn * 2 + 8 * nc);
    }
    /* list[start[c] .. start[c+1]) are the faces of cell c (0-based), 2f + (1 for c1) */
    int64_t max_faces = 0;
    for (size_t c = 0; s == CM_OK && c < nc; ++c) {
        const int64_t k = start[c + 1] - start[c];
        if (k < 4) {
            s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: cell %llx (hexadecimal) is closed by %lld faces (at least 4 needed)",
                         p->path, (unsigned long long)c + 1, (long long)k);
        }
        if (k > max_faces) max_faces = k;
    }
    if (s == CM_OK && !(cf = malloc((size_t)max_faces * sizeof *cf)))
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", p->path);
    size_t cap_stream = 0;
    for (size_t c = 0; s == CM_OK && c < nc; ++c) {
        const int nf = (int)(start[c + 1] - start[c]);
        size_t len = 1;
        for (int i = 0; i < nf; ++i) {
            const size_t e = list[start[c] + i], f = e / 2;
            cf[i].nodes = F->nodes + F->offset[f];
            cf[i].n = (int)(F->offset[f + 1] - F->offset[f]);
            cf[i].reversed = (e & 1) == 0; /* c0: the normal points in */
            len += 1 + (size_t)cf[i].n;
        }
        cm_cell_type type;
        int64_t typed[8];
        if (typed_cell(cf, nf, &type, typed)) {
            s = cm_mesh_add_cell(ctx, m, type, typed, (size_t)cm_cell_type_info(type)->nodes, phys[c], 0, 0);
            continue;
        }
        if (len > cap_stream) {
            int64_t *d = realloc(stream, 2 * len * sizeof *d);
            if (!d) {
                s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", p->path);
                break;
            }
            stream = d;
            cap_stream = 2 * len;
        }
        size_t at = 0;
        stream[at++] = nf;
        for (int i = 0; i < nf; ++i) {
            stream[at++] = cf[i].n;
            for (int k = 0; k < cf[i].n; ++k) stream[at++] = node_at(&cf[i], k);
        }
        s = cm_mesh_add_cell(ctx, m, CM_CELL_POLYHEDRON, stream, at, phys[c], 0, 0);
    }
    /* boundary faces as 2-D cells, outward (their normal points into c0) */
    for (size_t f = 0; s == CM_OK && f < F->n; ++f) {
        const cm_fluent_zone *z = &p->zones[F->zone[f]];
        if (z->type == BC_INTERIOR) continue;
        const int n = (int)(F->offset[f + 1] - F->offset[f]);
        int64_t small[4];
        int64_t *nodes = n <= 4 ? small : stream;
        if (n > 4 && (size_t)n > cap_stream) {
            int64_t *d = realloc(stream, (size_t)n * sizeof *d);
            if (!d) {
                s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", p->path);
                break;
            }
            stream = nodes = d;
            cap_stream = (size_t)n;
        }
        for (int k = 0; k < n; ++k) nodes[k] = F->nodes[F->offset[f + 1] - 1 - k];
        const cm_cell_type type = n == 3 ? CM_CELL_TRI3 : n == 4 ? CM_CELL_QUAD4 : CM_CELL_POLYGON;
        s = cm_mesh_add_cell(ctx, m, type, nodes, (size_t)n, (int)z->id, 0, 0);
    }
    char buf[64];
    for (size_t i = 0; s == CM_OK && i < p->n_zones; ++i) {
        const cm_fluent_zone *z = &p->zones[i];
        const int dim = z->kind == 12 ? 3 : 2;
        if ((z->kind == 13 && z->type == BC_INTERIOR) || has_group(m, dim, (int)z->id)) continue;
        s = cm_mesh_add_group(ctx, m, dim, (int)z->id, zone_name(z, buf, sizeof buf));
    }
    free(start);
    free(list);
    free(phys);
    free(cf);
    free(stream);
    return s;
}
