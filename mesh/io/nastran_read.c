/* Nastran bulk data reader: GRID (small, large, free field; CP systems CORD2R/C/S, chained,
 * and GRDSET's default), CTETRA/CHEXA/CPENTA/CPYRAM (linear and quadratic) and
 * CTRIA3/CTRIA6/CQUAD4/CQUAD8 (CTRIAR/CQUADR), CBAR/CBEAM/CROD as lines, with their PID as
 * physical group "PID <n>",
 * INCLUDE (relative to the including file; recursion refused). Executive and case control
 * before BEGIN BULK are skipped; ENDDATA ends the deck; other cards are ignored.
 *
 * Node order: Nastran's is VTK's except CHEXA20 and CPENTA15, whose vertical edges come before
 * the top edges (meshio's mapping); and Nastran does not fix the winding of a solid (G1-G4 of
 * a CHEXA may run either way around), so a solid whose corners give a negative volume is
 * mirrored into VTK's orientation. Either changes only the mesh, never the file. */
#define _POSIX_C_SOURCE 200809L
#include "cell_faces.h"
#include "formats.h"
#include "nastran_internal.h"
#include "rewrite.h"

#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

enum { MAX_DEPTH = 32 };

typedef struct grid {
    int64_t id, cp;
    int cp_blank;
    double x[3];
    size_t file, span; /* span: index in its file's spans */
    long line;
} grid;

typedef struct elem {
    int64_t eid, pid;
    uint8_t type;
    int n;
    size_t at; /* its GRID ids in ids[at .. at + n) */
    size_t file;
    long line;
    const char *card;
} elem;

typedef struct reader {
    cm_context *ctx;
    cm_rewrite_source *src;
    grid *g;
    size_t ng, cap_g;
    elem *el;
    size_t ne, cap_el;
    int64_t *ids;
    size_t nids, cap_ids;
    nas_coord *cs;
    size_t ncs, cap_cs;
    int64_t grdset_cp;
    int ended;
    nas_card card;
    struct { dev_t dev; ino_t ino; } stack[MAX_DEPTH];
    int depth;
} reader;

static int grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap) return 0;
    size_t c = *cap ? *cap : 64;
    while (c < need) {
        if (c > SIZE_MAX / 2 / size) return -1;
        c *= 2;
    }
    void *q = realloc(*p, c * size);
    if (!q) return -1;
    *p = q;
    *cap = c;
    return 0;
}

static const char *path_of(const reader *r, size_t file)
{
    return r->src->files[file].path;
}

static cm_status nomem(reader *r, size_t file)
{
    return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", path_of(r, file));
}

/* ---- fields ---- */

static cm_status field_int(reader *r, size_t file, const char *data, size_t i, const char *what,
                           int64_t lo, int64_t hi, int64_t dflt, int64_t *v)
{
    size_t n;
    const char *s = nas_field_text(data, &r->card, i, &n);
    const long line = r->card.n_lines ? r->card.lines[i < r->card.n_fields ? r->card.f[i].line : 0].number : 0;
    if (n == 0) {
        if (dflt < lo) return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %s: expected %s, got a blank field",
                                       path_of(r, file), line, r->card.name, what);
        *v = dflt;
        return CM_OK;
    }
    if (nas_parse_int(s, n, v) != 0 || *v < lo || *v > hi)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %s: expected %s (an integer in [%lld, %lld]), got '%.*s'",
                        path_of(r, file), line, r->card.name, what, (long long)lo, (long long)hi,
                        (int)(n > 24 ? 24 : n), s);
    return CM_OK;
}

static cm_status field_real(reader *r, size_t file, const char *data, size_t i, const char *what, double *v)
{
    size_t n;
    const char *s = nas_field_text(data, &r->card, i, &n);
    const long line = r->card.lines[i < r->card.n_fields ? r->card.f[i].line : 0].number;
    if (n == 0) {
        *v = 0.0;
        return CM_OK;
    }
    if (nas_parse_real(s, n, v) != 0)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %s: expected %s (a finite real), got '%.*s'", path_of(r, file),
                        line, r->card.name, what, (int)(n > 24 ? 24 : n), s);
    return CM_OK;
}

