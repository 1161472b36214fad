/* CGNS reader (docs/DESIGN.md, "Mesh formats"): the unstructured zones of every base as one
 * mesh. Zone vertices that coincide exactly (bit for bit) with a vertex of an earlier zone are
 * merged into one node (the zones' interfaces; a vertex is never merged with one of its own
 * zone); the map from each zone's vertices to the mesh's nodes is kept for writing back.
 * Volume cells take their zone's name as group; a BC_t takes its FamilyName, else its own
 * name (faces of element ranges/lists; vertex sets as point cells); 2-D cells no BC names
 * take their section's name. Structured zones are refused. */
#define _POSIX_C_SOURCE 200809L
#include "cgns_internal.h"
#include "formats.h"

#include <cgnslib.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static pthread_mutex_t cgns_mutex = PTHREAD_MUTEX_INITIALIZER;
void cm_cgns_lock(void) { pthread_mutex_lock(&cgns_mutex); }
void cm_cgns_unlock(void) { pthread_mutex_unlock(&cgns_mutex); }

int cm_cgns_magic_ok(const char *path)
{
    unsigned char b[32] = {0};
    FILE *f = cm_file_open_quiet(path, NULL);
    if (!f) return 1; /* the reader says why it cannot open it */
    size_t n = fread(b, 1, sizeof b, f);
    fclose(f);
    static const unsigned char hdf5[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    if (n >= 8 && memcmp(b, hdf5, 8) == 0) return 1;
    /* ADF: four bytes (the "@(#)" of old files) and the text below */
    return n >= 24 && memcmp(b + 4, "ADF Database Version", 20) == 0;
}

void cm_cgns_state_free(void *state)
{
    cm_cgns_state *st = state;
    if (!st) return;
    for (size_t z = 0; z < st->n_zones; ++z) free(st->zones[z].node);
    free(st->zones);
    free(st->path);
    free(st);
}

/* One element section of a zone, read whole. */
typedef struct section {
    char name[33];
    CGNS_ENUMT(ElementType_t) type;
    cgsize_t start, end;
    cgsize_t *data;
    cgsize_t *offsets;   /* MIXED, NGON_n, NFACE_n: #elements + 1 */
    int64_t *cell;       /* #elements: the mesh cell of each element, -1 for none */
} section;

typedef struct reader {
    cm_context *ctx;
    const char *path;
    int fn;
    cm_mesh *m;
    cm_cgns_state *st;
    int next_tag;
    char where[160];     /* the node path of messages */
} reader;

static cm_status fail(reader *r, cm_status code, const char *fmt, ...)
{
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    /* node names are the file's bytes: one printable line in the message */
    char where[sizeof r->where];
    snprintf(where, sizeof where, "%s", r->where[0] ? r->where : "/");
    for (char *c = where; *c; ++c) *c = (unsigned char)*c < 0x20 || (unsigned char)*c >= 0x7f ? '?' : *c;
    for (char *c = msg; *c; ++c) *c = (unsigned char)*c < 0x20 || (unsigned char)*c >= 0x7f ? '?' : *c;
    return cm_error(r->ctx, code, "cm_mesh_read: %s: %s: %s", r->path, where, msg);
}

static cm_status lib_fail(reader *r, const char *call)
{
    return fail(r, CM_ERR_FORMAT, "%s failed: %s", call, cg_get_error());
}

/* The tag of group (dim, name), created on first use. */
static cm_status group_tag(reader *r, int dim, const char *name, int *tag)
{
    for (size_t g = 0; g < r->m->n_groups; ++g)
        if (r->m->groups[g].dim == dim && strcmp(r->m->groups[g].name, name) == 0) {
            *tag = r->m->groups[g].tag;
            return CM_OK;
        }
    *tag = ++r->next_tag;
    return cm_mesh_add_group(r->ctx, r->m, dim, *tag, name);
}

/* ---- coordinates and the merging of zones' vertices ---- */

/* Vertices are compared at the precision both zones store: the hash is of the coordinates
 * rounded to float, so that a RealSingle zone meets a RealDouble one at their interface (and
 * still does after a motion written back in each zone's precision). */
static uint64_t hash_xyz(const double *p)
{
    uint64_t h = 1469598103934665603ull;
    for (int k = 0; k < 3; ++k) {
        float v = (float)p[k];
        uint32_t w;
        if (v == 0) v = 0; /* -0 and +0 are one point */
        memcpy(&w, &v, sizeof w);
        h = (h ^ w) * 1099511628211ull;
        h ^= h >> 29;
    }
    return h;
}

static int same_xyz(const double *a, const double *b, int single)
{
    if (single) return (float)a[0] == (float)b[0] && (float)a[1] == (float)b[1] && (float)a[2] == (float)b[2];
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

static cm_status read_coordinates(reader *r, int B, int Z, cm_cgns_zone *zn, double **xyz)
{
    int nc = 0;
    if (cg_ncoords(r->fn, B, Z, &nc)) return lib_fail(r, "cg_ncoords");
    snprintf(r->where, sizeof r->where, "%s/GridCoordinates", zn->path);
    int have[3] = {0, 0, 0};
    for (int c = 1; c <= nc; ++c) {
        char name[33] = "";
        CGNS_ENUMT(DataType_t) dt;
        if (cg_coord_info(r->fn, B, Z, c, &dt, name)) return lib_fail(r, "cg_coord_info");
        int k = strcmp(name, "CoordinateX") == 0 ? 0 : strcmp(name, "CoordinateY") == 0 ? 1
              : strcmp(name, "CoordinateZ") == 0 ? 2 : -1;
        if (k < 0)
            return fail(r, CM_ERR_UNSUPPORTED, "coordinate %s: only Cartesian CoordinateX/Y/Z are read", name);
        if (dt != CGNS_ENUMV(RealSingle) && dt != CGNS_ENUMV(RealDouble))
            return fail(r, CM_ERR_FORMAT, "%s: expected RealSingle or RealDouble data", name);
        have[k] = 1;
        zn->single[k] = dt == CGNS_ENUMV(RealSingle);
    }
    if (!have[0] || !have[1]) return fail(r, CM_ERR_FORMAT, "expected CoordinateX and CoordinateY");
    zn->n_coords = have[2] ? 3 : 2;
    const size_t n = (size_t)zn->n_vertices;
    double *p = n ? malloc(n * 3 * sizeof *p) : NULL, *c = n ? malloc(n * sizeof *c) : NULL;
    if (n && (!p || !c)) {
        free(p);
        free(c);
        return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for %zu vertices", r->path, n);
    }
    static const char *names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (int k = 0; k < 3; ++k) {
        cgsize_t lo = 1, hi = (cgsize_t)n;
        if (!have[k] || !n) {
            for (size_t i = 0; i < n; ++i) p[3 * i + k] = 0;
            continue;
        }
        if (cg_coord_read(r->fn, B, Z, names[k], CGNS_ENUMV(RealDouble), &lo, &hi, c)) {
            free(p);
            free(c);
            return lib_fail(r, "cg_coord_read");
        }
        for (size_t i = 0; i < n; ++i) p[3 * i + k] = c[i];
    }
    free(c);
    *xyz = p;
    return CM_OK;
}

/* Appends every zone's vertices to the mesh, merging a vertex into an earlier zone's node at
 * the same point. */
static cm_status merge_vertices(reader *r, double **xyz)
{
    size_t total = 0;
    for (size_t z = 0; z < r->st->n_zones; ++z) total += (size_t)r->st->zones[z].n_vertices;
    size_t cap = 16;
    while (r->st->n_zones > 1 && cap < 2 * total) cap *= 2;
    int64_t *table = r->st->n_zones > 1 ? malloc(cap * sizeof *table) : NULL;
    if (r->st->n_zones > 1 && !table) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
    for (size_t i = 0; table && i < cap; ++i) table[i] = -1;
    /* the zone of each node, for the precision of a comparison */
    int *zone_of = table ? malloc((total + 1) * sizeof *zone_of) : NULL;
    if (table && !zone_of) {
        free(table);
        return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
    }
    cm_status s = cm_mesh_resize_nodes(r->ctx, r->m, total, 0);
    size_t n = 0;
    for (size_t z = 0; s == CM_OK && z < r->st->n_zones; ++z) {
        cm_cgns_zone *zn = &r->st->zones[z];
        const size_t first = n;
        const int single = zn->single[0] || zn->single[1] || zn->single[2];
        zn->node = malloc(((size_t)zn->n_vertices + 1) * sizeof *zn->node);
        if (!zn->node) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
            break;
        }
        for (size_t i = 0; i < (size_t)zn->n_vertices; ++i) {
            const double *p = xyz[z] + 3 * i;
            int64_t found = -1;
            size_t h = table ? (size_t)hash_xyz(p) & (cap - 1) : 0;
            if (table)
                for (; table[h] >= 0; h = (h + 1) & (cap - 1))
                    if ((size_t)table[h] < first) {
                        const cm_cgns_zone *o = &r->st->zones[zone_of[table[h]]];
                        if (!same_xyz(r->m->xyz + 3 * table[h], p, single || o->single[0] || o->single[1] || o->single[2]))
                            continue;
                        found = table[h];
                        break;
                    }
            if (found >= 0) {
                zn->node[i] = found;
                continue;
            }
            memcpy(r->m->xyz + 3 * n, p, 3 * sizeof *p);
            zn->node[i] = (int64_t)n;
            if (table) {
                zone_of[n] = (int)z;
                /* a vertex of this zone at a point already in the table is not entered twice */
                while (table[h] >= 0) h = (h + 1) & (cap - 1);
                table[h] = (int64_t)n;
            }
            ++n;
        }
    }
    free(table);
    free(zone_of);
    if (s == CM_OK) s = cm_mesh_resize_nodes(r->ctx, r->m, n, 0);
    return s;
}

/* ---- elements ---- */

/* CGNS element type -> cadmorph type, and the CGNS node of each VTK-ordered node (NULL: the
 * same order). CGNS numbers quadratic hexahedra's and wedges' edges bottom, vertical, top
 * and a hexahedron's face centres bottom, -y, +x, +y, -x, top [CGNS SIDS]; VTK bottom, top,
 * vertical and -x, +x, -y, +y, bottom, top. */
static const int perm_hex20[20] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 16, 17, 18, 19, 12, 13, 14, 15};
static const int perm_hex27[27] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 16, 17, 18, 19, 12, 13,
                                   14, 15, 24, 22, 21, 23, 20, 25, 26};
