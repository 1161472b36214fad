/* Curved slides (motion.h): a patch that is not flat keeps its nodes on its initial surface,
 * the closest point of its triangles (faces fanned from their first corner). The candidates
 * are the triangles whose centroids are nearest the query (a kD-tree); a node moves along the
 * surface by a fraction of the local face size per warp, so the closest triangle is among
 * them (docs/DESIGN.md, "Boundary motion by patch kind"). */
#include "motion_internal.h"

#include "cadmorph/kdtree.h"

#include <stdlib.h>
#include <string.h>

#define CANDIDATES 16

struct cm_motion_surface {
    size_t n_tri;
    double *tri; /* n_tri x 9 */
    cm_kdtree *tree;
};

cm_status cm_motion_surface_create(cm_context *ctx, const cm_mesh *mesh, const double *xyz,
                                   int tag, cm_motion_surface **out)
{
    *out = NULL;
    size_t nt = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *ci = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (ci && ci->dim == 2 && mesh->physical[c] == tag) {
            int64_t k = mesh->offset[c + 1] - mesh->offset[c];
            if (ci->corners > 0) k = ci->corners;
            nt += k >= 3 ? (size_t)(k - 2) : 0;
        }
    }
    if (!nt) return CM_OK;
    cm_motion_surface *s = calloc(1, sizeof *s);
    double *cen = malloc(3 * nt * sizeof *cen);
    if (!s || !cen || !(s->tri = malloc(9 * nt * sizeof *s->tri))) {
        free(cen);
        cm_motion_surface_destroy(s);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
    }
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *ci = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!ci || ci->dim != 2 || mesh->physical[c] != tag) continue;
        const int64_t *nd = mesh->conn + mesh->offset[c];
        int64_t k = ci->corners > 0 ? ci->corners : mesh->offset[c + 1] - mesh->offset[c];
        for (int64_t j = 1; j + 1 < k; ++j) {
            double *t = s->tri + 9 * s->n_tri;
            memcpy(t, xyz + 3 * nd[0], 3 * sizeof *t);
            memcpy(t + 3, xyz + 3 * nd[j], 3 * sizeof *t);
            memcpy(t + 6, xyz + 3 * nd[j + 1], 3 * sizeof *t);
            for (int q = 0; q < 3; ++q)
                cen[3 * s->n_tri + q] = (t[q] + t[3 + q] + t[6 + q]) / 3;
            ++s->n_tri;
        }
    }
    cm_status st = cm_kdtree_create(ctx, cen, s->n_tri, &s->tree);
    free(cen);
    if (st < 0) {
        cm_motion_surface_destroy(s);
        return st;
    }
    *out = s;
    return CM_OK;
}

void cm_motion_surface_destroy(cm_motion_surface *s)
{
    if (!s) return;
    cm_kdtree_destroy(&s->tree);
    free(s->tri);
    free(s);
}

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5). */
static void closest_on_triangle(const double *p, const double *a, const double *b,
                                const double *c, double *out)
{
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int k = 0; k < 3; ++k)
        ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k], bp[k] = p[k] - b[k],
        cp[k] = p[k] - c[k];
    double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) {
        memcpy(out, a, 3 * sizeof *out);
        return;
    }
    double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) {
        memcpy(out, b, 3 * sizeof *out);
        return;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        for (int k = 0; k < 3; ++k)
            out[k] = a[k] + v * ab[k];
        return;
    }
    double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) {
        memcpy(out, c, 3 * sizeof *out);
        return;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double w = d2 / (d2 - d6);
        for (int k = 0; k < 3; ++k)
            out[k] = a[k] + w * ac[k];
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        for (int k = 0; k < 3; ++k)
            out[k] = b[k] + w * (c[k] - b[k]);
        return;
    }
    double den = 1 / (va + vb + vc), v = vb * den, w = vc * den;
    for (int k = 0; k < 3; ++k)
        out[k] = a[k] + ab[k] * v + ac[k] * w;
}

void cm_motion_surface_closest(const cm_motion_surface *s, const double *p, double *out)
{
    int64_t idx[CANDIDATES];
    int k = s->n_tri < CANDIDATES ? (int)s->n_tri : CANDIDATES;
    memcpy(out, p, 3 * sizeof *out);
    /* a single-threaded query: the callers loop over nodes */
    if (cm_kdtree_nearest(NULL, s->tree, p, 1, k, idx, NULL) < 0) return;
    double best = -1;
    for (int j = 0; j < k; ++j) {
        const double *t = s->tri + 9 * idx[j];
        double q[3], d[3];
        closest_on_triangle(p, t, t + 3, t + 6, q);
        for (int c = 0; c < 3; ++c)
            d[c] = q[c] - p[c];
        double d2 = dot(d, d);
        if (best < 0 || d2 < best) best = d2, memcpy(out, q, 3 * sizeof *out);
    }
}
