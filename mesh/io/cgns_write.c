/* CGNS writer (docs/DESIGN.md, "Writing back into the file a mesh came from"). A mesh read
 * from a CGNS file is written back by copying that file and overwriting the data of each
 * zone's GridCoordinates/CoordinateX|Y|Z in the copy through the library's cgio layer, in the
 * stored data type: the mid-level API's modify mode is not used, because opening a file in
 * that mode may rewrite its CGNSLibraryVersion node. Any other mesh becomes a new file: one
 * base, one unstructured zone, one section per (group, type), and a BC_t with an element
 * range (FaceCenter) per group of 2-D cells. */
#define _POSIX_C_SOURCE 200809L
#include "cgns_internal.h"
#include "formats.h"
#include "rewrite.h"

#include <cgns_io.h>
#include <cgnslib.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cm_status cgio_fail(cm_context *ctx, const char *target, const char *node, const char *what)
{
    char msg[81] = "";
    cgio_error_message(msg);
    return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: %s: %s: %s", target, node, what, msg);
}

/* Overwrites the coordinates of every zone in the open copy. */
static cm_status rewrite_zones(cm_context *ctx, const cm_mesh *mesh, const cm_cgns_state *st,
                               int cg, const char *target)
{
    double root;
    if (cgio_get_root_id(cg, &root)) return cgio_fail(ctx, target, "/", "no root node");
    static const char *names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (size_t z = 0; z < st->n_zones; ++z) {
        const cm_cgns_zone *zn = &st->zones[z];
        const size_t n = (size_t)zn->n_vertices;
        if (zn->n_coords == 2)
            for (size_t i = 0; i < n; ++i)
                if (mesh->xyz[3 * zn->node[i] + 2] != 0)
                    return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                    "cm_mesh_write: %s: %s has no CoordinateZ: a moved node left the plane z = 0",
                                    target, zn->path);
        void *buf = malloc((n ? n : 1) * sizeof(double));
        if (!buf) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: %s: out of memory", target);
        cm_status s = CM_OK;
        for (int k = 0; s == CM_OK && k < zn->n_coords; ++k) {
            char node[160], type[CGIO_MAX_DATATYPE_LENGTH + 1] = "";
            snprintf(node, sizeof node, "%s/GridCoordinates/%s", zn->path, names[k]);
            double id;
            int nd = 0;
            cgsize_t dims[CGIO_MAX_DIMENSIONS];
            if (cgio_get_node_id(cg, root, node, &id) || cgio_get_data_type(cg, id, type) ||
                cgio_get_dimensions(cg, id, &nd, dims)) {
                s = cgio_fail(ctx, target, node, "cannot read the node");
                break;
            }
            if (nd != 1 || (size_t)dims[0] != n || strcmp(type, zn->single[k] ? "R4" : "R8") != 0) {
                s = cm_error(ctx, CM_ERR_MISMATCH, "cm_mesh_write: %s: %s: the file changed since it was read",
                             target, node);
                break;
            }
            if (zn->single[k])
                for (size_t i = 0; i < n; ++i) ((float *)buf)[i] = (float)mesh->xyz[3 * zn->node[i] + k];
            else
                for (size_t i = 0; i < n; ++i) ((double *)buf)[i] = mesh->xyz[3 * zn->node[i] + k];
            if (n && cgio_write_all_data(cg, id, buf)) s = cgio_fail(ctx, target, node, "write failed");
        }
        free(buf);
        if (s != CM_OK) return s;
    }
    return CM_OK;
}

static cm_status write_back(cm_context *ctx, const cm_mesh *mesh, const cm_cgns_state *st, const char *path)
{
    cm_outfile out;
    cm_status s = cm_rewrite_copy_open(ctx, st->path, &st->stamp, path, &out);
    if (s != CM_OK) return s;
    {
        int type = 0, cg = -1;
        cm_cgns_lock();
        if (cgio_check_file(out.tmp, &type) || cgio_open_file(out.tmp, CGIO_MODE_MODIFY, type, &cg)) {
            s = cgio_fail(ctx, path, "/", "cannot open the copy");
        } else {
            s = rewrite_zones(ctx, mesh, st, cg, path);
            if (cgio_close_file(cg) && s == CM_OK) s = cgio_fail(ctx, path, "/", "close failed");
        }
        cm_cgns_unlock();
    }
    if (s != CM_OK) {
        cm_outfile_abort(&out);
        return s;
    }
    return cm_outfile_commit(ctx, &out);
}

/* ---- a new file ---- */

