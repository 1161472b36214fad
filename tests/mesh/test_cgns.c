/* CGNS files (mesh/io/cgns_read.c, cgns_write.c) against files the CGNS library itself
 * writes here: every element type in SIDS node order (each higher-order node placed at the
 * mean of the corners SIDS gives it, checked against VTK's lists after the read), MIXED
 * sections, NGON_n/NFACE_n polyhedra, two zones merged at their interface with BCs, families
 * and vertex sets as groups, RealSingle coordinates, ADF and HDF5; an affine motion written
 * back is the affine image to the stored precision; structured zones and hostile files are
 * refused with the file and the node path. Leaves pairs <name>.cgns / <name>_moved.cgns in
 * <work>/cgns for the tree comparison (test_cgns_tree.py). */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/mesh.h"
#include "test_files.h"
#include "test_util.h"

#include <cgnslib.h>
#include <stdlib.h>
#include <string.h>

/* ---- element types: corners and the SIDS lists of corners each further node is the mean of */

typedef struct elem {
    CGNS_ENUMT(ElementType_t) type;
    cm_cell_type cm;
    int corners;
    double ref[8][3];
    const char *sids;  /* further nodes: corner digits (1-based), '|' between nodes */
    const char *vtk;   /* the same in VTK's order, 0-based */
} elem;

static const elem elems[] = {
    {CGNS_ENUMV(BAR_3), CM_CELL_LINE3, 2, {{0, 0, 0}, {1, 0.2, 0}}, "12", "01"},
    {CGNS_ENUMV(TRI_6), CM_CELL_TRI6, 3, {{0, 0, 0}, {1, 0, 0}, {0.1, 1, 0}}, "12|23|31", "01|12|20"},
    {CGNS_ENUMV(QUAD_8), CM_CELL_QUAD8, 4, {{0, 0, 0}, {1, 0, 0}, {1.2, 1, 0}, {0, 1.1, 0}}, "12|23|34|41", "01|12|23|30"},
    {CGNS_ENUMV(QUAD_9), CM_CELL_QUAD9, 4, {{0, 0, 0}, {1, 0, 0}, {1.2, 1, 0}, {0, 1.1, 0}}, "12|23|34|41|1234", "01|12|23|30|0123"},
    {CGNS_ENUMV(TETRA_10), CM_CELL_TET10, 4, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.1, 0.2, 1}},
     "12|23|31|14|24|34", "01|12|02|03|13|23"},
    {CGNS_ENUMV(PYRA_13), CM_CELL_PYR13, 5, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.4, 1}},
     "12|23|34|41|15|25|35|45", "01|12|23|30|04|14|24|34"},
    {CGNS_ENUMV(PYRA_14), CM_CELL_PYR14, 5, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.4, 1}},
     "12|23|34|41|15|25|35|45|1234", "01|12|23|30|04|14|24|34|0123"},
    {CGNS_ENUMV(PENTA_15), CM_CELL_WEDGE15, 6, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0.1, 1}, {0, 1, 1.2}},
     "12|23|31|14|25|36|45|56|64", "01|12|20|34|45|53|03|14|25"},
    {CGNS_ENUMV(PENTA_18), CM_CELL_WEDGE18, 6, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0.1, 1}, {0, 1, 1.2}},
     "12|23|31|14|25|36|45|56|64|1254|2365|3146", "01|12|20|34|45|53|03|14|25|0143|1254|2035"},
    {CGNS_ENUMV(HEXA_20), CM_CELL_HEX20, 8,
     {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1.1}, {1.2, 1, 1}, {0, 1, 1}},
     "12|23|34|41|15|26|37|48|56|67|78|85", "01|12|23|30|45|56|67|74|04|15|26|37"},
    {CGNS_ENUMV(HEXA_27), CM_CELL_HEX27, 8,
     {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1.1}, {1.2, 1, 1}, {0, 1, 1}},
     "12|23|34|41|15|26|37|48|56|67|78|85|1234|1265|2376|3487|1584|5678|12345678",
     "01|12|23|30|45|56|67|74|04|15|26|37|0473|1265|0154|3267|0123|4567|01234567"},
};
enum { N_ELEMS = sizeof elems / sizeof elems[0] };

