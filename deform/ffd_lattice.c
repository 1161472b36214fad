/* The FFD lattice [SMB14 §2.1] (design notes: docs/ffd.md, sections 1-2):
 * knots, cubic B-spline and Bernstein bases per axis, Greville placement of the control
 * points (so the reference map is exactly affine), and local coordinates - the affine inverse
 * for the reference lattice, damped Newton for a moved one. */
#include "ffd_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cm_ffd_desc_init(cm_ffd_desc *desc)
{
    if (!desc) return;
    memset(desc, 0, sizeof *desc);
    desc->n[0] = desc->n[1] = desc->n[2] = 4;
    desc->basis = CM_FFD_BSPLINE;
    desc->knots = CM_FFD_KNOTS_UNIFORM;
    desc->axes[0] = desc->axes[4] = desc->axes[8] = 1;
}

void cm_ffd_box_axes(const double length[3], const double angle_deg[3], double axes[9])
{
    const double deg = 3.14159265358979323846 / 180;
    double cx = cos(angle_deg[0] * deg), sx = sin(angle_deg[0] * deg);
    double cy = cos(angle_deg[1] * deg), sy = sin(angle_deg[1] * deg);
    double cz = cos(angle_deg[2] * deg), sz = sin(angle_deg[2] * deg);
    double rx[9] = {1, 0, 0, 0, cx, -sx, 0, sx, cx};
    double ry[9] = {cy, 0, sy, 0, 1, 0, -sy, 0, cy};
    double rz[9] = {cz, -sz, 0, sz, cz, 0, 0, 0, 1};
    double t[9], r[9];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            t[3 * i + j] = 0;
            for (int k = 0; k < 3; ++k)
                t[3 * i + j] += rx[3 * i + k] * ry[3 * k + j];
        }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            r[3 * i + j] = 0;
            for (int k = 0; k < 3; ++k)
                r[3 * i + j] += t[3 * i + k] * rz[3 * k + j];
        }
    /* PyGeM skips a zero angle's factor; cos 0 = 1 and sin 0 = 0 exactly, so the product is
     * the same bit for bit */
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            axes[3 * i + j] = r[3 * i + j] * length[j];
}

void cm_ffd_desc_enclosing(cm_ffd_desc *desc, const double bb[6], double margin, int n)
{
    cm_ffd_desc_init(desc);
    double g = margin * cm_bbox_diagonal(bb);
    for (int a = 0; a < 3; ++a) {
        desc->n[a] = n;
        desc->origin[a] = bb[a] - g;
        double len = bb[a + 3] - bb[a] + 2 * g;
        /* a flat box (a planar point set) still needs an invertible lattice */
        if (!(len > 0)) len = g > 0 ? 2 * g : 1;
        desc->axes[4 * a] = len;
    }
}

static double det3(const double m[9])
{
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
}

/* Inverse of a 3x3 row-major matrix; 0 if it is singular relative to its size. */
static int inv3(const double m[9], double out[9])
{
    double d = det3(m), s = 0;
    for (int i = 0; i < 9; ++i)
        s = fmax(s, fabs(m[i]));
    if (!(fabs(d) > 1e-14 * s * s * s) || !isfinite(d)) return 0;
    out[0] = (m[4] * m[8] - m[5] * m[7]) / d;
    out[1] = (m[2] * m[7] - m[1] * m[8]) / d;
    out[2] = (m[1] * m[5] - m[2] * m[4]) / d;
    out[3] = (m[5] * m[6] - m[3] * m[8]) / d;
    out[4] = (m[0] * m[8] - m[2] * m[6]) / d;
    out[5] = (m[2] * m[3] - m[0] * m[5]) / d;
    out[6] = (m[3] * m[7] - m[4] * m[6]) / d;
    out[7] = (m[1] * m[6] - m[0] * m[7]) / d;
    out[8] = (m[0] * m[4] - m[1] * m[3]) / d;
    return 1;
}

