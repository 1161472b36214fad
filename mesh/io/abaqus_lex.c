/* Abaqus input decks (abaqus_internal.h): the element types, lines, comma-separated fields,
 * numbers and keyword lines, and the sets the reader fills (found through a hash of their
 * names, case-insensitive as Abaqus's names are). */
#define _POSIX_C_SOURCE 200809L
#include "abaqus_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Abaqus wedge: the triangle 1-2-3 turns towards 4-5-6 (VTK's turns away: CalculiX ccx
 * reports a nonpositive Jacobian for VTK's order), so corners 2<->3 and 5<->6 and their edges
 * swap; its own inverse. */
static const int wedge6_perm[6] = {0, 2, 1, 3, 5, 4};
static const int wedge15_perm[15] = {0, 2, 1, 3, 5, 4, 8, 7, 6, 11, 10, 9, 12, 14, 13};

typedef struct abq_family {
    const char *prefix;
    int dim; /* 3 solid, 2 surface, 1 line */
} abq_family;

static const abq_family families[] = {
    {"C3D", 3}, {"SFM3D", 2}, {"M3D", 2}, {"R3D", 2}, {"CPS", 2}, {"CPE", 2}, {"CAX", 2},
    {"S", 2},   {"T3D", 1},   {"T2D", 1},
};

int abq_element_type(const char *name, abq_type *t)
{
    t->perm = NULL;
    if (!strcmp(name, "STRI3")) return t->nodes = 3, t->type = CM_CELL_TRI3, 1;
    if (!strcmp(name, "STRI65")) return t->nodes = 6, t->type = CM_CELL_TRI6, 1;
    /* beams: B21, B31H, the cubic B23, B33 (2 nodes); B22, B32H (3 nodes) */
    if (name[0] == 'B' && (name[1] == '2' || name[1] == '3') && name[2] >= '1' && name[2] <= '3' &&
        (!name[3] || !strcmp(name + 3, "H")))
        return name[2] != '2' ? (t->nodes = 2, t->type = CM_CELL_LINE2, 1) : (t->nodes = 3, t->type = CM_CELL_LINE3, 1);
    for (size_t i = 0; i < sizeof families / sizeof *families; ++i) {
        const size_t l = strlen(families[i].prefix);
        if (strncmp(name, families[i].prefix, l) || !isdigit((unsigned char)name[l])) continue;
        char *end;
        const long n = strtol(name + l, &end, 10);
        /* what follows the node count is the formulation (R, H, I, M, T, RS, R5, ...): letters,
         * or digits after a letter */
        if (*end && !isalpha((unsigned char)*end)) return 0;
        for (const char *p = end; *p; ++p)
            if (!isalnum((unsigned char)*p)) return 0;
        if (families[i].dim == 3) {
            switch (n) {
            case 4: return t->nodes = 4, t->type = CM_CELL_TET4, 1;
            case 5: return t->nodes = 5, t->type = CM_CELL_PYR5, 1;
            case 6: return t->nodes = 6, t->type = CM_CELL_WEDGE6, t->perm = wedge6_perm, 1;
            case 8: return t->nodes = 8, t->type = CM_CELL_HEX8, 1;
            case 10: return t->nodes = 10, t->type = CM_CELL_TET10, 1;
            case 15: return t->nodes = 15, t->type = CM_CELL_WEDGE15, t->perm = wedge15_perm, 1;
            case 20: return t->nodes = 20, t->type = CM_CELL_HEX20, 1;
            default: return 0;
            }
        }
        if (families[i].dim == 2) {
            switch (n) {
            case 3: return t->nodes = 3, t->type = CM_CELL_TRI3, 1;
            case 4: return t->nodes = 4, t->type = CM_CELL_QUAD4, 1;
            case 6: return t->nodes = 6, t->type = CM_CELL_TRI6, 1;
            case 8: return t->nodes = 8, t->type = CM_CELL_QUAD8, 1;
            case 9: return t->nodes = 9, t->type = CM_CELL_QUAD9, 1;
            default: return 0;
            }
        }
        if (n == 2) return t->nodes = 2, t->type = CM_CELL_LINE2, 1;
        if (n == 3) return t->nodes = 3, t->type = CM_CELL_LINE3, 1;
        return 0;
    }
    return 0;
}

