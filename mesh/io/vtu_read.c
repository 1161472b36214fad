/* Reader of VTK XML UnstructuredGrid (.vtu) files as ParaView, VTK and meshio write them:
 * ascii, inline base64 and appended (raw or base64) data, optionally zlib-compressed. */
#include "vtk_internal.h"
#include "formats.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

typedef struct vtu_reader {
    cm_context *ctx;
    const char *path;
    cm_xml x;
    cm_vtu_decoder d;
    size_t n_points, n_cells;
} vtu_reader;

static cm_status parse_count(vtu_reader *r, int piece, const char *name, size_t *n)
{
    const char *v = cm_xml_get(&r->x, piece, name);
    char *end;
    errno = 0;
    long long k = v ? strtoll(v, &end, 10) : -1;
    if (!v || !*v || *end || k < 0 || errno)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: <Piece> needs a non-negative %s", r->path,
                        cm_xml_line(&r->x, r->x.elem[piece].pos), name);
    /* Every point and cell takes at least one byte of data, which zlib packs at most ~1032:1:
     * a count beyond that cannot be in the file (and 3 x count must not wrap). */
    if ((unsigned long long)k / 1100 > r->x.size)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: <Piece> %s=\"%lld\" is more than a file of %zu bytes can hold",
                        r->path, cm_xml_line(&r->x, r->x.elem[piece].pos), name, k, r->x.size);
    *n = (size_t)k;
    return CM_OK;
}

/* Decodes a DataArray that must hold `want` values (SIZE_MAX: any count up to max). */
static cm_status decode(vtu_reader *r, int elem, size_t want, size_t max, cm_vtu_array *a)
{
    cm_status s = cm_vtu_array_decode(&r->d, elem, want != SIZE_MAX ? want : max, a);
    if (s == CM_ERR_UNSUPPORTED && a->unsupported_type) s = CM_ERR_FORMAT;
    if (s != CM_OK) return s;
    if (want != SIZE_MAX && a->count != want)
        return cm_error(r->ctx, CM_ERR_FORMAT,
                        "%s:%ld: DataArray '%s': expected %zu values, got %zu (wrong NumberOfPoints/NumberOfCells?)",
                        r->path, cm_xml_line(&r->x, r->x.elem[elem].pos), a->name ? a->name : "", want,
                        a->count);
    return CM_OK;
}

static cm_status to_int64(vtu_reader *r, int elem, cm_vtu_array *a, int64_t **out)
{
    if (a->type == CM_VTK_INT64) {
        /* already the right type: take the buffer instead of copying 8 bytes per id */
        *out = (int64_t *)(void *)a->bytes;
        a->bytes = NULL;
        return CM_OK;
    }
    *out = malloc((a->count ? a->count : 1) * sizeof(int64_t));
    if (!*out) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
    size_t bad = cm_vtk_to_int64(a->type, a->bytes, a->count, *out);
    if (bad != a->count)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: DataArray '%s': value %zu is not an integer id",
                        r->path, cm_xml_line(&r->x, r->x.elem[elem].pos), a->name ? a->name : "", bad);
    return CM_OK;
}

static int find_array(const cm_xml *x, int parent, const char *name)
{
    for (int c = cm_xml_child(x, parent, "DataArray", -1); c >= 0; c = cm_xml_child(x, parent, "DataArray", c)) {
        const char *n = cm_xml_get(x, c, "Name");
        if (n && !strcmp(n, name)) return c;
    }
    return -1;
}