void cm_ffd_destroy(cm_ffd **ffd)
{
    if (!ffd || !*ffd) return;
    for (int a = 0; a < 3; ++a) {
        free((*ffd)->knot[a]);
        free((*ffd)->xi[a]);
    }
    free((*ffd)->ctrl);
    free(*ffd);
    *ffd = NULL;
}

static void reference_points(const cm_ffd *f, double *xyz)
{
    for (int i = 0; i < f->n[0]; ++i)
        for (int j = 0; j < f->n[1]; ++j)
            for (int k = 0; k < f->n[2]; ++k) {
                double *p = xyz + 3 * (((size_t)i * f->n[1] + j) * f->n[2] + k);
                double s[3] = {f->xi[0][i], f->xi[1][j], f->xi[2][k]};
                for (int r = 0; r < 3; ++r)
                    p[r] = f->origin[r] + f->a[3 * r] * s[0] + f->a[3 * r + 1] * s[1] +
                           f->a[3 * r + 2] * s[2];
            }
}

cm_status cm_ffd_create(cm_context *ctx, const cm_ffd_desc *desc, cm_ffd **ffd)
{
    if (!ffd) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_create: ffd is NULL");
    *ffd = NULL;
    if (!desc) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_create: desc is NULL");
    if (desc->knots != CM_FFD_KNOTS_UNIFORM && desc->knots != CM_FFD_KNOTS_CLAMPED &&
        desc->knots != CM_FFD_KNOTS_CUSTOM)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_create: unknown knot kind %d",
                        (int)desc->knots);
    if (desc->basis != CM_FFD_BSPLINE && desc->basis != CM_FFD_BERNSTEIN)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_create: unknown basis %d",
                        (int)desc->basis);
    int nmin = desc->basis == CM_FFD_BSPLINE ? 4 : 2;
    double count = 1;
    for (int a = 0; a < 3; ++a) {
        if (desc->n[a] < nmin)
            return cm_error(ctx, CM_ERR_ARGUMENT,
                            "cm_ffd_create: %d control points along axis %d; %s needs at least %d",
                            desc->n[a], a,
                            desc->basis == CM_FFD_BSPLINE ? "a cubic B-spline" : "Bernstein",
                            nmin);
        if (desc->basis == CM_FFD_BERNSTEIN && desc->n[a] > CM_FFD_MAX_AXIS)
            return cm_error(ctx, CM_ERR_ARGUMENT,
                            "cm_ffd_create: %d control points along axis %d; Bernstein bases "
                            "are limited to degree %d",
                            desc->n[a], a, CM_FFD_MAX_AXIS - 1);
        count *= desc->n[a];
    }
    if (count > 2147483647.0)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_create: %.0f control points (limit 2^31)",
                        count);
    for (int i = 0; i < 3; ++i)
        if (!isfinite(desc->origin[i]))
            return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_create: non-finite origin");
    cm_ffd *f = calloc(1, sizeof *f);
    if (!f) return cm_error(ctx, CM_ERR_NOMEM, "cm_ffd_create: out of memory");
    memcpy(f->n, desc->n, sizeof f->n);
    f->basis = desc->basis;
    f->knots = desc->knots;
    f->local = CM_FFD_LOCAL_AUTO;
    memcpy(f->origin, desc->origin, sizeof f->origin);
    memcpy(f->a, desc->axes, sizeof f->a);
    if (!inv3(f->a, f->ainv)) {
        cm_ffd_destroy(&f);
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_ffd_create: the lattice axes are linearly dependent (det %g)",
                        det3(desc->axes));
    }
    for (int r = 0; r < 3; ++r) {
        double s = f->a[3 * r] + f->a[3 * r + 1] + f->a[3 * r + 2];
        f->diag += s * s;
    }
    f->diag = sqrt(f->diag);
    f->n_ctrl = (size_t)count;
    for (int a = 0; a < 3; ++a) {
        int n = f->n[a];
        f->xi[a] = malloc((size_t)n * sizeof(double));
        if (f->basis == CM_FFD_BSPLINE) f->knot[a] = malloc((size_t)(n + 4) * sizeof(double));
        if (!f->xi[a] || (f->basis == CM_FFD_BSPLINE && !f->knot[a])) {
            cm_ffd_destroy(&f);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_ffd_create: out of memory");
        }
        if (f->basis == CM_FFD_BERNSTEIN) {
            for (int i = 0; i < n; ++i)
                f->xi[a][i] = (double)i / (n - 1);
            continue;
        }
        double *t = f->knot[a];
        if (f->knots == CM_FFD_KNOTS_CUSTOM) {
            const double *g = desc->knot[a];
            int ok = g != NULL;
            for (int j = 0; ok && j < n + 4; ++j)
                ok = isfinite(g[j]) && (j == 0 || g[j] >= g[j - 1]) &&
                     (j <= 3 || j > n || g[j] > g[j - 1]);
            if (!ok || g[3] != 0 || g[n] != 1) {
                cm_ffd_destroy(&f);
                return cm_error(ctx, CM_ERR_ARGUMENT,
                                "cm_ffd_create: axis %d: custom knots must be %d non-decreasing "
                                "values with t_3 = 0, t_%d = 1 and no repeated knot inside",
                                a, n + 4, n);
            }
            memcpy(t, g, (size_t)(n + 4) * sizeof *t);
            for (int i = 0; i < n; ++i)
                f->xi[a][i] = (t[i + 1] + t[i + 2] + t[i + 3]) / 3;
            continue;
        }
        for (int j = 0; j < n + 4; ++j) {
            double v = (double)(j - 3) / (n - 3);
            if (f->knots == CM_FFD_KNOTS_CLAMPED) v = j < 3 ? 0 : j > n ? 1 : v;
            t[j] = v;
        }
        /* the interior knots exactly on the grid, and the domain ends exactly 0 and 1 */
        t[3] = 0;
        t[n] = 1;
        for (int i = 0; i < n; ++i)
            f->xi[a][i] = (t[i + 1] + t[i + 2] + t[i + 3]) / 3;
    }
    f->ctrl = malloc(f->n_ctrl * 3 * sizeof(double));
    if (!f->ctrl) {
        cm_ffd_destroy(&f);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_ffd_create: out of memory");
    }
    reference_points(f, f->ctrl);
    *ffd = f;
    return CM_OK;
}

