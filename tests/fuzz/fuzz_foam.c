/* libFuzzer driver for the OpenFOAM polyMesh reader. A case is a directory, so the input is
 * split at each line "@@" (the separator: "\n@@\n") into the members points, faces, owner,
 * neighbour, boundary, cellZones, faceZones, pointZones, in that order; each member present
 * becomes a file of constant/polyMesh in a case directory of this process (in /dev/shm when
 * there is one), an absent one no file. A member that starts with the gzip magic bytes is
 * written as NAME.gz as it is; with CM_FUZZ_GZ (fuzz_foam_gz) every member is written
 * gzip-compressed as NAME.gz, so that the mutations act on the inflated text. The reader may
 * refuse anything, but must not crash, leak, hang, inflate without bound or let a message span
 * lines; a mesh it accepts has finite coordinates. */
#include "cadmorph/mesh.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

static const char *const members[] = {"points",    "faces",     "owner",     "neighbour",
                                      "boundary",  "cellZones", "faceZones", "pointZones"};
enum { N_MEMBERS = sizeof members / sizeof *members };
static char root[200], mesh_dir[256];

static void setup(void)
{
    snprintf(root, sizeof root, "%s/cm-fuzz-%ld", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp",
             (long)getpid());
    char p[300];
    mkdir(root, 0700);
    snprintf(p, sizeof p, "%s/constant", root);
    mkdir(p, 0700);
    snprintf(mesh_dir, sizeof mesh_dir, "%s/constant/polyMesh", root);
    mkdir(mesh_dir, 0700);
}

static void write_member(int m, const uint8_t *d, size_t n)
{
    char p[300];
    int gz = n >= 2 && d[0] == 0x1f && d[1] == 0x8b;
#ifdef CM_FUZZ_GZ
    gz = 1;
#endif
    snprintf(p, sizeof p, "%s/%s%s", mesh_dir, members[m], gz ? ".gz" : "");
#ifdef CM_FUZZ_GZ
    gzFile g = gzopen(p, "wb1");
    if (!g) abort();
    if (n && gzwrite(g, d, (unsigned)n) != (int)n) abort();
    if (gzclose(g) != Z_OK) abort();
#else
    FILE *f = fopen(p, "wb");
    if (!f) abort();
    if (n && fwrite(d, 1, n, f) != n) abort();
    fclose(f);
#endif
}

static const uint8_t *find_sep(const uint8_t *at, const uint8_t *end)
{
    for (; end - at >= 4; ++at)
        if (!memcmp(at, "\n@@\n", 4)) return at;
    return NULL;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!root[0]) setup();
    char p[300];
    for (int m = 0; m < N_MEMBERS; ++m) {
        snprintf(p, sizeof p, "%s/%s", mesh_dir, members[m]);
        unlink(p);
        snprintf(p, sizeof p, "%s/%s.gz", mesh_dir, members[m]);
        unlink(p);
    }
    if (!size) data = (const uint8_t *)""; /* an empty points file */
    const uint8_t *at = data, *end = data + size;
    for (int m = 0; m < N_MEMBERS; ++m) {
        const uint8_t *next = find_sep(at, end);
        const uint8_t *stop = next ? next : end;
        write_member(m, at, (size_t)(stop - at));
        if (!next) break;
        at = next + 4;
    }
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) abort();
    cm_mesh *mesh = NULL;
    cm_status s = cm_mesh_read(ctx, root, &mesh);
    if (s < 0 && (mesh != NULL || strchr(cm_context_message(ctx), '\n'))) abort();
    if (s >= 0 && mesh)
        for (size_t i = 0; i < 3 * mesh->n_nodes; ++i)
            if (!isfinite(mesh->xyz[i])) abort();
    cm_mesh_destroy(&mesh);
    cm_context_destroy(&ctx);
    return 0;
}