/* cadmorph (VTK order) -> CGNS: vtk[j] = cgns[perm[j]] as in the reader, inverted here. */
static CGNS_ENUMT(ElementType_t) cgns_type_of(cm_cell_type t, const int **perm)
{
    static const int hex20[20] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 16, 17, 18, 19, 12, 13, 14, 15};
    static const int hex27[27] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 16, 17, 18, 19, 12, 13, 14, 15,
                                  24, 22, 21, 23, 20, 25, 26};
    static const int wedge15[15] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 13, 14, 9, 10, 11};
    static const int wedge18[18] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 13, 14, 9, 10, 11, 15, 16, 17};
    *perm = NULL;
    switch (t) {
    case CM_CELL_POINT: return CGNS_ENUMV(NODE);
    case CM_CELL_LINE2: return CGNS_ENUMV(BAR_2);
    case CM_CELL_LINE3: return CGNS_ENUMV(BAR_3);
    case CM_CELL_TRI3: return CGNS_ENUMV(TRI_3);
    case CM_CELL_TRI6: return CGNS_ENUMV(TRI_6);
    case CM_CELL_QUAD4: return CGNS_ENUMV(QUAD_4);
    case CM_CELL_QUAD8: return CGNS_ENUMV(QUAD_8);
    case CM_CELL_QUAD9: return CGNS_ENUMV(QUAD_9);
    case CM_CELL_TET4: return CGNS_ENUMV(TETRA_4);
    case CM_CELL_TET10: return CGNS_ENUMV(TETRA_10);
    case CM_CELL_HEX8: return CGNS_ENUMV(HEXA_8);
    case CM_CELL_HEX20: *perm = hex20; return CGNS_ENUMV(HEXA_20);
    case CM_CELL_HEX27: *perm = hex27; return CGNS_ENUMV(HEXA_27);
    case CM_CELL_WEDGE6: return CGNS_ENUMV(PENTA_6);
    case CM_CELL_WEDGE15: *perm = wedge15; return CGNS_ENUMV(PENTA_15);
    case CM_CELL_WEDGE18: *perm = wedge18; return CGNS_ENUMV(PENTA_18);
    case CM_CELL_PYR5: return CGNS_ENUMV(PYRA_5);
    case CM_CELL_PYR13: return CGNS_ENUMV(PYRA_13);
    case CM_CELL_PYR14: return CGNS_ENUMV(PYRA_14);
    default: return CGNS_ENUMV(ElementTypeNull);
    }
}

static const char *group_name(const cm_mesh *m, int dim, int tag, char *buf, size_t n)
{
    for (size_t g = 0; g < m->n_groups; ++g)
        if (m->groups[g].dim == dim && m->groups[g].tag == tag && m->groups[g].name && m->groups[g].name[0]) {
            snprintf(buf, n, "%.32s", m->groups[g].name);
            return buf;
        }
    if (tag) snprintf(buf, n, "group%d", tag);
    else snprintf(buf, n, "Elements");
    return buf;
}

typedef struct key { int dim, tag, type; size_t cell; } key;

static int by_key(const void *a, const void *b)
{
    const key *x = a, *y = b;
    /* volume first, then faces, lines, points; by group, type, file order */
    if (x->dim != y->dim) return x->dim > y->dim ? -1 : 1;
    if (x->tag != y->tag) return x->tag < y->tag ? -1 : 1;
    if (x->type != y->type) return x->type < y->type ? -1 : 1;
    return x->cell < y->cell ? -1 : x->cell > y->cell;
}

static cm_status lib_fail_w(cm_context *ctx, const char *path, const char *what)
{
    return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: %s: %s", path, what, cg_get_error());
}

static cm_status write_sections(cm_context *ctx, const cm_mesh *m, int fn, const char *path, key *keys)
{
    cgsize_t number = 1;
    int only_tets = 1;
    for (size_t c = 0; c < m->n_cells; ++c)
        if (keys[c].dim == 3 && keys[c].type != CM_CELL_TET4) only_tets = 0;
    cgsize_t *conn = NULL;
    cm_status s = CM_OK;
    char names[64][33];
    int used = 0;
    for (size_t a = 0, b; s == CM_OK && a < m->n_cells; a = b) {
        for (b = a + 1; b < m->n_cells && keys[b].dim == keys[a].dim && keys[b].tag == keys[a].tag && keys[b].type == keys[a].type;) ++b;
        const int *perm;
        const CGNS_ENUMT(ElementType_t) t = cgns_type_of((cm_cell_type)keys[a].type, &perm);
        const int npe = cm_cell_type_info((cm_cell_type)keys[a].type)->nodes;
        conn = realloc(conn, (b - a) * (size_t)npe * sizeof *conn);
        if (!conn) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: %s: out of memory", path);
        for (size_t i = a; i < b; ++i) {
            const int64_t *v = m->conn + m->offset[keys[i].cell];
            for (int j = 0; j < npe; ++j) conn[(i - a) * (size_t)npe + (size_t)(perm ? perm[j] : j)] = (cgsize_t)(v[j] + 1);
        }
        char gname[40], sname[40];
        /* meshio reads a tetrahedra-only file's one section named GridElements */
        if (only_tets && keys[a].dim == 3 && a == 0 && (b == m->n_cells || keys[b].dim < 3)) snprintf(sname, sizeof sname, "GridElements");
        else snprintf(sname, sizeof sname, "%.20s_%s", group_name(m, keys[a].dim, keys[a].tag, gname, sizeof gname),
                      cg_ElementTypeName(t));
        /* section names are unique within a zone */
        int dup = 0;
        for (int u = 0; u < used; ++u) dup |= strcmp(names[u], sname) == 0;
        if (dup) {
            char base[40];
            snprintf(base, sizeof base, "%s", sname);
            snprintf(sname, sizeof sname, "%.24s_%d", base, used + 1);
        }
        if (used < 64) snprintf(names[used++], sizeof names[0], "%.32s", sname);
        int S;
        if (cg_section_write(fn, 1, 1, sname, t, number, number + (cgsize_t)(b - a) - 1, 0, conn, &S))
            s = lib_fail_w(ctx, path, "cg_section_write");
        number += (cgsize_t)(b - a);
    }
    free(conn);
    /* one BC per group of 2-D cells: the cells are consecutive after the sort */
    number = 1;
    for (size_t a = 0, b; s == CM_OK && a < m->n_cells; a = b) {
        for (b = a + 1; b < m->n_cells && keys[b].dim == keys[a].dim && keys[b].tag == keys[a].tag;) ++b;
        if (keys[a].dim == 2 && keys[a].tag) {
            char gname[40];
            cgsize_t range[2] = {number, number + (cgsize_t)(b - a) - 1};
            int BC;
            if (cg_boco_write(fn, 1, 1, group_name(m, 2, keys[a].tag, gname, sizeof gname), CGNS_ENUMV(BCTypeUserDefined),
                              CGNS_ENUMV(PointRange), 2, range, &BC) ||
                cg_boco_gridlocation_write(fn, 1, 1, BC, CGNS_ENUMV(FaceCenter)))
                s = lib_fail_w(ctx, path, "cg_boco_write");
        }
        number += (cgsize_t)(b - a);
    }
    return s;
}

