/* Abaqus decks written (abaqus_internal.h). A mesh read from a deck is written back through
 * rewrite.h: only the coordinate numbers of *NODE data lines change (the node id, separators,
 * fields after the third and every other line stay byte for byte; an included file that holds
 * nodes is written beside the output). A changed number is the shortest text that reads back
 * as the new value, within 20 characters (CalculiX reads no more of a field). A node of an instanced part goes back through the
 * inverse of its instance's placement; a part placed by several instances holds one position
 * per node, so instances moved differently are refused. Any other mesh is written as a plain
 * new deck: *NODE, one *ELEMENT block per type and group (ELSET= the group's name), point
 * cells' groups as *NSET. */
#define _POSIX_C_SOURCE 200809L
#include "abaqus_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int blank(char c)
{
    return c == ' ' || c == '\t' || c == '\f' || c == '\v' || c == '\r';
}

/* The local position of a node placed by x: r^T (p - c). */
static void unapply(const abq_xform *x, const double *p, double *l)
{
    const double d[3] = {p[0] - x->c[0], p[1] - x->c[1], p[2] - x->c[2]};
    for (int j = 0; j < 3; ++j) l[j] = x->r[j] * d[0] + x->r[3 + j] * d[1] + x->r[6 + j] * d[2];
}

static void apply(const abq_xform *x, const double *l, double *p)
{
    for (int i = 0; i < 3; ++i) p[i] = x->r[3 * i] * l[0] + x->r[3 * i + 1] * l[1] + x->r[3 * i + 2] * l[2] + x->c[i];
}

/* The field k of a span: [*b, *e) trimmed, *next past its comma; 0 when the span has no more. */
typedef struct span_field {
    const char *lead, *b, *e, *next; /* leading blanks from lead, the number [b, e), to next */
} span_field;

static int field_at(const char *p, const char *end, span_field *f)
{
    if (p >= end) return 0;
    f->lead = p;
    while (p < end && blank(*p)) ++p;
    f->b = p;
    while (p < end && *p != ',') ++p;
    f->e = p;
    while (f->e > f->b && blank(f->e[-1])) --f->e;
    f->next = p;
    return 1;
}

static double field_value(const span_field *f)
{
    char buf[64];
    size_t n = (size_t)(f->e - f->b);
    if (n == 0 || n >= sizeof buf) return 0.0;
    memcpy(buf, f->b, n);
    buf[n] = '\0';
    for (size_t i = 0; i < n; ++i)
        if (buf[i] == 'd' || buf[i] == 'D') buf[i] = 'e';
    return strtod(buf, NULL);
}

/* CalculiX reads 20 characters of a field (f20.0): a number longer than that gets the most
 * significant digits that fit (at least 14 with an exponent), unless its bytes are kept. */
enum { FIELD_CHARS = 20 };

static int number(char *out, size_t cap, double v, const char *original, size_t n)
{
    /* an unchanged number keeps its bytes, a Fortran exponent (2.5D0) too */
    double was;
    if (original && n < cap && abq_parse_coord(original, original + n, &was) && was == v && signbit(was) == signbit(v)) {
        memcpy(out, original, n);
        out[n] = '\0';
        return (int)n;
    }
    int len = cm_rewrite_number(out, cap, v, original, n);
    if (len <= FIELD_CHARS || (original && (size_t)len == n && !memcmp(out, original, n))) return len;
    for (int digits = 16; digits > 0 && len > FIELD_CHARS; --digits) len = snprintf(out, cap, "%.*g", digits, v);
    return len;
}

static cm_status emit(cm_context *ctx, const cm_rewrite_source *src, const cm_rewrite_file *file,
                      const cm_rewrite_span *span, const char *original, const double xyz[3], cm_rewrite_buf *out)
{
    (void)ctx, (void)file;
    const abq_record *rec = src->format;
    const char *end = original + span->length;
    double v[3] = {xyz[0], xyz[1], xyz[2]};
    span_field f[3];
    int nf = 0;
    for (const char *p = original; nf < 3 && field_at(p, end, &f[nf]); ++nf) p = f[nf].next < end ? f[nf].next + 1 : end;
    if (span->aux >= 0) {
        /* a placed node: unchanged when the placement of the deck's numbers is where it is */
        const abq_xform *x = &rec->insts[span->aux].x;
        double l[3] = {0, 0, 0}, p[3];
        for (int k = 0; k < nf; ++k) l[k] = field_value(&f[k]);
        apply(x, l, p);
        if (p[0] == xyz[0] && p[1] == xyz[1] && p[2] == xyz[2]) {
            cm_rewrite_put(out, original, (size_t)span->length);
            return CM_OK;
        }
        unapply(x, xyz, v);
    }
    const char *at = original;
    char num[40];
    for (int k = 0; k < 3; ++k) {
        if (k < nf) {
            cm_rewrite_put(out, at, (size_t)(f[k].b - at));
            const size_t n = (size_t)(f[k].e - f[k].b);
            /* an empty field is 0: it stays empty while the value is +0 */
            if (n == 0 && v[k] == 0 && !signbit(v[k])) {
                at = f[k].e;
                continue;
            }
            const int len = number(num, sizeof num, v[k], n ? f[k].b : NULL, n);
            cm_rewrite_put(out, num, (size_t)len);
            at = f[k].e;
        } else if (v[k] != 0 || signbit(v[k])) {
            /* a coordinate the line leaves out (0) that is not 0 any more */
            cm_rewrite_put(out, at, (size_t)(end - at));
            at = end;
            const int len = number(num, sizeof num, v[k], NULL, 0);
            cm_rewrite_put(out, ", ", 2);
            cm_rewrite_put(out, num, (size_t)len);
        }
    }
    cm_rewrite_put(out, at, (size_t)(end - at));
    return CM_OK;
}

