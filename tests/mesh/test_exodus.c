/* Exodus II (mesh/io/exodus.c) on files written here with SEACAS's own library: quadratic
 * node order against VTK's (mid-edge nodes at their edges' midpoints by VTK's edge tables,
 * positive volume), blocks, node sets and side sets as groups (faces outward), number maps as
 * tags, the write back (coordinates only, in the file's word size; an affine motion comes back
 * as its image), the refusals, and hostile files (truncated, indices out of range).
 *
 * `test_exodus --fixture PATH [4|8]` only writes the 3-D fixture (for the Python cross-check). */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/mesh.h"
#include "test_files.h"
#include "test_util.h"

#include <exodusII.h>

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- the fixture: elements given in Exodus numbering (Exodus II manual, element figures) ---- */

/* unit cube at x0: Exodus corners 1..8 = (0,0,0) (1,0,0) (1,1,0) (0,1,0), then z = 1 */
static const double cube[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                  {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
/* HEX20 mid-edge nodes 9..20: bottom edges, vertical edges, top edges */
static const int hex_edges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 5},
                                     {2, 6}, {3, 7}, {4, 5}, {5, 6}, {6, 7}, {7, 4}};
/* HEX27 nodes 21..27: centre, then the faces z-, z+, x-, x+, y-, y+ */
static const double hex27_extra[7][3] = {{.5, .5, .5}, {.5, .5, 0}, {.5, .5, 1}, {0, .5, .5},
                                         {1, .5, .5},  {.5, 0, .5}, {.5, 1, .5}};
/* wedge: triangle 1,2,3 counter-clockwise seen from 4,5,6 (z = 1) */
static const double wedge[6][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}};
/* WEDGE15 nodes 7..15: bottom edges, vertical edges, top edges */
static const int wedge_edges[9][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 4}, {2, 5}, {3, 4}, {4, 5}, {5, 3}};

typedef struct fixture {
    int64_t n;
    double x[200], y[200], z[200];
} fixture;

static int64_t add_node(fixture *f, double x, double y, double z)
{
    f->x[f->n] = x, f->y[f->n] = y, f->z[f->n] = z;
    return ++f->n; /* 1-based */
}

/* One element, nodes 1-based in Exodus order, shifted by dx along x. */
static void hex_nodes(fixture *f, int nodes, double dx, int64_t *conn)
{
    for (int i = 0; i < 8; ++i) conn[i] = add_node(f, cube[i][0] + dx, cube[i][1], cube[i][2]);
    for (int e = 0; nodes >= 20 && e < 12; ++e) {
        const double *a = cube[hex_edges[e][0]], *b = cube[hex_edges[e][1]];
        conn[8 + e] = add_node(f, (a[0] + b[0]) / 2 + dx, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2);
    }
    for (int i = 0; nodes == 27 && i < 7; ++i)
        conn[20 + i] = add_node(f, hex27_extra[i][0] + dx, hex27_extra[i][1], hex27_extra[i][2]);
}

static void wedge_nodes(fixture *f, int nodes, double dx, int64_t *conn)
{
    for (int i = 0; i < 6; ++i) conn[i] = add_node(f, wedge[i][0] + dx, wedge[i][1], wedge[i][2]);
    for (int e = 0; nodes == 15 && e < 9; ++e) {
        const double *a = wedge[wedge_edges[e][0]], *b = wedge[wedge_edges[e][1]];
        conn[6 + e] = add_node(f, (a[0] + b[0]) / 2 + dx, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2);
    }
}

/* Writes the 3-D fixture: blocks "solid" (HEX20), 20 (WEDGE15, unnamed), "cube27" (HEX27),
 * "prisms" (WEDGE6) and "tets" (TETRA4); node sets "inlet" and 6 (unnamed); side set "wall"
 * (HEX20 side 5, WEDGE15 side 4, HEX27 side 1, TETRA side 4); node map 101.., element map
 * 1001... bad: 1 puts node 0 in the tets' connectivity, 2 side 7 on the tet, 3 node set entry
 * past the nodes. */
