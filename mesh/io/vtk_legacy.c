/* Reader of legacy VTK (.vtk) DATASET UNSTRUCTURED_GRID files, ASCII and BINARY (big-endian):
 * classic "CELLS n size" and VTK 5.1 OFFSETS/CONNECTIVITY layouts, SCALARS, VECTORS, FIELD. */
#include "vtk_internal.h"
#include "formats.h"

#include <stdlib.h>
#include <string.h>

typedef struct legacy_reader {
    cm_context *ctx;
    const char *path;
    cm_text t;
    int binary;
} legacy_reader;

static int tok_is(const char *tok, size_t len, const char *word)
{
    return strlen(word) == len && !memcmp(tok, word, len);
}

static cm_status expect_word(legacy_reader *r, const char *word)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len) || !tok_is(tok, len, word))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: expected '%s', got '%.*s'", r->path, r->t.line,
                        word, tok ? (int)(len > 40 ? 40 : len) : 11, tok ? tok : "end of file");
    return CM_OK;
}

/* A count from the file; bounded by what the rest of the file can hold so that a corrupt
 * count cannot make us allocate gigabytes. */
static cm_status read_count(legacy_reader *r, const char *what, size_t min_bytes_each, size_t *n)
{
    int64_t v = 0;
    *n = 0;
    cm_status s = cm_text_int(r->ctx, &r->t, what, &v);
    if (s != CM_OK) return s;
    size_t left = r->t.size - r->t.pos;
    if (v < 0 || (min_bytes_each && (uint64_t)v > left / min_bytes_each + 1))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %s %lld does not fit in the rest of the file (truncated?)",
                        r->path, r->t.line, what, (long long)v);
    *n = (size_t)v;
    return CM_OK;
}

static cm_status read_type(legacy_reader *r, cm_vtk_scalar *type)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: expected a data type, got end of file", r->path, r->t.line);
    *type = cm_vtk_scalar_from_legacy(tok, len);
    if (*type == CM_VTK_SCALAR_COUNT)
        return cm_error(r->ctx, CM_ERR_UNSUPPORTED, "%s:%ld: data type '%.*s' is not supported", r->path,
                        r->t.line, (int)(len > 40 ? 40 : len), tok);
    return CM_OK;
}

/* n values of type into dbl (as double) or i64 (as int64, must be integers). */
static cm_status read_values(legacy_reader *r, cm_vtk_scalar type, size_t n, double *dbl, int64_t *i64,
                             const char *what)
{
    if (!r->binary) {
        for (size_t i = 0; i < n; ++i) {
            cm_status s;
            if (i64) {
                s = cm_text_int(r->ctx, &r->t, what, &i64[i]);
            } else {
                s = cm_text_double(r->ctx, &r->t, what, &dbl[i]);
                /* VTK stores "float" data as float: round the same way. */
                if (type == CM_VTK_FLOAT32) dbl[i] = (float)dbl[i];
            }
            if (s != CM_OK) return s;
        }
        return CM_OK;
    }
    /* Binary data starts on the line after the keyword line. */
    cm_text_next_line(&r->t);
    size_t w = cm_vtk_scalar_size(type), at = r->t.pos;
    if (n > (r->t.size - at) / w)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s: byte offset %zu: %s: expected %zu binary values of %zu bytes, file ends first (truncated?)",
                        r->path, at, what, n, w);
    void *tmp = malloc(n ? n * w : 1);
    if (!tmp) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
    memcpy(tmp, r->t.data + at, n * w);
    if (cm_host_little_endian()) cm_vtk_swap(type, tmp, n);
    cm_status s = CM_OK;
    if (i64) {
        size_t bad = cm_vtk_to_int64(type, tmp, n, i64);
        if (bad != n)
            s = cm_error(r->ctx, CM_ERR_FORMAT, "%s: byte offset %zu: %s: value %zu is not an integer",
                         r->path, at + bad * w, what, bad);
    } else {
        cm_vtk_to_double(type, tmp, n, dbl);
    }
    free(tmp);
    r->t.pos = at + n * w;
    return s;
}

