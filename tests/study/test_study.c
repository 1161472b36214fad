/* cm_study_run over five STEP files written by gmsh (make_variants.py): four bore radii and
 * one variant with an extra hole. The odd one's rows carry a topology mismatch, the others
 * complete with the boundary on their G (1e-9 x diagonal) and, for RBF-S, no inverted cell;
 * absolute and relative both run; the absolute factorisation is made once for the family;
 * the relative series chains (its first step is the absolute one, later ones differ); failed
 * meshes are written exactly for the rows with inverted cells. The RBF warps' AUTO choice
 * counts the solves of their fit (cm_warp_options.solves, from the debug log of warp
 * create): the shared absolute warp one per variant and method sharing it, each relative
 * warp one. Also the variant lists (list file, glob, the bad ones) and the method names.
 * usage: test_study DIR   (DIR from make_variants.py) */
#include "cadmorph/study.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int failed;
#define EXPECT(cond, ...)                                                                          \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: %s: ", __FILE__, __LINE__, #cond);                             \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            ++failed;                                                                              \
        }                                                                                          \
    } while (0)

static const char *dir;

static const char *at(const char *name)
{
    static char buf[4][4096];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

typedef struct progress_log {
    int calls, monotone;
    double last_done, last_total;
} progress_log;

static void on_progress(void *user, const char *stage, double done, double total)
{
    progress_log *p = user;
    if (strcmp(stage, "study")) return;
    if (p->calls && done < p->last_done) p->monotone = 0;
    ++p->calls;
    p->last_done = done;
    p->last_total = total;
}

/* The solve counts the RBF warps were created for ("... for N solve(s)" in the debug log). */
typedef struct solves_log {
    int creates, shared, single, other;
    int expect; /* the shared warp's count */
} solves_log;

static void on_log(void *user, cm_log_level level, const char *msg)
{
    solves_log *l = user;
    (void)level;
    const char *p = strstr(msg, " solve(s)");
    if (!strstr(msg, "cm_warp_create: component") || !p) return;
    while (p > msg && p[-1] >= '0' && p[-1] <= '9') --p;
    const int n = atoi(p);
    ++l->creates;
    if (n == l->expect) ++l->shared;
    else if (n == 1) ++l->single;
    else ++l->other;
}

static void test_lists(cm_context *ctx)
{
    char **paths = NULL;
    size_t n = 0;
    cm_status s = cm_study_read_list(ctx, at("list.txt"), &paths, &n);
    EXPECT(s == CM_OK && n == 5, "list.txt: %s, %zu paths", cm_context_message(ctx), n);
    if (s == CM_OK && n == 5) {
        EXPECT(!strcmp(paths[2], at("v/v3_hole.step")), "relative path %s", paths[2]);
        EXPECT(!strcmp(paths[4], at("v/v5_r1.00.step")), "last path %s", paths[4]);
    }
    cm_study_paths_free(&paths, n);
    EXPECT(!paths, "paths not cleared");

    s = cm_study_read_list(ctx, at("v/v*.step"), &paths, &n);
    EXPECT(s == CM_OK && n == 5, "glob: %s, %zu paths", cm_context_message(ctx), n);
    if (s == CM_OK && n == 5) EXPECT(strstr(paths[0], "v1_r0.70"), "glob not sorted: %s", paths[0]);
    cm_study_paths_free(&paths, n);

    s = cm_study_read_list(ctx, at("bad_missing.txt"), &paths, &n);
    EXPECT(s == CM_ERR_IO && !paths && n == 0, "missing file: status %d", s);
    EXPECT(strstr(cm_context_message(ctx), "bad_missing.txt:3: ") &&
               strstr(cm_context_message(ctx), "nope.step"),
           "message '%s'", cm_context_message(ctx));
    s = cm_study_read_list(ctx, at("bad_empty.txt"), &paths, &n);
    EXPECT(s == CM_ERR_FORMAT && strstr(cm_context_message(ctx), "bad_empty.txt: no STEP paths"),
           "empty list: %d '%s'", s, cm_context_message(ctx));
    s = cm_study_read_list(ctx, at("no_such_list.txt"), &paths, &n);
    EXPECT(s == CM_ERR_IO && strstr(cm_context_message(ctx), "no_such_list.txt"),
           "missing list: %d '%s'", s, cm_context_message(ctx));
    s = cm_study_read_list(ctx, at("v/*.stp"), &paths, &n);
    EXPECT(s == CM_ERR_IO && strstr(cm_context_message(ctx), "no file matches"),
           "empty glob: %d '%s'", s, cm_context_message(ctx));
}

static void test_methods(cm_context *ctx)
{
    cm_study_method m[8];
    size_t n = 0;
    cm_status s = cm_study_methods_parse(
        ctx, "rbf-s,project,rbf-s-biharmonic,rbf,rbf-s-rbf-biharmonic,project-rbf-biharmonic", m,
        8, &n);
    EXPECT(s == CM_OK && n == 6, "parse: %s", cm_context_message(ctx));
    if (n == 6) {
        const int surface[] = {CM_SURFACE_RBF, CM_SURFACE_PROJECT, CM_SURFACE_RBF,
                               CM_SURFACE_PROJECT, CM_SURFACE_RBF, CM_SURFACE_PROJECT};
        const int warp[] = {CM_WARP_RBF, CM_WARP_RBF, CM_WARP_RBF_BIHARMONIC, CM_WARP_RBF,
                            CM_WARP_RBF_BIHARMONIC, CM_WARP_RBF_BIHARMONIC};
        for (size_t i = 0; i < n; ++i)
            EXPECT((int)m[i].method.surface == surface[i] &&
                       (int)m[i].method.warp.method == warp[i],
                   "%s: surface %d warp %d", m[i].name, m[i].method.surface,
                   m[i].method.warp.method);
        EXPECT(!strcmp(m[3].name, "rbf"), "name kept: %s", m[3].name);
        EXPECT(cm_study_method_slot(&m[1], 1) == 1 && cm_study_method_slot(&m[3], 3) == 6,
               "slots");
    }
    EXPECT(cm_study_methods_parse(ctx, "rbf-s,nope", m, 8, &n) == CM_ERR_ARGUMENT &&
               strstr(cm_context_message(ctx), "'nope'"),
           "unknown name: '%s'", cm_context_message(ctx));
    EXPECT(cm_study_methods_parse(ctx, "rbf-s,,rbf", m, 8, &n) == CM_ERR_ARGUMENT, "empty entry");
    EXPECT(cm_study_methods_parse(ctx, "rbf,rbf", m, 8, &n) == CM_ERR_ARGUMENT, "duplicate");
    EXPECT(cm_study_methods_parse(ctx, "rbf-s-", m, 8, &n) == CM_ERR_ARGUMENT, "bare prefix");
}

static int file_exists(const char *path) { return access(path, F_OK) == 0; }

static void test_study(cm_context *ctx)
{
    cm_cad_model *g0 = NULL;
    cm_mesh *mesh = NULL;
    char **paths = NULL;
    size_t n = 0;
    cm_study_family fam = {0};
    cm_study_result *r = NULL;
    cm_study_method methods[2];
    size_t nm = 0;
    cm_status s = cm_cad_read(ctx, at("G0.step"), NULL, &g0);
    if (s >= 0) s = cm_mesh_read(ctx, at("M0.msh"), &mesh);
    if (s >= 0) s = cm_study_read_list(ctx, at("list.txt"), &paths, &n);
    if (s >= 0)
        s = cm_study_family_files(ctx, (const char *const *)paths, n, NULL, &fam);
    if (s >= 0) s = cm_study_methods_parse(ctx, "rbf-s,rbf", methods, 2, &nm);
    EXPECT(s >= 0, "setup: %s", cm_context_message(ctx));
    if (s < 0) goto done;

    char out[2048];
    snprintf(out, sizeof out, "%s/lib_out", dir);
    mkdir(out, 0777);
    cm_study_options so;
    cm_study_options_init(&so);
    so.modes = CM_STUDY_BOTH;
    so.methods = methods;
    so.n_methods = nm;
    so.write_meshes = CM_STUDY_WRITE_FAILED;
    so.out_dir = out;
    /* the one-step morphs with their inverted cells kept: rbf (closest point) inverts, and
     * only those results are written */
    so.morph.steps = 1;
    so.morph.allow_inverted = 1;
    progress_log pl = {0, 1, 0, 0};
    solves_log sl = {0, 0, 0, 0, (int)fam.n * 2}; /* rbf-s and rbf share the warp */
    cm_context_set_progress(ctx, on_progress, &pl);
    cm_context_set_log(ctx, on_log, &sl);
    s = cm_study_run(ctx, g0, mesh, &fam, &so, &r);
    cm_context_set_progress(ctx, NULL, NULL);
    cm_context_set_log(ctx, NULL, NULL);
    /* one shared absolute warp (one component); the relative series' warps count one each */
    EXPECT(sl.shared == 1 && sl.single >= 1 && sl.other == 0,
           "warp creates: %d for %d solves, %d for one, %d other", sl.shared, sl.expect,
           sl.single, sl.other);
    EXPECT(s == CM_WARNING && r, "run: %d %s", s, cm_context_message(ctx));
    EXPECT(strstr(cm_context_message(ctx), "v3_hole"), "warning names the odd variant: %s",
           cm_context_message(ctx));
    EXPECT(pl.calls >= 2 && pl.monotone && pl.last_done == 5 && pl.last_total == 5,
           "progress: %d calls, last %g/%g", pl.calls, pl.last_done, pl.last_total);
    if (!r) goto done;
    EXPECT(r->n_rows == 5 * 2 * 2 && r->n_failed == 4, "%zu rows, %zu failed", r->n_rows,
           r->n_failed);
    int solves_abs = 0, solves_rel = 0, rows_rel = 0;
    const cm_study_row *abs1 = NULL, *rel1 = NULL, *abs2 = NULL, *rel2 = NULL;
    for (size_t i = 0; i < r->n_rows; ++i) {
        const cm_study_row *w = &r->rows[i];
        const char *name = r->methods[w->method].name;
        if (w->variant == 2) {
            EXPECT(w->status == CM_ERR_MISMATCH && strstr(w->message, "differs"),
                   "odd variant %s %s: %d '%s'", name, cm_study_mode_name(w->mode), w->status,
                   w->message);
            continue;
        }
        EXPECT(w->status >= 0, "%s %s %s: %s", w->label, name, cm_study_mode_name(w->mode),
               w->message);
        if (w->status < 0) continue;
        EXPECT(w->max_dist <= 1e-9 * r->diagonal, "%s %s: boundary %g from its G", w->label,
               name, w->max_dist);
        EXPECT(w->cells == r->cells && w->min_sj <= w->mean_sj, "%s %s: quality", w->label, name);
        if (!strcmp(name, "rbf-s"))
            EXPECT(w->inverted == 0, "%s rbf-s %s: %zu inverted", w->label,
                   cm_study_mode_name(w->mode), w->inverted);
        char path[4096];
        snprintf(path, sizeof path, "%s/%s_%s_%s.vtu", out, name, cm_study_mode_name(w->mode),
                 w->label);
        EXPECT(file_exists(path) == (w->inverted > 0), "%s: written %d, %zu inverted", path,
               file_exists(path), w->inverted);
        if (w->mode == CM_STUDY_ABSOLUTE) {
            solves_abs += w->t_volume_solve > 0;
        } else {
            solves_rel += w->t_volume_solve > 0;
            ++rows_rel;
        }
        if (!strcmp(name, "rbf-s") && w->variant == 0) *(w->mode == CM_STUDY_ABSOLUTE ? &abs1 : &rel1) = w;
        if (!strcmp(name, "rbf-s") && w->variant == 1) *(w->mode == CM_STUDY_ABSOLUTE ? &abs2 : &rel2) = w;
    }
    /* rbf-s and rbf share the triharmonic warp: one factorisation for the whole family */
    EXPECT(solves_abs == 1, "%d absolute rows factorised, expected 1", solves_abs);
    EXPECT(solves_rel == rows_rel, "%d of %d relative rows factorised", solves_rel, rows_rel);
    /* equal to rounding: the absolute morphs share one multi-column solve (batches) */
    EXPECT(abs1 && rel1 && fabs(abs1->min_sj - rel1->min_sj) <= 1e-12 &&
               fabs(abs1->mean_sj - rel1->mean_sj) <= 1e-12,
           "the first relative step is the absolute one");
    EXPECT(abs2 && rel2 && abs2->mean_sj != rel2->mean_sj, "the relative series did not chain");

    /* the table: a header and one line per row, the odd variant's message quoted */
    char csv[4096];
    snprintf(csv, sizeof csv, "%s/study.csv", out);
    EXPECT(cm_study_write_csv(ctx, r, csv, CM_STUDY_CSV_FULL) == CM_OK, "%s", cm_context_message(ctx));
    FILE *f = fopen(csv, "r");
    int lines = 0, odd = 0;
    char line[4096];
    while (f && fgets(line, sizeof line, f)) {
        ++lines;
        odd += strstr(line, ",v3_hole,mismatch,\"") != NULL;
    }
    if (f) fclose(f);
    EXPECT(lines == 21 && odd == 4, "study.csv: %d lines, %d odd rows", lines, odd);
    snprintf(csv, sizeof csv, "%s/study.svg", out);
    EXPECT(cm_study_write_svg(ctx, r, csv) == CM_OK, "%s", cm_context_message(ctx));

done:
    cm_study_result_destroy(&r);
    EXPECT(!r, "result not cleared");
    cm_study_family_release(&fam);
    cm_study_paths_free(&paths, n);
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&g0);
}

