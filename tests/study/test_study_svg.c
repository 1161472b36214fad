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
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
