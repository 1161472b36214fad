/* STL reader and writer, binary and ASCII. STL is a triangle soup: the reader merges corners
 * with bit-identical coordinates (after -0 -> +0) into one node, so the mesh has the
 * connectivity every algorithm needs; facet normals are read over (recomputed when writing).
 * Binary: 80-byte header, uint32 count, 50 bytes per triangle (normal, 3 corners as float32
 * little-endian, attribute word) - recognised by its size, since binary files may start with
 * "solid" too. ASCII: solid/facet normal/outer loop/vertex x3/endloop/endfacet/endsolid; each
 * named solid becomes a physical group. Writer: binary (float32: coordinates keep ~7 digits)
 * unless opt->binary is 0, then ASCII with %.17g (exact); quads and polygons are split into
 * triangles fanned from their first corner; other cells are left out with a warning. */
#include "formats.h"
#include "surface_io.h"
#include "text.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- corner merging: an open-addressing hash of coordinates -> node ---- */

typedef struct merge {
    size_t cap;    /* power of two */
    int64_t *slot; /* node index or -1 */
} merge;

static uint64_t hash_xyz(const double *x)
{
    uint64_t h = 1469598103934665603ull;
    for (int k = 0; k < 3; ++k) {
        uint64_t b;
        memcpy(&b, &x[k], sizeof b);
        h ^= b + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
        h *= 1099511628211ull;
    }
    return h ^ (h >> 29);
}

static cm_status merge_init(cm_context *ctx, merge *mg, size_t corners)
{
    mg->cap = 16;
    while (mg->cap < 2 * corners) mg->cap *= 2;
    mg->slot = malloc(mg->cap * sizeof *mg->slot);
    if (!mg->slot) return cm_error(ctx, CM_ERR_NOMEM, "STL: out of memory for %zu corners", corners);
    memset(mg->slot, 0xff, mg->cap * sizeof *mg->slot);
    return CM_OK;
}

/* Node of corner x (added to m->xyz at m->n_nodes if new; room is reserved by the caller). */
static int64_t merge_corner(merge *mg, cm_mesh *m, const double *xin)
{
    double x[3];
    for (int k = 0; k < 3; ++k) x[k] = xin[k] == 0.0 ? 0.0 : xin[k];
    size_t i = (size_t)hash_xyz(x) & (mg->cap - 1);
    for (;; i = (i + 1) & (mg->cap - 1)) {
        int64_t v = mg->slot[i];
        if (v < 0) break;
        if (!memcmp(m->xyz + 3 * v, x, sizeof x)) return v;
    }
    int64_t v = (int64_t)m->n_nodes++;
    memcpy(m->xyz + 3 * v, x, sizeof x);
    mg->slot[i] = v;
    return v;
}

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static float lefloat(const unsigned char *p)
{
    uint32_t u = le32(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* Adds the triangles (corner coordinates, 9 per triangle) to m, merging corners. */
static cm_status add_soup(cm_context *ctx, cm_mesh *m, const double *corners, const int *solid,
                          size_t nt)
{
    merge mg;
    cm_status s = merge_init(ctx, &mg, 3 * nt);
    if (s == CM_OK) s = cm_mesh_resize_nodes(ctx, m, 3 * nt, 0);
    if (s == CM_OK) s = cm_mesh_reserve_cells(ctx, m, nt, 3 * nt);
    if (s != CM_OK) {
        free(mg.slot);
        return s;
    }
    m->n_nodes = 0;
    for (size_t t = 0; s == CM_OK && t < nt; ++t) {
        int64_t ids[3];
        for (int k = 0; k < 3; ++k) ids[k] = merge_corner(&mg, m, corners + 9 * t + 3 * k);
        s = cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, ids, 3, solid ? solid[t] : 0, 0, 0);
    }
    free(mg.slot);
    if (s == CM_OK) s = cm_mesh_resize_nodes(ctx, m, m->n_nodes, 0); /* give back the room */
    return s;
}

static cm_status read_binary(cm_context *ctx, const char *path, const unsigned char *d, size_t size,
                             cm_mesh *m)
{
    if (size < 84)
        return cm_error(ctx, CM_ERR_FORMAT, "%s: %zu bytes: too short for a binary STL (80-byte header and a count) "
                        "and does not start with 'solid' (ASCII)", path, size);
    uint64_t nt = le32(d + 80);
    if (84 + 50 * nt != size)
        return cm_error(ctx, CM_ERR_FORMAT, "%s: binary STL header says %llu triangles (%llu bytes), the file has %zu bytes%s",
                        path, (unsigned long long)nt, (unsigned long long)(84 + 50 * nt), size,
                        84 + 50 * nt > size ? " (truncated)" : "");
    double *corners = malloc((nt ? nt : 1) * 9 * sizeof *corners);
    if (!corners) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory for %llu triangles", path, (unsigned long long)nt);
    for (uint64_t t = 0; t < nt; ++t) {
        const unsigned char *p = d + 84 + 50 * t + 12; /* past the normal */
        for (int k = 0; k < 9; ++k) {
            double x = lefloat(p + 4 * k);
            if (!isfinite(x)) {
                free(corners);
                return cm_error(ctx, CM_ERR_FORMAT, "%s: byte %llu: triangle %llu, corner %d: coordinate is not finite",
                                path, (unsigned long long)(84 + 50 * t + 12 + 4 * (uint64_t)k), (unsigned long long)t, k / 3);
            }
            corners[9 * t + (uint64_t)k] = x;
        }
    }
    cm_status s = add_soup(ctx, m, corners, NULL, (size_t)nt);
    free(corners);
    return s;
}

static int word_is(const char *tok, size_t len, const char *w)
{
    return strlen(w) == len && !memcmp(tok, w, len);
}

static cm_status expect(cm_context *ctx, cm_text *t, const char *w)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(t, &tok, &len))
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected '%s', got end of file (truncated?)", t->path, t->line, w);
    if (!word_is(tok, len, w))
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected '%s', got '%.*s'", t->path, t->line, w,
                        (int)(len > 40 ? 40 : len), tok);
    return CM_OK;
}

