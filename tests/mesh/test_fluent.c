/* Fluent .msh/.cas (mesh/io/fluent_*.c) on files OpenFOAM's foamMeshToFluent wrote
 * (tests/data/fluent, make_fixtures.py) and their binary variants: told apart from gmsh's .msh
 * by content, cells typed from their faces, zones as groups, ASCII and binary agree; the
 * write back changes only node coordinates (the bytes between them compared), an affine
 * motion comes back as the affine image to the file's precision; a mesh not read from Fluent
 * is refused; hostile files (every truncation, wrong counts, missing nodes and cells, NaN,
 * unterminated lists, 2-D and hanging-node files) fail with the file and the line or byte. */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/mesh.h"
#include "origin.h"
#include "rewrite.h"
#include "test_files.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

static const char *data_dir, *work_dir;

static char *fixture(const char *name)
{
    static char path[4][512];
    static int k;
    char *p = path[k++ % 4];
    snprintf(p, 512, "%s/fluent/%s", data_dir, name);
    return p;
}

static char *work(const char *name)
{
    static char path[4][512];
    static int k;
    char *p = path[k++ % 4];
    snprintf(p, 512, "%s/fluent_%s", work_dir, name);
    return p;
}

static cm_mesh *read_ok(cm_context *ctx, const char *path)
{
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    CHECK_MSG(s == CM_OK && m, "%s: %s", path, cm_context_message(ctx));
    return m;
}

static size_t count_type(const cm_mesh *m, cm_cell_type t)
{
    size_t n = 0;
    for (size_t c = 0; c < m->n_cells; ++c) n += m->type[c] == t;
    return n;
}

static const cm_mesh_group *group(const cm_mesh *m, int dim, const char *name)
{
    for (size_t i = 0; i < m->n_groups; ++i)
        if (m->groups[i].dim == dim && !strcmp(m->groups[i].name, name)) return &m->groups[i];
    return NULL;
}

static void test_formats(cm_context *ctx)
{
    CHECK(cm_mesh_format_from_path(fixture("box.msh")) == CM_FORMAT_FLUENT);
    CHECK(cm_mesh_format_from_path(fixture("box_double.msh")) == CM_FORMAT_FLUENT);
    char gmsh[512];
    snprintf(gmsh, sizeof gmsh, "%s/msh/box_hole_41.msh", data_dir);
    CHECK(cm_mesh_format_from_path(gmsh) == CM_FORMAT_MSH);
    snprintf(gmsh, sizeof gmsh, "%s/msh/box_hole_22b.msh", data_dir);
    CHECK(cm_mesh_format_from_path(gmsh) == CM_FORMAT_MSH);
    CHECK(cm_mesh_format_from_path("new.cas") == CM_FORMAT_FLUENT);
    CHECK(cm_mesh_format_from_path("new.msh") == CM_FORMAT_MSH);
    CHECK(strstr(cm_mesh_format_list(), ".cas") != NULL);
    /* a gmsh mesh still reads as gmsh and writes as gmsh to .msh; to .cas it is refused */
    cm_mesh *m = read_ok(ctx, gmsh);
    if (!m) return;
    CHECK(cm_mesh_origin_format(m) != CM_FORMAT_FLUENT);
    CHECK(cm_mesh_write(ctx, m, work("gmsh.msh"), NULL) == CM_OK);
    CHECK(cm_mesh_format_from_path(work("gmsh.msh")) == CM_FORMAT_MSH);
    CHECK(cm_mesh_write(ctx, m, work("gmsh.cas"), NULL) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "Fluent") != NULL);
    cm_mesh_destroy(&m);
}

