/* Nastran bulk data writer: a deck read from Nastran is written back changing only GRID
 * coordinates (rewrite.h); any other mesh becomes a new deck.
 *
 * Write-back: a GRID that did not move keeps its bytes; a moved coordinate is written in the
 * field it had (in the GRID's own CP system) with at least the digits the deck gave it: in 8
 * columns for small field when they hold them, else the card becomes large field (GRID* and a
 * '*' continuation, its other fields kept as text); in 16 for large and free field (the most
 * digits that fit). A fixed-field card with tabs whose coordinates change is written with
 * spaces. */
#define _POSIX_C_SOURCE 200809L
#include "formats.h"
#include "nastran_internal.h"
#include "rewrite.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A copy of text[0, n) with the tabs of its fixed lines expanded to spaces. */
static char *expand_tabs(const char *text, size_t n, size_t *out_n)
{
    size_t cap = n * 8 + 1, k = 0, col = 0;
    char *d = malloc(cap);
    if (!d) return NULL;
    for (size_t i = 0; i < n; ++i) {
        if (text[i] == '\n') col = 0, d[k++] = '\n';
        else if (text[i] == '\t') {
            do d[k++] = ' ';
            while (++col % 8);
        } else {
            d[k++] = text[i];
            ++col;
        }
    }
    d[k] = '\0';
    *out_n = k;
    return d;
}

static void put_padded(cm_rewrite_buf *b, const char *s, size_t n, int width)
{
    cm_rewrite_put(b, s, n);
    for (size_t i = n; i < (size_t)width; ++i) cm_rewrite_put(b, " ", 1);
}

static void rstrip(cm_rewrite_buf *b, size_t from)
{
    while (b->n > from && b->d[b->n - 1] == ' ') --b->n;
    if (b->d) b->d[b->n] = '\0';
}

