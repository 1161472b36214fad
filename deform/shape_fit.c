/* Shape-Up projections (paper section 6.2; Bouaziz et al. 2012): each projection is the
 * nearest point set of its kind, found through a least-squares fit of that kind: plane
 * (total least squares), circle (geometric fit in the plane), cylinder (Eberly's direction
 * search, then Levenberg-Marquardt on the geometric distances), cone (the same search on a
 * cone's algebraic error, then Levenberg-Marquardt), similar/rigid match (Kabsch/Umeyama). */
#include "cadmorph/shapeup.h"
#include "shape_internal.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static void centroid(size_t n, const double *x, double c[3])
{
    c[0] = c[1] = c[2] = 0;
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a)
            c[a] += x[3 * i + a];
    for (int a = 0; a < 3; ++a)
        c[a] /= (double)n;
}

/* u, v: an orthonormal basis of the plane normal to the unit vector w. */
static void plane_basis(const double w[3], double u[3], double v[3])
{
    double t[3] = {0, 0, 0};
    int ax = fabs(w[0]) < fabs(w[1]) ? (fabs(w[0]) < fabs(w[2]) ? 0 : 2)
                                     : (fabs(w[1]) < fabs(w[2]) ? 1 : 2);
    t[ax] = 1;
    cross3(w, t, u);
    double l = sqrt(dot3(u, u));
    for (int a = 0; a < 3; ++a)
        u[a] /= l;
    cross3(w, u, v);
}

/* shape_internal.h says why the singularity test is relative */
int cm_shape_solve_small(int n, double *a, double *b)
{
    double amax = 0;
    for (int i = 0; i < n * n; ++i) amax = fmax(amax, fabs(a[i]));
    for (int c = 0; c < n; ++c) {
        int p = c;
        for (int r = c + 1; r < n; ++r)
            if (fabs(a[r * n + c]) > fabs(a[p * n + c])) p = r;
        if (!(fabs(a[p * n + c]) > 1e-13 * amax)) return 0;
        if (p != c) {
            for (int j = 0; j < n; ++j) {
                double t = a[c * n + j];
                a[c * n + j] = a[p * n + j], a[p * n + j] = t;
            }
            double t = b[c];
            b[c] = b[p], b[p] = t;
        }
        for (int r = c + 1; r < n; ++r) {
            double f = a[r * n + c] / a[c * n + c];
            for (int j = c; j < n; ++j)
                a[r * n + j] -= f * a[c * n + j];
            b[r] -= f * b[c];
        }
    }
    for (int c = n - 1; c >= 0; --c) {
        double s = b[c];
        for (int j = c + 1; j < n; ++j)
            s -= a[c * n + j] * b[j];
        b[c] = s / a[c * n + c];
    }
    return 1;
}

static int finite_n(size_t n, const double *x)
{
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(x[i])) return 0;
    return 1;
}

/* centroid and the unit normal of the total-least-squares plane (smallest eigenvector of
 * the scatter matrix; dsyev returns eigenvalues ascending) */
static cm_status fit_plane(cm_context *ctx, const char *who, size_t n, const double *x,
                           double c[3], double nrm[3])
{
    centroid(n, x, c);
    double m[9] = {0};
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - c[0], x[3 * i + 1] - c[1], x[3 * i + 2] - c[2]};
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                m[3 * a + b] += y[a] * y[b];
    }
    double ev[3];
    if (LAPACKE_dsyev(LAPACK_ROW_MAJOR, 'V', 'U', 3, m, 3, ev) != 0)
        return cm_error(ctx, CM_ERR_NUMERIC, "%s: eigenvalues of the scatter matrix failed", who);
    nrm[0] = m[0], nrm[1] = m[3], nrm[2] = m[6];
    return CM_OK;
}

static cm_status check_points(cm_context *ctx, const char *who, size_t n, size_t min,
                              const double *x, const double *p)
{
    if (!x || !p) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL points", who);
    if (n < min) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: %zu points, need at least %zu", who, n, min);
    if (!finite_n(3 * n, x)) return cm_error(ctx, CM_ERR_NUMERIC, "%s: non-finite point", who);
    return CM_OK;
}