static int write_fixture(const char *path, int ws, int bad)
{
    int comp_ws = 8, io_ws = ws;
    int exoid = ex_create(path, EX_CLOBBER, &comp_ws, &io_ws);
    if (exoid < 0) return -1;
    static fixture f;
    f.n = 0;
    int64_t c_hex20[20], c_wedge15[15], c_hex27[27], c_wedge6[6], c_tet[4];
    hex_nodes(&f, 20, 0, c_hex20);
    wedge_nodes(&f, 15, 2, c_wedge15);
    hex_nodes(&f, 27, 4, c_hex27);
    wedge_nodes(&f, 6, 6, c_wedge6);
    /* tet (0,0,0) (1,0,0) (0,1,0) (0,0,1) at x = 8: positive by the right-hand rule */
    for (int i = 0; i < 4; ++i) c_tet[i] = add_node(&f, wedge[i][0] + 8, wedge[i][1], wedge[i][2]);
    if (bad == 1) c_tet[2] = 0;
    int rc = ex_put_init(exoid, "cadmorph test fixture", 3, f.n, 5, 5, 2, 1);
    rc |= ex_put_coord(exoid, f.x, f.y, f.z);
    const char *coord_names[3] = {"x", "y", "z"};
    rc |= ex_put_coord_names(exoid, (char **)coord_names);
    rc |= ex_put_block(exoid, EX_ELEM_BLOCK, 10, "HEX20", 1, 20, 0, 0, 0);
    rc |= ex_put_block(exoid, EX_ELEM_BLOCK, 20, "WEDGE15", 1, 15, 0, 0, 0);
    rc |= ex_put_block(exoid, EX_ELEM_BLOCK, 30, "HEX27", 1, 27, 0, 0, 0);
    rc |= ex_put_block(exoid, EX_ELEM_BLOCK, 40, "WEDGE", 1, 6, 0, 0, 0);
    rc |= ex_put_block(exoid, EX_ELEM_BLOCK, 50, "TETRA", 1, 4, 0, 0, 0);
    int conn32[27];
    const int64_t *conns[5] = {c_hex20, c_wedge15, c_hex27, c_wedge6, c_tet};
    const int sizes[5] = {20, 15, 27, 6, 4};
    for (int b = 0; b < 5; ++b) {
        for (int i = 0; i < sizes[b]; ++i) conn32[i] = (int)conns[b][i];
        rc |= ex_put_conn(exoid, EX_ELEM_BLOCK, 10 * (b + 1), conn32, NULL, NULL);
    }
    rc |= ex_put_name(exoid, EX_ELEM_BLOCK, 10, "solid");
    rc |= ex_put_name(exoid, EX_ELEM_BLOCK, 30, "cube27");
    rc |= ex_put_name(exoid, EX_ELEM_BLOCK, 40, "prisms");
    rc |= ex_put_name(exoid, EX_ELEM_BLOCK, 50, "tets");
    /* node sets: the hex20's bottom corners; the tet's apex */
    int inlet[4] = {(int)c_hex20[0], (int)c_hex20[1], (int)c_hex20[2], (int)c_hex20[3]};
    if (bad == 3) inlet[3] = (int)f.n + 1;
    int apex[1] = {(int)c_tet[3]};
    rc |= ex_put_set_param(exoid, EX_NODE_SET, 5, 4, 0);
    rc |= ex_put_set(exoid, EX_NODE_SET, 5, inlet, NULL);
    rc |= ex_put_set_param(exoid, EX_NODE_SET, 6, 1, 0);
    rc |= ex_put_set(exoid, EX_NODE_SET, 6, apex, NULL);
    rc |= ex_put_name(exoid, EX_NODE_SET, 5, "inlet");
    int ss_elem[4] = {1, 2, 3, 5}, ss_side[4] = {5, 4, 1, bad == 2 ? 7 : 4};
    rc |= ex_put_set_param(exoid, EX_SIDE_SET, 7, 4, 0);
    rc |= ex_put_set(exoid, EX_SIDE_SET, 7, ss_elem, ss_side);
    rc |= ex_put_name(exoid, EX_SIDE_SET, 7, "wall");
    int node_map[200], elem_map[5];
    for (int i = 0; i < f.n; ++i) node_map[i] = 101 + i;
    for (int i = 0; i < 5; ++i) elem_map[i] = 1001 + i;
    rc |= ex_put_id_map(exoid, EX_NODE_MAP, node_map);
    rc |= ex_put_id_map(exoid, EX_ELEM_MAP, elem_map);
    rc |= ex_close(exoid);
    return rc;
}

/* ---- checks ---- */

/* VTK's edges of the quadratic types (the tables of mesh/cell_faces.c, checked against
 * vtkQuadraticHexahedron / vtkQuadraticWedge) and face centres of vtkTriQuadraticHexahedron */
