/* Mean curvature of a surface mesh, H = |lap x| / 2 with the cotangent Laplace-Beltrami
 * operator and barycentric vertex areas (Meyer et al., the operator of the paper's section
 * 3): what Figure 3 plots. Quads and polygons are fanned into triangles. */
#include "cadmorph/mls.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Edge bookkeeping for boundary detection: sorted (a, b) pairs, a < b. */
static int cmp_edge(const void *x, const void *y)
{
    const int64_t *a = x, *b = y;
    if (a[0] != b[0]) return (a[0] > b[0]) - (a[0] < b[0]);
    return (a[1] > b[1]) - (a[1] < b[1]);
}

cm_status cm_mls_mean_curvature(cm_context *ctx, const cm_mesh *mesh, double *H,
                                unsigned char *boundary)
{
    if (!mesh || !H) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_mean_curvature: NULL argument");
    size_t n = mesh->n_nodes, nt = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!info || info->dim != 2) continue;
        int64_t len = info->corners > 0 ? info->corners : mesh->offset[c + 1] - mesh->offset[c];
        if (len >= 3) nt += (size_t)(len - 2);
    }
    double *lap = calloc((n ? n : 1) * 3, sizeof *lap), *area = calloc(n ? n : 1, sizeof *area);
    int64_t *edges = malloc((nt ? nt : 1) * 3 * 2 * sizeof *edges);
    if (!lap || !area || !edges) {
        free(lap), free(area), free(edges);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_mean_curvature: out of memory");
    }
    size_t ne = 0;
    const double *x = mesh->xyz;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!info || info->dim != 2) continue;
        const int64_t *p = mesh->conn + mesh->offset[c];
        int64_t len = info->corners > 0 ? info->corners : mesh->offset[c + 1] - mesh->offset[c];
        /* polygon edges (not the fan's diagonals) decide the boundary */
        for (int64_t i = 0; i < len; ++i) {
            int64_t a = p[i], b = p[(i + 1) % len];
            edges[2 * ne] = a < b ? a : b, edges[2 * ne + 1] = a < b ? b : a;
            ++ne;
        }
        for (int64_t f = 1; f + 1 < len; ++f) {
            int64_t v[3] = {p[0], p[f], p[f + 1]};
            double e[3][3], cr[3];
            for (int q = 0; q < 3; ++q)
                for (int a = 0; a < 3; ++a)
                    e[q][a] = x[3 * v[(q + 2) % 3] + a] - x[3 * v[(q + 1) % 3] + a];
            cr[0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
            cr[1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
            cr[2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
            double a2 = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
            if (!(a2 > 0)) continue;
            for (int q = 0; q < 3; ++q) {
                area[v[q]] += a2 / 6;
                /* the angle at v[q] is opposite edge e[q] = v[q+2] - v[q+1] */
                const double *u = e[(q + 1) % 3], *w = e[(q + 2) % 3];
                double cot = -(u[0] * w[0] + u[1] * w[1] + u[2] * w[2]) / a2;
                int64_t i = v[(q + 1) % 3], j = v[(q + 2) % 3];
                for (int a = 0; a < 3; ++a) {
                    double d = x[3 * j + a] - x[3 * i + a];
                    lap[3 * i + a] += 0.5 * cot * d;
                    lap[3 * j + a] -= 0.5 * cot * d;
                }
            }
        }
    }
    qsort(edges, ne, 2 * sizeof *edges, cmp_edge);
    unsigned char *bnd = boundary ? boundary : calloc(n ? n : 1, 1);
    if (!bnd) {
        free(lap), free(area), free(edges);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_mean_curvature: out of memory");
    }
    memset(bnd, 0, n);
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && edges[2 * j] == edges[2 * i] && edges[2 * j + 1] == edges[2 * i + 1])
            ++j;
        if (j - i == 1) bnd[edges[2 * i]] = bnd[edges[2 * i + 1]] = 1;
        i = j;
    }
    for (size_t i = 0; i < n; ++i) {
        double l = sqrt(lap[3 * i] * lap[3 * i] + lap[3 * i + 1] * lap[3 * i + 1] +
                        lap[3 * i + 2] * lap[3 * i + 2]);
        H[i] = area[i] > 0 && !bnd[i] ? 0.5 * l / area[i] : 0;
    }
    if (!boundary) free(bnd);
    free(lap), free(area), free(edges);
    return CM_OK;
}