/* ---- cards ---- */

static cm_status read_grid(reader *r, size_t file, const char *data)
{
    const nas_card *c = &r->card;
    grid g = {0};
    g.file = file;
    g.line = c->lines[0].number;
    cm_status s = field_int(r, file, data, 0, "a GRID id", 1, INT64_MAX / 2, 0, &g.id);
    g.cp_blank = nas_field_blank(data, c, 1);
    if (s == CM_OK) s = field_int(r, file, data, 1, "a coordinate system id (CP)", 0, INT64_MAX / 2, 0, &g.cp);
    for (int k = 0; s == CM_OK && k < 3; ++k) s = field_real(r, file, data, 2 + (size_t)k, "a coordinate", &g.x[k]);
    if (s != CM_OK) return s;
    /* the bytes to rewrite: from the card's start to the end of the line of its last
     * coordinate field (X3 of a large-field card is on its continuation) */
    int last = 0;
    for (size_t k = 2; k <= 4 && k < c->n_fields; ++k)
        if (c->f[k].line > last) last = c->f[k].line;
    size_t span_index = r->src->files[file].n_spans;
    s = cm_rewrite_add_span(r->ctx, r->src, file, (int64_t)c->lines[0].b,
                            (int64_t)(c->lines[last].e - c->lines[0].b), (int64_t)r->ng,
                            c->lines[0].e < c->lines[0].next && data[c->lines[0].e] == '\r');
    if (s != CM_OK) return s;
    g.span = span_index;
    if (grow((void **)&r->g, &r->cap_g, r->ng + 1, sizeof *r->g)) return nomem(r, file);
    r->g[r->ng++] = g;
    return CM_OK;
}

static cm_status read_coord(reader *r, size_t file, const char *data, char type, int form)
{
    nas_coord cs = {0};
    cs.type = type;
    cs.form = form;
    cs.file = file;
    cs.line = r->card.lines[0].number;
    cm_status s = field_int(r, file, data, 0, "a coordinate system id", 1, INT64_MAX / 2, 0, &cs.id);
    if (s == CM_OK && form == 2) s = field_int(r, file, data, 1, "a reference system id (RID)", 0, INT64_MAX / 2, 0, &cs.rid);
    for (int k = 0; s == CM_OK && form == 2 && k < 9; ++k) s = field_real(r, file, data, 2 + (size_t)k, "a point coordinate", &cs.abc[k]);
    if (s != CM_OK) return s;
    if (grow((void **)&r->cs, &r->cap_cs, r->ncs + 1, sizeof *r->cs)) return nomem(r, file);
    r->cs[r->ncs++] = cs;
    return CM_OK;
}

typedef struct elem_kind {
    const char *name;
    cm_cell_type lin, quad;
    int n_lin, n_quad;
    int shell; /* exactly n_lin nodes, further fields are not nodes */
} elem_kind;

static const elem_kind kinds[] = {
    {"CTETRA", CM_CELL_TET4, CM_CELL_TET10, 4, 10, 0},  {"CHEXA", CM_CELL_HEX8, CM_CELL_HEX20, 8, 20, 0},
    {"CPENTA", CM_CELL_WEDGE6, CM_CELL_WEDGE15, 6, 15, 0}, {"CPYRAM", CM_CELL_PYR5, CM_CELL_PYR13, 5, 13, 0},
    {"CPYRA", CM_CELL_PYR5, CM_CELL_PYR13, 5, 13, 0},   {"CTRIA3", CM_CELL_TRI3, CM_CELL_TRI3, 3, 3, 1},
    {"CTRIAR", CM_CELL_TRI3, CM_CELL_TRI3, 3, 3, 1},    {"CTRIA6", CM_CELL_TRI6, CM_CELL_TRI6, 6, 6, 1},
    {"CQUAD4", CM_CELL_QUAD4, CM_CELL_QUAD4, 4, 4, 1},  {"CQUADR", CM_CELL_QUAD4, CM_CELL_QUAD4, 4, 4, 1},
    {"CQUAD8", CM_CELL_QUAD8, CM_CELL_QUAD8, 8, 8, 1},
    /* beams and rods as lines (their end grids; a CBAR's orientation fields are not nodes) */
    {"CBAR", CM_CELL_LINE2, CM_CELL_LINE2, 2, 2, 1},   {"CBEAM", CM_CELL_LINE2, CM_CELL_LINE2, 2, 2, 1},
    {"CROD", CM_CELL_LINE2, CM_CELL_LINE2, 2, 2, 1},
};