static const int vtk_hex_edges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                         {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
static const int vtk_hex_faces[6][4] = {{0, 3, 7, 4}, {1, 2, 6, 5}, {0, 1, 5, 4},
                                        {3, 2, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7}};
static const int vtk_wedge_edges[9][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5},
                                          {5, 3}, {0, 3}, {1, 4}, {2, 5}};

static const double *node(const cm_mesh *m, int64_t i) { return m->xyz + 3 * i; }

static int is_mean(const cm_mesh *m, int64_t c, const int64_t *nodes, int k)
{
    double p[3] = {0, 0, 0};
    for (int i = 0; i < k; ++i)
        for (int d = 0; d < 3; ++d) p[d] += node(m, nodes[i])[d] / k;
    const double *q = node(m, c);
    return fabs(p[0] - q[0]) + fabs(p[1] - q[1]) + fabs(p[2] - q[2]) < 1e-12;
}

static void check_cell_layout(const cm_mesh *m, size_t c)
{
    const int64_t *v = m->conn + m->offset[c];
    const cm_cell_type t = (cm_cell_type)m->type[c];
    if (t == CM_CELL_HEX20 || t == CM_CELL_HEX27)
        for (int e = 0; e < 12; ++e) {
            const int64_t ends[2] = {v[vtk_hex_edges[e][0]], v[vtk_hex_edges[e][1]]};
            CHECK_MSG(is_mean(m, v[8 + e], ends, 2), "cell %zu edge %d", c, e);
        }
    if (t == CM_CELL_HEX27) {
        for (int f = 0; f < 6; ++f) {
            int64_t corners[4];
            for (int i = 0; i < 4; ++i) corners[i] = v[vtk_hex_faces[f][i]];
            CHECK_MSG(is_mean(m, v[20 + f], corners, 4), "hex27 face %d", f);
        }
        CHECK(is_mean(m, v[26], v, 8));
    }
    if (t == CM_CELL_WEDGE15)
        for (int e = 0; e < 9; ++e) {
            const int64_t ends[2] = {v[vtk_wedge_edges[e][0]], v[vtk_wedge_edges[e][1]]};
            CHECK_MSG(is_mean(m, v[6 + e], ends, 2), "wedge15 edge %d", e);
        }
}

static const cm_mesh_group *group(const cm_mesh *m, const char *name, int dim)
{
    for (size_t g = 0; g < m->n_groups; ++g)
        if (!strcmp(m->groups[g].name, name) && m->groups[g].dim == dim) return &m->groups[g];
    return NULL;
}