static const int perm_wedge15[15] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 13, 14, 9, 10, 11};
static const int perm_wedge18[18] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 13, 14, 9, 10, 11, 15, 16, 17};

static cm_cell_type cell_type_of(CGNS_ENUMT(ElementType_t) t, const int **perm)
{
    *perm = NULL;
    switch (t) {
    case CGNS_ENUMV(NODE): return CM_CELL_POINT;
    case CGNS_ENUMV(BAR_2): return CM_CELL_LINE2;
    case CGNS_ENUMV(BAR_3): return CM_CELL_LINE3;
    case CGNS_ENUMV(TRI_3): return CM_CELL_TRI3;
    case CGNS_ENUMV(TRI_6): return CM_CELL_TRI6;
    case CGNS_ENUMV(QUAD_4): return CM_CELL_QUAD4;
    case CGNS_ENUMV(QUAD_8): return CM_CELL_QUAD8;
    case CGNS_ENUMV(QUAD_9): return CM_CELL_QUAD9;
    case CGNS_ENUMV(TETRA_4): return CM_CELL_TET4;
    case CGNS_ENUMV(TETRA_10): return CM_CELL_TET10;
    case CGNS_ENUMV(PYRA_5): return CM_CELL_PYR5;
    case CGNS_ENUMV(PYRA_13): return CM_CELL_PYR13;
    case CGNS_ENUMV(PYRA_14): return CM_CELL_PYR14;
    case CGNS_ENUMV(PENTA_6): return CM_CELL_WEDGE6;
    case CGNS_ENUMV(PENTA_15): *perm = perm_wedge15; return CM_CELL_WEDGE15;
    case CGNS_ENUMV(PENTA_18): *perm = perm_wedge18; return CM_CELL_WEDGE18;
    case CGNS_ENUMV(HEXA_8): return CM_CELL_HEX8;
    case CGNS_ENUMV(HEXA_20): *perm = perm_hex20; return CM_CELL_HEX20;
    case CGNS_ENUMV(HEXA_27): *perm = perm_hex27; return CM_CELL_HEX27;
    default: return CM_CELL_TYPE_COUNT;
    }
}