/* ---- lines and fields ---- */


int abq_next_line(abq_file *f, const char **b, const char **e)
{
    if (f->pos >= f->n) return 0;
    const char *p = f->d + f->pos, *end = f->d + f->n;
    const char *nl = memchr(p, '\n', (size_t)(end - p));
    const char *q = nl ? nl : end;
    f->pos = (size_t)(q - f->d) + (nl ? 1 : 0);
    ++f->line;
    while (q > p && (q[-1] == '\r')) --q;
    *b = p;
    *e = q;
    return 1;
}

int abq_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\f' || c == '\v' || c == '\r';
}

/* The next comma-separated field of [*p, e), trimmed: 0 when none is left. A trailing comma
 * ends the fields (it continues the line). */
int abq_next_field(const char **p, const char *e, const char **fb, const char **fe)
{
    const char *q = *p;
    while (q < e && abq_blank(*q)) ++q;
    if (q >= e) return 0;
    const char *s = q;
    while (q < e && *q != ',') ++q;
    const char *t = q;
    while (t > s && abq_blank(t[-1])) --t;
    *fb = s;
    *fe = t;
    *p = q < e ? q + 1 : e;
    return 1;
}

int abq_ends_with_comma(const char *b, const char *e)
{
    while (e > b && abq_blank(e[-1])) --e;
    return e > b && e[-1] == ',';
}

cm_status abq_err(abq_reader *r, const abq_file *f, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s:%ld: %s", f->path, f->line, msg);
}

/* A coordinate: empty is 0 (Abaqus's rule for blank fields); finite only. */
int abq_parse_coord(const char *b, const char *e, double *v)
{
    char buf[64], *end;
    const size_t n = (size_t)(e - b);
    if (n == 0) return *v = 0.0, 1;
    if (n >= sizeof buf) return 0;
    memcpy(buf, b, n);
    buf[n] = '\0';
    for (size_t i = 0; i < n; ++i)
        if (!strchr("0123456789+-.eEdD", buf[i])) return 0;
    for (size_t i = 0; i < n; ++i)
        if (buf[i] == 'd' || buf[i] == 'D') buf[i] = 'e'; /* Fortran's double exponent */
    *v = strtod(buf, &end);
    return *end == '\0' && isfinite(*v);
}

const char *abq_show(const char *b, const char *e, char *buf, size_t cap)
{
    size_t n = (size_t)(e - b);
    if (n >= cap) n = cap - 1;
    memcpy(buf, b, n);
    buf[n] = '\0';
    return buf;
}

/* ---- keyword lines ---- */


void abq_upper(char *dst, size_t cap, const char *b, const char *e)
{
    size_t k = 0;
    for (; b < e && k + 1 < cap; ++b)
        if (!abq_blank(*b)) dst[k++] = (char)toupper((unsigned char)*b);
    dst[k] = '\0';
}