/* The node of list item k ("12|23": item 1 is corners 2 and 3) as the corners' mean. */
static void mean_of(const elem *e, const char *list, int k, int base, double *p)
{
    const char *s = list;
    for (int i = 0; i < k; ++i) s = strchr(s, '|') + 1;
    int n = 0;
    p[0] = p[1] = p[2] = 0;
    for (; *s && *s != '|'; ++s, ++n)
        for (int d = 0; d < 3; ++d) p[d] += e->ref[*s - '0' - base][d];
    for (int d = 0; d < 3; ++d) p[d] /= n;
}

static int count_items(const char *list)
{
    int n = 1;
    for (; *list; ++list) n += *list == '|';
    return n;
}

/* One zone, each element type in its own section with its own nodes, the 3-D ones also once
 * more in one MIXED section. */
static void write_all_types(const char *path)
{
    int fn, B, Z, S, C;
    double x[2][400][3];
    int nn = 0;
    cgsize_t conn[2][N_ELEMS][28], mixed[400], nm = 0;
    for (int copy = 0; copy < 2; ++copy)
        for (int e = 0; e < N_ELEMS; ++e) {
            const elem *el = &elems[e];
            const int extra = count_items(el->sids);
            for (int c = 0; c < el->corners + extra; ++c, ++nn) {
                double *p = x[0][nn];
                if (c < el->corners) memcpy(p, el->ref[c], sizeof el->ref[c]);
                else mean_of(el, el->sids, c - el->corners, 1, p);
                p[0] += 3.0 * e; /* apart */
                p[1] += 3.0 * copy;
                conn[copy][e][c] = nn + 1;
            }
        }
    CHECK(cg_open(path, CG_MODE_WRITE, &fn) == CG_OK);
    CHECK(cg_base_write(fn, "Base", 3, 3, &B) == CG_OK);
    cgsize_t size[3] = {nn, 2 * N_ELEMS, 0};
    CHECK(cg_zone_write(fn, B, "All", size, CGNS_ENUMV(Unstructured), &Z) == CG_OK);
    static const char *names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    double c[400];
    for (int d = 0; d < 3; ++d) {
        for (int i = 0; i < nn; ++i) c[i] = x[0][i][d];
        CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), names[d], c, &C) == CG_OK);
    }
    cgsize_t number = 1;
    for (int e = 0; e < N_ELEMS; ++e, ++number)
        CHECK(cg_section_write(fn, B, Z, cg_ElementTypeName(elems[e].type), elems[e].type, number, number, 0,
                               conn[0][e], &S) == CG_OK);
    cgsize_t offsets[N_ELEMS + 1] = {0};
    for (int e = 0; e < N_ELEMS; ++e) {
        const int n = elems[e].corners + count_items(elems[e].sids);
        mixed[nm++] = elems[e].type;
        for (int i = 0; i < n; ++i) mixed[nm++] = conn[1][e][i];
        offsets[e + 1] = nm;
    }
    CHECK(cg_poly_section_write(fn, B, Z, "Mixed", CGNS_ENUMV(MIXED), number, number + N_ELEMS - 1, 0, mixed,
                                offsets, &S) == CG_OK);
    CHECK(cg_close(fn) == CG_OK);
}

