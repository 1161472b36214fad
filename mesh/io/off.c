/* Object File Format .off (ASCII) reader and writer for surface meshes: header OFF (COFF,
 * NOFF, CNOFF and STOFF accepted: per-vertex colours, normals and texture coordinates after
 * x y z are read over), counts `nv nf ne`, vertices, faces `n i0 .. i(n-1) [colour]`; '#'
 * starts a comment. Binary OFF and 4D/nD variants are refused. The writer keeps the faces
 * (triangles, quads, polygons; corners of higher-order faces); lines, volume cells and fields
 * have no place in OFF (other cells are left out with a warning). */
#include "formats.h"
#include "surface_io.h"
#include "text.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Moves the cursor to the next token that is not in a comment; 0 at end of file. */
static int skip_comments(cm_text *t)
{
    for (;;) {
        if (!cm_text_skip_space(t)) return 0;
        if (t->data[t->pos] != '#') return 1;
        cm_text_next_line(t);
    }
}

static cm_status next_int(cm_context *ctx, cm_text *t, const char *what, int64_t *v)
{
    skip_comments(t);
    return cm_text_int(ctx, t, what, v);
}

/* The rest of the current line is data the reader does not keep (colours, normals). */
static void skip_rest_of_line(cm_text *t)
{
    while (t->pos < t->size && t->data[t->pos] != '\n') {
        if (t->data[t->pos] == '#') break;
        ++t->pos;
    }
    cm_text_next_line(t);
}

static cm_status read_off(cm_context *ctx, cm_text *t, cm_mesh *m)
{
    const char *tok;
    size_t len;
    if (!skip_comments(t) || !cm_text_token(t, &tok, &len))
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected the header 'OFF', got end of file", t->path, t->line);
    static const char *const headers[] = {"OFF", "COFF", "NOFF", "CNOFF", "STOFF", "STCOFF", "STNOFF", "STCNOFF"};
    int ok = 0;
    for (size_t k = 0; k < sizeof headers / sizeof *headers; ++k)
        if (strlen(headers[k]) == len && !memcmp(tok, headers[k], len)) ok = 1;
    if (!ok)
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected the header 'OFF', got '%.*s'%s", t->path, t->line,
                        (int)(len > 40 ? 40 : len), tok,
                        len >= 3 && !memcmp(tok + len - 3, "OFF", 3) ? " (4D, nD and homogeneous OFF are not supported)" : "");
    /* "OFF BINARY" on the header line */
    size_t save = t->pos;
    long save_line = t->line;
    while (t->pos < t->size && (t->data[t->pos] == ' ' || t->data[t->pos] == '\t')) ++t->pos;
    if (t->size - t->pos >= 6 && !memcmp(t->data + t->pos, "BINARY", 6))
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s:%ld: binary OFF is not supported (write it as ASCII OFF)", t->path, t->line);
    t->pos = save, t->line = save_line;
    int64_t nv, nf, ne;
    cm_status s = next_int(ctx, t, "vertex count", &nv);
    if (s == CM_OK) s = next_int(ctx, t, "face count", &nf);
    if (s == CM_OK) s = next_int(ctx, t, "edge count", &ne);
    if (s != CM_OK) return s;
    /* a vertex takes at least 6 bytes ("0 0 0\n"), a face at least 8 ("3 0 1 2\n") */
    size_t left = t->size - t->pos;
    if (nv < 0 || nf < 0 || (uint64_t)nv > left / 6 + 1 || (uint64_t)nf > left / 8 + 1 ||
        (uint64_t)nv * 6 + (uint64_t)nf * 8 > left + 8)
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %lld vertices and %lld faces do not fit in the rest of the file (%zu bytes; truncated?)",
                        t->path, t->line, (long long)nv, (long long)nf, left);
    skip_rest_of_line(t);
    s = cm_mesh_resize_nodes(ctx, m, (size_t)nv, 0);
    for (int64_t i = 0; s == CM_OK && i < nv; ++i) {
        double *x = m->xyz + 3 * i;
        for (int k = 0; k < 3 && s == CM_OK; ++k) {
            skip_comments(t);
            s = cm_text_double(ctx, t, "vertex coordinate", &x[k]);
        }
        if (s == CM_OK && !(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2])))
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: vertex %lld: coordinate is not finite", t->path, t->line, (long long)i);
        if (s == CM_OK) skip_rest_of_line(t);
    }
    int64_t *ids = NULL;
    size_t cap = 0;
    for (int64_t f = 0; s == CM_OK && f < nf; ++f) {
        int64_t n;
        s = next_int(ctx, t, "face vertex count", &n);
        if (s != CM_OK) break;
        long line = t->line;
        if (n < 3 || (uint64_t)n > (t->size - t->pos) / 2 + 1) {
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: face %lld has %lld vertices (expected at least 3, and no more than the file holds)",
                         t->path, line, (long long)f, (long long)n);
            break;
        }
        if ((size_t)n > cap) {
            int64_t *p = realloc(ids, (size_t)n * sizeof *p);
            if (!p) {
                s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", t->path);
                break;
            }
            ids = p, cap = (size_t)n;
        }
        for (int64_t k = 0; k < n && s == CM_OK; ++k) {
            s = cm_text_int(ctx, t, "vertex index", &ids[k]);
            if (s == CM_OK && (ids[k] < 0 || ids[k] >= nv))
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: face %lld: vertex index %lld out of range [0, %lld)",
                             t->path, t->line, (long long)f, (long long)ids[k], (long long)nv);
        }
        if (s == CM_OK && t->line != line)
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: face %lld: its %lld indices run past the end of its line", t->path, line,
                         (long long)f, (long long)n);
        if (s != CM_OK) break;
        cm_cell_type type = n == 3 ? CM_CELL_TRI3 : n == 4 ? CM_CELL_QUAD4 : CM_CELL_POLYGON;
        s = cm_mesh_add_cell(ctx, m, type, ids, (size_t)n, 0, 0, 0);
        if (s == CM_OK) skip_rest_of_line(t);
    }
    free(ids);
    return s;
}

static cm_status parse_off(cm_context *ctx, const char *path, const char *data, size_t size,
                           cm_mesh *m)
{
    cm_text t;
    cm_text_init(&t, path, data, size);
    return read_off(ctx, &t, m);
}

cm_status cm_mesh_read_off(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    return cm_mesh_read_whole(ctx, "cm_mesh_read_off", path, parse_off, mesh);
}

cm_status cm_mesh_write_off(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt)
{
    (void)opt;
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_off: NULL argument");
    size_t nf = 0, skipped = 0, n;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (cm_surface_io_corners(mesh, c, &n) && n >= 3) ++nf;
        else ++skipped;
    }
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    FILE *f = out.f;
    fprintf(f, "OFF\n# written by cadmorph\n%zu %zu 0\n", mesh->n_nodes, nf);
    for (size_t i = 0; i < mesh->n_nodes; ++i)
        fprintf(f, "%.17g %.17g %.17g\n", mesh->xyz[3 * i], mesh->xyz[3 * i + 1], mesh->xyz[3 * i + 2]);
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const int64_t *v = cm_surface_io_corners(mesh, c, &n);
        if (!v || n < 3) continue;
        fprintf(f, "%zu", n);
        for (size_t k = 0; k < n; ++k) fprintf(f, " %lld", (long long)v[k]);
        fputc('\n', f);
    }
    s = cm_outfile_commit(ctx, &out);
    if (s == CM_OK && skipped)
        return cm_error(ctx, CM_WARNING, "%s: %zu cells that are not faces are not written (OFF holds faces only)", path,
                        skipped);
    return s;
}
