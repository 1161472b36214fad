/* Malformed .vtu / .vtk / .mesh input: each broken fixture (tests/data/vtk/bad, made by
 * generate.py from real VTK/meshio files) fails with CM_ERR_FORMAT naming the file and a
 * line or byte offset; and thousands of random corruptions of the good fixtures never crash
 * (a crash fails the test) and never return a mesh that breaks the mesh invariants. */
#include "cadmorph/mesh.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static cm_context *ctx;

typedef struct bad_case {
    const char *file;
    cm_status status;
    const char *where;  /* "line" (path:N:) or "offset" (byte offset N) */
    const char *words;  /* must appear in the message */
} bad_case;

static const bad_case cases[] = {
    {"truncated_appended.vtu", CM_ERR_FORMAT, "offset", "truncated"},
    {"truncated_inline.vtu", CM_ERR_FORMAT, "line", "truncated"},
    {"bad_base64.vtu", CM_ERR_FORMAT, "offset", "base64"},
    {"bad_zlib.vtu", CM_ERR_FORMAT, "offset", "zlib"},
    {"huge_block.vtu", CM_ERR_FORMAT, "offset", "compression header"},
    {"huge_nblocks.vtu", CM_ERR_FORMAT, "offset", "compression header"},
    {"wrong_npoints.vtu", CM_ERR_FORMAT, "line", "expected 69 values"},
    {"node_out_of_range.vtu", CM_ERR_FORMAT, "line", "out of range"},
    {"unknown_type.vtu", CM_ERR_FORMAT, "line", "cell type 99"},
    {"nan.vtu", CM_ERR_FORMAT, "line", "not finite"},
    {"not_xml.vtu", CM_ERR_FORMAT, "line", "XML"},
    {"node_out_of_range.vtk", CM_ERR_FORMAT, "line", "out of range"},
    {"unknown_type.vtk", CM_ERR_FORMAT, "line", "cell type 99"},
    {"nan.vtk", CM_ERR_FORMAT, "line", "not finite"},
    {"wrong_npoints.vtk", CM_ERR_FORMAT, "line", "point coordinate"},
    {"truncated_binary.vtk", CM_ERR_FORMAT, "line", "truncated"},
    {"truncated.mesh", CM_ERR_FORMAT, "line", "truncated"},
    {"node_out_of_range.mesh", CM_ERR_FORMAT, "line", "out of range"},
    {"nan.mesh", CM_ERR_FORMAT, "line", "not finite"},
    {"wrong_count.mesh", CM_ERR_FORMAT, "line", "vertex coordinate"},
    {"unknown.xyz", CM_ERR_UNSUPPORTED, "", "extension"},
    {"lz4.vtu", CM_ERR_UNSUPPORTED, "", "vtkLZ4DataCompressor"},
    {"missing.vtu", CM_ERR_IO, "", "cannot open"},
};

static void test_bad_files(const char *dir)
{
    for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
        char p[2100];
        snprintf(p, sizeof p, "%s/%s", dir, cases[i].file);
        cm_mesh *m = (cm_mesh *)1;
        cm_status s = cm_mesh_read(ctx, p, &m);
        const char *msg = cm_context_message(ctx);
        CHECK_MSG(s == cases[i].status && m == NULL, "%s: status %d: %s", cases[i].file, s, msg);
        CHECK_MSG(strstr(msg, p) != NULL, "%s: message does not name the file: %s", cases[i].file, msg);
        CHECK_MSG(strstr(msg, cases[i].words) != NULL, "%s: '%s' not in: %s", cases[i].file, cases[i].words, msg);
        if (!strcmp(cases[i].where, "offset")) {
            CHECK_MSG(strstr(msg, "byte offset ") != NULL, "%s: no byte offset: %s", cases[i].file, msg);
        } else if (!strcmp(cases[i].where, "line")) {
            char prefix[2200];
            snprintf(prefix, sizeof prefix, "%s:", p);
            const char *after = strstr(msg, prefix);
            CHECK_MSG(after && after[strlen(prefix)] >= '1' && after[strlen(prefix)] <= '9',
                      "%s: no line number: %s", cases[i].file, msg);
        }
        CHECK(strchr(msg, '\n') == NULL);
    }
}

static unsigned rng_state = 2463534242u;
static unsigned rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

/* Random byte flips, insertions of digits and truncations of a good file. */
static void fuzz(const char *dir, const char *work, const char *name, int rounds)
{
    char p[2100];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "rb");
    CHECK_MSG(f != NULL, "%s", p);
    if (!f) return;
    char *orig = malloc(1 << 20);
    size_t n = fread(orig, 1, 1 << 20, f);
    fclose(f);
    char *buf = malloc(n + 64);
    const char *ext = strrchr(name, '.');
    char q[2100];
    snprintf(q, sizeof q, "%s/fuzz%s", work, ext);
    int ok = 0, failed_cleanly = 0;
    for (int r = 0; r < rounds; ++r) {
        memcpy(buf, orig, n);
        size_t len = n;
        int edits = 1 + (int)(rnd() % 4);
        for (int e = 0; e < edits; ++e) {
            size_t at = rnd() % len;
            switch (rnd() % 4) {
            case 0: buf[at] = (char)rnd(); break;
            case 1: buf[at] = "0123456789-9e+."[rnd() % 15]; break;
            case 2: buf[at] = (char)(buf[at] ^ (1 << (rnd() % 8))); break;
            default: if (rnd() % 4 == 0) len = at + 1; break;
            }
        }
        f = fopen(q, "wb");
        fwrite(buf, 1, len, f);
        fclose(f);
        cm_mesh *m = NULL;
        cm_status s = cm_mesh_read(ctx, q, &m);
        if (s >= 0) {
            /* whatever was accepted is a valid mesh */
            ++ok;
            CHECK(m && cm_mesh_validate(ctx, m, q) == CM_OK);
        } else {
            failed_cleanly += m == NULL && cm_context_message(ctx)[0] != '\0';
            CHECK(m == NULL);
        }
        cm_mesh_destroy(&m);
    }
    CHECK(ok + failed_cleanly == rounds);
    printf("fuzz %s: %d rounds, %d still valid, %d rejected\n", name, rounds, ok, rounds - ok);
    free(buf);
    free(orig);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    cm_context_create(&ctx);
    char bad[1024], good[1024], work[1024];
    snprintf(work, sizeof work, "%s/vtk", argv[2]);
    mkdir(work, 0777);
    snprintf(bad, sizeof bad, "%s/vtk/bad", argv[1]);
    snprintf(good, sizeof good, "%s/vtk", argv[1]);
    test_bad_files(bad);
    static const char *fixtures[] = {
        "vtk_ascii.vtu",           "vtk_binary_u32.vtu",         "vtk_binary_zlib_u32.vtu",
        "vtk_appended_raw_u32.vtu", "vtk_appended_raw_zlib_u64.vtu", "vtk_appended_b64_zlib_u64.vtu",
        "vtk_legacy_ascii.vtk",    "vtk_legacy_binary.vtk",      "meshio_42.vtk",
        "meshio.mesh",             "gmsh_blocks.mesh"};
    for (size_t i = 0; i < sizeof fixtures / sizeof *fixtures; ++i) fuzz(good, work, fixtures[i], 200);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