/* VTK escapes spaces and odd characters in names as %xx. */
static char *decode_name(const char *tok, size_t len)
{
    char *s = malloc(len + 1);
    if (!s) return NULL;
    size_t k = 0;
    for (size_t i = 0; i < len; ++i) {
        unsigned v;
        char hex[3] = {0};
        if (tok[i] == '%' && i + 2 < len) {
            hex[0] = tok[i + 1];
            hex[1] = tok[i + 2];
            if (sscanf(hex, "%2x", &v) == 1) {
                s[k++] = (char)v;
                i += 2;
                continue;
            }
        }
        s[k++] = tok[i];
    }
    s[k] = '\0';
    return s;
}

static cm_status read_points(legacy_reader *r, cm_mesh *mesh)
{
    size_t n;
    cm_vtk_scalar type;
    long line = r->t.line;
    cm_status s = read_count(r, "point count", r->binary ? 12 : 6, &n);
    if (s == CM_OK) s = read_type(r, &type);
    if (s == CM_OK) s = cm_mesh_resize_nodes(r->ctx, mesh, n, 0);
    if (s == CM_OK) s = read_values(r, type, 3 * n, mesh->xyz, NULL, "point coordinate");
    if (s == CM_OK) {
        char where[4096];
        snprintf(where, sizeof where, "%s:%ld", r->path, line);
        s = cm_vtk_check_points(r->ctx, mesh, where);
    }
    return s;
}

typedef struct cells_in {
    size_t n;
    int64_t *off, *conn, *type;
    size_t n_conn;
    long line;
} cells_in;

static cm_status read_cells(legacy_reader *r, cells_in *c)
{
    size_t a, b;
    c->line = r->t.line;
    cm_status s = read_count(r, "cell count", r->binary ? 4 : 2, &a);
    if (s == CM_OK) s = read_count(r, "cell list size", r->binary ? 4 : 2, &b);
    if (s != CM_OK) return s;
    size_t save = r->t.pos;
    long save_line = r->t.line;
    const char *tok = NULL;
    size_t len = 0;
    if (cm_text_token(&r->t, &tok, &len) && tok_is(tok, len, "OFFSETS")) {
        /* VTK 5.1: a = cells + 1 offsets, b = connectivity entries */
        cm_vtk_scalar ot, ct;
        if (a < 1) return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: CELLS needs at least one offset", r->path, c->line);
        c->n = a - 1;
        c->off = malloc(a * sizeof(int64_t));
        c->conn = malloc((b ? b : 1) * sizeof(int64_t));
        if (!c->off || !c->conn) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
        c->n_conn = b;
        s = read_type(r, &ot);
        if (s == CM_OK) s = read_values(r, ot, a, NULL, c->off, "cell offset");
        if (s == CM_OK) s = expect_word(r, "CONNECTIVITY");
        if (s == CM_OK) s = read_type(r, &ct);
        if (s == CM_OK) s = read_values(r, ct, b, NULL, c->conn, "cell node id");
        if (s == CM_OK && c->off[0] != 0)
            s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: OFFSETS must start at 0", r->path, c->line);
        if (s == CM_OK && (uint64_t)c->off[a - 1] != b)
            s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: last offset %lld differs from the %zu connectivity entries",
                         r->path, c->line, (long long)c->off[a - 1], b);
        return s;
    }
    r->t.pos = save;
    r->t.line = save_line;
    /* classic: a cells, b integers "n id id ..." */
    if (a > b) return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: CELLS %zu %zu: list is too short", r->path, c->line, a, b);
    int64_t *list = malloc((b ? b : 1) * sizeof(int64_t));
    c->off = malloc((a + 1) * sizeof(int64_t));
    c->conn = malloc((b ? b : 1) * sizeof(int64_t));
    if (!list || !c->off || !c->conn) {
        free(list);
        return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
    }
    s = read_values(r, CM_VTK_INT32, b, NULL, list, "cell list entry");
    size_t p = 0, k = 0;
    c->off[0] = 0;
    for (size_t i = 0; s == CM_OK && i < a; ++i) {
        if (p >= b || list[p] < 0 || (uint64_t)list[p] > b - p - 1) {
            s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: CELLS: cell %zu: node count runs past the list of %zu entries",
                         r->path, c->line, i, b);
            break;
        }
        memcpy(c->conn + k, list + p + 1, (size_t)list[p] * sizeof(int64_t));
        k += (size_t)list[p];
        p += 1 + (size_t)list[p];
        c->off[i + 1] = (int64_t)k;
    }
    if (s == CM_OK && p != b)
        s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: CELLS: list has %zu entries, cells use %zu", r->path, c->line, b, p);
    free(list);
    c->n = a;
    c->n_conn = k;
    return s;
}

