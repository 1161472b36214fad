/* Affine edits whose vertices cannot determine the map (docs/DESIGN.md, "Affine edits"):
 * fewer than 4 vertices, or all of them in one plane or on one line, as on a revolved part
 * whose seams share a plane. The map is then found from more of the part:
 *  1. a first guess from the solids' volume moments, which transform covariantly under
 *     x -> A x + b (V' = |det A| V, c' = A c + b, S' = A S A^T): with S = L L^T and
 *     S' = L' L'^T, A = L' Q L^-1 for an orthogonal Q, which the vertices and points at equal
 *     arc-length fractions of the edges fix (Procrustes, Q a rotation so that det A > 0: a
 *     map with det A < 0 would turn every cell of a morphed mesh inside out). Without a solid,
 *     a least-squares fit on the same points;
 *  2. Gauss-Newton on points spread over every edge and face of G: each image A x + b is
 *     projected onto the same entity of G' and A, b move to put the images on their
 *     entities (point-to-line for edge points, point-to-plane for face points, point-to-point
 *     for vertices), so no correspondence inside an entity is assumed;
 *  3. the map is accepted only when every vertex, edge point and face point of G lands on its
 *     entity of G' within the tolerance, and V' = |det A| V holds. An edit that is not affine
 *     (a bore widened alone) leaves points off by far more and is refused. */
#include "surface_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { EDGE_SAMPLES = 8, FACE_GRID = 6, MAX_ITER = 40 };

typedef struct samples {
    size_t n;
    double *x;    /* n x 3: points of G */
    double *y;    /* n x 3: the vertex of G', or the edge point of G' at the same arc length */
    double *uv;   /* n x 2: face points, their last parameters on the face of G' */
    int *kind;    /* 0 vertex, 1 edge, 2 face; runs of one entity are contiguous */
    int *ent;
} samples;

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static int inv3(const double c[3][3], double inv[3][3])
{
    double det = c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1]) -
                 c[0][1] * (c[1][0] * c[2][2] - c[1][2] * c[2][0]) +
                 c[0][2] * (c[1][0] * c[2][1] - c[1][1] * c[2][0]);
    if (!(fabs(det) > 0) || !isfinite(det)) return 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
            inv[i][j] = (c[i1][j1] * c[i2][j2] - c[i1][j2] * c[i2][j1]) / det;
        }
    return 1;
}

static double det3(const double a[3][3])
{
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

/* Cholesky factor of a symmetric positive definite 3 x 3 (row-major s); 0 if not. */
static int chol3(const double *s, double l[3][3])
{
    memset(l, 0, 9 * sizeof(double));
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j <= i; ++j) {
            double v = 0.5 * (s[3 * i + j] + s[3 * j + i]);
            for (int k = 0; k < j; ++k)
                v -= l[i][k] * l[j][k];
            if (i == j) {
                if (!(v > 0)) return 0;
                l[i][i] = sqrt(v);
            } else {
                l[i][j] = v / l[j][j];
            }
        }
    return 1;
}