static cm_status read_ascii(cm_context *ctx, cm_text *t, cm_mesh *m)
{
    double *corners = NULL;
    int *solid = NULL;
    size_t nt = 0, cap = 0;
    int n_solids = 0;
    cm_status s = CM_OK;
    const char *tok;
    size_t len;
    while (s == CM_OK && cm_text_token(t, &tok, &len)) {
        if (!word_is(tok, len, "solid")) {
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected 'solid', got '%.*s'", t->path, t->line,
                         (int)(len > 40 ? 40 : len), tok);
            break;
        }
        /* the name: the rest of the line */
        while (t->pos < t->size && (t->data[t->pos] == ' ' || t->data[t->pos] == '\t')) ++t->pos;
        size_t b = t->pos;
        while (t->pos < t->size && t->data[t->pos] != '\n' && t->data[t->pos] != '\r') ++t->pos;
        char name[256];
        size_t nl = t->pos - b < sizeof name - 1 ? t->pos - b : sizeof name - 1;
        memcpy(name, t->data + b, nl);
        name[nl] = 0;
        ++n_solids;
        if (nl) s = cm_mesh_add_group(ctx, m, 2, n_solids, name);
        for (;;) {
            if (s != CM_OK) break;
            if (!cm_text_token(t, &tok, &len)) {
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected 'facet' or 'endsolid', got end of file (truncated?)",
                             t->path, t->line);
                break;
            }
            if (word_is(tok, len, "endsolid")) {
                cm_text_next_line(t); /* its name, if any */
                break;
            }
            if (!word_is(tok, len, "facet")) {
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected 'facet' or 'endsolid', got '%.*s'", t->path, t->line,
                             (int)(len > 40 ? 40 : len), tok);
                break;
            }
            double nrm;
            s = expect(ctx, t, "normal");
            for (int k = 0; k < 3 && s == CM_OK; ++k) s = cm_text_double(ctx, t, "normal component", &nrm);
            if (s == CM_OK) s = expect(ctx, t, "outer");
            if (s == CM_OK) s = expect(ctx, t, "loop");
            if (s != CM_OK) break;
            if (nt == cap) {
                size_t nc = cap ? 2 * cap : 1024;
                double *c2 = realloc(corners, nc * 9 * sizeof *c2);
                if (c2) corners = c2;
                int *s2 = c2 ? realloc(solid, nc * sizeof *s2) : NULL;
                if (s2) solid = s2;
                if (!c2 || !s2) {
                    s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory at %zu triangles", t->path, nt);
                    break;
                }
                cap = nc;
            }
            for (int v = 0; v < 3 && s == CM_OK; ++v) {
                s = expect(ctx, t, "vertex");
                for (int k = 0; k < 3 && s == CM_OK; ++k) {
                    double *x = &corners[9 * nt + 3 * (size_t)v + (size_t)k];
                    s = cm_text_double(ctx, t, "vertex coordinate", x);
                    if (s == CM_OK && !isfinite(*x))
                        s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: facet %zu: coordinate is not finite", t->path, t->line, nt);
                }
            }
            if (s == CM_OK) s = expect(ctx, t, "endloop");
            if (s == CM_OK) s = expect(ctx, t, "endfacet");
            if (s == CM_OK) solid[nt++] = nl ? n_solids : 0;
        }
    }
    if (s == CM_OK && n_solids == 0) s = cm_error(ctx, CM_ERR_FORMAT, "%s: empty (expected 'solid')", t->path);
    if (s == CM_OK) s = add_soup(ctx, m, corners, solid, nt);
    free(corners);
    free(solid);
    return s;
}

