/* Writer of legacy VTK (.vtk) files in the VTK 5.1 layout (OFFSETS/CONNECTIVITY, vtktypeint64),
 * which VTK 9 and meshio both read; BINARY data is big-endian as the format requires. */
#include "vtk_internal.h"
#include "formats.h"

#include <stdlib.h>
#include <string.h>

typedef struct legacy_writer {
    cm_context *ctx;
    const char *path;
    FILE *f;
    int binary;
} legacy_writer;

/* Writes n values; src holds them as `from` (double, int64_t or int), written as `as`. */
static cm_status put_values(legacy_writer *w, cm_vtk_scalar as, const void *src, size_t n, int per_line)
{
    FILE *f = w->f;
    if (!w->binary) {
        for (size_t i = 0; i < n; ++i) {
            if (as == CM_VTK_FLOAT64) fprintf(f, "%.17g", ((const double *)src)[i]);
            else if (as == CM_VTK_INT64) fprintf(f, "%lld", (long long)((const int64_t *)src)[i]);
            else fprintf(f, "%d", ((const int *)src)[i]);
            fputc((i + 1) % (size_t)per_line == 0 || i + 1 == n ? '\n' : ' ', f);
        }
        return CM_OK;
    }
    size_t wd = cm_vtk_scalar_size(as);
    enum { CHUNK = 8192 };
    uint8_t buf[CHUNK * 8];
    for (size_t b = 0; b < n; b += CHUNK) {
        size_t m = n - b < CHUNK ? n - b : CHUNK;
        memcpy(buf, (const uint8_t *)src + b * wd, m * wd);
        if (cm_host_little_endian()) cm_vtk_swap(as, buf, m);
        fwrite(buf, wd, m, f);
    }
    fputc('\n', f);
    return CM_OK;
}

/* Legacy names cannot hold whitespace: VTK's own escape is %xx. An empty name would leave
 * the line without one: it is written as %00, which reads back as "". */
static void put_name(FILE *f, const char *s)
{
    if (!*s) fputs("%00", f);
    for (; *s; ++s) {
        unsigned char c = (unsigned char)*s;
        if (c <= ' ' || c == '%' || c >= 127) fprintf(f, "%%%02X", c);
        else fputc(c, f);
    }
}

static int any_nonzero(const int *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (v[i]) return 1;
    return 0;
}

static cm_status put_fields(legacy_writer *w, const cm_mesh *m, cm_field_location loc)
{
    size_t n = loc == CM_FIELD_NODE ? m->n_nodes : m->n_cells;
    int has_phys = loc == CM_FIELD_CELL && any_nonzero(m->physical, m->n_cells);
    int has_ent = loc == CM_FIELD_CELL && any_nonzero(m->entity, m->n_cells);
    size_t k = (size_t)has_phys + (size_t)has_ent;
    for (size_t i = 0; i < m->n_fields; ++i) k += m->fields[i].location == loc;
    if (k == 0) return CM_OK;
    fprintf(w->f, "%s %zu\nFIELD FieldData %zu\n", loc == CM_FIELD_NODE ? "POINT_DATA" : "CELL_DATA", n, k);
    cm_status s = CM_OK;
    for (size_t i = 0; s == CM_OK && i < m->n_fields; ++i) {
        const cm_field *fd = &m->fields[i];
        if (fd->location != loc) continue;
        put_name(w->f, fd->name);
        fprintf(w->f, " %d %zu double\n", fd->components, n);
        s = put_values(w, CM_VTK_FLOAT64, fd->data, n * (size_t)fd->components, fd->components);
    }
    /* meshio's names, so that msh -> vtk -> msh keeps the tags. vtktypeint64 because meshio
     * 5 reads a 5.1 file's "int" as 64 bits; VTK and meshio agree on vtktypeint64. */
    for (int which = 0; s == CM_OK && which < 2; ++which) {
        if (!(which ? has_ent : has_phys)) continue;
        const int *v = which ? m->entity : m->physical;
        int64_t *w64 = malloc((n ? n : 1) * sizeof *w64);
        if (!w64) return cm_error(w->ctx, CM_ERR_NOMEM, "%s: out of memory", w->path);
        for (size_t i = 0; i < n; ++i) w64[i] = v[i];
        fprintf(w->f, "%s 1 %zu vtktypeint64\n", which ? "gmsh:geometrical" : "gmsh:physical", n);
        s = put_values(w, CM_VTK_INT64, w64, n, 9);
        free(w64);
    }
    return s;
}

static cm_status put_body(legacy_writer *w, const cm_mesh *m)
{
    FILE *f = w->f;
    fprintf(f, "# vtk DataFile Version 5.1\nwritten by cadmorph\n%s\nDATASET UNSTRUCTURED_GRID\n",
            w->binary ? "BINARY" : "ASCII");
    fprintf(f, "POINTS %zu double\n", m->n_nodes);
    cm_status s = put_values(w, CM_VTK_FLOAT64, m->xyz, 3 * m->n_nodes, 3);
    if (s != CM_OK) return s;
    /* Polyhedra keep their face stream in the connectivity, as VTK's legacy writer does. */
    fprintf(f, "CELLS %zu %lld\nOFFSETS vtktypeint64\n", m->n_cells + 1, (long long)m->offset[m->n_cells]);
    s = put_values(w, CM_VTK_INT64, m->offset, m->n_cells + 1, 9);
    fprintf(f, "CONNECTIVITY vtktypeint64\n");
    if (s == CM_OK) s = put_values(w, CM_VTK_INT64, m->conn, (size_t)m->offset[m->n_cells], 9);
    if (s != CM_OK) return s;
    int *types = malloc((m->n_cells ? m->n_cells : 1) * sizeof *types);
    if (!types) return cm_error(w->ctx, CM_ERR_NOMEM, "%s: out of memory", w->path);
    for (size_t c = 0; c < m->n_cells; ++c) types[c] = cm_cell_type_info((cm_cell_type)m->type[c])->vtk;
    fprintf(f, "CELL_TYPES %zu\n", m->n_cells);
    s = put_values(w, CM_VTK_INT32, types, m->n_cells, 1);
    free(types);
    if (s == CM_OK) s = put_fields(w, m, CM_FIELD_CELL);
    if (s == CM_OK) s = put_fields(w, m, CM_FIELD_NODE);
    return s;
}

cm_status cm_mesh_write_vtk(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_vtk: NULL argument");
    cm_mesh_write_options defaults;
    cm_mesh_write_options_init(&defaults);
    if (!opt) opt = &defaults;
    legacy_writer w = {ctx, path, NULL, opt->binary != 0};
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    w.f = out.f;
    s = put_body(&w, mesh);
    if (s != CM_OK) {
        cm_outfile_abort(&out);
        return s;
    }
    return cm_outfile_commit(ctx, &out);
}