/* M0 that is not a mesh of G0 ends the study before any variant. */
static void test_mismatch(cm_context *ctx)
{
    cm_cad_model *g = NULL;
    cm_mesh *mesh = NULL;
    cm_study_family fam = {0};
    const char *one[] = {at("v/v2_r0.80.step")};
    cm_status s = cm_cad_read(ctx, at("v/v5_r1.00.step"), NULL, &g);
    if (s >= 0) s = cm_mesh_read(ctx, at("M0.msh"), &mesh);
    if (s >= 0) s = cm_study_family_files(ctx, one, 1, NULL, &fam);
    EXPECT(s >= 0, "setup: %s", cm_context_message(ctx));
    cm_study_options so;
    cm_study_options_init(&so);
    cm_study_result *r = NULL;
    if (s >= 0) {
        s = cm_study_run(ctx, g, mesh, &fam, &so, &r);
        EXPECT(s == CM_ERR_MISMATCH && !r, "M0 of another G: %d %s", s, cm_context_message(ctx));
    }
    cm_study_family_release(&fam);
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&g);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_study DIR\n");
        return 2;
    }
    dir = argv[1];
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    test_lists(ctx);
    test_methods(ctx);
    test_study(ctx);
    test_mismatch(ctx);
    cm_context_destroy(&ctx);
    printf("%s\n", failed ? "FAILED" : "ok");
    return failed != 0;
}
