/* Abaqus input decks (.inp): lines, keywords and their data (abaqus_internal.h). Keywords and
 * parameters are case-insensitive, "**" starts a comment line, blank lines are skipped, a line
 * ending in ',' continues a keyword line or an element's node list. *INCLUDE (and INPUT= on
 * *NODE and *ELEMENT) is transparent: the included lines continue the keyword block they are
 * read in, so a *NODE block may take its data lines from another file. What the deck says
 * beyond the mesh (materials, steps, loads) is skipped here and kept byte for byte by the
 * writer. */
#define _POSIX_C_SOURCE 200809L
#include "abaqus_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

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

typedef struct abq_file {
    const char *path;
    const char *d;
    size_t n, pos;
    long line;      /* of the line last taken */
    size_t index;   /* in the rewrite source */
    const char *name; /* relative to the main file's directory (NULL: the main file) */
} abq_file;

static int next_line(abq_file *f, const char **b, const char **e)
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

static int blank(char c)
{
    return c == ' ' || c == '\t' || c == '\f' || c == '\v' || c == '\r';
}

/* The next comma-separated field of [*p, e), trimmed: 0 when none is left. A trailing comma
 * ends the fields (it continues the line). */
static int next_field(const char **p, const char *e, const char **fb, const char **fe)
{
    const char *q = *p;
    while (q < e && blank(*q)) ++q;
    if (q >= e) return 0;
    const char *s = q;
    while (q < e && *q != ',') ++q;
    const char *t = q;
    while (t > s && blank(t[-1])) --t;
    *fb = s;
    *fe = t;
    *p = q < e ? q + 1 : e;
    return 1;
}

static int ends_with_comma(const char *b, const char *e)
{
    while (e > b && blank(e[-1])) --e;
    return e > b && e[-1] == ',';
}