cm_status cm_shape_project_plane(cm_context *ctx, size_t n, const double *x, double *p,
                                 double fit[6])
{
    cm_status s = check_points(ctx, "cm_shape_project_plane", n, 3, x, p);
    if (s < 0) return s;
    double c[3], nr[3];
    s = fit_plane(ctx, "cm_shape_project_plane", n, x, c, nr);
    if (s < 0) return s;
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - c[0], x[3 * i + 1] - c[1], x[3 * i + 2] - c[2]};
        double h = dot3(y, nr);
        for (int a = 0; a < 3; ++a)
            p[3 * i + a] = x[3 * i + a] - h * nr[a];
    }
    if (fit) memcpy(fit, c, sizeof c), memcpy(fit + 3, nr, sizeof nr);
    return CM_OK;
}

/* Kasa's algebraic circle through 2D points (s, t): min sum (s^2 + t^2 + D s + E t + F)^2,
 * in coordinates scaled by the points' extent L, so that cm_shape_solve_small's relative
 * singularity test does not depend on the units. Returns 0 when the points are collinear
 * (to rounding: an arc whose sagitta is below ~1e-7 of L counts as a line). */
static int circle_algebraic(size_t n, const double *s, const double *t, double *a, double *b,
                            double *r)
{
    double m[9] = {0}, rhs[3] = {0}, L = 0;
    for (size_t i = 0; i < n; ++i) L = fmax(L, fmax(fabs(s[i]), fabs(t[i])));
    if (!(L > 0) || !isfinite(L)) return 0;
    for (size_t i = 0; i < n; ++i) {
        const double si = s[i] / L, ti = t[i] / L;
        double row[3] = {si, ti, 1}, z = -(si * si + ti * ti);
        for (int p = 0; p < 3; ++p) {
            rhs[p] += row[p] * z;
            for (int q = 0; q < 3; ++q)
                m[3 * p + q] += row[p] * row[q];
        }
    }
    if (!cm_shape_solve_small(3, m, rhs)) return 0;
    *a = -rhs[0] / 2, *b = -rhs[1] / 2;
    double r2 = *a * *a + *b * *b - rhs[2];
    if (!(r2 > 0) || !isfinite(r2)) return 0;
    *r = L * sqrt(r2);
    *a *= L, *b *= L;
    return 1;
}

/* Geometric least squares circle: Gauss-Newton on |p_i - c| - r from Kasa's circle, step
 * halving when the cost rises. */
static int circle_geometric(size_t n, const double *s, const double *t, double *a, double *b,
                            double *r)
{
    if (!circle_algebraic(n, s, t, a, b, r)) return 0;
    double cost = 0;
    for (size_t i = 0; i < n; ++i) {
        double e = hypot(s[i] - *a, t[i] - *b) - *r;
        cost += e * e;
    }
    for (int it = 0; it < 100; ++it) {
        double jt[9] = {0}, g[3] = {0};
        for (size_t i = 0; i < n; ++i) {
            double dx = s[i] - *a, dy = t[i] - *b, rho = hypot(dx, dy);
            if (!(rho > 0)) continue;
            double j[3] = {-dx / rho, -dy / rho, -1}, e = rho - *r;
            for (int p = 0; p < 3; ++p) {
                g[p] -= j[p] * e;
                for (int q = 0; q < 3; ++q)
                    jt[3 * p + q] += j[p] * j[q];
            }
        }
        if (!cm_shape_solve_small(3, jt, g)) break;
        double step = 1, nc = cost;
        double na = *a, nb = *b, nr = *r;
        for (int h = 0; h < 30; ++h, step /= 2) {
            na = *a + step * g[0], nb = *b + step * g[1], nr = *r + step * g[2];
            nc = 0;
            for (size_t i = 0; i < n; ++i) {
                double e = hypot(s[i] - na, t[i] - nb) - nr;
                nc += e * e;
            }
            if (nc <= cost) break;
        }
        if (!(nc <= cost)) break;
        double move = fabs(na - *a) + fabs(nb - *b) + fabs(nr - *r);
        *a = na, *b = nb, *r = nr;
        int done = move <= 1e-15 * (*r + fabs(*a) + fabs(*b)) || cost - nc <= 1e-30 + 1e-15 * cost;
        cost = nc;
        if (done) break;
    }
    return *r > 0 && isfinite(*r);
}

