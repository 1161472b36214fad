/* Hostile input that is not a file: names every writer must turn into something
 * every reader accepts, a cell copied from the mesh's own connectivity, geometric growth,
 * one-line messages, and the registry of output temporaries a signal handler unlinks. */
#include "cadmorph/mesh.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static cm_context *ctx;
static const char *work_dir;

/* One tet with fields whose names no format holds as they are. */
static const char *const hostile[] = {"a\"b", "a\nb", "", "sp ace", "x%y", "\xc3\xbc", "t\tab\"\""};
#define N_HOSTILE (sizeof hostile / sizeof *hostile)

static cm_mesh *hostile_mesh(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, 4, 0) == CM_OK);
    const double xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(m->xyz, xyz, sizeof xyz);
    const int64_t tet[4] = {0, 1, 2, 3};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet, 4, 1, 1, 0) == CM_OK);
    CHECK(cm_mesh_add_group(ctx, m, 3, 1, "vol\"ume\n2") == CM_OK);
    for (size_t i = 0; i < N_HOSTILE; ++i) {
        double *d = NULL;
        /* names must differ for the mesh: suffix the index where the format keeps names */
        CHECK(cm_mesh_add_field(ctx, m, hostile[i], i % 2 ? CM_FIELD_NODE : CM_FIELD_CELL, 1, &d) == CM_OK);
        if (d)
            for (size_t k = 0; k < (i % 2 ? 4u : 1u); ++k) d[k] = (double)i + 0.5;
    }
    return m;
}

static void test_round_trips(void)
{
    static const struct {
        const char *name;
        int msh_version, binary, compress, appended;
    } variants[] = {
        {"rt.msh", 41, 0, 0, 0},  {"rtb.msh", 41, 1, 0, 0}, {"rt22.msh", 22, 0, 0, 0},
        {"rt22b.msh", 22, 1, 0, 0}, {"rt.vtu", 41, 0, 0, 0}, {"rtz.vtu", 41, 1, 1, 0},
        {"rta.vtu", 41, 1, 0, 1}, {"rt.vtk", 41, 0, 0, 0},  {"rtb.vtk", 41, 1, 0, 0},
        {"rt.mesh", 41, 0, 0, 0},   {"rt_foam_case", 41, 0, 0, 0},
    };
    cm_mesh *m = hostile_mesh();
    for (size_t v = 0; v < sizeof variants / sizeof *variants; ++v) {
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", work_dir, variants[v].name);
        cm_mesh_write_options o;
        cm_mesh_write_options_init(&o);
        o.msh_version = variants[v].msh_version;
        o.binary = variants[v].binary;
        o.compress = variants[v].compress;
        o.appended = variants[v].appended;
        cm_status s = cm_mesh_write(ctx, m, path, &o);
        CHECK_MSG(s >= 0, "%s: write: %s", variants[v].name, cm_context_message(ctx));
        cm_mesh *back = NULL;
        s = cm_mesh_read(ctx, path, &back);
        CHECK_MSG(s == CM_OK, "%s: read back: %s", variants[v].name, cm_context_message(ctx));
        if (back) {
            CHECK(back->n_nodes == 4);
            CHECK(cm_mesh_count_dim(back, 3) == 1);
            /* every field that went out comes back (under some name), except in Medit and
             * OpenFOAM polyMesh (geometry only) */
            if (!strstr(variants[v].name, ".mesh") && !strstr(variants[v].name, "foam"))
                CHECK_MSG(back->n_fields >= N_HOSTILE, "%s: %zu fields back", variants[v].name, back->n_fields);
            for (size_t f = 0; f < back->n_fields; ++f) CHECK(back->fields[f].name != NULL);
        }
        cm_mesh_destroy(&back);
    }
    cm_mesh_destroy(&m);
}

/* cm_mesh_add_cell with nodes pointing into the mesh: each copy may grow conn under them. */
static void test_add_cell_from_itself(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, 4, 0) == CM_OK);
    const int64_t tet[4] = {3, 2, 1, 0};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet, 4, 1, 1, 0) == CM_OK);
    int ok = 1;
    for (size_t i = 0; i < 5000 && ok; ++i) {
        const size_t c = m->n_cells - 1; /* the last cell: it sits at the end of conn */
        ok = cm_mesh_add_cell(ctx, m, CM_CELL_TET4, m->conn + m->offset[c], 4, 1, 1, 0) == CM_OK;
    }
    CHECK(ok);
    int same = 1;
    for (size_t c = 0; c < m->n_cells; ++c)
        for (int k = 0; k < 4; ++k) same &= m->conn[m->offset[c] + k] == tet[k];
    CHECK(same);
    cm_mesh_destroy(&m);
}

