/* Uniform grid over a point set: the nearest-neighbour search of the MLS sampling and of the
 * support radii (our own rather than FLANN: deform/ does not depend on cad/, and the queries
 * are small k-nearest searches over a few thousand samples, where a grid is exact and
 * simple). */
#include "mls_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void mls_grid_free(mls_grid *g)
{
    free(g->start);
    free(g->items);
    memset(g, 0, sizeof *g);
}

cm_status mls_grid_build(cm_context *ctx, mls_grid *g, size_t n, const double *xyz, double target)
{
    memset(g, 0, sizeof *g);
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            if (xyz[3 * i + a] < lo[a]) lo[a] = xyz[3 * i + a];
            if (xyz[3 * i + a] > hi[a]) hi[a] = xyz[3 * i + a];
        }
    if (n == 0)
        for (int a = 0; a < 3; ++a)
            lo[a] = hi[a] = 0;
    double ext = 0;
    for (int a = 0; a < 3; ++a)
        ext = fmax(ext, hi[a] - lo[a]);
    if (ext <= 0) ext = 1;
    /* the coarsest h with about n/target cells: halve from the extent (flat sets work too) */
    double want = fmax(1.0, (double)n / fmax(target, 1.0));
    double h = ext;
    for (int it = 0; it < 60; ++it) {
        double cells = 1;
        for (int a = 0; a < 3; ++a)
            cells *= floor((hi[a] - lo[a]) / h) + 1;
        if (cells >= want || cells > 4e6) break;
        h *= 0.5;
    }
    size_t nc = 1;
    for (int a = 0; a < 3; ++a) {
        g->n[a] = (int)floor((hi[a] - lo[a]) / h) + 1;
        g->lo[a] = lo[a];
        nc *= (size_t)g->n[a];
    }
    g->h = h;
    g->xyz = xyz;
    g->n_points = n;
    g->start = calloc(nc + 1, sizeof *g->start);
    g->items = malloc((n ? n : 1) * sizeof *g->items);
    int32_t *cell = malloc((n ? n : 1) * sizeof *cell);
    if (!g->start || !g->items || !cell) {
        free(cell);
        mls_grid_free(g);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mls: out of memory (grid)");
    }
    for (size_t i = 0; i < n; ++i) {
        int ci[3];
        for (int a = 0; a < 3; ++a) {
            ci[a] = (int)floor((xyz[3 * i + a] - lo[a]) / h);
            if (ci[a] >= g->n[a]) ci[a] = g->n[a] - 1;
            if (ci[a] < 0) ci[a] = 0;
        }
        cell[i] = (int32_t)(((size_t)ci[2] * g->n[1] + ci[1]) * g->n[0] + ci[0]);
        ++g->start[cell[i] + 1];
    }
    for (size_t c = 0; c < nc; ++c)
        g->start[c + 1] += g->start[c];
    int32_t *fill = malloc((nc ? nc : 1) * sizeof *fill);
    if (!fill) {
        free(cell);
        mls_grid_free(g);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mls: out of memory (grid)");
    }
    memcpy(fill, g->start, nc * sizeof *fill);
    for (size_t i = 0; i < n; ++i)
        g->items[fill[cell[i]]++] = (int32_t)i;
    free(fill);
    free(cell);
    return CM_OK;
}

static void consider(const mls_grid *g, const double x[3], int32_t p, int s, int *m, int32_t *idx,
                     double *dist)
{
    const double *q = g->xyz + 3 * (size_t)p;
    double d = sqrt((q[0] - x[0]) * (q[0] - x[0]) + (q[1] - x[1]) * (q[1] - x[1]) +
                    (q[2] - x[2]) * (q[2] - x[2]));
    if (*m == s && d >= dist[s - 1]) return;
    int i = *m < s ? (*m)++ : s - 1;
    while (i > 0 && dist[i - 1] > d) {
        dist[i] = dist[i - 1];
        idx[i] = idx[i - 1];
        --i;
    }
    dist[i] = d;
    idx[i] = p;
}

int mls_grid_nearest(const mls_grid *g, const double x[3], int s, int32_t *idx, double *dist)
{
    int ci[3], m = 0, rmax = 0;
    for (int a = 0; a < 3; ++a) {
        ci[a] = (int)floor((x[a] - g->lo[a]) / g->h);
        if (ci[a] >= g->n[a]) ci[a] = g->n[a] - 1;
        if (ci[a] < 0) ci[a] = 0;
        if (g->n[a] > rmax) rmax = g->n[a];
    }
    /* distance from x to the outside of its own cell, for the stopping test */
    double inner = DBL_MAX;
    for (int a = 0; a < 3; ++a) {
        double l = x[a] - (g->lo[a] + ci[a] * g->h), u = g->lo[a] + (ci[a] + 1) * g->h - x[a];
        inner = fmin(inner, fmin(fmax(l, 0), fmax(u, 0)));
    }
    for (int r = 0; r <= rmax; ++r) {
        for (int k = ci[2] - r; k <= ci[2] + r; ++k) {
            if (k < 0 || k >= g->n[2]) continue;
            for (int j = ci[1] - r; j <= ci[1] + r; ++j) {
                if (j < 0 || j >= g->n[1]) continue;
                int shell = abs(k - ci[2]) == r || abs(j - ci[1]) == r;
                for (int i = ci[0] - r; i <= ci[0] + r; i += (shell || r == 0) ? 1 : 2 * r) {
                    if (i < 0 || i >= g->n[0]) continue;
                    size_t c = ((size_t)k * g->n[1] + j) * g->n[0] + i;
                    for (int32_t p = g->start[c]; p < g->start[c + 1]; ++p)
                        consider(g, x, g->items[p], s, &m, idx, dist);
                }
            }
        }
        /* every point beyond ring r is at least inner + r h away */
        if (m == s && dist[s - 1] <= inner + r * g->h) break;
    }
    return m;
}
