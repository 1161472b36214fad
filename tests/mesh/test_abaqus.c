/* Abaqus input decks (mesh/io/abaqus_*.c) on decks written here: every element type in
 * Abaqus's node order read into VTK's (positive volumes, mid-side nodes at the middle of
 * their VTK edge), keywords and parameters in any case, comments, continuation lines,
 * *INCLUDE, sets and surfaces as groups, parts placed by instances; writing back changes only
 * the numbers of *NODE lines; a new deck read back; hostile decks refused with file:line. */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/mesh.h"
#include "test_files.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static cm_context *ctx;

static cm_mesh *read_ok(const char *name)
{
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, test_at(name), &m);
    CHECK_MSG(s == CM_OK && m, "%s: %s", name, cm_context_message(ctx));
    return m;
}

static int group_tag(const cm_mesh *m, const char *name, int *dim)
{
    for (size_t g = 0; g < m->n_groups; ++g)
        if (!strcmp(m->groups[g].name, name)) {
            if (dim) *dim = m->groups[g].dim;
            return m->groups[g].tag;
        }
    return -1;
}

static size_t count_tag(const cm_mesh *m, int tag, cm_cell_type type)
{
    size_t n = 0;
    for (size_t c = 0; c < m->n_cells; ++c) n += m->physical[c] == tag && m->type[c] == type;
    return n;
}

/* ---- every type: Abaqus's corner order, mid-side nodes from Abaqus's edge list ---- */

typedef struct type_case {
    const char *name;
    int corners, nodes;
    double x[8][3];
    int edges[12][2]; /* Abaqus mid-side node k+corners sits on corners (a, b), 1-based */
    cm_cell_type type;
    int vtk_edges[12][2]; /* VTK's: mid-side node corners+k between VTK corners (a, b) */
} type_case;

static const type_case cases[] = {
    {"C3D4", 4, 4, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0}}, CM_CELL_TET4, {{0}}},
    {"c3d10m", 4, 10, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
     {{1, 2}, {2, 3}, {3, 1}, {1, 4}, {2, 4}, {3, 4}}, CM_CELL_TET10,
     {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}},
    {"C3D5", 5, 5, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1}}, {{0}}, CM_CELL_PYR5, {{0}}},
    {"C3D6", 6, 6, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}}, {{0}}, CM_CELL_WEDGE6, {{0}}},
    {"C3D15", 6, 15, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}},
     {{1, 2}, {2, 3}, {3, 1}, {4, 5}, {5, 6}, {6, 4}, {1, 4}, {2, 5}, {3, 6}}, CM_CELL_WEDGE15,
     {{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}}},
    {"C3D8R", 8, 8, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}}, {{0}},
     CM_CELL_HEX8, {{0}}},
    {"C3D20R", 8, 20, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
     {{1, 2}, {2, 3}, {3, 4}, {4, 1}, {5, 6}, {6, 7}, {7, 8}, {8, 5}, {1, 5}, {2, 6}, {3, 7}, {4, 8}}, CM_CELL_HEX20,
     {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}},
};

static void test_types(void)
{
    for (size_t t = 0; t < sizeof cases / sizeof *cases; ++t) {
        const type_case *tc = &cases[t];
        char deck[4096];
        size_t n = (size_t)snprintf(deck, sizeof deck, "** one %s\n*Node\n", tc->name);
        double x[20][3];
        for (int i = 0; i < tc->nodes; ++i) {
            for (int k = 0; k < 3; ++k)
                x[i][k] = i < tc->corners ? tc->x[i][k]
                                          : 0.5 * (tc->x[tc->edges[i - tc->corners][0] - 1][k] + tc->x[tc->edges[i - tc->corners][1] - 1][k]);
            /* ids far apart and out of order: mapped, never indexed */
            n += (size_t)snprintf(deck + n, sizeof deck - n, "%lld, %g, %g, %g\n", 1000000000000LL - 7 * i, x[i][0], x[i][1], x[i][2]);
        }
        n += (size_t)snprintf(deck + n, sizeof deck - n, "*element, type=%s, elset=E\n 5", tc->name);
        for (int i = 0; i < tc->nodes; ++i)
            n += (size_t)snprintf(deck + n, sizeof deck - n, "%s%lld", i == 12 ? ",\n " : ", ", 1000000000000LL - 7 * i);
        snprintf(deck + n, sizeof deck - n, "\n");
        test_write_text(test_at("type.inp"), deck);
        cm_mesh *m = read_ok("type.inp");
        if (!m) continue;
        CHECK_MSG(m->n_cells == 1 && m->type[0] == tc->type, "%s", tc->name);
        double sj = 0;
        CHECK(cm_mesh_quality(ctx, m, &sj) == CM_OK);
        CHECK_MSG(sj > 0.1, "%s: scaled Jacobian %g (not in VTK's order?)", tc->name, sj);
        const int64_t *v = m->conn;
        for (int e = 0; e < tc->nodes - tc->corners; ++e)
            for (int k = 0; k < 3; ++k) {
                const double mid = 0.5 * (m->xyz[3 * v[tc->vtk_edges[e][0]] + k] + m->xyz[3 * v[tc->vtk_edges[e][1]] + k]);
                CHECK_MSG(m->xyz[3 * v[tc->corners + e] + k] == mid, "%s: mid-side node %d", tc->name, e);
            }
        CHECK(m->node_tag && m->node_tag[0] == 1000000000000LL);
        CHECK(m->cell_tag && m->cell_tag[0] == 5);
        cm_mesh_destroy(&m);
    }
}