/* Eigenvector of the largest eigenvalue of a symmetric 4 x 4 (cyclic Jacobi). */
static void top_eigenvector4(double a[4][4], double q[4])
{
    double v[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    for (int sweep = 0; sweep < 60; ++sweep) {
        double off = 0, diag = 0;
        for (int i = 0; i < 4; ++i) {
            diag += a[i][i] * a[i][i];
            for (int j = i + 1; j < 4; ++j)
                off += a[i][j] * a[i][j];
        }
        if (!(off > 1e-30 * diag)) break;
        for (int p = 0; p < 4; ++p)
            for (int r = p + 1; r < 4; ++r) {
                if (a[p][r] == 0) continue;
                double th = (a[r][r] - a[p][p]) / (2 * a[p][r]);
                double t = (th >= 0 ? 1 : -1) / (fabs(th) + sqrt(th * th + 1));
                double c = 1 / sqrt(t * t + 1), s = t * c;
                for (int k = 0; k < 4; ++k) { /* columns p, r */
                    double akp = a[k][p], akr = a[k][r];
                    a[k][p] = c * akp - s * akr, a[k][r] = s * akp + c * akr;
                }
                for (int k = 0; k < 4; ++k) { /* rows p, r */
                    double apk = a[p][k], ark = a[r][k];
                    a[p][k] = c * apk - s * ark, a[r][k] = s * apk + c * ark;
                }
                for (int k = 0; k < 4; ++k) {
                    double vkp = v[k][p], vkr = v[k][r];
                    v[k][p] = c * vkp - s * vkr, v[k][r] = s * vkp + c * vkr;
                }
            }
    }
    int best = 0;
    for (int i = 1; i < 4; ++i)
        if (a[i][i] > a[best][best]) best = i;
    for (int i = 0; i < 4; ++i)
        q[i] = v[i][best];
}

/* The rotation R maximising sum w . R u over the pairs (Horn's quaternion method), from
 * h[a][b] = sum u_a w_b. */
static void procrustes_rotation(const double h[3][3], double r[3][3])
{
    double sxx = h[0][0], sxy = h[0][1], sxz = h[0][2], syx = h[1][0], syy = h[1][1],
           syz = h[1][2], szx = h[2][0], szy = h[2][1], szz = h[2][2];
    double n[4][4] = {{sxx + syy + szz, syz - szy, szx - sxz, sxy - syx},
                      {syz - szy, sxx - syy - szz, sxy + syx, szx + sxz},
                      {szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy},
                      {sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz}};
    double q[4];
    top_eigenvector4(n, q);
    double w = q[0], x = q[1], y = q[2], z = q[3];
    r[0][0] = w * w + x * x - y * y - z * z, r[0][1] = 2 * (x * y - w * z),
    r[0][2] = 2 * (x * z + w * y);
    r[1][0] = 2 * (y * x + w * z), r[1][1] = w * w - x * x + y * y - z * z,
    r[1][2] = 2 * (y * z - w * x);
    r[2][0] = 2 * (z * x - w * y), r[2][1] = 2 * (z * y + w * x),
    r[2][2] = w * w - x * x - y * y + z * z;
}

/* Solves the 12 x 12 system n p = b in place (partial pivoting); 0 if singular. */
static int solve12(double n[12][12], double b[12], double p[12])
{
    for (int c = 0; c < 12; ++c) {
        int piv = c;
        for (int r = c + 1; r < 12; ++r)
            if (fabs(n[r][c]) > fabs(n[piv][c])) piv = r;
        if (!(fabs(n[piv][c]) > 0)) return 0;
        if (piv != c) {
            for (int k = 0; k < 12; ++k) {
                double t = n[c][k];
                n[c][k] = n[piv][k], n[piv][k] = t;
            }
            double t = b[c];
            b[c] = b[piv], b[piv] = t;
        }
        for (int r = c + 1; r < 12; ++r) {
            double f = n[r][c] / n[c][c];
            for (int k = c; k < 12; ++k)
                n[r][k] -= f * n[c][k];
            b[r] -= f * b[c];
        }
    }
    for (int c = 11; c >= 0; --c) {
        double v = b[c];
        for (int k = c + 1; k < 12; ++k)
            v -= n[c][k] * p[k];
        p[c] = v / n[c][c];
    }
    for (int c = 0; c < 12; ++c)
        if (!isfinite(p[c])) return 0;
    return 1;
}

static void samples_free(samples *s)
{
    free(s->x);
    free(s->y);
    free(s->uv);
    free(s->kind);
    free(s->ent);
}

/* Vertices (given), EDGE_SAMPLES points per edge at arc-length fractions (i + 1/2) / n with
 * their counterparts at the same fractions of G' (a first guess only: arc length is not
 * affine-invariant), FACE_GRID^2 parameter-grid points per face that lie on the face. */
static cm_status collect(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                         const double *xv, const double *yv, int nv, samples *s)
{
    cm_cad_counts c;
    cm_cad_get_counts(g, &c);
    size_t cap = (size_t)nv + (size_t)c.edges * EDGE_SAMPLES + (size_t)c.faces * FACE_GRID * FACE_GRID;
    memset(s, 0, sizeof *s);
    s->x = malloc(3 * cap * sizeof *s->x);
    s->y = malloc(3 * cap * sizeof *s->y);
    s->uv = malloc(2 * cap * sizeof *s->uv);
    s->kind = malloc(cap * sizeof *s->kind);
    s->ent = malloc(cap * sizeof *s->ent);
    if (!s->x || !s->y || !s->uv || !s->kind || !s->ent)
        return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    for (int v = 0; v < nv; ++v, ++s->n) {
        memcpy(s->x + 3 * s->n, xv + 3 * v, 3 * sizeof(double));
        memcpy(s->y + 3 * s->n, yv + 3 * v, 3 * sizeof(double));
        s->kind[s->n] = 0, s->ent[s->n] = v;
    }
    cm_status r = CM_OK;
    for (int e = 0; e < c.edges && r >= 0; ++e) {
        cm_cad_edge_info ei;
        r = cm_cad_edge_get_info(ctx, g, e, &ei);
        if (r < 0 || ei.degenerate) continue;
        double f[EDGE_SAMPLES], t[EDGE_SAMPLES];
        for (int i = 0; i < EDGE_SAMPLES; ++i)
            f[i] = (i + 0.5) / EDGE_SAMPLES;
        r = cm_cad_edge_s_to_t(ctx, g, e, f, EDGE_SAMPLES, t);
        if (r >= 0) r = cm_cad_edge_eval(ctx, g, e, t, EDGE_SAMPLES, s->x + 3 * s->n);
        if (r >= 0) r = cm_cad_edge_s_to_t(ctx, g2, e, f, EDGE_SAMPLES, t);
        if (r >= 0) r = cm_cad_edge_eval(ctx, g2, e, t, EDGE_SAMPLES, s->y + 3 * s->n);
        for (int i = 0; i < EDGE_SAMPLES && r >= 0; ++i, ++s->n)
            s->kind[s->n] = 1, s->ent[s->n] = e;
    }
    for (int f = 0; f < c.faces && r >= 0; ++f) {
        cm_cad_face_info fi;
        r = cm_cad_face_get_info(ctx, g, f, &fi);
        double uv[2 * FACE_GRID * FACE_GRID];
        int inside[FACE_GRID * FACE_GRID];
        for (int i = 0; i < FACE_GRID; ++i)
            for (int j = 0; j < FACE_GRID; ++j) {
                uv[2 * (FACE_GRID * i + j)] =
                    fi.uv_range[0] + (i + 0.5) / FACE_GRID * (fi.uv_range[1] - fi.uv_range[0]);
                uv[2 * (FACE_GRID * i + j) + 1] =
                    fi.uv_range[2] + (j + 0.5) / FACE_GRID * (fi.uv_range[3] - fi.uv_range[2]);
            }
        if (r >= 0) r = cm_cad_face_inside(ctx, g, f, uv, FACE_GRID * FACE_GRID, inside);
        size_t k = 0;
        for (int i = 0; i < FACE_GRID * FACE_GRID && r >= 0; ++i)
            if (inside[i]) memmove(uv + 2 * k++, uv + 2 * i, 2 * sizeof(double));
        if (r >= 0 && k) r = cm_cad_face_eval(ctx, g, f, uv, k, s->x + 3 * s->n, NULL);
        for (size_t i = 0; i < k && r >= 0; ++i, ++s->n)
            s->kind[s->n] = 2, s->ent[s->n] = f;
    }
    return r < 0 ? r : CM_OK;
}

/* The first guess (m, row-major 3 x 4) from the volume moments and the corresponding points
 * (vertices weigh 10, edge points 1); *ok = 0 when the model has no solid or S is singular. */
static cm_status guess_moments(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                               const samples *s, double m[3][4], double vol[2], int *ok)
{
    *ok = 0;
    cm_cad_counts c, c2;
    cm_cad_get_counts(g, &c);
    cm_cad_get_counts(g2, &c2);
    if (c.solids == 0 || c2.solids == 0) return CM_OK;
    double cen[2][3], sec[2][9], l[2][3][3], li[2][3][3];
    for (int k = 0; k < 2; ++k) {
        cm_status r = cm_cad_volume_moments(ctx, k ? g2 : g, &vol[k], cen[k], sec[k]);
        if (r == CM_ERR_NOMEM) return r;
        if (r < 0) return CM_OK; /* no solid, or OpenCASCADE could not integrate: no guess */
        if (!chol3(sec[k], l[k]) || !inv3(l[k], li[k])) return CM_OK;
    }
    double h[3][3] = {{0}};
    for (size_t i = 0; i < s->n; ++i) {
        if (s->kind[i] == 2) continue;
        double dx[3], dy[3], u[3], w[3], wt = s->kind[i] == 0 ? 10 : 1;
        for (int a = 0; a < 3; ++a)
            dx[a] = s->x[3 * i + a] - cen[0][a], dy[a] = s->y[3 * i + a] - cen[1][a];
        for (int a = 0; a < 3; ++a)
            u[a] = dot3(li[0][a], dx), w[a] = dot3(li[1][a], dy);
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                h[a][b] += wt * u[a] * w[b];
    }
    double q[3][3], ql[3][3];
    procrustes_rotation(h, q);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            ql[i][j] = q[i][0] * li[0][0][j] + q[i][1] * li[0][1][j] + q[i][2] * li[0][2][j];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            m[i][j] = l[1][i][0] * ql[0][j] + l[1][i][1] * ql[1][j] + l[1][i][2] * ql[2][j];
        m[i][3] = cen[1][i] - m[i][0] * cen[0][0] - m[i][1] * cen[0][1] - m[i][2] * cen[0][2];
    }
    *ok = 1;
    return CM_OK;
}