/* The mesh node of a zone's 1-based vertex index, -1 when out of range. */
static int64_t vertex(const cm_cgns_zone *zn, cgsize_t v)
{
    return v >= 1 && (int64_t)v <= zn->n_vertices ? zn->node[v - 1] : -1;
}

static cm_status add_standard(reader *r, const cm_cgns_zone *zn, CGNS_ENUMT(ElementType_t) t,
                              const cgsize_t *e, size_t n, int tag, cgsize_t number, int64_t *cell)
{
    const int *perm;
    const cm_cell_type ct = cell_type_of(t, &perm);
    if (ct == CM_CELL_TYPE_COUNT)
        return fail(r, CM_ERR_UNSUPPORTED, "element %ld: element type %s is not read", (long)number,
                    (unsigned)t < (unsigned)NofValidElementTypes ? cg_ElementTypeName(t) : "(invalid)");
    int64_t ids[27];
    if (n != (size_t)cm_cell_type_info(ct)->nodes)
        return fail(r, CM_ERR_FORMAT, "element %ld: %zu nodes for %s", (long)number, n, cg_ElementTypeName(t));
    for (size_t j = 0; j < n; ++j) {
        ids[j] = vertex(zn, e[perm ? perm[j] : (int)j]);
        if (ids[j] < 0)
            return fail(r, CM_ERR_FORMAT, "element %ld: vertex %ld out of range 1..%ld", (long)number,
                        (long)e[perm ? perm[j] : (int)j], (long)zn->n_vertices);
    }
    *cell = (int64_t)r->m->n_cells;
    return cm_mesh_add_cell(r->ctx, r->m, ct, ids, n, cm_cell_type_info(ct)->dim == 3 ? tag : 0, 0, 0);
}

