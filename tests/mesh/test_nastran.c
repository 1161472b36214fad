/* Nastran bulk data: real numbers both ways, small / large / free field with every kind of
 * continuation, executive and case control, CORD2R/CORD2C systems (chained), CHEXA20 and
 * CPENTA15 node order (mid-side nodes at the middle of VTK's edges, positive volume either
 * winding), INCLUDE, hostile decks (file:line in every message), and writing back: an unmoved
 * mesh byte for byte, a moved one changing only GRID coordinates, the large-field fallback, an
 * affine motion to the precision of each field, new decks. */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/mesh.h"
#include "formats.h"
#include "nastran_internal.h"
#include "test_files.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static cm_context *ctx;

static cm_mesh *read_text(const char *name, const char *text)
{
    test_write_text(test_at(name), text);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, test_at(name), &m);
    CHECK_MSG(s == CM_OK, "%s: %s", name, cm_context_message(ctx));
    return m;
}

/* The read fails with a message naming the file and (when line > 0) the line. */
static void refuse(const char *name, const char *text, int line, const char *what)
{
    test_write_text(test_at(name), text);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, test_at(name), &m);
    char want[300];
    snprintf(want, sizeof want, line > 0 ? "%s:%d:" : "%s", test_at(name), line);
    CHECK_MSG(s < 0 && !m, "%s: read succeeded", name);
    CHECK_MSG(strstr(cm_context_message(ctx), want) && strstr(cm_context_message(ctx), what), "%s: %s (want %s ... %s)",
              name, cm_context_message(ctx), want, what);
    CHECK(!strchr(cm_context_message(ctx), '\n'));
}

static void test_numbers(void)
{
    static const struct { const char *s; double v; } ok[] = {
        {"1.5-3", 1.5e-3}, {"1.+2", 100.0}, {"-.5", -0.5}, {"1.5D-3", 1.5e-3}, {"7.", 7.0}, {".7E1", 7.0},
        {"0.7+1", 7.0},    {"70.-1", 7.0},  {"1.5e+3", 1500}, {"-2", -2.0},   {"+3.25", 3.25}, {"1.0d2", 100.0},
        {"0.00E+00", 0.0}, {"-1.234-12", -1.234e-12},
    };
    for (size_t i = 0; i < sizeof ok / sizeof *ok; ++i) {
        double v = -99;
        CHECK_MSG(nas_parse_real(ok[i].s, strlen(ok[i].s), &v) == 0 && v == ok[i].v, "%s -> %.17g", ok[i].s, v);
    }
    static const char *const bad[] = {"", "1.5x", "nan", "inf", "1e", "+", ".", "1.5-", "1.+", "1.5E+3.", "1.+999", "--1", "1 2"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; ++i) {
        double v;
        CHECK_MSG(nas_parse_real(bad[i], strlen(bad[i]), &v) != 0, "'%s' accepted", bad[i]);
    }
    int64_t k;
    CHECK(nas_parse_int("123456789012345678", 18, &k) == 0 && k == 123456789012345678LL);
    CHECK(nas_parse_int("1234567890123456789", 19, &k) != 0); /* no overflow: refused */
    CHECK(nas_parse_int("1.", 2, &k) != 0);
    CHECK(nas_text_digits("0.166667", 8) == 6 && nas_text_digits("1.000000", 8) == 7);
    CHECK(nas_text_digits("0.00E+00", 8) == 3 && nas_text_digits("-1.5-3", 6) == 2 && nas_text_digits("0.", 2) == 1);
    char out[40];
    CHECK(nas_format_digits(out, sizeof out, 0.0015, 3) && !strcmp(out, ".0015"));
    CHECK(nas_format_digits(out, sizeof out, 1.5e-7, 3) && !strcmp(out, "1.5-7"));
    CHECK(nas_format_digits(out, sizeof out, -123456789.0, 3) && !strcmp(out, "-1.23+8"));
    CHECK(nas_format_digits(out, sizeof out, 100.0, 7) && !strcmp(out, "100."));
    CHECK(nas_format_digits(out, sizeof out, -0.5, 7) && !strcmp(out, "-.5"));
    /* fits: the shortest exact text, else the most digits that fit, else nothing */
    CHECK(nas_format_fit(out, sizeof out, 0.1, 8, 6) && !strcmp(out, ".1"));
    CHECK(nas_format_fit(out, sizeof out, 0.123456789, 8, 6) && !strcmp(out, ".1234568"));
    CHECK(nas_format_fit(out, sizeof out, -123.4567891, 8, 7) == 0);
    CHECK(nas_format_fit(out, sizeof out, -123.4567891, 16, 7) && !strcmp(out, "-123.4567891"));
    CHECK(nas_format_fit(out, sizeof out, 1.0 / 3.0, 16, 1) && !strcmp(out, ".333333333333333"));
    for (double v = -1e6; v < 1e6; v = v * -1.37 + 0.123) {
        CHECK(nas_format_fit(out, sizeof out, v, 16, 1) > 0);
        double back;
        CHECK(nas_parse_real(out, strlen(out), &back) == 0 && fabs(back - v) <= 1e-13 * fabs(v));
        if (fabs(v) > 1e5) break;
    }
}