/* One data array: gmsh:physical / gmsh:geometrical (meshio's names) become cell tags,
 * everything else a field (gmsh's own CellEntityIds too: which tag it holds depends on
 * gmsh's Mesh.SaveElementTagType, so it is not guessed). */
static cm_status store_array(legacy_reader *r, cm_mesh *mesh, cm_field_location loc, size_t n,
                             const char *name, int comps, cm_vtk_scalar type)
{
    int tag = 0;
    if (loc == CM_FIELD_CELL && comps == 1) {
        if (!strcmp(name, "gmsh:physical")) tag = 1;
        else if (!strcmp(name, "gmsh:geometrical")) tag = 2;
    }
    size_t count = n * (size_t)comps;
    /* bound before allocating: each value takes >= 2 bytes of text or its width in binary */
    size_t each = r->binary ? cm_vtk_scalar_size(type) : 2;
    if (count / (size_t)comps != n || count > (r->t.size - r->t.pos) / each + 1)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: array '%s': %zu x %d values do not fit in the rest of the file (truncated?)",
                        r->path, r->t.line, name, n, comps);
    if (tag) {
        int64_t *v = malloc((count ? count : 1) * sizeof *v);
        if (!v) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
        cm_status s = read_values(r, type, count, NULL, v, name);
        for (size_t i = 0; s == CM_OK && i < count; ++i) {
            if (v[i] < INT32_MIN || v[i] > INT32_MAX)
                s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %s: value %lld out of range", r->path,
                             r->t.line, name, (long long)v[i]);
            else (tag == 1 ? mesh->physical : mesh->entity)[i] = (int)v[i];
        }
        free(v);
        return s;
    }
    double *d = NULL;
    cm_status s = cm_mesh_add_field(r->ctx, mesh, name, loc, comps, &d);
    if (s == CM_OK) s = read_values(r, type, count, d, NULL, name);
    return s;
}

static cm_status read_name(legacy_reader *r, char **name)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: expected an array name, got end of file", r->path, r->t.line);
    *name = decode_name(tok, len);
    return *name ? CM_OK : cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
}

/* METADATA blocks (VTK 9 writes them after arrays) end at an empty line. */
static void skip_metadata(legacy_reader *r)
{
    cm_text_next_line(&r->t);
    while (r->t.pos < r->t.size) {
        size_t p = r->t.pos;
        while (p < r->t.size && (r->t.data[p] == ' ' || r->t.data[p] == '\t' || r->t.data[p] == '\r')) ++p;
        if (p >= r->t.size || r->t.data[p] == '\n') {
            cm_text_next_line(&r->t);
            return;
        }
        cm_text_next_line(&r->t);
    }
}

