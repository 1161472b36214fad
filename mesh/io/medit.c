/* Medit (.mesh) ASCII reader and writer: Vertices, Edges, Triangles, Quadrilaterals,
 * Tetrahedra, Prisms, Pyramids, Hexahedra with their references (-> physical tags).
 * Node order: edges, triangles, quadrilaterals, tetrahedra, pyramids and hexahedra are in
 * VTK's order in the files gmsh (-format mesh) and meshio write (checked in
 * tests/mesh/test_vtk_io.c against the same meshes as .vtk/.vtu). Prisms are in gmsh's
 * order (meshio writes them so; gmsh 4.8 does not write prisms to .mesh at all): the
 * triangle (0,1,2) is wound the other way than VTK's wedge, so nodes 1<->2 and 4<->5 swap. */
#include "formats.h"
#include "text.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Medit prism <-> VTK wedge (the permutation is its own inverse). */
static const int prism_order[6] = {0, 2, 1, 3, 5, 4};

typedef struct medit_section {
    const char *name;
    cm_cell_type type;
    int nodes;
} medit_section;

/* Writer order; the reader accepts any order. */
static const medit_section sections[] = {
    {"Edges", CM_CELL_LINE2, 2},       {"Triangles", CM_CELL_TRI3, 3},
    {"Quadrilaterals", CM_CELL_QUAD4, 4}, {"Tetrahedra", CM_CELL_TET4, 4},
    {"Pyramids", CM_CELL_PYR5, 5},     {"Prisms", CM_CELL_WEDGE6, 6},
    {"Hexahedra", CM_CELL_HEX8, 8},
};
enum { N_SECTIONS = sizeof sections / sizeof *sections };

/* Sections that carry no cells: name and integers/reals per entry (skipped). */
static const struct { const char *name; int ints, reals; } skipped[] = {
    {"Corners", 1, 0},        {"RequiredVertices", 1, 0}, {"Ridges", 1, 0},
    {"RequiredEdges", 1, 0},  {"RequiredTriangles", 1, 0}, {"RequiredQuadrilaterals", 1, 0},
    {"Normals", 0, 3},        {"NormalAtVertices", 2, 0},  {"Tangents", 0, 3},
    {"TangentAtVertices", 2, 0}, {"TangentAtEdges", 3, 0},
};

static int word_is(const char *tok, size_t len, const char *w)
{
    return strlen(w) == len && !strncasecmp(tok, w, len);
}

/* Next token that is not in a comment ('#' to end of line). */
static int next_token(cm_text *t, const char **tok, size_t *len)
{
    for (;;) {
        if (!cm_text_token(t, tok, len)) return 0;
        if ((*tok)[0] != '#') return 1;
        t->pos = (size_t)(*tok - t->data);
        cm_text_next_line(t);
    }
}

static cm_status read_int(cm_context *ctx, cm_text *t, const char *what, int64_t *v)
{
    const char *tok;
    size_t len;
    size_t save = t->pos;
    if (next_token(t, &tok, &len)) t->pos = (size_t)(tok - t->data);
    else t->pos = save;
    return cm_text_int(ctx, t, what, v);
}

static cm_status read_double(cm_context *ctx, cm_text *t, const char *what, double *v)
{
    const char *tok;
    size_t len;
    if (next_token(t, &tok, &len)) t->pos = (size_t)(tok - t->data);
    return cm_text_double(ctx, t, what, v);
}

/* An entry count, bounded by the bytes left (each entry takes at least 2 per number). */
static cm_status read_count(cm_context *ctx, cm_text *t, const char *what, int per, size_t *n)
{
    int64_t v = 0;
    *n = 0;
    cm_status s = read_int(ctx, t, what, &v);
    if (s != CM_OK) return s;
    if (v < 0 || (uint64_t)v > (t->size - t->pos) / (2 * (size_t)per) + 1)
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s %lld does not fit in the rest of the file (truncated?)",
                        t->path, t->line, what, (long long)v);
    *n = (size_t)v;
    return CM_OK;
}