/* Nastran's CHEXA20 / CPENTA15 node i is VTK's node perm[i]'s source: vtk[j] = nas[perm[j]] */
static const int hex20_perm[20] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 16, 17, 18, 19, 12, 13, 14, 15};
static const int wedge15_perm[15] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 13, 14, 9, 10, 11};

static cm_status read_elem(reader *r, size_t file, const char *data, const elem_kind *k)
{
    const nas_card *c = &r->card;
    elem e = {0};
    e.file = file;
    e.line = c->lines[0].number;
    e.card = k->name;
    cm_status s = field_int(r, file, data, 0, "an element id", 1, INT64_MAX / 2, 0, &e.eid);
    if (s == CM_OK) s = field_int(r, file, data, 1, "a property id (PID)", 1, INT_MAX, e.eid, &e.pid);
    if (s == CM_OK && e.pid > INT_MAX)
        s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %s %lld: property id %lld out of range (PID defaults to the element id)",
                     path_of(r, file), e.line, k->name, (long long)e.eid, (long long)e.pid);
    if (s != CM_OK) return s;
    int n = 0;
    if (k->shell) {
        n = k->n_lin;
    } else {
        for (int i = 0; i < k->n_quad; ++i)
            if (!nas_field_blank(data, c, 2 + (size_t)i)) n = i + 1;
        for (size_t i = 2 + (size_t)k->n_quad; i < c->n_fields; ++i)
            if (!nas_field_blank(data, c, i))
                return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %s %lld has more than %d nodes", path_of(r, file), e.line,
                                k->name, (long long)e.eid, k->n_quad);
    }
    if (n != k->n_lin && n != k->n_quad)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %s %lld has %d nodes (expected %d or %d; a missing continuation line?)",
                        path_of(r, file), e.line, k->name, (long long)e.eid, n, k->n_lin, k->n_quad);
    if (grow((void **)&r->ids, &r->cap_ids, r->nids + (size_t)n, sizeof *r->ids)) return nomem(r, file);
    int64_t nas[20];
    for (int i = 0; i < n; ++i) {
        size_t len;
        (void)nas_field_text(data, c, 2 + (size_t)i, &len);
        if (len == 0)
            return cm_error(r->ctx, CM_ERR_UNSUPPORTED, "%s:%ld: %s %lld: node %d is blank (elements without some "
                            "mid-side nodes are not supported)", path_of(r, file), e.line, k->name, (long long)e.eid, i + 1);
        s = field_int(r, file, data, 2 + (size_t)i, "a GRID id", 1, INT64_MAX / 2, 0, &nas[i]);
        if (s != CM_OK) return s;
    }
    e.type = (uint8_t)(n == k->n_lin ? k->lin : k->quad);
    e.n = n;
    e.at = r->nids;
    for (int i = 0; i < n; ++i)
        r->ids[r->nids++] = e.type == CM_CELL_HEX20 ? nas[hex20_perm[i]] : e.type == CM_CELL_WEDGE15 ? nas[wedge15_perm[i]] : nas[i];
    if (grow((void **)&r->el, &r->cap_el, r->ne + 1, sizeof *r->el)) return nomem(r, file);
    r->el[r->ne++] = e;
    return CM_OK;
}

/* ---- files ---- */

static int word_at(const char *data, size_t b, size_t e, const char *w)
{
    const size_t n = strlen(w);
    return e - b >= n && !strncasecmp(data + b, w, n);
}