cm_status cm_shape_project_circle(cm_context *ctx, size_t n, const double *x, double *p,
                                  double fit[7])
{
    const char *who = "cm_shape_project_circle";
    cm_status st = check_points(ctx, who, n, 3, x, p);
    if (st < 0) return st;
    double c[3], nr[3], u[3], v[3];
    st = fit_plane(ctx, who, n, x, c, nr);
    if (st < 0) return st;
    plane_basis(nr, u, v);
    double *s = calloc(2 * n, sizeof *s);
    if (!s) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
    double *t = s + n;
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - c[0], x[3 * i + 1] - c[1], x[3 * i + 2] - c[2]};
        s[i] = dot3(y, u), t[i] = dot3(y, v);
    }
    double a, b, r;
    if (!circle_geometric(n, s, t, &a, &b, &r)) {
        free(s);
        return cm_error(ctx, CM_ERR_NUMERIC, "%s: %zu points on a line define no circle", who, n);
    }
    for (size_t i = 0; i < n; ++i) {
        double dx = s[i] - a, dy = t[i] - b, rho = hypot(dx, dy);
        /* the centre itself has no nearest circle point: any will do */
        if (!(rho > 0)) dx = 1, dy = 0, rho = 1;
        double ps = a + r * dx / rho, pt = b + r * dy / rho;
        for (int k = 0; k < 3; ++k)
            p[3 * i + k] = c[k] + ps * u[k] + pt * v[k];
    }
    free(s);
    if (fit) {
        for (int k = 0; k < 3; ++k)
            fit[k] = c[k] + a * u[k] + b * v[k], fit[3 + k] = nr[k];
        fit[6] = r;
    }
    return CM_OK;
}

/* ---- cylinder ---- */

/* Eberly's error of a direction w: the algebraic circle residual of the points projected
 * onto the plane normal to w (relative to the spread, so directions compare); also the
 * circle's centre on the axis and its radius. */
static double cylinder_direction_error(size_t n, const double *x, const double *mean,
                                       const double w[3], double *s, double *t, double axis_pt[3],
                                       double *radius)
{
    double u[3], v[3];
    plane_basis(w, u, v);
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - mean[0], x[3 * i + 1] - mean[1], x[3 * i + 2] - mean[2]};
        s[i] = dot3(y, u), t[i] = dot3(y, v);
    }
    double a, b, r;
    if (!circle_algebraic(n, s, t, &a, &b, &r)) return INFINITY;
    double err = 0;
    for (size_t i = 0; i < n; ++i) {
        double e = (s[i] - a) * (s[i] - a) + (t[i] - b) * (t[i] - b) - r * r;
        err += e * e;
    }
    for (int k = 0; k < 3; ++k)
        axis_pt[k] = mean[k] + a * u[k] + b * v[k];
    *radius = r;
    /* algebraic residuals scale with r^2: relative to r^4, so that a huge circle through
     * nearly collinear projections does not win */
    return err / (r * r * r * r);
}

static double cylinder_cost(size_t n, const double *x, const double pt[3], const double w[3],
                            double r)
{
    double cost = 0;
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - pt[0], x[3 * i + 1] - pt[1], x[3 * i + 2] - pt[2]};
        double h = dot3(y, w), q[3] = {y[0] - h * w[0], y[1] - h * w[1], y[2] - h * w[2]};
        double e = sqrt(dot3(q, q)) - r;
        cost += e * e;
    }
    return cost;
}

/* Levenberg-Marquardt on the 5 parameters (axis tilt 2, axis shift 2, radius) of
 * r_i = |(x_i - P) x W| - R, the geometric distance to the cylinder. */
