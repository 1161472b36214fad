/* What the .vtu and legacy .vtk readers share: VTK scalar types and their conversion, and
 * the translation of VTK cell arrays (connectivity, offsets, types, faces) into a cm_mesh. */
#include "vtk_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const size_t sizes[CM_VTK_SCALAR_COUNT] = {1, 1, 2, 2, 4, 4, 8, 8, 4, 8};

size_t cm_vtk_scalar_size(cm_vtk_scalar t) { return (unsigned)t < CM_VTK_SCALAR_COUNT ? sizes[t] : 0; }

int cm_vtk_scalar_is_float(cm_vtk_scalar t) { return t == CM_VTK_FLOAT32 || t == CM_VTK_FLOAT64; }

cm_vtk_scalar cm_vtk_scalar_from_xml(const char *name)
{
    static const char *names[CM_VTK_SCALAR_COUNT] = {"Int8",  "UInt8",  "Int16",  "UInt16",
                                                     "Int32", "UInt32", "Int64",  "UInt64",
                                                     "Float32", "Float64"};
    if (!name) return CM_VTK_SCALAR_COUNT;
    for (int t = 0; t < CM_VTK_SCALAR_COUNT; ++t)
        if (!strcmp(name, names[t])) return (cm_vtk_scalar)t;
    return CM_VTK_SCALAR_COUNT;
}

cm_vtk_scalar cm_vtk_scalar_from_legacy(const char *name, size_t len)
{
    /* every numeric name vtkDataReader knows: the C names, the fixed-width vtktype names
     * (meshio writes vtktypeint32, vtktypefloat64, ...) and vtkIdType; like VTK, in any case */
    static const struct { const char *name; cm_vtk_scalar t; } names[] = {
        {"char", CM_VTK_INT8},           {"signed_char", CM_VTK_INT8},
        {"unsigned_char", CM_VTK_UINT8}, {"short", CM_VTK_INT16},
        {"unsigned_short", CM_VTK_UINT16}, {"int", CM_VTK_INT32},
        {"unsigned_int", CM_VTK_UINT32}, {"long", CM_VTK_INT64},
        {"unsigned_long", CM_VTK_UINT64}, {"long_long", CM_VTK_INT64},
        {"unsigned_long_long", CM_VTK_UINT64}, {"vtkidtype", CM_VTK_INT64},
        {"vtktypeint8", CM_VTK_INT8},    {"vtktypeuint8", CM_VTK_UINT8},
        {"vtktypeint16", CM_VTK_INT16},  {"vtktypeuint16", CM_VTK_UINT16},
        {"vtktypeint32", CM_VTK_INT32},  {"vtktypeuint32", CM_VTK_UINT32},
        {"vtktypeint64", CM_VTK_INT64},  {"vtktypeuint64", CM_VTK_UINT64},
        {"vtktypefloat32", CM_VTK_FLOAT32}, {"vtktypefloat64", CM_VTK_FLOAT64},
        {"float", CM_VTK_FLOAT32},       {"double", CM_VTK_FLOAT64}};
    for (size_t i = 0; i < sizeof names / sizeof *names; ++i) {
        const char *n = names[i].name;
        if (strlen(n) != len) continue;
        size_t k = 0;
        while (k < len && (name[k] >= 'A' && name[k] <= 'Z' ? name[k] - 'A' + 'a' : name[k]) == n[k]) ++k;
        if (k == len) return names[i].t;
    }
    return CM_VTK_SCALAR_COUNT;
}

void cm_vtk_swap(cm_vtk_scalar t, void *data, size_t n)
{
    size_t w = cm_vtk_scalar_size(t);
    uint8_t *b = data;
    if (w < 2) return;
    for (size_t i = 0; i < n; ++i, b += w)
        for (size_t k = 0; k < w / 2; ++k) {
            uint8_t c = b[k];
            b[k] = b[w - 1 - k];
            b[w - 1 - k] = c;
        }
}

#define CONVERT(T, OUT)                                                                            \
    do {                                                                                           \
        for (size_t i = 0; i < n; ++i) {                                                           \
            T v;                                                                                   \
            memcpy(&v, b + i * sizeof(T), sizeof(T));                                              \
            OUT;                                                                                   \
        }                                                                                          \
    } while (0)