static cm_status err(abq_reader *r, const abq_file *f, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static cm_status err(abq_reader *r, const abq_file *f, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s:%ld: %s", f->path, f->line, msg);
}

/* An integer: an optional sign and digits, no overflow. */
static int parse_int(const char *b, const char *e, int64_t *v)
{
    int neg = 0;
    if (b < e && (*b == '+' || *b == '-')) neg = *b++ == '-';
    if (b == e) return 0;
    uint64_t x = 0;
    for (; b < e; ++b) {
        const unsigned d = (unsigned)(*b - '0');
        if (d > 9 || x > (UINT64_C(9223372036854775807) - d) / 10) return 0;
        x = 10 * x + d;
    }
    *v = neg ? -(int64_t)x : (int64_t)x;
    return 1;
}

/* A coordinate: empty is 0 (Abaqus's rule for blank fields); finite only. */
static int parse_coord(const char *b, const char *e, double *v)
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

static const char *show(const char *b, const char *e, char *buf, size_t cap)
{
    size_t n = (size_t)(e - b);
    if (n >= cap) n = cap - 1;
    memcpy(buf, b, n);
    buf[n] = '\0';
    return buf;
}

/* ---- keyword lines ---- */

enum { KW_MAX_PARAMS = 24, KW_VALUE = 1024 };

typedef struct abq_keyword {
    char key[48]; /* upper case, blanks removed, without '*' */
    int n;
    char name[KW_MAX_PARAMS][32];
    char value[KW_MAX_PARAMS][KW_VALUE];
    int has_value[KW_MAX_PARAMS];
} abq_keyword;

static void upper_squeeze(char *dst, size_t cap, const char *b, const char *e)
{
    size_t k = 0;
    for (; b < e && k + 1 < cap; ++b)
        if (!blank(*b)) dst[k++] = (char)toupper((unsigned char)*b);
    dst[k] = '\0';
}

static cm_status parse_keyword(abq_reader *r, abq_file *f, const char *b, const char *e, abq_keyword *kw)
{
    /* the line with its continuations, in one buffer */
    char text[8192];
    size_t n = 0;
    for (;;) {
        if (n + (size_t)(e - b) >= sizeof text) return err(r, f, "expected a keyword line shorter than %zu bytes", sizeof text);
        memcpy(text + n, b, (size_t)(e - b));
        n += (size_t)(e - b);
        if (!ends_with_comma(b, e)) break;
        if (!next_line(f, &b, &e)) break;
    }
    const char *p = text + 1, *end = text + n; /* past the '*' */
    const char *fb, *fe;
    memset(kw, 0, sizeof *kw);
    /* fields split at commas outside double quotes */
    int first = 1;
    while (p < end) {
        while (p < end && blank(*p)) ++p;
        if (p >= end) break;
        const char *s = p;
        int quoted = 0;
        while (p < end && (quoted || *p != ',')) {
            if (*p == '"') quoted = !quoted;
            ++p;
        }
        fb = s;
        fe = p;
        while (fe > fb && blank(fe[-1])) --fe;
        if (p < end) ++p;
        if (first) {
            upper_squeeze(kw->key, sizeof kw->key, fb, fe);
            first = 0;
            continue;
        }
        if (fb == fe) continue;
        if (kw->n == KW_MAX_PARAMS) return err(r, f, "expected at most %d parameters on a keyword line", KW_MAX_PARAMS);
        const char *eq = memchr(fb, '=', (size_t)(fe - fb));
        const char *ne = eq ? eq : fe;
        upper_squeeze(kw->name[kw->n], sizeof kw->name[kw->n], fb, ne);
        if (eq) {
            const char *vb = eq + 1, *ve = fe;
            while (vb < ve && blank(*vb)) ++vb;
            if (ve - vb >= 2 && *vb == '"' && ve[-1] == '"') ++vb, --ve;
            if ((size_t)(ve - vb) >= KW_VALUE) return err(r, f, "expected a parameter value shorter than %d bytes", KW_VALUE);
            memcpy(kw->value[kw->n], vb, (size_t)(ve - vb));
            kw->value[kw->n][ve - vb] = '\0';
            kw->has_value[kw->n] = 1;
        }
        ++kw->n;
    }
    return CM_OK;
}

static const char *param(const abq_keyword *kw, const char *name)
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

static char *dup_text(const char *s)
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
static void *grow(void *a, size_t n, size_t size)
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
static cm_status get_set(abq_reader *r, abq_file *f, int part, int kind, const char *name, int *index)
{
    if (!*name) return err(r, f, "expected a set name");
    const int k = lookup_set(r, part, kind, name);
    if (k >= 0) {
        *index = k;
        return CM_OK;
    }
    if (r->n_sets >= INT32_MAX / 4) return err(r, f, "expected fewer sets");
    abq_set *sets = grow(r->sets, r->n_sets, sizeof *sets);
    if (!sets) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    r->sets = sets;
    memset(&sets[r->n_sets], 0, sizeof *sets);
    sets[r->n_sets].name = dup_text(name);
    if (!sets[r->n_sets].name) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    sets[r->n_sets].kind = kind;
    sets[r->n_sets].part = part;
    *index = (int)r->n_sets++;
    if (!hash_set(r, *index)) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    return CM_OK;
}

/* Members copied from set `from` (qualified by instance `inst`, or its own), with face. */
static cm_status copy_set(abq_reader *r, abq_file *f, int to, int from, int64_t inst, int face)
{
    const size_t n = r->sets[from].n;
    /* a bound on what sets may hold together: a deck that names a large set over and over
     * would otherwise grow without limit */
    const size_t bound = 16 * (r->nn + r->m->n_cells) + 65536;
    if (n > bound || r->members > bound - n)
        return err(r, f, "expected sets of at most %zu members in all (a large set named again and again?)", bound);
    r->members += n;
    for (size_t i = 0; i < n; ++i) {
        const abq_set *s = &r->sets[from];
        const int64_t in = s->inst[i] >= 0 ? s->inst[i] : inst;
        cm_status st = abq_set_add(r, &r->sets[to], in, s->id[i], face >= 0 ? face : s->face[i]);
        if (st != CM_OK) return st;
    }
    return CM_OK;
}

/* ---- the reader's state between lines ---- */

enum { B_NONE, B_NODE, B_ELEMENT, B_NSET, B_ELSET, B_SURFACE, B_INSTANCE, B_SKIP_ELEMENT };

typedef struct abq_block {
    int kind;
    int set;              /* NSET= of *NODE, ELSET= of *ELEMENT, the set of a set or surface block */
    int generate;
    int64_t inst;         /* INSTANCE= of a set: the instance its ids are in (-1: own) */
    int node_surface;     /* *SURFACE, TYPE=NODE */
    abq_type type;
    char type_name[32];
    int64_t vals[21];     /* an element being read: id and nodes */
    int have;
    int inst_lines;       /* data lines of *INSTANCE taken */
} abq_block;

static cm_status parse_file(abq_reader *r, abq_block *blk, const char *path, const char *name);

static cm_status touch_nodes(abq_reader *r, abq_file *f)
{
    abq_part *p = &r->parts[r->cur];
    if (!p->used || p->node1 == p->node0) {
        if (p->node1 == p->node0) p->node0 = p->node1 = r->nn;
    } else if (p->node1 != r->nn)
        return err(r, f, "expected the nodes of %s in one stretch of the deck (parts first, then the assembly)",
                   r->cur ? p->name : "the model");
    if (r->cur == 0 && r->any_part && !r->in_assembly)
        return err(r, f, "expected *NODE inside *PART or *ASSEMBLY in a deck with parts");
    p->used = 1;
    return CM_OK;
}

static cm_status touch_cells(abq_reader *r, abq_file *f)
{
    abq_part *p = &r->parts[r->cur];
    if (p->cell1 == p->cell0) p->cell0 = p->cell1 = r->m->n_cells;
    else if (p->cell1 != r->m->n_cells)
        return err(r, f, "expected the elements of %s in one stretch of the deck (parts first, then the assembly)",
                   r->cur ? p->name : "the model");
    if (r->cur == 0 && r->any_part && !r->in_assembly)
        return err(r, f, "expected *ELEMENT inside *PART or *ASSEMBLY in a deck with parts");
    p->used = 1;
    return CM_OK;
}

static cm_status node_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    char show_buf[48];
    int64_t id;
    if (!next_field(&p, e, &fb, &fe) || !parse_int(fb, fe, &id))
        return err(r, f, "expected a node id, got '%s'", show(b, e, show_buf, sizeof show_buf));
    if (id < 1) return err(r, f, "expected a node id >= 1, got %lld", (long long)id);
    const char *span = p;
    if (span > e) span = e;
    double x[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
        const char *q = p;
        if (!next_field(&q, e, &fb, &fe)) break;
        if (!parse_coord(fb, fe, &x[k]))
            return err(r, f, "expected a finite coordinate of node %lld, got '%s'", (long long)id, show(fb, fe, show_buf, sizeof show_buf));
        p = q;
    }
    cm_status s = touch_nodes(r, f);
    if (s != CM_OK) return s;
    cm_mesh *m = r->m;
    if (r->nn == m->n_nodes) {
        s = cm_mesh_resize_nodes(r->ctx, m, m->n_nodes < 1024 ? 1024 : 2 * m->n_nodes, 1);
        if (s != CM_OK) return s;
    }
    memcpy(m->xyz + 3 * r->nn, x, sizeof x);
    m->node_tag[r->nn] = id;
    s = cm_rewrite_add_span(r->ctx, r->src, f->index, span - f->d, e - span, (int64_t)r->nn, -1);
    if (s == CM_OK && blk->set >= 0) s = abq_set_add(r, &r->sets[blk->set], -1, id, 0);
    ++r->nn;
    r->parts[r->cur].node1 = r->nn;
    return s;
}

