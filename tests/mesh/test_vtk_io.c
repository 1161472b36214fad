/* .vtu / legacy .vtk / Medit .mesh I/O on files written by VTK 9, meshio and gmsh
 * (tests/data/vtk, see generate.py there): every variant reads to the same mesh, and every
 * variant we write reads back bit-exactly. Dumps go to WORK/vtk for test_vtk_crosscheck.py,
 * which compares them with what VTK and meshio read. */
#define _POSIX_C_SOURCE 200809L
#include "test_vtk_common.h"

#include <dirent.h>
#include <math.h>
#include <stdlib.h>
#include <sys/stat.h>

static const char *data_dir, *work_dir;
static cm_context *ctx;

static void path_in(char *buf, size_t n, const char *dir, const char *name)
{
    snprintf(buf, n, "%s/%s", dir, name);
}

static cm_mesh *read_fixture(const char *name)
{
    char p[2100];
    path_in(p, sizeof p, data_dir, name);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, p, &m);
    CHECK_MSG(s == CM_OK, "%s: %s", name, cm_context_message(ctx));
    if (m) {
        char d[2100], dn[300];
        snprintf(dn, sizeof dn, "fx_%s.dump", name);
        path_in(d, sizeof d, work_dir, dn);
        CHECK(mesh_dump(m, d));
    }
    return m;
}

static int close_to(const cm_mesh *a, const cm_mesh *b, double rel)
{
    if (a->n_nodes != b->n_nodes) return 0;
    for (size_t i = 0; i < 3 * a->n_nodes; ++i)
        if (fabs(a->xyz[i] - b->xyz[i]) > rel * (1 + fabs(a->xyz[i]))) return 0;
    return 1;
}

static int same_cells(const cm_mesh *a, const cm_mesh *b)
{
    if (a->n_cells != b->n_cells) return 0;
    for (size_t c = 0; c <= a->n_cells; ++c)
        if (a->offset[c] != b->offset[c]) return 0;
    return !memcmp(a->type, b->type, a->n_cells) &&
           !memcmp(a->conn, b->conn, (size_t)a->offset[a->n_cells] * sizeof(int64_t));
}

/* The mixed grid of generate.py: every VTK XML encoding and the binary legacy file read to
 * the same mesh, bit for bit, including fields and gmsh tags. */
static void test_vtk_fixtures(cm_mesh **reference)
{
    static const char *exact[] = {
        "vtk_binary_u32.vtu",        "vtk_binary_u64.vtu",           "vtk_binary_zlib_u32.vtu",
        "vtk_appended_raw_u32.vtu",  "vtk_appended_raw_zlib_u64.vtu", "vtk_appended_b64_u32.vtu",
        "vtk_appended_b64_zlib_u64.vtu", "vtk_ascii.vtu",            "vtk_legacy_binary.vtk"};
    cm_mesh *ref = read_fixture("vtk_binary_zlib_u64.vtu");
    *reference = ref;
    if (!ref) return;
    for (size_t i = 0; i < sizeof exact / sizeof *exact; ++i) {
        cm_mesh *m = read_fixture(exact[i]);
        if (m) CHECK_MSG(mesh_same(ref, m, CMP_FIELDS | CMP_TAGS, exact[i]), "%s", exact[i]);
        cm_mesh_destroy(&m);
    }
    /* VTK's legacy ASCII writer prints 11 significant digits: equal to that precision. */
    cm_mesh *m = read_fixture("vtk_legacy_ascii.vtk");
    if (m) {
        CHECK(close_to(ref, m, 1e-9));
        CHECK(same_cells(ref, m));
    }
    cm_mesh_destroy(&m);

    /* what generate.py put in */
    static const cm_cell_type types[12] = {CM_CELL_HEX8,  CM_CELL_PYR5,  CM_CELL_WEDGE6, CM_CELL_WEDGE6,
                                           CM_CELL_TET4,  CM_CELL_TET4,  CM_CELL_TRI3,   CM_CELL_TRI3,
                                           CM_CELL_QUAD4, CM_CELL_LINE2, CM_CELL_POINT,  CM_CELL_POLYHEDRON};
    static const int phys[12] = {1, 1, 2, 2, 3, 3, 10, 11, 12, 0, 0, 4};
    CHECK(ref->n_nodes == 22 && ref->n_cells == 12);
    if (ref->n_cells != 12) return;
    for (int c = 0; c < 12; ++c) {
        CHECK_MSG(ref->type[c] == types[c], "cell %d type %d", c, ref->type[c]);
        CHECK(ref->physical[c] == phys[c] && ref->entity[c] == 100 * phys[c] + 1);
    }
    const int64_t *poly = ref->conn + ref->offset[11];
    CHECK(poly[0] == 6 && ref->offset[12] - ref->offset[11] == 31 && poly[1] == 4 && poly[2] == 14);
    const cm_field *f = cm_mesh_find_field(ref, "i64", CM_FIELD_CELL);
    CHECK(f && f->data[5] == 5e12);
    f = cm_mesh_find_field(ref, "i8", CM_FIELD_CELL);
    CHECK(f && f->data[0] == -3);
    f = cm_mesh_find_field(ref, "u8", CM_FIELD_CELL);
    CHECK(f && f->data[11] == 220);
    f = cm_mesh_find_field(ref, "displacement", CM_FIELD_NODE);
    CHECK(f && f->components == 3);
    f = cm_mesh_find_field(ref, "temperature", CM_FIELD_NODE);
    CHECK(f && f->data[3] == (double)(float)f->data[3] && f->data[3] != 0);
    CHECK(cm_mesh_find_field(ref, "gmsh:physical", CM_FIELD_CELL) == NULL);
}

