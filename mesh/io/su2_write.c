/* SU2 native mesh (.su2) writers. A mesh read from .su2 that still has the nodes and cells it
 * was read with is written back into a copy of its file where only the coordinate numbers of
 * the point lines change (an unmoved number keeps its bytes; the index columns, the cells, the
 * markers, comments and whatever SU2_DEF appended stay byte for byte). Any other mesh is
 * written as a new file in the layout SU2 writes: NDIME=, NELEM= (with element indices),
 * NPOIN= (with point indices), NMARK= with one marker per physical group of the boundary
 * cells. */
#define _POSIX_C_SOURCE 200809L
#include "formats.h"
#include "rewrite.h"
#include "su2_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A point line's coordinate numbers (span->aux of them: NDIME) anew; the blanks between them
 * as they were. */
static cm_status emit_point(cm_context *ctx, const cm_rewrite_source *src, const cm_rewrite_file *file,
                            const cm_rewrite_span *span, const char *original, const double xyz[3],
                            cm_rewrite_buf *out)
{
    (void)src;
    const int dim = (int)span->aux;
    for (int k = 0; k < 3; ++k)
        if (!isfinite(xyz[k]))
            return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: node %lld has a coordinate that is not finite",
                            file->path, (long long)span->node);
    if (dim == 2 && xyz[2] != 0)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_mesh_write: %s: node %lld is at z = %.17g, but the file is 2-D (NDIME= 2: x and y "
                        "only); write the mesh to another format",
                        file->path, (long long)span->node, xyz[2]);
    const char *p = original;
    for (int k = 0; k < dim; ++k) {
        const char *b = p;
        while (*b == ' ' || *b == '\t') ++b;
        cm_rewrite_put(out, p, (size_t)(b - p));
        const char *e = b;
        while (*e && *e != ' ' && *e != '\t') ++e;
        char num[40];
        const int n = cm_rewrite_number(num, sizeof num, xyz[k], b, (size_t)(e - b));
        cm_rewrite_put(out, num, (size_t)n);
        p = e;
    }
    cm_rewrite_put(out, p, strlen(p));
    return CM_OK;
}

/* SU2's id of a cell type, 0 for a type SU2 does not have. */
static int su2_id(cm_cell_type type)
{
    const cm_cell_info *inf = cm_cell_type_info(type);
    cm_cell_type t;
    return inf && cm_su2_cell(inf->vtk, &t) && t == type ? inf->vtk : 0;
}

static int cell_dim(const cm_mesh *m, size_t c)
{
    const cm_cell_info *inf = cm_cell_type_info((cm_cell_type)m->type[c]);
    return inf ? inf->dim : -1;
}

/* A marker's name: its group's, with blanks (which SU2 drops from MARKER_TAG) as '_', or
 * "marker_<tag>" for a tag without a name. */
static void marker_name(const cm_mesh *m, int dim, int tag, char *out, size_t cap)
{
    const char *name = NULL;
    for (size_t g = 0; g < m->n_groups && !name; ++g)
        if (m->groups[g].dim == dim && m->groups[g].tag == tag && m->groups[g].name && m->groups[g].name[0])
            name = m->groups[g].name;
    if (!name) {
        snprintf(out, cap, "marker_%d", tag);
        return;
    }
    size_t n = 0;
    for (; name[n] && n + 1 < cap; ++n)
        out[n] = (unsigned char)name[n] <= ' ' || name[n] == '%' || name[n] == '=' ? '_' : name[n];
    out[n] = '\0';
}

static void put_point(FILE *f, const double *x, int dim, size_t index)
{
    char num[40];
    for (int k = 0; k < dim; ++k) {
        cm_rewrite_number(num, sizeof num, x[k], NULL, 0);
        fputs(num, f);
        fputc(' ', f);
    }
    fprintf(f, "%zu\n", index);
}

static void put_cell(FILE *f, const cm_mesh *m, size_t c, long long index)
{
    fprintf(f, "%d", su2_id((cm_cell_type)m->type[c]));
    for (int64_t k = m->offset[c]; k < m->offset[c + 1]; ++k) fprintf(f, " %lld", (long long)m->conn[k]);
    if (index >= 0) fprintf(f, " %lld", index);
    fputc('\n', f);
}

