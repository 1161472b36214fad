/* Writer of VTK XML UnstructuredGrid (.vtu): ascii, inline base64 or appended raw data,
 * optionally zlib-compressed in VTK's block format; header_type UInt64, Int64 ids. */
#include "vtk_internal.h"
#include "formats.h"

#include <stdlib.h>
#include <string.h>
#include <zlib.h>

enum { MODE_ASCII, MODE_INLINE, MODE_APPENDED };
enum { BLOCK = 32768 };

typedef struct payload {
    uint8_t *data;
    size_t size;
} payload;

typedef struct vtu_writer {
    cm_context *ctx;
    const char *path;
    FILE *f;
    int mode, compress;
    payload *app; /* appended blobs in order */
    size_t n_app, app_offset;
} vtu_writer;

static cm_status nomem(vtu_writer *w) { return cm_error(w->ctx, CM_ERR_NOMEM, "%s: out of memory", w->path); }

/* Header + data as VTK expects them (UInt64 header). */
static cm_status encode(vtu_writer *w, const void *src, size_t nbytes, payload *p)
{
    p->data = NULL;
    p->size = 0;
    if (!w->compress) {
        p->data = malloc(8 + nbytes);
        if (!p->data) return nomem(w);
        uint64_t n = nbytes;
        memcpy(p->data, &n, 8);
        if (nbytes) memcpy(p->data + 8, src, nbytes);
        p->size = 8 + nbytes;
        return CM_OK;
    }
    const size_t nb = (nbytes + BLOCK - 1) / BLOCK;
    const size_t bound = compressBound(BLOCK);
    uint8_t *tmp = malloc(nb ? nb * bound : 1);
    uint64_t *cs = malloc((nb + 3) * sizeof *cs);
    if (!tmp || !cs) {
        free(tmp);
        free(cs);
        return nomem(w);
    }
    int bad = 0;
    const long n_blocks = (long)nb;
    const int threads = cm_context_threads_for(w->ctx, nb, 1);
#pragma omp parallel for schedule(static) num_threads(threads) if (n_blocks > 8) reduction(| : bad)
    for (long i = 0; i < n_blocks; ++i) {
        size_t b = (size_t)i * BLOCK;
        size_t len = nbytes - b < BLOCK ? nbytes - b : BLOCK;
        uLongf out = (uLongf)bound;
        if (compress2(tmp + (size_t)i * bound, &out, (const Bytef *)src + b, (uLong)len, 5) != Z_OK) bad = 1;
        cs[3 + i] = out;
    }
    if (bad) {
        free(tmp);
        free(cs);
        return cm_error(w->ctx, CM_ERR_INTERNAL, "%s: zlib compression failed", w->path);
    }
    cs[0] = nb;
    cs[1] = BLOCK;
    cs[2] = nb ? nbytes - (nb - 1) * BLOCK : 0;
    size_t total = (nb + 3) * 8;
    for (size_t i = 0; i < nb; ++i) total += cs[3 + i];
    p->data = malloc(total);
    if (!p->data) {
        free(tmp);
        free(cs);
        return nomem(w);
    }
    memcpy(p->data, cs, (nb + 3) * 8);
    size_t o = (nb + 3) * 8;
    for (size_t i = 0; i < nb; ++i) {
        memcpy(p->data + o, tmp + i * bound, cs[3 + i]);
        o += cs[3 + i];
    }
    p->size = total;
    free(tmp);
    free(cs);
    return CM_OK;
}

/* The header is encoded apart from the data, as VTK and meshio do (meshio relies on it). */
static cm_status put_base64(vtu_writer *w, const uint8_t *data, size_t n)
{
    size_t enc = cm_b64_encoded_size(n);
    char *buf = malloc(enc ? enc : 1);
    if (!buf) return nomem(w);
    cm_b64_encode(data, n, buf);
    fwrite(buf, 1, enc, w->f);
    free(buf);
    return CM_OK;
}

