/* checkMesh's directions and its checks of meshes with fewer than 3 geometric directions,
 * written from the definitions of OpenFOAM v1912 (polyMesh::calcDirections, wedgePolyPatch's
 * geometry, polyMesh::checkEdgeAlignment, checkMesh's checkWedges and findOppositeWedge). */
#define _POSIX_C_SOURCE 200809L
#include "quality_foam_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static int is_type(const cm_foam_patch *pt, const char *type) { return pt->type && !strcmp(pt->type, type); }

/* A wedge patch as wedgePolyPatch defines it: n the average of its unit face normals, the
 * centre normal the coordinate direction n leans from, the axis their cross product. */
typedef struct wedge_geom {
    double n[3], centre[3], axis[3], cos_angle;
} wedge_geom;

static void wedge_of(const cm_foam_patch *pt, const double *fa, wedge_geom *w)
{
    memset(w, 0, sizeof *w);
    for (int64_t f = pt->start; f < pt->start + pt->n; ++f) {
        const double *a = fa + 3 * f;
        const double m = sqrt(dot(a, a));
        for (int k = 0; k < 3; ++k) w->n[k] += m > FOAM_VSMALL ? a[k] / m : 0;
    }
    for (int k = 0; k < 3; ++k) w->n[k] /= (double)(pt->n ? pt->n : 1);
    for (int k = 0; k < 3; ++k) {
        const double a = fabs(w->n[k]);
        w->centre[k] = (w->n[k] < 0 ? -1.0 : 1.0) * ((a > 0.5 ? a : 0.5) - 0.5);
    }
    double m = sqrt(dot(w->centre, w->centre));
    if (m > FOAM_VSMALL)
        for (int k = 0; k < 3; ++k) w->centre[k] /= m;
    w->cos_angle = dot(w->centre, w->n);
    const double *c = w->centre, *n = w->n;
    w->axis[0] = c[1] * n[2] - c[2] * n[1];
    w->axis[1] = c[2] * n[0] - c[0] * n[2];
    w->axis[2] = c[0] * n[1] - c[1] * n[0];
    m = sqrt(dot(w->axis, w->axis));
    if (m > FOAM_VSMALL)
        for (int k = 0; k < 3; ++k) w->axis[k] /= m;
}

void cm_foam_directions(const cm_foam_poly *p, const double *xyz, const double *fa, cm_foam_quality *q)
{
    (void)xyz;
    double e[3] = {0, 0, 0}, w[3] = {0, 0, 0};
    int n_empty = 0, n_wedge = 0;
    for (size_t i = 0; i < p->n_patches; ++i) {
        const cm_foam_patch *pt = &p->patches[i];
        if (pt->n == 0) continue;
        if (is_type(pt, "empty")) {
            ++n_empty;
            for (int64_t f = pt->start; f < pt->start + pt->n; ++f)
                for (int k = 0; k < 3; ++k) e[k] += fabs(fa[3 * f + k]);
        } else if (is_type(pt, "wedge")) {
            wedge_geom g;
            wedge_of(pt, fa, &g);
            ++n_wedge;
            for (int k = 0; k < 3; ++k) w[k] += fabs(g.centre[k]);
        }
    }
    const double me = sqrt(dot(e, e)), mw = sqrt(dot(w, w));
    for (int k = 0; k < 3; ++k) {
        q->solution_directions[k] = n_empty && me > FOAM_VSMALL && e[k] / me > 1e-6 ? -1 : 1;
        /* wedges decide every geometric direction when there are any (as calcDirections) */
        q->directions[k] = n_wedge ? (mw > FOAM_VSMALL && w[k] / mw > 1e-6 ? -1 : 1) : q->solution_directions[k];
    }
}

typedef struct edge_rec {
    int64_t a, b;
    int wedge; /* 1: an edge of a wedge patch (never an error) */
} edge_rec;

static int cmp_edge(const void *x, const void *y)
{
    const edge_rec *p = x, *q = y;
    if (p->a != q->a) return p->a < q->a ? -1 : 1;
    if (p->b != q->b) return p->b < q->b ? -1 : 1;
    return q->wedge - p->wedge; /* wedge edges first */
}

/* Edges of faces (each once: from the face that walks it from its lower point) that lean
 * into a taken direction while not lying along it: counted once per edge, edges of wedge
 * patches excepted. */