size_t cm_ffd_control_count(const cm_ffd *ffd) { return ffd ? ffd->n_ctrl : 0; }

void cm_ffd_control_points(const cm_ffd *ffd, double *xyz)
{
    memcpy(xyz, ffd->ctrl, ffd->n_ctrl * 3 * sizeof(double));
}

cm_status cm_ffd_set_control_points(cm_context *ctx, cm_ffd *ffd, const double *xyz)
{
    if (!ffd) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_set_control_points: ffd is NULL");
    if (!xyz) {
        reference_points(ffd, ffd->ctrl);
        ffd->moved = 0;
        return CM_OK;
    }
    for (size_t i = 0; i < 3 * ffd->n_ctrl; ++i)
        if (!isfinite(xyz[i]))
            return cm_error(ctx, CM_ERR_ARGUMENT,
                            "cm_ffd_set_control_points: control point %zu is not finite", i / 3);
    memcpy(ffd->ctrl, xyz, ffd->n_ctrl * 3 * sizeof(double));
    ffd->moved = 1;
    for (int a = 0; a < 3; ++a) {
        ffd->cbox[a] = INFINITY;
        ffd->cbox[a + 3] = -INFINITY;
    }
    for (size_t p = 0; p < ffd->n_ctrl; ++p)
        for (int a = 0; a < 3; ++a) {
            ffd->cbox[a] = fmin(ffd->cbox[a], xyz[3 * p + a]);
            ffd->cbox[a + 3] = fmax(ffd->cbox[a + 3], xyz[3 * p + a]);
        }
    return CM_OK;
}

void cm_ffd_set_local(cm_ffd *ffd, cm_ffd_local mode)
{
    if (ffd) ffd->local = mode;
}

size_t cm_ffd_support_size(const cm_ffd *ffd)
{
    if (ffd->basis == CM_FFD_BSPLINE) return 64;
    return ffd->n_ctrl;
}