/* The position after a "BEGIN BULK" line, or 0 for a file of bulk data alone. */
static size_t bulk_start(const char *data, size_t size, long *line)
{
    nas_line l;
    long ln = 1;
    for (size_t p = 0; p < size; p = l.next, ++ln) {
        nas_line_at(data, size, p, &l);
        size_t b = l.b;
        while (b < l.e && isspace((unsigned char)data[b])) ++b;
        if (!word_at(data, b, l.e, "BEGIN")) continue;
        b += 5;
        while (b < l.e && isspace((unsigned char)data[b])) ++b;
        if (word_at(data, b, l.e, "BULK")) {
            *line = ln + 1;
            return l.next;
        }
    }
    *line = 1;
    return 0;
}

static cm_status read_file(reader *r, const char *path, const char *name, long from_line, size_t from_file);

/* INCLUDE 'path' (the path may run over several lines until its closing quote) or INCLUDE
 * path: reads the file, relative to the including one. Returns where the next card starts. */
static cm_status include(reader *r, size_t file, const char *data, size_t size, size_t *pos, long *line)
{
    const long at_line = *line;
    nas_line l;
    nas_line_at(data, size, *pos, &l);
    size_t b = l.b + 7;
    while (b < l.e && isspace((unsigned char)data[b])) ++b;
    char *inc = malloc(size + 1);
    if (!inc) return nomem(r, file);
    size_t n = 0;
    if (b < l.e && (data[b] == '\'' || data[b] == '"')) {
        const char q = data[b++];
        for (;;) {
            const char *end = memchr(data + b, q, l.e - b);
            size_t e = end ? (size_t)(end - data) : l.e;
            while (b < e && isspace((unsigned char)data[b])) ++b;
            size_t t = e;
            if (!end)
                while (t > b && isspace((unsigned char)data[t - 1])) --t;
            memcpy(inc + n, data + b, t - b);
            n += t - b;
            if (end) break;
            if (l.next >= size) {
                free(inc);
                return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: INCLUDE: the file name has no closing quote",
                                path_of(r, file), at_line);
            }
            nas_line_at(data, size, l.next, &l);
            ++*line;
            b = l.b;
            while (b < l.e && isspace((unsigned char)data[b])) ++b;
        }
    } else {
        size_t e = l.e;
        while (e > b && isspace((unsigned char)data[e - 1])) --e;
        memcpy(inc + n, data + b, e - b);
        n = e - b;
    }
    inc[n] = '\0';
    *pos = l.next;
    ++*line;
    if (n == 0 || memchr(inc, '\0', n)) {
        free(inc);
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: INCLUDE without a file name", path_of(r, file), at_line);
    }
    /* the file beside the including one; its name for the written copy likewise beside the
     * including file's copy */
    const char *base = path_of(r, file), *slash = strrchr(base, '/');
    const char *iname = r->src->files[file].name, *nslash = iname ? strrchr(iname, '/') : NULL;
    const size_t dir = inc[0] == '/' || !slash ? 0 : (size_t)(slash - base) + 1;
    const size_t ndir = inc[0] == '/' || !nslash ? 0 : (size_t)(nslash - iname) + 1;
    char *full = malloc(dir + n + 1), *nm = malloc(ndir + n + 1);
    cm_status s = CM_OK;
    if (!full || !nm) {
        s = nomem(r, file);
    } else {
        memcpy(full, base, dir);
        memcpy(full + dir, inc, n + 1);
        if (ndir) memcpy(nm, iname, ndir);
        memcpy(nm + ndir, inc, n + 1);
        s = read_file(r, full, nm, at_line, file);
    }
    free(full);
    free(nm);
    free(inc);
    return s;
}