static void test_all_types(cm_context *ctx)
{
    const char *path = test_at("types.cgns");
    write_all_types(path);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (s != CM_OK) return;
    CHECK(m->n_cells == 2 * N_ELEMS);
    for (size_t cell = 0; cell < m->n_cells; ++cell) {
        const elem *el = &elems[cell % N_ELEMS];
        CHECK(m->type[cell] == el->cm);
        const int64_t *v = m->conn + m->offset[cell];
        /* the corners as written, then each further node where VTK's list puts it */
        const int extra = count_items(el->vtk);
        for (int k = 0; k < extra; ++k) {
            double want[3] = {0, 0, 0}, got[3];
            const char *sp = el->vtk;
            for (int i = 0; i < k; ++i) sp = strchr(sp, '|') + 1;
            int n = 0;
            for (; *sp && *sp != '|'; ++sp, ++n)
                for (int d = 0; d < 3; ++d) want[d] += m->xyz[3 * v[*sp - '0'] + d];
            memcpy(got, m->xyz + 3 * v[el->corners + k], sizeof got);
            for (int d = 0; d < 3; ++d) CHECK_NEAR(got[d], want[d] / n, 1e-12);
        }
    }
    /* the volume cells carry the zone's group; the 1-D and 2-D ones their section's */
    int zone = 0, tri = 0;
    for (size_t g = 0; g < m->n_groups; ++g) {
        if (m->groups[g].dim == 3 && strcmp(m->groups[g].name, "All") == 0) zone = m->groups[g].tag;
        if (m->groups[g].dim == 2 && strcmp(m->groups[g].name, "TRI_6") == 0) tri = m->groups[g].tag;
    }
    CHECK(zone && tri);
    CHECK(m->physical[4] == zone && m->physical[1] == tri);
    /* a new file of every type reads back the same */
    const char *copy = test_at("types_new.cgns");
    cm_mesh *n = NULL;
    cm_mesh *plain = NULL;
    CHECK(cm_mesh_copy(ctx, m, &plain) == CM_OK);
    /* more nodes: no longer the mesh read, so a new file is written */
    CHECK(cm_mesh_resize_nodes(ctx, plain, plain->n_nodes + 1, 0) == CM_OK);
    plain->xyz[3 * plain->n_nodes - 3] = plain->xyz[3 * plain->n_nodes - 2] = plain->xyz[3 * plain->n_nodes - 1] = 0;
    s = cm_mesh_write(ctx, plain, copy, NULL);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    s = cm_mesh_read(ctx, copy, &n);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (s == CM_OK) {
        CHECK(n->n_nodes == plain->n_nodes && n->n_cells == plain->n_cells);
        /* cells are grouped by (dim, group, type) in the new file: compare as multisets of
         * node lists by type */
        size_t same = 0;
        for (size_t a = 0; a < n->n_cells; ++a)
            for (size_t b = 0; b < plain->n_cells; ++b)
                if (n->type[a] == plain->type[b] && n->offset[a + 1] - n->offset[a] == plain->offset[b + 1] - plain->offset[b] &&
                    memcmp(n->conn + n->offset[a], plain->conn + plain->offset[b],
                           (size_t)(n->offset[a + 1] - n->offset[a]) * sizeof(int64_t)) == 0) {
                    ++same;
                    break;
                }
        CHECK(same == n->n_cells);
        CHECK(memcmp(n->xyz, plain->xyz, 3 * n->n_nodes * sizeof(double)) == 0);
    }
    cm_mesh_destroy(&n);
    cm_mesh_destroy(&plain);
    cm_mesh_destroy(&m);
}

/* ---- two zones of 2x2x2 hexahedra side by side (x in [0,2] and [2,4]) ---- */

