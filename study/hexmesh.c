/* O-grid hex meshes of the bore and pipe models at t = 0. Every node on the model's surface
 * is computed from the surface's own formula (circle, square side, torus section), so the
 * boundary is exact up to rounding; interior nodes blend linearly between the surfaces. */
#include "cadmorph/models.h"

#include <math.h>
#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static cm_status add_hex(cm_context *ctx, cm_mesh *m, const int64_t *n)
{
    return cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, n, 8, 1, 1, 0);
}

/* point at arc-length fraction f in [0, 1) of the square [-h, h]^2, from (h, 0) anticlockwise */
static void square_point(double h, double f, double *x, double *y)
{
    double s = fmod(f * 8.0 * h + h, 8.0 * h); /* from the corner (h, -h) */
    if (s < 2 * h) *x = h, *y = -h + s;
    else if (s < 4 * h) *x = h - (s - 2 * h), *y = h;
    else if (s < 6 * h) *x = -h, *y = h - (s - 4 * h);
    else *x = -h + (s - 6 * h), *y = -h;
}

cm_status cm_hexmesh_bore(cm_context *ctx, int n_theta, int n_r, int n_z, double grading,
                          cm_mesh **mesh)
{
    *mesh = NULL;
    if (n_theta < 8 || n_theta % 8 || n_r < 1 || n_z < 1 || !(grading > 0))
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_hexmesh_bore: n_theta %d (multiple of 8), n_r %d, n_z %d, grading %g",
                        n_theta, n_r, n_z, grading);
    cm_model_bore p;
    cm_model_bore_at(0, &p);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_create(ctx, &m);
    const size_t layer = (size_t)n_theta * (n_r + 1);
    if (s >= 0) s = cm_mesh_resize_nodes(ctx, m, layer * (n_z + 1), 0);
    if (s < 0) {
        cm_mesh_destroy(&m);
        return s;
    }
    for (int k = 0; k <= n_z; ++k)
        for (int j = 0; j < n_theta; ++j) {
            const double th = 2 * M_PI * j / n_theta;
            double sx, sy;
            square_point(2.0, (double)j / n_theta, &sx, &sy);
            for (int i = 0; i <= n_r; ++i) {
                /* geometric spacing: cell i is grading^i times the first */
                const double f = grading == 1 ? (double)i / n_r
                                              : (pow(grading, i) - 1) / (pow(grading, n_r) - 1);
                double *x = &m->xyz[3 * ((size_t)k * layer + (size_t)j * (n_r + 1) + i)];
                const double cx = p.radius * cos(th), cy = p.radius * sin(th);
                /* the ends exactly on their surfaces, not through the blend's rounding */
                x[0] = i == 0 ? cx : i == n_r ? sx : (1 - f) * cx + f * sx;
                x[1] = i == 0 ? cy : i == n_r ? sy : (1 - f) * cy + f * sy;
                x[2] = 2.0 * k / n_z;
            }
        }
    /* (r, theta, z) is right-handed: the VTK hex order gives a positive Jacobian */
    for (int k = 0; k < n_z && s >= 0; ++k)
        for (int j = 0; j < n_theta && s >= 0; ++j)
            for (int i = 0; i < n_r && s >= 0; ++i) {
                const int j1 = (j + 1) % n_theta;
                int64_t n[8];
                for (int z = 0; z < 2; ++z) {
                    const int64_t base = (int64_t)(k + z) * (int64_t)layer;
                    n[4 * z + 0] = base + (int64_t)j * (n_r + 1) + i;
                    n[4 * z + 1] = base + (int64_t)j * (n_r + 1) + i + 1;
                    n[4 * z + 2] = base + (int64_t)j1 * (n_r + 1) + i + 1;
                    n[4 * z + 3] = base + (int64_t)j1 * (n_r + 1) + i;
                }
                s = add_hex(ctx, m, n);
            }
    if (s >= 0) s = cm_mesh_add_group(ctx, m, 3, 1, "bore");
    if (s < 0) cm_mesh_destroy(&m);
    *mesh = m;
    return s;
}

/* The disc's 2D O-grid: nodes uv (n2 x 2) and quads (nq x 4, anticlockwise). */
typedef struct disc {
    int n2, nq;
    double *uv;
    int *quad;
} disc;

