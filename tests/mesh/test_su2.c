/* SU2 native mesh (.su2) on files written here: what the reader makes of every section
 * (comments, keyword spelling, index columns, "NPOIN= n m", FFD blocks, zones, 2-D files),
 * the write back (only coordinate numbers change; an affine image of every node reads back
 * exactly), new files from a mesh built in memory, and hostile files (file:line messages,
 * no mesh, no crash). Files written by gmsh and meshio: su2_crosscheck.py. */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/mesh.h"
#include "test_files.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static int group_tag(const cm_mesh *m, int dim, const char *name)
{
    for (size_t g = 0; g < m->n_groups; ++g)
        if (m->groups[g].dim == dim && m->groups[g].name && !strcmp(m->groups[g].name, name)) return m->groups[g].tag;
    return -1;
}

/* A hex with a prism on top and a pyramid and a tet beside, as SU2 writes it (tabs, element
 * and point indices, the comments SU2 puts in), with two markers, CRLF lines in places and an
 * FFD box that SU2_DEF appends. */
static const char *mixed =
    "%\r\n% Problem dimension\r\n%\r\nndime =3\r\n"
    "%\n% Inner element connectivity\n%\nNELEM= 4\n"
    "12\t0\t1\t2\t3\t4\t5\t6\t7\t0\n"
    "13\t4\t5\t8\t7\t6\t9\t1\n"
    "14 1 10 11 2 12 2\n"
    "10 1 12 2 5\n"
    "%\n% Node coordinates\n%\nNPOIN= 13 13\n"
    "0.0000000000\t0.0000000000\t0.0000000000\t0\n"
    "1.0\t0.0\t0.0\t1\n"
    "1.0 1.0 0.0 2\n"
    "0 1 0 3\n"
    "0.0 0.0 1.0 4\n"
    "1.0e+00 0.0 1.0 5\n"
    "1.000 1.000 1.000 6\n"
    "0 1 1 7\n"
    "0.5 0.0 2.0 8\n"
    "0.5 1.0 2.0 9\n"
    "2 0 0 10\n"
    "2 1 0 11\n"
    "1.5   0.5   -0.5     12\n"
    "%\n% Boundary elements\n%\nNMARK= 2\n"
    "MARKER_TAG= lower wall\nMARKER_ELEMS= 2\n9 0 3 2 1\n5 1 2 12 \n"
    "MARKER_TAG=top\nMARKER_ELEMS= 1\n5 7 9 6\n"
    "FFD_NBOX= 1\nFFD_NLEVEL= 1\nFFD_TAG= 0\nFFD_LEVEL= 0\nFFD_DEGREE_I= 1\n"
    "FFD_CORNER_POINTS= 2\n0 0 0\n1 1 1\nFFD_CONTROL_POINTS= 0\nFFD_SURFACE_POINTS= 0\n";

static void test_read(cm_context *ctx)
{
    test_write_text(test_at("mixed.su2"), mixed);
    cm_mesh *m = NULL;
    CHECK_MSG(cm_mesh_read(ctx, test_at("mixed.su2"), &m) == CM_OK, "%s", cm_context_message(ctx));
    if (!m) return;
    CHECK(m->n_nodes == 13 && m->n_cells == 7);
    CHECK(m->type[0] == CM_CELL_HEX8 && m->type[1] == CM_CELL_WEDGE6 && m->type[2] == CM_CELL_PYR5 &&
          m->type[3] == CM_CELL_TET4 && m->type[4] == CM_CELL_QUAD4 && m->type[5] == CM_CELL_TRI3 &&
          m->type[6] == CM_CELL_TRI3);
    const int64_t wedge[6] = {4, 5, 8, 7, 6, 9};
    CHECK(!memcmp(m->conn + m->offset[1], wedge, sizeof wedge));
    CHECK(m->xyz[3 * 12] == 1.5 && m->xyz[3 * 12 + 2] == -0.5 && m->xyz[3 * 5] == 1.0);
    /* markers as groups of faces by name (blanks inside kept), the cells without a group */
    const int low = group_tag(m, 2, "lower wall"), top = group_tag(m, 2, "top");
    CHECK(low > 0 && top > 0 && low != top && m->n_groups == 2);
    CHECK(m->physical[0] == 0 && m->physical[3] == 0 && m->physical[4] == low && m->physical[5] == low &&
          m->physical[6] == top);
    cm_mesh_destroy(&m);
}