/* One unit cube of 5 tets (ids 10..80 step 10) in three layouts; the same mesh from each. */
static const double cube[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
static const char *tets =
    "CTETRA  1       7       10      20      40      50\n"
    "CTETRA  2       7       20      30      40      70\n"
    "CTETRA  3       7       50      70      60      20\n"
    "CTETRA  4       7       50      80      70      40\n"
    "CTETRA  5       8       20      40      50      70\n"
    "CTRIA3  6       9       10      40      20\n";

static void check_cube(const cm_mesh *m, const char *what)
{
    CHECK_MSG(m && m->n_nodes == 8 && m->n_cells == 6, "%s", what);
    if (!m || m->n_nodes != 8) return;
    for (int i = 0; i < 8; ++i) {
        CHECK_MSG(m->node_tag[i] == 10 * (i + 1), "%s: tag %lld", what, (long long)m->node_tag[i]);
        for (int k = 0; k < 3; ++k) CHECK_MSG(m->xyz[3 * i + k] == cube[i][k], "%s: node %d", what, i);
    }
    double sj[6];
    CHECK(cm_mesh_quality(ctx, m, sj) == CM_OK);
    for (int c = 0; c < 5; ++c) CHECK_MSG(m->type[c] == CM_CELL_TET4 && sj[c] > 0, "%s: cell %d", what, c);
    CHECK(m->type[5] == CM_CELL_TRI3 && m->physical[5] == 9 && m->physical[4] == 8 && m->physical[0] == 7);
    CHECK(m->n_groups == 3 && !strcmp(m->groups[0].name, "PID 7") && m->groups[2].dim == 2);
}

static void test_layouts(void)
{
    char deck[4096];
    /* small field, executive and case control first, ENDDATA with text after it */
    snprintf(deck, sizeof deck,
             "ID test\nSOL 101\nCEND\nTITLE = GRID 1 2 3\n  SUBCASE 1\nBEGIN BULK\n$ nodes\n"
             "GRID    10              0.      0.      0.\n"
             "GRID    20      0       1.      0.      0.\n"
             "GRID    30              1.0     1.+0    0.0\n"
             "GRID    40              .0      10.-1   -0.\n"
             "grid    50              0.0     0.0     1.0\n"
             "GRID    60              1.      0.      1.\n"
             "GRID\t70\t\t1.\t1.\t1.\n"
             "GRID    80              0.      1.      1.      \n"
             "%sENDDATA\nGRID    90      0       not a number\n",
             tets);
    cm_mesh *m = read_text("small.bdf", deck);
    check_cube(m, "small");
    if (m) CHECK(m->xyz[3 * 3 + 2] == 0 && signbit(m->xyz[3 * 3 + 2]));
    cm_mesh_destroy(&m);

    /* large field, '*' continuations (with and without markers), no BEGIN BULK */
    char large[2048] = "";
    for (int i = 0; i < 8; ++i) {
        char line[200];
        if (i % 2)
            snprintf(line, sizeof line, "GRID*   %-16d%-16s%16.3f%16.3f*N%-6d\n*N%-6d%16.3f\n", 10 * (i + 1), "", cube[i][0],
                     cube[i][1], i, i, cube[i][2]);
        else
            snprintf(line, sizeof line, "GRID*   %-16d%-16s%-16.1f%-16.1f\n*       %-16.1f\n", 10 * (i + 1), "0", cube[i][0],
                     cube[i][1], cube[i][2]);
        strcat(large, line);
    }
    strcat(large, tets);
    m = read_text("large.nas", large);
    check_cube(m, "large");
    cm_mesh_destroy(&m);

    /* free field, small and large ("GRID*,...", "*,..."), continuations "+", ",", blank */
    snprintf(deck, sizeof deck,
             "BEGIN BULK\n"
             "GRID,10,,0.,0.,0.\nGRID, 20 ,0, 1.0 , 0. , 0.\nGRID*,30,,1.,1.\n*,0.\nGRID,40,,0.,1.,0.\n"
             "GRID,50,,0.,0.,1.\nGRID,60,,1.,0.,1.\nGRID,70,,1.,1.,1.,,,,+G70\n+G70\nGRID,80,,0.,1.,1. $ comment\n"
             "CTETRA,1,7,10,20,40,50\nCTETRA,2,7,20,30,40,70\nCTETRA,3,7,50,70,60,20\nCTETRA,4,7,50,80,70,40\n"
             "CTETRA,5,8,20,40,50,70,,,\n,\nCTRIA3,6,9,10,40,20\nENDDATA\n");
    m = read_text("free.dat", deck);
    check_cube(m, "free");
    cm_mesh_destroy(&m);
}

/* A unit hex [0,2]^2 x [0,1] as CHEXA20 and a wedge as CPENTA15, mid-side nodes in Nastran's
 * order (bottom edges, vertical edges, top edges); the hex also with the other winding. */
static void test_quadratic(void)
{
    const double c[8][3] = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {0, 0, 1}, {2, 0, 1}, {2, 2, 1}, {0, 2, 1}};
    /* Nastran edge order: 1-2 2-3 3-4 4-1, 1-5 2-6 3-7 4-8, 5-6 6-7 7-8 8-5 */
    static const int e[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 5}, {2, 6}, {3, 7}, {4, 5}, {5, 6}, {6, 7}, {7, 4}};
    char deck[8192] = "BEGIN BULK\n", line[128];
    for (int i = 0; i < 8; ++i) {
        snprintf(line, sizeof line, "GRID    %-8d        %-8.1f%-8.1f%-8.1f\n", i + 1, c[i][0], c[i][1], c[i][2]);
        strcat(deck, line);
    }
    for (int i = 0; i < 12; ++i) {
        snprintf(line, sizeof line, "GRID    %-8d        %-8.1f%-8.1f%-8.1f\n", 101 + i, (c[e[i][0]][0] + c[e[i][1]][0]) / 2,
                 (c[e[i][0]][1] + c[e[i][1]][1]) / 2, (c[e[i][0]][2] + c[e[i][1]][2]) / 2);
        strcat(deck, line);
    }
    /* G1..G20 = corners 1..8 then 101..112 */
    strcat(deck, "CHEXA   1       3       1       2       3       4       5       6       +\n"
                 "+       7       8       101     102     103     104     105     106     +\n"
                 "+       107     108     109     110     111     112\n");
    /* the same hex, top face first (the other winding) */
    strcat(deck, "CHEXA   2       3       5       6       7       8       1       2\n"
                 "        3       4       109     110     111     112     105     106\n"
                 "        107     108     101     102     103     104\n");
    /* a wedge on corners 1 2 4 / 5 6 8: edges 1-2 (101), 2-4 (none: a GRID of its own), ... */
    strcat(deck, "GRID    201             1.      1.      0.\nGRID    202             1.      1.      1.\n"
                 "GRID    203             0.      0.      .5\nGRID    204             2.      0.      .5\n"
                 "GRID    205             0.      2.      .5\n");
    /* CPENTA15: G1-G3 bottom, G4-G6 top, G7-G9 bottom edges 1-2 2-3 3-1, G10-G12 vertical,
     * G13-G15 top edges */
    strcat(deck, "CPENTA  3       4       1       2       4       5       6       8       +\n"
                 "+       101     201     104     203     204     205     109     202     +\n"
                 "+       112\nENDDATA\n");
    cm_mesh *m = read_text("quad.bdf", deck);
    if (!m) return;
    CHECK(m->n_cells == 3 && m->type[0] == CM_CELL_HEX20 && m->type[1] == CM_CELL_HEX20 && m->type[2] == CM_CELL_WEDGE15);
    double sj[3];
    CHECK(cm_mesh_quality(ctx, m, sj) == CM_OK && sj[0] > 0.99 && sj[1] > 0.99 && sj[2] > 0);
    /* every mid-side node at the middle of its VTK edge */
    static const int hex_edges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    static const int wedge_edges[9][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}};
    for (size_t cell = 0; cell < 3; ++cell) {
        const int64_t *v = m->conn + m->offset[cell];
        const int ne = cell < 2 ? 12 : 9, nc = cell < 2 ? 8 : 6;
        for (int i = 0; i < ne; ++i) {
            const int *ed = cell < 2 ? hex_edges[i] : wedge_edges[i];
            for (int k = 0; k < 3; ++k)
                CHECK_MSG(m->xyz[3 * v[nc + i] + k] == (m->xyz[3 * v[ed[0]] + k] + m->xyz[3 * v[ed[1]] + k]) / 2,
                          "cell %zu edge %d", cell, i);
        }
    }
    cm_mesh_destroy(&m);
}