static cm_status write_new(cm_context *ctx, const cm_mesh *m, const char *path)
{
    int maxdim = 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        const cm_cell_type t = (cm_cell_type)m->type[c];
        const int *perm;
        if (cgns_type_of(t, &perm) == CGNS_ENUMV(ElementTypeNull))
            return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_write: %s: cell %zu: %s cells are not written to new CGNS files",
                            path, c, cm_cell_type_info(t)->name);
        if (cm_cell_type_info(t)->dim > maxdim) maxdim = cm_cell_type_info(t)->dim;
    }
    if (m->n_nodes >= (size_t)INT_MAX || m->n_cells >= (size_t)INT_MAX || (size_t)m->offset[m->n_cells] >= (size_t)INT_MAX)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_write: %s: more than 2^31 nodes or entries (a 32-bit CGNS library)", path);
    key *keys = malloc((m->n_cells + 1) * sizeof *keys);
    double *c = malloc((m->n_nodes + 1) * sizeof *c);
    if (!keys || !c) {
        free(keys);
        free(c);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: %s: out of memory", path);
    }
    for (size_t i = 0; i < m->n_cells; ++i)
        keys[i] = (key){cm_cell_type_info((cm_cell_type)m->type[i])->dim, m->physical[i], m->type[i], i};
    qsort(keys, m->n_cells, sizeof *keys, by_key);
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) {
        free(keys);
        free(c);
        return s;
    }
    cm_cgns_lock();
    int fn = -1, B, Z, C;
    cgsize_t size[3] = {(cgsize_t)m->n_nodes, (cgsize_t)cm_mesh_count_dim(m, maxdim), 0};
    if (cg_set_file_type(CG_FILE_HDF5) || cg_open(out.tmp, CG_MODE_WRITE, &fn)) s = lib_fail_w(ctx, path, "cg_open");
    if (s == CM_OK && (cg_base_write(fn, "Base", maxdim < 1 ? 1 : maxdim, 3, &B) ||
                       cg_zone_write(fn, B, "Zone1", size, CGNS_ENUMV(Unstructured), &Z)))
        s = lib_fail_w(ctx, path, "cg_zone_write");
    static const char *names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (int k = 0; s == CM_OK && k < 3; ++k) {
        for (size_t i = 0; i < m->n_nodes; ++i) c[i] = m->xyz[3 * i + k];
        if (cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), names[k], c, &C)) s = lib_fail_w(ctx, path, "cg_coord_write");
    }
    if (s == CM_OK) s = write_sections(ctx, m, fn, path, keys);
    if (fn >= 0 && cg_close(fn) && s == CM_OK) s = lib_fail_w(ctx, path, "cg_close");
    cm_cgns_unlock();
    free(keys);
    free(c);
    if (s != CM_OK) {
        cm_outfile_abort(&out);
        return s;
    }
    return cm_outfile_commit(ctx, &out);
}

cm_status cm_mesh_write_cgns(cm_context *ctx, const cm_mesh *mesh, const char *path,
                             const cm_mesh_write_options *opt)
{
    (void)opt;
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_cgns: NULL argument");
    const cm_cgns_state *st = cm_mesh_origin_state(mesh, CM_FORMAT_CGNS);
    return st ? write_back(ctx, mesh, st, path) : write_new(ctx, mesh, path);
}