static cm_status emit_grid(cm_context *ctx, const cm_rewrite_source *src, const cm_rewrite_file *file,
                           const cm_rewrite_span *span, const char *original, const double xyz[3],
                           cm_rewrite_buf *out)
{
    const nas_record *rec = src->format;
    const double *was = rec->xyz + 3 * span->node;
    if (!memcmp(xyz, was, 3 * sizeof *xyz)) {
        cm_rewrite_put(out, original, (size_t)span->length);
        return CM_OK;
    }
    double local[3];
    const int64_t sys = span->aux / 2 - 1;
    const char *eol = span->aux & 1 ? "\r\n" : "\n";
    if (sys >= 0) nas_coord_from_basic(&rec->coords[sys], xyz, local);
    else memcpy(local, xyz, sizeof local);
    if (!(isfinite(local[0]) && isfinite(local[1]) && isfinite(local[2])))
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: node %lld: coordinates are not finite", file->path, (long long)span->node + 1);

    nas_card c = {0};
    long ln = 1;
    size_t n = (size_t)span->length;
    char *text = NULL;
    const char *t = original;
    if (nas_card_split(t, n, 0, &ln, &c) == (size_t)-1) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", file->path);
    int tabs = 0;
    for (size_t i = 0; i < c.n_lines; ++i) tabs |= c.lines[i].tabs;
    if (tabs) {
        text = expand_tabs(original, n, &n);
        if (!text || nas_card_split(text, n, 0, &ln, &c) == (size_t)-1) {
            free(text);
            nas_card_free(&c);
            return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", file->path);
        }
        t = text;
    }
    /* the new text of each coordinate field ("" keeps it) */
    char nt[3][40];
    int changed[3] = {0, 0, 0}, need_large = 0, pmax = 1;
    for (int k = 0; k < 3; ++k) {
        size_t len;
        const char *s = nas_field_text(t, &c, 2 + (size_t)k, &len);
        if (len) {
            const int p = nas_text_digits(s, len);
            if (p > pmax) pmax = p;
        }
    }
    for (int k = 0; k < 3; ++k) {
        size_t len;
        const char *s = nas_field_text(t, &c, 2 + (size_t)k, &len);
        double ov = 0.0;
        if (len) nas_parse_real(s, len, &ov);
        nt[k][0] = '\0';
        if (local[k] == ov && signbit(local[k]) == signbit(ov)) continue;
        changed[k] = 1;
        const int p = len ? nas_text_digits(s, len) : pmax;
        const int width = 2 + (size_t)k < c.n_fields ? c.f[2 + k].width : 16;
        if (!nas_format_fit(nt[k], sizeof nt[k], local[k], width, p)) {
            if (width == 8) need_large = 1;
            else nas_format_fit(nt[k], sizeof nt[k], local[k], width, 1);
        }
    }
    if (need_large) {
        /* GRID* ID CP X1 X2 / * X3 CD PS SEID, the other fields as they were, the moved
         * coordinates in 16 columns */
        for (int k = 0; k < 3; ++k) {
            size_t len;
            const char *s = nas_field_text(t, &c, 2 + (size_t)k, &len);
            if (changed[k] && !nas_format_fit(nt[k], sizeof nt[k], local[k], 16, len ? nas_text_digits(s, len) : pmax))
                nas_format_fit(nt[k], sizeof nt[k], local[k], 16, 1);
        }
        const size_t start = out->n;
        cm_rewrite_put(out, "GRID*   ", 8);
        for (size_t i = 0; i < 8; ++i) {
            if (i == 4) {
                rstrip(out, start);
                cm_rewrite_put(out, eol, strlen(eol));
                cm_rewrite_put(out, "*       ", 8);
            }
            size_t len;
            const char *s = i >= 2 && i <= 4 && changed[i - 2] ? nt[i - 2] : nas_field_text(t, &c, i, &len);
            if (i >= 2 && i <= 4 && changed[i - 2]) len = strlen(s);
            put_padded(out, s, len, 16);
        }
        rstrip(out, start);
        /* whatever followed the first line within the span (nothing for a small-field GRID) */
        cm_rewrite_put(out, t + c.lines[0].e, n - c.lines[0].e);
    } else {
        size_t at = 0;
        for (size_t li = 0; li < c.n_lines; ++li) {
            const nas_line *l = &c.lines[li];
            cm_rewrite_put(out, t + at, l->b - at);
            const size_t line_start = out->n, orig_len = l->e - l->b;
            if (l->kind != NAS_FREE) {
                cm_rewrite_put(out, t + l->b, orig_len);
                for (int k = 0; k < 3; ++k) {
                    const nas_field *f = &c.f[2 + k];
                    if (!changed[k] || (size_t)f->line != li) continue;
                    const size_t col = (size_t)f->col, w = (size_t)f->width, len = strlen(nt[k]);
                    while (out->n < line_start + col + w) cm_rewrite_put(out, " ", 1);
                    if (out->fail) break;
                    char *dst = out->d + line_start + col;
                    /* the side the old value was on */
                    const int left = f->e == f->b || t[f->b] != ' ';
                    memset(dst, ' ', w);
                    memcpy(dst + (left ? 0 : w - len), nt[k], len);
                }
                rstrip(out, line_start + orig_len);
            } else {
                /* free field: replace the fields' bytes, add the fields the line lacks */
                size_t pos = l->b;
                int last_pad = -1;
                for (int k = 0; k < 3; ++k)
                    if (changed[k] && (size_t)c.f[2 + k].line == li && c.f[2 + k].pad) last_pad = k;
                for (size_t fi = 0; fi < c.n_fields; ++fi) {
                    const nas_field *f = &c.f[fi];
                    if ((size_t)f->line != li || f->pad) continue;
                    const int k = (int)fi - 2;
                    if (k < 0 || k > 2 || !changed[k]) continue;
                    cm_rewrite_put(out, t + pos, f->b - pos);
                    cm_rewrite_put(out, nt[k], strlen(nt[k]));
                    pos = f->e;
                }
                /* the text up to the comment, then the missing fields */
                size_t end = l->e;
                const char *d = memchr(t + l->b, '$', l->e - l->b);
                if (d) end = (size_t)(d - t);
                cm_rewrite_put(out, t + pos, end - pos);
                for (size_t fi = 0; last_pad >= 0 && fi < c.n_fields; ++fi) {
                    const nas_field *f = &c.f[fi];
                    if ((size_t)f->line != li || !f->pad) continue;
                    const int k = (int)fi - 2;
                    cm_rewrite_put(out, ",", 1);
                    if (k >= 0 && k <= 2 && changed[k]) cm_rewrite_put(out, nt[k], strlen(nt[k]));
                    if (k >= last_pad) break;
                }
                cm_rewrite_put(out, t + end, l->e - end);
            }
            at = l->e;
        }
        cm_rewrite_put(out, t + at, n - at);
    }
    free(text);
    nas_card_free(&c);
    return CM_OK;
}

/* ---- a new deck ---- */

typedef struct nas_out_type {
    cm_cell_type type;
    const char *name;
} nas_out_type;