static cm_status read_attribute(legacy_reader *r, cm_mesh *mesh, cm_field_location loc, size_t n,
                                const char *kw, size_t kwlen)
{
    char *name = NULL;
    cm_vtk_scalar type;
    cm_status s = CM_OK;
    if (tok_is(kw, kwlen, "SCALARS")) {
        int64_t comps = 1;
        s = read_name(r, &name);
        if (s == CM_OK) s = read_type(r, &type);
        /* optional component count on the same line */
        if (s == CM_OK) {
            size_t p = r->t.pos;
            while (p < r->t.size && (r->t.data[p] == ' ' || r->t.data[p] == '\t')) ++p;
            if (p < r->t.size && r->t.data[p] >= '0' && r->t.data[p] <= '9') s = cm_text_int(r->ctx, &r->t, "component count", &comps);
            if (s == CM_OK && (comps < 1 || comps > 4))
                s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: SCALARS: component count %lld is not 1..4", r->path, r->t.line, (long long)comps);
        }
        const char *tok = NULL;
        size_t len = 0;
        size_t save = r->t.pos;
        long save_line = r->t.line;
        if (s == CM_OK && cm_text_token(&r->t, &tok, &len) && tok_is(tok, len, "LOOKUP_TABLE")) {
            if (!cm_text_token(&r->t, &tok, &len))
                s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: LOOKUP_TABLE needs a name", r->path, r->t.line);
        } else {
            r->t.pos = save;
            r->t.line = save_line;
        }
        if (s == CM_OK) s = store_array(r, mesh, loc, n, name, (int)comps, type);
    } else if (tok_is(kw, kwlen, "VECTORS") || tok_is(kw, kwlen, "NORMALS") || tok_is(kw, kwlen, "TENSORS")) {
        s = read_name(r, &name);
        if (s == CM_OK) s = read_type(r, &type);
        if (s == CM_OK) s = store_array(r, mesh, loc, n, name, kw[0] == 'T' ? 9 : 3, type);
    } else if (tok_is(kw, kwlen, "GLOBAL_IDS") || tok_is(kw, kwlen, "PEDIGREE_IDS")) {
        s = read_name(r, &name);
        if (s == CM_OK) s = read_type(r, &type);
        if (s == CM_OK) s = store_array(r, mesh, loc, n, name, 1, type);
    } else if (tok_is(kw, kwlen, "TEXTURE_COORDINATES")) {
        int64_t dim;
        s = read_name(r, &name);
        if (s == CM_OK) s = cm_text_int(r->ctx, &r->t, "texture dimension", &dim);
        if (s == CM_OK && (dim < 1 || dim > 3)) s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: bad texture dimension", r->path, r->t.line);
        if (s == CM_OK) s = read_type(r, &type);
        if (s == CM_OK) s = store_array(r, mesh, loc, n, name, (int)dim, type);
    } else if (tok_is(kw, kwlen, "FIELD")) {
        size_t narr;
        s = read_name(r, &name);
        free(name);
        name = NULL;
        if (s == CM_OK) s = read_count(r, "field array count", 4, &narr);
        for (size_t i = 0; s == CM_OK && i < narr; ++i) {
            const char *tok = NULL;
            size_t len = 0;
            if (!cm_text_token(&r->t, &tok, &len)) {
                s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: FIELD: expected %zu arrays, file ends first", r->path, r->t.line, narr);
                break;
            }
            if (tok_is(tok, len, "METADATA")) {
                skip_metadata(r);
                --i;
                continue;
            }
            free(name);
            name = decode_name(tok, len);
            if (!name) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
            int64_t comps, tuples;
            s = cm_text_int(r->ctx, &r->t, "component count", &comps);
            if (s == CM_OK) s = cm_text_int(r->ctx, &r->t, "tuple count", &tuples);
            if (s == CM_OK) s = read_type(r, &type);
            if (s == CM_OK && (comps < 1 || comps > 1000 || (uint64_t)tuples != n))
                s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: FIELD array '%s': %lld x %lld values, expected %zu tuples",
                             r->path, r->t.line, name, (long long)tuples, (long long)comps, n);
            if (s == CM_OK) s = store_array(r, mesh, loc, n, name, (int)comps, type);
        }
    } else if (tok_is(kw, kwlen, "LOOKUP_TABLE")) {
        size_t size;
        const char *tok = NULL;
        size_t len = 0;
        if (!cm_text_token(&r->t, &tok, &len)) return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: LOOKUP_TABLE needs a name", r->path, r->t.line);
        s = read_count(r, "lookup table size", 4, &size);
        double *tmp = malloc((size ? 4 * size : 1) * sizeof *tmp);
        if (s == CM_OK && !tmp) s = cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
        if (s == CM_OK) s = read_values(r, r->binary ? CM_VTK_UINT8 : CM_VTK_FLOAT64, 4 * size, tmp, NULL, "lookup table");
        free(tmp);
    } else {
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: unknown or unsupported keyword '%.*s'", r->path,
                        r->t.line, (int)(kwlen > 40 ? 40 : kwlen), kw);
    }
    free(name);
    return s;
}