/* ---- keywords, includes, sets, surfaces ---- */

static void test_features(void)
{
    mkdir(test_at("sub"), 0777);
    test_write_text(test_at("sub/nodes.inp"),
                    "** nodes only: they continue the *NODE block of the includer\n"
                    "3, 0., 1., 0.\n4, 0., 0., 1.\n*include, input=more.inp\n");
    test_write_text(test_at("sub/more.inp"), "5, 1.0, 1.0, 1.0\n");
    test_write_text(test_at("feat.inp"),
        "*HEADING\n a deck *with* words\n**\n"
        "*NODE, NSET=NALL\n"
        "1, 0.0, 0.0, 0.0\n"
        "  2 ,  1.0 ,0,\n" /* a blank field and a missing z: 0 */
        "*Include,\n  Input=sub/nodes.inp\n"
        "\n"
        "*Element, Type=C3D4, ELSET=EALL\n1, 1, 2, 3, 4\n2, 2, 3, 4,\n 5\n"
        "*ELEMENT,TYPE=S3R,ELSET=SKIN\n10, 1, 3, 2\n"
        "*ELEMENT, TYPE=MASS, ELSET=M\n20, 5\n"
        "*Nset, nset=TOP, generate\n 4, 5, 1\n"
        "*NSET,NSET=CORNER\n1\n"
        "*nset, nset=BOTH\n top, corner\n"
        "*ELSET, ELSET=ONE\n2\n"
        "*Surface, type=ELEMENT, name=BASE\n EALL, S1\n 10, SPOS\n"
        "*SURFACE, NAME=PTS, TYPE=NODE\n CORNER\n"
        "*MATERIAL, NAME=STEEL\n*ELASTIC\n 210000, 0.3\n*STEP\n*STATIC\n*END STEP\n");
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, test_at("feat.inp"), &m);
    /* the MASS element is skipped with a warning naming it */
    CHECK_MSG(s == CM_WARNING && m && strstr(cm_context_message(ctx), "MASS"), "%d %s", s, cm_context_message(ctx));
    if (!m) return;
    CHECK(m->n_nodes == 5);
    CHECK(m->xyz[3] == 1.0 && m->xyz[4] == 0.0 && m->xyz[5] == 0.0);
    CHECK(m->xyz[12] == 1.0 && m->xyz[13] == 1.0);
    int dim = -1;
    const int eall = group_tag(m, "EALL", &dim), one = group_tag(m, "ONE", NULL), top = group_tag(m, "TOP", NULL);
    CHECK(eall > 0 && dim == 3 && one > 0 && top > 0);
    /* element 2 is in EALL and ONE: the smaller set's tag */
    CHECK(m->physical[0] == eall && m->physical[1] == one);
    CHECK(count_tag(m, top, CM_CELL_POINT) == 2);
    CHECK(count_tag(m, group_tag(m, "BOTH", &dim), CM_CELL_POINT) == 3 && dim == 0);
    CHECK(count_tag(m, group_tag(m, "NALL", NULL), CM_CELL_POINT) == 5);
    CHECK(count_tag(m, group_tag(m, "PTS", NULL), CM_CELL_POINT) == 1);
    /* the surface: face S1 of both tets (outward: opposite node 4's side), the shell's own side */
    const int base = group_tag(m, "BASE", &dim);
    CHECK(dim == 2 && count_tag(m, base, CM_CELL_TRI3) == 3);
    int found_s1 = 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        const int64_t *v = m->conn + m->offset[c];
        if (m->physical[c] == base && m->type[c] == CM_CELL_TRI3) {
            const double *a = m->xyz + 3 * v[0], *b = m->xyz + 3 * v[1], *d = m->xyz + 3 * v[2];
            const double nz = (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]);
            if (a[2] == 0 && b[2] == 0 && d[2] == 0 && v[0] == 0) found_s1 += nz < 0;
        }
    }
    /* S1 of element 1 (nodes 1, 2, 3 at z = 0) and the shell's side 1-3-2: both face -z */
    CHECK_MSG(found_s1 == 2, "outward faces at z = 0: %d", found_s1);
    cm_mesh_destroy(&m);
}