static void write_two_zones(const char *path, int file_type)
{
    int fn, B, Z, S, C, BC;
    CHECK(cg_set_file_type(file_type) == CG_OK);
    CHECK(cg_open(path, CG_MODE_WRITE, &fn) == CG_OK);
    CHECK(cg_base_write(fn, "Base", 3, 3, &B) == CG_OK);
    int F;
    CHECK(cg_family_write(fn, B, "wall", &F) == CG_OK);
    for (int zone = 0; zone < 2; ++zone) {
        cgsize_t size[3] = {27, 8, 0};
        CHECK(cg_zone_write(fn, B, zone ? "right" : "left", size, CGNS_ENUMV(Unstructured), &Z) == CG_OK);
        double c[3][27];
        float cf[3][27];
        for (int k = 0, i = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
                for (int l = 0; l < 3; ++l, ++i) {
                    /* dyadic values: the same in float and double */
                    c[0][i] = 2.0 * zone + l + 0.125 * j;
                    c[1][i] = j + 0.0625 * k;
                    c[2][i] = k + 0.0625 * (l + 2 * zone) * j;
                    for (int d = 0; d < 3; ++d) cf[d][i] = (float)c[d][i];
                }
        static const char *names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
        for (int d = 0; d < 3; ++d)
            CHECK(cg_coord_write(fn, B, Z, zone ? CGNS_ENUMV(RealSingle) : CGNS_ENUMV(RealDouble), names[d],
                                 zone ? (void *)cf[d] : (void *)c[d], &C) == CG_OK);
        cgsize_t hex[64], n = 0;
        for (int k = 0; k < 2; ++k)
            for (int j = 0; j < 2; ++j)
                for (int l = 0; l < 2; ++l) {
                    const cgsize_t o = 9 * k + 3 * j + l + 1;
                    const cgsize_t v[8] = {o, o + 1, o + 4, o + 3, o + 9, o + 10, o + 13, o + 12};
                    memcpy(hex + n, v, sizeof v);
                    n += 8;
                }
        CHECK(cg_section_write(fn, B, Z, "Hexa", CGNS_ENUMV(HEXA_8), 1, 8, 0, hex, &S) == CG_OK);
        /* the bottom z = 0: four quads */
        cgsize_t quad[16], q = 0;
        for (int j = 0; j < 2; ++j)
            for (int l = 0; l < 2; ++l) {
                const cgsize_t o = 3 * j + l + 1;
                const cgsize_t v[4] = {o, o + 3, o + 4, o + 1};
                memcpy(quad + q, v, sizeof v);
                q += 4;
            }
        CHECK(cg_section_write(fn, B, Z, "Bottom", CGNS_ENUMV(QUAD_4), 9, 12, 0, quad, &S) == CG_OK);
        cgsize_t range[2] = {9, 12};
        CHECK(cg_boco_write(fn, B, Z, zone ? "floor2" : "floor1", CGNS_ENUMV(FamilySpecified),
                            CGNS_ENUMV(PointRange), 2, range, &BC) == CG_OK);
        CHECK(cg_boco_gridlocation_write(fn, B, Z, BC, CGNS_ENUMV(FaceCenter)) == CG_OK);
        CHECK(cg_goto(fn, B, "Zone_t", Z, "ZoneBC_t", 1, "BC_t", BC, NULL) == CG_OK);
        CHECK(cg_famname_write("wall") == CG_OK);
        if (zone == 0) { /* the inlet x = 0 as a vertex list */
            cgsize_t pts[9] = {1, 4, 7, 10, 13, 16, 19, 22, 25};
            CHECK(cg_boco_write(fn, B, Z, "inlet", CGNS_ENUMV(BCInflow), CGNS_ENUMV(PointList), 9, pts, &BC) == CG_OK);
        }
    }
    CHECK(cg_close(fn) == CG_OK);
    cg_set_file_type(CG_FILE_HDF5);
}

static int group(const cm_mesh *m, int dim, const char *name)
{
    for (size_t g = 0; g < m->n_groups; ++g)
        if (m->groups[g].dim == dim && strcmp(m->groups[g].name, name) == 0) return m->groups[g].tag;
    return 0;
}

static void affine(const double *p, double *q)
{
    q[0] = 1.1 * p[0] + 0.2 * p[1] - 0.1 * p[2] + 0.3;
    q[1] = -0.05 * p[0] + 0.9 * p[1] + 0.1 * p[2] - 1.0;
    q[2] = 0.02 * p[0] + 0.0 * p[1] + 1.2 * p[2] + 2.5;
}

/* Reads a zone's coordinates straight through the library. */
static void zone_coords(const char *path, int Z, double *x, int n)
{
    int fn;
    CHECK(cg_open(path, CG_MODE_READ, &fn) == CG_OK);
    static const char *names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    double c[64];
    for (int d = 0; d < 3; ++d) {
        cgsize_t lo = 1, hi = n;
        CHECK(cg_coord_read(fn, 1, Z, names[d], CGNS_ENUMV(RealDouble), &lo, &hi, c) == CG_OK);
        for (int i = 0; i < n; ++i) x[3 * i + d] = c[i];
    }
    cg_close(fn);
}

static void test_two_zones(cm_context *ctx, const char *name, int file_type)
{
    char in[64], out[64];
    snprintf(in, sizeof in, "%s.cgns", name);
    snprintf(out, sizeof out, "%s_moved.cgns", name);
    write_two_zones(test_at(in), file_type);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, test_at(in), &m);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (s != CM_OK) return;
    CHECK(m->n_nodes == 27 + 27 - 9); /* the interface merged */
    if (m->n_nodes != 45) return;
    const int left = group(m, 3, "left"), right = group(m, 3, "right"), wall = group(m, 2, "wall"),
              inlet = group(m, 0, "inlet");
    CHECK(left && right && wall && inlet);
    size_t n_wall = 0, n_inlet = 0, n_left = 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        n_wall += m->physical[c] == wall && m->type[c] == CM_CELL_QUAD4;
        n_inlet += m->physical[c] == inlet && m->type[c] == CM_CELL_POINT;
        n_left += m->physical[c] == left && m->type[c] == CM_CELL_HEX8;
    }
    CHECK(n_wall == 8 && n_inlet == 9 && n_left == 8);
    /* every node moved by one affine map, written back */
    double orig[45 * 3];
    memcpy(orig, m->xyz, sizeof orig);
    for (size_t i = 0; i < m->n_nodes; ++i) affine(orig + 3 * i, m->xyz + 3 * i);
    s = cm_mesh_write(ctx, m, test_at(out), NULL);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    double a[27 * 3], b[27 * 3], want[3];
    for (int Z = 1; Z <= 2; ++Z) {
        zone_coords(test_at(in), Z, a, 27);
        zone_coords(test_at(out), Z, b, 27);
        for (int i = 0; i < 27; ++i) {
            affine(a + 3 * i, want);
            for (int d = 0; d < 3; ++d) {
                /* RealSingle in the right zone: the affine image rounded to float */
                const double w = Z == 2 ? (double)(float)want[d] : want[d];
                CHECK_NEAR(b[3 * i + d], w, 0);
            }
        }
    }
    /* read again: same mesh, moved */
    cm_mesh *r = NULL;
    CHECK(cm_mesh_read(ctx, test_at(out), &r) == CM_OK);
    if (r) CHECK(r->n_nodes == m->n_nodes && r->n_cells == m->n_cells);
    cm_mesh_destroy(&r);
    cm_mesh_destroy(&m);
}

