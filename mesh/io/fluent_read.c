/* Fluent mesh (.msh) and case (.cas) files: the sections (fluent_internal.h). Nodes (10, 2010,
 * 3010), cells (12, 2012, 3012: zones only, the cells themselves come from the faces), faces
 * (13, 2013, 3013), zone names (39, 45); comments, headers and every other section are
 * skipped with their bytes kept (strings, nested lists, binary sections by their trailer).
 * Hanging-node trees (58, 59, 61) and 2-D meshes are refused. The place of every node's
 * coordinates is recorded for the write back (rewrite.h). */
#define _POSIX_C_SOURCE 200809L
#include "fluent_internal.h"
#include "formats.h"
#include "rewrite.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "the Fluent reader reads binary sections as little-endian"
#endif

#define BINARY_TRAILER "End of Binary Section"

typedef struct parser {
    cm_context *ctx;
    cm_fluent_parsed *p;
    size_t pos;
    cm_rewrite_source *src;
    double *xyz; /* grows with the node sections */
    unsigned char *have;
    size_t cap_nodes;
    int64_t *tokens; /* one ASCII face */
    size_t cap_tokens;
    struct zone_name_rec {
        int64_t id;
        char name[128];
    } *names; /* from (39)/(45), applied to the zones at the end */
    size_t n_names, cap_names;
} parser;

