/* The general line plot of cadmorph (study.h, cm_plot_write_svg): series of (x, y) points as
 * polylines with markers, linear or log axes, a legend - the benchmarks' figures, written by
 * hand like the study plot (svg.c) so that cadmorph needs no plotting package. */
#include "cadmorph/study.h"
#include "svg_common.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

/* Plot area inside a 960 x 540 canvas; the legend sits right of it. */
#define PW 1100
#define PH 540
#define X0 85.0
#define X1 640.0
#define Y0 60.0
#define Y1 460.0

typedef struct axis {
    double lo, hi;
    int log;
} axis;

static double tr(const axis *a, double v)
{
    return a->log ? log10(v) : v;
}

static double to_px(const axis *a, double v, double p0, double p1)
{
    return p0 + (p1 - p0) * (tr(a, v) - tr(a, a->lo)) / (tr(a, a->hi) - tr(a, a->lo));
}

/* Range of the finite values (positive ones on a log axis), rounded outwards. */
static void fit(axis *a, const cm_plot *p, int which)
{
    double lo = DBL_MAX, hi = -DBL_MAX;
    for (size_t s = 0; s < p->n_series; ++s)
        for (size_t i = 0; i < p->series[s].n; ++i) {
            double v = which ? p->series[s].y[i] : p->series[s].x[i];
            if (!isfinite(v) || (a->log && !(v > 0))) continue;
            lo = fmin(lo, v), hi = fmax(hi, v);
        }
    if (lo > hi) lo = a->log ? 1 : 0, hi = a->log ? 10 : 1;
    if (a->log) {
        lo = pow(10, floor(log10(lo) + 1e-9));
        hi = pow(10, ceil(log10(hi) - 1e-9));
        if (hi <= lo) hi = lo * 10;
    } else {
        if (hi - lo < 1e-12 * fmax(1, fabs(hi))) lo -= 0.5, hi += 0.5;
        double step = cm_svg_tick_step(hi - lo);
        lo = floor(lo / step + 1e-9) * step, hi = ceil(hi / step - 1e-9) * step;
    }
    a->lo = lo, a->hi = hi;
}

/* Ticks and grid lines of one axis (vertical = the y axis). */
static void ticks(FILE *f, const axis *a, int vertical)
{
    double p0 = vertical ? Y1 : X0, p1 = vertical ? Y0 : X1;
    if (a->log) {
        for (double d = a->lo; d <= a->hi * (1 + 1e-9); d *= 10)
            for (int m = 1; m < 10; ++m) {
                double v = d * m;
                if (v > a->hi * (1 + 1e-9)) break;
                double q = to_px(a, v, p0, p1);
                const char *col = m == 1 ? "#d0d0d0" : "#f0f0f0";
                if (vertical)
                    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>\n", X0, q, X1, q, col);
                else
                    fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>\n", q, Y0, q, Y1, col);
                if (m != 1) continue;
                /* decades as plain numbers (1000000, not 1e+06) up to 1e9 */
                char lab[32];
                snprintf(lab, sizeof lab, v >= 1 && v < 1e9 ? "%.0f" : "%g", v);
                if (vertical)
                    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%s</text>\n", X0 - 8, q + 4, lab);
                else
                    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%s</text>\n", q, Y1 + 20, lab);
            }
        return;
    }
    double step = cm_svg_tick_step(a->hi - a->lo);
    for (double v = a->lo; v <= a->hi + 1e-9 * step; v += step) {
        double w = fabs(v) < 1e-9 * step ? 0 : v, q = to_px(a, w, p0, p1);
        if (vertical) {
            fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\"/>\n", X0, q, X1, q,
                    w == 0 ? "#888" : "#e4e4e4");
            fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.4g</text>\n", X0 - 8, q + 4, w);
        } else {
            fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n", q, Y0, q, Y1);
            fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%.4g</text>\n", q, Y1 + 20, w);
        }
    }
}

