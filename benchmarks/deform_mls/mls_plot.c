/* A CSV of points to an SVG line plot through cadmorph's plot writer (cm_plot_write_svg): the
 * figures of the MLS benchmarks (benchmarks/deform_mls/README.md).
 * CSV: header series,x,y[,style[,colour]]; style: solid|dashed, optionally +markers; colour:
 * a slot of the colour table (default: the series' order). Series in order of appearance.
 * usage: mls_plot IN.csv OUT.svg TITLE XLABEL YLABEL [logx] [logy] [ymin=A] [ymax=B] [note=TEXT] */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/study.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct series {
    char name[128];
    size_t n, cap;
    double *x, *y;
    int dashed, markers, colour;
} series;

int main(int argc, char **argv)
{
    if (argc < 6) {
        fprintf(stderr, "usage: mls_plot IN.csv OUT.svg TITLE XLABEL YLABEL [logx] [logy] [ymin=A] [ymax=B] [note=T]\n");
        return 1;
    }
    cm_plot p = {argv[3], argv[4], argv[5], NULL, 0, 0, 0, 0, 0, NULL};
    for (int i = 6; i < argc; ++i) {
        if (!strcmp(argv[i], "logx")) p.log_x = 1;
        else if (!strcmp(argv[i], "logy")) p.log_y = 1;
        else if (!strncmp(argv[i], "ymin=", 5)) p.y_min = atof(argv[i] + 5);
        else if (!strncmp(argv[i], "ymax=", 5)) p.y_max = atof(argv[i] + 5);
        else if (!strncmp(argv[i], "note=", 5)) p.note = argv[i] + 5;
    }
    FILE *f = fopen(argv[1], "r");
    if (!f) {
        perror(argv[1]);
        return 2;
    }
    series s[32];
    size_t ns = 0;
    char line[512];
    long ln = 0;
    while (fgets(line, sizeof line, f)) {
        if (++ln == 1) continue; /* header */
        line[strcspn(line, "\r\n")] = 0;
        if (!*line) continue;
        char *name = strtok(line, ","), *xs = strtok(NULL, ","), *ys = strtok(NULL, ",");
        char *style = strtok(NULL, ","), *col = strtok(NULL, ",");
        if (!name || !xs || !ys) {
            fprintf(stderr, "%s:%ld: expected series,x,y\n", argv[1], ln);
            return 2;
        }
        size_t k = 0;
        while (k < ns && strcmp(s[k].name, name)) ++k;
        if (k == ns) {
            if (ns == 32) {
                fprintf(stderr, "%s:%ld: more than 32 series\n", argv[1], ln);
                return 2;
            }
            memset(&s[ns], 0, sizeof s[ns]);
            snprintf(s[ns].name, sizeof s[ns].name, "%s", name);
            s[ns].dashed = style && strstr(style, "dashed");
            s[ns].markers = style && strstr(style, "markers");
            s[ns].colour = col ? atoi(col) : -1;
            ++ns;
        }
        series *q = &s[k];
        if (q->n == q->cap) {
            q->cap = q->cap ? 2 * q->cap : 16;
            q->x = realloc(q->x, q->cap * sizeof *q->x);
            q->y = realloc(q->y, q->cap * sizeof *q->y);
            if (!q->x || !q->y) return 3;
        }
        q->x[q->n] = strtod(xs, NULL);
        q->y[q->n++] = strtod(ys, NULL);
    }
    fclose(f);
    cm_plot_series ps[32];
    for (size_t k = 0; k < ns; ++k)
        ps[k] = (cm_plot_series){s[k].name, s[k].n, s[k].x, s[k].y, s[k].dashed, s[k].markers, s[k].colour};
    p.n_series = ns;
    p.series = ps;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    int rc = cm_plot_write_svg(ctx, &p, argv[2]) < 0;
    if (rc) fprintf(stderr, "%s\n", cm_context_message(ctx));
    cm_context_destroy(&ctx);
    for (size_t k = 0; k < ns; ++k) free(s[k].x), free(s[k].y);
    return rc;
}
