/* study.svg / sweep.svg: min scaled Jacobian against the variant (or percent of parameter
 * change), one polyline per method and mode (solid absolute, dashed relative), written by hand
 * so that cadmorph needs no plotting package. */
#include "cadmorph/study.h"
#include "svg_common.h"

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

/* Curves of methods that agree lie on top of each other: the later ones are drawn thinner so
 * that the earlier stay visible. */
static const double widths[] = {4, 2.5, 1.5};

/* By cm_study_method_slot: the sweeps' three methods keep their colours. */
static const char *colour(const cm_study_result *r, size_t m)
{
    return cm_svg_colours[cm_study_method_slot(&r->methods[m], m) % CM_SVG_N_COLOURS];
}

static double width(const cm_study_result *r, size_t m)
{
    int k = cm_study_method_slot(&r->methods[m], m);
    return k < 3 ? widths[k] : 1.5;
}

/* A collapsing method (min SJ down to -1) would squeeze the curves that matter into a few
 * pixels at the top: the y axis stops here, and lower values are drawn on it as downward
 * triangles (their value in a tooltip; the CSV has them all). */
#define SVG_Y_CLIP (-0.2)

typedef struct frame {
    double ylo, yhi;
    double xmax, xtick;
    int clipped; /* some value lies below ylo = SVG_Y_CLIP */
    double xmin, x0; /* x range [xmin, xmax]; M0 at x0 */
} frame;

static double px(const frame *fr, double x)
{
    return PX0 + (PX1 - PX0) * (x - fr->xmin) / (fr->xmax - fr->xmin);
}

/* A row's x: t in [0, 1] across the range. */
static double row_x(const frame *fr, const cm_study_row *w)
{
    return fr->xmin + w->t * (fr->xmax - fr->xmin);
}
static double py(const frame *fr, double y)
{
    if (y < fr->ylo) y = fr->ylo; /* clipped: on the axis */
    return PY1 - (PY1 - PY0) * (y - fr->ylo) / (fr->yhi - fr->ylo);
}

static void axes(FILE *f, const frame *fr, const char *x_label)
{
    fprintf(f, "<g font-family=\"sans-serif\" font-size=\"13\" fill=\"#222\">\n");
    const double k0 = ceil(fr->xmin / fr->xtick - 1e-9);
    for (int k = 0; (k0 + k) * fr->xtick <= fr->xmax + 1e-9 * fabs(fr->xmax); ++k) {
        double x = (k0 + k) * fr->xtick;
        if (fabs(x) < 1e-9 * fr->xtick) x = 0;
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#e4e4e4\"/>\n",
                px(fr, x), PY0, px(fr, x), PY1);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#222\"/>\n",
                px(fr, x), PY1, px(fr, x), PY1 + 5);
        fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%g</text>\n", px(fr, x),
                PY1 + 20, x);
    }
    double step = cm_svg_tick_step(fr->yhi - fr->ylo);
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
    if (fr->clipped) {
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#c00\" "
                "stroke-width=\"2\" stroke-dasharray=\"4,3\"/>\n",
                PX0, PY1, PX1, PY1);
        fprintf(f,
                "<text x=\"%.1f\" y=\"%.1f\" fill=\"#c00\" font-size=\"12\">axis clipped at "
                "%g: values below it drawn on it as &#9660; (exact values in the CSV)</text>\n",
                PX0 + 6, PY1 - 6, SVG_Y_CLIP);
    }
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">", (PX0 + PX1) / 2, PY1 + 45);
    cm_svg_text(f, x_label);
    fputs("</text>\n", f);
    fprintf(f,
            "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" "
            "transform=\"rotate(-90 %.1f %.1f)\">min scaled Jacobian</text>\n",
            PX0 - 55, (PY0 + PY1) / 2, PX0 - 55, (PY0 + PY1) / 2);
    fprintf(f, "</g>\n");
}

static int complete(const cm_study_row *w, int mode, size_t method)
{
    return w->mode == mode && w->method == method && w->status >= 0;
}

/* The polyline of one method x mode, from M0 at 0 through its complete rows; returns 1 if
 * drawn. */
static int curve(FILE *f, const cm_study_result *r, const frame *fr, int mode, size_t method)
{
    int n = 0;
    for (size_t i = 0; i < r->n_rows; ++i)
        n += complete(&r->rows[i], mode, method);
    if (n == 0) return 0;
    fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"%g\"%s points=\"",
            colour(r, method), width(r, method),
            mode == CM_STUDY_RELATIVE ? " stroke-dasharray=\"7,4\"" : "");
    /* M0 and the rows in the order of x (a sweep of a parameter around G0's value); rows
     * of equal x keep their order */
    int m0_drawn = 0, drawn = 0;
    double last = -INFINITY;
    for (;;) {
        double next = INFINITY;
        for (size_t i = 0; i < r->n_rows; ++i)
            if (complete(&r->rows[i], mode, method) && row_x(fr, &r->rows[i]) > last)
                next = fmin(next, row_x(fr, &r->rows[i]));
        if (!m0_drawn && fr->x0 <= next) {
            fprintf(f, "%s%.2f,%.2f", drawn++ ? " " : "", px(fr, fr->x0), py(fr, r->min_sj0));
            m0_drawn = 1;
        }
        if (next == INFINITY) break;
        for (size_t i = 0; i < r->n_rows; ++i)
            if (complete(&r->rows[i], mode, method) && row_x(fr, &r->rows[i]) == next)
                fprintf(f, "%s%.2f,%.2f", drawn++ ? " " : "", px(fr, next),
                        py(fr, r->rows[i].min_sj));
        last = next;
    }
    fprintf(f, "\"/>\n");
    for (size_t i = 0; i < r->n_rows; ++i) {
        const cm_study_row *w = &r->rows[i];
        if (!complete(w, mode, method)) continue;
        double x = px(fr, row_x(fr, w)), y = py(fr, w->min_sj);
        if (w->min_sj < fr->ylo)
            fprintf(f,
                    "<path d=\"M%.2f %.2f l5 0 l-5 8 l-5 -8 z\" fill=\"%s\"><title>%.4g"
                    "</title></path>\n",
                    x, y - 4, colour(r, method), w->min_sj);
        else
            fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"2.5\" fill=\"%s\"/>\n", x, y,
                    colour(r, method));
    }
    return 1;
}