static void put_escaped(FILE *f, const char *s)
{
    for (; *s; ++s) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

static void put_ascii(FILE *f, cm_vtk_scalar t, const void *src, size_t n)
{
    const uint8_t *b = src;
    for (size_t i = 0; i < n; ++i) {
        fputs(i % 6 == 0 ? "\n          " : " ", f);
        switch (t) {
        case CM_VTK_FLOAT64: { double v; memcpy(&v, b + 8 * i, 8); fprintf(f, "%.17g", v); break; }
        case CM_VTK_INT64: { int64_t v; memcpy(&v, b + 8 * i, 8); fprintf(f, "%lld", (long long)v); break; }
        case CM_VTK_INT32: { int32_t v; memcpy(&v, b + 4 * i, 4); fprintf(f, "%d", (int)v); break; }
        case CM_VTK_UINT8: fprintf(f, "%u", (unsigned)b[i]); break;
        default: break;
        }
    }
    fputs("\n        ", f);
}

static cm_status write_array(vtu_writer *w, const char *name, cm_vtk_scalar t, int comps,
                             const void *src, size_t n)
{
    static const char *tn[CM_VTK_SCALAR_COUNT] = {"Int8", "UInt8", "Int16", "UInt16", "Int32",
                                                  "UInt32", "Int64", "UInt64", "Float32", "Float64"};
    FILE *f = w->f;
    fprintf(f, "        <DataArray type=\"%s\" Name=\"", tn[t]);
    put_escaped(f, name);
    fprintf(f, "\" NumberOfComponents=\"%d\" format=\"%s\"", comps,
            w->mode == MODE_ASCII ? "ascii" : w->mode == MODE_INLINE ? "binary" : "appended");
    const size_t nbytes = n * cm_vtk_scalar_size(t);
    if (w->mode == MODE_ASCII) {
        fputs(">", f);
        put_ascii(f, t, src, n);
        fputs("</DataArray>\n", f);
        return CM_OK;
    }
    payload p;
    cm_status s = encode(w, src, nbytes, &p);
    if (s != CM_OK) return s;
    if (w->mode == MODE_INLINE) {
        size_t hdr = w->compress ? (3 + (size_t)((const uint64_t *)(void *)p.data)[0]) * 8 : 8;
        fputs(">\n          ", f);
        s = put_base64(w, p.data, hdr);
        if (s == CM_OK) s = put_base64(w, p.data + hdr, p.size - hdr);
        fputs("\n        </DataArray>\n", f);
        free(p.data);
        return s;
    }
    fprintf(f, " offset=\"%zu\"/>\n", w->app_offset);
    payload *a = realloc(w->app, (w->n_app + 1) * sizeof *a);
    if (!a) {
        free(p.data);
        return nomem(w);
    }
    w->app = a;
    w->app[w->n_app++] = p;
    w->app_offset += p.size;
    return CM_OK;
}

/* Cells in VTK XML layout: connectivity lists a polyhedron's distinct points, its faces go to
 * faces/faceoffsets. */
typedef struct cell_arrays {
    int64_t *conn, *off, *faces, *foff;
    uint8_t *types;
    size_t n_conn, n_faces;
    int has_poly;
} cell_arrays;

static void free_cells(cell_arrays *c)
{
    free(c->conn);
    free(c->off);
    free(c->faces);
    free(c->foff);
    free(c->types);
}

static cm_status build_cells(vtu_writer *w, const cm_mesh *m, cell_arrays *c)
{
    memset(c, 0, sizeof *c);
    const size_t nc = m->n_cells, total = (size_t)m->offset[nc];
    for (size_t i = 0; i < nc; ++i) c->has_poly |= m->type[i] == CM_CELL_POLYHEDRON;
    c->types = malloc(nc ? nc : 1);
    c->off = malloc((nc ? nc : 1) * sizeof(int64_t));
    c->conn = malloc((total ? total : 1) * sizeof(int64_t));
    if (c->has_poly) {
        c->faces = malloc((total ? total : 1) * sizeof(int64_t));
        c->foff = malloc((nc ? nc : 1) * sizeof(int64_t));
    }
    if (!c->types || !c->off || !c->conn || (c->has_poly && (!c->faces || !c->foff))) {
        free_cells(c);
        return nomem(w);
    }
    size_t k = 0, fk = 0;
    for (size_t i = 0; i < nc; ++i) {
        const int64_t *s = m->conn + m->offset[i];
        size_t len = (size_t)(m->offset[i + 1] - m->offset[i]);
        c->types[i] = (uint8_t)cm_cell_type_info((cm_cell_type)m->type[i])->vtk;
        if (m->type[i] == CM_CELL_POLYHEDRON) {
            k += cm_vtk_polyhedron_points(s, c->conn + k);
            memcpy(c->faces + fk, s, len * sizeof *s);
            fk += len;
            c->foff[i] = (int64_t)fk;
        } else {
            memcpy(c->conn + k, s, len * sizeof *s);
            k += len;
            if (c->foff) c->foff[i] = -1;
        }
        c->off[i] = (int64_t)k;
    }
    c->n_conn = k;
    c->n_faces = fk;
    return CM_OK;
}

static int any_nonzero(const int *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (v[i]) return 1;
    return 0;
}

static cm_status write_body(vtu_writer *w, const cm_mesh *m)
{
    FILE *f = w->f;
    cm_status s = CM_OK;
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" "
               "byte_order=\"LittleEndian\" header_type=\"UInt64\"%s>\n  <UnstructuredGrid>\n"
               "    <Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n",
            w->compress ? " compressor=\"vtkZLibDataCompressor\"" : "", m->n_nodes, m->n_cells);
    fputs("      <PointData>\n", f);
    for (size_t i = 0; s == CM_OK && i < m->n_fields; ++i)
        if (m->fields[i].location == CM_FIELD_NODE)
            s = write_array(w, m->fields[i].name, CM_VTK_FLOAT64, m->fields[i].components,
                            m->fields[i].data, m->n_nodes * (size_t)m->fields[i].components);
    fputs("      </PointData>\n      <CellData>\n", f);
    for (size_t i = 0; s == CM_OK && i < m->n_fields; ++i)
        if (m->fields[i].location == CM_FIELD_CELL)
            s = write_array(w, m->fields[i].name, CM_VTK_FLOAT64, m->fields[i].components,
                            m->fields[i].data, m->n_cells * (size_t)m->fields[i].components);
    /* meshio's names, so that msh -> vtu -> msh keeps the tags (int is 32 bits here). */
    if (s == CM_OK && any_nonzero(m->physical, m->n_cells))
        s = write_array(w, "gmsh:physical", CM_VTK_INT32, 1, m->physical, m->n_cells);
    if (s == CM_OK && any_nonzero(m->entity, m->n_cells))
        s = write_array(w, "gmsh:geometrical", CM_VTK_INT32, 1, m->entity, m->n_cells);
    if (s != CM_OK) return s;
    fputs("      </CellData>\n      <Points>\n", f);
    s = write_array(w, "Points", CM_VTK_FLOAT64, 3, m->xyz, 3 * m->n_nodes);
    if (s != CM_OK) return s;
    fputs("      </Points>\n      <Cells>\n", f);
    cell_arrays c;
    s = build_cells(w, m, &c);
    if (s != CM_OK) return s;
    s = write_array(w, "connectivity", CM_VTK_INT64, 1, c.conn, c.n_conn);
    if (s == CM_OK) s = write_array(w, "offsets", CM_VTK_INT64, 1, c.off, m->n_cells);
    if (s == CM_OK) s = write_array(w, "types", CM_VTK_UINT8, 1, c.types, m->n_cells);
    if (s == CM_OK && c.has_poly) s = write_array(w, "faces", CM_VTK_INT64, 1, c.faces, c.n_faces);
    if (s == CM_OK && c.has_poly) s = write_array(w, "faceoffsets", CM_VTK_INT64, 1, c.foff, m->n_cells);
    free_cells(&c);
    if (s != CM_OK) return s;
    fputs("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n", f);
    if (w->mode == MODE_APPENDED) {
        fputs("  <AppendedData encoding=\"raw\">\n   _", f);
        for (size_t i = 0; i < w->n_app; ++i) fwrite(w->app[i].data, 1, w->app[i].size, f);
        fputs("\n  </AppendedData>\n", f);
    }
    fputs("</VTKFile>\n", f);
    return CM_OK;
}

cm_status cm_mesh_write_vtu(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt)
{
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_vtu: NULL argument");
    cm_mesh_write_options defaults;
    cm_mesh_write_options_init(&defaults);
    if (!opt) opt = &defaults;
    if (!cm_host_little_endian())
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_write_vtu: big-endian hosts are not supported");
    vtu_writer w;
    memset(&w, 0, sizeof w);
    w.ctx = ctx;
    w.path = path;
    w.mode = !opt->binary ? MODE_ASCII : opt->appended ? MODE_APPENDED : MODE_INLINE;
    w.compress = opt->binary && opt->compress;
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    w.f = out.f;
    s = write_body(&w, mesh);
    for (size_t i = 0; i < w.n_app; ++i) free(w.app[i].data);
    free(w.app);
    if (s != CM_OK) {
        cm_outfile_abort(&out);
        return s;
    }
    return cm_outfile_commit(ctx, &out);
}
