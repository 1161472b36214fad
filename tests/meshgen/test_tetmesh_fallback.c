/* The retries of cm_tetmesh_create (meshgen/tetmesh.cpp) on a real TetGen failure: under an
 * address-space limit a little above what the process holds, TetGen's child runs out of
 * memory on the fine mesh asked for (its error path then crashes or reports code 1), and the
 * retry with the surface kept (-Y, far fewer tets) fits: the call succeeds, logs one warning
 * naming what worked and what failed, and the mesh is valid (no inverted tet, closed).
 * The limit is 60 MB above the process (30 and 120 pass too): TetGen
 * needs more than 1 GB for the ~3e6 tets of size 0.06.
 * usage: test_tetmesh_fallback DATA_DIR [WORK_DIR [EXTRA_MB]] */
#include "cadmorph/tetmesh.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

static char warning[4096];
static int n_warnings;

static void on_log(void *user, cm_log_level level, const char *msg)
{
    (void)user;
    if (level < CM_LOG_WARNING) return;
    ++n_warnings;
    snprintf(warning, sizeof warning, "%s", msg);
}

static long vm_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long pages = 0;
    if (f) {
        if (fscanf(f, "%ld", &pages) != 1) pages = 0;
        fclose(f);
    }
    return pages * 4096L;
}

int main(int argc, char **argv)
{
    if (argc < 2) return 2;
    const long extra_mb = argc > 3 ? atol(argv[3]) : 60; /* argv[2]: ctest's work directory */
    char path[4096];
    snprintf(path, sizeof path, "%s/models/bore_0.step", argv[1]);
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_context_set_log(ctx, on_log, NULL);
    cm_context_set_threads(ctx, 1);
    cm_cad_model *model = NULL;
    CHECK_MSG(cm_cad_read(ctx, path, NULL, &model) >= 0, "%s", cm_context_message(ctx));
    if (!model) return TEST_REPORT();

    cm_tetmesh_options opt;
    cm_tetmesh_options_init(&opt);
    opt.size = 0.06; /* ~3e6 tets asked for: hundreds of MB in TetGen */
    opt.optimize = 0;
    opt.mesher = CM_MESHER_TETGEN;
    struct rlimit old, lim;
    getrlimit(RLIMIT_AS, &old);
    lim = old;
    lim.rlim_cur = (rlim_t)(vm_bytes() + extra_mb * 1024L * 1024L);
    CHECK(setrlimit(RLIMIT_AS, &lim) == 0);
    cm_mesh *m = NULL;
    const cm_status s = cm_tetmesh_create(ctx, model, &opt, &m);
    setrlimit(RLIMIT_AS, &old);
    fprintf(stderr, "status %d, %d warnings: %s\n", (int)s, n_warnings, s < 0 ? cm_context_message(ctx) : warning);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    CHECK(n_warnings == 1);
    CHECK_MSG(strstr(warning, "TetGen meshed with -Y (surface kept)") != NULL, "warning: %s", warning);
    CHECK_MSG(strstr(warning, "after: the switches asked for: TetGen ") != NULL, "warning: %s", warning);
    if (m) {
        CHECK(cm_mesh_validate(ctx, m, "fallback") == CM_OK);
        double *sj = malloc(m->n_cells * sizeof *sj);
        cm_quality_stats all;
        CHECK(cm_mesh_quality(ctx, m, sj) == CM_OK);
        CHECK(cm_quality_summarize(ctx, m, sj, NULL, &all) == CM_OK);
        CHECK_MSG(all.inverted == 0, "%zu inverted", all.inverted);
        cm_mesh_boundary *b = NULL;
        CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
        if (b) CHECK(b->n_components == 1);
        cm_mesh_boundary_destroy(&b);
        free(sj);
    }
    cm_mesh_destroy(&m);
    cm_cad_destroy(&model);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