static void test_big_endian(void)
{
    char p[2100];
    path_in(p, sizeof p, data_dir, "vtk_bigendian.vtu");
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, p, &m);
    CHECK(s == CM_ERR_UNSUPPORTED && !m && strstr(cm_context_message(ctx), "BigEndian"));
}

/* meshio writes the same small mesh in every format it has. */
static void test_meshio_fixtures(void)
{
    cm_mesh *ref = read_fixture("meshio_binary.vtu");
    if (!ref) return;
    static const char *exact[] = {"meshio_raw.vtu", "meshio_binary.vtk", "meshio_42.vtk", "meshio.mesh"};
    for (size_t i = 0; i < sizeof exact / sizeof *exact; ++i) {
        cm_mesh *m = read_fixture(exact[i]);
        if (m) CHECK_MSG(mesh_same(ref, m, 0, exact[i]), "%s", exact[i]);
        if (m && strstr(exact[i], ".mesh")) {
            /* Medit references come from meshio's medit:ref cell data */
            const cm_field *r = cm_mesh_find_field(ref, "medit:ref", CM_FIELD_CELL);
            CHECK(r != NULL);
            for (size_t c = 0; r && c < m->n_cells; ++c) CHECK(m->physical[c] == (int)r->data[c]);
        } else if (m) {
            CHECK(cm_mesh_find_field(m, "medit:ref", CM_FIELD_CELL) != NULL);
            CHECK(cm_mesh_find_field(m, "displacement", CM_FIELD_NODE) != NULL);
        }
        cm_mesh_destroy(&m);
    }
    static const char *ascii[] = {"meshio_ascii.vtu", "meshio_ascii.vtk"};
    for (size_t i = 0; i < 2; ++i) {
        cm_mesh *m = read_fixture(ascii[i]);
        if (m) CHECK_MSG(close_to(ref, m, 1e-9) && same_cells(ref, m), "%s", ascii[i]);
        cm_mesh_destroy(&m);
    }
    cm_mesh_destroy(&ref);
}

/* gmsh writes the same mesh as .vtk, .mesh and .msh: the Medit file (which gmsh 4.8 writes
 * without its prisms) must list the same cells, in the same node order, as the .vtk file. */
static void test_gmsh_fixtures(void)
{
    cm_mesh *v = read_fixture("gmsh_blocks.vtk");
    cm_mesh *m = read_fixture("gmsh_blocks.mesh");
    if (v && m) {
        CHECK(close_to(v, m, 1e-12));
        static const cm_cell_type kinds[] = {CM_CELL_TRI3, CM_CELL_QUAD4, CM_CELL_TET4, CM_CELL_HEX8};
        for (size_t k = 0; k < 4; ++k) {
            size_t cv = 0, cm = 0, bad = 0;
            while (1) {
                while (cv < v->n_cells && v->type[cv] != kinds[k]) ++cv;
                while (cm < m->n_cells && m->type[cm] != kinds[k]) ++cm;
                if (cv >= v->n_cells || cm >= m->n_cells) break;
                bad += memcmp(v->conn + v->offset[cv], m->conn + m->offset[cm],
                              (size_t)(v->offset[cv + 1] - v->offset[cv]) * sizeof(int64_t)) != 0;
                ++cv;
                ++cm;
            }
            CHECK_MSG(bad == 0 && cv >= v->n_cells && cm >= m->n_cells, "%s: %zu cells differ",
                      cm_cell_type_info(kinds[k])->name, bad);
        }
        CHECK(cm_mesh_count_dim(m, 3) > 0);
        /* gmsh's CellEntityIds stays a plain field */
        CHECK(cm_mesh_find_field(v, "CellEntityIds", CM_FIELD_CELL) != NULL);
    }
    cm_mesh_destroy(&v);
    cm_mesh_destroy(&m);
}