static void cylinder_refine(size_t n, const double *x, const double mean[3], double pt[3],
                            double w[3], double *r)
{
    double cost = cylinder_cost(n, x, pt, w, *r), lambda = -1;
    for (int it = 0; it < 200; ++it) {
        double u[3], v[3], jt[25] = {0}, g[5] = {0};
        plane_basis(w, u, v);
        for (size_t i = 0; i < n; ++i) {
            double y[3] = {x[3 * i] - pt[0], x[3 * i + 1] - pt[1], x[3 * i + 2] - pt[2]};
            double h = dot3(y, w), q[3] = {y[0] - h * w[0], y[1] - h * w[1], y[2] - h * w[2]};
            double d = sqrt(dot3(q, q));
            if (!(d > 0)) continue;
            double nh[3] = {q[0] / d, q[1] / d, q[2] / d};
            double j[5] = {-h * dot3(nh, u), -h * dot3(nh, v), -dot3(nh, u), -dot3(nh, v), -1};
            double e = d - *r;
            for (int a = 0; a < 5; ++a) {
                g[a] -= j[a] * e;
                for (int b = 0; b < 5; ++b)
                    jt[5 * a + b] += j[a] * j[b];
            }
        }
        if (lambda < 0) lambda = 1e-6 * (jt[0] + jt[6] + jt[12] + jt[18] + jt[24]) / 5;
        int accepted = 0;
        for (int tries = 0; tries < 20 && !accepted; ++tries) {
            double a[25], b[5];
            memcpy(a, jt, sizeof a);
            memcpy(b, g, sizeof b);
            for (int k = 0; k < 5; ++k)
                a[6 * k] += lambda * (jt[6 * k] > 0 ? jt[6 * k] : 1);
            if (!cm_shape_solve_small(5, a, b)) {
                lambda *= 10;
                continue;
            }
            double nw[3], np[3], nr = *r + b[4];
            for (int k = 0; k < 3; ++k)
                nw[k] = w[k] + b[0] * u[k] + b[1] * v[k], np[k] = pt[k] + b[2] * u[k] + b[3] * v[k];
            double l = sqrt(dot3(nw, nw));
            for (int k = 0; k < 3; ++k)
                nw[k] /= l;
            /* keep the axis point the one nearest the centroid: conditioning */
            double off[3] = {mean[0] - np[0], mean[1] - np[1], mean[2] - np[2]};
            double hh = dot3(off, nw);
            for (int k = 0; k < 3; ++k)
                np[k] += hh * nw[k];
            double nc = cylinder_cost(n, x, np, nw, nr);
            double step = fabs(b[0]) + fabs(b[1]) + (fabs(b[2]) + fabs(b[3]) + fabs(b[4])) / *r;
            /* near the minimum the cost resolves parameters only to sqrt(eps): steps below
             * 1e-9 are taken on the gradient's word, not the cost's */
            if (nc <= cost || step < 1e-9) {
                int done = step <= 1e-14;
                memcpy(w, nw, sizeof nw);
                memcpy(pt, np, sizeof np);
                *r = nr;
                cost = nc;
                lambda /= 3;
                accepted = 1;
                if (done) return;
            } else {
                lambda *= 4;
            }
        }
        if (!accepted) return;
    }
}

cm_status cm_shape_project_cylinder(cm_context *ctx, size_t n, const double *x,
                                    const double *guess, double *p, double fit[7])
{
    const char *who = "cm_shape_project_cylinder";
    cm_status st = check_points(ctx, who, n, 5, x, p);
    if (st < 0) return st;
    double mean[3], pt[3], w[3], r = 0;
    centroid(n, x, mean);
    if (guess && finite_n(7, guess) && guess[6] > 0 && dot3(guess + 3, guess + 3) > 0) {
        double l = sqrt(dot3(guess + 3, guess + 3));
        for (int k = 0; k < 3; ++k)
            pt[k] = guess[k], w[k] = guess[3 + k] / l;
        r = guess[6];
    } else {
        double *s = calloc(2 * n, sizeof *s);
        if (!s) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
        double best = INFINITY;
        /* Fibonacci directions over the hemisphere, then a shrinking pattern search */
        const int nd = 600;
        for (int i = 0; i < nd; ++i) {
            double z = 1 - (i + 0.5) / nd, rho = sqrt(1 - z * z), phi = i * 2.399963229728653;
            double d[3] = {rho * cos(phi), rho * sin(phi), z}, ap[3], rr;
            double e = cylinder_direction_error(n, x, mean, d, s, s + n, ap, &rr);
            if (e < best) best = e, memcpy(w, d, sizeof d), memcpy(pt, ap, sizeof ap), r = rr;
        }
        for (double step = 0.1; step > 1e-7 && isfinite(best);) {
            double u[3], v[3];
            plane_basis(w, u, v);
            int improved = 0;
            for (int k = 0; k < 8; ++k) {
                double ang = k * 0.7853981633974483, d[3], ap[3], rr;
                for (int a = 0; a < 3; ++a)
                    d[a] = w[a] + step * (cos(ang) * u[a] + sin(ang) * v[a]);
                double l = sqrt(dot3(d, d));
                for (int a = 0; a < 3; ++a)
                    d[a] /= l;
                double e = cylinder_direction_error(n, x, mean, d, s, s + n, ap, &rr);
                if (e < best) {
                    best = e, memcpy(w, d, sizeof d), memcpy(pt, ap, sizeof ap), r = rr;
                    improved = 1;
                    break;
                }
            }
            if (!improved) step /= 2;
        }
        free(s);
        if (!isfinite(best))
            return cm_error(ctx, CM_ERR_NUMERIC, "%s: %zu points fit no cylinder", who, n);
    }
    cylinder_refine(n, x, mean, pt, w, &r);
    if (!(r > 0) || !isfinite(r))
        return cm_error(ctx, CM_ERR_NUMERIC, "%s: the cylinder fit failed (radius %g)", who, r);
    double u[3], v[3];
    plane_basis(w, u, v);
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - pt[0], x[3 * i + 1] - pt[1], x[3 * i + 2] - pt[2]};
        double h = dot3(y, w), q[3] = {y[0] - h * w[0], y[1] - h * w[1], y[2] - h * w[2]};
        double d = sqrt(dot3(q, q));
        if (!(d > 0)) memcpy(q, u, sizeof q), d = 1;
        for (int k = 0; k < 3; ++k)
            p[3 * i + k] = pt[k] + h * w[k] + r * q[k] / d;
    }
    if (fit) memcpy(fit, pt, sizeof pt), memcpy(fit + 3, w, sizeof w), fit[6] = r;
    return CM_OK;
}