static cm_status finish_element(abq_reader *r, abq_file *f, abq_block *blk)
{
    int64_t v[20];
    for (int k = 0; k < blk->type.nodes; ++k) v[k] = blk->vals[1 + (blk->type.perm ? blk->type.perm[k] : k)];
    cm_status s = touch_cells(r, f);
    if (s == CM_OK) s = cm_mesh_add_cell(r->ctx, r->m, blk->type.type, v, (size_t)blk->type.nodes, 0, 0, blk->vals[0]);
    if (s == CM_OK && blk->set >= 0) s = abq_set_add(r, &r->sets[blk->set], -1, blk->vals[0], 0);
    r->parts[r->cur].cell1 = r->m->n_cells;
    blk->have = 0;
    return s;
}

static cm_status element_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    char show_buf[48];
    const int want = blk->type.nodes + 1;
    while (next_field(&p, e, &fb, &fe)) {
        int64_t v;
        if (blk->have == want)
            return err(r, f, "expected %d nodes for element %lld of type %s, got more", want - 1,
                       (long long)blk->vals[0], blk->type_name);
        if (!parse_int(fb, fe, &v))
            return err(r, f, "expected an %s, got '%s'", blk->have ? "element's node id" : "element id",
                       show(fb, fe, show_buf, sizeof show_buf));
        if (v < 1) return err(r, f, "expected an id >= 1, got %lld", (long long)v);
        blk->vals[blk->have++] = v;
    }
    if (blk->have == want) return finish_element(r, f, blk);
    return CM_OK; /* the node list continues on the next line */
}

