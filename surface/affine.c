/* Affine edits G' = A G + b reproduced exactly (benchmarks/RESULTS.md, Affine edits). Arc length is not
 * affine-invariant (a circle becomes an ellipse), nor is a face's (u,v) once OpenCASCADE
 * converts a plane into a B-spline, so the surface morph's correspondences slide nodes along
 * G' under such edits. Here A, b are estimated from the corresponding vertices (least
 * squares), and an edge or face is called an affine image when A x + b of points spread over
 * it lands on its counterpart in G' (within a tolerance of the model size); the morph then
 * sends a node at x to the projection of A x + b, which is A x + b itself. Edits that are
 * not affine fail the vertex fit and keep the arc-length / parameter-warp morph unchanged.
 * When the vertices cannot determine A (fewer than 4, or coplanar: a revolved part), the map
 * comes from the volume moments and points over the edges and faces (affine_fit.c). */
#include "surface_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cm_surface_affine_apply(const cm_surface_affine *a, const double *x, double *y)
{
    for (int i = 0; i < 3; ++i)
        y[i] = a->m[i][0] * x[0] + a->m[i][1] * x[1] + a->m[i][2] * x[2] + a->m[i][3];
}

/* 3 x 3 inverse by cofactors; 0 if singular relative to the matrix's own scale. */
static int inverse3(const double c[3][3], double inv[3][3])
{
    double det = c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) -
                 c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0]) +
                 c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
    double tr = (c[0][0] + c[1][1] + c[2][2]) / 3;
    /* the centred second moments of the vertices: a flat or collinear set (det ~ 0 against
     * tr^3) leaves A undetermined across it */
    if (!(tr > 0) || !(fabs(det) > 1e-9 * tr * tr * tr)) return 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
            inv[i][j] = (c[i1][j1] * c[i2][j2] - c[i1][j2] * c[i2][j1]) / det;
        }
    return 1;
}

cm_status cm_surface_affine_fit(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                                double tol, cm_surface_affine *a)
{
    memset(a, 0, sizeof *a);
    a->residual = INFINITY;
    cm_cad_counts c;
    cm_cad_get_counts(g, &c);
    double *x = malloc(6 * (size_t)(c.vertices > 0 ? c.vertices : 1) * sizeof *x);
    if (!x) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    double *y = x + 3 * (size_t)c.vertices, xc[3] = {0, 0, 0}, yc[3] = {0, 0, 0};
    cm_status r = CM_OK;
    for (int v = 0; v < c.vertices && r == CM_OK; ++v) {
        r = cm_cad_vertex_point(ctx, g, v, x + 3 * v);
        if (r == CM_OK) r = cm_cad_vertex_point(ctx, g2, v, y + 3 * v);
        for (int i = 0; i < 3 && r == CM_OK; ++i)
            xc[i] += x[3 * v + i] / c.vertices, yc[i] += y[3 * v + i] / c.vertices;
    }
    double cxx[3][3] = {{0}}, cyx[3][3] = {{0}}, inv[3][3];
    for (int v = 0; v < c.vertices && r == CM_OK; ++v)
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                cxx[i][j] += (x[3 * v + i] - xc[i]) * (x[3 * v + j] - xc[j]);
                cyx[i][j] += (y[3 * v + i] - yc[i]) * (x[3 * v + j] - xc[j]);
            }
    if (r == CM_OK && (c.vertices < 4 || !inverse3(cxx, inv))) {
        /* the vertices leave A undetermined across their plane or line (affine_fit.c) */
        r = cm_surface_affine_fit_samples(ctx, g, g2, x, y, c.vertices, tol, a);
    } else if (r == CM_OK) {
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                a->m[i][j] = cyx[i][0] * inv[0][j] + cyx[i][1] * inv[1][j] + cyx[i][2] * inv[2][j];
            a->m[i][3] = yc[i] - a->m[i][0] * xc[0] - a->m[i][1] * xc[1] - a->m[i][2] * xc[2];
        }
        double worst = 0;
        for (int v = 0; v < c.vertices; ++v) {
            double p[3];
            cm_surface_affine_apply(a, x + 3 * v, p);
            double d = sqrt((p[0] - y[3 * v]) * (p[0] - y[3 * v]) +
                            (p[1] - y[3 * v + 1]) * (p[1] - y[3 * v + 1]) +
                            (p[2] - y[3 * v + 2]) * (p[2] - y[3 * v + 2]));
            if (d > worst) worst = d;
        }
        a->residual = worst;
        a->tol = tol;
        a->valid = worst <= tol;
    }
    free(x);
    return r;
}

/* Points at equal steps of t on edge e of G: their images must lie on e in G'. The vertices
 * matched already (the fit). */
cm_status cm_surface_affine_edge(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                                 const cm_surface_affine *a, int e, int n, int *is_image)
{
    *is_image = 0;
    if (!a->valid) return CM_OK;
    cm_cad_edge_info ei;
    cm_status r = cm_cad_edge_get_info(ctx, g, e, &ei);
    if (r < 0) return r;
    if (ei.degenerate) { /* a point: it is its vertex, which matched */
        *is_image = 1;
        return CM_OK;
    }
    double *t = malloc((size_t)n * 8 * sizeof *t);
    if (!t) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    double *x = t + n, *y = x + 3 * n, *d = y + 3 * n;
    for (int i = 0; i < n; ++i)
        t[i] = ei.t_range[0] + (i + 0.5) / n * (ei.t_range[1] - ei.t_range[0]);
    r = cm_cad_edge_eval(ctx, g, e, t, (size_t)n, x);
    for (int i = 0; i < n && r >= 0; ++i)
        cm_surface_affine_apply(a, x + 3 * i, y + 3 * i);
    if (r >= 0) r = cm_cad_project_edge(ctx, g2, e, y, (size_t)n, t, d);
    if (r >= 0) {
        *is_image = 1;
        for (int i = 0; i < n; ++i)
            if (!(d[i] <= a->tol)) *is_image = 0;
    }
    free(t);
    return r < 0 ? r : CM_OK;
}
