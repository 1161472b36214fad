/* The snap of the Shape-Up alternation (shapeup.h, cm_shapeup_options.snap): the set nodes
 * onto their shapes after everything else is applied, so that a plane holds to rounding in
 * the written result. Two things would break it otherwise:
 *  - exact constraints (keep_constrained): the constrained nodes of a set keep their
 *    prescribed positions, which lie on the true plane (a fixed wall, a handle moving within
 *    it), while the alternation's plane is fitted to the field's positions, which miss them.
 *    So a plane set with constrained nodes spanning a plane is fitted to those alone, and the
 *    free nodes go onto that plane;
 *  - a node of two plane sets (the axis of a wedge: both wedge planes; a corner of two
 *    symmetry planes) goes to the closest point of their intersection, not onto the last
 *    plane only. */
#include "mls_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A plane n.x = e (unit n) through the anchors (n x 3) if they span one: NULL-free fit of
 * cm_shape_project_plane after a check that they are not (nearly) collinear. Returns 1 if
 * they do. */
static int anchor_plane(cm_context *ctx, size_t n, const double *a, double tol, double *scratch,
                        double plane[4])
{
    if (n < 3) return 0;
    double c[3] = {0, 0, 0};
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k)
            c[k] += a[3 * i + k] / (double)n;
    size_t far = 0;
    double dmax = -1;
    for (size_t i = 0; i < n; ++i) {
        double d = 0;
        for (int k = 0; k < 3; ++k)
            d += (a[3 * i + k] - c[k]) * (a[3 * i + k] - c[k]);
        if (d > dmax) dmax = d, far = i;
    }
    if (!(dmax > 0)) return 0;
    double u[3], len = sqrt(dmax), off = 0;
    for (int k = 0; k < 3; ++k)
        u[k] = (a[3 * far + k] - c[k]) / len;
    for (size_t i = 0; i < n; ++i) {
        double r[3], t = 0, e = 0;
        for (int k = 0; k < 3; ++k)
            r[k] = a[3 * i + k] - c[k], t += r[k] * u[k];
        for (int k = 0; k < 3; ++k)
            e += (r[k] - t * u[k]) * (r[k] - t * u[k]);
        off = fmax(off, sqrt(e));
    }
    if (!(off > tol)) return 0; /* on a line: no plane of their own */
    double fit[6];
    if (cm_shape_project_plane(ctx, n, a, scratch, fit) < 0) return 0;
    memcpy(plane, fit + 3, 3 * sizeof *plane);
    plane[3] = fit[0] * fit[3] + fit[1] * fit[4] + fit[2] * fit[5];
    return 1;
}