cm_status cm_plot_write_svg(cm_context *ctx, const cm_plot *p, const char *path)
{
    if (!p || !path || (p->n_series && !p->series))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_plot_write_svg: NULL input");
    for (size_t s = 0; s < p->n_series; ++s)
        if (p->series[s].n && (!p->series[s].x || !p->series[s].y))
            return cm_error(ctx, CM_ERR_ARGUMENT, "cm_plot_write_svg: series %zu has no data", s);
    axis ax = {0, 1, p->log_x}, ay = {0, 1, p->log_y};
    fit(&ax, p, 0);
    fit(&ay, p, 1);
    if (p->y_min < p->y_max && !p->log_y) ay.lo = p->y_min, ay.hi = p->y_max;
    cm_outfile out;
    cm_status st = cm_outfile_open(ctx, path, &out);
    if (st < 0) return st;
    FILE *f = out.f;
    fprintf(f,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">\n"
            "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
            PW, PH, PW, PH);
    fprintf(f, "<text x=\"%.1f\" y=\"32\" font-family=\"sans-serif\" font-size=\"16\" text-anchor=\"middle\">",
            (X0 + X1) / 2);
    cm_svg_text(f, p->title);
    fputs("</text>\n<g font-family=\"sans-serif\" font-size=\"13\" fill=\"#222\">\n", f);
    ticks(f, &ax, 0);
    ticks(f, &ay, 1);
    fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"#222\"/>\n", X0, Y0,
            X1 - X0, Y1 - Y0);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">", (X0 + X1) / 2, Y1 + 45);
    cm_svg_text(f, p->x_label);
    fprintf(f, "</text>\n<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" transform=\"rotate(-90 %.1f %.1f)\">",
            X0 - 60, (Y0 + Y1) / 2, X0 - 60, (Y0 + Y1) / 2);
    cm_svg_text(f, p->y_label);
    fputs("</text>\n</g>\n", f);
    /* values outside the y range (a collapsing variant) are drawn on the frame as triangles */
    for (size_t s = 0; s < p->n_series; ++s) {
        const cm_plot_series *se = &p->series[s];
        const char *col = cm_svg_colours[(se->colour >= 0 ? (size_t)se->colour : s) % CM_SVG_N_COLOURS];
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"2\"%s points=\"", col,
                se->dashed ? " stroke-dasharray=\"7,4\"" : "");
        for (size_t i = 0; i < se->n; ++i) {
            double x = se->x[i], y = se->y[i];
            if (!isfinite(x) || !isfinite(y) || (ax.log && !(x > 0)) || (ay.log && !(y > 0))) continue;
            y = fmin(fmax(y, ay.lo), ay.hi);
            fprintf(f, " %.2f,%.2f", to_px(&ax, x, X0, X1), to_px(&ay, y, Y1, Y0));
        }
        fputs("\"/>\n", f);
        for (size_t i = 0; i < se->n; ++i) {
            double x = se->x[i], y = se->y[i];
            if (!isfinite(x) || !isfinite(y) || (ax.log && !(x > 0)) || (ay.log && !(y > 0))) continue;
            double qx = to_px(&ax, x, X0, X1), qy = to_px(&ay, fmin(fmax(y, ay.lo), ay.hi), Y1, Y0);
            if (y < ay.lo || y > ay.hi)
                fprintf(f, "<path d=\"M%.2f %.2f l5 %d l-10 0 z\" fill=\"%s\"><title>%.4g</title></path>\n", qx, qy,
                        y < ay.lo ? -8 : 8, col, y);
            else if (se->markers)
                fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"3\" fill=\"%s\"><title>%.4g, %.4g</title></circle>\n", qx,
                        qy, col, x, y);
        }
        double ly = Y0 + 10 + 22 * (double)s;
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" stroke-width=\"2\"%s/>\n",
                X1 + 18, ly, X1 + 55, ly, col, se->dashed ? " stroke-dasharray=\"7,4\"" : "");
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" font-family=\"sans-serif\" font-size=\"12\">", X1 + 62, ly + 4);
        cm_svg_text(f, se->name);
        fputs("</text>\n", f);
    }
    if (p->note) {
        fprintf(f, "<text x=\"%.1f\" y=\"%d\" font-family=\"sans-serif\" font-size=\"11\" fill=\"#555\">", X0, PH - 12);
        cm_svg_text(f, p->note);
        fputs("</text>\n", f);
    }
    fputs("</svg>\n", f);
    return cm_outfile_commit(ctx, &out);
}
