/* Surface formats .obj, .off, .stl (binary and ASCII): round trips through our own writer and
 * reader, hostile files (huge counts, truncated binary STL, NaN, indices out of range) with
 * their file:line (or byte) in the message. `test_surface_io convert IN OUT` converts a file
 * (used by test_surface_io_meshio.py against meshio's files). */
#include "cadmorph/mesh.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static const char *work_dir;

/* A 3x2 grid of quads split into 2 triangles on one side, plus a pentagon, a line, a tet. */
static cm_mesh *sample_mesh(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, 13, 0) == CM_OK);
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i) {
            double *x = m->xyz + 3 * (4 * j + i);
            x[0] = 0.1 * i + 1.0 / 3.0, x[1] = 0.25 * j, x[2] = 1e-3 * i * j;
        }
    m->xyz[36] = 0.5, m->xyz[37] = 0.75, m->xyz[38] = -0.125;
    const int64_t q0[4] = {0, 1, 5, 4}, q1[4] = {1, 2, 6, 5}, t0[3] = {2, 3, 7}, t1[3] = {2, 7, 6};
    const int64_t pent[5] = {4, 5, 9, 12, 8}, q2[4] = {5, 6, 10, 9}, q3[4] = {6, 7, 11, 10};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, q0, 4, 1, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, q1, 4, 1, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, t0, 3, 1, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, t1, 3, 2, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POLYGON, pent, 5, 2, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, q2, 4, 2, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, q3, 4, 2, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_group(ctx, m, 2, 1, "left side") == CM_OK);
    CHECK(cm_mesh_add_group(ctx, m, 2, 2, "right") == CM_OK);
    return m;
}

static void path_of(char *buf, size_t n, const char *name)
{
    snprintf(buf, n, "%s/%s", work_dir, name);
}

/* Area-weighted normal sum and area of the faces: the same for any triangulation. */
static void surface_moments(const cm_mesh *m, double *area, double *nsum)
{
    *area = 0, nsum[0] = nsum[1] = nsum[2] = 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        if (m->type[c] != CM_CELL_TRI3 && m->type[c] != CM_CELL_QUAD4 && m->type[c] != CM_CELL_POLYGON) continue;
        const int64_t *v = m->conn + m->offset[c];
        size_t n = (size_t)(m->offset[c + 1] - m->offset[c]);
        for (size_t k = 1; k + 1 < n; ++k) {
            const double *a = m->xyz + 3 * v[0], *b = m->xyz + 3 * v[k], *d = m->xyz + 3 * v[k + 1];
            double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
            double cr[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
            for (int j = 0; j < 3; ++j) nsum[j] += 0.5 * cr[j];
            *area += 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
        }
    }
}

