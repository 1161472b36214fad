/* SU2 native mesh (.su2, ASCII) reader; the writers are in su2_write.c.
 *
 * The file is a list of "KEYWORD= value" lines, each followed by its data lines:
 *   NDIME= 2|3                   the dimension (first in every zone)
 *   NELEM= n                     n lines "type n0 n1 ... [index]": the cells of dimension NDIME
 *   NPOIN= n [m]                 n lines "x y [z] [index [index]]" (m: the domain points of a
 *                                partitioned file; every point is read)
 *   NMARK= k                     k markers, each "MARKER_TAG= name", "MARKER_ELEMS= n" and n
 *                                lines "type n0 n1 ...": boundary cells (dimension NDIME - 1)
 *   NZONE= z, IZONE= i           a multi-zone file: each IZONE= starts a zone of the sections
 *                                above, with its own point numbering
 * Element types are VTK's ids (3 line, 5 triangle, 9 quadrilateral, 10 tetrahedron,
 * 12 hexahedron, 13 prism, 14 pyramid) in VTK's node order: gmsh writes the same connectivity
 * to .su2 and .vtk (tests/mesh/su2_crosscheck.py), and meshio reads both with one table.
 * Indices are 0-based. Lines whose first character that is not a blank is '%' are comments;
 * keywords are matched ignoring case and blanks around '=' (SU2 and gmsh write "NPOIN= 12",
 * meshio the same). A keyword this reader does not know (SU2's FFD_* box definitions that
 * SU2_DEF appends, an old NPERIODIC block) is skipped with the lines after it, up to the next
 * keyword it knows.
 *
 * What it becomes: a 2-D file (NDIME= 2) is a mesh in the plane z = 0 with its triangles and
 * quadrilaterals as cells and its markers as lines; a 3-D file has volume cells and marker
 * faces. Each marker is a physical group (dimension NDIME - 1, named by MARKER_TAG, the same
 * group for the same name in every zone), so `deform` and constraints use it by name. The
 * zones of a multi-zone file are one mesh, their nodes numbered on in file order; each zone's
 * cells are the group "zone_<i>" (a single-zone file's cells have no group).
 *
 * The origin (rewrite.h) keeps where every point's coordinates are, so a mesh written back
 * into .su2 changes only those numbers (su2_write.c). */
#define _POSIX_C_SOURCE 200809L
#include "formats.h"
#include "rewrite.h"
#include "text.h"
#include "su2_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int cm_su2_cell(int64_t id, cm_cell_type *type)
{
    switch (id) {
    case 3: *type = CM_CELL_LINE2; return 2;
    case 5: *type = CM_CELL_TRI3; return 3;
    case 9: *type = CM_CELL_QUAD4; return 4;
    case 10: *type = CM_CELL_TET4; return 4;
    case 12: *type = CM_CELL_HEX8; return 8;
    case 13: *type = CM_CELL_WEDGE6; return 6;
    case 14: *type = CM_CELL_PYR5; return 5;
    default: return 0;
    }
}

typedef struct su2_reader {
    cm_context *ctx;
    const char *path;
    const char *data;
    size_t size;
    size_t pos; /* start of the next line */
    long next;  /* its number */
    /* the current line: its text without blanks at either end, and its number */
    const char *b, *e;
    long line;
    cm_mesh *m;
    cm_rewrite_source *src;
    int next_tag; /* physical tags of the groups: one counter for markers and zones */
    int zones;    /* zones begun (IZONE= lines; 1 for a file without them) */
    /* the zone being read */
    int dim;             /* NDIME (0 before it) */
    size_t base;         /* nodes of the zones before */
    int64_t npoin;       /* -1 before NPOIN= */
    long npoin_line;
    int have_elem, have_mark;
    int zone_tag;        /* the physical tag of its cells, 0 in a single-zone file */
    int64_t max_id;      /* the largest node index of its cells, and its line */
    long max_line;
} su2_reader;