static cm_status read_cards(reader *r, size_t file, const char *data, size_t size)
{
    long line = 1;
    size_t pos = bulk_start(data, size, &line);
    cm_status s = CM_OK;
    while (s == CM_OK && pos < size && !r->ended) {
        nas_line l;
        nas_line_at(data, size, pos, &l);
        if (nas_line_is_comment(data, &l)) {
            pos = l.next;
            ++line;
            continue;
        }
        if (word_at(data, l.b, l.e, "INCLUDE") && (l.e - l.b == 7 || isspace((unsigned char)data[l.b + 7]) ||
                                                   data[l.b + 7] == '\'' || data[l.b + 7] == '"')) {
            s = include(r, file, data, size, &pos, &line);
            continue;
        }
        if (nas_line_is_continuation(data, &l))
            return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: a continuation line without a card before it",
                            path_of(r, file), line);
        const long first = line;
        const size_t next = nas_card_split(data, size, pos, &line, &r->card);
        if (next == (size_t)-1) return nomem(r, file);
        pos = next;
        const char *nm = r->card.name;
        if (r->card.too_many)
            return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %s: a free-field line with more than 10 fields", path_of(r, file),
                            first, nm);
        if (!strcmp(nm, "ENDDATA")) {
            r->ended = 1;
        } else if (!strcmp(nm, "GRID")) {
            s = read_grid(r, file, data);
        } else if (!strcmp(nm, "GRDSET")) {
            s = field_int(r, file, data, 1, "a coordinate system id (CP)", 0, INT64_MAX / 2, 0, &r->grdset_cp);
        } else if (!strncmp(nm, "CORD", 4) && (nm[4] == '1' || nm[4] == '2') && strchr("RCS", nm[5]) && nm[5] && !nm[6]) {
            s = read_coord(r, file, data, nm[5], nm[4] - '0');
        } else {
            for (size_t k = 0; k < sizeof kinds / sizeof *kinds; ++k)
                if (!strcmp(nm, kinds[k].name)) s = read_elem(r, file, data, &kinds[k]);
        }
    }
    return s;
}

static cm_status read_file(reader *r, const char *path, const char *name, long from_line, size_t from_file)
{
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode)) {
        if (name) return cm_error(r->ctx, CM_ERR_IO, "%s:%ld: INCLUDE: cannot read %s", path_of(r, from_file), from_line, path);
        return cm_error(r->ctx, CM_ERR_IO, "%s: cannot read the file", path);
    }
    for (int i = 0; i < r->depth; ++i)
        if (r->stack[i].dev == st.st_dev && r->stack[i].ino == st.st_ino)
            return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: INCLUDE of %s includes itself (recursive INCLUDE)",
                            path_of(r, from_file), from_line, path);
    if (r->depth >= MAX_DEPTH)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: INCLUDE nested deeper than %d files", path_of(r, from_file),
                        from_line, MAX_DEPTH);
    char *data = NULL;
    size_t size = 0;
    cm_status s = cm_file_read(r->ctx, path, &data, &size);
    if (s != CM_OK) return s;
    size_t file = 0;
    s = cm_rewrite_add_file(r->ctx, r->src, path, name, &file);
    if (s == CM_OK) {
        r->stack[r->depth].dev = st.st_dev;
        r->stack[r->depth].ino = st.st_ino;
        ++r->depth;
        s = read_cards(r, file, data, size);
        --r->depth;
    }
    free(data);
    return s;
}

/* ---- after the cards: systems, ids, the mesh ---- */

static int cmp_id(const void *a, const void *b)
{
    const int64_t x = ((const int64_t *)a)[0], y = ((const int64_t *)b)[0];
    return x < y ? -1 : x > y;
}

static int cmp_coord(const void *a, const void *b)
{
    const int64_t x = ((const nas_coord *)a)->id, y = ((const nas_coord *)b)->id;
    return x < y ? -1 : x > y;
}

static nas_coord *find_coord(reader *r, int64_t id)
{
    nas_coord key = {0};
    key.id = id;
    /* no system at all: r->cs is NULL, which bsearch must not see */
    return r->ncs ? bsearch(&key, r->cs, r->ncs, sizeof *r->cs, cmp_coord) : NULL;
}