static void test_read(cm_context *ctx)
{
    cm_mesh *m = read_ok(ctx, fixture("box.msh"));
    if (!m) return;
    /* 3x2x2 hexes, 4*3*3 nodes; boundary quads: inlet 4, outlet 4, walls 2*(6+6) */
    CHECK(m->n_nodes == 36);
    CHECK(count_type(m, CM_CELL_HEX8) == 12);
    CHECK(count_type(m, CM_CELL_QUAD4) == 4 + 4 + 24);
    CHECK(group(m, 3, "fluid-1") && group(m, 2, "inlet") && group(m, 2, "outlet") && group(m, 2, "walls"));
    CHECK(group(m, 2, "interior") == NULL);
    const cm_mesh_group *inlet = group(m, 2, "inlet");
    size_t n_inlet = 0;
    for (size_t c = 0; inlet && c < m->n_cells; ++c) n_inlet += m->physical[c] == inlet->tag;
    CHECK(n_inlet == 4);
    double *sj = malloc(m->n_cells * sizeof *sj);
    cm_quality_stats all;
    CHECK(cm_mesh_quality(ctx, m, sj) == CM_OK && cm_quality_summarize(ctx, m, sj, NULL, &all) == CM_OK);
    CHECK(all.count == 12 && all.inverted == 0 && all.min > 0.9);
    free(sj);

    /* the binary variant (double precision) is the same mesh, bit for bit */
    cm_mesh *b = read_ok(ctx, fixture("box_double.msh"));
    if (b) {
        CHECK(b->n_nodes == m->n_nodes && b->n_cells == m->n_cells);
        CHECK(!memcmp(b->xyz, m->xyz, 3 * m->n_nodes * sizeof *m->xyz));
        CHECK(!memcmp(b->conn, m->conn, (size_t)m->offset[m->n_cells] * sizeof *m->conn));
    }
    cm_mesh_destroy(&b);
    cm_mesh_destroy(&m);

    /* hexes, prisms, pyramids and tets from faces; single precision agrees to float rounding */
    m = read_ok(ctx, fixture("mixed.msh"));
    b = read_ok(ctx, fixture("mixed_single.msh"));
    if (m && b) {
        CHECK(count_type(m, CM_CELL_HEX8) == 4 && count_type(m, CM_CELL_WEDGE6) == 8);
        CHECK(count_type(m, CM_CELL_PYR5) == 4 && count_type(m, CM_CELL_TET4) == 105);
        CHECK(group(m, 2, "bottom") && group(m, 2, "walls"));
        CHECK(b->n_cells == m->n_cells && !memcmp(b->conn, m->conn, (size_t)m->offset[m->n_cells] * sizeof *m->conn));
        for (size_t i = 0; i < 3 * m->n_nodes; ++i) CHECK_NEAR(b->xyz[i], (float)m->xyz[i], 0);
        double *q = malloc(m->n_cells * sizeof *q);
        cm_quality_stats all2;
        CHECK(cm_mesh_quality(ctx, m, q) == CM_OK && cm_quality_summarize(ctx, m, q, NULL, &all2) == CM_OK);
        CHECK(all2.inverted == 0 && all2.count == 121);
        free(q);
    }
    cm_mesh_destroy(&b);
    cm_mesh_destroy(&m);

    /* polyhedra with polygon faces, ASCII and binary */
    m = read_ok(ctx, fixture("poly.msh"));
    b = read_ok(ctx, fixture("poly_double.msh"));
    if (m && b) {
        CHECK(cm_mesh_count_dim(m, 3) == 36 && count_type(m, CM_CELL_POLYHEDRON) > 0 && count_type(m, CM_CELL_POLYGON) > 0);
        CHECK(b->n_cells == m->n_cells && !memcmp(b->xyz, m->xyz, 3 * m->n_nodes * sizeof *m->xyz));
        CHECK(!memcmp(b->conn, m->conn, (size_t)m->offset[m->n_cells] * sizeof *m->conn));
        cm_mesh_boundary *bd = NULL;
        CHECK(cm_mesh_boundary_create(ctx, m, &bd) == CM_OK);
        if (bd) CHECK(bd->n_components == 1 && bd->n_nonmanifold == 0);
        cm_mesh_boundary_destroy(&bd);
    }
    cm_mesh_destroy(&b);
    cm_mesh_destroy(&m);
}