static cm_status fail(su2_reader *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static cm_status fail(su2_reader *r, const char *fmt, ...)
{
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s:%ld: %s", r->path, r->line, what);
}

/* The current line shown in a message: at most 40 bytes, no control characters. */
static const char *shown(const su2_reader *r, char buf[48])
{
    size_t n = (size_t)(r->e - r->b), k = 0;
    for (size_t i = 0; i < n && k < 40; ++i) buf[k++] = isprint((unsigned char)r->b[i]) ? r->b[i] : '?';
    if (n > 40) {
        buf[k - 3] = buf[k - 2] = buf[k - 1] = '.';
    }
    buf[k] = '\0';
    return buf;
}

static int blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

/* The next line that is neither blank nor a comment; 0 at the end of the file. */
static int next_line(su2_reader *r)
{
    while (r->pos < r->size) {
        const char *p = r->data + r->pos, *end = r->data + r->size;
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const char *le = nl ? nl : end;
        r->line = r->next++;
        r->pos = (size_t)(le - r->data) + (nl ? 1 : 0);
        while (p < le && blank(*p)) ++p;
        while (le > p && blank(le[-1])) --le;
        if (p == le || *p == '%') continue;
        r->b = p;
        r->e = le;
        return 1;
    }
    r->b = r->e = r->data + r->size;
    r->line = r->next;
    return 0;
}

/* The current line as "KEY= value": KEY upper-cased into key (letters, digits, '_'), *value
 * after the '='. 0 when the line is not of that form. */
static int keyword(const su2_reader *r, char *key, size_t cap, const char **value)
{
    const char *p = r->b;
    size_t n = 0;
    while (p < r->e && (isalnum((unsigned char)*p) || *p == '_')) {
        if (n + 1 < cap) key[n++] = (char)toupper((unsigned char)*p);
        ++p;
    }
    key[n] = '\0';
    if (p == r->b || !isalpha((unsigned char)*r->b)) return 0;
    while (p < r->e && blank(*p)) ++p;
    if (p == r->e || *p != '=') return 0;
    *value = p + 1;
    return 1;
}

/* The next blank-separated token of [*p, e): [*tb, *te). 0 when none is left. */
static int token(const char **p, const char *e, const char **tb, const char **te)
{
    const char *q = *p;
    while (q < e && blank(*q)) ++q;
    if (q == e) return 0;
    *tb = q;
    while (q < e && !blank(*q)) ++q;
    *te = q;
    *p = q;
    return 1;
}

/* A finite number filling [b, e) exactly (the data is NUL-terminated: cm_file_read). */
static int parse_real(const char *b, const char *e, double *v)
{
    char *end = NULL;
    if (!(isdigit((unsigned char)*b) || *b == '-' || *b == '+' || *b == '.')) return 0;
    *v = strtod(b, &end);
    return end == e && isfinite(*v);
}

static cm_status expected_token(su2_reader *r, const char *what, const char *tb, const char *te)
{
    if (!tb) return fail(r, "expected %s, got the end of the line", what);
    char got[44];
    size_t n = 0;
    for (; tb + n < te && n < 40; ++n) got[n] = isprint((unsigned char)tb[n]) ? tb[n] : '?';
    got[n] = '\0';
    return fail(r, "expected %s, got '%s'", what, got);
}

/* The count after a keyword (the first token of value; *rest after it), no larger than the
 * items the rest of the file can hold at min_bytes each (0: a number, not a count): a huge
 * count is refused before anything is allocated for it. */
static cm_status read_count(su2_reader *r, const char *value, const char *key, size_t min_bytes,
                            int64_t *n, const char **rest)
{
    const char *p = value, *tb = NULL, *te = NULL;
    char what[64];
    snprintf(what, sizeof what, "a count after %s=", key);
    if (!token(&p, r->e, &tb, &te) || !cm_text_parse_int(tb, te, n) || *n < 0) return expected_token(r, what, tb, te);
    if (min_bytes && (uint64_t)*n > (r->size - r->pos) / min_bytes + 1)
        return fail(r, "expected at most %llu %s after %s= in the rest of the file, got %lld (truncated?)",
                    (unsigned long long)((r->size - r->pos) / min_bytes + 1),
                    key[1] == 'P' ? "points" : key[1] == 'M' ? "markers" : key[1] == 'Z' ? "zones" : "elements", key,
                    (long long)*n);
    if (rest) *rest = p;
    else if (token(&p, r->e, &tb, &te)) return expected_token(r, "the end of the line", tb, te);
    return CM_OK;
}

/* Optional trailing integers (the index columns): at most max_extra of them. */
static cm_status trailing(su2_reader *r, const char *p, int max_extra, const char *what)
{
    const char *tb, *te;
    int64_t v;
    for (int k = 0; token(&p, r->e, &tb, &te); ++k)
        if (k >= max_extra || !cm_text_parse_int(tb, te, &v)) return expected_token(r, what, tb, te);
    return CM_OK;
}

/* n point lines of the current zone. */
static cm_status read_points(su2_reader *r, int64_t n)
{
    const size_t base = r->base;
    cm_status s = cm_mesh_resize_nodes(r->ctx, r->m, base + (size_t)n, 0);
    if (s != CM_OK) return s;
    const char *tb = NULL, *te = NULL;
    for (int64_t i = 0; i < n; ++i) {
        if (!next_line(r))
            return fail(r, "expected point %lld of the %lld after NPOIN= (line %ld), got the end of the file",
                        (long long)i, (long long)n, r->npoin_line);
        double *x = r->m->xyz + 3 * (base + (size_t)i);
        x[2] = 0;
        const char *p = r->b, *first = NULL;
        for (int k = 0; k < r->dim; ++k) {
            const int got = token(&p, r->e, &tb, &te);
            if (!got || !parse_real(tb, te, &x[k])) {
                char what[96];
                snprintf(what, sizeof what, "coordinate %c of point %lld (a finite number)", "xyz"[k], (long long)i);
                return expected_token(r, what, got ? tb : NULL, te);
            }
            if (!first) first = tb;
        }
        s = trailing(r, p, 2, "the end of the point line (or its index)");
        if (s == CM_OK)
            s = cm_rewrite_add_span(r->ctx, r->src, 0, first - r->data, te - first, (int64_t)(base + (size_t)i), r->dim);
        if (s != CM_OK) return s;
    }
    return CM_OK;
}

/* n cell lines: the zone's cells (marker 0: dimension NDIME) or a marker's (dimension
 * NDIME - 1, physical tag marker). */
static cm_status read_cells(su2_reader *r, int64_t n, int marker, long key_line)
{
    const int want = marker ? r->dim - 1 : r->dim;
    cm_status s = cm_mesh_reserve_cells(r->ctx, r->m, r->m->n_cells + (size_t)n, (size_t)n * (r->dim == 3 ? 4 : 3));
    for (int64_t i = 0; s == CM_OK && i < n; ++i) {
        if (!next_line(r))
            return fail(r, "expected element %lld of the %lld after line %ld, got the end of the file", (long long)i,
                        (long long)n, key_line);
        const char *p = r->b, *tb = NULL, *te = NULL;
        int64_t id = 0, nodes[8];
        cm_cell_type type = CM_CELL_TYPE_COUNT;
        const int nn = token(&p, r->e, &tb, &te) && cm_text_parse_int(tb, te, &id) ? cm_su2_cell(id, &type) : 0;
        if (!nn) {
            char buf[48];
            return fail(r, "expected an element type (3, 5, 9, 10, 12, 13 or 14), got '%s'", shown(r, buf));
        }
        if (cm_cell_type_info(type)->dim != want)
            return fail(r, "expected a %s element (%s), got type %lld (%s)", marker ? "marker" : "zone",
                        want == 3 ? "10, 12, 13 or 14" : want == 2 ? "5 or 9" : "3", (long long)id,
                        cm_cell_type_info(type)->name);
        for (int k = 0; k < nn; ++k) {
            const int got = token(&p, r->e, &tb, &te);
            if (!got || !cm_text_parse_int(tb, te, &nodes[k]) || nodes[k] < 0 || nodes[k] > INT64_MAX / 2) {
                char what[64];
                snprintf(what, sizeof what, "node %d of a %s (a point index >= 0)", k, cm_cell_type_info(type)->name);
                return expected_token(r, what, got ? tb : NULL, te);
            }
            if (nodes[k] > r->max_id) {
                r->max_id = nodes[k];
                r->max_line = r->line;
            }
            nodes[k] += (int64_t)r->base;
        }
        s = trailing(r, p, 1, "the end of the element line (or its index)");
        /* entities as gmsh would make them (one per marker, one per zone), so that a .msh
         * written from the mesh keeps each marker's group (gmsh 4 files give groups to
         * entities) */
        if (s == CM_OK)
            s = cm_mesh_add_cell(r->ctx, r->m, type, nodes, (size_t)nn, marker ? marker : r->zone_tag,
                                 marker ? marker : r->zones, 0);
    }
    return s;
}

/* The group of a marker name of the given dimension, added when new. */
static cm_status marker_group(su2_reader *r, const char *name, size_t len, int *tag)
{
    char nm[256];
    if (len >= sizeof nm) len = sizeof nm - 1;
    memcpy(nm, name, len);
    nm[len] = '\0';
    for (size_t g = 0; g < r->m->n_groups; ++g)
        if (r->m->groups[g].dim == r->dim - 1 && r->m->groups[g].name && !strcmp(r->m->groups[g].name, nm)) {
            *tag = r->m->groups[g].tag;
            return CM_OK;
        }
    *tag = ++r->next_tag;
    return cm_mesh_add_group(r->ctx, r->m, r->dim - 1, *tag, nm);
}

/* NMARK= k (its count read): the k markers. */
static cm_status read_markers(su2_reader *r, int64_t k)
{
    char key[32], buf[48];
    const char *value = NULL;
    for (int64_t i = 0; i < k; ++i) {
        if (!next_line(r) || !keyword(r, key, sizeof key, &value) || strcmp(key, "MARKER_TAG"))
            return fail(r, "expected MARKER_TAG= of marker %lld of the %lld after NMARK=, got %s%s%s", (long long)i,
                        (long long)k, r->b < r->e ? "'" : "", r->b < r->e ? shown(r, buf) : "the end of the file",
                        r->b < r->e ? "'" : "");
        while (value < r->e && blank(*value)) ++value;
        if (value == r->e) return fail(r, "expected a marker name after MARKER_TAG=");
        int tag = 0;
        cm_status s = marker_group(r, value, (size_t)(r->e - value), &tag);
        if (s != CM_OK) return s;
        if (!next_line(r) || !keyword(r, key, sizeof key, &value) || strcmp(key, "MARKER_ELEMS"))
            return fail(r, "expected MARKER_ELEMS= after MARKER_TAG=, got %s%s%s", r->b < r->e ? "'" : "",
                        r->b < r->e ? shown(r, buf) : "the end of the file", r->b < r->e ? "'" : "");
        int64_t n = 0;
        const long at = r->line;
        s = read_count(r, value, "MARKER_ELEMS", 6, &n, NULL);
        if (s == CM_OK) s = read_cells(r, n, tag, at);
        if (s != CM_OK) return s;
    }
    return CM_OK;
}

/* The end of a zone: its sections all there, its cells' indices within its points. */
static cm_status end_zone(su2_reader *r)
{
    if (!r->dim) return fail(r, "expected NDIME= in zone %d, got the end of the zone", r->zones);
    if (r->npoin < 0) return fail(r, "expected NPOIN= in zone %d, got the end of the zone", r->zones);
    if (!r->have_elem) return fail(r, "expected NELEM= in zone %d, got the end of the zone", r->zones);
    if (r->max_id >= r->npoin) {
        r->line = r->max_line;
        return fail(r, "expected point indices below %lld (NPOIN= at line %ld), got %lld", (long long)r->npoin,
                    r->npoin_line, (long long)r->max_id);
    }
    return CM_OK;
}

static void begin_zone(su2_reader *r)
{
    r->dim = 0;
    r->base = r->m->n_nodes;
    r->npoin = -1;
    r->have_elem = r->have_mark = 0;
    r->max_id = -1;
}

static cm_status parse_su2(cm_context *ctx, const char *path, const char *data, size_t size, cm_mesh *m)
{
    su2_reader r = {.ctx = ctx, .path = path, .data = data, .size = size, .next = 1, .m = m};
    begin_zone(&r);
    r.src = cm_rewrite_source_new();
    if (!r.src) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    cm_status s = cm_rewrite_add_file(ctx, r.src, path, NULL, NULL);
    int64_t nzone = -1;
    int skipping = 0, any = 0;
    char key[32], buf[48];
    const char *value = NULL;
    while (s == CM_OK && next_line(&r)) {
        if (!keyword(&r, key, sizeof key, &value)) {
            if (skipping) continue;
            s = fail(&r, "expected a keyword (NDIME=, NELEM=, NPOIN=, NMARK=), got '%s'", shown(&r, buf));
            break;
        }
        skipping = 0;
        int64_t n = 0;
        if (!strcmp(key, "NZONE")) {
            if (any || nzone >= 0) s = fail(&r, "expected NZONE= first in the file, once");
            else s = read_count(&r, value, key, 8, &nzone, NULL);
            if (s == CM_OK && nzone < 1) s = fail(&r, "expected NZONE= 1 or more, got %lld", (long long)nzone);
        } else if (!strcmp(key, "IZONE")) {
            if (nzone < 0) s = fail(&r, "expected NZONE= before IZONE=");
            else if (any) s = end_zone(&r);
            if (s == CM_OK) s = read_count(&r, value, key, 0, &n, NULL);
            if (s == CM_OK && n != r.zones + 1)
                s = fail(&r, "expected IZONE= %d (the zones in order), got %lld", r.zones + 1, (long long)n);
            if (s == CM_OK && n > nzone)
                s = fail(&r, "expected at most the %lld zones of NZONE=, got IZONE= %lld", (long long)nzone, (long long)n);
            if (s != CM_OK) break;
            begin_zone(&r);
            r.zones = (int)n;
            r.zone_tag = nzone > 1 ? ++r.next_tag : 0; /* its group is added at NDIME= */
            any = 1;
        } else if (!strcmp(key, "NDIME")) {
            if (nzone > 1 && !r.zones) s = fail(&r, "expected IZONE= before NDIME= in a file of %lld zones", (long long)nzone);
            else if (r.dim) s = fail(&r, "expected one NDIME= per zone, got another");
            else s = read_count(&r, value, key, 0, &n, NULL);
            if (s == CM_OK && n != 2 && n != 3) s = fail(&r, "expected NDIME= 2 or 3, got %lld", (long long)n);
            if (s != CM_OK) break;
            r.dim = (int)n;
            if (!r.zones) r.zones = 1;
            any = 1;
            if (r.zone_tag) {
                char name[32];
                snprintf(name, sizeof name, "zone_%d", r.zones);
                s = cm_mesh_add_group(ctx, m, r.dim, r.zone_tag, name);
            }
        } else if (!strcmp(key, "NELEM") || !strcmp(key, "NPOIN") || !strcmp(key, "NMARK")) {
            const int which = key[1] == 'E' ? 0 : key[1] == 'P' ? 1 : 2;
            const int done = which == 0 ? r.have_elem : which == 1 ? r.npoin >= 0 : r.have_mark;
            if (!r.dim) s = fail(&r, "expected NDIME= before %s=", key);
            else if (done) s = fail(&r, "expected one %s= per zone, got another", key);
            if (s != CM_OK) break;
            const long at = r.line;
            if (which == 0) {
                s = read_count(&r, value, key, 6, &n, NULL);
                r.have_elem = 1;
                if (s == CM_OK) s = read_cells(&r, n, 0, at);
            } else if (which == 1) {
                const char *rest = NULL, *tb, *te;
                int64_t domain = 0;
                s = read_count(&r, value, key, 2 * (size_t)r.dim, &n, &rest);
                if (s == CM_OK && token(&rest, r.e, &tb, &te) && (!cm_text_parse_int(tb, te, &domain) || domain < 0 || domain > n))
                    s = expected_token(&r, "the domain point count (at most the points)", tb, te);
                if (s == CM_OK) s = trailing(&r, rest, 0, "the end of the line");
                if (s == CM_OK && (uint64_t)n > (SIZE_MAX / 24) - r.base)
                    s = fail(&r, "expected at most %zu points in all, got %lld", SIZE_MAX / 24, (long long)n);
                if (s != CM_OK) break;
                r.npoin = n;
                r.npoin_line = at;
                s = read_points(&r, n);
            } else {
                s = read_count(&r, value, key, 16, &n, NULL);
                r.have_mark = 1;
                if (s == CM_OK) s = read_markers(&r, n);
            }
        } else if (!strcmp(key, "MARKER_TAG") || !strcmp(key, "MARKER_ELEMS")) {
            s = fail(&r, "expected %s= only among the markers that NMARK= counts", key);
        } else {
            skipping = 1; /* SU2's FFD box definitions and the like: not the mesh */
        }
    }
    if (s == CM_OK && !any) s = fail(&r, "expected NDIME=, got the end of the file (not an SU2 mesh?)");
    if (s == CM_OK) s = end_zone(&r);
    if (s == CM_OK && nzone >= 0 && r.zones != nzone)
        s = fail(&r, "expected the %lld zones of NZONE=, got %d (truncated?)", (long long)nzone, r.zones);
    if (s != CM_OK) {
        cm_rewrite_source_free(r.src);
        return s;
    }
    return cm_mesh_set_origin(ctx, m, CM_FORMAT_SU2, r.src, cm_rewrite_source_free);
}

cm_status cm_mesh_read_su2(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    return cm_mesh_read_whole(ctx, "cm_mesh_read_su2", path, parse_su2, mesh);
}