static cm_status resolve(reader *r, nas_coord *c, int depth)
{
    if (c->state == 2) return CM_OK;
    const char *p = path_of(r, c->file);
    if (c->state == 1 || depth > 1000)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: CORD2%c %lld: its reference systems (RID) form a cycle", p,
                        c->line, c->type, (long long)c->id);
    if (c->form != 2)
        return cm_error(r->ctx, CM_ERR_UNSUPPORTED, "%s:%ld: CORD1%c %lld (a system on grid points) is not supported; "
                        "use CORD2%c", p, c->line, c->type, (long long)c->id, c->type);
    c->state = 1;
    double a[3], b[3], cc[3];
    if (c->rid != 0) {
        nas_coord *ref = find_coord(r, c->rid);
        if (!ref)
            return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: CORD2%c %lld: reference system %lld is not defined", p,
                            c->line, c->type, (long long)c->id, (long long)c->rid);
        cm_status s = resolve(r, ref, depth + 1);
        if (s != CM_OK) return s;
        nas_coord_to_basic(ref, c->abc, a);
        nas_coord_to_basic(ref, c->abc + 3, b);
        nas_coord_to_basic(ref, c->abc + 6, cc);
    } else {
        memcpy(a, c->abc, sizeof a);
        memcpy(b, c->abc + 3, sizeof b);
        memcpy(cc, c->abc + 6, sizeof cc);
    }
    /* z along A->B, x in the plane of A, B, C */
    double z[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, xc[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
    double y[3] = {z[1] * xc[2] - z[2] * xc[1], z[2] * xc[0] - z[0] * xc[2], z[0] * xc[1] - z[1] * xc[0]};
    const double nz = sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]), ny = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    if (!(nz > 0) || !(ny > 1e-12 * nz * sqrt(xc[0] * xc[0] + xc[1] * xc[1] + xc[2] * xc[2])) || !isfinite(nz * ny))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: CORD2%c %lld: points A, B, C are on one line", p, c->line,
                        c->type, (long long)c->id);
    for (int i = 0; i < 3; ++i) z[i] /= nz, y[i] /= ny;
    const double x[3] = {y[1] * z[2] - y[2] * z[1], y[2] * z[0] - y[0] * z[2], y[0] * z[1] - y[1] * z[0]};
    memcpy(c->o, a, sizeof a);
    memcpy(c->e[0], x, sizeof x);
    memcpy(c->e[1], y, sizeof y);
    memcpy(c->e[2], z, sizeof z);
    c->state = 2;
    return CM_OK;
}

/* The signed volume of a solid's corners (centroid fan over its faces). */
static double solid_volume(const cm_mesh *m, cm_cell_type type, const int64_t *v)
{
    const cm_face_table *t = cm_cell_face_table(type);
    const int nc = cm_cell_type_info(type)->corners;
    double c[3] = {0, 0, 0}, vol = 0;
    for (int i = 0; i < nc; ++i)
        for (int k = 0; k < 3; ++k) c[k] += m->xyz[3 * v[i] + k] / nc;
    for (int f = 0; f < t->n_faces; ++f)
        for (int j = 1; j + 1 < t->size[f]; ++j) {
            const double *p0 = m->xyz + 3 * v[t->node[f][0]], *p1 = m->xyz + 3 * v[t->node[f][j]],
                         *p2 = m->xyz + 3 * v[t->node[f][j + 1]];
            const double a[3] = {p0[0] - c[0], p0[1] - c[1], p0[2] - c[2]}, b[3] = {p1[0] - c[0], p1[1] - c[1], p1[2] - c[2]},
                         d[3] = {p2[0] - c[0], p2[1] - c[1], p2[2] - c[2]};
            vol += a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0]);
        }
    return vol / 6;
}