/* ---- cone ---- */

/* For a direction w, the points' coordinates (s, t) in the plane normal to w and their
 * height h along it: the circles' common centre (a, b) from the linear least squares of
 * s^2 + t^2 = 2 a s + 2 b t + k0 + k1 h + k2 h^2 (radius^2 any quadratic in h), then the
 * radii r_i = |(s, t) - (a, b)| fitted by a line c + d h. Returns the geometric error of that
 * line, sum (r_i - c - d h_i)^2 (a quadric of revolution that is no cone scores badly, unlike
 * in the algebraic error), and the apex (c + d h = 0), the axis into the nappe (sign d w) and
 * the half-angle atan |d|. */
static double cone_direction_error(size_t n, const double *x, const double *mean,
                                   const double w[3], double apex[3], double axis[3],
                                   double *angle)
{
    double u[3], v[3], a[25] = {0}, b[5] = {0};
    plane_basis(w, u, v);
    double h2 = 0;
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - mean[0], x[3 * i + 1] - mean[1], x[3 * i + 2] - mean[2]};
        double h = dot3(y, w);
        h2 += h * h;
    }
    /* h scaled by its spread: the 5 x 5 normal equations stay balanced */
    double hs = sqrt(h2 / (double)n);
    if (!(hs > 0)) return INFINITY;
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - mean[0], x[3 * i + 1] - mean[1], x[3 * i + 2] - mean[2]};
        double s = dot3(y, u), t = dot3(y, v), h = dot3(y, w) / hs;
        double row[5] = {2 * s, 2 * t, 1, h, h * h}, rhs = s * s + t * t;
        for (int p = 0; p < 5; ++p) {
            b[p] += row[p] * rhs;
            for (int q = 0; q < 5; ++q)
                a[5 * p + q] += row[p] * row[q];
        }
    }
    if (!cm_shape_solve_small(5, a, b)) return INFINITY;
    /* the radius line r = c + d h by least squares */
    double sh = 0, sr = 0, shh = 0, shr = 0;
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - mean[0], x[3 * i + 1] - mean[1], x[3 * i + 2] - mean[2]};
        double s = dot3(y, u) - b[0], t = dot3(y, v) - b[1], h = dot3(y, w);
        double r = sqrt(s * s + t * t);
        sh += h, sr += r, shh += h * h, shr += h * r;
    }
    double det = (double)n * shh - sh * sh;
    if (!(det > 0)) return INFINITY;
    double d = ((double)n * shr - sh * sr) / det, c = (sr - d * sh) / (double)n;
    if (!(fabs(d) > 0)) return INFINITY; /* a cylinder */
    double err = 0;
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - mean[0], x[3 * i + 1] - mean[1], x[3 * i + 2] - mean[2]};
        double s = dot3(y, u) - b[0], t = dot3(y, v) - b[1], h = dot3(y, w);
        double e = sqrt(s * s + t * t) - c - d * h;
        err += e * e;
    }
    double h0 = -c / d;
    for (int k = 0; k < 3; ++k) {
        apex[k] = mean[k] + b[0] * u[k] + b[1] * v[k] + h0 * w[k];
        axis[k] = d > 0 ? w[k] : -w[k];
    }
    *angle = atan(fabs(d));
    return err;
}