/* An affine motion of every node, written back: only the coordinate numbers of the point
 * lines differ, the numbers read back as the affine image exactly, and an unmoved mesh is
 * written byte for byte. */
static void test_write_back(cm_context *ctx)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_read(ctx, test_at("mixed.su2"), &m) == CM_OK);
    if (!m) return;
    CHECK(cm_mesh_write(ctx, m, test_at("same.su2"), NULL) == CM_OK);
    char *same = test_read_file(test_at("same.su2"), NULL);
    CHECK(same && !strcmp(same, mixed));
    free(same);

    const double A[3][4] = {{0.9, 0.1, -0.2, 0.3}, {0.05, 1.1, 0.0, -1.0 / 3}, {0.0, -0.3, 1.2, 2.5}};
    double *want = malloc(3 * m->n_nodes * sizeof *want);
    for (size_t i = 0; i < m->n_nodes; ++i) {
        const double *x = m->xyz + 3 * i;
        for (int r = 0; r < 3; ++r) want[3 * i + r] = A[r][0] * x[0] + A[r][1] * x[1] + A[r][2] * x[2] + A[r][3];
    }
    /* node 3 stays where it is: its numbers keep their bytes */
    want[9] = m->xyz[9], want[10] = m->xyz[10], want[11] = m->xyz[11];
    memcpy(m->xyz, want, 3 * m->n_nodes * sizeof *want);
    CHECK_MSG(cm_mesh_write(ctx, m, test_at("moved.su2"), NULL) == CM_OK, "%s", cm_context_message(ctx));
    char *moved = test_read_file(test_at("moved.su2"), NULL);
    /* line by line: a point line keeps its blanks and index, every other line its bytes (no
     * file: no lines, the count check below fails) */
    const char *a = mixed, *b = moved ? moved : "";
    int in_points = 0, points = 0, diff_other = 0;
    while (*a && *b) {
        const char *ae = strchr(a, '\n'), *be = strchr(b, '\n');
        if (!ae || !be) break;
        if (in_points && points < 13) {
            ++points;
            /* same blanks and index; numbers differ */
            char ablank[64] = "", bblank[64] = "";
            size_t na = 0, nb = 0;
            for (const char *p = a; p < ae && na < 63; ++p) if (*p == ' ' || *p == '\t') ablank[na++] = *p;
            for (const char *p = b; p < be && nb < 63; ++p) if (*p == ' ' || *p == '\t') bblank[nb++] = *p;
            CHECK_MSG(!strcmp(ablank, bblank), "point line %d: blanks changed", points);
            const char *ai = ae, *bi = be;
            while (ai > a && ai[-1] != ' ' && ai[-1] != '\t') --ai;
            while (bi > b && bi[-1] != ' ' && bi[-1] != '\t') --bi;
            CHECK(ae - ai == be - bi && !memcmp(ai, bi, (size_t)(ae - ai)));
            if (points == 4) CHECK(ae - a == be - b && !memcmp(a, b, (size_t)(ae - a)));
        } else {
            diff_other += ae - a != be - b || memcmp(a, b, (size_t)(ae - a));
        }
        if (!strncmp(a, "NPOIN", 5)) in_points = 1;
        a = ae + 1;
        b = be + 1;
    }
    CHECK(points == 13 && diff_other == 0 && !*a && !*b);
    free(moved);
    cm_mesh *r = NULL;
    CHECK(cm_mesh_read(ctx, test_at("moved.su2"), &r) == CM_OK);
    if (r) {
        CHECK(!memcmp(r->xyz, want, 3 * r->n_nodes * sizeof *want));
        cm_mesh_destroy(&r);
    }
    /* a mesh with a node more is no longer the file's: a new file, which reads back */
    CHECK(cm_mesh_resize_nodes(ctx, m, m->n_nodes + 1, 0) == CM_OK);
    m->xyz[3 * 13] = 7, m->xyz[3 * 13 + 1] = 8, m->xyz[3 * 13 + 2] = 9;
    CHECK(cm_mesh_write(ctx, m, test_at("grown.su2"), NULL) == CM_OK);
    CHECK(cm_mesh_read(ctx, test_at("grown.su2"), &r) == CM_OK);
    if (r) {
        CHECK(r->n_nodes == 14 && r->n_cells == 7 && !memcmp(r->xyz, m->xyz, 3 * 14 * sizeof(double)));
        CHECK(group_tag(r, 2, "lower_wall") > 0 && group_tag(r, 2, "top") > 0);
        for (size_t c = 0; c < r->n_cells; ++c)
            CHECK(r->type[c] == m->type[c] && r->offset[c + 1] == m->offset[c + 1] &&
                  !memcmp(r->conn + r->offset[c], m->conn + m->offset[c], (size_t)(r->offset[c + 1] - r->offset[c]) * 8));
        cm_mesh_destroy(&r);
    }
    free(want);
    cm_mesh_destroy(&m);
}