/* The mirror image of a solid in VTK's order: vtk'[j] = vtk[mirror[j]]. */
static const int *mirror_of(cm_cell_type t)
{
    static const int tet[10] = {0, 2, 1, 3, 6, 5, 4, 7, 9, 8};
    static const int hex[20] = {4, 5, 6, 7, 0, 1, 2, 3, 12, 13, 14, 15, 8, 9, 10, 11, 16, 17, 18, 19};
    static const int wedge[15] = {3, 4, 5, 0, 1, 2, 9, 10, 11, 6, 7, 8, 12, 13, 14};
    static const int pyr[13] = {0, 3, 2, 1, 4, 8, 7, 6, 5, 9, 12, 11, 10};
    switch (t) {
    case CM_CELL_TET4: case CM_CELL_TET10: return tet;
    case CM_CELL_HEX8: case CM_CELL_HEX20: return hex;
    case CM_CELL_WEDGE6: case CM_CELL_WEDGE15: return wedge;
    case CM_CELL_PYR5: case CM_CELL_PYR13: return pyr;
    default: return NULL;
    }
}

static cm_status build(reader *r, cm_mesh *m, nas_record *rec)
{
    cm_context *ctx = r->ctx;
    /* systems: sorted by id, each id once, resolved */
    if (r->ncs > 1) qsort(r->cs, r->ncs, sizeof *r->cs, cmp_coord); /* r->cs NULL when none */
    for (size_t i = 1; i < r->ncs; ++i)
        if (r->cs[i].id == r->cs[i - 1].id)
            return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: coordinate system %lld is defined twice", path_of(r, r->cs[i].file),
                            r->cs[i].line, (long long)r->cs[i].id);
    cm_status s = cm_mesh_resize_nodes(ctx, m, r->ng, 1);
    if (s != CM_OK) return s;
    rec->xyz = malloc((r->ng ? r->ng : 1) * 3 * sizeof(double));
    if (!rec->xyz) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path_of(r, 0));
    for (size_t i = 0; i < r->ng; ++i) {
        grid *g = &r->g[i];
        const int64_t cp = g->cp_blank ? r->grdset_cp : g->cp;
        double *x = m->xyz + 3 * i;
        m->node_tag[i] = g->id;
        if (cp == 0) {
            memcpy(x, g->x, sizeof g->x);
            continue;
        }
        nas_coord *c = find_coord(r, cp);
        if (!c)
            return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: GRID %lld: coordinate system %lld (CP%s) is not defined",
                            path_of(r, g->file), g->line, (long long)g->id, (long long)cp, g->cp_blank ? ", from GRDSET" : "");
        s = resolve(r, c, 0);
        if (s != CM_OK) {
            char why[512];
            snprintf(why, sizeof why, "%s", cm_context_message(ctx));
            return cm_error(ctx, s, "%s (the system of GRID %lld at %s:%ld)", why, (long long)g->id,
                            path_of(r, g->file), g->line);
        }
        nas_coord_to_basic(c, g->x, x);
        if (!(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2])))
            return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: GRID %lld: not finite in the basic system", path_of(r, g->file),
                            g->line, (long long)g->id);
        r->src->files[g->file].spans[g->span].aux += 2 * (1 + (int64_t)(c - r->cs));
    }
    if (r->ng) memcpy(rec->xyz, m->xyz, r->ng * 3 * sizeof(double));
    /* GRID ids: sorted (id, index) pairs, each id once */
    int64_t *pairs = malloc((r->ng ? r->ng : 1) * 2 * sizeof *pairs);
    if (!pairs) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path_of(r, 0));
    for (size_t i = 0; i < r->ng; ++i) pairs[2 * i] = r->g[i].id, pairs[2 * i + 1] = (int64_t)i;
    qsort(pairs, r->ng, 2 * sizeof *pairs, cmp_id);
    for (size_t i = 1; s == CM_OK && i < r->ng; ++i)
        if (pairs[2 * i] == pairs[2 * i - 2]) {
            const grid *g = &r->g[pairs[2 * i + 1] > pairs[2 * i - 1] ? pairs[2 * i + 1] : pairs[2 * i - 1]];
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: GRID %lld is defined twice", path_of(r, g->file), g->line, (long long)g->id);
        }
    if (s == CM_OK) s = cm_mesh_reserve_cells(ctx, m, r->ne, r->nids);
    for (size_t c = 0; s == CM_OK && c < r->ne; ++c) {
        const elem *e = &r->el[c];
        int64_t v[20];
        for (int i = 0; i < e->n; ++i) {
            const int64_t key[2] = {r->ids[e->at + (size_t)i], 0};
            const int64_t *hit = bsearch(key, pairs, r->ng, 2 * sizeof *pairs, cmp_id);
            if (!hit) {
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s %lld: GRID %lld is not defined", path_of(r, e->file), e->line,
                             e->card, (long long)e->eid, (long long)key[0]);
                break;
            }
            v[i] = hit[1];
        }
        const int *mir = s == CM_OK ? mirror_of((cm_cell_type)e->type) : NULL;
        if (mir && solid_volume(m, (cm_cell_type)e->type, v) < 0) {
            int64_t w[20];
            for (int i = 0; i < e->n; ++i) w[i] = v[mir[i]];
            memcpy(v, w, sizeof(int64_t) * (size_t)e->n);
        }
        if (s == CM_OK) s = cm_mesh_add_cell(ctx, m, (cm_cell_type)e->type, v, (size_t)e->n, (int)e->pid, 0, e->eid);
    }
    free(pairs);
    /* groups: one per (dimension, PID) */
    for (size_t c = 0; s == CM_OK && c < m->n_cells; ++c) {
        const int dim = cm_cell_type_info((cm_cell_type)m->type[c])->dim;
        int seen = 0;
        for (size_t g = 0; g < m->n_groups && !seen; ++g) seen = m->groups[g].dim == dim && m->groups[g].tag == m->physical[c];
        if (seen) continue;
        char name[32];
        snprintf(name, sizeof name, "PID %d", m->physical[c]);
        s = cm_mesh_add_group(ctx, m, dim, m->physical[c], name);
    }
    return s;
}

