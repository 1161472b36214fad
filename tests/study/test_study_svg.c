/* study.svg keeps the curves that matter readable when a method collapses: the y axis stops
 * at -0.2, lower values sit on it as triangles with their value, and the plot says so; a
 * study without such values is not clipped. Results are built in code. */
#include "cadmorph/study.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char *svg_of(cm_context *ctx, const char *dir, const double *sj1, int n, char *path)
{
    cm_study_result r;
    memset(&r, 0, sizeof r);
    snprintf(r.model, sizeof r.model, "pipe");
    snprintf(r.mesh, sizeof r.mesh, "hex");
    snprintf(r.x_label, sizeof r.x_label, "parameter change (%%)");
    r.min_sj0 = 0.71;
    r.x_max = 100;
    r.x_tick = 20;
    cm_study_method m[2];
    cm_study_method_parse(ctx, "rbf-s", &m[0]);
    cm_study_method_parse(ctx, "simplex", &m[1]);
    r.methods = m;
    r.n_methods = 2;
    cm_study_row rows[8];
    memset(rows, 0, sizeof rows);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < 2; ++j) {
            cm_study_row *w = &rows[2 * k + j];
            w->mode = CM_STUDY_ABSOLUTE;
            w->method = (size_t)j;
            w->variant = (size_t)k;
            w->t = (k + 1.0) / n;
            w->min_sj = j ? sj1[k] : 0.70 - 0.01 * k;
        }
    r.rows = rows;
    r.n_rows = (size_t)(2 * n);
    snprintf(path, 4096, "%s/clip_%g.svg", dir, sj1[n - 1]);
    CHECK_MSG(cm_study_write_svg(ctx, &r, path) == CM_OK, "%s", cm_context_message(ctx));
    FILE *f = fopen(path, "rb");
    static char buf[1 << 16];
    size_t len = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    if (f) fclose(f);
    buf[len] = 0;
    return buf;
}

/* cm_plot_write_svg: log axes at decades, a value beyond the fixed y range drawn on the frame
 * (with its value), non-positive values left out of a log axis, names escaped. */
static void test_plot(cm_context *ctx, const char *dir)
{
    const double x[4] = {1000, 2000, 4000, 8000}, y1[4] = {0.05, 0.4, 2.5, 14.5}, y2[4] = {2.0, 0, 7.2, 14.9};
    const double sj[3] = {0.12, 0.05, -0.9}, k[3] = {500, 1000, 2000};
    cm_plot_series s[2] = {{"rbf <dense>", 4, x, y1, 0, 1, -1}, {"mls & co", 4, x, y2, 1, 1, -1}};
    cm_plot p = {"time", "k", "s", "a note", 1, 1, 0, 0, 2, s};
    char path[4096];
    snprintf(path, sizeof path, "%s/plot_log.svg", dir);
    CHECK(cm_plot_write_svg(ctx, &p, path) == CM_OK);
    char *t = NULL;
    size_t n = 0;
    CHECK(cm_file_read(ctx, path, &t, &n) == CM_OK);
    if (t) {
        CHECK_MSG(strstr(t, ">1000<") && strstr(t, ">10000<") && strstr(t, ">0.01<") && strstr(t, ">100<"),
                  "%s: decade ticks", path);
        CHECK_MSG(strstr(t, "rbf &lt;dense&gt;") && strstr(t, "mls &amp; co"), "%s: names not escaped", path);
        CHECK_MSG(strstr(t, "stroke-dasharray") != NULL, "%s: no dashed series", path);
        /* the 0 of the second series is not on the log axis: 3 markers, not 4 */
        size_t dots = 0;
        for (const char *q = t; (q = strstr(q, "<circle")); ++q) ++dots;
        CHECK_MSG(dots == 7, "%s: %zu markers (want 4 + 3)", path, dots);
    }
    free(t);
    cm_plot_series c = {"sj", 3, k, sj, 0, 1, 2};
    cm_plot q = {"sphere", "k", "min SJ", NULL, 0, 0, -0.2, 0.2, 1, &c};
    snprintf(path, sizeof path, "%s/plot_clip.svg", dir);
    CHECK(cm_plot_write_svg(ctx, &q, path) == CM_OK);
    t = NULL;
    CHECK(cm_file_read(ctx, path, &t, &n) == CM_OK);
    if (t) CHECK_MSG(strstr(t, "<title>-0.9</title>") != NULL, "%s: the clipped value is not marked", path);
    free(t);
    cm_plot bad = {"x", "x", "y", NULL, 0, 0, 0, 0, 2, NULL};
    CHECK(cm_plot_write_svg(ctx, &bad, path) == CM_ERR_ARGUMENT);
}

int main(int argc, char **argv)
{
    const char *dir = argc > 2 ? argv[2] : ".";
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    char path[4096];
    const double collapse[4] = {0.6, 0.1, -0.5, -0.97};
    const char *s = svg_of(ctx, dir, collapse, 4, path);
    CHECK_MSG(strstr(s, "axis clipped at -0.2") != NULL, "%s: no clipping note", path);
    CHECK_MSG(strstr(s, ">-0.2<") != NULL, "%s: no -0.2 tick", path);
    CHECK_MSG(strstr(s, ">-1<") == NULL && strstr(s, ">-0.4<") == NULL, "%s: axis below -0.2",
              path);
    CHECK_MSG(strstr(s, "<title>-0.97</title>") && strstr(s, "<title>-0.5</title>"),
              "%s: clipped values not marked", path);
    const double fine[4] = {0.6, 0.5, 0.3, -0.1};
    s = svg_of(ctx, dir, fine, 4, path);
    CHECK_MSG(strstr(s, "clipped") == NULL && strstr(s, "<title>") == NULL, "%s: clipped", path);
    CHECK_MSG(strstr(s, ">-0.4<") == NULL, "%s: the axis goes below its lowest value", path);
    test_plot(ctx, dir);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