void cm_vtk_to_double(cm_vtk_scalar t, const void *src, size_t n, double *dst)
{
    const uint8_t *b = src;
    switch (t) {
    case CM_VTK_INT8: CONVERT(int8_t, dst[i] = v); break;
    case CM_VTK_UINT8: CONVERT(uint8_t, dst[i] = v); break;
    case CM_VTK_INT16: CONVERT(int16_t, dst[i] = v); break;
    case CM_VTK_UINT16: CONVERT(uint16_t, dst[i] = v); break;
    case CM_VTK_INT32: CONVERT(int32_t, dst[i] = v); break;
    case CM_VTK_UINT32: CONVERT(uint32_t, dst[i] = v); break;
    case CM_VTK_INT64: CONVERT(int64_t, dst[i] = (double)v); break;
    case CM_VTK_UINT64: CONVERT(uint64_t, dst[i] = (double)v); break;
    case CM_VTK_FLOAT32: CONVERT(float, dst[i] = v); break;
    case CM_VTK_FLOAT64: memcpy(dst, src, n * sizeof(double)); break;
    default: break;
    }
}

size_t cm_vtk_to_int64(cm_vtk_scalar t, const void *src, size_t n, int64_t *dst)
{
    const uint8_t *b = src;
    switch (t) {
    case CM_VTK_INT8: CONVERT(int8_t, dst[i] = v); break;
    case CM_VTK_UINT8: CONVERT(uint8_t, dst[i] = v); break;
    case CM_VTK_INT16: CONVERT(int16_t, dst[i] = v); break;
    case CM_VTK_UINT16: CONVERT(uint16_t, dst[i] = v); break;
    case CM_VTK_INT32: CONVERT(int32_t, dst[i] = v); break;
    case CM_VTK_UINT32: CONVERT(uint32_t, dst[i] = v); break;
    case CM_VTK_INT64: memcpy(dst, src, n * sizeof(int64_t)); break;
    case CM_VTK_UINT64:
        CONVERT(uint64_t, if (v > (uint64_t)INT64_MAX) return i; dst[i] = (int64_t)v);
        break;
    case CM_VTK_FLOAT32:
        CONVERT(float, if (!(v == floorf(v) && fabsf(v) < 9e15f)) return i; dst[i] = (int64_t)v);
        break;
    case CM_VTK_FLOAT64:
        CONVERT(double, if (!(v == floor(v) && fabs(v) < 9e15)) return i; dst[i] = (int64_t)v);
        break;
    default: return 0;
    }
    return n;
}

size_t cm_vtk_polyhedron_points(const int64_t *stream, int64_t *ids)
{
    size_t n = 0;
    for (cm_polyhedron_face f = cm_polyhedron_begin(stream, -1); cm_polyhedron_more(&f);
         cm_polyhedron_next(&f))
        for (int64_t k = 0; k < f.n; ++k) {
            int64_t id = f.nodes[k];
            size_t j = 0;
            while (j < n && ids[j] != id) ++j;
            if (j == n) ids[n++] = id;
        }
    return n;
}

/* VTK_PIXEL and VTK_VOXEL are axis-aligned quads/hexes in lexicographic order. */
static const int pixel_order[4] = {0, 1, 3, 2};
static const int voxel_order[8] = {0, 1, 3, 2, 4, 5, 7, 6};

static cm_status check_stream(cm_context *ctx, const char *where, size_t c, const int64_t *s,
                              int64_t len, size_t n_nodes)
{
    if (len < 1 || s[0] < 1)
        return cm_error(ctx, CM_ERR_FORMAT, "%s: polyhedron cell %zu: empty face stream", where, c);
    int64_t pos = 1;
    for (int64_t f = 0; f < s[0]; ++f) {
        if (pos >= len || s[pos] < 3 || s[pos] > len - pos - 1)
            return cm_error(ctx, CM_ERR_FORMAT,
                            "%s: polyhedron cell %zu: face %lld: face stream is inconsistent", where,
                            c, (long long)f);
        for (int64_t k = 1; k <= s[pos]; ++k)
            if (s[pos + k] < 0 || (uint64_t)s[pos + k] >= n_nodes)
                return cm_error(ctx, CM_ERR_FORMAT,
                                "%s: polyhedron cell %zu: node id %lld out of range [0, %zu)", where,
                                c, (long long)s[pos + k], n_nodes);
        pos += 1 + s[pos];
    }
    if (pos != len)
        return cm_error(ctx, CM_ERR_FORMAT, "%s: polyhedron cell %zu: face stream has %lld extra entries",
                        where, c, (long long)(len - pos));
    return CM_OK;
}

