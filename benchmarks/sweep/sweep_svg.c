/* sweep.svg: min scaled Jacobian against percent of parameter change, one polyline per method
 * and mode (solid absolute, dashed relative), written by hand so that the benchmarks need no
 * plotting package. */
#include "sweep.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Plot area inside a 900 x 520 canvas; the legend sits right of it. */
#define SVG_W 900
#define SVG_H 520
#define PX0 80.0
#define PX1 640.0
#define PY0 60.0
#define PY1 450.0

static const char *const colours[CM_SWEEP_N_METHODS] = {"#1f77b4", "#d62728", "#2ca02c"};
/* Curves of methods that agree lie on top of each other: the later ones are drawn thinner so
 * that the earlier stay visible. */
static const double widths[CM_SWEEP_N_METHODS] = {4, 2.5, 1.5};

/* Writes s with &, <, > and quotes escaped (model and mesh names come from the user). */
static void xml_text(FILE *f, const char *s)
{
    for (; *s; ++s) {
        switch (*s) {
        case '&':
            fputs("&amp;", f);
            break;
        case '<':
            fputs("&lt;", f);
            break;
        case '>':
            fputs("&gt;", f);
            break;
        case '"':
            fputs("&quot;", f);
            break;
        default:
            fputc(*s, f);
        }
    }
}

/* A tick step of 1, 2 or 5 x 10^k giving about 5 to 10 ticks over span. */
static double tick_step(double span)
{
    double raw = span / 6, p = pow(10, floor(log10(raw))), f = raw / p;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
}

typedef struct frame {
    double ylo, yhi;
} frame;

static double px(double pct)
{
    return PX0 + (PX1 - PX0) * pct / 100;
}
static double py(const frame *fr, double y)
{
    return PY1 - (PY1 - PY0) * (y - fr->ylo) / (fr->yhi - fr->ylo);
}

static void axes(FILE *f, const frame *fr)
{
    fprintf(f, "<g font-family=\"sans-serif\" font-size=\"13\" fill=\"#222\">\n");
    for (int x = 0; x <= 100; x += 10) {
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n",
                px(x), PY0, px(x), PY1);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#222\"/>\n",
                px(x), PY1, px(x), PY1 + 5);
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%d</text>\n", px(x),
                PY1 + 20, x);
    }
    double step = tick_step(fr->yhi - fr->ylo);
    for (double y = ceil(fr->ylo / step - 1e-9) * step; y <= fr->yhi + 1e-9 * step; y += step) {
        double v = fabs(y) < 1e-9 * step ? 0 : y;
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>\n", PX0,
                py(fr, v), PX1, py(fr, v), v == 0 ? "#888" : "#e4e4e4");
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#222\"/>\n",
                PX0 - 5, py(fr, v), PX0, py(fr, v));
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.3g</text>\n", PX0 - 8,
                py(fr, v) + 4, v);
    }
    fprintf(f,
            "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" "
            "stroke=\"#222\"/>\n",
            PX0, PY0, PX1 - PX0, PY1 - PY0);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">parameter change (%%)</text>\n",
            (PX0 + PX1) / 2, PY1 + 45);
    fprintf(f,
            "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" "
            "transform=\"rotate(-90 %.1f %.1f)\">min scaled Jacobian</text>\n",
            PX0 - 55, (PY0 + PY1) / 2, PX0 - 55, (PY0 + PY1) / 2);
    fprintf(f, "</g>\n");
}

/* The polyline of one method x mode, from M(0) at 0 % through its rows; returns 1 if drawn. */
static int curve(FILE *f, const cm_sweep_result *r, const frame *fr, int mode, int method)
{
    int n = 0;
    for (size_t i = 0; i < r->n_rows; ++i)
        n += r->rows[i].mode == mode && r->rows[i].method == method;
    if (n == 0) return 0;
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"%g\"%s points=\"%.2f,%.2f",
            colours[method], widths[method],
            mode == CM_SWEEP_RELATIVE ? " stroke-dasharray=\"7,4\"" : "", px(0),
            py(fr, r->min_sj0));
    for (size_t i = 0; i < r->n_rows; ++i) {
        const cm_sweep_row *w = &r->rows[i];
        if (w->mode == mode && w->method == method)
            fprintf(f, " %.2f,%.2f", px(100 * w->t), py(fr, w->min_sj));
    }
    fprintf(f, "\"/>\n");
    for (size_t i = 0; i < r->n_rows; ++i) {
        const cm_sweep_row *w = &r->rows[i];
        if (w->mode == mode && w->method == method)
            fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"2.5\" fill=\"%s\"/>\n", px(100 * w->t),
                    py(fr, w->min_sj), colours[method]);
    }
    return 1;
}

cm_status cm_sweep_write_svg(cm_context *ctx, const cm_sweep_result *r, const char *path)
{
    frame fr = {r->min_sj0, r->min_sj0};
    for (size_t i = 0; i < r->n_rows; ++i) {
        if (r->rows[i].min_sj < fr.ylo) fr.ylo = r->rows[i].min_sj;
        if (r->rows[i].min_sj > fr.yhi) fr.yhi = r->rows[i].min_sj;
    }
    if (!isfinite(fr.ylo) || !isfinite(fr.yhi)) fr.ylo = 0, fr.yhi = 1;
    /* round outwards to tenths; keep a visible span */
    fr.ylo = floor(fr.ylo * 10 - 1e-9) / 10;
    fr.yhi = ceil(fr.yhi * 10 + 1e-9) / 10;
    if (fr.yhi - fr.ylo < 0.1) fr.yhi = fr.ylo + 0.1;

    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s < 0) return s;
    FILE *f = out.f;
    fprintf(f,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
            "viewBox=\"0 0 %d %d\">\n",
            SVG_W, SVG_H, SVG_W, SVG_H);
    fprintf(f, "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n");
    fprintf(f,
            "<text x=\"%.1f\" y=\"32\" font-family=\"sans-serif\" font-size=\"17\" "
            "text-anchor=\"middle\">",
            (PX0 + PX1) / 2);
    xml_text(f, r->model);
    fputs(", ", f);
    xml_text(f, r->mesh);
    fprintf(f, " mesh (%zu nodes, %zu cells): min scaled Jacobian over the sweep</text>\n",
            r->nodes, r->cells);
    axes(f, &fr);
    int shown = 0;
    for (int mode = CM_SWEEP_ABSOLUTE; mode <= CM_SWEEP_RELATIVE; ++mode)
        for (int m = 0; m < CM_SWEEP_N_METHODS; ++m) {
            if (!curve(f, r, &fr, mode, m)) continue;
            double y = PY0 + 10 + 24 * shown++;
            fprintf(f,
                    "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
                    "stroke-width=\"%g\"%s/>\n",
                    PX1 + 20, y, PX1 + 60, y, colours[m], widths[m],
                    mode == CM_SWEEP_RELATIVE ? " stroke-dasharray=\"7,4\"" : "");
            fprintf(f,
                    "<text x=\"%.1f\" y=\"%.1f\" font-family=\"sans-serif\" "
                    "font-size=\"13\">%s, %s</text>\n",
                    PX1 + 68, y + 4, cm_sweep_method_name(m), cm_sweep_mode_name(mode));
        }
    fprintf(f, "</svg>\n");
    return cm_outfile_commit(ctx, &out);
}