static cm_status read_points(vtu_reader *r, int piece, cm_mesh *mesh)
{
    int pts = cm_xml_child(&r->x, piece, "Points", -1);
    int arr = pts >= 0 ? cm_xml_child(&r->x, pts, "DataArray", -1) : -1;
    if (arr < 0) {
        if (r->n_points == 0) return CM_OK;
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: <Piece> has no <Points><DataArray>", r->path,
                        cm_xml_line(&r->x, r->x.elem[piece].pos));
    }
    cm_vtu_array a;
    cm_status s = decode(r, arr, 3 * r->n_points, SIZE_MAX, &a);
    if (s == CM_OK && a.components != 3)
        s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: points need NumberOfComponents=\"3\"", r->path,
                     cm_xml_line(&r->x, r->x.elem[arr].pos));
    if (s == CM_OK) s = cm_mesh_resize_nodes(r->ctx, mesh, r->n_points, 0);
    if (s == CM_OK) {
        cm_vtk_to_double(a.type, a.bytes, a.count, mesh->xyz);
        char where[64];
        snprintf(where, sizeof where, "%ld", cm_xml_line(&r->x, r->x.elem[arr].pos));
        size_t n = strlen(r->path) + sizeof where + 2;
        char *w = malloc(n);
        if (!w) s = cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
        else {
            snprintf(w, n, "%s:%s", r->path, where);
            s = cm_vtk_check_points(r->ctx, mesh, w);
            free(w);
        }
    }
    cm_vtu_array_free(&a);
    return s;
}

static cm_status read_cells(vtu_reader *r, int piece, cm_mesh *mesh)
{
    const cm_xml *x = &r->x;
    int cells = cm_xml_child(x, piece, "Cells", -1);
    if (cells < 0) {
        if (r->n_cells == 0) return CM_OK;
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: <Piece> has no <Cells>", r->path,
                        cm_xml_line(x, x->elem[piece].pos));
    }
    const char *names[5] = {"connectivity", "offsets", "types", "faces", "faceoffsets"};
    int el[5];
    for (int i = 0; i < 5; ++i) {
        el[i] = find_array(x, cells, names[i]);
        if (i < 3 && el[i] < 0)
            return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: <Cells> has no DataArray '%s'", r->path,
                            cm_xml_line(x, x->elem[cells].pos), names[i]);
    }
    if ((el[3] < 0) != (el[4] < 0))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: <Cells> needs both 'faces' and 'faceoffsets'",
                        r->path, cm_xml_line(x, x->elem[cells].pos));
    cm_vtu_array a[5];
    int64_t *v[5] = {0};
    size_t count[5] = {0};
    memset(a, 0, sizeof a);
    int64_t *off = NULL, *foff = NULL;
    cm_status s = CM_OK;
    const size_t want[5] = {SIZE_MAX, r->n_cells, r->n_cells, SIZE_MAX, r->n_cells};
    /* the offsets first: their last values bound connectivity and faces, so that neither
     * can be inflated past what the cells use */
    static const int order[5] = {1, 2, 4, 0, 3};
    size_t max[5] = {0, SIZE_MAX, SIZE_MAX, 0, SIZE_MAX};
    for (int k = 0; k < 5 && s == CM_OK; ++k) {
        const int i = order[k];
        if (el[i] < 0) continue;
        if (i == 0 && r->n_cells > 0 && v[1][r->n_cells - 1] > 0) max[0] = (size_t)v[1][r->n_cells - 1];
        if (i == 3)
            for (size_t c = 0; c < r->n_cells; ++c)
                if (v[4][c] > 0 && (size_t)v[4][c] > max[3]) max[3] = (size_t)v[4][c];
        s = decode(r, el[i], want[i], max[i], &a[i]);
        if (s == CM_OK) s = to_int64(r, el[i], &a[i], &v[i]);
        count[i] = a[i].count;
        cm_vtu_array_free(&a[i]);
    }
    if (s == CM_OK) {
        off = malloc((r->n_cells + 1) * sizeof *off);
        foff = v[3] ? malloc((r->n_cells + 1) * sizeof *foff) : NULL;
        if (!off || (v[3] && !foff)) s = cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
    }
    if (s == CM_OK) {
        /* .vtu offsets are end offsets; faceoffsets are end offsets or -1 (not a polyhedron). */
        off[0] = 0;
        memcpy(off + 1, v[1], r->n_cells * sizeof *off);
        if (foff) {
            foff[0] = 0;
            for (size_t c = 0; c < r->n_cells; ++c) foff[c + 1] = v[4][c] >= 0 ? v[4][c] : foff[c];
        }
        cm_vtk_cells vc = {r->n_cells, v[2], off, v[0], count[0], v[3], foff, count[3]};
        char where[32];
        snprintf(where, sizeof where, "%ld", cm_xml_line(x, x->elem[cells].pos));
        size_t n = strlen(r->path) + sizeof where + 2;
        char *w = malloc(n);
        if (!w) s = cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->path);
        else {
            snprintf(w, n, "%s:%s", r->path, where);
            s = cm_vtk_cells_to_mesh(r->ctx, &vc, w, mesh);
            free(w);
        }
    }
    for (int i = 0; i < 5; ++i) free(v[i]);
    free(off);
    free(foff);
    return s;
}