static cm_status set_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    char show_buf[48];
    abq_set *s = &r->sets[blk->set];
    const int kind = s->kind;
    if (blk->generate) {
        int64_t v[3] = {0, 0, 1};
        int k = 0;
        while (next_field(&p, e, &fb, &fe)) {
            if (k == 3 || !parse_int(fb, fe, &v[k]))
                return err(r, f, "expected 'first, last[, increment]' of GENERATE, got '%s'", show(b, e, show_buf, sizeof show_buf));
            ++k;
        }
        if (k < 2) return err(r, f, "expected 'first, last[, increment]' of GENERATE");
        if (v[0] < 1 || v[1] < v[0] || v[2] < 1)
            return err(r, f, "expected 1 <= first <= last and an increment >= 1, got %lld, %lld, %lld",
                       (long long)v[0], (long long)v[1], (long long)v[2]);
        const uint64_t count = (uint64_t)(v[1] - v[0]) / (uint64_t)v[2] + 1;
        const size_t bound = 16 * (r->nn + r->m->n_cells) + 65536;
        if (count > bound || r->members > bound - count)
            return err(r, f, "expected a GENERATE range within the deck's ids, got %llu members", (unsigned long long)count);
        r->members += count;
        for (uint64_t i = 0; i < count; ++i) {
            cm_status st = abq_set_add(r, &r->sets[blk->set], blk->inst, v[0] + (int64_t)i * v[2], 0);
            if (st != CM_OK) return st;
        }
        return CM_OK;
    }
    while (next_field(&p, e, &fb, &fe)) {
        int64_t v;
        if (fb == fe) continue;
        if (parse_int(fb, fe, &v)) {
            if (v < 1) return err(r, f, "expected an id >= 1, got %lld", (long long)v);
            cm_status st = abq_set_add(r, &r->sets[blk->set], blk->inst, v, 0);
            if (st != CM_OK) return st;
            ++r->members;
            continue;
        }
        char name[256];
        show(fb, fe, name, sizeof name);
        int64_t inst = -1;
        const int part = blk->inst >= 0 ? r->insts[blk->inst].part : r->cur;
        const int from = abq_find_set(r, part, kind, name, &inst);
        if (from < 0 || from == blk->set)
            return err(r, f, "expected a %s id or the name of a set defined before, got '%s'",
                       kind == ABQ_NSET ? "node" : "element", show(fb, fe, show_buf, sizeof show_buf));
        cm_status st = copy_set(r, f, blk->set, from, inst >= 0 ? inst : blk->inst, -1);
        if (st != CM_OK) return st;
    }
    return CM_OK;
}

static cm_status surface_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    char show_buf[48], name[256];
    if (!next_field(&p, e, &fb, &fe)) return CM_OK;
    show(fb, fe, name, sizeof name);
    int face = 0;
    if (!blk->node_surface) {
        const char *lb, *le;
        char label[16];
        face = 7; /* a shell's own side when no label */
        if (next_field(&p, e, &lb, &le)) {
            upper_squeeze(label, sizeof label, lb, le);
            if (label[0] == 'S' && label[1] >= '1' && label[1] <= '6' && !label[2]) face = label[1] - '0';
            else if (!strcmp(label, "SPOS")) face = 7;
            else if (!strcmp(label, "SNEG")) face = 8;
            else return err(r, f, "expected a face label S1..S6, SPOS or SNEG, got '%s'", show(lb, le, show_buf, sizeof show_buf));
        }
    }
    int64_t v;
    if (parse_int(fb, fe, &v)) {
        if (v < 1) return err(r, f, "expected an id >= 1, got %lld", (long long)v);
        ++r->members;
        return abq_set_add(r, &r->sets[blk->set], -1, v, face);
    }
    int64_t inst = -1;
    const int from = abq_find_set(r, r->cur, blk->node_surface ? ABQ_NSET : ABQ_ELSET, name, &inst);
    if (from < 0)
        return err(r, f, "expected an %s id or the name of a set defined before, got '%s'",
                   blk->node_surface ? "node" : "element", show(fb, fe, show_buf, sizeof show_buf));
    return copy_set(r, f, blk->set, from, inst, face);
}