/* A variant none of whose rows completed: a grey cross on the x axis. */
static void failed_marks(FILE *f, const cm_study_result *r, const frame *fr)
{
    for (size_t i = 0; i < r->n_rows; ++i) {
        const cm_study_row *w = &r->rows[i];
        if (w->status >= 0) continue;
        int any = 0;
        for (size_t j = 0; j < r->n_rows && !any; ++j)
            any = r->rows[j].variant == w->variant && r->rows[j].status >= 0;
        int first = 1;
        for (size_t j = 0; j < i && first; ++j)
            first = r->rows[j].variant != w->variant;
        if (any || !first) continue;
        double x = px(fr, row_x(fr, w));
        fprintf(f,
                "<path d=\"M%.1f %.1f l8 8 m0 -8 l-8 8\" stroke=\"#888\" stroke-width=\"2\">"
                "<title>",
                x - 4, PY1 - 12);
        cm_svg_text(f, w->label);
        fputs(": ", f);
        cm_svg_text(f, w->message);
        fputs("</title></path>\n", f);
    }
}

cm_status cm_study_write_svg(cm_context *ctx, const cm_study_result *r, const char *path)
{
    if (!r || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_write_svg: NULL input");
    frame fr = {r->min_sj0, r->min_sj0, r->x_max > 0 || r->x_min < r->x_max ? r->x_max : 1,
                r->x_tick, 0, 0, 0};
    if (r->x_min < fr.xmax) fr.xmin = r->x_min;
    fr.x0 = r->x0;
    if (!(fr.xtick > 0)) {
        fr.xtick = cm_svg_tick_step(fr.xmax - fr.xmin);
        if (fr.xtick < 1 && fr.xmax >= 1) fr.xtick = 1; /* variants are counted */
    }
    for (size_t i = 0; i < r->n_rows; ++i) {
        if (r->rows[i].status < 0) continue;
        if (r->rows[i].min_sj < fr.ylo) fr.ylo = r->rows[i].min_sj;
        if (r->rows[i].min_sj > fr.yhi) fr.yhi = r->rows[i].min_sj;
    }
    if (!isfinite(fr.ylo) || !isfinite(fr.yhi)) fr.ylo = 0, fr.yhi = 1;
    /* round outwards to tenths; keep a visible span */
    fr.ylo = floor(fr.ylo * 10 - 1e-9) / 10;
    fr.yhi = ceil(fr.yhi * 10 + 1e-9) / 10;
    if (fr.ylo < SVG_Y_CLIP) fr.ylo = SVG_Y_CLIP, fr.clipped = 1;
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
    cm_svg_text(f, r->model);
    fputs(", ", f);
    cm_svg_text(f, r->mesh);
    /* a family counted in variants is a study; one in percent of a parameter a sweep */
    fprintf(f, " mesh (%zu nodes, %zu cells): min scaled Jacobian over the %s</text>\n",
            r->nodes, r->cells, strcmp(r->x_label, "variant") ? "sweep" : "study");
    axes(f, &fr, r->x_label);
    failed_marks(f, r, &fr);
    int shown = 0;
    for (int mode = CM_STUDY_ABSOLUTE; mode <= CM_STUDY_RELATIVE; ++mode)
        for (size_t m = 0; m < r->n_methods; ++m) {
            if (!curve(f, r, &fr, mode, m)) continue;
            double y = PY0 + 10 + 24 * shown++;
            fprintf(f,
                    "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
                    "stroke-width=\"%g\"%s/>\n",
                    PX1 + 20, y, PX1 + 60, y, colour(r, m), width(r, m),
                    mode == CM_STUDY_RELATIVE ? " stroke-dasharray=\"7,4\"" : "");
            fprintf(f,
                    "<text x=\"%.1f\" y=\"%.1f\" font-family=\"sans-serif\" "
                    "font-size=\"13\">",
                    PX1 + 68, y + 4);
            cm_svg_text(f, r->methods[m].name);
            fprintf(f, ", %s</text>\n", cm_study_mode_name(mode));
        }
    fprintf(f, "</svg>\n");
    return cm_outfile_commit(ctx, &out);
}