/* A part's nodes are written once: every instance of it must agree on where they are. */
static cm_status check_instances(cm_context *ctx, const abq_record *rec, const cm_mesh *mesh, const char *path)
{
    for (size_t k = 0; k < rec->n_insts; ++k) {
        const abq_inst *a = &rec->insts[k];
        size_t first = k;
        for (size_t j = 0; j < k; ++j)
            if (rec->insts[j].part == a->part) {
                first = j;
                break;
            }
        if (first == k) continue;
        const abq_inst *f = &rec->insts[first];
        for (size_t i = 0; i < rec->part_nodes[a->part]; ++i) {
            double la[3], lf[3];
            unapply(&a->x, mesh->xyz + 3 * (a->node_base + i), la);
            unapply(&f->x, mesh->xyz + 3 * (f->node_base + i), lf);
            for (int c = 0; c < 3; ++c) {
                const double tol = 1e-9 * (1 + fabs(la[c]) + fabs(lf[c]));
                if (!(fabs(la[c] - lf[c]) <= tol))
                    return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                    "cm_mesh_write: %s: instances %s and %s of one part were moved differently "
                                    "(node %lld of the part: %.17g against %.17g); the deck holds the part's nodes "
                                    "once, so it cannot hold both: write a new file (.vtu, .msh) instead",
                                    path, f->name, a->name,
                                    (long long)(mesh->node_tag ? mesh->node_tag[f->node_base + i] : (int64_t)(f->node_base + i) + 1),
                                    lf[c], la[c]);
            }
        }
    }
    return CM_OK;
}

/* ---- a new deck ---- */

typedef struct abq_out_type {
    cm_cell_type type;
    const char *name;
    const int *perm; /* abaqus[i] = vtk[perm[i]] (the wedges' permutation is its own inverse) */
} abq_out_type;

static const int wedge6[6] = {0, 2, 1, 3, 5, 4};
static const int wedge15[15] = {0, 2, 1, 3, 5, 4, 8, 7, 6, 11, 10, 9, 12, 14, 13};

static const abq_out_type out_types[] = {
    {CM_CELL_TET4, "C3D4", NULL},     {CM_CELL_TET10, "C3D10", NULL},    {CM_CELL_HEX8, "C3D8", NULL},
    {CM_CELL_HEX20, "C3D20", NULL},   {CM_CELL_WEDGE6, "C3D6", wedge6},  {CM_CELL_WEDGE15, "C3D15", wedge15},
    {CM_CELL_PYR5, "C3D5", NULL},     {CM_CELL_TRI3, "S3", NULL},        {CM_CELL_QUAD4, "S4", NULL},
    {CM_CELL_TRI6, "STRI65", NULL},   {CM_CELL_QUAD8, "S8R", NULL},      {CM_CELL_QUAD9, "S9R5", NULL},
    {CM_CELL_LINE2, "T3D2", NULL},    {CM_CELL_LINE3, "T3D3", NULL},
};
enum { N_OUT = sizeof out_types / sizeof *out_types };

/* A name Abaqus reads: letters, digits, '_', '-' and '.' kept, others '_'; a leading digit
 * gets a letter before it. */
static void set_name(char *out, size_t cap, const cm_mesh *mesh, int dim, int tag)
{
    const char *name = NULL;
    for (size_t g = 0; g < mesh->n_groups; ++g)
        if (mesh->groups[g].tag == tag && mesh->groups[g].dim == dim && mesh->groups[g].name) name = mesh->groups[g].name;
    char raw[256];
    if (!name || !*name) {
        snprintf(raw, sizeof raw, "PHYSICAL_%d_%d", dim, tag < 0 ? -tag : tag);
        name = raw;
    }
    size_t k = 0;
    if (!isalpha((unsigned char)name[0]) && name[0] != '_' && k + 1 < cap) out[k++] = 'G';
    for (const char *p = name; *p && k + 1 < cap; ++p)
        out[k++] = isalnum((unsigned char)*p) || *p == '_' || *p == '-' || *p == '.' ? *p : '_';
    out[k] = '\0';
}