/* The face's corners wind outward: their normal points away from the cell's centroid. */
static int outward(const cm_mesh *m, size_t face, size_t cell)
{
    const int64_t *f = m->conn + m->offset[face];
    const double *a = node(m, f[0]), *b = node(m, f[1]), *c = node(m, f[2]);
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double nrm[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const cm_cell_info *info = cm_cell_type_info((cm_cell_type)m->type[cell]);
    double ctr[3] = {0, 0, 0};
    for (int i = 0; i < info->corners; ++i)
        for (int d = 0; d < 3; ++d) ctr[d] += node(m, m->conn[m->offset[cell] + i])[d] / info->corners;
    return nrm[0] * (a[0] - ctr[0]) + nrm[1] * (a[1] - ctr[1]) + nrm[2] * (a[2] - ctr[2]) > 0;
}

static void test_read(cm_context *ctx, const char *path)
{
    cm_mesh *m = NULL;
    CHECK_MSG(cm_mesh_read(ctx, path, &m) == CM_OK, "%s", cm_context_message(ctx));
    if (!m) return;
    CHECK(cm_mesh_format_from_path(path) == CM_FORMAT_EXODUS);
    CHECK(m->n_nodes == 20 + 15 + 27 + 6 + 4);
    /* 5 elements, 4 + 1 node-set points, 4 side faces */
    CHECK(m->n_cells == 5 + 5 + 4);
    const cm_cell_type types[5] = {CM_CELL_HEX20, CM_CELL_WEDGE15, CM_CELL_HEX27, CM_CELL_WEDGE6, CM_CELL_TET4};
    for (size_t c = 0; c < 5; ++c) {
        CHECK(m->type[c] == types[c]);
        check_cell_layout(m, c);
        CHECK(m->cell_tag && m->cell_tag[c] == (int64_t)(1001 + c));
    }
    double sj[14];
    CHECK(cm_mesh_quality(ctx, m, sj) == CM_OK);
    for (size_t c = 0; c < 5; ++c) CHECK_MSG(sj[c] > 0.5, "cell %zu: scaled Jacobian %g", c, sj[c]);
    CHECK(m->node_tag && m->node_tag[0] == 101 && m->node_tag[m->n_nodes - 1] == (int64_t)(100 + m->n_nodes));
    const cm_mesh_group *solid = group(m, "solid", 3), *b20 = group(m, "block 20", 3);
    const cm_mesh_group *inlet = group(m, "inlet", 0), *ns6 = group(m, "nodeset 6", 0);
    const cm_mesh_group *wall = group(m, "wall", 2);
    CHECK(solid && b20 && group(m, "cube27", 3) && group(m, "prisms", 3) && group(m, "tets", 3));
    CHECK(inlet && ns6 && wall);
    if (!solid || !b20 || !inlet || !ns6 || !wall) goto out;
    CHECK(m->physical[0] == solid->tag && m->physical[1] == b20->tag);
    for (size_t c = 5; c < 9; ++c)
        CHECK(m->type[c] == CM_CELL_POINT && m->physical[c] == inlet->tag && m->conn[m->offset[c]] == (int64_t)(c - 5));
    CHECK(m->type[9] == CM_CELL_POINT && m->physical[9] == ns6->tag);
    /* side set: HEX20 side 5 (bottom, QUAD8), WEDGE15 side 4 (bottom, TRI6), HEX27 side 1
     * (y = 0, QUAD9), TETRA side 4 (z = 0, TRI3); each outward, mid nodes at their places */
    const cm_cell_type face_types[4] = {CM_CELL_QUAD8, CM_CELL_TRI6, CM_CELL_QUAD9, CM_CELL_TRI3};
    const size_t owner[4] = {0, 1, 2, 4};
    const int axis[4] = {2, 2, 1, 2};
    for (size_t k = 0; k < 4; ++k) {
        const size_t c = 10 + k;
        CHECK(m->type[c] == face_types[k] && m->physical[c] == wall->tag);
        CHECK_MSG(outward(m, c, owner[k]), "side %zu inward", k);
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)m->type[c]);
        const int64_t *v = m->conn + m->offset[c];
        for (int i = 0; i < info->nodes; ++i) CHECK(node(m, v[i])[axis[k]] == 0.0);
        for (int i = 0; info->nodes > info->corners && i < info->corners; ++i) {
            const int64_t ends[2] = {v[i], v[(i + 1) % info->corners]};
            CHECK_MSG(is_mean(m, v[info->corners + i], ends, 2), "side %zu edge %d", k, i);
        }
        if (m->type[c] == CM_CELL_QUAD9) CHECK(is_mean(m, v[8], v, 4));
    }
out:
    cm_mesh_destroy(&m);
}

/* Reads path with the library: coordinates, word size, the connectivity of block 10. */
static int read_back(const char *path, double *x, double *y, double *z, int *ws, int64_t *conn)
{
    int comp_ws = 8, io_ws = 0;
    float version;
    int exoid = ex_open(path, EX_READ, &comp_ws, &io_ws, &version);
    if (exoid < 0) return -1;
    ex_set_int64_status(exoid, EX_ALL_INT64_API);
    *ws = io_ws;
    int rc = ex_get_coord(exoid, x, y, z);
    rc |= ex_get_conn(exoid, EX_ELEM_BLOCK, 10, conn, NULL, NULL);
    rc |= ex_close(exoid);
    return rc;
}

static void affine(const double *p, double *q)
{
    q[0] = 1.5 * p[0] + 0.25 * p[1] - 0.5 * p[2] + 3.0;
    q[1] = -0.25 * p[0] + 0.75 * p[1] + 0.125 * p[2] - 1.0;
    q[2] = 0.5 * p[0] + 0.5 * p[1] + 2.0 * p[2] + 0.5;
}