/* ---- parts and instances ---- */

static const char *parts_deck =
    "*Part, name=Brick\n*Node\n 1, 0., 0., 0.\n 2, 1., 0., 0.\n 3, 0., 1., 0.\n 4, 0., 0., 1.\n"
    "*Element, type=C3D4\n 1, 1, 2, 3, 4\n*Nset, nset=Tip\n 4\n*Elset, elset=All\n 1\n*End Part\n"
    "*Part, name=Unused\n*Node\n 1, 9., 9., 9.\n*End Part\n"
    "*Assembly, name=A\n"
    "*Instance, name=B-1, part=Brick\n*End Instance\n"
    "*Instance, name=B-2, part=Brick\n 10., 0., 0.\n 0., 0., 0., 0., 0., 1., 90.\n*End Instance\n"
    "*Nset, nset=Ends, instance=B-2\n 1, 2\n"
    "*Nset, nset=Tips\n B-1.Tip, B-2.Tip\n"
    "*End Assembly\n";

static void test_parts(void)
{
    mkdir(test_at("parts_out"), 0777);
    test_write_text(test_at("parts.inp"), parts_deck);
    cm_mesh *m = read_ok("parts.inp");
    if (!m) return;
    CHECK(m->n_nodes == 8 && cm_mesh_count_dim(m, 3) == 2);
    /* B-2: translated by (10, 0, 0), then turned 90 degrees about z: (x, y) -> (-y, x) */
    const double *p = m->xyz + 3 * 5; /* B-2's node 2 = (1, 0, 0) -> (11, 0, 0) -> (0, 11, 0) */
    CHECK_NEAR(p[0], 0, 1e-12);
    CHECK_NEAR(p[1], 11, 1e-12);
    CHECK(group_tag(m, "B-1.Tip", NULL) > 0 && group_tag(m, "B-2.All", NULL) > 0);
    CHECK(count_tag(m, group_tag(m, "Ends", NULL), CM_CELL_POINT) == 2);
    CHECK(count_tag(m, group_tag(m, "Tips", NULL), CM_CELL_POINT) == 2);
    CHECK(m->node_tag == NULL); /* ids repeat between instances */
    /* moved alike in the part's frame: written back; the part's node lines hold the motion */
    double *x1 = m->xyz + 3 * 3, *x2 = m->xyz + 3 * 7; /* node 4 of each instance: (0,0,1) */
    x1[2] += 0.5;
    x2[2] += 0.5; /* the axis is z: z is the part's z in both */
    CHECK_MSG(cm_mesh_write(ctx, m, test_at("parts_out/parts.inp"), NULL) == CM_OK, "%s", cm_context_message(ctx));
    char *out = test_read_file(test_at("parts_out/parts.inp"), NULL);
    CHECK(out && strstr(out, " 4, 0., 0., 1.5\n") && strstr(out, "*Part, name=Unused\n*Node\n 1, 9., 9., 9.\n"));
    free(out);
    /* one instance only moved: refused, naming both */
    x2[0] += 0.25;
    CHECK(cm_mesh_write(ctx, m, test_at("parts_out/bad.inp"), NULL) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "B-1") && strstr(cm_context_message(ctx), "B-2"));
    CHECK(access(test_at("parts_out/bad.inp"), F_OK) != 0);
    cm_mesh_destroy(&m);
}

/* ---- writing back ---- */