/* Signed distances to the nappe (apex p[0..2], unit axis p[3..5], half-angle p[6]):
 * r cos(angle) - h sin(angle) in the half-plane of the axis; the cost, res (may be NULL). */
static double cone_cost(size_t n, const double *x, const double *p, double *res)
{
    double cost = 0, ca = cos(p[6]), sa = sin(p[6]);
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - p[0], x[3 * i + 1] - p[1], x[3 * i + 2] - p[2]};
        double h = dot3(y, p + 3), r2 = dot3(y, y) - h * h;
        double r = sqrt(r2 > 0 ? r2 : 0), e = r * ca - h * sa;
        /* a point behind the apex (foot beyond it): its distance to the apex */
        if (h * ca + r * sa < 0) e = sqrt(dot3(y, y));
        if (res) res[i] = e;
        cost += e * e;
    }
    return cost;
}

/* p moved by t: apex + t0..2, axis tilted by t3, t4 in its normal plane, angle + t5. */
static void cone_moved(const double *p, const double *t, double *q)
{
    double u[3], v[3];
    plane_basis(p + 3, u, v);
    for (int k = 0; k < 3; ++k)
        q[k] = p[k] + t[k], q[3 + k] = p[3 + k] + t[3] * u[k] + t[4] * v[k];
    double l = sqrt(dot3(q + 3, q + 3));
    for (int k = 0; k < 3; ++k)
        q[3 + k] /= l;
    q[6] = p[6] + t[5];
}

/* The Jacobian of the signed distances with respect to the moves of cone_moved: apex
 * shift, axis tilt along u and v (plane_basis of the axis), angle. jac: n x 6. */
static void cone_jacobian(size_t n, const double *x, const double *p, double *jac)
{
    double ca = cos(p[6]), sa = sin(p[6]), u[3], v[3];
    plane_basis(p + 3, u, v);
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - p[0], x[3 * i + 1] - p[1], x[3 * i + 2] - p[2]};
        double h = dot3(y, p + 3), q[3] = {y[0] - h * p[3], y[1] - h * p[4], y[2] - h * p[5]};
        double r = sqrt(dot3(q, q)), *j = jac + 6 * i;
        if (h * ca + r * sa < 0) { /* behind the apex: e = |y| */
            double l = sqrt(dot3(y, y));
            for (int k = 0; k < 3; ++k)
                j[k] = l > 0 ? -y[k] / l : 0;
            j[3] = j[4] = j[5] = 0;
            continue;
        }
        if (r > 0)
            for (int k = 0; k < 3; ++k)
                q[k] /= r;
        /* e = r cos - h sin: d e / d apex = -cos q^ + sin w; a tilt t along u changes h by
         * t (y.u) and r by -h (q^.u) t; d e / d angle = -(r sin + h cos) */
        for (int k = 0; k < 3; ++k)
            j[k] = -ca * q[k] + sa * p[3 + k];
        double g = h * ca + r * sa;
        j[3] = -dot3(q, u) * g, j[4] = -dot3(q, v) * g, j[5] = -g;
    }
}

/* Levenberg-Marquardt on the 6 parameters (scale: the points' spread, for the step size
 * test). jac: n x 6, res, res2: n. */