/* NDIME= 2: a mesh at z = 0, two numbers a point written back; leaving the plane is refused. */
static void test_2d(cm_context *ctx)
{
    const char *text = "NDIME= 2\nNELEM= 2\n5 0 1 2 0\n9 1 3 4 2 1\nNPOIN= 5\n0 0 0\n1 0 1\n0 1 2\n2 0 3\n2 1 4\n"
                       "NMARK= 1\nMARKER_TAG= farfield\nMARKER_ELEMS= 2\n3 0 1\n3 2 0\n";
    test_write_text(test_at("flat.su2"), text);
    cm_mesh *m = NULL;
    CHECK_MSG(cm_mesh_read(ctx, test_at("flat.su2"), &m) == CM_OK, "%s", cm_context_message(ctx));
    if (!m) return;
    CHECK(m->n_nodes == 5 && m->n_cells == 4 && m->type[1] == CM_CELL_QUAD4 && m->type[2] == CM_CELL_LINE2);
    CHECK(group_tag(m, 1, "farfield") > 0 && m->xyz[3 * 3] == 2 && m->xyz[3 * 3 + 2] == 0);
    m->xyz[3 * 4 + 1] = 1.25;
    CHECK(cm_mesh_write(ctx, m, test_at("flat_moved.su2"), NULL) == CM_OK);
    char *flat = test_read_file(test_at("flat_moved.su2"), NULL);
    CHECK(flat && strstr(flat, "\n2 1.25 4\nNMARK") != NULL);
    free(flat);
    m->xyz[3 * 4 + 2] = 0.5;
    CHECK(cm_mesh_write(ctx, m, test_at("flat_z.su2"), NULL) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "NDIME= 2") != NULL && access(test_at("flat_z.su2"), F_OK) != 0);
    cm_mesh_destroy(&m);
}

/* Two zones: one mesh, the second zone's indices after the first's points, a group per zone,
 * one group for a marker name both zones have. */