static void test_write_back(void)
{
    mkdir(test_at("wb_in"), 0777);
    mkdir(test_at("wb_out"), 0777);
    test_write_text(test_at("wb_in/inc.inp"), "5,\t1.5E+00 , 2.5D0,3.5 , 7, 8\n");
    test_write_text(test_at("wb_in/deck.inp"),
        "** deck\r\n*NODE\r\n1,0.1,0.2,0.3\r\n2, 1.000, 0.0, 0.0\r\n3, 0, 1\r\n4,0,0,1\r\n"
        "*INCLUDE, INPUT=inc.inp\r\n*ELEMENT, TYPE=C3D4\r\n1, 1, 2, 3, 4\r\n2, 2, 3, 4, 5\r\n");
    cm_mesh *m = read_ok("wb_in/deck.inp");
    if (!m) return;
    CHECK(m->xyz[12 + 1] == 2.5);
    /* unchanged: every byte the same */
    CHECK(cm_mesh_write(ctx, m, test_at("wb_out/same.inp"), NULL) == CM_OK);
    char *a = test_read_file(test_at("wb_in/deck.inp"), NULL);
    char *b = test_read_file(test_at("wb_out/same.inp"), NULL);
    CHECK(a && b && !strcmp(a, b));
    free(b);
    b = test_read_file(test_at("wb_out/inc.inp"), NULL);
    CHECK_MSG(b && !strcmp(b, "5,\t1.5E+00 , 2.5D0,3.5 , 7, 8\n"), "%s", b ? b : "(none)");
    free(b);
    /* written beside the source, the include would overwrite its own source: refused */
    CHECK(cm_mesh_write(ctx, m, test_at("wb_in/other.inp"), NULL) == CM_ERR_ARGUMENT);
    /* an affine motion of every node: the affine image, separators and ids byte for byte */
    const double A[9] = {1.25, 0.5, 0, 0, 2, 0, 0.125, 0, 1}, t[3] = {0.1, -3, 1e-3};
    double want[15];
    for (size_t i = 0; i < m->n_nodes; ++i) {
        double *x = m->xyz + 3 * i;
        for (int k = 0; k < 3; ++k) want[3 * i + k] = A[3 * k] * x[0] + A[3 * k + 1] * x[1] + A[3 * k + 2] * x[2] + t[k];
    }
    memcpy(m->xyz, want, sizeof want);
    m->xyz[3 * 3] = 0.0; /* node 4's x stays 0: its bytes stay */
    want[9] = 0.0;
    CHECK_MSG(cm_mesh_write(ctx, m, test_at("wb_out/deck.inp"), NULL) == CM_OK, "%s", cm_context_message(ctx));
    b = test_read_file(test_at("wb_out/deck.inp"), NULL);
    char *inc = test_read_file(test_at("wb_out/inc.inp"), NULL);
    CHECK(b && inc);
    if (b && inc) {
        CHECK_MSG(strstr(b, "\r\n4,0,") != NULL, "%s", b);
        CHECK(strstr(b, "*INCLUDE, INPUT=inc.inp\r\n*ELEMENT, TYPE=C3D4\r\n1, 1, 2, 3, 4\r\n2, 2, 3, 4, 5\r\n"));
        CHECK(!strncmp(b, "** deck\r\n*NODE\r\n1,", 18));
        /* node 3 had no z: it is appended (its z became 1e-3) */
        CHECK_MSG(strstr(b, "\r\n3, ") && strstr(strstr(b, "\r\n3, "), ", 0.001\r\n"), "%s", b);
        CHECK_MSG(!strncmp(inc, "5,\t", 3) && strstr(inc, " , ") && strstr(inc, ", 7, 8\n"), "%s", inc);
    }
    free(b);
    free(inc);
    cm_mesh *back = read_ok("wb_out/deck.inp");
    for (size_t i = 0; back && i < 15; ++i) CHECK_MSG(back->xyz[i] == want[i], "%zu: %.17g vs %.17g", i, back->xyz[i], want[i]);
    cm_mesh_destroy(&back);
    /* a file with nodes included into two parts: refused (each copy could move differently) */
    test_write_text(test_at("wb_in/twice.inp"),
                    "*PART, NAME=A\n*INCLUDE, INPUT=inc.inp\n*END PART\n*PART, NAME=B\n*INCLUDE, INPUT=inc.inp\n"
                    "*END PART\n*ASSEMBLY\n*INSTANCE, NAME=A1, PART=A\n*END INSTANCE\n"
                    "*INSTANCE, NAME=B1, PART=B\n*END INSTANCE\n*END ASSEMBLY\n");
    test_write_text(test_at("wb_in/inc.inp"), "*NODE\n5,\t1.5E+00 , 2.5D0,3.5 , 7, 8\n");
    cm_mesh *twice = read_ok("wb_in/twice.inp");
    if (twice) {
        CHECK(twice->n_nodes == 2);
        CHECK(cm_mesh_write(ctx, twice, test_at("wb_out/twice.inp"), NULL) == CM_ERR_UNSUPPORTED);
        CHECK_MSG(strstr(cm_context_message(ctx), "included more than once"), "%s", cm_context_message(ctx));
    }
    cm_mesh_destroy(&twice);
    /* the source changed since it was read: refused */
    test_write_text(test_at("wb_in/deck.inp"), "*NODE\n1, 0, 0, 0\n");
    CHECK(cm_mesh_write(ctx, m, test_at("wb_out/late.inp"), NULL) == CM_ERR_IO);
    free(a);
    cm_mesh_destroy(&m);
}