static void test_write_back(cm_context *ctx, const char *in, int ws)
{
    char out[1024];
    snprintf(out, sizeof out, "%s/moved_%d.exo", test_work_dir(), ws);
    cm_mesh *m = NULL;
    CHECK(cm_mesh_read(ctx, in, &m) == CM_OK);
    if (!m) return;
    double before[3 * 72];
    memcpy(before, m->xyz, sizeof before);
    for (size_t i = 0; i < m->n_nodes; ++i) affine(before + 3 * i, m->xyz + 3 * i);
    CHECK_MSG(cm_mesh_write(ctx, m, out, NULL) == CM_OK, "%s", cm_context_message(ctx));
    double x[72], y[72], z[72];
    int64_t conn[20], conn0[20];
    int got_ws = 0, ws0 = 0;
    CHECK(read_back(out, x, y, z, &got_ws, conn) == 0);
    CHECK(got_ws == ws);
    double x0[72], y0[72], z0[72];
    CHECK(read_back(in, x0, y0, z0, &ws0, conn0) == 0);
    CHECK(!memcmp(conn, conn0, sizeof conn));
    /* the affine image, to the file's precision (float: the image rounded to float) */
    int exact = 1;
    for (size_t i = 0; i < m->n_nodes; ++i) {
        const double *q = m->xyz + 3 * i;
        const double want[3] = {ws == 4 ? (float)q[0] : q[0], ws == 4 ? (float)q[1] : q[1],
                                ws == 4 ? (float)q[2] : q[2]};
        exact &= x[i] == want[0] && y[i] == want[1] && z[i] == want[2];
    }
    CHECK_MSG(exact, "word size %d: written coordinates differ from the affine image", ws);
    /* read back through cadmorph: same cells and groups */
    cm_mesh *r = NULL;
    CHECK(cm_mesh_read(ctx, out, &r) == CM_OK);
    if (r) {
        CHECK(r->n_cells == m->n_cells && r->n_groups == m->n_groups);
        CHECK(!memcmp(r->conn, m->conn, (size_t)m->offset[m->n_cells] * sizeof *m->conn));
        cm_mesh_destroy(&r);
    }
    /* in place: the source itself rewritten, then its unchanged copy refused after the change */
    if (ws == 8) {
        const char *copy = test_at("in_place.exo");
        char cmd[2200];
        snprintf(cmd, sizeof cmd, "cp %s %s", in, copy);
        CHECK(system(cmd) == 0);
        cm_mesh *p = NULL;
        CHECK(cm_mesh_read(ctx, copy, &p) == CM_OK);
        if (p) {
            memcpy(p->xyz, m->xyz, 3 * m->n_nodes * sizeof *p->xyz);
            CHECK(cm_mesh_write(ctx, p, copy, NULL) == CM_OK);
            CHECK(read_back(copy, x0, y0, z0, &ws0, conn0) == 0 && !memcmp(x0, x, sizeof x));
            /* the file changed since p was read: refused */
            CHECK(cm_mesh_write(ctx, p, out, NULL) == CM_ERR_IO);
            CHECK(strstr(cm_context_message(ctx), "changed") != NULL);
            cm_mesh_destroy(&p);
        }
    }
    /* a mesh that is no longer the one read (one more cell) is not written back: refused */
    const int64_t one = 0;
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POINT, &one, 1, 0, 0, 0) == CM_OK);
    const char *other = test_at("other.e");
    CHECK(cm_mesh_write(ctx, m, other, NULL) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "Exodus II is written only back") != NULL);
    CHECK(access(other, F_OK) != 0);
    cm_mesh_destroy(&m);
}

static void test_2d(cm_context *ctx)
{
    const char *path = test_at("flat.exo"), *out = test_at("flat_out.exo");
    int comp_ws = 8, io_ws = 8;
    int exoid = ex_create(path, EX_CLOBBER, &comp_ws, &io_ws);
    const double x[6] = {0, 1, 2, 0, 1, 2}, y[6] = {0, 0, 0, 1, 1, 1};
    const int conn[8] = {1, 2, 5, 4, 2, 3, 6, 5};
    int rc = ex_put_init(exoid, "flat", 2, 6, 2, 1, 0, 1);
    rc |= ex_put_coord(exoid, x, y, NULL);
    rc |= ex_put_block(exoid, EX_ELEM_BLOCK, 1, "QUAD4", 2, 4, 0, 0, 0);
    rc |= ex_put_conn(exoid, EX_ELEM_BLOCK, 1, conn, NULL, NULL);
    const int el[1] = {2}, side[1] = {2}; /* the edge x = 2 */
    rc |= ex_put_set_param(exoid, EX_SIDE_SET, 3, 1, 0);
    rc |= ex_put_set(exoid, EX_SIDE_SET, 3, el, side);
    rc |= ex_close(exoid);
    CHECK(rc == 0);
    cm_mesh *m = NULL;
    CHECK_MSG(cm_mesh_read(ctx, path, &m) == CM_OK, "%s", cm_context_message(ctx));
    if (!m) return;
    CHECK(m->n_nodes == 6 && m->n_cells == 3 && m->type[0] == CM_CELL_QUAD4);
    CHECK(m->xyz[3 * 5 + 0] == 2 && m->xyz[3 * 5 + 1] == 1 && m->xyz[3 * 5 + 2] == 0);
    CHECK(m->type[2] == CM_CELL_LINE2 && m->conn[m->offset[2]] == 2 && m->conn[m->offset[2] + 1] == 5);
    CHECK(group(m, "sideset 3", 1) != NULL);
    m->xyz[0] = -0.5;
    CHECK(cm_mesh_write(ctx, m, out, NULL) == CM_OK);
    m->xyz[2] = 1.0;
    CHECK(cm_mesh_write(ctx, m, out, NULL) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "2-D") != NULL);
    cm_mesh_destroy(&m);
    CHECK(cm_mesh_read(ctx, out, &m) == CM_OK && m && m->xyz[0] == -0.5);
    cm_mesh_destroy(&m);
}