/* The bytes between the coordinate spans of the file a mesh was read from. */
static int same_outside_spans(cm_context *ctx, const char *a, const char *b)
{
    cm_mesh *ma = read_ok(ctx, a), *mb = read_ok(ctx, b);
    int same = 0;
    if (ma && mb) {
        const cm_rewrite_source *sa = cm_mesh_origin_state(ma, CM_FORMAT_FLUENT), *sb = cm_mesh_origin_state(mb, CM_FORMAT_FLUENT);
        size_t na, nb;
        char *da = test_read_file(a, &na), *db = test_read_file(b, &nb);
        const cm_rewrite_file *fa = &sa->files[0], *fb = &sb->files[0];
        same = fa->n_spans == fb->n_spans && fa->n_spans > 0;
        int64_t pa = 0, pb = 0;
        for (size_t i = 0; same && i <= fa->n_spans; ++i) {
            const int64_t ea = i < fa->n_spans ? fa->spans[i].offset : (int64_t)na;
            const int64_t eb = i < fb->n_spans ? fb->spans[i].offset : (int64_t)nb;
            same = ea - pa == eb - pb && !memcmp(da + pa, db + pb, (size_t)(ea - pa));
            if (i < fa->n_spans) {
                same = same && fa->spans[i].node == fb->spans[i].node;
                pa = ea + fa->spans[i].length;
                pb = eb + fb->spans[i].length;
            }
        }
        free(da);
        free(db);
    }
    cm_mesh_destroy(&ma);
    cm_mesh_destroy(&mb);
    return same;
}

static void test_write_back(cm_context *ctx, const char *name, double tol)
{
    cm_mesh *m = read_ok(ctx, fixture(name));
    if (!m) return;
    /* unchanged: the file comes back byte for byte (to .msh: the origin wins over gmsh) */
    CHECK(cm_mesh_write(ctx, m, work(name), NULL) == CM_OK);
    size_t n0, n1;
    char *d0 = test_read_file(fixture(name), &n0), *d1 = test_read_file(work(name), &n1);
    CHECK_MSG(d1 && n0 == n1 && !memcmp(d0, d1, n0), "%s: unchanged mesh not written back byte for byte", name);
    free(d1);
    /* an affine motion of every node */
    const double A[9] = {1.1, 0.2, -0.05, 0.03, 0.95, 0.1, -0.02, 0.07, 1.3}, t[3] = {0.5, -1.25, 3e-3};
    double *x0 = malloc(3 * m->n_nodes * sizeof *x0);
    memcpy(x0, m->xyz, 3 * m->n_nodes * sizeof *x0);
    for (size_t i = 0; i < m->n_nodes; ++i)
        for (int r = 0; r < 3; ++r)
            m->xyz[3 * i + r] = A[3 * r] * x0[3 * i] + A[3 * r + 1] * x0[3 * i + 1] + A[3 * r + 2] * x0[3 * i + 2] + t[r];
    char out[512];
    snprintf(out, sizeof out, "%s", work(name));
    char *dot = strrchr(out, '.');
    snprintf(dot, 16, "_moved.cas");
    CHECK_MSG(cm_mesh_write(ctx, m, out, NULL) == CM_OK, "%s", cm_context_message(ctx));
    cm_mesh *r = read_ok(ctx, out);
    if (r) {
        CHECK(r->n_nodes == m->n_nodes && r->n_cells == m->n_cells);
        double worst = 0;
        for (size_t i = 0; i < 3 * m->n_nodes; ++i) {
            const double e = fabs(r->xyz[i] - m->xyz[i]) / (fabs(m->xyz[i]) > 1 ? fabs(m->xyz[i]) : 1);
            if (e > worst) worst = e;
        }
        CHECK_MSG(worst <= tol, "%s: moved nodes read back within %g, expected %g", name, worst, tol);
        CHECK(!memcmp(r->conn, m->conn, (size_t)m->offset[m->n_cells] * sizeof *m->conn));
    }
    cm_mesh_destroy(&r);
    CHECK_MSG(same_outside_spans(ctx, fixture(name), out), "%s: bytes outside the node coordinates changed", name);
    /* moved nodes come back; unmoved ones keep their text */
    memcpy(m->xyz, x0, 3 * m->n_nodes * sizeof *x0);
    CHECK(cm_mesh_write(ctx, m, work("back.msh"), NULL) == CM_OK);
    d1 = test_read_file(work("back.msh"), &n1);
    CHECK_MSG(d1 && n0 == n1 && !memcmp(d0, d1, n0), "%s: moved back, not the original bytes", name);
    free(d1);
    free(d0);
    /* more cells than were read: no longer the file's mesh */
    const int64_t nodes[3] = {0, 1, 2};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, nodes, 3, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_write(ctx, m, work("changed.msh"), NULL) == CM_ERR_UNSUPPORTED);
    CHECK(strstr(cm_context_message(ctx), "changed") != NULL);
    CHECK(cm_mesh_write(ctx, m, work("changed.vtu"), NULL) == CM_OK);
    free(x0);
    cm_mesh_destroy(&m);
}