static void test_round_trips(void)
{
    cm_mesh *m = sample_mesh();
    double a0, n0[3];
    surface_moments(m, &a0, n0);
    static const struct {
        const char *name;
        int binary, exact, keeps_polygons, keeps_groups;
    } v[] = {
        {"srt.obj", 0, 1, 1, 1}, {"srt.off", 0, 1, 1, 0}, {"srt_ascii.stl", 0, 1, 0, 0}, {"srt_bin.stl", 1, 0, 0, 0},
    };
    for (size_t k = 0; k < sizeof v / sizeof *v; ++k) {
        char path[2048];
        path_of(path, sizeof path, v[k].name);
        cm_mesh_write_options o;
        cm_mesh_write_options_init(&o);
        o.binary = v[k].binary;
        CHECK_MSG(cm_mesh_write(ctx, m, path, &o) == CM_OK, "%s: %s", v[k].name, cm_context_message(ctx));
        cm_mesh *b = NULL;
        cm_status s = cm_mesh_read(ctx, path, &b);
        CHECK_MSG(s == CM_OK, "%s: %s", v[k].name, cm_context_message(ctx));
        if (!b) continue;
        /* STL merges corners: all 13 nodes are used by faces, so all 13 come back */
        CHECK_MSG(b->n_nodes == 13, "%s: %zu nodes", v[k].name, b->n_nodes);
        if (v[k].keeps_polygons) {
            CHECK(b->n_cells == m->n_cells);
            for (size_t c = 0; c < m->n_cells && c < b->n_cells; ++c) {
                CHECK(b->type[c] == m->type[c]);
                CHECK(!memcmp(b->conn + b->offset[c], m->conn + m->offset[c],
                              (size_t)(m->offset[c + 1] - m->offset[c]) * sizeof(int64_t)));
            }
        } else {
            CHECK_MSG(b->n_cells == 13, "%s: %zu triangles (4 quads x 2 + pentagon 3 + 2)", v[k].name, b->n_cells);
        }
        if (v[k].exact && v[k].keeps_polygons) {
            CHECK(!memcmp(b->xyz, m->xyz, 39 * sizeof(double)));
        }
        double a1, n1[3];
        surface_moments(b, &a1, n1);
        double tol = v[k].exact ? 1e-15 : 1e-7;
        CHECK_NEAR(a1, a0, tol);
        for (int j = 0; j < 3; ++j) CHECK_NEAR(n1[j], n0[j], tol);
        if (v[k].keeps_groups) {
            CHECK(b->n_groups == 2);
            CHECK(b->n_groups == 2 && !strcmp(b->groups[0].name, "left side") && b->physical[4] == 2);
        }
        cm_mesh_destroy(&b);
    }
    /* a volume cell is left out with a warning, the faces are still written */
    const int64_t tet[4] = {0, 1, 4, 12};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet, 4, 0, 0, 0) == CM_OK);
    const char *names[] = {"sw.obj", "sw.off", "sw.stl"};
    for (int k = 0; k < 3; ++k) {
        char path[2048];
        path_of(path, sizeof path, names[k]);
        cm_status s = cm_mesh_write(ctx, m, path, NULL);
        CHECK_MSG(s == CM_WARNING && strstr(cm_context_message(ctx), "not written"), "%s: %d %s", names[k], s,
                  cm_context_message(ctx));
        cm_mesh *b = NULL;
        CHECK(cm_mesh_read(ctx, path, &b) == CM_OK);
        CHECK(b && cm_mesh_count_dim(b, 3) == 0 && cm_mesh_count_dim(b, 2) >= 7);
        cm_mesh_destroy(&b);
    }
    cm_mesh_destroy(&m);
}

static void write_bytes(const char *name, const void *data, size_t n, char *path, size_t pn)
{
    path_of(path, pn, name);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f) return;
    fwrite(data, 1, n, f);
    fclose(f);
}

/* Each hostile file must be refused with a message naming the file and `where` (a line
 * "name:L:" or a byte offset) and containing `what`. */
static void expect_refused(const char *name, const char *text, size_t n, const char *where, const char *what)
{
    char path[2048];
    write_bytes(name, text, n ? n : strlen(text), path, sizeof path);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    const char *msg = cm_context_message(ctx);
    CHECK_MSG(s < 0 && m == NULL, "%s: accepted", name);
    char loc[2200];
    snprintf(loc, sizeof loc, "%s%s", path, where);
    CHECK_MSG(s < 0 && strstr(msg, loc) && strstr(msg, what), "%s: message '%s' lacks '%s' / '%s'", name, msg, loc, what);
    cm_mesh_destroy(&m);
}