static void test_coords(void)
{
    /* system 1: origin (1,2,3), rotated 90 degrees about z (x along basic y); system 2 in 1:
     * origin (1,0,0) of system 1, axes of system 1; system 3: cylindrical about basic z */
    const char *deck = "BEGIN BULK\n"
                       "GRID    1       2       1.      0.      0.\n"
                       "GRID    2       1       0.      1.      0.\n"
                       "GRID    3       3       2.      90.     5.\n"
                       "GRID    4               1.      1.      1.\n"
                       "CORD2R  2       1       1.      0.      0.      1.      0.      1.      +\n"
                       "+       2.      0.      0.\n"
                       "CORD2R  1               1.      2.      3.      1.      2.      4.\n"
                       "        1.      3.      3.\n"
                       "CORD2C  3               0.      0.      0.      0.      0.      1.\n"
                       "        1.      0.      0.\n"
                       "CTETRA  1       1       1       2       3       4\n";
    cm_mesh *m = read_text("cord.bdf", deck);
    if (!m) return;
    /* node 1: x=1 in system 2 = (2,0,0) in system 1 = (1,2,3) + 2*(0,1,0) */
    const double want[4][3] = {{1, 4, 3}, {0, 2, 3}, {0, 2, 5}, {1, 1, 1}};
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) CHECK_NEAR(m->xyz[3 * i + k], want[i][k], 1e-14);
    /* moved and written back: in each GRID's own system, read back to the field's precision */
    const double d[3] = {0.25, -0.5, 0.125};
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 3; ++k) m->xyz[3 * i + k] += d[k];
    CHECK_MSG(cm_mesh_write(ctx, m, test_at("cord_out.bdf"), NULL) == CM_OK, "%s", cm_context_message(ctx));
    cm_mesh *b = NULL;
    CHECK_MSG(cm_mesh_read(ctx, test_at("cord_out.bdf"), &b) == CM_OK, "%s", cm_context_message(ctx));
    for (int i = 0; b && i < 4; ++i)
        for (int k = 0; k < 3; ++k) CHECK_NEAR(b->xyz[3 * i + k], want[i][k] + d[k], 1e-6);
    char *out = test_read_file(test_at("cord_out.bdf"), NULL);
    /* node 2 in system 1 (x along basic y, y along -x): moved by (0.25, -0.5) basic = (-0.5, -0.25) local */
    CHECK_MSG(strstr(out, "GRID    2       1       -.5     .75     .125\n") != NULL, "%s", out);
    /* the systems' cards are untouched */
    CHECK(strstr(out, "CORD2R  2       1       1.      0.      0.      1.      0.      1.      +\n+       2.      0.      0.\n"));
    free(out);
    cm_mesh_destroy(&b);
    cm_mesh_destroy(&m);
}