/* The first guess without a solid: least squares on the vertices and edge points. */
static int guess_points(const samples *s, double m[3][4])
{
    double xc[3] = {0, 0, 0}, yc[3] = {0, 0, 0}, cxx[3][3] = {{0}}, cyx[3][3] = {{0}}, inv[3][3];
    size_t k = 0;
    for (size_t i = 0; i < s->n; ++i)
        if (s->kind[i] != 2) {
            for (int a = 0; a < 3; ++a)
                xc[a] += s->x[3 * i + a], yc[a] += s->y[3 * i + a];
            ++k;
        }
    if (k < 4) return 0;
    for (int a = 0; a < 3; ++a)
        xc[a] /= (double)k, yc[a] /= (double)k;
    for (size_t i = 0; i < s->n; ++i)
        if (s->kind[i] != 2)
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) {
                    cxx[a][b] += (s->x[3 * i + a] - xc[a]) * (s->x[3 * i + b] - xc[b]);
                    cyx[a][b] += (s->y[3 * i + a] - yc[a]) * (s->x[3 * i + b] - xc[b]);
                }
    double tr = cxx[0][0] + cxx[1][1] + cxx[2][2];
    if (!(fabs(det3(cxx)) > 1e-9 * tr * tr * tr) || !inv3(cxx, inv)) return 0;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            m[i][j] = cyx[i][0] * inv[0][j] + cyx[i][1] * inv[1][j] + cyx[i][2] * inv[2][j];
        m[i][3] = yc[i] - m[i][0] * xc[0] - m[i][1] * xc[1] - m[i][2] * xc[2];
    }
    return 1;
}

