/* The residual blend of the MLS deformation (mls.h, cm_mls_options.blend). The MLS field is
 * a least-squares fit: it misses the constrained nodes by a residual r (a few % of the
 * motion). When the constrained nodes keep their prescribed value (the warp's contract: the
 * boundary stays on the CAD), that miss lands entirely in the first layer of cells, which is
 * often the thinnest (hex O-grids, boundary layers) - there it costs more quality than the
 * field itself. The blend carries r into the free nodes near the constraints and lets it
 * decay over R = blend x the mean support radius (the subspace's own resolution), so that the
 * correction's strain is about |r| / R instead of |r| / (first layer's thickness):
 *     d(x) += psi(d1 / R) sum_b w_b(x) r_b,   psi(t) = (1 - t)^3 (1 + 3t)  (C^2, psi(0) = 1),
 * d1 the distance to the nearest constrained node, w_b the Franke-Little weights of the
 * BLEND_NEAR nearest constrained nodes (continuous: each vanishes at the distance of the
 * next one; normalised; exact where x is a constrained node). The weights depend only on
 * the positions: built once, one sparse product per apply. */
#include "mls_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { BLEND_NEAR = 8 };

void mls_blend_free(mls_blend *b)
{
    free(b->node), free(b->row), free(b->col), free(b->val);
    memset(b, 0, sizeof *b);
}

static double decay(double t)
{
    return t >= 1 ? 0 : (1 - t) * (1 - t) * (1 - t) * (1 + 3 * t);
}

cm_status mls_blend_create(cm_context *ctx, size_t n, const double *xyz, const unsigned char *is_con,
                           size_t n_con, const int64_t *con, double radius, mls_blend *b)
{
    memset(b, 0, sizeof *b);
    if (!(radius > 0) || n_con == 0) return CM_OK;
    double *cx = malloc(n_con * 3 * sizeof *cx);
    if (!cx) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory (blend)");
    for (size_t i = 0; i < n_con; ++i)
        memcpy(cx + 3 * i, xyz + 3 * con[i], 3 * sizeof *cx);
    mls_grid g;
    cm_status s = mls_grid_build(ctx, &g, n_con, cx, 4.0);
    if (s < 0) {
        free(cx);
        return s;
    }
    int near = n_con > BLEND_NEAR ? BLEND_NEAR : (int)n_con - 1;
    if (near < 1) near = 1;
    /* pass 1: which free nodes lie in the band (d1 < R) */
    unsigned char *in = calloc(n ? n : 1, 1);
    if (!in) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory (blend)");
    int nt = cm_context_threads_for(ctx, n, 5000);
    if (s >= 0) {
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
        for (size_t i = 0; i < n; ++i) {
            if (is_con[i]) continue;
            int32_t idx[1];
            double d[1];
            if (mls_grid_nearest(&g, xyz + 3 * i, 1, idx, d) == 1 && d[0] < radius) in[i] = 1;
        }
        for (size_t i = 0; i < n; ++i)
            b->n += in[i];
        b->node = malloc((b->n ? b->n : 1) * sizeof *b->node);
        b->row = malloc((b->n + 1) * sizeof *b->row);
        b->col = malloc((b->n ? b->n : 1) * (size_t)near * sizeof *b->col);
        b->val = malloc((b->n ? b->n : 1) * (size_t)near * sizeof *b->val);
        if (!b->node || !b->row || !b->col || !b->val)
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory (blend)");
    }
    if (s >= 0) {
        for (size_t i = 0, j = 0; i < n; ++i)
            if (in[i]) b->node[j++] = (int64_t)i;
        /* pass 2: fixed-width rows (near entries; unused ones get weight 0) */
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
        for (size_t j = 0; j < b->n; ++j) {
            int32_t idx[BLEND_NEAR + 1];
            double d[BLEND_NEAR + 1], w[BLEND_NEAR];
            const double *x = xyz + 3 * b->node[j];
            int m = mls_grid_nearest(&g, x, near + 1, idx, d);
            int use = m > near ? near : m;
            double rx = m > near ? d[near] : d[m - 1] * 1.5 + 1e-300, sum = 0;
            for (int q = 0; q < use; ++q) {
                double t = rx > d[q] ? (rx - d[q]) / (rx * d[q]) : 0;
                w[q] = d[0] > 0 ? t * t : q == 0; /* on a constrained node's position: its r */
                sum += w[q];
            }
            /* all of them as far as the next (a lattice): the nearest ones alike */
            if (!(sum > 0))
                for (int q = 0; q < use; ++q)
                    sum += w[q] = d[q] <= d[0];
            double scale = decay(d[0] / radius) / (sum > 0 ? sum : 1);
            for (int q = 0; q < near; ++q) {
                b->col[(size_t)near * j + (size_t)q] = q < use ? idx[q] : idx[0];
                b->val[(size_t)near * j + (size_t)q] = q < use && sum > 0 ? w[q] * scale : 0;
            }
        }
        b->width = near;
        for (size_t j = 0; j <= b->n; ++j)
            b->row[j] = (int64_t)j * near;
    }
    free(in);
    free(cx);
    mls_grid_free(&g);
    if (s < 0) mls_blend_free(b);
    return s;
}

void mls_blend_apply(const mls_blend *b, const double *r, double *disp, int threads)
{
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
    for (size_t j = 0; j < b->n; ++j) {
        double c[3] = {0, 0, 0};
        for (int64_t p = b->row[j]; p < b->row[j + 1]; ++p)
            for (int a = 0; a < 3; ++a)
                c[a] += b->val[p] * r[3 * (size_t)b->col[p] + a];
        for (int a = 0; a < 3; ++a)
            disp[3 * (size_t)b->node[j] + a] += c[a];
    }
}