static cm_status misaligned_edges(cm_context *ctx, const cm_foam_poly *p, const double *xyz, const int *dirs,
                                  int wedges, size_t *count)
{
    size_t n = 0, cap = 1024;
    edge_rec *e = malloc(cap * sizeof *e);
    if (!e) return cm_error(ctx, CM_ERR_NOMEM, "out of memory for the edge alignment check");
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 0 && !wedges) continue;
        for (size_t pi = 0; pi < (pass ? 1 : p->n_patches); ++pi) {
            const int64_t f0 = pass ? 0 : p->patches[pi].start;
            const int64_t f1 = pass ? p->n_faces : f0 + p->patches[pi].n;
            if (!pass && !is_type(&p->patches[pi], "wedge")) continue;
            for (int64_t f = f0; f < f1; ++f) {
                const int64_t *v = p->face_nodes + p->face_off[f], k = p->face_off[f + 1] - p->face_off[f];
                for (int64_t i = 0; i < k; ++i) {
                    int64_t a = v[i], b = v[(i + 1) % k];
                    if (pass) {
                        if (a >= b) continue;
                        double d[3], m = 0;
                        for (int c = 0; c < 3; ++c) {
                            d[c] = xyz[3 * b + c] - xyz[3 * a + c];
                            m += d[c] * d[c];
                        }
                        m = sqrt(m);
                        if (m <= FOAM_ROOTVSMALL) continue;
                        int taken = 0, kept = 0;
                        for (int c = 0; c < 3; ++c)
                            if (fabs(d[c] / m) > 1e-6) {
                                if (dirs[c] == 1) ++kept;
                                else ++taken;
                            }
                        if (taken == 0 || (taken == 1 && kept == 0)) continue;
                    } else if (a > b) {
                        int64_t t = a;
                        a = b;
                        b = t;
                    }
                    if (n == cap) {
                        edge_rec *t = realloc(e, 2 * cap * sizeof *e);
                        if (!t) {
                            free(e);
                            return cm_error(ctx, CM_ERR_NOMEM, "out of memory for the edge alignment check");
                        }
                        e = t;
                        cap *= 2;
                    }
                    e[n++] = (edge_rec){a, b, !pass};
                }
            }
        }
    }
    qsort(e, n, sizeof *e, cmp_edge);
    size_t bad = 0;
    for (size_t i = 0; i < n; ++i) {
        if (i > 0 && e[i].a == e[i - 1].a && e[i].b == e[i - 1].b) continue;
        if (!e[i].wedge) ++bad;
    }
    free(e);
    *count = bad;
    return CM_OK;
}

cm_status cm_foam_check_alignment(cm_context *ctx, const cm_foam_poly *p, const double *xyz, const double *fa,
                                  cm_foam_quality *q, int *failed)
{
    *failed = 0;
    const int same = q->directions[0] == q->solution_directions[0] &&
                     q->directions[1] == q->solution_directions[1] &&
                     q->directions[2] == q->solution_directions[2];
    if (same) {
        q->alignment_checked = 1;
        cm_status s = misaligned_edges(ctx, p, xyz, q->directions, 0, &q->non_aligned_edges);
        if (s < 0) return s;
        *failed = q->non_aligned_edges > 0;
        return CM_OK;
    }
    q->alignment_checked = 2;
    int first = 1;
    for (size_t i = 0; i < p->n_patches; ++i) {
        const cm_foam_patch *pt = &p->patches[i];
        if (pt->n == 0 || !is_type(pt, "wedge")) continue;
        wedge_geom w;
        wedge_of(pt, fa, &w);
        if (first) q->wedge_angle = acos(w.cos_angle < -1 ? -1 : w.cos_angle > 1 ? 1 : w.cos_angle) * 180.0 / M_PI;
        first = 0;
        /* the opposite wedge: as many faces, the same axis, another angle to this centre normal */
        int found = 0;
        for (size_t j = 0; j < p->n_patches && !found; ++j) {
            const cm_foam_patch *o = &p->patches[j];
            if (j == i || o->n == 0 || !is_type(o, "wedge")) continue;
            wedge_geom v;
            wedge_of(o, fa, &v);
            if (o->n == pt->n && fabs(dot(v.axis, w.axis)) >= 1 - 1e-3 &&
                fabs(dot(w.centre, v.n) - w.cos_angle) >= 1e-3)
                found = 1;
        }
        if (!found) {
            q->wedge_error = 1;
            q->wedge_patch = (int64_t)i;
            *failed = 1;
            return CM_OK;
        }
        /* planar: every point of the patch within ROOTSMALL of the first one's plane */
        const int64_t *v0 = p->face_nodes + p->face_off[pt->start];
        const double *x0 = xyz + 3 * v0[0];
        for (int64_t k = p->face_off[pt->start]; k < p->face_off[pt->start + pt->n]; ++k) {
            const double *x = xyz + 3 * p->face_nodes[k];
            double d[3] = {x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]};
            const double dist = fabs(dot(d, w.n));
            if (dist > FOAM_ROOTSMALL) {
                q->wedge_error = 3;
                q->wedge_patch = (int64_t)i;
                q->wedge_off_plane = dist;
                *failed = 1;
                return CM_OK;
            }
        }
    }
    int dirs[3];
    for (int k = 0; k < 3; ++k) dirs[k] = q->directions[k];
    cm_status s = misaligned_edges(ctx, p, xyz, dirs, 1, &q->non_aligned_edges);
    if (s < 0) return s;
    *failed = q->non_aligned_edges > 0;
    return CM_OK;
}