static void write_read(const cm_mesh *ref, const char *name, int binary, int compress, int appended,
                       int what)
{
    char p[2100];
    path_in(p, sizeof p, work_dir, name);
    cm_mesh_write_options o;
    cm_mesh_write_options_init(&o);
    o.binary = binary;
    o.compress = compress;
    o.appended = appended;
    cm_status s = cm_mesh_write(ctx, ref, p, &o);
    CHECK_MSG(s == CM_OK, "%s: %s", name, cm_context_message(ctx));
    cm_mesh *m = NULL;
    s = cm_mesh_read(ctx, p, &m);
    CHECK_MSG(s == CM_OK, "%s: %s", name, cm_context_message(ctx));
    if (m) CHECK_MSG(mesh_same(ref, m, what, name), "%s", name);
    cm_mesh_destroy(&m);
}

/* The cells Medit can hold, in the order our writer puts its sections. */
static cm_mesh *medit_subset(const cm_mesh *ref)
{
    static const cm_cell_type order[] = {CM_CELL_LINE2, CM_CELL_TRI3,  CM_CELL_QUAD4, CM_CELL_TET4,
                                         CM_CELL_PYR5,  CM_CELL_WEDGE6, CM_CELL_HEX8};
    cm_mesh *m = NULL;
    if (cm_mesh_create(ctx, &m) != CM_OK) return NULL;
    cm_mesh_resize_nodes(ctx, m, ref->n_nodes, 0);
    memcpy(m->xyz, ref->xyz, 3 * ref->n_nodes * sizeof(double));
    for (size_t k = 0; k < sizeof order / sizeof *order; ++k)
        for (size_t c = 0; c < ref->n_cells; ++c)
            if (ref->type[c] == order[k])
                cm_mesh_add_cell(ctx, m, order[k], ref->conn + ref->offset[c],
                                 (size_t)(ref->offset[c + 1] - ref->offset[c]), ref->physical[c], 0, 0);
    return m;
}

static void test_round_trips(const cm_mesh *ref)
{
    char p[2100];
    path_in(p, sizeof p, work_dir, "rt_reference.dump");
    CHECK(mesh_dump(ref, p));
    const int all = CMP_FIELDS | CMP_TAGS;
    write_read(ref, "rt_ascii.vtu", 0, 0, 0, all);
    write_read(ref, "rt_inline.vtu", 1, 0, 0, all);
    write_read(ref, "rt_inline_zlib.vtu", 1, 1, 0, all);
    write_read(ref, "rt_appended.vtu", 1, 0, 1, all);
    write_read(ref, "rt_appended_zlib.vtu", 1, 1, 1, all);
    write_read(ref, "rt_ascii.vtk", 0, 0, 0, all);
    write_read(ref, "rt_binary.vtk", 1, 0, 0, all);

    /* Medit: no polyhedra (a clear error, no file left behind) */
    path_in(p, sizeof p, work_dir, "rt_refused.mesh");
    remove(p);
    CHECK(cm_mesh_write(ctx, ref, p, NULL) == CM_ERR_UNSUPPORTED);
    FILE *f = fopen(p, "r");
    CHECK(f == NULL);
    if (f) fclose(f);
    cm_mesh *sub = medit_subset(ref);
    if (sub) {
        path_in(p, sizeof p, work_dir, "rt_medit.dump");
        CHECK(mesh_dump(sub, p));
        write_read(sub, "rt_medit.mesh", 0, 0, 0, CMP_TAGS);
        /* meshio / VTK cross-checks of files without polyhedra or vertex cells */
        path_in(p, sizeof p, work_dir, "rt_std.dump");
        CHECK(mesh_dump(sub, p));
        write_read(sub, "rt_std_binary.vtk", 1, 0, 0, CMP_TAGS);
        write_read(sub, "rt_std_ascii.vtk", 0, 0, 0, CMP_TAGS);
        write_read(sub, "rt_std_inline_zlib.vtu", 1, 1, 0, CMP_TAGS);
        write_read(sub, "rt_std_appended.vtu", 1, 0, 1, CMP_TAGS);
        write_read(sub, "rt_std_ascii.vtu", 0, 0, 0, CMP_TAGS);
    }
    cm_mesh_destroy(&sub);
}