static void test_include(void)
{
    mkdir(test_at("inc"), 0777);
    mkdir(test_at("inc/sub"), 0777);
    mkdir(test_at("inc_out"), 0777);
    mkdir(test_at("inc_out/sub"), 0777);
    test_write_text(test_at("inc/sub/nodes.bdf"),
                    "$ nodes\nGRID    2               1.      0.      0.\nINCLUDE 'more.bdf'\n");
    test_write_text(test_at("inc/sub/more.bdf"), "GRID    3               0.      1.      0.\n");
    test_write_text(test_at("inc/main.bdf"),
                    "SOL 101\nCEND\nBEGIN BULK\nGRID    1               0.      0.      0.\n"
                    "INCLUDE 'su\n  b/nodes.bdf'\nGRID    4               0.      0.      1.\n"
                    "CTETRA  1       1       1       2       3       4\nENDDATA\n");
    cm_mesh *m = NULL;
    CHECK_MSG(cm_mesh_read(ctx, test_at("inc/main.bdf"), &m) == CM_OK, "%s", cm_context_message(ctx));
    if (!m) return;
    CHECK(m->n_nodes == 4 && m->node_tag[1] == 2 && m->node_tag[2] == 3 && m->xyz[3 * 2 + 1] == 1.0);
    m->xyz[3 * 1 + 0] = 1.5;  /* in sub/nodes.bdf */
    m->xyz[3 * 2 + 2] = -0.25; /* in sub/more.bdf, included by sub/nodes.bdf */
    /* beside the source: the included copies would overwrite their sources */
    CHECK(cm_mesh_write(ctx, m, test_at("inc/main2.bdf"), NULL) == CM_ERR_ARGUMENT);
    CHECK_MSG(cm_mesh_write(ctx, m, test_at("inc_out/main.bdf"), NULL) == CM_OK, "%s", cm_context_message(ctx));
    char *a = test_read_file(test_at("inc/main.bdf"), NULL), *b = test_read_file(test_at("inc_out/main.bdf"), NULL);
    CHECK(a && b && !strcmp(a, b));
    free(a);
    free(b);
    a = test_read_file(test_at("inc_out/sub/nodes.bdf"), NULL);
    CHECK_MSG(a && !strcmp(a, "$ nodes\nGRID    2               1.5     0.      0.\nINCLUDE 'more.bdf'\n"), "%s", a);
    free(a);
    a = test_read_file(test_at("inc_out/sub/more.bdf"), NULL);
    CHECK_MSG(a && !strcmp(a, "GRID    3               0.      1.      -.25\n"), "%s", a);
    free(a);
    cm_mesh_destroy(&m);
}