static void test_zones(cm_context *ctx)
{
    const char *zone = "NDIME= 3\nNELEM= 1\n10 0 1 2 3\nNPOIN= 4\n0 0 0\n1 0 0\n0 1 0\n0 0 %d\n"
                       "NMARK= 1\nMARKER_TAG= interface\nMARKER_ELEMS= 1\n5 0 1 2\n";
    char text[1024], z1[256], z2[256];
    snprintf(z1, sizeof z1, zone, 1);
    snprintf(z2, sizeof z2, zone, 2);
    snprintf(text, sizeof text, "NZONE= 2\n\nIZONE= 1\n%s\nIZONE= 2\n%s", z1, z2);
    test_write_text(test_at("zones.su2"), text);
    cm_mesh *m = NULL;
    CHECK_MSG(cm_mesh_read(ctx, test_at("zones.su2"), &m) == CM_OK, "%s", cm_context_message(ctx));
    if (!m) return;
    CHECK(m->n_nodes == 8 && m->n_cells == 4 && m->conn[m->offset[2] + 3] == 7 && m->xyz[3 * 7 + 2] == 2);
    const int a = group_tag(m, 3, "zone_1"), b = group_tag(m, 3, "zone_2"), i = group_tag(m, 2, "interface");
    CHECK(a > 0 && b > 0 && i > 0 && m->physical[0] == a && m->physical[2] == b && m->physical[1] == i &&
          m->physical[3] == i);
    m->xyz[3 * 7 + 2] = 3;
    CHECK(cm_mesh_write(ctx, m, test_at("zones_moved.su2"), NULL) == CM_OK);
    snprintf(z2, sizeof z2, zone, 3);
    snprintf(text, sizeof text, "NZONE= 2\n\nIZONE= 1\n%s\nIZONE= 2\n%s", z1, z2);
    char *moved = test_read_file(test_at("zones_moved.su2"), NULL);
    CHECK(moved && !strcmp(moved, text));
    free(moved);
    cm_mesh_destroy(&m);
}

/* A new file from a mesh built here: quadratic cells refused, no boundary cells -> the
 * boundary as one marker (with a warning). */
static void test_new(cm_context *ctx)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, 5, 0) == CM_OK);
    const double xyz[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    memcpy(m->xyz, xyz, sizeof xyz);
    const int64_t t0[4] = {0, 1, 2, 3}, t1[4] = {1, 2, 3, 4}, p[1] = {4};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, t0, 4, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, t1, 4, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POINT, p, 1, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_write(ctx, m, test_at("new.su2"), NULL) == CM_WARNING);
    CHECK(strstr(cm_context_message(ctx), "6 boundary faces are the marker 'boundary'; 1 cells") != NULL);
    cm_mesh *r = NULL;
    CHECK_MSG(cm_mesh_read(ctx, test_at("new.su2"), &r) == CM_OK, "%s", cm_context_message(ctx));
    if (r) {
        CHECK(r->n_nodes == 5 && r->n_cells == 8 && cm_mesh_count_dim(r, 2) == 6 && group_tag(r, 2, "boundary") > 0);
        CHECK(!memcmp(r->xyz, xyz, sizeof xyz));
        cm_mesh_destroy(&r);
    }
    const int64_t q[10] = {0, 1, 2, 3, 0, 1, 2, 3, 0, 1};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET10, q, 10, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_write(ctx, m, test_at("quadratic.su2"), NULL) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "tet10") != NULL && access(test_at("quadratic.su2"), F_OK) != 0);
    cm_mesh_destroy(&m);
}