static void test_hostile(void)
{
    /* OBJ */
    expect_refused("h_nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", 0, ":3:", "not finite");
    expect_refused("h_inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n", 0, ":3:", "not finite");
    expect_refused("h_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", 0, ":4:", "out of range");
    expect_refused("h_zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n# c\nf 0 1 2\n", 0, ":5:", "out of range");
    expect_refused("h_forward.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n", 0, ":3:", "out of range");
    expect_refused("h_huge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n", 0, ":4:", "vertex index");
    expect_refused("h_word.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nfx 1 2 3\n", 0, ":4:", "unknown OBJ statement");
    expect_refused("h_short.obj", "v 0 0\n", 0, ":1:", "expected 'v x y z");
    expect_refused("h_empty.obj", "# nothing\n", 0, "", "no vertices");
    /* OFF */
    expect_refused("h_count.off", "OFF\n4000000000000 1 0\n0 0 0\n", 0, ":2:", "do not fit");
    expect_refused("h_neg.off", "OFF\n3 -1 0\n0 0 0\n1 0 0\n0 1 0\n", 0, ":2:", "do not fit");
    expect_refused("h_nan.off", "OFF\n3 1 0\n0 0 0\n1 NaN 0\n0 1 0\n3 0 1 2\n", 0, ":4:", "not finite");
    expect_refused("h_range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", 0, ":6:", "out of range");
    expect_refused("h_trunc.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", 0, ":7:", "end of file");
    expect_refused("h_face.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n900000000 0 1 2\n", 0, ":6:", "vertices");
    expect_refused("h_head.off", "4OFF\n3 1 0\n", 0, ":1:", "not supported");
    expect_refused("h_bin.off", "OFF BINARY\n", 0, ":1:", "binary OFF");
    /* ASCII STL */
    const char *tri = "solid s\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 %s 0\n"
                      " endloop\nendfacet\nendsolid s\n";
    char buf[512];
    snprintf(buf, sizeof buf, tri, "nan");
    expect_refused("h_nan_a.stl", buf, 0, ":6:", "not finite");
    snprintf(buf, sizeof buf, tri, "1");
    buf[strlen(buf) - 31] = 0; /* cut inside the last vertex line */
    expect_refused("h_trunc_a.stl", buf, 0, ":", "end of file");
    expect_refused("h_word_a.stl", "solid s\nfacet normal 0 0 1\n outer loops\n", 0, ":3:", "expected 'loop'");
    /* binary STL */
    unsigned char bin[84 + 2 * 50];
    memset(bin, 0, sizeof bin);
    bin[80] = 2;
    float one = 1.0f, nanf_ = NAN;
    memcpy(bin + 84 + 12 + 12, &one, 4);
    memcpy(bin + 84 + 12 + 28, &one, 4);
    memcpy(bin + 134 + 12 + 12, &one, 4);
    memcpy(bin + 134 + 12 + 32, &one, 4);
    char path[2048];
    write_bytes("ok_bin.stl", bin, sizeof bin, path, sizeof path);
    cm_mesh *m = NULL;
    CHECK_MSG(cm_mesh_read(ctx, path, &m) == CM_OK, "%s", cm_context_message(ctx));
    CHECK(m && m->n_nodes == 4 && m->n_cells == 2); /* the shared corners (0,0,0), (1,0,0) merged */
    cm_mesh_destroy(&m);
    expect_refused("h_trunc_b.stl", (const char *)bin, sizeof bin - 7, ": binary STL", "truncated");
    expect_refused("h_short_b.stl", (const char *)bin, 40, ":", "too short");
    unsigned char huge[84 + 50];
    memcpy(huge, bin, sizeof huge);
    huge[80] = huge[81] = huge[82] = huge[83] = 0xff; /* 4,294,967,295 triangles claimed */
    expect_refused("h_count_b.stl", (const char *)huge, sizeof huge, ": binary STL", "4294967295 triangles");
    memcpy(bin + 134 + 12 + 20, &nanf_, 4);
    expect_refused("h_nan_b.stl", (const char *)bin, sizeof bin, ": byte 166", "not finite");
}

static int convert(const char *in, const char *out, int binary)
{
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, in, &m);
    if (s >= 0) {
        cm_mesh_write_options o;
        cm_mesh_write_options_init(&o);
        o.binary = binary;
        s = cm_mesh_write(ctx, m, out, &o);
    }
    if (s < 0) fprintf(stderr, "convert: %s\n", cm_context_message(ctx));
    cm_mesh_destroy(&m);
    return s < 0;
}

int main(int argc, char **argv)
{
    if (cm_context_create(&ctx) != CM_OK) return 1;
    if (argc >= 4 && !strcmp(argv[1], "convert")) {
        int rc = convert(argv[2], argv[3], argc < 5 || strcmp(argv[4], "ascii"));
        cm_context_destroy(&ctx);
        return rc;
    }
    work_dir = argc > 2 ? argv[2] : ".";
    test_round_trips();
    test_hostile();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