/* Translation, then the rotation about a->b by an angle in degrees. */
static cm_status instance_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    const char *p = b, *fb, *fe;
    double v[7] = {0};
    int k = 0;
    char show_buf[48];
    const int want = blk->inst_lines == 0 ? 3 : 7;
    if (blk->inst_lines >= 2) return err(r, f, "expected at most two data lines of *INSTANCE");
    while (next_field(&p, e, &fb, &fe)) {
        if (k == want || !parse_coord(fb, fe, &v[k]))
            return err(r, f, "expected %d numbers on this *INSTANCE line, got '%s'", want, show(b, e, show_buf, sizeof show_buf));
        ++k;
    }
    abq_xform *x = &r->insts[r->n_insts - 1].x;
    if (blk->inst_lines++ == 0) {
        for (int i = 0; i < 3; ++i) x->c[i] += v[i];
    } else {
        double a[3] = {v[0], v[1], v[2]}, d[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]};
        const double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(len > 0)) return err(r, f, "expected two distinct points on the rotation axis");
        for (int i = 0; i < 3; ++i) d[i] /= len;
        const double th = v[6] * acos(-1.0) / 180.0, cs = cos(th), sn = sin(th), t = 1 - cs;
        const double R[9] = {cs + d[0] * d[0] * t, d[0] * d[1] * t - d[2] * sn, d[0] * d[2] * t + d[1] * sn,
                             d[1] * d[0] * t + d[2] * sn, cs + d[1] * d[1] * t, d[1] * d[2] * t - d[0] * sn,
                             d[2] * d[0] * t - d[1] * sn, d[2] * d[1] * t + d[0] * sn, cs + d[2] * d[2] * t};
        /* global = a + R (r local + c - a) */
        double nr[9], nc[3];
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                nr[3 * i + j] = R[3 * i] * x->r[j] + R[3 * i + 1] * x->r[3 + j] + R[3 * i + 2] * x->r[6 + j];
            nc[i] = a[i] + R[3 * i] * (x->c[0] - a[0]) + R[3 * i + 1] * (x->c[1] - a[1]) + R[3 * i + 2] * (x->c[2] - a[2]);
        }
        memcpy(x->r, nr, sizeof nr);
        memcpy(x->c, nc, sizeof nc);
    }
    r->insts[r->n_insts - 1].moved = 1;
    return CM_OK;
}

/* A block left when the next keyword (or the end) comes. */
static cm_status end_block(abq_reader *r, abq_file *f, abq_block *blk)
{
    if (blk->kind == B_ELEMENT && blk->have)
        return err(r, f, "expected %d nodes for element %lld of type %s, got %d (truncated?)", blk->type.nodes,
                   (long long)blk->vals[0], blk->type_name, blk->have - 1);
    return CM_OK;
}

/* The file named by INPUT=, relative to the directory of the file that names it; *full and
 * *rel (relative to the main file's directory, or absolute) are allocated. */
static cm_status include_path(abq_reader *r, abq_file *f, const char *input, char **full, char **rel)
{
    *full = *rel = NULL;
    if (!*input) return err(r, f, "expected INPUT=<file>");
    const char *ref[2] = {f->path, f->name ? f->name : ""};
    char *out[2] = {NULL, NULL};
    for (int k = 0; k < 2; ++k) {
        const char *slash = strrchr(ref[k], '/');
        const size_t dir = input[0] == '/' || !slash ? 0 : (size_t)(slash - ref[k]) + 1;
        out[k] = malloc(dir + strlen(input) + 1);
        if (!out[k]) {
            free(out[0]);
            return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        }
        memcpy(out[k], ref[k], dir);
        strcpy(out[k] + dir, input);
    }
    *full = out[0];
    *rel = out[1];
    return CM_OK;
}

