/* Pieces both SVG writers of study/ share (svg.c: the study plot; plot.c: the general line
 * plot): the colour table, XML escaping, tick steps. Not public. */
#ifndef CADMORPH_STUDY_SVG_COMMON_H
#define CADMORPH_STUDY_SVG_COMMON_H

#include <math.h>
#include <stdio.h>

static const char *const cm_svg_colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                             "#ff7f0e", "#8c564b", "#e377c2", "#17becf",
                                             "#7f7f7f", "#bcbd22"};
enum { CM_SVG_N_COLOURS = sizeof cm_svg_colours / sizeof *cm_svg_colours };

/* Writes s with &, <, > and quotes escaped (names come from the user). */
static inline void cm_svg_text(FILE *f, const char *s)
{
    for (; s && *s; ++s) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

/* A tick step of 1, 2 or 5 x 10^k giving about 5 to 10 ticks over span. */
static inline double cm_svg_tick_step(double span)
{
    double raw = span / 6, p = pow(10, floor(log10(raw))), f = raw / p;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
}

#endif