/* Enough data for many zlib blocks (and the OpenMP paths), with awkward doubles. */
static void test_many_blocks(void)
{
    const int n = 24;
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    if (!m) return;
    cm_mesh_resize_nodes(ctx, m, (size_t)(n + 1) * (n + 1) * (n + 1), 0);
    unsigned seed = 12345;
    for (int k = 0, i = 0; k <= n; ++k)
        for (int j = 0; j <= n; ++j)
            for (int l = 0; l <= n; ++l, ++i) {
                seed = seed * 1103515245u + 12345u;
                double jit = (double)(seed >> 8) / (1 << 24) * 1e-3;
                m->xyz[3 * i] = l / 3.0 + jit;
                m->xyz[3 * i + 1] = j / 7.0 - jit;
                m->xyz[3 * i + 2] = k * 0.1 + jit * jit;
            }
#define ID(l, j, k) ((int64_t)((k) * (n + 1) * (n + 1) + (j) * (n + 1) + (l)))
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int l = 0; l < n; ++l) {
                int64_t h[8] = {ID(l, j, k),         ID(l + 1, j, k),         ID(l + 1, j + 1, k),
                                ID(l, j + 1, k),     ID(l, j, k + 1),         ID(l + 1, j, k + 1),
                                ID(l + 1, j + 1, k + 1), ID(l, j + 1, k + 1)};
                cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, h, 8, (l + j + k) % 5, k, 0);
            }
    double *sj = NULL;
    cm_mesh_add_field(ctx, m, "scaled_jacobian", CM_FIELD_CELL, 1, &sj);
    for (size_t c = 0; sj && c < m->n_cells; ++c) sj[c] = 1.0 / (double)(c + 3);
    write_read(m, "big_inline_zlib.vtu", 1, 1, 0, CMP_FIELDS | CMP_TAGS);
    write_read(m, "big_appended_zlib.vtu", 1, 1, 1, CMP_FIELDS | CMP_TAGS);
    write_read(m, "big_binary.vtk", 1, 0, 0, CMP_FIELDS | CMP_TAGS);
    cm_mesh_destroy(&m);
}

/* A failed write leaves nothing; a good one leaves no temporary file (in a folder of its own:
 * the temporaries have short generic names). */
static void test_atomic_writes(const cm_mesh *ref)
{
    char dir[2100], p[2200];
    path_in(dir, sizeof dir, work_dir, "atomic");
    mkdir(dir, 0777);
    path_in(p, sizeof p, work_dir, "no_such_dir/x.vtu");
    CHECK(cm_mesh_write(ctx, ref, p, NULL) == CM_ERR_IO);
    path_in(p, sizeof p, dir, "ok.vtu");
    CHECK(cm_mesh_write(ctx, ref, p, NULL) == CM_OK);
    path_in(p, sizeof p, dir, "is_a_dir.vtu"); /* the rename fails: the temporary must go */
    mkdir(p, 0777);
    CHECK(cm_mesh_write(ctx, ref, p, NULL) == CM_ERR_IO);
    DIR *d = opendir(dir);
    CHECK(d != NULL);
    struct dirent *e;
    int tmp = 0, files = 0;
    while (d && (e = readdir(d))) {
        if (!strncmp(e->d_name, ".cm-", 4)) ++tmp; /* cm_outfile temporaries */
        files += e->d_name[0] != '.';
    }
    if (d) closedir(d);
    CHECK(tmp == 0);
    CHECK(files == 2);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s DATA_DIR WORK_DIR\n", argv[0]);
        return 2;
    }
    char buf[1024], wbuf[1024];
    snprintf(buf, sizeof buf, "%s/vtk", argv[1]);
    snprintf(wbuf, sizeof wbuf, "%s/vtk", argv[2]);
    data_dir = buf;
    work_dir = wbuf;
    mkdir(wbuf, 0777); /* the work dir is shared by all tests: ours is a subfolder */
    cm_context_create(&ctx);
    cm_mesh *ref = NULL;
    test_vtk_fixtures(&ref);
    test_big_endian();
    test_meshio_fixtures();
    test_gmsh_fixtures();
    if (ref) {
        test_round_trips(ref);
        test_atomic_writes(ref);
    }
    test_many_blocks();
    cm_mesh_destroy(&ref);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