/* ---- a new deck ---- */

static void test_new_deck(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    const double x[7][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {0, 0, -1}};
    CHECK(cm_mesh_resize_nodes(ctx, m, 7, 0) == CM_OK);
    memcpy(m->xyz, x, sizeof x);
    const int64_t wedge[6] = {0, 2, 1, 3, 5, 4}, tet[4] = {0, 2, 1, 6}, tri[3] = {3, 4, 5}, pt = 6;
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_WEDGE6, wedge, 6, 1, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet, 4, 1, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, tri, 3, 2, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POINT, &pt, 1, 3, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_group(ctx, m, 3, 1, "solid part") == CM_OK);
    CHECK(cm_mesh_add_group(ctx, m, 2, 2, "top") == CM_OK);
    CHECK(cm_mesh_add_group(ctx, m, 0, 3, "tip") == CM_OK);
    double sj[4];
    CHECK(cm_mesh_quality(ctx, m, sj) == CM_OK && sj[0] > 0 && sj[1] > 0);
    CHECK_MSG(cm_mesh_write(ctx, m, test_at("new.inp"), NULL) == CM_OK, "%s", cm_context_message(ctx));
    char *text = test_read_file(test_at("new.inp"), NULL);
    /* Abaqus's wedge order: corners 2<->3 and 5<->6 of VTK's */
    CHECK(text && strstr(text, "*ELEMENT, TYPE=C3D6, ELSET=solid_part\n2, 1, 2, 3, 4, 5, 6\n"));
    free(text);
    cm_mesh *b = read_ok("new.inp");
    if (b) {
        CHECK(b->n_nodes == 7 && cm_mesh_count_dim(b, 3) == 2 && cm_mesh_count_dim(b, 2) == 1);
        double sb[8];
        CHECK(cm_mesh_quality(ctx, b, sb) == CM_OK);
        for (size_t c = 0; c < b->n_cells; ++c)
            if (b->type[c] == CM_CELL_WEDGE6) CHECK(!memcmp(b->conn + b->offset[c], wedge, sizeof wedge) && sb[c] > 0);
        CHECK(count_tag(b, group_tag(b, "tip", NULL), CM_CELL_POINT) == 1);
        CHECK(count_tag(b, group_tag(b, "top", NULL), CM_CELL_TRI3) == 1);
        CHECK(memcmp(b->xyz, x, sizeof x) == 0);
    }
    cm_mesh_destroy(&b);
    /* a type a deck has no element for */
    const int64_t poly[4] = {0, 1, 2, 3};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POLYGON, poly, 4, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_write(ctx, m, test_at("poly.inp"), NULL) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "polygon") != NULL);
    cm_mesh_destroy(&m);
}

/* ---- hostile decks ---- */

typedef struct bad_case {
    const char *text, *message;
} bad_case;