/* Binary if the size matches its count (binary headers may start with "solid" too). */
static cm_status parse_stl(cm_context *ctx, const char *path, const char *data, size_t size,
                           cm_mesh *m)
{
    const unsigned char *d = (const unsigned char *)data;
    size_t lead = 0;
    while (lead < size && (data[lead] == ' ' || data[lead] == '\t' || data[lead] == '\r' || data[lead] == '\n')) ++lead;
    int binary = size >= 84 && 84 + 50 * (uint64_t)le32(d + 80) == size;
    int ascii = !binary && size - lead >= 5 && !memcmp(data + lead, "solid", 5);
    if (!ascii) return read_binary(ctx, path, d, size, m);
    cm_text t;
    cm_text_init(&t, path, data, size);
    return read_ascii(ctx, &t, m);
}

cm_status cm_mesh_read_stl(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    return cm_mesh_read_whole(ctx, "cm_mesh_read_stl", path, parse_stl, mesh);
}

static void put_le32(unsigned char *p, uint32_t u)
{
    p[0] = (unsigned char)u, p[1] = (unsigned char)(u >> 8), p[2] = (unsigned char)(u >> 16), p[3] = (unsigned char)(u >> 24);
}

static void put_float(unsigned char *p, double x)
{
    float f = (float)x;
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    put_le32(p, u);
}

static void facet_normal(const double *a, const double *b, const double *c, double *n)
{
    double u[3], v[3];
    for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], v[k] = c[k] - a[k];
    n[0] = u[1] * v[2] - u[2] * v[1], n[1] = u[2] * v[0] - u[0] * v[2], n[2] = u[0] * v[1] - u[1] * v[0];
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; ++k) n[k] = l > 0 ? n[k] / l : 0.0;
}

cm_status cm_mesh_write_stl(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_stl: NULL argument");
    int binary = !opt || opt->binary;
    size_t nt = 0, skipped = 0, n;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (cm_surface_io_corners(mesh, c, &n) && n >= 3) nt += n - 2;
        else ++skipped;
    }
    if (binary && nt > UINT32_MAX)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: %zu triangles do not fit a binary STL's count; write ASCII", path, nt);
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    FILE *f = out.f;
    if (binary) {
        unsigned char head[84] = {0};
        snprintf((char *)head, 80, "binary STL written by cadmorph");
        put_le32(head + 80, (uint32_t)nt);
        fwrite(head, 1, sizeof head, f);
    } else {
        fputs("solid cadmorph\n", f);
    }
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const int64_t *v = cm_surface_io_corners(mesh, c, &n);
        if (!v || n < 3) continue;
        for (size_t k = 1; k + 1 < n; ++k) {
            const double *x[3] = {mesh->xyz + 3 * v[0], mesh->xyz + 3 * v[k], mesh->xyz + 3 * v[k + 1]};
            double nrm[3];
            facet_normal(x[0], x[1], x[2], nrm);
            if (binary) {
                unsigned char rec[50] = {0};
                for (int j = 0; j < 3; ++j) put_float(rec + 4 * j, nrm[j]);
                for (int q = 0; q < 3; ++q)
                    for (int j = 0; j < 3; ++j) put_float(rec + 12 + 12 * q + 4 * j, x[q][j]);
                fwrite(rec, 1, sizeof rec, f);
            } else {
                fprintf(f, "facet normal %.9g %.9g %.9g\n outer loop\n", nrm[0], nrm[1], nrm[2]);
                for (int q = 0; q < 3; ++q) fprintf(f, "  vertex %.17g %.17g %.17g\n", x[q][0], x[q][1], x[q][2]);
                fputs(" endloop\nendfacet\n", f);
            }
        }
    }
    if (!binary) fputs("endsolid cadmorph\n", f);
    s = cm_outfile_commit(ctx, &out);
    if (s == CM_OK && skipped)
        return cm_error(ctx, CM_WARNING, "%s: %zu cells that are not faces are not written (STL holds triangles only)",
                        path, skipped);
    return s;
}