static const section *find_element(const section *secs, int ns, cgsize_t number, size_t *index)
{
    for (int s = 0; s < ns; ++s)
        if (number >= secs[s].start && number <= secs[s].end) {
            *index = (size_t)(number - secs[s].start);
            return &secs[s];
        }
    return NULL;
}

/* A polyhedron of NFACE_n element k of sec: its faces from the NGON_n sections, reversed
 * where the index is negative; all reversed if that gives a negative volume (a writer with
 * the opposite convention). */
static cm_status add_polyhedron(reader *r, const cm_cgns_zone *zn, const section *secs, int ns,
                                const section *sec, size_t k, int tag, int64_t **buf, size_t *cap)
{
    const cgsize_t *f = sec->data + sec->offsets[k];
    const size_t nf = (size_t)(sec->offsets[k + 1] - sec->offsets[k]);
    const long number = (long)(sec->start + (cgsize_t)k);
    size_t len = 1;
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1) {
            if (len > *cap) {
                int64_t *nb = realloc(*buf, len * sizeof *nb);
                if (!nb) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
                *buf = nb;
                *cap = len;
            }
            (*buf)[0] = (int64_t)nf;
            len = 1;
        }
        for (size_t i = 0; i < nf; ++i) {
            const cgsize_t fi = f[i] < 0 ? -f[i] : f[i];
            size_t j;
            const section *g = f[i] == 0 ? NULL : find_element(secs, ns, fi, &j);
            if (!g || g->type != CGNS_ENUMV(NGON_n))
                return fail(r, CM_ERR_FORMAT, "NFACE_n element %ld: face %ld is not an NGON_n element", number, (long)f[i]);
            const cgsize_t *v = g->data + g->offsets[j];
            const size_t nv = (size_t)(g->offsets[j + 1] - g->offsets[j]);
            if (pass == 0) {
                len += 1 + nv;
                continue;
            }
            (*buf)[len++] = (int64_t)nv;
            for (size_t a = 0; a < nv; ++a) {
                const cgsize_t id = v[f[i] > 0 ? a : nv - 1 - a];
                const int64_t node = vertex(zn, id);
                if (node < 0)
                    return fail(r, CM_ERR_FORMAT, "NGON_n element %ld: vertex %ld out of range", (long)fi, (long)id);
                (*buf)[len++] = node;
            }
        }
    }
    /* signed volume by the divergence theorem over fan triangles from each face's first node */
    double vol = 0;
    const double *x = r->m->xyz;
    for (cm_polyhedron_face pf = cm_polyhedron_begin(*buf, (int64_t)len); cm_polyhedron_more(&pf); cm_polyhedron_next(&pf))
        for (int64_t a = 1; a + 1 < pf.n; ++a) {
            const double *p = x + 3 * pf.nodes[0], *q = x + 3 * pf.nodes[a], *s = x + 3 * pf.nodes[a + 1];
            vol += p[0] * (q[1] * s[2] - q[2] * s[1]) - p[1] * (q[0] * s[2] - q[2] * s[0]) + p[2] * (q[0] * s[1] - q[1] * s[0]);
        }
    if (vol < 0)
        for (cm_polyhedron_face pf = cm_polyhedron_begin(*buf, (int64_t)len); cm_polyhedron_more(&pf); cm_polyhedron_next(&pf))
            for (int64_t a = 0, b = pf.n - 1; a < b; ++a, --b) {
                int64_t *w = (int64_t *)pf.nodes, t = w[a];
                w[a] = w[b];
                w[b] = t;
            }
    return cm_mesh_add_cell(r->ctx, r->m, CM_CELL_POLYHEDRON, *buf, len, tag, 0, 0);
}

/* A face of an NGON_n section as a 2-D cell (for a BC that names it). */
static cm_status add_ngon_face(reader *r, const cm_cgns_zone *zn, section *g, size_t j)
{
    const cgsize_t *v = g->data + g->offsets[j];
    const size_t nv = (size_t)(g->offsets[j + 1] - g->offsets[j]);
    int64_t small[4], *ids = nv <= 4 ? small : malloc(nv * sizeof *ids);
    if (!ids) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
    cm_status s = CM_OK;
    for (size_t a = 0; s == CM_OK && a < nv; ++a) {
        ids[a] = vertex(zn, v[a]);
        if (ids[a] < 0) s = fail(r, CM_ERR_FORMAT, "NGON_n element %ld: vertex %ld out of range", (long)(g->start + (cgsize_t)j), (long)v[a]);
    }
    if (s == CM_OK && nv < 3) s = fail(r, CM_ERR_FORMAT, "NGON_n element %ld: %zu vertices", (long)(g->start + (cgsize_t)j), nv);
    const cm_cell_type t = nv == 3 ? CM_CELL_TRI3 : nv == 4 ? CM_CELL_QUAD4 : CM_CELL_POLYGON;
    if (s == CM_OK) {
        g->cell[j] = (int64_t)r->m->n_cells;
        s = cm_mesh_add_cell(r->ctx, r->m, t, ids, nv, 0, 0, 0);
    }
    if (ids != small) free(ids);
    return s;
}