static void test_hostile(void)
{
    test_write_text(test_at("self.inp"), "*NODE\n1, 0, 0, 0\n*INCLUDE, INPUT=self.inp\n");
    test_write_text(test_at("loop_a.inp"), "*INCLUDE, INPUT=loop_b.inp\n");
    test_write_text(test_at("loop_b.inp"), "** b\n*INCLUDE, INPUT=loop_a.inp\n");
    const bad_case bad[] = {
        {"*NODE\n1, 0, 0, 0\n*INCLUDE, INPUT=self.inp\n", "self.inp:3: the included file"},
        {"*INCLUDE, INPUT=loop_a.inp\n", "loop_b.inp:2: the included file"},
        {"*NODE\n*INCLUDE, INPUT=missing.inp\n", "bad.inp:2: cannot open the included file"},
        {"*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D10\n1, 1, 2, 3, 4,", "bad.inp:7: expected 10 nodes for element 1"},
        {"*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4, 5\n", "bad.inp:4: expected 4 nodes for element 1 of type C3D4, got more"},
        {"*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=C3D4\n1, 1, 1, 1, 9\n", "element 1 of the model: node 9 is not defined"},
        {"*NODE\n1, 0, nan, 0\n", "bad.inp:2: expected a finite coordinate of node 1"},
        {"*NODE\n1, 0, 1e999, 0\n", "bad.inp:2: expected a finite coordinate"},
        {"*NODE\n99999999999999999999, 0, 0, 0\n", "bad.inp:2: expected a node id"},
        {"*NODE\n-3, 0, 0, 0\n", "bad.inp:2: expected a node id >= 1"},
        {"*NODE\n1, 0, 0, 0\n1, 1, 0, 0\n", "node 1 of the model is defined twice"},
        {"*NODE\n1, 0, 0, 0\n*NSET, NSET=A, GENERATE\n1, 9000000000000000000\n", "bad.inp:4: expected a GENERATE range"},
        {"*NODE\n1, 0, 0, 0\n*NSET, NSET=A\n1, 2\n", "*NSET A: node 2 is not defined"},
        {"*NODE\n1, 0, 0, 0\n*NSET, NSET=A\n1, B\n", "bad.inp:4: expected a node id or the name of a set"},
        {"*ELEMENT\n1, 1\n", "bad.inp:1: expected TYPE="},
        {"** nothing\n", "no *NODE data"},
        {"*PART, NAME=P\n*NODE\n1, 0, 0, 0\n", "expected *END PART"},
        {"*ASSEMBLY\n*INSTANCE, NAME=I, PART=NOPE\n*END INSTANCE\n*END ASSEMBLY\n", "bad.inp:2: expected NAME= and PART="},
        {"*NODE, SYSTEM=C\n1, 1, 0, 0\n", "bad.inp:1: *NODE, SYSTEM=C is not supported"},
        {"*ASSEMBLY\n*NODE\n1, 0, 0, 0\n*END ASSEMBLY\n*PART, NAME=P\n", "bad.inp:5: expected every *PART before *ASSEMBLY"},
        {"*NODE\n1, 0, 0, 0\n*SURFACE, NAME=S\nNOSET, S1\n", "bad.inp:4: expected an element id or the name"},
        {"*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4, ELSET=E\n1, 1, 2, 3, 4\n*SURFACE, NAME=S\nE, S5\n",
         "*SURFACE S: element 1 (tet4) has no face S5"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; ++i) {
        test_write_text(test_at("bad.inp"), bad[i].text);
        cm_mesh *m = NULL;
        cm_status s = cm_mesh_read(ctx, test_at("bad.inp"), &m);
        CHECK_MSG(s < 0 && !m && strstr(cm_context_message(ctx), bad[i].message) &&
                      !strncmp(cm_context_message(ctx), "cm_mesh_read: ", 14),
                  "case %zu: %d '%s' (expected '%s')", i, s, cm_context_message(ctx), bad[i].message);
        cm_mesh_destroy(&m);
    }
    /* includes nested deeper than the limit */
    for (int d = 0; d < 20; ++d) {
        char name[32], text[64];
        snprintf(name, sizeof name, "deep%d.inp", d);
        snprintf(text, sizeof text, "*INCLUDE, INPUT=deep%d.inp\n", d + 1);
        test_write_text(test_at(name), text);
    }
    test_write_text(test_at("deep20.inp"), "*NODE\n1, 0, 0, 0\n");
    cm_mesh *m = NULL;
    CHECK(cm_mesh_read(ctx, test_at("deep0.inp"), &m) == CM_ERR_FORMAT && !m);
    CHECK_MSG(strstr(cm_context_message(ctx), "nested at most 16 deep"), "%s", cm_context_message(ctx));
}

int main(int argc, char **argv)
{
    if (test_work_in(argc > 2 ? argv[2] : "/tmp", "abaqus") != 0) return 1;
    cm_context_create(&ctx);
    test_types();
    test_features();
    test_parts();
    test_write_back();
    test_new_deck();
    test_hostile();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