static int rank_of(cm_cell_type type)
{
    for (int t = 0; t < N_OUT; ++t)
        if (out_types[t].type == type) return t;
    return type == CM_CELL_POINT ? N_OUT : -1;
}

typedef struct cell_key {
    int rank, physical;
    size_t cell;
} cell_key;

static int by_key(const void *a, const void *b)
{
    const cell_key *x = a, *y = b;
    if (x->rank != y->rank) return x->rank < y->rank ? -1 : 1;
    if (x->physical != y->physical) return x->physical < y->physical ? -1 : 1;
    return (x->cell > y->cell) - (x->cell < y->cell);
}

static cm_status write_new(cm_context *ctx, const cm_mesh *mesh, const char *path)
{
    for (size_t c = 0; c < mesh->n_cells; ++c)
        if (rank_of((cm_cell_type)mesh->type[c]) < 0)
            return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_write: %s: an Abaqus deck has no %s elements (cell %zu); write .vtu or .msh",
                            path, cm_cell_type_info((cm_cell_type)mesh->type[c])->name, c);
    /* the cells by type, then group: one *ELEMENT block (or *NSET) each */
    cell_key *keys = malloc((mesh->n_cells ? mesh->n_cells : 1) * sizeof *keys);
    if (!keys) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory");
    for (size_t c = 0; c < mesh->n_cells; ++c)
        keys[c] = (cell_key){rank_of((cm_cell_type)mesh->type[c]), mesh->physical[c], c};
    qsort(keys, mesh->n_cells, sizeof *keys, by_key);
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) {
        free(keys);
        return s;
    }
    FILE *f = out.f;
    fprintf(f, "*HEADING\ncadmorph\n*NODE\n");
    for (size_t i = 0; i < mesh->n_nodes; ++i)
        fprintf(f, "%zu, %.17g, %.17g, %.17g\n", i + 1, mesh->xyz[3 * i], mesh->xyz[3 * i + 1], mesh->xyz[3 * i + 2]);
    size_t id = 0;
    int col = 0;
    char name[300];
    for (size_t k = 0; k < mesh->n_cells; ++k) {
        const cell_key *key = &keys[k];
        const size_t c = key->cell;
        const int header = k == 0 || keys[k - 1].rank != key->rank || keys[k - 1].physical != key->physical;
        const int64_t *v = mesh->conn + mesh->offset[c];
        if (key->rank == N_OUT) {
            /* point cells: node sets (the points of no group are nodes already) */
            if (key->physical == 0) continue;
            if (header) {
                if (col) fputc('\n', f);
                set_name(name, sizeof name, mesh, 0, key->physical);
                fprintf(f, "*NSET, NSET=%s\n", name);
                col = 0;
            }
            fprintf(f, col ? ", %lld" : "%lld", (long long)v[0] + 1);
            if (++col == 16) fputc('\n', f), col = 0;
            continue;
        }
        const abq_out_type *t = &out_types[key->rank];
        if (header) {
            fprintf(f, "*ELEMENT, TYPE=%s", t->name);
            if (key->physical != 0) {
                set_name(name, sizeof name, mesh, cm_cell_type_info(t->type)->dim, key->physical);
                fprintf(f, ", ELSET=%s", name);
            }
            fputc('\n', f);
        }
        const int n = (int)(mesh->offset[c + 1] - mesh->offset[c]);
        fprintf(f, "%zu", ++id);
        /* at most 16 entries on a line: the rest on a continuation line */
        for (int j = 0; j < n; ++j)
            fprintf(f, j == 15 ? ",\n%lld" : ", %lld", (long long)v[t->perm ? t->perm[j] : j] + 1);
        fputc('\n', f);
    }
    if (col) fputc('\n', f);
    free(keys);
    return cm_outfile_commit(ctx, &out);
}

cm_status cm_mesh_write_abaqus(cm_context *ctx, const cm_mesh *mesh, const char *path,
                               const cm_mesh_write_options *opt)
{
    (void)opt;
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_abaqus: NULL argument");
    const cm_rewrite_source *src = cm_mesh_origin_state(mesh, CM_FORMAT_ABAQUS);
    if (!src) return write_new(ctx, mesh, path);
    /* a file with nodes included twice (into two parts, say) would be written twice, the
     * second copy over the first: refused */
    for (size_t i = 1; i < src->n_files; ++i)
        for (size_t j = 1; j < i && src->files[i].n_spans; ++j)
            if (src->files[j].n_spans && !strcmp(src->files[i].path, src->files[j].path))
                return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                "cm_mesh_write: %s: %s holds nodes and is included more than once; the deck "
                                "cannot be written back (write a new file: .vtu, .msh)", path, src->files[i].path);
    cm_status s = check_instances(ctx, src->format, mesh, path);
    if (s == CM_OK) s = cm_rewrite_write(ctx, src, mesh, path, emit);
    return s;
}