static cm_status read_section(reader *r, int B, int Z, int S, section *sec, size_t n_zone_cells)
{
    int nbndry = 0, parent = 0;
    if (cg_section_read(r->fn, B, Z, S, sec->name, &sec->type, &sec->start, &sec->end, &nbndry, &parent))
        return lib_fail(r, "cg_section_read");
    if (sec->start < 1 || sec->end < sec->start)
        return fail(r, CM_ERR_FORMAT, "section %s: element range %ld..%ld", sec->name, (long)sec->start, (long)sec->end);
    const size_t n = (size_t)(sec->end - sec->start) + 1;
    (void)n_zone_cells;
    cgsize_t size = 0;
    if (cg_ElementDataSize(r->fn, B, Z, S, &size)) return lib_fail(r, "cg_ElementDataSize");
    if (size < 0) return fail(r, CM_ERR_FORMAT, "section %s: connectivity size %ld", sec->name, (long)size);
    const int poly = sec->type == CGNS_ENUMV(MIXED) || sec->type == CGNS_ENUMV(NGON_n) || sec->type == CGNS_ENUMV(NFACE_n);
    if (!poly) {
        int npe = 0;
        const int *perm;
        if (cell_type_of(sec->type, &perm) == CM_CELL_TYPE_COUNT || cg_npe(sec->type, &npe) || npe <= 0)
            return fail(r, CM_ERR_UNSUPPORTED, "section %s: element type %s is not read", sec->name,
                        (unsigned)sec->type < (unsigned)NofValidElementTypes ? cg_ElementTypeName(sec->type) : "(invalid)");
        if ((size_t)size / (size_t)npe != n || (size_t)size % (size_t)npe)
            return fail(r, CM_ERR_FORMAT, "section %s: %ld connectivity entries for %zu elements of %d nodes",
                        sec->name, (long)size, n, npe);
    }
    sec->data = malloc(((size_t)size + 1) * sizeof *sec->data);
    sec->offsets = poly ? malloc((n + 1) * sizeof *sec->offsets) : NULL;
    sec->cell = malloc(n * sizeof *sec->cell);
    if (!sec->data || (poly && !sec->offsets) || !sec->cell)
        return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for section %s", r->path, sec->name);
    for (size_t i = 0; i < n; ++i) sec->cell[i] = -1;
    if (poly ? cg_poly_elements_read(r->fn, B, Z, S, sec->data, sec->offsets, NULL)
             : cg_elements_read(r->fn, B, Z, S, sec->data, NULL))
        return lib_fail(r, "reading the elements");
    if (poly) {
        if (sec->offsets[0] != 0 || sec->offsets[n] != size)
            return fail(r, CM_ERR_FORMAT, "section %s: ElementStartOffset does not span the connectivity", sec->name);
        for (size_t i = 0; i < n; ++i)
            if (sec->offsets[i + 1] < sec->offsets[i])
                return fail(r, CM_ERR_FORMAT, "section %s: ElementStartOffset decreases at element %zu", sec->name, i + 1);
    }
    return CM_OK;
}

/* The cells of one section other than NGON_n faces (added for BCs) and NFACE_n (after). */
static cm_status add_section_cells(reader *r, const cm_cgns_zone *zn, section *sec, int tag)
{
    const size_t n = (size_t)(sec->end - sec->start) + 1;
    if (sec->type == CGNS_ENUMV(NGON_n) || sec->type == CGNS_ENUMV(NFACE_n)) return CM_OK;
    int npe = 0;
    if (sec->type != CGNS_ENUMV(MIXED)) cg_npe(sec->type, &npe);
    for (size_t i = 0; i < n; ++i) {
        const cgsize_t number = sec->start + (cgsize_t)i;
        cm_status s;
        if (sec->type == CGNS_ENUMV(MIXED)) {
            const cgsize_t *e = sec->data + sec->offsets[i];
            const size_t len = (size_t)(sec->offsets[i + 1] - sec->offsets[i]);
            if (len < 1) return fail(r, CM_ERR_FORMAT, "section %s: empty MIXED element %ld", sec->name, (long)number);
            s = add_standard(r, zn, (CGNS_ENUMT(ElementType_t))e[0], e + 1, len - 1, tag, number, &sec->cell[i]);
        } else {
            s = add_standard(r, zn, sec->type, sec->data + i * (size_t)npe, (size_t)npe, tag, number, &sec->cell[i]);
        }
        if (s != CM_OK) return s;
    }
    return CM_OK;
}