static int disc_build(disc *d, double radius, int n, int n_ring)
{
    const double a = 0.36 * radius; /* half-width of the central square */
    const int inner = (n + 1) * (n + 1), perim = 4 * n;
    d->n2 = inner + perim * n_ring;
    d->nq = n * n + perim * n_ring;
    d->uv = malloc(2 * (size_t)d->n2 * sizeof *d->uv);
    d->quad = malloc(4 * (size_t)d->nq * sizeof *d->quad);
    if (!d->uv || !d->quad) return -1;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            d->uv[2 * (j * (n + 1) + i)] = -a + 2 * a * i / n;
            d->uv[2 * (j * (n + 1) + i) + 1] = -a + 2 * a * j / n;
        }
    /* index of the central node at perimeter position q (anticlockwise from (-a, -a)) */
    int *ring0 = malloc((size_t)perim * sizeof *ring0);
    if (!ring0) return -1;
    for (int q = 0; q < perim; ++q) {
        const int side = q / n, t = q % n;
        int i, j;
        if (side == 0) i = t, j = 0;
        else if (side == 1) i = n, j = t;
        else if (side == 2) i = n - t, j = n;
        else i = 0, j = n - t;
        ring0[q] = j * (n + 1) + i;
    }
    for (int r = 1; r <= n_ring; ++r)
        for (int q = 0; q < perim; ++q) {
            const double *in = &d->uv[2 * ring0[q]];
            const double phi = 1.25 * M_PI + 2 * M_PI * q / perim; /* (-a,-a) sits at 225 deg */
            const double f = (double)r / n_ring;
            double *o = &d->uv[2 * (inner + (r - 1) * perim + q)];
            if (r == n_ring) {
                o[0] = radius * cos(phi), o[1] = radius * sin(phi);
            } else {
                o[0] = (1 - f) * in[0] + f * radius * cos(phi);
                o[1] = (1 - f) * in[1] + f * radius * sin(phi);
            }
        }
    int c = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i, ++c) {
            int *qd = &d->quad[4 * c];
            qd[0] = j * (n + 1) + i, qd[1] = qd[0] + 1, qd[2] = qd[0] + n + 2, qd[3] = qd[0] + n + 1;
        }
    for (int r = 0; r < n_ring; ++r)
        for (int q = 0; q < perim; ++q, ++c) {
            const int q1 = (q + 1) % perim;
            const int lo0 = r == 0 ? ring0[q] : inner + (r - 1) * perim + q;
            const int lo1 = r == 0 ? ring0[q1] : inner + (r - 1) * perim + q1;
            int *qd = &d->quad[4 * c];
            /* outward, then anticlockwise: an anticlockwise quad */
            qd[0] = lo0, qd[1] = inner + r * perim + q, qd[2] = inner + r * perim + q1, qd[3] = lo1;
        }
    free(ring0);
    return 0;
}

cm_status cm_hexmesh_pipe(cm_context *ctx, int n, int n_ring, double step, cm_mesh **mesh)
{
    *mesh = NULL;
    if (n < 1 || n_ring < 1 || !(step > 0))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_hexmesh_pipe: n %d, n_ring %d, step %g", n, n_ring,
                        step);
    cm_model_pipe p;
    cm_model_pipe_at(0, &p);
    const double alpha = p.bend_deg * M_PI / 180.0;
    const int n1 = (int)ceil(p.inlet / step), n2 = (int)ceil(p.bend_radius * alpha / step),
              n3 = (int)ceil(p.outlet / step), ns = n1 + n2 + n3 + 1;
    disc d = {0, 0, NULL, NULL};
    if (disc_build(&d, p.radius, n, n_ring) < 0) {
        free(d.uv), free(d.quad);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_hexmesh_pipe: out of memory");
    }
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_create(ctx, &m);
    if (s >= 0) s = cm_mesh_resize_nodes(ctx, m, (size_t)ns * d.n2, 0);
    for (int k = 0; k < ns && s >= 0; ++k) {
        /* centre c and the section's frame (e1, e2 = z); e1 x e2 is the tangent */
        double c[3], e1[3];
        if (k <= n1) {
            c[0] = p.inlet * k / n1, c[1] = 0, c[2] = 0;
            e1[0] = 0, e1[1] = 1, e1[2] = 0;
        } else if (k <= n1 + n2) {
            const double phi = alpha * (k - n1) / n2;
            c[0] = p.inlet + p.bend_radius * sin(phi), c[1] = p.bend_radius * (1 - cos(phi)), c[2] = 0;
            e1[0] = -sin(phi), e1[1] = cos(phi), e1[2] = 0;
        } else {
            const double l = p.outlet * (k - n1 - n2) / n3;
            c[0] = p.inlet + p.bend_radius * sin(alpha) + l * cos(alpha);
            c[1] = p.bend_radius * (1 - cos(alpha)) + l * sin(alpha), c[2] = 0;
            e1[0] = -sin(alpha), e1[1] = cos(alpha), e1[2] = 0;
        }
        for (int i = 0; i < d.n2; ++i) {
            double *x = &m->xyz[3 * ((size_t)k * d.n2 + i)];
            const double u = d.uv[2 * i], v = d.uv[2 * i + 1];
            x[0] = c[0] + u * e1[0], x[1] = c[1] + u * e1[1], x[2] = c[2] + v;
        }
    }
    for (int k = 0; k + 1 < ns && s >= 0; ++k)
        for (int q = 0; q < d.nq && s >= 0; ++q) {
            int64_t h[8];
            for (int z = 0; z < 2; ++z)
                for (int v = 0; v < 4; ++v)
                    h[4 * z + v] = (int64_t)(k + z) * d.n2 + d.quad[4 * q + v];
            s = add_hex(ctx, m, h);
        }
    if (s >= 0) s = cm_mesh_add_group(ctx, m, 3, 1, "pipe");
    free(d.uv);
    free(d.quad);
    if (s < 0) cm_mesh_destroy(&m);
    *mesh = m;
    return s;
}