/* A hostile variant of a fixture: the read fails with the message naming the file and want. */
static void hostile(cm_context *ctx, const char *name, const char *text, size_t n, const char *want)
{
    const char *path = work(name);
    test_write_file(path, text, n);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    const char *msg = cm_context_message(ctx);
    CHECK_MSG(s < 0 && !m, "%s: read", name);
    CHECK_MSG(strstr(msg, path) && strstr(msg, want) && !strchr(msg, '\n'), "%s: %s (want '%s')", name, msg, want);
    cm_mesh_destroy(&m);
}

/* text with the first occurrence of from replaced by to */
static char *edit(const char *text, const char *from, const char *to, size_t *n)
{
    const char *at = strstr(text, from);
    if (!at) return NULL;
    const size_t a = (size_t)(at - text), lf = strlen(from), lt = strlen(to), len = strlen(text);
    char *d = malloc(len - lf + lt + 1);
    memcpy(d, text, a);
    memcpy(d + a, to, lt);
    memcpy(d + a + lt, at + lf, len - a - lf + 1);
    *n = len - lf + lt;
    return d;
}

static void test_hostile(cm_context *ctx)
{
    size_t n = 0, nb = 0, ne = 0;
    char *box = test_read_file(fixture("box.msh"), &n);
    char *bin = test_read_file(fixture("box_double.msh"), &nb);
    /* truncations (every 29th / 11th byte: the files are written to disk) fail cleanly, or
     * read: a cut in trailing blanks */
    int crashes = 0;
    for (size_t k = 0; k < n; k += 29) {
        test_write_file(work("cut.msh"), box, k);
        cm_mesh *m = NULL;
        cm_status s = cm_mesh_read(ctx, work("cut.msh"), &m);
        crashes += s < 0 ? m != NULL || strchr(cm_context_message(ctx), '\n') != NULL : m == NULL;
        cm_mesh_destroy(&m);
    }
    for (size_t k = 0; k < nb; k += 11) {
        test_write_file(work("cutb.msh"), bin, k);
        cm_mesh *m = NULL;
        cm_status s = cm_mesh_read(ctx, work("cutb.msh"), &m);
        crashes += s < 0 ? m != NULL || strchr(cm_context_message(ctx), '\n') != NULL : m == NULL;
        cm_mesh_destroy(&m);
    }
    CHECK(crashes == 0);
    char *e;
    /* more nodes in the header than in the data */
    if ((e = edit(box, "(10 (1 1 24 1 3)", "(10 (1 1 25 1 3)", &ne))) hostile(ctx, "count.msh", e, ne, ".msh:49: expected a node coordinate"), free(e);
    /* fewer */
    if ((e = edit(box, "(10 (1 1 24 1 3)", "(10 (1 1 23 1 3)", &ne))) hostile(ctx, "count2.msh", e, ne, ".msh:48: expected ')' after the node coordinates"), free(e);
    /* a NaN coordinate */
    if ((e = edit(box, "0.0000000000e+00", "nan", &ne))) hostile(ctx, "nan.msh", e, ne, ".msh:13: a node coordinate is not a finite number"), free(e);
    /* a face naming a node that does not exist, a cell that does not exist */
    if ((e = edit(box, "4 2 6 12 e 2 1", "4 2 6 12 fff 2 1", &ne))) hostile(ctx, "node.msh", e, ne, ".msh:53: face names a missing node fff"), free(e);
    if ((e = edit(box, " 2 1\n", " 2 99\n", &ne))) hostile(ctx, "cell.msh", e, ne, ".msh:53: face names a missing cell c1 99"), free(e);
    /* a face line of the wrong length */
    if ((e = edit(box, " 2 1\n", " 2\n", &ne))) hostile(ctx, "short.msh", e, ne, "a face's line does not match its type"), free(e);
    /* unterminated lists and strings */
    if ((e = edit(box, "(39 (1 fluid fluid-1)())", "(39 (1 fluid fluid-1)(", &ne))) hostile(ctx, "open.msh", e, ne, "unterminated section"), free(e);
    if ((e = edit(box, "(0 \"Dimension:\")", "(0 \"Dimension:)", &ne))) hostile(ctx, "string.msh", e, ne, "unterminated"), free(e);
    /* a 2-D file, a hanging-node tree, a huge count */
    if ((e = edit(box, "(2 3)", "(2 2)", &ne))) hostile(ctx, "2d.msh", e, ne, "2-D Fluent mesh"), free(e);
    if ((e = edit(box, "(0 \"Dimension:\")", "(59 (1 2 3 4)())", &ne))) hostile(ctx, "tree.msh", e, ne, "hanging-node trees"), free(e);
    if ((e = edit(box, "(10 (1 1 24 1 3)", "(10 (1 1 fffffffffff 1 3)", &ne))) hostile(ctx, "huge.msh", e, ne, "more nodes than the file has bytes"), free(e);
    if ((e = edit(box, "(12 (0 1 c 0 0))", "(12 (0 1 ffffffffff 0 0))", &ne))) hostile(ctx, "cells.msh", e, ne, "faces to close them"), free(e);
    /* binary: a broken trailer, a face naming a missing node */
    if ((e = edit(bin, "End of Binary Section   3010", "End of Binary Section   3013", &ne))) hostile(ctx, "trailer.msh", e, ne, "trailer names another section"), free(e);
    char *b2 = malloc(nb);
    memcpy(b2, bin, nb);
    const char *key = "(3013 (2 1 14 2 0)(", *faces = NULL;
    for (size_t k = 0; !faces && k + strlen(key) <= nb; ++k)
        if (!memcmp(b2 + k, key, strlen(key))) faces = b2 + k;
    CHECK(faces != NULL);
    if (faces) {
        const int32_t big = 0x7ffffff;
        memcpy(b2 + (faces - b2) + strlen("(3013 (2 1 14 2 0)(") + 4, &big, 4); /* the first face's first node */
        hostile(ctx, "binnode.msh", b2, nb, "byte ");
    }
    free(b2);
    free(box);
    free(bin);
}