cm_status shapeup_snap(cm_context *ctx, const shapeup_snap_in *in, double *disp, double *move)
{
    const mls_view *v = in->v;
    size_t nt = in->off[in->n_sets];
    int keep = v->keep_constrained;
    cm_status st = CM_OK;
    double *f = malloc((nt ? nt : 1) * 3 * sizeof *f), *tmp = malloc((nt ? nt : 1) * 3 * sizeof *tmp);
    double *plane = malloc((in->n_sets ? in->n_sets : 1) * 4 * sizeof *plane);
    unsigned char *is_plane = calloc(in->n_sets ? in->n_sets : 1, 1);
    int64_t *head = malloc((v->n_nodes ? v->n_nodes : 1) * sizeof *head);
    int64_t *next = malloc((nt ? nt : 1) * sizeof *next);
    size_t *set_of = malloc((nt ? nt : 1) * sizeof *set_of);
    if (!f || !tmp || !plane || !is_plane || !head || !next || !set_of) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_shapeup_apply: out of memory (snap)");
        goto done;
    }
    for (size_t i = 0; i < nt; ++i)
        for (int k = 0; k < 3; ++k)
            f[3 * i + k] = in->ref[3 * i + k] + disp[3 * (size_t)in->nodes[i] + k];
    for (size_t i = 0; i < v->n_nodes; ++i)
        head[i] = -1;
    for (size_t t = 0; t < in->n_sets; ++t)
        for (size_t i = in->off[t]; i < in->off[t + 1]; ++i) {
            set_of[i] = t;
            next[i] = head[in->nodes[i]];
            head[in->nodes[i]] = (int64_t)i;
        }
    /* the planes: through the constrained nodes where they span one, else the least-squares
     * plane of the set's positions as they are now */
    for (size_t t = 0; t < in->n_sets; ++t) {
        if (in->type[t] != CM_SHAPE_PLANE) continue;
        size_t o = in->off[t], n = in->off[t + 1] - o, na = 0;
        if (keep)
            for (size_t i = o; i < o + n; ++i)
                if (v->is_con[in->nodes[i]]) memcpy(tmp + 3 * na++, f + 3 * i, 3 * sizeof *tmp);
        is_plane[t] = (unsigned char)(na && anchor_plane(ctx, na, tmp, 1e-9 * in->diag, tmp, plane + 4 * t));
        if (!is_plane[t]) {
            double fit[6];
            st = cm_shape_project_plane(ctx, n, f + 3 * o, tmp, fit);
            if (st < 0) goto done;
            memcpy(plane + 4 * t, fit + 3, 3 * sizeof *plane);
            plane[4 * t + 3] = fit[0] * fit[3] + fit[1] * fit[4] + fit[2] * fit[5];
            is_plane[t] = 1;
        }
    }
    double mv = 0;
    for (size_t t = 0; t < in->n_sets; ++t)
        for (size_t i = in->off[t]; i < in->off[t + 1]; ++i) {
            int64_t node = in->nodes[i];
            if (keep && v->is_con[node]) continue; /* prescribed stays */
            if (head[node] != (int64_t)i) continue; /* a node of several sets: once, by its last */
            double q[3];
            memcpy(q, f + 3 * i, sizeof q);
            if (is_plane[t]) {
                /* the closest point on every plane of the node at once: the constraints
                 * n_j.q = e_j made orthonormal (Gram-Schmidt; a plane parallel to an earlier
                 * one adds nothing), then q -= sum_j (u_j.q - g_j) u_j */
                double u[3][3], g[3];
                int m = 0;
                for (int64_t e = (int64_t)i; e >= 0 && m < 3; e = next[e]) {
                    size_t tt = set_of[e];
                    if (in->type[tt] != CM_SHAPE_PLANE) continue;
                    double w[3], h = plane[4 * tt + 3];
                    memcpy(w, plane + 4 * tt, sizeof w);
                    for (int j = 0; j < m; ++j) {
                        double dt = w[0] * u[j][0] + w[1] * u[j][1] + w[2] * u[j][2];
                        for (int k = 0; k < 3; ++k)
                            w[k] -= dt * u[j][k];
                        h -= dt * g[j];
                    }
                    double len = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
                    if (!(len > 1e-8)) continue;
                    for (int k = 0; k < 3; ++k)
                        u[m][k] = w[k] / len;
                    g[m++] = h / len;
                }
                for (int j = 0; j < m; ++j) {
                    double r = u[j][0] * q[0] + u[j][1] * q[1] + u[j][2] * q[2] - g[j];
                    for (int k = 0; k < 3; ++k)
                        q[k] -= r * u[j][k];
                }
            } else {
                memcpy(q, in->p + 3 * i, sizeof q); /* the set's own projection */
            }
            double e = 0;
            for (int k = 0; k < 3; ++k) {
                double target = q[k] - in->ref[3 * i + k];
                e += (target - disp[3 * node + k]) * (target - disp[3 * node + k]);
                disp[3 * node + k] = target;
            }
            mv = fmax(mv, sqrt(e));
        }
    *move = mv;
done:
    free(f), free(tmp), free(plane), free(is_plane), free(head), free(next), free(set_of);
    return st;
}