static cm_status include(abq_reader *r, abq_file *f, abq_block *blk, const char *input)
{
    char *full, *rel;
    cm_status s = include_path(r, f, input, &full, &rel);
    if (s != CM_OK) return s;
    struct stat st;
    if (stat(full, &st) != 0) s = err(r, f, "cannot open the included file %s: %s", full, strerror(errno));
    for (int k = 0; s == CM_OK && k < r->depth; ++k)
        if (r->dev[k] == st.st_dev && r->ino[k] == st.st_ino) s = err(r, f, "the included file %s includes itself", full);
    if (s == CM_OK && r->depth >= ABQ_MAX_DEPTH) s = err(r, f, "expected *INCLUDE nested at most %d deep", ABQ_MAX_DEPTH);
    if (s == CM_OK) s = parse_file(r, blk, full, rel);
    free(full);
    free(rel);
    return s;
}

static int find_part(const abq_reader *r, const char *name)
{
    for (size_t i = 1; i < r->n_parts; ++i)
        if (abq_name_eq(r->parts[i].name, name)) return (int)i;
    return -1;
}

static cm_status keyword_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    abq_keyword *kw = malloc(sizeof *kw);
    if (!kw) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    cm_status s = parse_keyword(r, f, b, e, kw);
    const char *k = kw->key;
    const int mesh_kw = !strcmp(k, "NODE") || !strcmp(k, "ELEMENT") || !strcmp(k, "NSET") ||
                        !strcmp(k, "ELSET") || !strcmp(k, "SURFACE");
    if (s == CM_OK && strcmp(k, "INCLUDE")) {
        s = end_block(r, f, blk);
        blk->kind = B_NONE;
        blk->set = -1;
        blk->inst = -1;
    }
    if (s != CM_OK) goto done;
    if (mesh_kw && r->in_instance) {
        s = err(r, f, "expected *END INSTANCE before *%s (nodes and elements belong to a part)", k);
        goto done;
    }
    if (!strcmp(k, "INCLUDE")) {
        const char *in = param(kw, "INPUT");
        s = include(r, f, blk, in ? in : "");
    } else if (!strcmp(k, "NODE")) {
        const char *sys = param(kw, "SYSTEM");
        if (sys && strcasecmp(sys, "R")) {
            s = err(r, f, "*NODE, SYSTEM=%s is not supported (rectangular coordinates only)", sys);
            goto done;
        }
        blk->kind = B_NODE;
        const char *ns = param(kw, "NSET");
        if (ns) s = get_set(r, f, r->cur, ABQ_NSET, ns, &blk->set);
        const char *in = param(kw, "INPUT");
        if (s == CM_OK && in) s = include(r, f, blk, in);
    } else if (!strcmp(k, "ELEMENT")) {
        const char *type = param(kw, "TYPE");
        if (!type || !*type) {
            s = err(r, f, "expected TYPE= on *ELEMENT");
            goto done;
        }
        upper_squeeze(blk->type_name, sizeof blk->type_name, type, type + strlen(type));
        blk->have = 0;
        if (abq_element_type(blk->type_name, &blk->type)) {
            blk->kind = B_ELEMENT;
            const char *es = param(kw, "ELSET");
            if (es) s = get_set(r, f, r->cur, ABQ_ELSET, es, &blk->set);
        } else {
            blk->kind = B_SKIP_ELEMENT;
            if (!r->skipped) snprintf(r->skipped_type, sizeof r->skipped_type, "%s", blk->type_name);
            r->parts[r->cur].skipped = 1;
        }
        const char *in = param(kw, "INPUT");
        if (s == CM_OK && in) s = include(r, f, blk, in);
    } else if (!strcmp(k, "NSET") || !strcmp(k, "ELSET")) {
        const int kind = k[0] == 'N' ? ABQ_NSET : ABQ_ELSET;
        const char *name = param(kw, kind == ABQ_NSET ? "NSET" : "ELSET");
        if (!name) {
            s = err(r, f, "expected %s= on *%s", k, k);
            goto done;
        }
        if (kind == ABQ_NSET && param(kw, "ELSET")) {
            s = err(r, f, "*NSET, ELSET= is not supported (list the nodes)");
            goto done;
        }
        blk->kind = kind == ABQ_NSET ? B_NSET : B_ELSET;
        blk->generate = param(kw, "GENERATE") != NULL;
        const char *in = param(kw, "INSTANCE");
        if (in) {
            int found = -1;
            for (size_t i = 0; i < r->n_insts; ++i)
                if (abq_name_eq(r->insts[i].name, in)) found = (int)i;
            if (found < 0 || r->cur != 0) {
                s = err(r, f, "expected INSTANCE= to name an instance of the assembly, got '%s'", in);
                goto done;
            }
            blk->inst = found;
        }
        s = get_set(r, f, r->cur, kind, name, &blk->set);
    } else if (!strcmp(k, "SURFACE")) {
        const char *name = param(kw, "NAME"), *type = param(kw, "TYPE");
        if (!name) {
            s = err(r, f, "expected NAME= on *SURFACE");
            goto done;
        }
        if (type && strcasecmp(type, "ELEMENT") && strcasecmp(type, "NODE")) {
            blk->kind = B_NONE; /* analytical and cutting surfaces have no faces of the mesh */
            goto done;
        }
        blk->kind = B_SURFACE;
        blk->node_surface = type && !strcasecmp(type, "NODE");
        s = get_set(r, f, r->cur, ABQ_SURFACE, name, &blk->set);
    } else if (!strcmp(k, "PART")) {
        const char *name = param(kw, "NAME");
        if (!name || !*name) s = err(r, f, "expected NAME= on *PART");
        else if (r->cur != 0 || r->in_assembly) s = err(r, f, "expected *END PART (or *END ASSEMBLY) before *PART");
        else if (find_part(r, name) >= 0) s = err(r, f, "part %s defined twice", name);
        else if (r->parts[0].used && !r->any_part) s = err(r, f, "expected *PART before any *NODE or *ELEMENT of the model");
        if (s != CM_OK) goto done;
        abq_part *parts = grow(r->parts, r->n_parts, sizeof *parts);
        if (!parts) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            goto done;
        }
        r->parts = parts;
        memset(&parts[r->n_parts], 0, sizeof *parts);
        parts[r->n_parts].name = dup_text(name);
        if (!parts[r->n_parts].name) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            goto done;
        }
        r->cur = (int)r->n_parts++;
        r->any_part = 1;
    } else if (!strcmp(k, "ENDPART")) {
        if (r->cur == 0) s = err(r, f, "*END PART without *PART");
        r->parts[r->cur].ended = 1;
        r->cur = 0;
    } else if (!strcmp(k, "ASSEMBLY")) {
        if (r->cur != 0 || r->in_assembly) s = err(r, f, "expected *END PART before *ASSEMBLY");
        r->in_assembly = 1;
    } else if (!strcmp(k, "ENDASSEMBLY")) {
        if (r->in_instance) s = err(r, f, "expected *END INSTANCE before *END ASSEMBLY");
        r->in_assembly = 0;
    } else if (!strcmp(k, "INSTANCE")) {
        const char *name = param(kw, "NAME"), *part = param(kw, "PART");
        if (!r->in_assembly || r->in_instance) {
            s = err(r, f, "expected *INSTANCE inside *ASSEMBLY (and after *END INSTANCE)");
            goto done;
        }
        const int p = part ? find_part(r, part) : -1;
        if (!name || !*name || p < 0) {
            s = err(r, f, "expected NAME= and PART= naming a part defined before, on *INSTANCE");
            goto done;
        }
        for (size_t i = 0; i < r->n_insts; ++i)
            if (abq_name_eq(r->insts[i].name, name)) {
                s = err(r, f, "instance %s defined twice", name);
                goto done;
            }
        abq_inst *insts = grow(r->insts, r->n_insts, sizeof *insts);
        if (!insts) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            goto done;
        }
        r->insts = insts;
        abq_inst *in = &insts[r->n_insts];
        memset(in, 0, sizeof *in);
        in->name = dup_text(name);
        if (!in->name) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            goto done;
        }
        in->part = p;
        in->x.r[0] = in->x.r[4] = in->x.r[8] = 1.0;
        ++r->n_insts;
        r->parts[p].n_inst++;
        r->in_instance = 1;
        blk->kind = B_INSTANCE;
        blk->inst_lines = 0;
    } else if (!strcmp(k, "ENDINSTANCE")) {
        if (!r->in_instance) s = err(r, f, "*END INSTANCE without *INSTANCE");
        r->in_instance = 0;
    }