static void test_hostile(void)
{
    const char *g4 = "GRID    1               0.      0.      0.\nGRID    2               1.      0.      0.\n"
                     "GRID    3               0.      1.      0.\nGRID    4               0.      0.      1.\n";
    char deck[2048];
    snprintf(deck, sizeof deck, "%sCHEXA   1       1       1       2       3       4       1       2       +\n", g4);
    refuse("h_truncated.bdf", deck, 5, "has 6 nodes");
    snprintf(deck, sizeof deck, "%sCTETRA  1       1       1       2       3       99\n", g4);
    refuse("h_undefined.bdf", deck, 5, "GRID 99 is not defined");
    snprintf(deck, sizeof deck, "%sGRID    5               nan     0.      0.\n", g4);
    refuse("h_nan.bdf", deck, 5, "'nan'");
    snprintf(deck, sizeof deck, "%sGRID*   5                               1.+999          0.\n*       0.\n", g4);
    refuse("h_overflow.bdf", deck, 5, "finite");
    snprintf(deck, sizeof deck, "%sCTETRA,1,1,1,2,3,99999999999999999999\n", g4);
    refuse("h_bigid.bdf", deck, 5, "GRID id");
    /* a huge id is only a number: no allocation by its value */
    test_write_text(test_at("h_hugeok.bdf"), "GRID*   9999999999999999                0.              0.\n*       0.\n"
                                 "GRID    1               1.      0.      0.\n");
    cm_mesh *m = NULL;
    CHECK_MSG(cm_mesh_read(ctx, test_at("h_hugeok.bdf"), &m) == CM_OK && m->node_tag[0] == 9999999999999999LL, "%s",
              cm_context_message(ctx));
    cm_mesh_destroy(&m);
    snprintf(deck, sizeof deck, "%sGRID    2               0.      0.      0.\n", g4);
    refuse("h_twice.bdf", deck, 5, "GRID 2 is defined twice");
    snprintf(deck, sizeof deck, "%sGRID    5       7       0.      0.      0.\n", g4);
    refuse("h_nocord.bdf", deck, 5, "GRID 5: coordinate system 7");
    snprintf(deck, sizeof deck, "%sGRID    5       7       0.      0.      0.\nCORD2R  7       8       0.      0.      0.      0.      0.      1.\n"
             "        1.      0.      0.\nCORD2R  8       7       0.      0.      0.      0.      0.      1.\n        1.      0.      0.\n", g4);
    refuse("h_cycle.bdf", deck, 6, "cycle");
    snprintf(deck, sizeof deck, "%sGRID    5       7       0.      0.      0.\nCORD2R  7               0.      0.      0.      0.      0.      1.\n"
             "        0.      0.      2.\n", g4);
    refuse("h_line.bdf", deck, 6, "on one line");
    snprintf(deck, sizeof deck, "$ c\n+       1.\n%s", g4);
    refuse("h_orphan.bdf", deck, 2, "continuation");
    snprintf(deck, sizeof deck, "%sGRID,5,,0.,0.,0.,,,,,,,7\n", g4);
    refuse("h_fields.bdf", deck, 5, "more than 10 fields");
    snprintf(deck, sizeof deck, "%sINCLUDE 'never\n", g4);
    refuse("h_quote.bdf", deck, 5, "closing quote");
    snprintf(deck, sizeof deck, "%sINCLUDE 'missing.bdf'\n", g4);
    refuse("h_missing.bdf", deck, 5, "missing.bdf");
    snprintf(deck, sizeof deck, "%sINCLUDE 'h_self.bdf'\n", g4);
    refuse("h_self.bdf", deck, 5, "recursive INCLUDE");
    snprintf(deck, sizeof deck, "%sCTETRA  1       1       1       2       3       4       5\n", g4);
    refuse("h_partial.bdf", deck, 5, "has 5 nodes");
    snprintf(deck, sizeof deck, "%sCTETRA  1       0       1       2       3       4\n", g4);
    refuse("h_pid.bdf", deck, 5, "property id");
    refuse("h_empty.bdf", "$ nothing\nBEGIN BULK\nENDDATA\n", 0, "no GRID");
    refuse("h_cord1.bdf", "GRID    1       5       0.      0.      0.\nCORD1R  5       1       2       3\n", 2, "CORD1R 5");
    /* truncated everywhere: never a crash, an error or a mesh */
    const char *full = "BEGIN BULK\nGRID*   1               0               .5              1.5-1\n*       2.\n"
                       "GRID,2,,1.,0.,0.\nGRID    3               0.      1.      0.\nGRID    4               0.      0.      1.\n"
                       "CTETRA  1       1       1       2       3       4\nENDDATA\n";
    for (size_t n = 0; n < strlen(full); ++n) {
        FILE *f = fopen(test_at("h_cut.bdf"), "wb");
        fwrite(full, 1, n, f);
        fclose(f);
        cm_status s = cm_mesh_read(ctx, test_at("h_cut.bdf"), &m);
        CHECK((s < 0) == (m == NULL));
        cm_mesh_destroy(&m);
    }
}