static void expect_error(cm_context *ctx, const char *path, const char *needle)
{
    cm_mesh *m = NULL;
    const cm_status s = cm_mesh_read(ctx, path, &m);
    CHECK_MSG(s < 0 && !m, "%s: status %d", path, (int)s);
    const char *msg = cm_context_message(ctx);
    CHECK_MSG(strstr(msg, path) && strstr(msg, needle), "%s: message '%s' lacks '%s'", path, msg, needle);
    cm_mesh_destroy(&m);
}

static void test_hostile(cm_context *ctx, const char *good)
{
    char path[1024];
    const char *cases[3][2] = {{"bad_node", "block \"tets\": element 1: node 0 out of range"},
                               {"bad_side", "side set \"wall\": entry 4: element 5 (tet4) has no side 7"},
                               {"bad_nodeset", "node set \"inlet\": entry 4: node 73 out of range"}};
    for (int k = 0; k < 3; ++k) {
        snprintf(path, sizeof path, "%s/%s.exo", test_work_dir(), cases[k][0]);
        CHECK(write_fixture(path, 8, k + 1) == 0);
        expect_error(ctx, path, cases[k][1]);
    }
    snprintf(path, sizeof path, "%s", test_at("text.exo"));
    test_write_text(path, "not a netCDF file\n");
    expect_error(ctx, path, "not an Exodus II file");
    /* every truncation of the classic file: an error, never a crash */
    size_t n = 0;
    char *data = test_read_file(good, &n);
    CHECK(data && n > 100);
    snprintf(path, sizeof path, "%s", test_at("cut.exo"));
    int failed = 0;
    for (size_t len = 0; len < n; len += 1 + len / 16) {
        test_write_file(path, data, len);
        cm_mesh *m = NULL;
        const cm_status s = cm_mesh_read(ctx, path, &m);
        if (s >= 0 && m) cm_mesh_destroy(&m);
        else if (!strstr(cm_context_message(ctx), path)) ++failed;
    }
    CHECK_MSG(failed == 0, "%d truncations with a message that does not name the file", failed);
    /* a classic header whose first dimension name claims 2 GB: refused from the header, before
     * the netCDF library allocates the name */
    if (!memcmp(data, "CDF", 3) && data[3] != 5) {
        unsigned char *d = (unsigned char *)data;
        CHECK(d[11] == 0x0A); /* NC_DIMENSION, then the count, then the first name's length */
        d[16] = 0x7f, d[17] = 0xff, d[18] = 0, d[19] = 0;
        snprintf(path, sizeof path, "%s", test_at("huge_name.exo"));
        test_write_file(path, data, n < 4096 ? n : 4096);
        expect_error(ctx, path, "byte 20: corrupt netCDF header (the dimension list");
    }
    free(data);
}

int main(int argc, char **argv)
{
    if (argc == 4 && !strcmp(argv[1], "--fixture")) return write_fixture(argv[2], atoi(argv[3]), 0) != 0;
    if (test_work_temp("exodus") != 0) return 1;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    char path8[1024], path4[1024];
    snprintf(path8, sizeof path8, "%s/mixed.exo", test_work_dir());
    snprintf(path4, sizeof path4, "%s/mixed_float.e", test_work_dir());
    CHECK(write_fixture(path8, 8, 0) == 0);
    CHECK(write_fixture(path4, 4, 0) == 0);
    test_read(ctx, path8);
    test_read(ctx, path4);
    test_write_back(ctx, path8, 8);
    test_write_back(ctx, path4, 4);
    test_2d(ctx);
    test_hostile(ctx, path8);
    cm_context_destroy(&ctx);
    if (test_work_remove() != 0) return 1;
    return TEST_REPORT();
}
