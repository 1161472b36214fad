/* libFuzzer driver for the text tables and lists that are not meshes; CM_FUZZ_READER picks one:
 *   prm     PyGeM .prm lattice (cm_ffd_prm_read)
 *   ctrl    control-point displacements of `cadmorph ffd` (cm_ffd_read_displacements, 4x3x2)
 *   nodes   node list (cm_mesh_read_node_list, 64 nodes)
 *   sens    sensitivity CSV (cm_design_read_sensitivity, 64 nodes)
 *   design  design table (cm_design_table_read)
 *   list    variant list of `cadmorph study` (cm_study_read_list)
 * Each input goes to a file in a directory of its own (in /dev/shm when there is one) that
 * also holds a.step, b.step and sub/c.step (empty files), so that a list or a table can name
 * readable files and get past that check. A reader may refuse anything, but must not crash,
 * leak, hang or let a message span lines, and what it accepts holds finite numbers only. */
#include "cadmorph/deform.h"
#include "cadmorph/mesh.h"
#include "cadmorph/study.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define READER_prm 1
#define READER_ctrl 2
#define READER_nodes 3
#define READER_sens 4
#define READER_design 5
#define READER_list 6
#define CAT(a, b) a##b
#define ID(r) CAT(READER_, r)
#ifndef CM_FUZZ_READER
#error "define CM_FUZZ_READER"
#endif
#define READER ID(CM_FUZZ_READER)

static char dir[200], path[256];

static void touch(const char *name)
{
    char p[300];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "wb");
    if (!f) abort();
    fclose(f);
}

static void setup(void)
{
    snprintf(dir, sizeof dir, "%s/cm-fuzz-%ld", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp",
             (long)getpid());
    mkdir(dir, 0700);
    char sub[300];
    snprintf(sub, sizeof sub, "%s/sub", dir);
    mkdir(sub, 0700);
    touch("a.step");
    touch("b.step");
    touch("sub/c.step");
    const char *name = READER == ID(prm) ? "in.prm" : READER == ID(list) ? "in.txt" : "in.csv";
    snprintf(path, sizeof path, "%s/%s", dir, name);
}

static void finite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(v[i])) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!path[0]) setup();
    FILE *f = fopen(path, "wb");
    if (!f) abort();
    if (size && fwrite(data, 1, size, f) != size) abort();
    fclose(f);
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) abort();
    cm_status s;
#if READER == READER_prm
    cm_ffd_prm prm;
    memset(&prm, 0, sizeof prm);
    s = cm_ffd_prm_read(ctx, path, &prm);
    if (s >= 0) {
        if (prm.n[0] < 1 || prm.n[1] < 1 || prm.n[2] < 1 || !prm.mu) abort();
        finite(prm.length, 3);
        finite(prm.origin, 3);
        finite(prm.angle, 3);
        finite(prm.mu, (size_t)prm.n[0] * prm.n[1] * prm.n[2] * 3);
    }
    cm_ffd_prm_free(&prm);
#elif READER == READER_ctrl
    const int n[3] = {4, 3, 2};
    double dc[24 * 3];
    unsigned char listed[24];
    s = cm_ffd_read_displacements(ctx, path, n, dc, listed);
    if (s >= 0) finite(dc, 24 * 3);
#elif READER == READER_nodes
    unsigned char mark[64] = {0};
    s = cm_mesh_read_node_list(ctx, path, 64, mark);
#elif READER == READER_sens
    double sens[64 * 3];
    unsigned char listed[64];
    s = cm_design_read_sensitivity(ctx, path, 64, sens, listed);
    if (s >= 0) finite(sens, 64 * 3);
#elif READER == READER_design
    cm_design_table *t = NULL;
    s = cm_design_table_read(ctx, path, &t);
    if (s >= 0) {
        size_t np = cm_design_table_n_parameters(t), nr = cm_design_table_n_rows(t);
        if (nr == 0) abort();
        for (size_t i = 0; i < nr; ++i) {
            if (!cm_design_table_path(t, i)) abort();
            finite(cm_design_table_values(t, i), np);
        }
        for (size_t j = 0; j < np; ++j)
            if (!cm_design_table_parameter(t, j)) abort();
    } else if (t) {
        abort();
    }
    cm_design_table_destroy(&t);
#elif READER == READER_list
    char **paths = NULL;
    size_t n = 0;
    s = cm_study_read_list(ctx, path, &paths, &n);
    if (s >= 0 && n == 0) abort();
    if (s < 0 && (paths || n)) abort();
    cm_study_paths_free(&paths, n);
#else
#error "unknown CM_FUZZ_READER"
#endif
    if (s < 0 && strchr(cm_context_message(ctx), '\n')) abort();
    cm_context_destroy(&ctx);
    return 0;
}