static cm_status read_body(legacy_reader *r, cm_mesh *mesh)
{
    cm_text *t = &r->t;
    if (t->size < 23 || memcmp(t->data, "# vtk DataFile Version", 22))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:1: expected '# vtk DataFile Version x.y'", r->path);
    cm_text_next_line(t);
    cm_text_next_line(t); /* title */
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(t, &tok, &len) || (!tok_is(tok, len, "ASCII") && !tok_is(tok, len, "BINARY")))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: expected ASCII or BINARY", r->path, t->line);
    r->binary = tok[0] == 'B';
    cm_status s = expect_word(r, "DATASET");
    if (s != CM_OK) return s;
    if (!cm_text_token(t, &tok, &len) || !tok_is(tok, len, "UNSTRUCTURED_GRID"))
        return cm_error(r->ctx, CM_ERR_UNSUPPORTED, "%s:%ld: DATASET '%.*s' is not supported (only UNSTRUCTURED_GRID)",
                        r->path, t->line, tok ? (int)(len > 40 ? 40 : len) : 0, tok ? tok : "");
    cells_in cells;
    memset(&cells, 0, sizeof cells);
    int have_points = 0, have_cells = 0, have_types = 0, built = 0;
    cm_field_location loc = CM_FIELD_NODE;
    size_t n_data = 0;
    int in_data = 0;
    while (s == CM_OK && cm_text_token(t, &tok, &len)) {
        if (tok_is(tok, len, "POINTS") && !have_points) {
            s = read_points(r, mesh);
            have_points = 1;
        } else if (tok_is(tok, len, "CELLS") && !have_cells) {
            s = read_cells(r, &cells);
            have_cells = 1;
        } else if (tok_is(tok, len, "CELL_TYPES") && !have_types) {
            size_t n;
            long line = t->line;
            s = read_count(r, "cell type count", r->binary ? 4 : 2, &n);
            if (s == CM_OK && (!have_cells || n != cells.n))
                s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: CELL_TYPES %zu does not match CELLS (%zu cells)",
                             r->path, line, n, cells.n);
            if (s == CM_OK) {
                cells.type = malloc((n ? n : 1) * sizeof(int64_t));
                if (!cells.type) s = cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
            }
            if (s == CM_OK) s = read_values(r, CM_VTK_INT32, n, NULL, cells.type, "cell type");
            have_types = 1;
        } else if (tok_is(tok, len, "POINT_DATA") || tok_is(tok, len, "CELL_DATA")) {
            loc = tok[0] == 'P' ? CM_FIELD_NODE : CM_FIELD_CELL;
            long line = t->line;
            s = read_count(r, "data count", 0, &n_data);
            size_t want = loc == CM_FIELD_NODE ? mesh->n_nodes : cells.n;
            if (s == CM_OK && n_data != want)
                s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: %.*s %zu, but the grid has %zu", r->path, line,
                             (int)len, tok, n_data, want);
            in_data = 1;
        } else if (tok_is(tok, len, "METADATA")) {
            skip_metadata(r);
        } else if (in_data) {
            if (!built && have_cells) {
                if (!have_types)
                    s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: CELL_TYPES missing", r->path, cells.line);
                if (s == CM_OK) {
                    char where[4096];
                    snprintf(where, sizeof where, "%s:%ld", r->path, cells.line);
                    cm_vtk_cells vc = {cells.n, cells.type, cells.off, cells.conn, cells.n_conn, NULL, NULL, 0};
                    s = cm_vtk_cells_to_mesh(r->ctx, &vc, where, mesh);
                }
                built = 1;
            }
            if (s == CM_OK) s = read_attribute(r, mesh, loc, n_data, tok, len);
        } else {
            s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: unexpected keyword '%.*s'", r->path, t->line,
                         (int)(len > 40 ? 40 : len), tok);
        }
    }
    if (s == CM_OK && !have_points && (have_cells || in_data))
        s = cm_error(r->ctx, CM_ERR_FORMAT, "%s: no POINTS section", r->path);
    if (s == CM_OK && have_cells && !have_types)
        s = cm_error(r->ctx, CM_ERR_FORMAT, "%s: CELLS without CELL_TYPES (truncated?)", r->path);
    if (s == CM_OK && have_cells && !built) {
        char where[4096];
        snprintf(where, sizeof where, "%s:%ld", r->path, cells.line);
        cm_vtk_cells vc = {cells.n, cells.type, cells.off, cells.conn, cells.n_conn, NULL, NULL, 0};
        s = cm_vtk_cells_to_mesh(r->ctx, &vc, where, mesh);
    }
    free(cells.off);
    free(cells.conn);
    free(cells.type);
    return s;
}

static cm_status parse_vtk(cm_context *ctx, const char *path, const char *data, size_t size,
                           cm_mesh *m)
{
    legacy_reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.path = path;
    cm_text_init(&r.t, path, data, size);
    return read_body(&r, m);
}

cm_status cm_mesh_read_vtk(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    return cm_mesh_read_whole(ctx, "cm_mesh_read_vtk", path, parse_vtk, mesh);
}