static void cone_refine(size_t n, const double *x, double *p, double scale, double *jac,
                        double *res, double *res2)
{
    double cost = cone_cost(n, x, p, res), lambda = -1;
    for (int it = 0; it < 200; ++it) {
        cone_jacobian(n, x, p, jac);
        double a[36] = {0}, g[6] = {0};
        for (size_t i = 0; i < n; ++i)
            for (int j = 0; j < 6; ++j) {
                g[j] -= jac[6 * i + j] * res[i];
                for (int l = 0; l < 6; ++l)
                    a[6 * j + l] += jac[6 * i + j] * jac[6 * i + l];
            }
        if (lambda < 0) lambda = 1e-6 * (a[0] + a[7] + a[14] + a[21] + a[28] + a[35]) / 6;
        int accepted = 0;
        for (int tries = 0; tries < 20 && !accepted; ++tries) {
            double aa[36], b[6], q[7];
            memcpy(aa, a, sizeof aa);
            memcpy(b, g, sizeof b);
            for (int j = 0; j < 6; ++j)
                aa[7 * j] += lambda * (a[7 * j] > 0 ? a[7 * j] : 1);
            if (!cm_shape_solve_small(6, aa, b)) {
                lambda *= 10;
                continue;
            }
            cone_moved(p, b, q);
            double step = (fabs(b[0]) + fabs(b[1]) + fabs(b[2])) / scale + fabs(b[3]) +
                          fabs(b[4]) + fabs(b[5]);
            if (!(q[6] > 0 && q[6] < 1.5707963267948966)) {
                lambda *= 4;
                continue;
            }
            double nc = cone_cost(n, x, q, res2);
            /* steps below 1e-9 are taken on the gradient's word: the cost resolves the
             * parameters only to sqrt(eps) near the minimum */
            if (nc <= cost || step < 1e-9) {
                memcpy(p, q, 7 * sizeof *p);
                cost = nc;
                memcpy(res, res2, n * sizeof *res);
                lambda /= 3;
                accepted = 1;
                if (step <= 1e-14) return;
            } else {
                lambda *= 4;
            }
        }
        if (!accepted) return;
    }
}

cm_status cm_shape_project_cone(cm_context *ctx, size_t n, const double *x, const double *guess,
                                double *p, double fit[7])
{
    const char *who = "cm_shape_project_cone";
    cm_status st = check_points(ctx, who, n, 6, x, p);
    if (st < 0) return st;
    double mean[3], c[7], scale = 0;
    centroid(n, x, mean);
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - mean[0], x[3 * i + 1] - mean[1], x[3 * i + 2] - mean[2]};
        scale = fmax(scale, sqrt(dot3(y, y)));
    }
    if (!(scale > 0)) return cm_error(ctx, CM_ERR_NUMERIC, "%s: %zu coincident points", who, n);
    if (guess && finite_n(7, guess) && guess[6] > 0 && guess[6] < 1.5707963267948966 &&
        dot3(guess + 3, guess + 3) > 0) {
        memcpy(c, guess, sizeof c);
        double l = sqrt(dot3(c + 3, c + 3));
        for (int k = 3; k < 6; ++k)
            c[k] /= l;
    } else {
        /* the direction search of the cylinder, on the cone's algebraic error */
        double best = INFINITY, w[3] = {0, 0, 1};
        const int nd = 600;
        for (int i = 0; i < nd; ++i) {
            double z = 1 - (i + 0.5) / nd, rho = sqrt(1 - z * z), phi = i * 2.399963229728653;
            double d[3] = {rho * cos(phi), rho * sin(phi), z}, ap[3], ax[3], an;
            double e = cone_direction_error(n, x, mean, d, ap, ax, &an);
            if (e < best) best = e, memcpy(w, d, sizeof d), memcpy(c, ap, sizeof ap),
                          memcpy(c + 3, ax, sizeof ax), c[6] = an;
        }
        for (double step = 0.1; step > 1e-7 && isfinite(best);) {
            double u[3], v[3];
            plane_basis(w, u, v);
            int improved = 0;
            for (int k = 0; k < 8; ++k) {
                double ang = k * 0.7853981633974483, d[3], ap[3], ax[3], an;
                for (int a = 0; a < 3; ++a)
                    d[a] = w[a] + step * (cos(ang) * u[a] + sin(ang) * v[a]);
                double l = sqrt(dot3(d, d));
                for (int a = 0; a < 3; ++a)
                    d[a] /= l;
                double e = cone_direction_error(n, x, mean, d, ap, ax, &an);
                if (e < best) {
                    best = e, memcpy(w, d, sizeof d), memcpy(c, ap, sizeof ap);
                    memcpy(c + 3, ax, sizeof ax), c[6] = an;
                    improved = 1;
                    break;
                }
            }
            if (!improved) step /= 2;
        }
        if (!isfinite(best))
            return cm_error(ctx, CM_ERR_NUMERIC, "%s: %zu points fit no cone", who, n);
    }
    double *buf = malloc(8 * n * sizeof *buf);
    if (!buf) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
    cone_refine(n, x, c, scale, buf, buf + 6 * n, buf + 7 * n);
    free(buf);
    if (!finite_n(7, c) || !(c[6] > 0 && c[6] < 1.5707963267948966))
        return cm_error(ctx, CM_ERR_NUMERIC, "%s: the cone fit failed (half-angle %g)", who, c[6]);
    /* the foot on the generator in the axis half-plane; behind the apex: the apex */
    double ca = cos(c[6]), sa = sin(c[6]), u[3], v[3];
    plane_basis(c + 3, u, v);
    for (size_t i = 0; i < n; ++i) {
        double y[3] = {x[3 * i] - c[0], x[3 * i + 1] - c[1], x[3 * i + 2] - c[2]};
        double h = dot3(y, c + 3), q[3] = {y[0] - h * c[3], y[1] - h * c[4], y[2] - h * c[5]};
        double r = sqrt(dot3(q, q));
        if (!(r > 0)) memcpy(q, u, sizeof q), r = 0;
        else
            for (int k = 0; k < 3; ++k)
                q[k] /= r;
        double t = h * ca + r * sa; /* distance from the apex along the generator */
        if (t < 0) t = 0;
        for (int k = 0; k < 3; ++k)
            p[3 * i + k] = c[k] + t * (ca * c[3 + k] + sa * q[k]);
    }
    if (fit) memcpy(fit, c, sizeof c);
    return CM_OK;
}