/* Lines of a and b equal except GRID cards'; returns the number of GRID lines that differ. */
static int compare_non_grid(const char *a, const char *b)
{
    int differ = 0;
    while (*a && *b) {
        const char *ea = strchr(a, '\n'), *eb = strchr(b, '\n');
        size_t na = ea ? (size_t)(ea - a) : strlen(a), nb = eb ? (size_t)(eb - b) : strlen(b);
        const int grid = !strncmp(a, "GRID", 4) || a[0] == '*';
        if (na != nb || memcmp(a, b, na)) {
            CHECK_MSG(grid, "a line other than a GRID changed: '%.*s' -> '%.*s'", (int)na, a, (int)nb, b);
            ++differ;
        }
        a += na + (ea != NULL);
        b += nb + (eb != NULL);
    }
    CHECK(!*a && !*b);
    return differ;
}

static void test_write_back(void)
{
    const char *deck = "$ header\nBEGIN BULK\nPARAM,POST,-1\n"
                       "GRID    1       0       0.00E+000.00E+001.000000\n"
                       "GRID    2               1.      0.      0.      0       3\n"
                       "GRID*   3                               0.166666666667  1.              *C3\n"
                       "*C3     0.\n"
                       "GRID,4,,0.,0.,1.\n"
                       "GRID    5               .5      .5\n"
                       "CTETRA  1       1       1       2       3       4\n"
                       "CTETRA  2       1       2       3       4       5\n"
                       "MAT1    1       2.1+5           .3\nENDDATA\n";
    cm_mesh *m = read_text("wb.bdf", deck);
    if (!m) return;
    /* unmoved: byte for byte */
    CHECK(cm_mesh_write(ctx, m, test_at("wb_same.bdf"), NULL) == CM_OK);
    char *same = test_read_file(test_at("wb_same.bdf"), NULL);
    CHECK(same && !strcmp(same, deck));
    free(same);
    /* an affine motion of every node */
    const double A[3][3] = {{1.1, 0.2, 0.0}, {-0.1, 0.9, 0.3}, {0.05, 0.0, 1.2}}, t[3] = {0.123, -2.5, 10.0};
    double was[15], now[15];
    memcpy(was, m->xyz, sizeof was);
    for (int i = 0; i < 5; ++i)
        for (int k = 0; k < 3; ++k)
            now[3 * i + k] = m->xyz[3 * i + k] = t[k] + A[k][0] * was[3 * i] + A[k][1] * was[3 * i + 1] + A[k][2] * was[3 * i + 2];
    CHECK_MSG(cm_mesh_write(ctx, m, test_at("wb_moved.bdf"), NULL) == CM_OK, "%s", cm_context_message(ctx));
    char *moved = test_read_file(test_at("wb_moved.bdf"), NULL);
    /* node 1 (-2.5 + 0.3 = -2.2 fits, 10 + 1.2 = 11.2 fits) in place; node 2's y = -2.6 fits */
    CHECK_MSG(strstr(moved, "GRID    1       0       .123    -2.2    11.2    \n") != NULL, "%s", moved);
    CHECK_MSG(strstr(moved, "GRID    2               1.223   -2.6    10.05   0       3\n") != NULL, "%s", moved);
    CHECK_MSG(strstr(moved, "GRID,4,,.123,-2.2,11.2\n") != NULL, "%s", moved);
    /* node 5 had no X3: written where it belongs */
    CHECK_MSG(strstr(moved, "GRID    5               .773    -2.1    10.025\n") != NULL, "%s", moved);
    /* the rest: byte for byte, lines of the GRID cards aside */
    compare_non_grid(deck, moved);
    cm_mesh *b = NULL;
    CHECK_MSG(cm_mesh_read(ctx, test_at("wb_moved.bdf"), &b) == CM_OK, "%s", cm_context_message(ctx));
    /* the affine image to each field's precision (node 3: 12 digits in 16 columns) */
    for (int i = 0; b && i < 15; ++i) CHECK_NEAR(b->xyz[i], now[i], 1e-11 * fabs(now[i]) + 1e-300);
    cm_mesh_destroy(&b);
    free(moved);

    /* a value 8 columns cannot hold to the deck's precision: the card becomes large field */
    memcpy(m->xyz, was, sizeof was);
    m->xyz[0] = -123.4567891; /* node 1, X1: input "0.00E+00" has 3 digits; fits ("-123.457") */
    m->xyz[2] = 1.23456789;   /* X3: input "1.000000", 7 digits: "1.234568" fits */
    m->xyz[3] = -1.234567e-7; /* node 2 X1, input "1." (1 digit): the most digits that fit */
    m->xyz[4] = 1234567.891;  /* node 2 X2, input "0." -> "1234568." fits in 8 */
    CHECK(cm_mesh_write(ctx, m, test_at("wb_fit.bdf"), NULL) == CM_OK);
    moved = test_read_file(test_at("wb_fit.bdf"), NULL);
    CHECK_MSG(strstr(moved, "GRID    1       0       -123.4570.00E+001.234568\n") != NULL, "%s", moved);
    CHECK_MSG(strstr(moved, "GRID    2               -1.235-71234568.0.      0       3\n") != NULL, "%s", moved);
    free(moved);
    memcpy(m->xyz, was, sizeof was);
    m->xyz[2] = -1.23456789; /* "1.000000" (7 digits): -1.234568 needs 9 columns */
    CHECK(cm_mesh_write(ctx, m, test_at("wb_large.bdf"), NULL) == CM_OK);
    moved = test_read_file(test_at("wb_large.bdf"), NULL);
    CHECK_MSG(strstr(moved, "\nGRID*   1               0               0.00E+00        0.00E+00\n"
                            "*       -1.23456789\nGRID    2 ") != NULL, "%s", moved);
    free(moved);
    CHECK(cm_mesh_read(ctx, test_at("wb_large.bdf"), &b) == CM_OK && b->xyz[2] == -1.23456789);
    cm_mesh_destroy(&b);
    /* written into a path of another format: a new file; into .bdf after the mesh changed: a new deck */
    cm_mesh_destroy(&m);
}