/* A case file's other sections (header, rp variables with parentheses in strings, periodic
 * shadow faces, an unknown binary section whose data holds parentheses) are skipped and kept. */
static void test_case_sections(cm_context *ctx)
{
    size_t n = 0;
    char *box = test_read_file(fixture("box.msh"), &n);
    static const char extra[] = "(1 \"header (with a parenthesis\")\n"
                                "(37 ((\"rp\" \"a string ) with \\\" quote\" (nested (list)))))\n"
                                "(18 (1 2 3 4)(\n1 2\n))\n"
                                "(2064 (1 2)(\x01()(\n))\nEnd of Binary Section   2064)\n";
    const size_t ne = sizeof extra - 1;
    char *cas = malloc(n + ne);
    memcpy(cas, extra, ne);
    memcpy(cas + ne, box, n);
    test_write_file(work("case.cas"), cas, n + ne);
    cm_mesh *a = read_ok(ctx, fixture("box.msh")), *b = read_ok(ctx, work("case.cas"));
    if (a && b) {
        CHECK(a->n_cells == b->n_cells && !memcmp(a->xyz, b->xyz, 3 * a->n_nodes * sizeof *a->xyz));
        for (size_t i = 0; i < 3 * b->n_nodes; ++i) b->xyz[i] *= 2;
        CHECK(cm_mesh_write(ctx, b, work("case2.cas"), NULL) == CM_OK);
        CHECK(same_outside_spans(ctx, work("case.cas"), work("case2.cas")));
        cm_mesh *c = read_ok(ctx, work("case2.cas"));
        for (size_t i = 0; c && i < 3 * c->n_nodes; ++i) CHECK(c->xyz[i] == 2 * a->xyz[i]);
        cm_mesh_destroy(&c);
    }
    cm_mesh_destroy(&a);
    cm_mesh_destroy(&b);
    free(cas);
    free(box);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_fluent <tests/data> <work dir>\n");
        return 2;
    }
    data_dir = argv[1];
    work_dir = argv[2];
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_formats(ctx);
    test_read(ctx);
    test_write_back(ctx, "box.msh", 0);
    test_write_back(ctx, "mixed.msh", 0);
    test_write_back(ctx, "poly.msh", 0);
    test_write_back(ctx, "box_double.msh", 0);
    test_write_back(ctx, "poly_double.msh", 0);
    test_write_back(ctx, "mixed_single.msh", 6e-8); /* single precision: float rounding */
    test_case_sections(ctx);
    test_hostile(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