static void apply(const double m[3][4], const double *x, double *y)
{
    for (int i = 0; i < 3; ++i)
        y[i] = m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2] + m[i][3];
}

/* Adds the row n . (A x + b) = n . foot to the normal equations, in coordinates centred at
 * xc (G) and yc (G') and scaled by 1 / sc. */
static void add_row(double nn[12][12], double rhs[12], const double *n, const double *x,
                    const double *foot, const double *xc, const double *yc, double sc)
{
    double a[12], xh[3], b = 0;
    for (int j = 0; j < 3; ++j)
        xh[j] = (x[j] - xc[j]) / sc, b += n[j] * (foot[j] - yc[j]) / sc;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            a[4 * i + j] = n[i] * xh[j];
        a[4 * i + 3] = n[i];
    }
    for (int i = 0; i < 12; ++i) {
        rhs[i] += a[i] * b;
        for (int j = 0; j < 12; ++j)
            nn[i][j] += a[i] * a[j];
    }
}

/* Unit vectors n1, n2 orthogonal to the unit vector t. */
static void normals_of(const double *t, double *n1, double *n2)
{
    int k = fabs(t[0]) <= fabs(t[1]) && fabs(t[0]) <= fabs(t[2]) ? 0 : fabs(t[1]) <= fabs(t[2]) ? 1 : 2;
    double e[3] = {0, 0, 0};
    e[k] = 1;
    n1[0] = t[1] * e[2] - t[2] * e[1], n1[1] = t[2] * e[0] - t[0] * e[2],
    n1[2] = t[0] * e[1] - t[1] * e[0];
    double l = sqrt(dot3(n1, n1));
    for (int i = 0; i < 3; ++i)
        n1[i] /= l;
    n2[0] = t[1] * n1[2] - t[2] * n1[1], n2[1] = t[2] * n1[0] - t[0] * n1[2],
    n2[2] = t[0] * n1[1] - t[1] * n1[0];
}