cm_status abq_parse_keyword(abq_reader *r, abq_file *f, const char *b, const char *e, abq_keyword *kw)
{
    /* the line with its continuations, in one buffer */
    char text[8192];
    size_t n = 0;
    for (;;) {
        if (n + (size_t)(e - b) >= sizeof text) return abq_err(r, f, "expected a keyword line shorter than %zu bytes", sizeof text);
        memcpy(text + n, b, (size_t)(e - b));
        n += (size_t)(e - b);
        if (!abq_ends_with_comma(b, e)) break;
        if (!abq_next_line(f, &b, &e)) break;
    }
    const char *p = text + 1, *end = text + n; /* past the '*' */
    const char *fb, *fe;
    memset(kw, 0, sizeof *kw);
    /* fields split at commas outside double quotes */
    int first = 1;
    while (p < end) {
        while (p < end && abq_blank(*p)) ++p;
        if (p >= end) break;
        const char *s = p;
        int quoted = 0;
        while (p < end && (quoted || *p != ',')) {
            if (*p == '"') quoted = !quoted;
            ++p;
        }
        fb = s;
        fe = p;
        while (fe > fb && abq_blank(fe[-1])) --fe;
        if (p < end) ++p;
        if (first) {
            abq_upper(kw->key, sizeof kw->key, fb, fe);
            first = 0;
            continue;
        }
        if (fb == fe) continue;
        if (kw->n == KW_MAX_PARAMS) return abq_err(r, f, "expected at most %d parameters on a keyword line", KW_MAX_PARAMS);
        const char *eq = memchr(fb, '=', (size_t)(fe - fb));
        const char *ne = eq ? eq : fe;
        abq_upper(kw->name[kw->n], sizeof kw->name[kw->n], fb, ne);
        if (eq) {
            const char *vb = eq + 1, *ve = fe;
            while (vb < ve && abq_blank(*vb)) ++vb;
            if (ve - vb >= 2 && *vb == '"' && ve[-1] == '"') ++vb, --ve;
            if ((size_t)(ve - vb) >= KW_VALUE) return abq_err(r, f, "expected a parameter value shorter than %d bytes", KW_VALUE);
            memcpy(kw->value[kw->n], vb, (size_t)(ve - vb));
            kw->value[kw->n][ve - vb] = '\0';
            kw->has_value[kw->n] = 1;
        }
        ++kw->n;
    }
    return CM_OK;
}

const char *abq_param(const abq_keyword *kw, const char *name)
{
    for (int i = 0; i < kw->n; ++i)
        if (!strcmp(kw->name[i], name)) return kw->has_value[i] ? kw->value[i] : "";
    return NULL;
}

/* ---- sets ---- */

int abq_name_eq(const char *a, const char *b)
{
    return strcasecmp(a, b) == 0;
}