/* NURBS Book A2.2 (Cox-de Boor, triangular scheme) up to degree p at span s. */
static void bspline_funs(const double *t, int s, double u, int p, double *nv)
{
    double left[4], right[4];
    nv[0] = 1;
    for (int j = 1; j <= p; ++j) {
        left[j] = u - t[s + 1 - j];
        right[j] = t[s + j] - u;
        double saved = 0;
        for (int r = 0; r < j; ++r) {
            double tmp = nv[r] / (right[r + 1] + left[j - r]);
            nv[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        nv[j] = saved;
    }
}

/* NURBS Book A1.3: all Bernstein polynomials of degree p at u. */
static void bernstein_funs(int p, double u, double *nv)
{
    double v = 1 - u;
    nv[0] = 1;
    for (int j = 1; j <= p; ++j) {
        double saved = 0;
        for (int k = 0; k < j; ++k) {
            double tmp = nv[k];
            nv[k] = saved + v * tmp;
            saved = u * tmp;
        }
        nv[j] = saved;
    }
}

int cm_ffd_axis_basis(const cm_ffd *f, int a, double t, double *nv, double *dn, int *count)
{
    int n = f->n[a];
    if (f->basis == CM_FFD_BERNSTEIN) {
        int p = n - 1;
        *count = n;
        if (dn) {
            /* B'_{i,p} = p (B_{i-1,p-1} - B_{i,p-1}) */
            double low[CM_FFD_MAX_AXIS];
            bernstein_funs(p - 1, t, low);
            for (int i = 0; i < n; ++i)
                dn[i] = p * ((i > 0 ? low[i - 1] : 0) - (i < p ? low[i] : 0));
        }
        bernstein_funs(p, t, nv);
        return 0;
    }
    const double *kn = f->knot[a];
    /* span s with t_s <= t < t_{s+1}; t = 1 closes the last span (and only it) */
    double ts = floor(t * (n - 3));
    int s = ts < 0 ? 3 : ts >= n - 3 ? n - 1 : 3 + (int)ts;
    if (f->knots == CM_FFD_KNOTS_CUSTOM) {
        /* binary search for t_s <= t < t_{s+1} in [3, n-1]; t >= 1 closes the last span */
        int lo = 3, hi = n - 1;
        if (!(t < 1)) lo = n - 1;
        while (lo < hi) {
            int mid = (lo + hi + 1) / 2;
            if (kn[mid] <= t)
                lo = mid;
            else
                hi = mid - 1;
        }
        s = lo;
    }
    *count = 4;
    if (f->knots == CM_FFD_KNOTS_UNIFORM) {
        /* the closed form of the uniform cubic (fewer roundings than Cox-de Boor) */
        double h = 1.0 / (n - 3), l = t * (n - 3) - (s - 3), m = 1 - l;
        nv[0] = m * m * m / 6;
        nv[1] = ((3 * l - 6) * l * l + 4) / 6;
        nv[2] = (((-3 * l + 3) * l + 3) * l + 1) / 6;
        nv[3] = l * l * l / 6;
        if (dn) {
            dn[0] = -m * m / 2 / h;
            dn[1] = (3 * l - 4) * l / 2 / h;
            dn[2] = ((-3 * l + 2) * l + 1) / 2 / h;
            dn[3] = l * l / 2 / h;
        }
        return s - 3;
    }
    if (dn) {
        double n2[3];
        bspline_funs(kn, s, t, 2, n2);
        for (int r = 0; r < 4; ++r) {
            int i = s - 3 + r;
            double a1 = 0, a2 = 0, d1 = kn[i + 3] - kn[i], d2 = kn[i + 4] - kn[i + 1];
            if (r >= 1 && d1 > 0) a1 = n2[r - 1] / d1;
            if (r <= 2 && d2 > 0) a2 = n2[r] / d2;
            dn[r] = 3 * (a1 - a2);
        }
    }
    bspline_funs(kn, s, t, 3, nv);
    return s - 3;
}

size_t cm_ffd_basis_eval(const cm_ffd *f, const double u[3], int64_t *idx, double *w)
{
    double nv[3][CM_FFD_MAX_AXIS];
    int first[3], cnt[3];
    for (int a = 0; a < 3; ++a)
        first[a] = cm_ffd_axis_basis(f, a, u[a], nv[a], NULL, &cnt[a]);
    size_t q = 0;
    for (int i = 0; i < cnt[0]; ++i)
        for (int j = 0; j < cnt[1]; ++j) {
            double wij = nv[0][i] * nv[1][j];
            int64_t base = ((int64_t)(first[0] + i) * f->n[1] + first[1] + j) * f->n[2] + first[2];
            for (int k = 0; k < cnt[2]; ++k) {
                idx[q] = base + k;
                w[q++] = wij * nv[2][k];
            }
        }
    return q;
}

/* x(u) = sum c_p N_p(u) and its Jacobian (row-major, column a = dx/du_a). */
static void lattice_map(const cm_ffd *f, const double u[3], double x[3], double jac[9])
{
    double nv[3][CM_FFD_MAX_AXIS], dn[3][CM_FFD_MAX_AXIS];
    int first[3], cnt[3];
    for (int a = 0; a < 3; ++a)
        first[a] = cm_ffd_axis_basis(f, a, u[a], nv[a], dn[a], &cnt[a]);
    for (int r = 0; r < 3; ++r)
        x[r] = 0;
    for (int r = 0; r < 9; ++r)
        jac[r] = 0;
    for (int i = 0; i < cnt[0]; ++i)
        for (int j = 0; j < cnt[1]; ++j) {
            size_t base = ((size_t)(first[0] + i) * f->n[1] + first[1] + j) * f->n[2] + first[2];
            for (int k = 0; k < cnt[2]; ++k) {
                const double *c = f->ctrl + 3 * (base + k);
                double w = nv[0][i] * nv[1][j] * nv[2][k];
                double w0 = dn[0][i] * nv[1][j] * nv[2][k];
                double w1 = nv[0][i] * dn[1][j] * nv[2][k];
                double w2 = nv[0][i] * nv[1][j] * dn[2][k];
                for (int r = 0; r < 3; ++r) {
                    x[r] += w * c[r];
                    jac[3 * r] += w0 * c[r];
                    jac[3 * r + 1] += w1 * c[r];
                    jac[3 * r + 2] += w2 * c[r];
                }
            }
        }
}

static int inside_clamp(double u[3])
{
    for (int a = 0; a < 3; ++a)
        if (!(u[a] >= -CM_FFD_INSIDE_TOL && u[a] <= 1 + CM_FFD_INSIDE_TOL)) return 0;
    for (int a = 0; a < 3; ++a)
        u[a] = u[a] < 0 ? 0 : u[a] > 1 ? 1 : u[a];
    return 1;
}

/* Newton iterates stay within this band around the domain: far enough to tell "outside"
 * from "inside", close enough that the end spans' polynomials stay tame. */
#define NEWTON_BAND 0.25

static double clampb(double v)
{
    return v < -NEWTON_BAND ? -NEWTON_BAND : v > 1 + NEWTON_BAND ? 1 + NEWTON_BAND : v;
}

int cm_ffd_locate(const cm_ffd *f, const double x[3], double u[3], int *iters)
{
    *iters = 0;
    if (!isfinite(x[0]) || !isfinite(x[1]) || !isfinite(x[2])) {
        u[0] = u[1] = u[2] = 0;
        return 2;
    }
    double r[3] = {x[0] - f->origin[0], x[1] - f->origin[1], x[2] - f->origin[2]};
    for (int a = 0; a < 3; ++a)
        u[a] = f->ainv[3 * a] * r[0] + f->ainv[3 * a + 1] * r[1] + f->ainv[3 * a + 2] * r[2];
    int newton = f->local == CM_FFD_LOCAL_NEWTON || (f->local == CM_FFD_LOCAL_AUTO && f->moved);
    if (!newton) return inside_clamp(u);
    /* the image of [0,1]^3 lies in the convex hull of the control points (the bases are
     * non-negative and sum to 1): outside their box is outside, without Newton */
    if (f->moved)
        for (int a = 0; a < 3; ++a)
            if (x[a] < f->cbox[a] - 1e-12 * f->diag || x[a] > f->cbox[a + 3] + 1e-12 * f->diag)
                return 0;
    for (int a = 0; a < 3; ++a)
        u[a] = clampb(u[a]);
    /* stop at the round-off level (quadratic convergence makes the last step cheap); accept
     * 1e-13 x the lattice size, the documented tolerance */
    const double target = 1e-15 * f->diag, accept = 1e-13 * f->diag;
    double xu[3], jac[9], ji[9];
    lattice_map(f, u, xu, jac);
    double fr[3] = {xu[0] - x[0], xu[1] - x[1], xu[2] - x[2]};
    double nf = sqrt(fr[0] * fr[0] + fr[1] * fr[1] + fr[2] * fr[2]);
    for (int it = 0; it < 30 && nf > target; ++it) {
        if (!inv3(jac, ji)) break; /* singular Jacobian: a folded lattice, reported as failed */
        double du[3];
        for (int a = 0; a < 3; ++a)
            du[a] = -(ji[3 * a] * fr[0] + ji[3 * a + 1] * fr[1] + ji[3 * a + 2] * fr[2]);
        /* damped: halve the step while |F| grows (only the full step once accepted) */
        double step = 1, un[3], xn[3], jn[9], fn[3], nn = INFINITY;
        for (int h = 0; h < (nf <= accept ? 1 : 40); ++h, step *= 0.5) {
            for (int a = 0; a < 3; ++a)
                un[a] = clampb(u[a] + step * du[a]);
            lattice_map(f, un, xn, jn);
            for (int a = 0; a < 3; ++a)
                fn[a] = xn[a] - x[a];
            nn = sqrt(fn[0] * fn[0] + fn[1] * fn[1] + fn[2] * fn[2]);
            if (nn < nf) break;
        }
        if (!(nn < nf)) break; /* no descent: the round-off floor, the band, or a fold */
        ++*iters;
        double change = fabs(un[0] - u[0]) + fabs(un[1] - u[1]) + fabs(un[2] - u[2]);
        memcpy(u, un, sizeof un);
        memcpy(fr, fn, sizeof fn);
        memcpy(jac, jn, sizeof jn);
        nf = nn;
        if (change <= 1e-15) break;
    }
    int converged = nf <= accept;
    if (converged) return inside_clamp(u);
    /* stuck against the band: the point lies outside the moved lattice */
    for (int a = 0; a < 3; ++a)
        if (u[a] <= -NEWTON_BAND + 1e-9 || u[a] >= 1 + NEWTON_BAND - 1e-9) return 0;
    return 2;
}

cm_status cm_ffd_local_coords(cm_context *ctx, const cm_ffd *ffd, size_t n, const double *x,
                              double *u, unsigned char *inside, cm_ffd_stats *stats)
{
    if (!ffd || (n && (!x || !u)))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_local_coords: NULL input");
    size_t nin = 0, nout = 0, nfail = 0;
    int maxit = 0;
    int threads = cm_context_threads_for(ctx, n, 2000);
#pragma omp parallel for schedule(static) num_threads(threads) reduction(+ : nin, nout, nfail) \
    reduction(max : maxit)
    for (size_t i = 0; i < n; ++i) {
        int it;
        int r = cm_ffd_locate(ffd, x + 3 * i, u + 3 * i, &it);
        if (inside) inside[i] = (unsigned char)r;
        nin += r == 1;
        nout += r == 0;
        nfail += r == 2;
        if (it > maxit) maxit = it;
    }
    if (stats) {
        stats->inside = nin;
        stats->outside = nout;
        stats->failed = nfail;
        stats->max_iterations = maxit;
    }
    if (nfail)
        return cm_error(ctx, CM_WARNING,
                        "cm_ffd_local_coords: Newton did not invert %zu of %zu points (folded "
                        "lattice?)",
                        nfail, n);
    return CM_OK;
}