/* One pass: projects the images of every sample onto its entity of G' (*worst: the largest
 * distance) and, if nn is not NULL, accumulates the linearised rows. */
static cm_status project_all(cm_context *ctx, const cm_cad_model *g2, samples *s,
                             const double m[3][4], int first, double *worst, double nn[12][12],
                             double rhs[12], const double *xc, const double *yc, double sc)
{
    double *q = malloc(s->n * 16 * sizeof *q);
    if (!q) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    double *foot = q + 3 * s->n, *nrm = foot + 3 * s->n, *t = nrm + 3 * s->n, *d = t + s->n,
           *uv = d + s->n, *scratch = uv + 2 * s->n;
    for (size_t i = 0; i < s->n; ++i)
        apply(m, s->x + 3 * i, q + 3 * i);
    cm_status r = CM_OK;
    *worst = 0;
    for (size_t i = 0; i < s->n && r >= 0;) {
        size_t j = i;
        while (j < s->n && s->kind[j] == s->kind[i] && s->ent[j] == s->ent[i])
            ++j;
        size_t k = j - i;
        if (s->kind[i] == 0) {
            for (size_t p = i; p < j; ++p) {
                double dd[3];
                for (int a = 0; a < 3; ++a)
                    dd[a] = q[3 * p + a] - s->y[3 * p + a];
                double dist = sqrt(dot3(dd, dd));
                if (!(dist <= *worst)) *worst = dist;
                static const double ax[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
                for (int a = 0; a < 3 && nn; ++a)
                    add_row(nn, rhs, ax[a], s->x + 3 * p, s->y + 3 * p, xc, yc, sc);
            }
        } else if (s->kind[i] == 1) {
            int e = s->ent[i];
            cm_cad_edge_info ei;
            r = cm_cad_edge_get_info(ctx, g2, e, &ei);
            if (r >= 0) r = cm_cad_project_edge(ctx, g2, e, q + 3 * i, k, t + i, d + i);
            if (r >= 0) r = cm_cad_edge_eval(ctx, g2, e, t + i, k, foot + 3 * i);
            /* tangents by central differences (only their direction matters) */
            double h = 1e-6 * (ei.t_range[1] - ei.t_range[0]);
            for (size_t p = i; p < j && r >= 0; ++p) {
                double tt[2] = {t[p] - h, t[p] + h}, pp[6];
                if (tt[0] < ei.t_range[0]) tt[0] = t[p];
                if (tt[1] > ei.t_range[1]) tt[1] = t[p];
                r = cm_cad_edge_eval(ctx, g2, e, tt, 2, pp);
                double tan[3] = {pp[3] - pp[0], pp[4] - pp[1], pp[5] - pp[2]}, n1[3], n2[3];
                double l = sqrt(dot3(tan, tan));
                if (!(d[p] <= *worst)) *worst = d[p];
                if (!nn || !(l > 0)) continue;
                for (int a = 0; a < 3; ++a)
                    tan[a] /= l;
                normals_of(tan, n1, n2);
                add_row(nn, rhs, n1, s->x + 3 * p, foot + 3 * p, xc, yc, sc);
                add_row(nn, rhs, n2, s->x + 3 * p, foot + 3 * p, xc, yc, sc);
            }
        } else {
            int f = s->ent[i];
            r = cm_cad_project_face(ctx, g2, f, q + 3 * i, k, first ? NULL : s->uv + 2 * i,
                                    uv + 2 * i, d + i, foot + 3 * i);
            if (r >= 0) memcpy(s->uv + 2 * i, uv + 2 * i, 2 * k * sizeof(double));
            if (r >= 0 && nn) r = cm_cad_face_eval(ctx, g2, f, uv + 2 * i, k, scratch, nrm + 3 * i);
            for (size_t p = i; p < j && r >= 0; ++p) {
                if (!(d[p] <= *worst)) *worst = d[p];
                const double *n = nrm + 3 * p;
                if (nn && isfinite(dot3(n, n)) && dot3(n, n) > 0.5)
                    add_row(nn, rhs, n, s->x + 3 * p, foot + 3 * p, xc, yc, sc);
            }
        }
        i = j;
    }
    free(q);
    return r < 0 ? r : CM_OK;
}

cm_status cm_surface_affine_fit_samples(cm_context *ctx, const cm_cad_model *g,
                                        const cm_cad_model *g2, const double *xv,
                                        const double *yv, int nv, double tol,
                                        cm_surface_affine *a)
{
    samples s;
    double m[3][4], vol[2] = {0, 0};
    int have_moments = 0;
    cm_status r = collect(ctx, g, g2, xv, yv, nv, &s);
    if (r == CM_OK) r = guess_moments(ctx, g, g2, &s, m, vol, &have_moments);
    if (r != CM_OK || (!have_moments && !guess_points(&s, m))) {
        samples_free(&s);
        return r == CM_ERR_NOMEM ? r : CM_OK; /* no guess: not affine */
    }
    /* coordinates centred on the boxes and scaled by G's diagonal: the normal equations
     * stay well conditioned whatever the part's size and position */
    double bb[6], bb2[6], xc[3], yc[3];
    cm_cad_bbox(g, bb);
    cm_cad_bbox(g2, bb2);
    double sc = cm_bbox_diagonal(bb);
    for (int i = 0; i < 3; ++i)
        xc[i] = 0.5 * (bb[i] + bb[i + 3]), yc[i] = 0.5 * (bb2[i] + bb2[i + 3]);
    double worst = INFINITY, best = INFINITY, best_m[3][4];
    int stalled = 0;
    for (int it = 0; it <= MAX_ITER && r == CM_OK; ++it) {
        double nn[12][12] = {{0}}, rhs[12] = {0}, p[12], cur[12];
        r = project_all(ctx, g2, &s, m, it == 0, &worst, nn, rhs, xc, yc, sc);
        if (r != CM_OK) break;
        if (worst < best) {
            stalled = worst > 0.9 * best ? stalled + 1 : 0;
            best = worst;
            memcpy(best_m, m, sizeof m);
        } else {
            ++stalled;
        }
        /* converged far below the tolerance, or no longer improving */
        if (best <= 1e-3 * tol || stalled >= 3 || it == MAX_ITER) break;
        /* the current map in scaled coordinates; a tiny pull towards it keeps directions
         * that no sample constrains where the first guess put them */
        for (int i = 0; i < 3; ++i) {
            double ax = m[i][0] * xc[0] + m[i][1] * xc[1] + m[i][2] * xc[2];
            for (int j = 0; j < 3; ++j)
                cur[4 * i + j] = m[i][j];
            cur[4 * i + 3] = (ax + m[i][3] - yc[i]) / sc;
        }
        double trace = 0;
        for (int i = 0; i < 12; ++i)
            trace += nn[i][i];
        for (int i = 0; i < 12; ++i)
            nn[i][i] += 1e-12 * trace, rhs[i] += 1e-12 * trace * cur[i];
        if (!solve12(nn, rhs, p)) break;
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j)
                m[i][j] = p[4 * i + j];
            m[i][3] = yc[i] + sc * p[4 * i + 3] - m[i][0] * xc[0] - m[i][1] * xc[1] -
                      m[i][2] * xc[2];
        }
    }
    samples_free(&s);
    if (r == CM_ERR_NOMEM || r == CM_ERR_INTERRUPTED) return r;
    if (r != CM_OK || !isfinite(best)) {
        /* a projection OpenCASCADE could not do: the edit keeps the parameter warps, as
         * before this fit existed */
        cm_log(ctx, CM_LOG_DEBUG, "surface morph: no affine fit from edge and face samples");
        return CM_OK;
    }
    memcpy(a->m, best_m, sizeof best_m);
    a->residual = best;
    a->tol = tol;
    double lin[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            lin[i][j] = best_m[i][j];
    double detv = fabs(det3(lin));
    /* OpenCASCADE's adaptive integration gets volumes to a few 1e-6 on B-spline faces
     * (tests/surface/test_affine.c): a looser bound, still a check of the whole solid */
    int volume_ok = !have_moments || fabs(detv * vol[0] - vol[1]) <= 1e-4 * vol[1];
    a->valid = best <= tol && volume_ok;
    cm_log(ctx, CM_LOG_DEBUG,
           "surface morph: affine fit from edge and face samples (%s first guess): largest miss "
           "%.3g, tolerance %.3g, volume ratio %.9g against |det A| %.9g: %s",
           have_moments ? "volume moments" : "least-squares", best, tol,
           have_moments ? vol[1] / vol[0] : NAN, detv, a->valid ? "affine" : "not affine");
    return CM_OK;
}