static const nas_out_type out_types[] = {
    {CM_CELL_TET4, "CTETRA"},  {CM_CELL_TET10, "CTETRA"},  {CM_CELL_HEX8, "CHEXA"},   {CM_CELL_HEX20, "CHEXA"},
    {CM_CELL_WEDGE6, "CPENTA"}, {CM_CELL_WEDGE15, "CPENTA"}, {CM_CELL_PYR5, "CPYRAM"}, {CM_CELL_PYR13, "CPYRAM"},
    {CM_CELL_TRI3, "CTRIA3"},  {CM_CELL_TRI6, "CTRIA6"},   {CM_CELL_QUAD4, "CQUAD4"}, {CM_CELL_QUAD8, "CQUAD8"},
};

static const char *card_of(cm_cell_type t)
{
    for (size_t i = 0; i < sizeof out_types / sizeof *out_types; ++i)
        if (out_types[i].type == t) return out_types[i].name;
    return NULL;
}

static void real16(FILE *f, double v)
{
    char s[40];
    if (!nas_format_fit(s, sizeof s, v, 16, 1)) snprintf(s, sizeof s, "0.");
    fprintf(f, "%16s", s);
}

static cm_status write_new(cm_context *ctx, const cm_mesh *mesh, const char *path)
{
    enum { MAX_ID = 99999999 }; /* 8 columns of small-field element cards */
    size_t skipped = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_type t = (cm_cell_type)mesh->type[c];
        if (card_of(t)) continue;
        if (cm_cell_type_info(t)->dim < 2) {
            ++skipped;
            continue;
        }
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: this Nastran writer has no card for %s cells (cell %zu); write .vtu or .msh",
                        path, cm_cell_type_info(t)->name, c);
    }
    if (mesh->n_nodes > MAX_ID || mesh->n_cells > MAX_ID)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: more than %d nodes or cells do not fit small-field element cards",
                        path, MAX_ID);
    for (size_t i = 0; i < 3 * mesh->n_nodes; ++i)
        if (!isfinite(mesh->xyz[i]))
            return cm_error(ctx, CM_ERR_ARGUMENT, "%s: node %zu: coordinates are not finite", path, i / 3);
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    FILE *f = out.f;
    fputs("$ Nastran bulk data written by cadmorph: GRID ids are the node numbers (1-based), PIDs the\n"
          "$ physical groups\n", f);
    for (size_t g = 0; g < mesh->n_groups; ++g)
        if (mesh->groups[g].name && !strchr(mesh->groups[g].name, '\n'))
            fprintf(f, "$ PID %d (dimension %d): %s\n", mesh->groups[g].tag, mesh->groups[g].dim, mesh->groups[g].name);
    fputs("BEGIN BULK\n", f);
    for (size_t i = 0; i < mesh->n_nodes; ++i) {
        const double *x = mesh->xyz + 3 * i;
        fprintf(f, "GRID*   %-16zu%-16s", i + 1, "");
        real16(f, x[0]);
        real16(f, x[1]);
        fputs("\n*       ", f);
        real16(f, x[2]);
        fputc('\n', f);
    }
    static const int hex20_out[20] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 16, 17, 18, 19, 12, 13, 14, 15};
    static const int wedge15_out[15] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 13, 14, 9, 10, 11};
    size_t eid = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_type t = (cm_cell_type)mesh->type[c];
        const char *name = card_of(t);
        if (!name) continue;
        const int64_t *v = mesh->conn + mesh->offset[c];
        const int nn = (int)(mesh->offset[c + 1] - mesh->offset[c]);
        const int pid = mesh->physical[c] > 0 ? mesh->physical[c] : 1;
        fprintf(f, "%-8s%-8zu%-8d", name, ++eid, pid);
        /* 6 nodes on the first line, 8 on each continuation, '+' markers */
        for (int j = 0, on_line = 2; j < nn; ++j) {
            if (on_line == 8) {
                fputs("+\n+       ", f);
                on_line = 0;
            }
            const int src = t == CM_CELL_HEX20 ? hex20_out[j] : t == CM_CELL_WEDGE15 ? wedge15_out[j] : j;
            fprintf(f, "%-8lld", (long long)v[src] + 1);
            ++on_line;
        }
        fputc('\n', f);
    }
    fputs("ENDDATA\n", f);
    s = cm_outfile_commit(ctx, &out);
    if (s == CM_OK && skipped)
        return cm_error(ctx, CM_WARNING, "%s: %zu point and line cells are not written", path, skipped);
    return s;
}

cm_status cm_mesh_write_nastran(cm_context *ctx, const cm_mesh *mesh, const char *path,
                                const cm_mesh_write_options *opt)
{
    (void)opt;
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_nastran: NULL argument");
    const cm_rewrite_source *src = cm_mesh_origin_state(mesh, CM_FORMAT_NASTRAN);
    if (src) return cm_rewrite_write(ctx, src, mesh, path, emit_grid);
    return write_new(ctx, mesh, path);
}