/* ---- NGON_n / NFACE_n: two unit cubes, the shared face once, signs as SIDS gives them ---- */

static void test_polyhedra(cm_context *ctx)
{
    const char *path = test_at("poly.cgns");
    int fn, B, Z, S, C, BC;
    double x[12], y[12], z[12];
    for (int i = 0; i < 12; ++i) {
        x[i] = i % 3;
        y[i] = (i / 3) % 2;
        z[i] = i / 6;
    }
    /* vertex (l, j, k) = 1 + l + 3 j + 6 k */
#define V(l, j, k) (1 + (l) + 3 * (j) + 6 * (k))
    cgsize_t faces[] = {
        V(0, 0, 0), V(0, 1, 0), V(1, 1, 0), V(1, 0, 0), /* 1 bottom of cube A (normal -z) */
        V(1, 0, 0), V(1, 1, 0), V(2, 1, 0), V(2, 0, 0), /* 2 bottom of B */
        V(0, 0, 1), V(1, 0, 1), V(1, 1, 1), V(0, 1, 1), /* 3 top of A (+z) */
        V(1, 0, 1), V(2, 0, 1), V(2, 1, 1), V(1, 1, 1), /* 4 top of B */
        V(0, 0, 0), V(0, 0, 1), V(0, 1, 1), V(0, 1, 0), /* 5 x = 0 (-x) */
        V(1, 0, 0), V(1, 1, 0), V(1, 1, 1), V(1, 0, 1), /* 6 x = 1 (+x: out of A, into B) */
        V(2, 0, 0), V(2, 1, 0), V(2, 1, 1), V(2, 0, 1), /* 7 x = 2 (+x) */
        V(0, 0, 0), V(1, 0, 0), V(1, 0, 1), V(0, 0, 1), /* 8 y = 0 of A (-y) */
        V(1, 0, 0), V(2, 0, 0), V(2, 0, 1), V(1, 0, 1), /* 9 y = 0 of B */
        V(0, 1, 0), V(0, 1, 1), V(1, 1, 1), V(1, 1, 0), /* 10 y = 1 of A (+y) */
        V(1, 1, 0), V(1, 1, 1), V(2, 1, 1), V(2, 1, 0), /* 11 y = 1 of B */
    };
#undef V
    cgsize_t off[12];
    for (int i = 0; i < 12; ++i) off[i] = 4 * i;
    cgsize_t cells[] = {1, 3, 5, 6, 8, 10, 2, 4, -6, 7, 9, 11}, coff[3] = {0, 6, 12};
    CHECK(cg_open(path, CG_MODE_WRITE, &fn) == CG_OK);
    CHECK(cg_base_write(fn, "Base", 3, 3, &B) == CG_OK);
    cgsize_t size[3] = {12, 2, 0};
    CHECK(cg_zone_write(fn, B, "Poly", size, CGNS_ENUMV(Unstructured), &Z) == CG_OK);
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateX", x, &C) == CG_OK);
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateY", y, &C) == CG_OK);
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateZ", z, &C) == CG_OK);
    CHECK(cg_poly_section_write(fn, B, Z, "Faces", CGNS_ENUMV(NGON_n), 1, 11, 0, faces, off, &S) == CG_OK);
    CHECK(cg_poly_section_write(fn, B, Z, "Cells", CGNS_ENUMV(NFACE_n), 12, 13, 0, cells, coff, &S) == CG_OK);
    cgsize_t inlet[1] = {5};
    CHECK(cg_boco_write(fn, B, Z, "inlet", CGNS_ENUMV(BCInflow), CGNS_ENUMV(PointList), 1, inlet, &BC) == CG_OK);
    CHECK(cg_boco_gridlocation_write(fn, B, Z, BC, CGNS_ENUMV(FaceCenter)) == CG_OK);
    CHECK(cg_close(fn) == CG_OK);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (s != CM_OK) return;
    size_t poly = 0, quads = 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        if (m->type[c] == CM_CELL_QUAD4) quads += m->physical[c] == group(m, 2, "inlet");
        if (m->type[c] != CM_CELL_POLYHEDRON) continue;
        ++poly;
        /* outward: each face's normal (Newell) points away from the cell's centroid */
        const int64_t *st = m->conn + m->offset[c];
        double cen[3] = {0, 0, 0};
        int nv = 0;
        for (cm_polyhedron_face f = cm_polyhedron_begin(st, -1); cm_polyhedron_more(&f); cm_polyhedron_next(&f))
            for (int64_t a = 0; a < f.n; ++a, ++nv)
                for (int d = 0; d < 3; ++d) cen[d] += m->xyz[3 * f.nodes[a] + d];
        for (int d = 0; d < 3; ++d) cen[d] /= nv;
        for (cm_polyhedron_face f = cm_polyhedron_begin(st, -1); cm_polyhedron_more(&f); cm_polyhedron_next(&f)) {
            double nrm[3] = {0, 0, 0}, fc[3] = {0, 0, 0};
            for (int64_t a = 0; a < f.n; ++a) {
                const double *p = m->xyz + 3 * f.nodes[a], *q = m->xyz + 3 * f.nodes[(a + 1) % f.n];
                nrm[0] += (p[1] - q[1]) * (p[2] + q[2]);
                nrm[1] += (p[2] - q[2]) * (p[0] + q[0]);
                nrm[2] += (p[0] - q[0]) * (p[1] + q[1]);
                for (int d = 0; d < 3; ++d) fc[d] += p[d] / (double)f.n;
            }
            CHECK((fc[0] - cen[0]) * nrm[0] + (fc[1] - cen[1]) * nrm[1] + (fc[2] - cen[2]) * nrm[2] > 0);
        }
    }
    CHECK(poly == 2 && quads == 1);
    cm_mesh_destroy(&m);
}