static void test_new_deck(void)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    cm_mesh_resize_nodes(ctx, m, 8, 0);
    for (int i = 0; i < 8; ++i)
        for (int k = 0; k < 3; ++k) m->xyz[3 * i + k] = cube[i][k] * (1.0 / 3.0) + (k == 2 ? -1e-9 : 1e5);
    const int64_t hex[8] = {0, 1, 2, 3, 4, 5, 6, 7}, tri[3] = {0, 1, 2}, pt = 5;
    cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, hex, 8, 4, 0, 0);
    cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, tri, 3, 2, 0, 0);
    cm_mesh_add_cell(ctx, m, CM_CELL_POINT, &pt, 1, 0, 0, 0);
    cm_mesh_add_group(ctx, m, 3, 4, "solid");
    CHECK(cm_mesh_write(ctx, m, test_at("new.bdf"), NULL) == CM_WARNING); /* the point cell is left out */
    cm_mesh *b = NULL;
    CHECK_MSG(cm_mesh_read(ctx, test_at("new.bdf"), &b) == CM_OK, "%s", cm_context_message(ctx));
    if (b) {
        CHECK(b->n_nodes == 8 && b->n_cells == 2 && b->type[0] == CM_CELL_HEX8 && b->physical[0] == 4 && b->physical[1] == 2);
        for (int i = 0; i < 24; ++i) CHECK_NEAR(b->xyz[i], m->xyz[i], 1e-10 * fabs(m->xyz[i]));
        for (int i = 0; i < 8; ++i) CHECK(b->conn[i] == i);
    }
    char *d = test_read_file(test_at("new.bdf"), NULL);
    CHECK(d && strstr(d, "$ PID 4 (dimension 3): solid\n") && strstr(d, "BEGIN BULK\n") && strstr(d, "ENDDATA\n"));
    free(d);
    cm_mesh_destroy(&b);
    /* no card for a polygon: refused, nothing written */
    const int64_t poly[5] = {0, 1, 2, 3, 4};
    cm_mesh_add_cell(ctx, m, CM_CELL_POLYGON, poly, 5, 0, 0, 0);
    CHECK(cm_mesh_write(ctx, m, test_at("poly.bdf"), NULL) == CM_ERR_UNSUPPORTED && access(test_at("poly.bdf"), F_OK) != 0);
    cm_mesh_destroy(&m);
}

static void test_sniff(void)
{
    CHECK(cm_mesh_format_from_path("x.bdf") == CM_FORMAT_NASTRAN && cm_mesh_format_from_path("x.NAS") == CM_FORMAT_NASTRAN);
    test_write_text(test_at("deck.dat"), "$ a deck\nGRID    1               0.      0.      0.\n");
    CHECK(cm_mesh_format_from_path(test_at("deck.dat")) == CM_FORMAT_NASTRAN);
    CHECK(cm_nastran_sniff("$ c\nBEGIN BULK\n", 15) && !cm_nastran_sniff("1 2 3\n4 5 6\n", 12));
}

int main(void)
{
    if (test_work_temp("nastran") != 0) return 1;
    cm_context_create(&ctx);
    test_numbers();
    test_layouts();
    test_quadratic();
    test_coords();
    test_include();
    test_hostile();
    test_write_back();
    test_new_deck();
    test_sniff();
    cm_context_destroy(&ctx);
    if (test_work_remove() != 0) return 1;
    return TEST_REPORT();
}