/* An error at byte at: "FILE:LINE: ..." for text, "FILE: byte N: ..." inside binary data. */
static cm_status fail_at(parser *ps, size_t at, int binary, const char *what)
{
    if (binary)
        return cm_error(ps->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: byte %zu: %s", ps->p->path, at, what);
    return cm_error(ps->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s:%ld: %s", ps->p->path, cm_fluent_line_of(ps->p, at), what);
}

static cm_status fail(parser *ps, const char *what)
{
    return fail_at(ps, ps->pos, 0, what);
}

static int at_end(const parser *ps)
{
    return ps->pos >= ps->p->size;
}

static char peek(const parser *ps)
{
    return at_end(ps) ? '\0' : ps->p->data[ps->pos];
}

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

static void skip_space(parser *ps)
{
    while (!at_end(ps) && is_space(ps->p->data[ps->pos])) ++ps->pos;
}

/* Spaces and tabs only: a face's numbers end at its line's end. */
static void skip_blank(parser *ps)
{
    while (!at_end(ps) && (peek(ps) == ' ' || peek(ps) == '\t' || peek(ps) == '\r')) ++ps->pos;
}

static cm_status expect(parser *ps, char c, const char *what)
{
    skip_space(ps);
    if (peek(ps) != c) return fail(ps, what);
    ++ps->pos;
    return CM_OK;
}

/* A hexadecimal (base 16) or decimal (base 10) number below 2^62. */
static cm_status number(parser *ps, int base, int64_t *v, const char *what)
{
    skip_space(ps);
    const size_t start = ps->pos;
    int64_t x = 0;
    for (; !at_end(ps); ++ps->pos) {
        const char c = peek(ps);
        int d = c >= '0' && c <= '9' ? c - '0' : -1;
        if (base == 16 && c >= 'a' && c <= 'f') d = c - 'a' + 10;
        if (base == 16 && c >= 'A' && c <= 'F') d = c - 'A' + 10;
        if (d < 0) break;
        if (x > ((INT64_C(1) << 62) - d) / base) return fail_at(ps, start, 0, "number too large");
        x = x * base + d;
    }
    if (ps->pos == start) {
        char msg[96];
        snprintf(msg, sizeof msg, "expected %s", what);
        return fail(ps, msg);
    }
    *v = x;
    return CM_OK;
}

/* Skips to the ')' that closes depth open lists (strings and their escapes honoured). */
static cm_status skip_lists(parser *ps, int depth)
{
    const size_t start = ps->pos;
    while (depth > 0) {
        if (at_end(ps)) return fail_at(ps, start, 0, "unterminated section: no closing ')' before the end of the file");
        const char c = ps->p->data[ps->pos++];
        if (c == '(') ++depth;
        else if (c == ')') --depth;
        else if (c == '"') {
            while (!at_end(ps) && peek(ps) != '"') ps->pos += peek(ps) == '\\' ? 2 : 1;
            if (at_end(ps)) return fail_at(ps, start, 0, "unterminated string");
            ++ps->pos;
        }
    }
    return CM_OK;
}

/* The end of a binary section from its data on: ") End of Binary Section <index>)". */
static cm_status binary_trailer(parser *ps, int64_t index)
{
    if (expect(ps, ')', "expected ')' after the binary data") != CM_OK) return CM_ERR_FORMAT;
    skip_space(ps);
    const size_t n = sizeof BINARY_TRAILER - 1;
    if (ps->p->size - ps->pos < n || memcmp(ps->p->data + ps->pos, BINARY_TRAILER, n) != 0)
        return fail(ps, "expected \"" BINARY_TRAILER "\" after the binary data");
    ps->pos += n;
    int64_t i = 0;
    if (number(ps, 10, &i, "the binary section's index") != CM_OK) return CM_ERR_FORMAT;
    if (i != index) return fail(ps, "the binary section's trailer names another section");
    return expect(ps, ')', "expected ')' closing the binary section");
}

/* A binary section whose data is not read: to its trailer. */
static cm_status skip_binary(parser *ps, int64_t index)
{
    const size_t start = ps->pos, n = sizeof BINARY_TRAILER - 1;
    for (size_t i = ps->pos; i + n <= ps->p->size; ++i)
        if (ps->p->data[i] == 'E' && memcmp(ps->p->data + i, BINARY_TRAILER, n) == 0) {
            /* the data ends with ')' before the trailer */
            size_t close = i;
            while (close > start && is_space(ps->p->data[close - 1])) --close;
            ps->pos = close > start ? close - 1 : start;
            return binary_trailer(ps, index);
        }
    return fail_at(ps, start, 0, "binary section without \"" BINARY_TRAILER "\"");
}

/* "(a b c ...)": up to 8 hexadecimal numbers; *n their count. */
static cm_status header(parser *ps, int64_t *v, int *n)
{
    if (expect(ps, '(', "expected '(' opening the section's header") != CM_OK) return CM_ERR_FORMAT;
    *n = 0;
    for (;;) {
        skip_space(ps);
        if (peek(ps) == ')') {
            ++ps->pos;
            return CM_OK;
        }
        if (*n == 8) return fail(ps, "too many numbers in the section's header");
        if (number(ps, 16, &v[(*n)++], "a hexadecimal number or ')' in the section's header") != CM_OK)
            return CM_ERR_FORMAT;
    }
}

/* Where the body of a section starts: 1 at its '(' (consumed), 0 at the section's ')'
 * (consumed: no body). Binary data starts right after the '('. */
static cm_status body(parser *ps, int *has)
{
    skip_space(ps);
    if (peek(ps) == ')') {
        ++ps->pos;
        *has = 0;
        return CM_OK;
    }
    if (peek(ps) != '(') return fail(ps, "expected '(' opening the section's data or ')' closing the section");
    ++ps->pos;
    *has = 1;
    return CM_OK;
}

static cm_status grow_nodes(parser *ps, int64_t last)
{
    if ((size_t)last <= ps->cap_nodes) return CM_OK;
    size_t cap = ps->cap_nodes ? ps->cap_nodes : 1024;
    while (cap < (size_t)last) cap *= 2;
    double *xyz = realloc(ps->xyz, cap * 3 * sizeof *xyz);
    if (xyz) ps->xyz = xyz;
    unsigned char *have = xyz ? realloc(ps->have, cap) : NULL;
    if (!have) return cm_error(ps->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for %lld nodes", ps->p->path, (long long)last);
    memset(have + ps->cap_nodes, 0, cap - ps->cap_nodes);
    ps->have = have;
    ps->cap_nodes = cap;
    return CM_OK;
}

static cm_status nodes(parser *ps, int64_t index)
{
    const size_t at = ps->pos;
    int64_t h[8];
    int nh = 0, has = 0;
    if (header(ps, h, &nh) != CM_OK) return CM_ERR_FORMAT;
    if (nh < 4) return fail_at(ps, at, 0, "expected (zone-id first-index last-index type [ND]) in a node section");
    if (body(ps, &has) != CM_OK) return CM_ERR_FORMAT;
    if (h[0] == 0 && !has) { /* the declaration of the node count */
        if (h[1] != 1 && h[2] >= h[1]) return fail_at(ps, at, 0, "the node count's declaration must start at 1");
        ps->p->n_nodes = h[2];
        return CM_OK;
    }
    if (!has) return CM_OK;
    const int nd = nh >= 5 ? (int)h[4] : ps->p->dim;
    if (nd != 3) return fail_at(ps, at, 0, "expected 3 coordinates per node (ND 3) in a 3-D file");
    if (h[1] < 1 || h[2] < h[1]) return fail_at(ps, at, 0, "node indices must satisfy 1 <= first-index <= last-index");
    const int64_t count = h[2] - h[1] + 1;
    const size_t size = index == 10 ? 0 : index == 2010 ? 4 : 8;
    const size_t left = ps->p->size - ps->pos;
    /* counts checked against the bytes left before anything is allocated */
    if ((size && (uint64_t)count > left / (3 * size)) || (!size && (uint64_t)count > left / 6))
        return fail_at(ps, at, 0, "the node section holds more nodes than the file has bytes for");
    if (grow_nodes(ps, h[2]) != CM_OK) return CM_ERR_NOMEM;
    for (int64_t i = 0; i < count; ++i) {
        const size_t node = (size_t)(h[1] - 1 + i);
        if (ps->have[node]) {
            char msg[96];
            snprintf(msg, sizeof msg, "node %llx (hexadecimal) defined twice", (unsigned long long)node + 1);
            return fail_at(ps, at, 0, msg);
        }
        ps->have[node] = 1;
        size_t first = 0;
        if (size) {
            first = ps->pos;
            for (int k = 0; k < 3; ++k) {
                if (size == 4) {
                    float f;
                    memcpy(&f, ps->p->data + ps->pos, 4);
                    ps->xyz[3 * node + k] = f;
                } else {
                    memcpy(&ps->xyz[3 * node + k], ps->p->data + ps->pos, 8);
                }
                ps->pos += size;
            }
            if (!isfinite(ps->xyz[3 * node]) || !isfinite(ps->xyz[3 * node + 1]) || !isfinite(ps->xyz[3 * node + 2]))
                return fail_at(ps, first, 1, "a node coordinate is not a finite number");
        } else {
            for (int k = 0; k < 3; ++k) {
                skip_space(ps);
                const size_t b = ps->pos;
                while (!at_end(ps) && !is_space(peek(ps)) && peek(ps) != ')' && peek(ps) != '(') ++ps->pos;
                char buf[64], *end = NULL;
                const size_t len = ps->pos - b;
                if (len == 0 || len >= sizeof buf) return fail_at(ps, b, 0, "expected a node coordinate");
                memcpy(buf, ps->p->data + b, len);
                buf[len] = '\0';
                ps->xyz[3 * node + k] = strtod(buf, &end);
                if (*end) return fail_at(ps, b, 0, "expected a node coordinate");
                if (!isfinite(ps->xyz[3 * node + k])) return fail_at(ps, b, 0, "a node coordinate is not a finite number");
                if (k == 0) first = b;
            }
        }
        if (cm_rewrite_add_span(ps->ctx, ps->src, 0, (int64_t)first, (int64_t)(ps->pos - first), (int64_t)node,
                                (int64_t)size) != CM_OK)
            return CM_ERR_NOMEM;
    }
    if (h[2] > ps->p->n_nodes) ps->p->n_nodes = h[2];
    if (size) return binary_trailer(ps, index);
    if (expect(ps, ')', "expected ')' after the node coordinates (more numbers than the header's count?)") != CM_OK)
        return CM_ERR_FORMAT;
    return expect(ps, ')', "expected ')' closing the node section");
}

static cm_status add_zone(parser *ps, int kind, const int64_t *h, size_t *index)
{
    cm_fluent_parsed *p = ps->p;
    if (p->n_zones == p->cap_zones) {
        size_t cap = p->cap_zones ? 2 * p->cap_zones : 16;
        cm_fluent_zone *z = realloc(p->zones, cap * sizeof *z);
        if (!z) return cm_error(ps->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", p->path);
        p->zones = z;
        p->cap_zones = cap;
    }
    cm_fluent_zone *z = &p->zones[p->n_zones];
    memset(z, 0, sizeof *z);
    z->id = h[0];
    z->first = h[1];
    z->last = h[2];
    z->kind = kind;
    z->type = kind == 13 ? h[3] : h[4];
    *index = p->n_zones++;
    return CM_OK;
}

static cm_status cells(parser *ps, int64_t index)
{
    const size_t at = ps->pos;
    int64_t h[8];
    int nh = 0, has = 0;
    if (header(ps, h, &nh) != CM_OK) return CM_ERR_FORMAT;
    if (nh < 4) return fail_at(ps, at, 0, "expected (zone-id first-index last-index type [element-type]) in a cell section");
    if (nh == 4) h[4] = 0;
    if (h[0] == 0) {
        if (h[2] >= h[1] && h[1] != 1) return fail_at(ps, at, 0, "the cell count's declaration must start at 1");
        ps->p->n_cells_declared = h[2];
    } else {
        if (h[1] < 1 || h[2] < h[1]) return fail_at(ps, at, 0, "cell indices must satisfy 1 <= first-index <= last-index");
        size_t z;
        if (add_zone(ps, 12, h, &z) != CM_OK) return CM_ERR_NOMEM;
    }
    if (body(ps, &has) != CM_OK) return CM_ERR_FORMAT;
    if (!has) return CM_OK;
    /* the cell types of a mixed zone: the faces say the same, so they are skipped */
    if (index != 12) return skip_binary(ps, index);
    return skip_lists(ps, 2);
}

static cm_status push_face(parser *ps, size_t zone, const int64_t *t, int64_t n, int64_t where)
{
    cm_fluent_faces *f = &ps->p->faces;
    if (f->n + 1 >= f->cap) {
        size_t cap = f->cap ? 2 * f->cap : 1024;
        int64_t *o = realloc(f->offset, (cap + 1) * sizeof *o);
        if (o) f->offset = o;
        int64_t *c0 = o ? realloc(f->c0, cap * sizeof *c0) : NULL;
        if (c0) f->c0 = c0;
        int64_t *c1 = c0 ? realloc(f->c1, cap * sizeof *c1) : NULL;
        if (c1) f->c1 = c1;
        int64_t *w = c1 ? realloc(f->where, cap * sizeof *w) : NULL;
        if (w) f->where = w;
        int *zn = w ? realloc(f->zone, cap * sizeof *zn) : NULL;
        if (!zn) return cm_error(ps->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for %zu faces", ps->p->path, cap);
        f->zone = zn;
        f->cap = cap;
        if (f->n == 0) f->offset[0] = 0;
    }
    if (f->n_conn + (size_t)n > f->cap_conn) {
        size_t cap = f->cap_conn ? 2 * f->cap_conn : 4096;
        while (cap < f->n_conn + (size_t)n) cap *= 2;
        int64_t *d = realloc(f->nodes, cap * sizeof *d);
        if (!d) return cm_error(ps->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for face nodes", ps->p->path);
        f->nodes = d;
        f->cap_conn = cap;
    }
    for (int64_t k = 0; k < n; ++k) f->nodes[f->n_conn++] = t[k] - 1;
    f->c0[f->n] = t[n];
    f->c1[f->n] = t[n + 1];
    f->where[f->n] = where;
    f->zone[f->n] = (int)zone;
    f->offset[++f->n] = (int64_t)f->n_conn;
    return CM_OK;
}

/* One face of an ASCII section, on its own line: its numbers into ps->tokens, *n of them. */
static cm_status face_line(parser *ps, size_t *n)
{
    *n = 0;
    skip_space(ps);
    for (;;) {
        skip_blank(ps);
        const char c = peek(ps);
        if (c == '\n' || c == ')' || c == '\0') return CM_OK;
        if (*n == ps->cap_tokens) {
            size_t cap = ps->cap_tokens ? 2 * ps->cap_tokens : 64;
            if (cap > 1 << 16) return fail(ps, "a face with more than 65536 numbers");
            int64_t *t = realloc(ps->tokens, cap * sizeof *t);
            if (!t) return cm_error(ps->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", ps->p->path);
            ps->tokens = t;
            ps->cap_tokens = cap;
        }
        if (number(ps, 16, &ps->tokens[(*n)++], "a hexadecimal face entry") != CM_OK) return CM_ERR_FORMAT;
    }
}

/* Where a face's nodes start in its numbers and how many: face type etype (0 mixed, 3 tri,
 * 4 quad, 5 polygon). A mixed face starts with its type (3, 4, or 5 followed by the count);
 * some writers put the node count first instead, which the line's length tells apart. */
static int face_layout(int64_t etype, const int64_t *t, size_t n, int64_t *skip, int64_t *count)
{
    if (etype == 3 || etype == 4) {
        *skip = 0;
        *count = etype;
    } else if (etype == 5 || (etype == 0 && n >= 1 && (size_t)t[0] + 3 != n)) {
        const size_t k = etype == 5 ? 0 : 1;
        if (n < k + 1 || (etype == 0 && t[0] != 5)) return -1;
        *skip = (int64_t)k + 1;
        *count = t[k];
    } else if (etype == 0 && n >= 1) {
        *skip = 1;
        *count = t[0];
    } else {
        return -1;
    }
    if (*count < 3 || (uint64_t)*count > n || (size_t)(*skip + *count + 2) != n) return -1;
    return 0;
}

/* One face of a binary section (32-bit integers): its nodes, c0 and c1 into t, *n nodes. A
 * mixed face starts with its type (3, 4; 5 followed by the count), a polygon with its count. */
static cm_status binary_face(parser *ps, int64_t etype, int64_t *t, int64_t *n)
{
    const size_t b = ps->pos;
    const size_t lead = etype == 0 ? (size_t)2 : etype == 5 ? 1 : 0;
    int32_t v[2] = {0, 0};
    if (ps->p->size - ps->pos < 4 * lead) return fail_at(ps, b, 1, "the binary face data ends early");
    memcpy(v, ps->p->data + ps->pos, 4 * lead);
    ps->pos += 4 * lead;
    if (etype == 0) {
        if (v[0] == 3 || v[0] == 4) {
            *n = v[0];
            ps->pos -= 4; /* the second number was a node */
        } else if (v[0] == 5) {
            *n = v[1];
        } else {
            return fail_at(ps, b, 1, "unknown face type in a mixed face section");
        }
    } else {
        *n = etype == 5 ? v[0] : etype;
    }
    if (*n < 3 || *n > 65536) return fail_at(ps, b, 1, "a face needs 3 to 65536 nodes");
    if ((uint64_t)(*n + 2) > (ps->p->size - ps->pos) / 4) return fail_at(ps, b, 1, "the binary face data ends early");
    for (int64_t k = 0; k < *n + 2; ++k, ps->pos += 4) {
        int32_t x;
        memcpy(&x, ps->p->data + ps->pos, 4);
        if (x < 0) return fail_at(ps, ps->pos, 1, "a negative node or cell index");
        t[k] = x;
    }
    return CM_OK;
}

static cm_status faces(parser *ps, int64_t index)
{
    const size_t at = ps->pos;
    int64_t h[8];
    int nh = 0, has = 0;
    if (header(ps, h, &nh) != CM_OK) return CM_ERR_FORMAT;
    if (nh < 4) return fail_at(ps, at, 0, "expected (zone-id first-index last-index bc-type [face-type]) in a face section");
    if (nh == 4) h[4] = 0;
    if (body(ps, &has) != CM_OK) return CM_ERR_FORMAT;
    if (h[0] == 0 || !has) return CM_OK; /* the declaration of the face count */
    if (h[1] < 1 || h[2] < h[1]) return fail_at(ps, at, 0, "face indices must satisfy 1 <= first-index <= last-index");
    const int64_t etype = h[4];
    if (etype == 2) return fail_at(ps, at, 0, "line faces (a 2-D mesh) in a 3-D file");
    if (etype != 0 && etype != 3 && etype != 4 && etype != 5)
        return fail_at(ps, at, 0, "unknown face type (expected 0 mixed, 3 triangle, 4 quadrilateral or 5 polygon)");
    const int64_t count = h[2] - h[1] + 1;
    const size_t isize = index == 13 ? 0 : 4;
    if ((uint64_t)count > (ps->p->size - ps->pos) / (isize ? 5 * isize : 10))
        return fail_at(ps, at, 0, "the face section holds more faces than the file has bytes for");
    size_t zone;
    if (add_zone(ps, 13, h, &zone) != CM_OK) return CM_ERR_NOMEM;
    int64_t *t = isize ? malloc((65536 + 2) * sizeof *t) : NULL;
    if (isize && !t) return cm_error(ps->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", ps->p->path);
    cm_status s = CM_OK;
    for (int64_t i = 0; s == CM_OK && i < count; ++i) {
        int64_t skip = 0, n = 0;
        if (!isize) skip_space(ps); /* binary data has no separators */
        const size_t b = ps->pos;
        if (isize) {
            s = binary_face(ps, etype, t, &n);
            if (s == CM_OK) s = push_face(ps, zone, t, n, -1 - (int64_t)b);
            continue;
        }
        size_t nt = 0;
        s = face_line(ps, &nt);
        if (s == CM_OK && nt == 0) s = fail_at(ps, b, 0, "expected a face (the section has fewer faces than its header's count)");
        if (s == CM_OK && face_layout(etype, ps->tokens, nt, &skip, &n) != 0)
            s = fail_at(ps, b, 0, "a face's line does not match its type (nodes, then c0 and c1)");
        if (s == CM_OK) s = push_face(ps, zone, ps->tokens + skip, n, (int64_t)b);
    }
    free(t);
    if (s != CM_OK) return s;
    if (isize) return binary_trailer(ps, index);
    if (expect(ps, ')', "expected ')' after the faces (more faces than the header's count?)") != CM_OK) return CM_ERR_FORMAT;
    return expect(ps, ')', "expected ')' closing the face section");
}

/* (39 (id type name ...) ...) and (45 ...): the name of zone id (decimal), kept for the end
 * (a name may come before or after its zone's section). */
static cm_status zone_name(parser *ps)
{
    int64_t id = 0;
    if (expect(ps, '(', "expected '(' opening the zone's description") != CM_OK) return CM_ERR_FORMAT;
    if (number(ps, 10, &id, "a decimal zone id") != CM_OK) return CM_ERR_FORMAT;
    const char *tok = NULL;
    size_t len = 0;
    for (int k = 0; k < 2; ++k) { /* the zone's type, then its name */
        skip_space(ps);
        const size_t b = ps->pos;
        while (!at_end(ps) && !is_space(peek(ps)) && peek(ps) != ')' && peek(ps) != '(') ++ps->pos;
        if (ps->pos == b) return fail(ps, "expected the zone's type and name");
        tok = ps->p->data + b;
        len = ps->pos - b;
    }
    if (ps->n_names == ps->cap_names) {
        size_t cap = ps->cap_names ? 2 * ps->cap_names : 16;
        struct zone_name_rec *r = realloc(ps->names, cap * sizeof *r);
        if (!r) return cm_error(ps->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", ps->p->path);
        ps->names = r;
        ps->cap_names = cap;
    }
    struct zone_name_rec *r = &ps->names[ps->n_names++];
    r->id = id;
    if (len >= sizeof r->name) len = sizeof r->name - 1;
    memcpy(r->name, tok, len);
    r->name[len] = '\0';
    return skip_lists(ps, 2);
}

static cm_status sections(parser *ps)
{
    for (;;) {
        skip_space(ps);
        if (at_end(ps)) return CM_OK;
        if (peek(ps) != '(') return fail(ps, "expected '(' opening a section");
        ++ps->pos;
        int64_t index = 0;
        if (number(ps, 10, &index, "a section index") != CM_OK) return CM_ERR_FORMAT;
        cm_status s = CM_OK;
        switch (index) {
        case 2: {
            int64_t d = 0;
            if ((s = number(ps, 10, &d, "the dimension")) != CM_OK) return s;
            if (d == 2)
                return fail(ps, "a 2-D Fluent mesh: cadmorph reads 3-D Fluent meshes only (its morphs move volume meshes)");
            if (d != 3) return fail(ps, "the dimension must be 2 or 3");
            ps->p->dim = 3;
            s = expect(ps, ')', "expected ')' closing the dimension section");
            break;
        }
        case 10:
        case 2010:
        case 3010:
            s = nodes(ps, index);
            break;
        case 12:
        case 2012:
        case 3012:
            s = cells(ps, index);
            break;
        case 13:
        case 2013:
        case 3013:
            s = faces(ps, index);
            break;
        case 39:
        case 45:
            s = zone_name(ps);
            break;
        case 58:
        case 59:
        case 61:
        case 2058:
        case 2059:
        case 2061:
        case 3058:
        case 3059:
        case 3061:
            return fail(ps, "hanging-node trees (sections 58, 59, 61) are not read: export the mesh without "
                            "hanging nodes (conformal)");
        default:
            /* every other section keeps its bytes and is skipped: binary ones by their trailer */
            if (index >= 2000 && index < 4000) {
                int64_t h[8];
                int nh = 0, has = 1;
                const size_t save = ps->pos;
                skip_space(ps);
                /* a header of hexadecimal numbers, then the data up to the trailer; a section
                 * without data ends after its header */
                if (peek(ps) != '(' || header(ps, h, &nh) != CM_OK || body(ps, &has) != CM_OK) ps->pos = save;
                s = has ? skip_binary(ps, index) : CM_OK;
            } else {
                s = skip_lists(ps, 1);
            }
        }
        if (s != CM_OK) return s;
    }
}

static void apply_names(parser *ps)
{
    for (size_t i = 0; i < ps->n_names; ++i)
        for (size_t z = 0; z < ps->p->n_zones; ++z)
            if (ps->p->zones[z].id == ps->names[i].id) memcpy(ps->p->zones[z].name, ps->names[i].name, sizeof ps->names[i].name);
}

static cm_status parse(cm_context *ctx, const char *path, const char *data, size_t size, cm_mesh *m)
{
    cm_fluent_parsed p = {.path = path, .data = data, .size = size, .dim = 3};
    parser ps = {.ctx = ctx, .p = &p};
    ps.src = cm_rewrite_source_new();
    if (!ps.src) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", path);
    cm_status s = cm_rewrite_add_file(ctx, ps.src, path, NULL, NULL);
    if (s == CM_OK) s = sections(&ps);
    if (s == CM_OK) apply_names(&ps);
    if (s == CM_OK && p.n_nodes == 0) s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: no nodes (not a Fluent mesh or case file?)", path);
    if (s == CM_OK && (size_t)p.n_nodes > ps.cap_nodes)
        s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %lld nodes declared, but the node sections hold fewer", path,
                     (long long)p.n_nodes);
    for (int64_t i = 0; s == CM_OK && i < p.n_nodes; ++i)
        if (!ps.have[i])
            s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: node %llx (hexadecimal) has no coordinates", path,
                         (unsigned long long)i + 1);
    if (s == CM_OK) s = cm_mesh_resize_nodes(ctx, m, (size_t)p.n_nodes, 0);
    if (s == CM_OK) memcpy(m->xyz, ps.xyz, (size_t)p.n_nodes * 3 * sizeof *m->xyz);
    if (s == CM_OK) s = cm_fluent_build(ctx, &p, m);
    if (s == CM_OK) {
        s = cm_mesh_set_origin(ctx, m, CM_FORMAT_FLUENT, ps.src, cm_rewrite_source_free);
        ps.src = NULL;
    }
    cm_rewrite_source_free(ps.src);
    free(ps.xyz);
    free(ps.have);
    free(ps.tokens);
    free(ps.names);
    free(p.faces.offset);
    free(p.faces.nodes);
    free(p.faces.c0);
    free(p.faces.c1);
    free(p.faces.where);
    free(p.faces.zone);
    free(p.zones);
    return s;
}

cm_status cm_mesh_read_fluent(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    return cm_mesh_read_whole(ctx, "cm_mesh_read", path, parse, mesh);
}

int cm_fluent_sniff(const char *head, size_t n)
{
    size_t i = 0;
    if (n >= 3 && (unsigned char)head[0] == 0xef && (unsigned char)head[1] == 0xbb && (unsigned char)head[2] == 0xbf) i = 3;
    while (i < n && is_space(head[i])) ++i;
    if (i >= n || head[i++] != '(') return 0;
    while (i < n && (head[i] == ' ' || head[i] == '\t')) ++i;
    const size_t d = i;
    while (i < n && head[i] >= '0' && head[i] <= '9') ++i;
    return i > d && i < n && (is_space(head[i]) || head[i] == '(' || head[i] == '"');
}