/* PointData / CellData arrays become fields; meshio's gmsh:physical / gmsh:geometrical cell
 * arrays become the cells' physical / entity tags. */
static cm_status read_data(vtu_reader *r, int piece, const char *section, cm_field_location loc,
                           cm_mesh *mesh)
{
    const cm_xml *x = &r->x;
    const size_t n = loc == CM_FIELD_NODE ? r->n_points : r->n_cells;
    cm_status s = CM_OK;
    for (int sec = cm_xml_child(x, piece, section, -1); sec >= 0 && s == CM_OK;
         sec = cm_xml_child(x, piece, section, sec))
        for (int e = cm_xml_child(x, sec, "DataArray", -1); e >= 0 && s == CM_OK;
             e = cm_xml_child(x, sec, "DataArray", e)) {
            cm_vtu_array a;
            /* components from the attribute: the bound is the expected count */
            const char *nc = cm_xml_get(x, e, "NumberOfComponents");
            const long ncomp = nc ? strtol(nc, NULL, 10) : 1;
            s = cm_vtu_array_decode(&r->d, e, ncomp >= 1 && ncomp <= 1000 ? n * (size_t)ncomp : n, &a);
            if (s == CM_ERR_UNSUPPORTED && a.unsupported_type) {
                /* String/Bit arrays carry no numbers for us: skip them. */
                cm_context_clear(r->ctx);
                s = CM_OK;
                continue;
            }
            if (s == CM_OK && (n == 0 ? a.count != 0 : a.count % n != 0 || a.count / n != (size_t)a.components))
                s = cm_error(r->ctx, CM_ERR_FORMAT,
                             "%s:%ld: DataArray '%s': expected %zu x %d values, got %zu", r->path,
                             cm_xml_line(x, x->elem[e].pos), a.name ? a.name : "", n, a.components, a.count);
            char fallback[32];
            const char *name = a.name;
            if (!name) {
                snprintf(fallback, sizeof fallback, "array%d", e);
                name = fallback;
            }
            int tag = loc == CM_FIELD_CELL && a.components == 1 ?
                          (!strcmp(name, "gmsh:physical") ? 1 : !strcmp(name, "gmsh:geometrical") ? 2 : 0) : 0;
            if (s == CM_OK && tag) {
                int64_t *iv = NULL;
                s = to_int64(r, e, &a, &iv);
                for (size_t c = 0; s == CM_OK && c < n; ++c) {
                    if (iv[c] < INT32_MIN || iv[c] > INT32_MAX)
                        s = cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: '%s' value %lld out of range",
                                     r->path, cm_xml_line(x, x->elem[e].pos), name, (long long)iv[c]);
                    else (tag == 1 ? mesh->physical : mesh->entity)[c] = (int)iv[c];
                }
                free(iv);
            } else if (s == CM_OK) {
                double *d = NULL;
                s = cm_mesh_add_field(r->ctx, mesh, name, loc, a.components, &d);
                if (s == CM_OK) cm_vtk_to_double(a.type, a.bytes, a.count, d);
            }
            cm_vtu_array_free(&a);
        }
    return s;
}