static cm_status read_body(cm_context *ctx, cm_text *t, cm_mesh *m)
{
    const char *tok;
    size_t len;
    int64_t version = 0, dim = 3;
    cm_status s = CM_OK;
    int have_vertices = 0, ended = 0;
    if (!next_token(t, &tok, &len) || !word_is(tok, len, "MeshVersionFormatted"))
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected 'MeshVersionFormatted'", t->path, t->line);
    s = read_int(ctx, t, "format version", &version);
    if (s != CM_OK) return s;
    if (version < 1 || version > 2)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s:%ld: MeshVersionFormatted %lld is not supported (1 or 2)",
                        t->path, t->line, (long long)version);
    while (s == CM_OK && next_token(t, &tok, &len)) {
        long line = t->line;
        if (word_is(tok, len, "End")) {
            ended = 1;
            break;
        }
        if (word_is(tok, len, "Dimension")) {
            s = read_int(ctx, t, "dimension", &dim);
            if (s == CM_OK && dim != 2 && dim != 3)
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: Dimension %lld (expected 2 or 3)", t->path, line, (long long)dim);
            continue;
        }
        if (word_is(tok, len, "Vertices")) {
            size_t n;
            if (have_vertices) return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: second Vertices section", t->path, line);
            have_vertices = 1;
            s = read_count(ctx, t, "vertex count", (int)dim + 1, &n);
            if (s == CM_OK) s = cm_mesh_resize_nodes(ctx, m, n, 0);
            for (size_t i = 0; s == CM_OK && i < n; ++i) {
                double *x = m->xyz + 3 * i;
                int64_t ref;
                x[2] = 0.0;
                for (int k = 0; s == CM_OK && k < dim; ++k) s = read_double(ctx, t, "vertex coordinate", &x[k]);
                if (s == CM_OK) s = read_int(ctx, t, "vertex reference", &ref);
                if (s == CM_OK && !(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2])))
                    s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: vertex %zu: coordinate is not finite", t->path, t->line, i + 1);
            }
            continue;
        }
        int sec = -1;
        for (int k = 0; k < N_SECTIONS; ++k)
            if (word_is(tok, len, sections[k].name)) sec = k;
        if (sec >= 0) {
            const medit_section *ms = &sections[sec];
            size_t n;
            if (!have_vertices)
                return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s before Vertices", t->path, line, ms->name);
            s = read_count(ctx, t, "element count", ms->nodes + 1, &n);
            if (s == CM_OK) s = cm_mesh_reserve_cells(ctx, m, n, n * (size_t)ms->nodes);
            for (size_t i = 0; s == CM_OK && i < n; ++i) {
                int64_t ids[8], ref;
                for (int k = 0; s == CM_OK && k < ms->nodes; ++k) {
                    s = read_int(ctx, t, "node index", &ids[k]);
                    if (s == CM_OK && (ids[k] < 1 || (uint64_t)ids[k] > m->n_nodes))
                        s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s %zu: node index %lld out of range [1, %zu]",
                                     t->path, t->line, ms->name, i + 1, (long long)ids[k], m->n_nodes);
                    ids[k] -= 1;
                }
                if (s == CM_OK && ms->type == CM_CELL_WEDGE6) {
                    int64_t v[6];
                    for (int k = 0; k < 6; ++k) v[k] = ids[prism_order[k]];
                    memcpy(ids, v, sizeof v);
                }
                if (s == CM_OK) s = read_int(ctx, t, "element reference", &ref);
                if (s == CM_OK && (ref < INT32_MIN || ref > INT32_MAX))
                    s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: reference %lld out of range", t->path, t->line, (long long)ref);
                if (s == CM_OK) s = cm_mesh_add_cell(ctx, m, ms->type, ids, (size_t)ms->nodes, (int)ref, 0, 0);
            }
            continue;
        }
        int sk = -1;
        for (size_t k = 0; k < sizeof skipped / sizeof *skipped; ++k)
            if (word_is(tok, len, skipped[k].name)) sk = (int)k;
        if (sk < 0)
            return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: unknown or unsupported keyword '%.*s'", t->path, line,
                            (int)(len > 40 ? 40 : len), tok);
        size_t n;
        int per = skipped[sk].ints + skipped[sk].reals;
        s = read_count(ctx, t, "entry count", per, &n);
        for (size_t i = 0; s == CM_OK && i < n * (size_t)per; ++i) {
            double v;
            s = read_double(ctx, t, skipped[sk].name, &v);
        }
    }
    if (s == CM_OK && !ended)
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected 'End' (truncated file?)", t->path, t->line);
    if (s == CM_OK && !have_vertices)
        return cm_error(ctx, CM_ERR_FORMAT, "%s: no Vertices section", t->path);
    return s;
}

static cm_status parse_medit(cm_context *ctx, const char *path, const char *data, size_t size,
                             cm_mesh *m)
{
    cm_text t;
    cm_text_init(&t, path, data, size);
    return read_body(ctx, &t, m);
}

cm_status cm_mesh_read_medit(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    return cm_mesh_read_whole(ctx, "cm_mesh_read_medit", path, parse_medit, mesh);
}

cm_status cm_mesh_write_medit(cm_context *ctx, const cm_mesh *mesh, const char *path,
                              const cm_mesh_write_options *opt)
{
    (void)opt;
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_medit: NULL argument");
    size_t count[N_SECTIONS] = {0}, skipped_points = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        int sec = -1;
        for (int k = 0; k < N_SECTIONS; ++k)
            if (sections[k].type == mesh->type[c]) sec = k;
        if (sec >= 0) ++count[sec];
        else if (mesh->type[c] == CM_CELL_POINT) ++skipped_points;
        else
            return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: Medit has no %s cells (cell %zu); write .vtu or .msh",
                            path, cm_cell_type_info((cm_cell_type)mesh->type[c])->name, c);
    }
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    FILE *f = out.f;
    fprintf(f, "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n%zu\n", mesh->n_nodes);
    for (size_t i = 0; i < mesh->n_nodes; ++i)
        fprintf(f, "%.17g %.17g %.17g 0\n", mesh->xyz[3 * i], mesh->xyz[3 * i + 1], mesh->xyz[3 * i + 2]);
    for (int k = 0; k < N_SECTIONS; ++k) {
        if (!count[k]) continue;
        fprintf(f, "\n%s\n%zu\n", sections[k].name, count[k]);
        for (size_t c = 0; c < mesh->n_cells; ++c) {
            if (mesh->type[c] != sections[k].type) continue;
            const int64_t *v = mesh->conn + mesh->offset[c];
            for (int j = 0; j < sections[k].nodes; ++j)
                fprintf(f, "%lld ", (long long)v[sections[k].type == CM_CELL_WEDGE6 ? prism_order[j] : j] + 1);
            fprintf(f, "%d\n", mesh->physical[c]);
        }
    }
    fputs("\nEnd\n", f);
    s = cm_outfile_commit(ctx, &out);
    if (s == CM_OK && skipped_points)
        return cm_error(ctx, CM_WARNING, "%s: %zu point cells are not written (Medit has no point elements)",
                        path, skipped_points);
    return s;
}