cm_status cm_mesh_read_nastran(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read_nastran: NULL argument");
    *mesh = NULL;
    reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.src = cm_rewrite_source_new();
    nas_record *rec = calloc(1, sizeof *rec);
    cm_mesh *m = NULL;
    cm_status s = r.src && rec ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
    if (s == CM_OK) s = read_file(&r, path, NULL, 0, 0);
    if (s == CM_OK && r.ng == 0) s = cm_error(ctx, CM_ERR_FORMAT, "%s: no GRID cards (is it Nastran bulk data?)", path);
    if (s == CM_OK) s = cm_mesh_create(ctx, &m);
    if (s == CM_OK) s = build(&r, m, rec);
    if (s == CM_OK) {
        rec->coords = r.cs;
        rec->n_coords = r.ncs;
        r.cs = NULL;
        r.src->format = rec;
        r.src->free_format = nas_record_free;
        rec = NULL;
        s = cm_mesh_set_origin(ctx, m, CM_FORMAT_NASTRAN, r.src, cm_rewrite_source_free);
        r.src = NULL; /* the origin owns it, or has freed it */
    }
    nas_record_free(rec);
    cm_rewrite_source_free(r.src);
    free(r.g);
    free(r.el);
    free(r.ids);
    free(r.cs);
    nas_card_free(&r.card);
    if (s != CM_OK) {
        cm_mesh_destroy(&m);
        return s;
    }
    *mesh = m;
    return CM_OK;
}

/* Content test for a shared extension (.dat): a line that starts a Nastran card or section. */
int cm_nastran_sniff(const char *head, size_t n)
{
    static const char *const words[] = {"BEGIN BULK", "GRID", "CEND", "SOL ", "INCLUDE", "CTETRA", "CHEXA",
                                        "CPENTA", "CPYRAM", "CQUAD4", "CTRIA3", "CORD2", "NASTRAN ", "ID "};
    for (size_t p = 0; p < n;) {
        const char *nl = memchr(head + p, '\n', n - p);
        const size_t e = nl ? (size_t)(nl - head) : n;
        for (size_t w = 0; w < sizeof words / sizeof *words; ++w) {
            const size_t k = strlen(words[w]);
            if (e - p >= k && !strncasecmp(head + p, words[w], k)) return 1;
        }
        p = e + 1;
    }
    return 0;
}