/* Many small reservations (one .msh element block each) grow the arrays geometrically. */
static void test_growth(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, 4, 0) == CM_OK);
    const int64_t tet[4] = {0, 1, 2, 3};
    size_t changes = 0, cap = m->cap_cells;
    for (size_t b = 0; b < 100000; ++b) {
        CHECK(cm_mesh_reserve_cells(ctx, m, 1, 4) == CM_OK);
        if (m->cap_cells != cap) ++changes, cap = m->cap_cells;
        cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet, 4, 1, 1, 0);
    }
    /* 1.5x growth from 16 to 1e5 is ~22 steps; exact-size growth was one per block */
    CHECK_MSG(changes < 40, "%zu reallocations for 100000 blocks", changes);
    cm_mesh_destroy(&m);
}

static void test_one_line_messages(void)
{
    cm_error(ctx, CM_ERR_FORMAT, "f.vtu:3: type '%s'", "Float64\nX\x1b[31m");
    const char *msg = cm_context_message(ctx);
    CHECK(strchr(msg, '\n') == NULL);
    CHECK(strchr(msg, '\x1b') == NULL);
    CHECK(strstr(msg, "Float64\\nX\\x1b[31m") != NULL);
}

/* A mesh with a non-finite coordinate is written in no format: rejected before anything is
 * created (a previous file stays as it was), naming the node and the coordinate. */
static void test_no_nonfinite_write(void)
{
    static const char *const names[] = {"nf.vtu", "nf.vtk", "nf.msh", "nf.mesh", "nf.obj", "nf.stl", "nf.off",
                                        "nf.su2", "nf.inp", "nf.bdf"};
    const double bad[3] = {NAN, INFINITY, -INFINITY};
    for (int b = 0; b < 3; ++b)
        for (size_t k = 0; k < sizeof names / sizeof *names; ++k) {
            cm_mesh *m = hostile_mesh();
            m->xyz[3 * 2 + 1] = bad[b];
            char path[1200];
            snprintf(path, sizeof path, "%s/%s", work_dir, names[k]);
            FILE *f = fopen(path, "w");
            if (f) fputs("previous", f), fclose(f);
            CHECK_MSG(cm_mesh_write(ctx, m, path, NULL) == CM_ERR_REJECTED, "%s", names[k]);
            const char *msg = cm_context_message(ctx);
            CHECK_MSG(strstr(msg, "node 2 (0-based, tag 3) has a non-finite coordinate (y = ") &&
                          strstr(msg, names[k]),
                      "%s", msg);
            char buf[16] = {0};
            f = fopen(path, "r");
            CHECK(f && fread(buf, 1, sizeof buf - 1, f) == 8 && !strcmp(buf, "previous"));
            if (f) fclose(f);
            remove(path);
            CHECK_MSG(cm_mesh_write(ctx, m, path, NULL) == CM_ERR_REJECTED, "%s", names[k]);
            struct stat st;
            CHECK_MSG(stat(path, &st) != 0, "%s was created", names[k]);
            cm_mesh_destroy(&m);
        }
}

static void test_temporary_registry(void)
{
    char path[2048];
    snprintf(path, sizeof path, "%s/registry_out.txt", work_dir);
    cm_outfile out;
    CHECK(cm_outfile_open(ctx, path, &out) == CM_OK);
    struct stat st;
    CHECK(out.tmp && stat(out.tmp, &st) == 0);
    /* the temporary is short, beside the output */
    CHECK(out.tmp && strlen(out.tmp) <= strlen(work_dir) + 12);
    cm_outfile_unlink_all();
    CHECK(out.tmp && stat(out.tmp, &st) != 0);
    cm_outfile_abort(&out);
    /* a committed file is no longer live: unlink_all leaves it */
    CHECK(cm_outfile_open(ctx, path, &out) == CM_OK);
    fputs("x\n", out.f);
    CHECK(cm_outfile_commit(ctx, &out) == CM_OK);
    cm_outfile_unlink_all();
    CHECK(stat(path, &st) == 0);
    /* an output name of 255 characters (NAME_MAX) */
    char name[256];
    memset(name, 'n', 251);
    memcpy(name + 251, ".vtk", 5);
    snprintf(path, sizeof path, "%s/%s", work_dir, name);
    cm_mesh *m = hostile_mesh();
    CHECK_MSG(cm_mesh_write(ctx, m, path, NULL) >= 0, "%s", cm_context_message(ctx));
    CHECK(stat(path, &st) == 0);
    remove(path);
    cm_mesh_destroy(&m);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s DATA_DIR WORK_DIR\n", argv[0]);
        return 2;
    }
    char wbuf[1024];
    snprintf(wbuf, sizeof wbuf, "%s/hostile", argv[2]);
    mkdir(wbuf, 0777); /* the work dir is shared by all tests: ours is a subfolder */
    work_dir = wbuf;
    cm_context_create(&ctx);
    test_round_trips();
    test_add_cell_from_itself();
    test_growth();
    test_one_line_messages();
    test_temporary_registry();
    test_no_nonfinite_write();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