/* Hostile files: refused with "cm_mesh_read: FILE:LINE: expected ...", no mesh. */
static void test_hostile(cm_context *ctx)
{
    static const struct { const char *name, *text; int line; const char *what; } cases[] = {
        {"truncated_points", "NDIME= 3\nNELEM= 1\n10 0 1 2 3 0\nNPOIN= 4\n0 0 0 0\n1 0 0 1\n0 1 0 2\n", 8, "point 3 of the 4"},
        {"truncated_count", "NDIME= 3\nNELEM= 1\n10 0 1 2 3 0\nNPOIN= 4\n0 0 0 0\n", 4, "at most 2 points"},
        {"truncated_line", "NDIME= 3\nNELEM= 1\n10 0 1 2 3 0\nNPOIN= 2\n0 0 0 0\n1 0", 6, "coordinate z of point 1"},
        {"truncated_cells", "NDIME= 3\nNELEM= 2\n10 0 1 2 3 0\n", 4, "element 1 of the 2"},
        {"huge_count", "NDIME= 3\nNELEM= 9223372036854775807\n10 0 1 2 3\n", 2, "at most"},
        {"overflow", "NDIME= 3\nNELEM= 99999999999999999999\n", 2, "a count after NELEM="},
        {"negative", "NDIME= 3\nNPOIN= -4\n", 2, "a count after NPOIN="},
        {"range", "NDIME= 3\nNELEM= 1\n10 0 1 2 4 0\nNPOIN= 4\n0 0 0 0\n1 0 0 1\n0 1 0 2\n0 0 1 3\n", 3,
         "point indices below 4"},
        {"negative_index", "NDIME= 3\nNELEM= 1\n10 0 1 -2 3 0\n", 3, "node 2 of a tet4"},
        {"nan", "NDIME= 3\nNELEM= 1\n10 0 1 2 3 0\nNPOIN= 4\n0 0 0 0\n1 0 0 1\n0 nan 0 2\n0 0 1 3\n", 7, "coordinate y"},
        {"inf", "NDIME= 3\nNELEM= 1\n10 0 1 2 3 0\nNPOIN= 4\n0 0 0 0\n1 0 1e999 1\n0 1 0 2\n0 0 1 3\n", 6, "coordinate z"},
        {"type", "NDIME= 3\nNELEM= 1\n11 0 1 2 3 0\n", 3, "an element type"},
        {"surface_in_volume", "NDIME= 3\nNELEM= 1\n5 0 1 2\n", 3, "a zone element"},
        {"extra_columns", "NDIME= 3\nNELEM= 1\n10 0 1 2 3 0 7\n", 3, "the end of the element line"},
        {"dimension", "NDIME= 4\n", 1, "NDIME= 2 or 3"},
        {"no_ndime", "NPOIN= 1\n0 0 0\n", 1, "NDIME= before NPOIN="},
        {"twice", "NDIME= 3\nNPOIN= 0\nNPOIN= 0\n", 3, "one NPOIN= per zone"},
        {"garbage", "NDIME= 3\n1 2 3\n", 2, "a keyword"},
        {"missing_marker", "NDIME= 3\nNELEM= 0\nNPOIN= 0\nNMARK= 2\nMARKER_TAG= a\nMARKER_ELEMS= 0\n", 7,
         "MARKER_TAG= of marker 1 of the 2"},
        {"marker_name", "NDIME= 3\nNMARK= 1\nMARKER_TAG=\nMARKER_ELEMS= 0\n", 3, "a marker name"},
        {"marker_volume", "NDIME= 3\nNMARK= 1\nMARKER_TAG= a\nMARKER_ELEMS= 1\n10 0 1 2 3\n", 5, "a marker element"},
        {"stray_marker", "NDIME= 3\nMARKER_TAG= a\n", 2, "only among the markers"},
        {"no_points", "NDIME= 3\nNELEM= 0\n", 3, "NPOIN= in zone 1"},
        {"zones", "NZONE= 2\nIZONE= 1\nNDIME= 3\nNELEM= 0\nNPOIN= 0\n", 6, "the 2 zones of NZONE="},
        {"zone_order", "NZONE= 2\nIZONE= 2\nNDIME= 3\n", 2, "IZONE= 1"},
        {"empty", "", 1, "NDIME="},
        {"binary", "NDIME= 3\nNELEM= 1\n10 0 1\0012 3\n", 3, "node 1 of a tet4"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
        char name[64], want[256];
        snprintf(name, sizeof name, "bad_%s.su2", cases[i].name);
        test_write_text(test_at(name), cases[i].text);
        cm_mesh *m = (cm_mesh *)1;
        const cm_status s = cm_mesh_read(ctx, test_at(name), &m);
        const char *msg = cm_context_message(ctx);
        snprintf(want, sizeof want, "cm_mesh_read: %s:%d: expected ", test_at(name), cases[i].line);
        CHECK_MSG(s == CM_ERR_FORMAT && m == NULL, "%s: status %d", cases[i].name, (int)s);
        CHECK_MSG(!strncmp(msg, want, strlen(want)) && strstr(msg, cases[i].what) && !strchr(msg, '\n'), "%s: %s",
                  cases[i].name, msg);
    }
}

int main(int argc, char **argv)
{
    if (test_work_in(argc > 2 ? argv[2] : "/tmp", "su2") != 0) return 1;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_read(ctx);
    test_write_back(ctx);
    test_2d(ctx);
    test_zones(ctx);
    test_new(ctx);
    test_hostile(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