/* ---- boundary conditions ---- */

/* Gives cell c group tag: its physical tag if it has none, else a copy of the cell. */
static cm_status tag_cell(reader *r, int64_t c, int tag)
{
    cm_mesh *m = r->m;
    if (m->physical[c] == 0 || m->physical[c] == tag) {
        m->physical[c] = tag;
        return CM_OK;
    }
    const size_t len = (size_t)(m->offset[c + 1] - m->offset[c]);
    int64_t *ids = malloc((len + 1) * sizeof *ids);
    if (!ids) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
    memcpy(ids, m->conn + m->offset[c], len * sizeof *ids);
    cm_status s = cm_mesh_add_cell(r->ctx, m, (cm_cell_type)m->type[c], ids, len, tag, 0, 0);
    free(ids);
    return s;
}

/* The motion rule a boundary condition's type implies (docs/DESIGN.md, "Boundary motion by
 * patch kind"): a symmetry plane slides. */
static void set_kind(cm_mesh *m, int tag, cm_patch_kind kind)
{
    for (size_t g = 0; g < m->n_groups; ++g)
        if (m->groups[g].tag == tag) m->groups[g].kind = kind;
}

static cm_status read_bcs(reader *r, int B, int Z, const cm_cgns_zone *zn, section *secs, int ns)
{
    int nb = 0;
    if (cg_nbocos(r->fn, B, Z, &nb)) return lib_fail(r, "cg_nbocos");
    for (int b = 1; b <= nb; ++b) {
        char name[33] = "", fam[33] = "";
        CGNS_ENUMT(BCType_t) bct;
        CGNS_ENUMT(PointSetType_t) pst;
        CGNS_ENUMT(GridLocation_t) loc = CGNS_ENUMV(Vertex);
        cgsize_t np = 0, nlist = 0;
        int normal[3], nds = 0;
        CGNS_ENUMT(DataType_t) ndt;
        snprintf(r->where, sizeof r->where, "%s/ZoneBC", zn->path);
        if (cg_boco_info(r->fn, B, Z, b, name, &bct, &pst, &np, normal, &nlist, &ndt, &nds)) return lib_fail(r, "cg_boco_info");
        snprintf(r->where, sizeof r->where, "%s/ZoneBC/%s", zn->path, name);
        if (cg_boco_gridlocation_read(r->fn, B, Z, b, &loc)) return lib_fail(r, "cg_boco_gridlocation_read");
        if (cg_goto(r->fn, B, "Zone_t", Z, "ZoneBC_t", 1, "BC_t", b, NULL) == CG_OK && cg_famname_read(fam) != CG_OK)
            fam[0] = '\0';
        const int range = pst == CGNS_ENUMV(PointRange) || pst == CGNS_ENUMV(ElementRange);
        const int list = pst == CGNS_ENUMV(PointList) || pst == CGNS_ENUMV(ElementList);
        if (!range && !list) return fail(r, CM_ERR_UNSUPPORTED, "point set type %s is not read", cg_PointSetTypeName(pst));
        if (np < 0 || (range && np != 2)) return fail(r, CM_ERR_FORMAT, "%ld points in a %s", (long)np, cg_PointSetTypeName(pst));
        cgsize_t *p = malloc(((size_t)np + 1) * sizeof *p);
        if (!p) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
        cm_status s = CM_OK;
        if (cg_boco_read(r->fn, B, Z, b, p, NULL)) s = lib_fail(r, "cg_boco_read");
        const int elements = pst == CGNS_ENUMV(ElementRange) || pst == CGNS_ENUMV(ElementList) || loc != CGNS_ENUMV(Vertex);
        int tag = 0;
        if (s == CM_OK) s = group_tag(r, elements ? 2 : 0, fam[0] ? fam : name, &tag);
        if (s == CM_OK && bct == CGNS_ENUMV(BCSymmetryPlane)) set_kind(r->m, tag, CM_PATCH_SYMMETRY);
        if (s == CM_OK && range && p[1] < p[0]) s = fail(r, CM_ERR_FORMAT, "range %ld..%ld", (long)p[0], (long)p[1]);
        const size_t count = s != CM_OK ? 0 : range ? (size_t)(p[1] - p[0]) + 1 : (size_t)np;
        for (size_t i = 0; s == CM_OK && i < count; ++i) {
            const cgsize_t id = range ? p[0] + (cgsize_t)i : p[i];
            if (!elements) {
                int64_t node = vertex(zn, id);
                if (node < 0) s = fail(r, CM_ERR_FORMAT, "vertex %ld out of range 1..%ld", (long)id, (long)zn->n_vertices);
                else s = cm_mesh_add_cell(r->ctx, r->m, CM_CELL_POINT, &node, 1, tag, 0, 0);
                continue;
            }
            size_t j;
            section *g = (section *)find_element(secs, ns, id, &j);
            if (!g) {
                s = fail(r, CM_ERR_FORMAT, "element %ld is in no section", (long)id);
                break;
            }
            if (g->type == CGNS_ENUMV(NGON_n) && g->cell[j] < 0) s = add_ngon_face(r, zn, g, j);
            /* volume cells keep their zone's group */
            if (s == CM_OK && g->cell[j] >= 0 && cm_cell_type_info((cm_cell_type)r->m->type[g->cell[j]])->dim < 3)
                s = tag_cell(r, g->cell[j], tag);
        }
        free(p);
        if (s != CM_OK) return s;
    }
    return CM_OK;
}

