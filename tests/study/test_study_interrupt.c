/* Stopping a study on request (cm_context_interrupt, docs/DESIGN.md "progress"): on the
 * built-in bore (G0 and two variants as STEP, its hex O-grid), cm_study_run stopped at its
 * first progress point returns CM_ERR_INTERRUPTED with no result and no mesh written, stopped
 * in the middle (inside a variant's morph) returns it too instead of a failed row, and the
 * same inputs then give the rows of an uninterrupted run.
 * usage: test_study_interrupt DATA WORK */
#include "cadmorph/models.h"
#include "cadmorph/study.h"
#include "test_stopper.h"
#include "test_util.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Files in dir (not . and ..). */
static int count_files(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return -1;
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    closedir(d);
    return n;
}

static void clear_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return;
    char path[4096];
    for (struct dirent *e; (e = readdir(d));) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        remove(path);
    }
    closedir(d);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s DATA WORK\n", argv[0]);
        return 2;
    }
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    stopper st = {ctx, 0, 0, ""};
    char p[3][4096], out[4096];
    const double t[3] = {0, 0.5, 1};
    cm_status s = CM_OK;
    for (int k = 0; k < 3 && s >= 0; ++k) {
        snprintf(p[k], sizeof p[k], "%s/study_interrupt_%d.step", argv[2], k);
        s = cm_model_write_step(ctx, "bore", t[k], p[k]);
    }
    snprintf(out, sizeof out, "%s/study_interrupt_out", argv[2]);
    mkdir(out, 0777);
    clear_dir(out);
    cm_cad_model *g0 = NULL;
    cm_mesh *m = NULL;
    if (s >= 0) s = cm_cad_read(ctx, p[0], NULL, &g0);
    if (s >= 0) s = cm_hexmesh_bore(ctx, 32, 4, 6, 1.05, &m);
    const char *variants[2] = {p[1], p[2]};
    cm_study_family fam;
    memset(&fam, 0, sizeof fam);
    if (s >= 0) s = cm_study_family_files(ctx, variants, 2, NULL, &fam);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    cm_study_method methods[3];
    cm_study_default_methods(methods, 3);
    cm_study_options o;
    cm_study_options_init(&o);
    o.modes = CM_STUDY_ABSOLUTE;
    o.methods = methods;
    o.n_methods = 1;
    o.write_meshes = CM_STUDY_WRITE_ALL;
    o.out_dir = out;
    cm_context_set_progress(ctx, on_progress, &st);
    if (s >= 0) {
        cm_study_result *r = NULL;
        st.at = 0;
        s = cm_study_run(ctx, g0, m, &fam, &o, &r);
        CHECK_MSG(s >= 0 && r && r->n_rows == 2 && r->n_failed == 0, "study: %s",
                  cm_context_message(ctx));
        const int calls = st.calls;
        printf("study: %d progress points, %d files written\n", calls, count_files(out));
        CHECK(count_files(out) == 2);
        double want[2] = {0, 0};
        for (size_t i = 0; r && i < r->n_rows && i < 2; ++i) want[i] = r->rows[i].min_sj;
        cm_study_result_destroy(&r);

        /* at the first point: nothing written; in the middle (a variant's morph): the study
         * stops, not a failed row */
        const int at[2] = {1, calls / 2};
        for (int k = 0; k < 2; ++k) {
            clear_dir(out);
            st.calls = 0;
            st.at = at[k];
            r = (cm_study_result *)1;
            s = cm_study_run(ctx, g0, m, &fam, &o, &r);
            if (s >= 0 && st.calls < at[k]) { /* points by time: fewer in this run */
                cm_context_clear(ctx);
                cm_study_result_destroy(&r);
                continue;
            }
            CHECK_MSG(s == CM_ERR_INTERRUPTED && !r, "stopped at %d (%s): status %d, %s", at[k],
                      st.stage, (int)s, cm_context_message(ctx));
            CHECK_MSG(st.calls == at[k], "%d progress calls after the stop", st.calls - at[k]);
            printf("study stopped at point %d (%s): %s; %d files\n", at[k], st.stage,
                   cm_context_message(ctx), count_files(out));
            if (k == 0) CHECK(count_files(out) == 0);
        }
        clear_dir(out);
        st.at = 0;
        s = cm_study_run(ctx, g0, m, &fam, &o, &r);
        CHECK_MSG(s >= 0 && r && r->n_rows == 2 && r->rows[0].min_sj == want[0] &&
                      r->rows[1].min_sj == want[1],
                  "study after interrupted ones: %s", cm_context_message(ctx));
        cm_study_result_destroy(&r);
    }
    clear_dir(out);
    cm_study_family_release(&fam);
    cm_mesh_destroy(&m);
    cm_cad_destroy(&g0);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