done:
    free(kw);
    return s;
}

static cm_status data_line(abq_reader *r, abq_file *f, abq_block *blk, const char *b, const char *e)
{
    switch (blk->kind) {
    case B_NODE: return node_line(r, f, blk, b, e);
    case B_ELEMENT: return element_line(r, f, blk, b, e);
    case B_SKIP_ELEMENT:
        /* one element per line unless the line ends with a comma */
        if (!ends_with_comma(b, e)) {
            ++r->skipped;
            r->parts[r->cur].skipped = 1;
        }
        return CM_OK;
    case B_NSET:
    case B_ELSET: return set_line(r, f, blk, b, e);
    case B_SURFACE: return surface_line(r, f, blk, b, e);
    case B_INSTANCE: return instance_line(r, f, blk, b, e);
    default: return CM_OK;
    }
}

static cm_status parse_file(abq_reader *r, abq_block *blk, const char *path, const char *name)
{
    char *data = NULL;
    size_t size = 0;
    cm_status s = cm_file_read(r->ctx, path, &data, &size);
    if (s != CM_OK) return s;
    abq_file f = {path, data, size, 0, 0, 0, name};
    s = cm_rewrite_add_file(r->ctx, r->src, path, name, &f.index);
    struct stat st;
    if (s == CM_OK && stat(path, &st) == 0) {
        r->dev[r->depth] = st.st_dev;
        r->ino[r->depth] = st.st_ino;
    }
    ++r->depth;
    const char *b, *e;
    while (s == CM_OK && next_line(&f, &b, &e)) {
        const char *p = b;
        while (p < e && blank(*p)) ++p;
        if (p == e) continue;
        if (p[0] == '*' && p + 1 < e && p[1] == '*') continue;
        if (p[0] == '*') s = keyword_line(r, &f, blk, p, e);
        else s = data_line(r, &f, blk, b, e);
    }
    --r->depth;
    if (s == CM_OK && r->depth == 0) s = end_block(r, &f, blk);
    free(data);
    return s;
}