static void free_sections(section *secs, int ns)
{
    for (int s = 0; secs && s < ns; ++s) {
        free(secs[s].data);
        free(secs[s].offsets);
        free(secs[s].cell);
    }
    free(secs);
}

/* The elements and BCs of zone z (coordinates merged already). */
static cm_status read_zone_cells(reader *r, int B, int Z, const cm_cgns_zone *zn, const char *zone_name)
{
    int ns = 0, tag = 0;
    snprintf(r->where, sizeof r->where, "%s", zn->path);
    if (cg_nsections(r->fn, B, Z, &ns)) return lib_fail(r, "cg_nsections");
    if (ns < 0) return fail(r, CM_ERR_FORMAT, "%d sections", ns);
    cm_status s = group_tag(r, 3, zone_name, &tag);
    section *secs = calloc((size_t)ns + 1, sizeof *secs);
    if (!secs) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
    for (int S = 1; s == CM_OK && S <= ns; ++S) {
        snprintf(r->where, sizeof r->where, "%s", zn->path);
        s = read_section(r, B, Z, S, &secs[S - 1], 0);
        if (s == CM_OK) snprintf(r->where, sizeof r->where, "%s/%s", zn->path, secs[S - 1].name);
        if (s == CM_OK) s = add_section_cells(r, zn, &secs[S - 1], tag);
    }
    /* overlapping element ranges would make BC element numbers ambiguous */
    for (int a = 0; s == CM_OK && a < ns; ++a)
        for (int b = a + 1; s == CM_OK && b < ns; ++b)
            if (secs[a].start <= secs[b].end && secs[b].start <= secs[a].end)
                s = fail(r, CM_ERR_FORMAT, "sections %s and %s: element ranges overlap", secs[a].name, secs[b].name);
    int64_t *buf = NULL;
    size_t cap = 0;
    for (int S = 0; s == CM_OK && S < ns; ++S) {
        section *sec = &secs[S];
        if (sec->type != CGNS_ENUMV(NFACE_n)) continue;
        snprintf(r->where, sizeof r->where, "%s/%s", zn->path, sec->name);
        for (size_t k = 0; s == CM_OK && k <= (size_t)(sec->end - sec->start); ++k) {
            sec->cell[k] = (int64_t)r->m->n_cells;
            s = add_polyhedron(r, zn, secs, ns, sec, k, tag, &buf, &cap);
        }
    }
    free(buf);
    if (s == CM_OK) s = read_bcs(r, B, Z, zn, secs, ns);
    /* lower-dimensional cells that no BC names: their section's name */
    for (int S = 0; s == CM_OK && S < ns; ++S) {
        const section *sec = &secs[S];
        for (size_t k = 0; s == CM_OK && k <= (size_t)(sec->end - sec->start); ++k) {
            const int64_t c = sec->cell[k];
            if (c < 0 || r->m->physical[c]) continue;
            const int dim = cm_cell_type_info((cm_cell_type)r->m->type[c])->dim;
            int t = 0;
            if (dim < 3) s = group_tag(r, dim, sec->name, &t);
            if (s == CM_OK) r->m->physical[c] = t;
        }
    }
    free_sections(secs, ns);
    return s;
}