static cm_status read_grid(vtu_reader *r, cm_mesh *mesh)
{
    cm_xml *x = &r->x;
    int root = 0;
    if (!cm_xml_is(x, root, "VTKFile"))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: expected <VTKFile> as the root element", r->path,
                        cm_xml_line(x, x->elem[root].pos));
    const char *type = cm_xml_get(x, root, "type");
    if (!type || strcmp(type, "UnstructuredGrid"))
        return cm_error(r->ctx, CM_ERR_UNSUPPORTED, "%s: VTK XML type '%s' is not supported (only UnstructuredGrid)",
                        r->path, type ? type : "(none)");
    const char *order = cm_xml_get(x, root, "byte_order");
    if (order && !strcmp(order, "BigEndian"))
        return cm_error(r->ctx, CM_ERR_UNSUPPORTED, "%s: byte_order=\"BigEndian\" is not supported (write LittleEndian)",
                        r->path);
    if (order && strcmp(order, "LittleEndian"))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s: unknown byte_order '%s'", r->path, order);
    const char *ht = cm_xml_get(x, root, "header_type");
    if (ht && strcmp(ht, "UInt32") && strcmp(ht, "UInt64"))
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s: unknown header_type '%s'", r->path, ht);
    const char *comp = cm_xml_get(x, root, "compressor");
    if (comp && *comp && strcmp(comp, "vtkZLibDataCompressor"))
        return cm_error(r->ctx, CM_ERR_UNSUPPORTED, "%s: compressor '%s' is not supported (only vtkZLibDataCompressor)",
                        r->path, comp);
    r->d.ctx = r->ctx;
    r->d.path = r->path;
    r->d.x = x;
    r->d.hdr64 = ht && !strcmp(ht, "UInt64");
    r->d.compressed = comp && *comp;
    r->d.app_end = x->size;
    if (x->appended_elem >= 0) {
        const char *enc = cm_xml_get(x, x->appended_elem, "encoding");
        if (!enc || (strcmp(enc, "raw") && strcmp(enc, "base64")))
            return cm_error(r->ctx, CM_ERR_FORMAT, "%s:%ld: <AppendedData> needs encoding=\"raw\" or \"base64\"",
                            r->path, cm_xml_line(x, x->elem[x->appended_elem].pos));
        r->d.app_base64 = !strcmp(enc, "base64");
        if (r->d.app_base64) {
            const char *lt = memchr(x->data + x->appended, '<', x->size - x->appended);
            if (lt) r->d.app_end = (size_t)(lt - x->data);
        }
    }
    int grid = cm_xml_child(x, root, "UnstructuredGrid", -1);
    int piece = grid >= 0 ? cm_xml_child(x, grid, "Piece", -1) : -1;
    if (piece < 0)
        return cm_error(r->ctx, CM_ERR_FORMAT, "%s: no <UnstructuredGrid><Piece> found", r->path);
    if (cm_xml_child(x, grid, "Piece", piece) >= 0)
        return cm_error(r->ctx, CM_ERR_UNSUPPORTED, "%s: files with several <Piece> elements are not supported",
                        r->path);
    cm_status s = parse_count(r, piece, "NumberOfPoints", &r->n_points);
    if (s == CM_OK) s = parse_count(r, piece, "NumberOfCells", &r->n_cells);
    if (s == CM_OK) s = read_points(r, piece, mesh);
    if (s == CM_OK) s = read_cells(r, piece, mesh);
    if (s == CM_OK) s = read_data(r, piece, "PointData", CM_FIELD_NODE, mesh);
    if (s == CM_OK) s = read_data(r, piece, "CellData", CM_FIELD_CELL, mesh);
    return s;
}

cm_status cm_mesh_read_vtu(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read_vtu: NULL argument");
    *mesh = NULL;
    char *data = NULL;
    size_t size = 0;
    cm_status s = cm_file_read(ctx, path, &data, &size);
    if (s != CM_OK) return s;
    vtu_reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.path = path;
    cm_mesh *m = NULL;
    s = cm_xml_parse(ctx, path, data, size, &r.x);
    if (s == CM_OK) s = cm_mesh_create(ctx, &m);
    if (s == CM_OK) s = read_grid(&r, m);
    cm_xml_free(&r.x);
    free(data);
    if (s != CM_OK) {
        cm_mesh_destroy(&m);
        return s;
    }
    *mesh = m;
    return CM_OK;
}