char *abq_dup(const char *s)
{
    const size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

cm_status abq_set_add(abq_reader *r, abq_set *s, int64_t inst, int64_t id, int face)
{
    if (s->n == s->cap) {
        const size_t cap = s->cap ? 2 * s->cap : 16;
        int64_t *a = realloc(s->inst, cap * sizeof *a);
        if (a) s->inst = a;
        int64_t *b = a ? realloc(s->id, cap * sizeof *b) : NULL;
        if (b) s->id = b;
        unsigned char *c = b ? realloc(s->face, cap) : NULL;
        if (c) s->face = c;
        if (!c) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory for set %s", s->name);
        s->cap = cap;
    }
    s->inst[s->n] = inst;
    s->id[s->n] = id;
    s->face[s->n] = (unsigned char)face;
    ++s->n;
    return CM_OK;
}

/* Room for item n of an array of n: grown when n is 0 or a power of 2 (to 2n + 1), so that
 * appending one at a time costs amortised linear time. */
void *abq_grow(void *a, size_t n, size_t size)
{
    if (n && (n & (n - 1))) return a;
    return realloc(a, (2 * n + 1) * size);
}

static size_t set_hash(int part, int kind, const char *name)
{
    uint64_t h = 1469598103934665603ull ^ (uint64_t)(part * 4 + kind);
    for (const char *p = name; *p; ++p) h = (h ^ (unsigned char)toupper((unsigned char)*p)) * 1099511628211ull;
    return (size_t)(h ^ (h >> 29));
}

/* The set of (part, kind, name) or -1, through the hash. */
static int lookup_set(const abq_reader *r, int part, int kind, const char *name)
{
    if (!r->set_slots) return -1;
    for (size_t i = set_hash(part, kind, name) & r->set_mask;; i = (i + 1) & r->set_mask) {
        const int k = r->set_slots[i];
        if (k < 0) return -1;
        if (r->sets[k].part == part && r->sets[k].kind == kind && abq_name_eq(r->sets[k].name, name)) return k;
    }
}

/* Set k entered in the hash (grown to twice the sets and more). */
static int hash_set(abq_reader *r, int k)
{
    if (!r->set_slots || 2 * (size_t)(k + 1) > r->set_mask + 1) {
        const size_t cap = r->set_slots ? 2 * (r->set_mask + 1) : 64;
        int *slots = malloc(cap * sizeof *slots);
        if (!slots) return 0;
        for (size_t i = 0; i < cap; ++i) slots[i] = -1;
        free(r->set_slots);
        r->set_slots = slots;
        r->set_mask = cap - 1;
        for (int j = 0; j < k; ++j) {
            size_t i = set_hash(r->sets[j].part, r->sets[j].kind, r->sets[j].name) & r->set_mask;
            while (slots[i] >= 0) i = (i + 1) & r->set_mask;
            slots[i] = j;
        }
    }
    size_t i = set_hash(r->sets[k].part, r->sets[k].kind, r->sets[k].name) & r->set_mask;
    while (r->set_slots[i] >= 0) i = (i + 1) & r->set_mask;
    r->set_slots[i] = k;
    return 1;
}

int abq_find_set(const abq_reader *r, int part, int kind, const char *name, int64_t *inst)
{
    *inst = -1;
    const int k = lookup_set(r, part, kind, name);
    if (k >= 0 || part != 0) return k;
    /* "instance.set" from the assembly: the set of the instance's part */
    const char *dot = strrchr(name, '.');
    if (!dot) return -1;
    for (size_t j = 0; j < r->n_insts; ++j) {
        const char *in = r->insts[j].name;
        if (strlen(in) != (size_t)(dot - name) || strncasecmp(in, name, (size_t)(dot - name))) continue;
        const int s = lookup_set(r, r->insts[j].part, kind, dot + 1);
        if (s >= 0) *inst = (int64_t)j;
        return s;
    }
    return -1;
}

/* The set of kind named name in scope part, made when new. */
cm_status abq_get_set(abq_reader *r, abq_file *f, int part, int kind, const char *name, int *index)
{
    if (!*name) return abq_err(r, f, "expected a set name");
    const int k = lookup_set(r, part, kind, name);
    if (k >= 0) {
        *index = k;
        return CM_OK;
    }
    if (r->n_sets >= INT32_MAX / 4) return abq_err(r, f, "expected fewer sets");
    abq_set *sets = abq_grow(r->sets, r->n_sets, sizeof *sets);
    if (!sets) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    r->sets = sets;
    memset(&sets[r->n_sets], 0, sizeof *sets);
    sets[r->n_sets].name = abq_dup(name);
    if (!sets[r->n_sets].name) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    sets[r->n_sets].kind = kind;
    sets[r->n_sets].part = part;
    *index = (int)r->n_sets++;
    if (!hash_set(r, *index)) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    return CM_OK;
}

/* Members copied from set `from` (qualified by instance `inst`, or its own), with face. */
cm_status abq_copy_set(abq_reader *r, abq_file *f, int to, int from, int64_t inst, int face)
{
    const size_t n = r->sets[from].n;
    /* a bound on what sets may hold together: a deck that names a large set over and over
     * would otherwise grow without limit */
    const size_t bound = 16 * (r->nn + r->m->n_cells) + 65536;
    if (n > bound || r->members > bound - n)
        return abq_err(r, f, "expected sets of at most %zu members in all (a large set named again and again?)", bound);
    r->members += n;
    for (size_t i = 0; i < n; ++i) {
        const abq_set *s = &r->sets[from];
        const int64_t in = s->inst[i] >= 0 ? s->inst[i] : inst;
        cm_status st = abq_set_add(r, &r->sets[to], in, s->id[i], face >= 0 ? face : s->face[i]);
        if (st != CM_OK) return st;
    }
    return CM_OK;
}