static cm_status read_file(reader *r)
{
    int nbases = 0;
    if (cg_nbases(r->fn, &nbases)) return lib_fail(r, "cg_nbases");
    if (nbases < 1) return fail(r, CM_ERR_FORMAT, "no CGNSBase_t node");
    /* the zones first, for their count */
    size_t nz = 0;
    for (int B = 1; B <= nbases; ++B) {
        int n = 0;
        if (cg_nzones(r->fn, B, &n)) return lib_fail(r, "cg_nzones");
        if (n < 0) return fail(r, CM_ERR_FORMAT, "%d zones", n);
        nz += (size_t)n;
    }
    if (!nz) return fail(r, CM_ERR_FORMAT, "no Zone_t node");
    r->st->zones = calloc(nz, sizeof *r->st->zones);
    double **xyz = calloc(nz, sizeof *xyz);
    int (*bz)[2] = calloc(nz, sizeof *bz);
    char (*zname)[33] = calloc(nz, sizeof *zname);
    cm_status s = r->st->zones && xyz && bz && zname ? CM_OK
                : cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
    for (int B = 1; s == CM_OK && B <= nbases; ++B) {
        char bname[33] = "";
        int cdim = 0, pdim = 0, n = 0;
        if (cg_base_read(r->fn, B, bname, &cdim, &pdim) || cg_nzones(r->fn, B, &n)) {
            s = lib_fail(r, "cg_base_read");
            break;
        }
        for (int Z = 1; s == CM_OK && Z <= n; ++Z) {
            cm_cgns_zone *zn = &r->st->zones[r->st->n_zones];
            cgsize_t size[9] = {0};
            CGNS_ENUMT(ZoneType_t) zt;
            snprintf(r->where, sizeof r->where, "/%s", bname);
            if (cg_zone_type(r->fn, B, Z, &zt) || cg_zone_read(r->fn, B, Z, zname[r->st->n_zones], size)) {
                s = lib_fail(r, "cg_zone_read");
                break;
            }
            snprintf(zn->path, sizeof zn->path, "/%s/%s", bname, zname[r->st->n_zones]);
            snprintf(r->where, sizeof r->where, "%s", zn->path);
            if (zt != CGNS_ENUMV(Unstructured)) {
                s = fail(r, CM_ERR_UNSUPPORTED, "structured zones are not read (cadmorph reads unstructured "
                         "zones only; convert the zone to unstructured hexahedra first)");
                break;
            }
            if (size[0] < 0) {
                s = fail(r, CM_ERR_FORMAT, "%ld vertices", (long)size[0]);
                break;
            }
            zn->n_vertices = size[0];
            bz[r->st->n_zones][0] = B;
            bz[r->st->n_zones][1] = Z;
            s = read_coordinates(r, B, Z, zn, &xyz[r->st->n_zones]);
            ++r->st->n_zones;
        }
    }
    if (s == CM_OK) s = merge_vertices(r, xyz);
    for (size_t z = 0; xyz && z < nz; ++z) free(xyz[z]);
    free(xyz);
    for (size_t z = 0; s == CM_OK && z < r->st->n_zones; ++z)
        s = read_zone_cells(r, bz[z][0], bz[z][1], &r->st->zones[z], zname[z]);
    free(bz);
    free(zname);
    return s;
}

cm_status cm_mesh_read_cgns(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read_cgns: NULL argument");
    *mesh = NULL;
    /* the input rule (core.h): a FIFO or a directory is refused here, before the CGNS
     * library opens (and blocks on) it */
    FILE *f = NULL;
    cm_status s0 = cm_file_open_read(ctx, path, &f);
    if (s0 != CM_OK) return cm_error_prefix(ctx, s0, "cm_mesh_read");
    fclose(f);
    if (!cm_cgns_magic_ok(path))
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: /: not a CGNS file (neither HDF5 nor ADF)", path);
    reader r = {.ctx = ctx, .path = path, .fn = -1};
    cm_status s = cm_mesh_create(ctx, &r.m);
    if (s != CM_OK) return s;
    r.st = calloc(1, sizeof *r.st);
    if (r.st) r.st->path = strdup(path);
    if (!r.st || !r.st->path) {
        cm_cgns_state_free(r.st);
        cm_mesh_destroy(&r.m);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", path);
    }
    /* the stamp before the read: a file changed while it is read is not written back either */
    s = cm_file_stamp_take(ctx, path, &r.st->stamp);
    if (s != CM_OK) {
        cm_cgns_state_free(r.st);
        cm_mesh_destroy(&r.m);
        return s;
    }
    cm_cgns_lock();
    if (cg_open(path, CG_MODE_READ, &r.fn) != CG_OK) {
        char why[256];
        snprintf(why, sizeof why, "%s", cg_get_error());
        for (char *c = why; *c; ++c) *c = (unsigned char)*c < 0x20 || (unsigned char)*c >= 0x7f ? '?' : *c;
        s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: /: not a CGNS file the CGNS library opens: %s", path, why);
        r.fn = -1;
    } else {
        s = read_file(&r);
        cg_close(r.fn);
    }
    cm_cgns_unlock();
    if (s == CM_OK) {
        s = cm_mesh_set_origin(ctx, r.m, CM_FORMAT_CGNS, r.st, cm_cgns_state_free);
        r.st = NULL;
    }
    cm_cgns_state_free(r.st);
    if (s != CM_OK) {
        cm_mesh_destroy(&r.m);
        return s;
    }
    *mesh = r.m;
    return CM_OK;
}