cm_status cm_vtk_cells_to_mesh(cm_context *ctx, const cm_vtk_cells *cells, const char *where,
                               cm_mesh *mesh)
{
    const size_t nn = mesh->n_nodes;
    size_t total = cells->n_conn;
    if (cells->faces) total += cells->n_faces;
    cm_status s = cm_mesh_reserve_cells(ctx, mesh, cells->n, total);
    if (s != CM_OK) return s;
    for (size_t c = 0; c < cells->n; ++c) {
        int64_t b = cells->off[c], e = cells->off[c + 1];
        if (b < 0 || e < b || (uint64_t)e > cells->n_conn)
            return cm_error(ctx, CM_ERR_FORMAT,
                            "%s: cell %zu: offsets %lld..%lld outside the %zu connectivity entries",
                            where, c, (long long)b, (long long)e, cells->n_conn);
        int64_t vt = cells->type[c];
        cm_cell_type t = vt == 8 ? CM_CELL_QUAD4 : vt == 11 ? CM_CELL_HEX8 :
                         (vt >= 0 && vt < 256) ? cm_cell_type_from_vtk((int)vt) : CM_CELL_TYPE_COUNT;
        if (t == CM_CELL_TYPE_COUNT)
            return cm_error(ctx, CM_ERR_FORMAT, "%s: cell %zu: unknown or unsupported VTK cell type %lld",
                            where, c, (long long)vt);
        const int64_t *nodes = cells->conn + b;
        int64_t len = e - b;
        if (t == CM_CELL_POLYHEDRON) {
            if (cells->faces) {
                int64_t fb = cells->face_off[c], fe = cells->face_off[c + 1];
                if (fb < 0 || fe < fb || (uint64_t)fe > cells->n_faces)
                    return cm_error(ctx, CM_ERR_FORMAT,
                                    "%s: polyhedron cell %zu: face offsets %lld..%lld outside the %zu "
                                    "face entries",
                                    where, c, (long long)fb, (long long)fe, cells->n_faces);
                nodes = cells->faces + fb;
                len = fe - fb;
            }
            s = check_stream(ctx, where, c, nodes, len, nn);
            if (s != CM_OK) return s;
        } else {
            const cm_cell_info *info = cm_cell_type_info(t);
            if ((info->nodes >= 0 && len != info->nodes) || (info->nodes < 0 && len < 3))
                return cm_error(ctx, CM_ERR_FORMAT, "%s: cell %zu (%s): expected %d node ids, got %lld",
                                where, c, info->name, info->nodes < 0 ? 3 : info->nodes, (long long)len);
            for (int64_t k = 0; k < len; ++k)
                if (nodes[k] < 0 || (uint64_t)nodes[k] >= nn)
                    return cm_error(ctx, CM_ERR_FORMAT,
                                    "%s: cell %zu (%s): node id %lld out of range [0, %zu)", where, c,
                                    info->name, (long long)nodes[k], nn);
        }
        int64_t tmp[8];
        if (vt == 8 || vt == 11) {
            const int *perm = vt == 8 ? pixel_order : voxel_order;
            for (int64_t k = 0; k < len; ++k) tmp[k] = nodes[perm[k]];
            nodes = tmp;
        }
        s = cm_mesh_add_cell(ctx, mesh, t, nodes, (size_t)len, 0, 0, 0);
        if (s != CM_OK) return s;
    }
    return CM_OK;
}

cm_status cm_vtk_check_points(cm_context *ctx, const cm_mesh *mesh, const char *where)
{
    for (size_t i = 0; i < 3 * mesh->n_nodes; ++i)
        if (!isfinite(mesh->xyz[i]))
            return cm_error(ctx, CM_ERR_FORMAT, "%s: point %zu: coordinate %c is not finite (%g)", where,
                            i / 3, "xyz"[i % 3], mesh->xyz[i]);
    return CM_OK;
}