void abq_reader_free(abq_reader *r)
{
    for (size_t i = 0; i < r->n_parts; ++i) free(r->parts[i].name);
    free(r->parts);
    for (size_t i = 0; i < r->n_insts; ++i) free(r->insts[i].name);
    free(r->insts);
    for (size_t i = 0; i < r->n_sets; ++i) {
        free(r->sets[i].name);
        free(r->sets[i].inst);
        free(r->sets[i].id);
        free(r->sets[i].face);
    }
    free(r->sets);
    free(r->set_slots);
    cm_rewrite_source_free(r->src);
}

cm_status cm_mesh_read_abaqus(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read_abaqus: NULL argument");
    *mesh = NULL;
    abq_reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    cm_status s = cm_mesh_create(ctx, &r.m);
    if (s != CM_OK) return s;
    r.src = cm_rewrite_source_new();
    r.parts = calloc(1, sizeof *r.parts);
    if (!r.src || !r.parts) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    r.n_parts = 1;
    abq_block blk;
    memset(&blk, 0, sizeof blk);
    blk.set = -1;
    blk.inst = -1;
    /* the deck is read file by file (each with the files it includes), not whole first */
    if (s == CM_OK) s = parse_file(&r, &blk, path, NULL);
    if (s == CM_OK && (r.cur != 0 || r.in_instance))
        s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: expected *END %s before the end of the deck (truncated?)",
                     path, r.in_instance ? "INSTANCE" : "PART");
    if (s == CM_OK) s = cm_mesh_resize_nodes(ctx, r.m, r.nn, 1);
    if (s == CM_OK) s = abq_build(&r, path);
    abq_reader_free(&r);
    if (s < 0) {
        cm_mesh_destroy(&r.m);
        return s;
    }
    *mesh = r.m;
    return s;
}