/* ---- similarity / rigid match ---- */

cm_status cm_shape_project_similar(cm_context *ctx, size_t n, const double *ref, const double *x,
                                   int scale, double *p)
{
    const char *who = "cm_shape_project_similar";
    cm_status st = check_points(ctx, who, n, 1, x, p);
    if (st < 0) return st;
    if (!ref) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL reference", who);
    double mr[3], mx[3], h[9] = {0}, var = 0;
    centroid(n, ref, mr);
    centroid(n, x, mx);
    for (size_t i = 0; i < n; ++i) {
        double a[3] = {ref[3 * i] - mr[0], ref[3 * i + 1] - mr[1], ref[3 * i + 2] - mr[2]};
        double b[3] = {x[3 * i] - mx[0], x[3 * i + 1] - mx[1], x[3 * i + 2] - mx[2]};
        var += dot3(a, a);
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k)
                h[3 * j + k] += a[j] * b[k];
    }
    /* H = U S V^T; the rotation taking ref to x is R = V D U^T with D = diag(1, 1, det(V U^T)) */
    double sv[3], u[9], vt[9], sup[2], rot[9];
    if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'A', 'A', 3, 3, h, 3, sv, u, 3, vt, 3, sup) != 0)
        return cm_error(ctx, CM_ERR_NUMERIC, "%s: SVD of the cross-covariance failed", who);
    double det_u = u[0] * (u[4] * u[8] - u[5] * u[7]) - u[1] * (u[3] * u[8] - u[5] * u[6]) +
                   u[2] * (u[3] * u[7] - u[4] * u[6]);
    double det_v = vt[0] * (vt[4] * vt[8] - vt[5] * vt[7]) - vt[1] * (vt[3] * vt[8] - vt[5] * vt[6]) +
                   vt[2] * (vt[3] * vt[7] - vt[4] * vt[6]);
    double dd[3] = {1, 1, det_u * det_v < 0 ? -1 : 1};
    for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) {
            double s = 0;
            for (int l = 0; l < 3; ++l)
                s += vt[3 * l + j] * dd[l] * u[3 * k + l];
            rot[3 * j + k] = s;
        }
    double sc = 1;
    if (scale && var > 0) sc = (sv[0] * dd[0] + sv[1] * dd[1] + sv[2] * dd[2]) / var;
    for (size_t i = 0; i < n; ++i) {
        double a[3] = {ref[3 * i] - mr[0], ref[3 * i + 1] - mr[1], ref[3 * i + 2] - mr[2]};
        for (int j = 0; j < 3; ++j)
            p[3 * i + j] = mx[j] + sc * (rot[3 * j] * a[0] + rot[3 * j + 1] * a[1] + rot[3 * j + 2] * a[2]);
    }
    return CM_OK;
}