/* ---- refusals ---- */

static void expect_error(cm_context *ctx, const char *path, const char *what1, const char *what2)
{
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    const char *msg = cm_context_message(ctx);
    CHECK_MSG(s < 0 && m == NULL, "%s read", path);
    CHECK_MSG(msg && strstr(msg, path) && strstr(msg, what1) && (!what2 || strstr(msg, what2)), "%s: %s", path, msg ? msg : "");
    cm_mesh_destroy(&m);
}

static void test_hostile(cm_context *ctx)
{
    int fn, B, Z, S, C;
    /* a structured zone */
    const char *st = test_at("structured.cgns");
    CHECK(cg_open(st, CG_MODE_WRITE, &fn) == CG_OK);
    CHECK(cg_base_write(fn, "Base", 3, 3, &B) == CG_OK);
    cgsize_t size[9] = {2, 2, 2, 1, 1, 1, 0, 0, 0};
    CHECK(cg_zone_write(fn, B, "Block", size, CGNS_ENUMV(Structured), &Z) == CG_OK);
    double c[8] = {0, 1, 0, 1, 0, 1, 0, 1};
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateX", c, &C) == CG_OK);
    CHECK(cg_close(fn) == CG_OK);
    expect_error(ctx, st, "/Base/Block", "structured zones are not read");
    /* an element's vertex out of range, a BC naming no element */
    const char *bad = test_at("bad_index.cgns");
    CHECK(cg_open(bad, CG_MODE_WRITE, &fn) == CG_OK);
    CHECK(cg_base_write(fn, "Base", 3, 3, &B) == CG_OK);
    cgsize_t usize[3] = {4, 1, 0};
    CHECK(cg_zone_write(fn, B, "Tet", usize, CGNS_ENUMV(Unstructured), &Z) == CG_OK);
    double xs[4] = {0, 1, 0, 0}, ys[4] = {0, 0, 1, 0}, zs[4] = {0, 0, 0, 1};
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateX", xs, &C) == CG_OK);
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateY", ys, &C) == CG_OK);
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateZ", zs, &C) == CG_OK);
    cgsize_t tet[4] = {1, 2, 3, 99};
    CHECK(cg_section_write(fn, B, Z, "Tets", CGNS_ENUMV(TETRA_4), 1, 1, 0, tet, &S) == CG_OK);
    CHECK(cg_close(fn) == CG_OK);
    expect_error(ctx, bad, "/Base/Tet/Tets", "vertex 99 out of range");
    const char *bc = test_at("bad_bc.cgns");
    CHECK(cg_open(bc, CG_MODE_WRITE, &fn) == CG_OK);
    CHECK(cg_base_write(fn, "Base", 3, 3, &B) == CG_OK);
    CHECK(cg_zone_write(fn, B, "Tet", usize, CGNS_ENUMV(Unstructured), &Z) == CG_OK);
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateX", xs, &C) == CG_OK);
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateY", ys, &C) == CG_OK);
    CHECK(cg_coord_write(fn, B, Z, CGNS_ENUMV(RealDouble), "CoordinateZ", zs, &C) == CG_OK);
    tet[3] = 4;
    CHECK(cg_section_write(fn, B, Z, "Tets", CGNS_ENUMV(TETRA_4), 1, 1, 0, tet, &S) == CG_OK);
    cgsize_t range[2] = {5, 7};
    int BC;
    CHECK(cg_boco_write(fn, B, Z, "ghost", CGNS_ENUMV(BCWall), CGNS_ENUMV(PointRange), 2, range, &BC) == CG_OK);
    CHECK(cg_boco_gridlocation_write(fn, B, Z, BC, CGNS_ENUMV(FaceCenter)) == CG_OK);
    cgsize_t pts[2] = {1, 7};
    CHECK(cg_boco_write(fn, B, Z, "far", CGNS_ENUMV(BCWall), CGNS_ENUMV(PointList), 2, pts, &BC) == CG_OK);
    CHECK(cg_close(fn) == CG_OK);
    expect_error(ctx, bc, "/Base/Tet/ZoneBC/ghost", "element 5 is in no section");
    /* not HDF5 or ADF; truncated HDF5 */
    test_write_file(test_at("text.cgns"), "CGNS? no\n", 9);
    expect_error(ctx, test_at("text.cgns"), "not a CGNS file", NULL);
    size_t n = 0;
    char *buf = test_read_file(test_at("types.cgns"), &n);
    for (size_t cut = 8; cut < n; cut = cut * 3 / 2 + 7) {
        test_write_file(test_at("cut.cgns"), buf, cut);
        cm_mesh *m = NULL;
        CHECK(cm_mesh_read(ctx, test_at("cut.cgns"), &m) < 0 && m == NULL);
        cm_mesh_destroy(&m);
    }
    free(buf);
    expect_error(ctx, test_at("missing.cgns"), "missing.cgns", NULL);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    if (test_work_in(argv[2], "cgns") != 0) return 1;
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    test_all_types(ctx);
    test_two_zones(ctx, "zones", CG_FILE_HDF5);
    test_two_zones(ctx, "zones_adf", CG_FILE_ADF);
    test_polyhedra(ctx);
    test_hostile(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