static cm_status write_new(cm_context *ctx, const cm_mesh *m, const char *path)
{
    int dim = 0;
    for (size_t c = 0; c < m->n_cells; ++c)
        if (cell_dim(m, c) > dim) dim = cell_dim(m, c);
    if (dim < 2)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_write_su2: %s: SU2 needs cells of dimension 3 (or 2); the mesh has none",
                        path);
    if (dim == 2)
        for (size_t i = 0; i < m->n_nodes; ++i)
            if (m->xyz[3 * i + 2] != 0)
                return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                "cm_mesh_write_su2: %s: a mesh of 2-D cells is an SU2 file of NDIME= 2, in the plane "
                                "z = 0, but node %zu has z = %.17g",
                                path, i, m->xyz[3 * i + 2]);
    /* the cells: those of dimension dim, the markers' of dim - 1 by physical tag, the rest skipped */
    size_t n_elem = 0, n_face = 0, skipped = 0, n_tags = 0;
    int *tags = malloc((m->n_cells ? m->n_cells : 1) * sizeof *tags);
    if (!tags) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write_su2: out of memory");
    for (size_t c = 0; c < m->n_cells; ++c) {
        const int d = cell_dim(m, c);
        if (d < dim - 1) {
            ++skipped;
            continue;
        }
        if (!su2_id((cm_cell_type)m->type[c])) {
            free(tags);
            return cm_error(ctx, CM_ERR_UNSUPPORTED,
                            "cm_mesh_write_su2: %s: SU2 has no %s cells (cell %zu; it has linear cells only); "
                            "write .vtu or .msh",
                            path, cm_cell_type_info((cm_cell_type)m->type[c])->name, c);
        }
        if (d == dim) {
            ++n_elem;
            continue;
        }
        ++n_face;
        size_t t = 0;
        while (t < n_tags && tags[t] != m->physical[c]) ++t;
        if (t == n_tags) tags[n_tags++] = m->physical[c];
    }
    /* no boundary cells: SU2 needs every boundary face in a marker, so the mesh's boundary is one */
    cm_mesh_boundary *bnd = NULL;
    cm_status s = CM_OK;
    if (n_face == 0 && dim == 3) {
        s = cm_mesh_boundary_create(ctx, m, &bnd);
        if (s < 0) {
            free(tags);
            return s;
        }
        s = CM_OK;
    }
    cm_outfile out;
    s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) {
        free(tags);
        cm_mesh_boundary_destroy(&bnd);
        return s;
    }
    FILE *f = out.f;
    fprintf(f, "NDIME= %d\nNELEM= %zu\n", dim, n_elem);
    size_t index = 0;
    for (size_t c = 0; c < m->n_cells; ++c)
        if (cell_dim(m, c) == dim) put_cell(f, m, c, (long long)index++);
    fprintf(f, "NPOIN= %zu\n", m->n_nodes);
    for (size_t i = 0; i < m->n_nodes; ++i) put_point(f, m->xyz + 3 * i, dim, i);
    fprintf(f, "NMARK= %zu\n", bnd ? (size_t)1 : n_tags);
    for (size_t t = 0; t < n_tags; ++t) {
        char name[256];
        marker_name(m, dim - 1, tags[t], name, sizeof name);
        size_t count = 0;
        for (size_t c = 0; c < m->n_cells; ++c) count += cell_dim(m, c) == dim - 1 && m->physical[c] == tags[t];
        fprintf(f, "MARKER_TAG= %s\nMARKER_ELEMS= %zu\n", name, count);
        for (size_t c = 0; c < m->n_cells; ++c)
            if (cell_dim(m, c) == dim - 1 && m->physical[c] == tags[t]) put_cell(f, m, c, -1);
    }
    if (bnd) {
        fprintf(f, "MARKER_TAG= boundary\nMARKER_ELEMS= %zu\n", bnd->n_faces);
        for (size_t i = 0; i < bnd->n_faces; ++i) {
            const int64_t n = bnd->face_offset[i + 1] - bnd->face_offset[i];
            fprintf(f, "%d", n == 3 ? 5 : 9);
            for (int64_t k = bnd->face_offset[i]; k < bnd->face_offset[i + 1]; ++k)
                fprintf(f, " %lld", (long long)bnd->face_nodes[k]);
            fputc('\n', f);
        }
    }
    free(tags);
    const size_t bnd_faces = bnd ? bnd->n_faces : 0;
    cm_mesh_boundary_destroy(&bnd);
    s = cm_outfile_commit(ctx, &out);
    if (s != CM_OK) return s;
    char said[160] = "";
    if (bnd_faces)
        snprintf(said, sizeof said, "the mesh has no boundary cells: its %zu boundary faces are the marker 'boundary'%s",
                 bnd_faces, skipped ? "; " : "");
    if (skipped)
        snprintf(said + strlen(said), sizeof said - strlen(said), "%zu cells of lower dimension are not written", skipped);
    if (said[0]) return cm_error(ctx, CM_WARNING, "cm_mesh_write_su2: %s: %s", path, said);
    return CM_OK;
}

cm_status cm_mesh_write_su2(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt)
{
    (void)opt;
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_su2: NULL argument");
    const cm_rewrite_source *src = cm_mesh_origin_state(mesh, CM_FORMAT_SU2);
    if (src) return cm_rewrite_write(ctx, src, mesh, path, emit_point);
    return write_new(ctx, mesh, path);
}
