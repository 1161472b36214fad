/* Boundary point sets shared by the iterative and the distributed RBF tests (header-only,
 * like test_mesh.h). */
#ifndef CADMORPH_TEST_RBF_SETS_H
#define CADMORPH_TEST_RBF_SETS_H

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

/* Boundary nodes of a box [0,a] x [0,b] x [0,c] with a bore of radius rad along z through
 * (xc, yc), spaced about h, shifted by off: the kind of set a tet mesh of bore_a.step has
 * (flat faces, a curved face, sharp edges). Returns the count written into x (n x 3). */
static inline size_t box_with_bore(double a, double b, double c, double xc, double yc, double rad,
                            double h, const double *off, double *x)
{
    size_t n = 0;
    const int na = (int)(a / h + 0.5), nb = (int)(b / h + 0.5), nz = (int)(c / h + 0.5);
#define PUT(px, py, pz)                                                                         \
    do {                                                                                       \
        if (x) {                                                                               \
            x[3 * n] = (px) + off[0];                                                          \
            x[3 * n + 1] = (py) + off[1];                                                      \
            x[3 * n + 2] = (pz) + off[2];                                                      \
        }                                                                                      \
        ++n;                                                                                   \
    } while (0)
    for (int i = 0; i <= na; ++i)
        for (int j = 0; j <= nb; ++j) {
            double px = a * i / na, py = b * j / nb;
            if (hypot(px - xc, py - yc) < rad + 0.3 * h) continue; /* the hole */
            PUT(px, py, 0.0);
            PUT(px, py, c);
        }
    for (int k = 1; k < nz; ++k) {
        double pz = c * k / nz;
        for (int i = 0; i <= na; ++i) {
            PUT(a * i / na, 0.0, pz);
            PUT(a * i / na, b, pz);
        }
        for (int j = 1; j < nb; ++j) {
            PUT(0.0, b * j / nb, pz);
            PUT(a, b * j / nb, pz);
        }
    }
    const int nt = (int)(6.283185307179586 * rad / h + 0.5);
    for (int k = 0; k <= nz; ++k)
        for (int t = 0; t < nt; ++t) {
            double th = 6.283185307179586 * (t + 0.5 * (k % 2)) / nt;
            PUT(xc + rad * cos(th), yc + rad * sin(th), c * k / nz);
        }
#undef PUT
    return n;
}

/* A displacement like the bore's edit: the bore face (axis through (xc, yc)) moves
 * radially, the rest follows smoothly, plus a global bend. */
static inline void bore_motion(size_t n, const double *x, double xc, double yc, double *d)
{
    for (size_t i = 0; i < n; ++i) {
        double dx = x[3 * i] - xc, dy = x[3 * i + 1] - yc, r = hypot(dx, dy) + 1e-12;
        double s = 0.05 * exp(-2.0 * (r - 0.4) * (r - 0.4));
        d[3 * i] = s * dx / r + 0.01 * sin(x[3 * i + 2]);
        d[3 * i + 1] = s * dy / r;
        d[3 * i + 2] = 0.02 * x[3 * i] * x[3 * i] / 16.0;
    }
}

/* The standard set of these tests: the 4 x 2 x 1 box with the bore (radius 0.4) through
 * (2, 1), spacing h; its m centres malloc'ed (m x 3), NULL out of memory. */
static inline double *bore_centres(double h, size_t *m)
{
    const double off[3] = {0.0, 0.0, 0.0};
    *m = box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, h, off, NULL);
    double *x = malloc(*m * 3 * sizeof *x);
    if (x) box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, h, off, x);
    return x;
}

/* The same centres with the bore's motion: *x and *d malloc'ed (m x 3). Returns m. */
static inline size_t bore_set(double h, double **x, double **d)
{
    size_t m = 0;
    *x = bore_centres(h, &m);
    *d = malloc(m * 3 * sizeof **d);
    if (*x && *d) bore_motion(m, *x, 2.0, 1.0, *d);
    return m;
}

/* Evaluation points for the box sets: the m centres x, then nin points spread through the
 * box [0.1, 3.9] x [0.1, 0.1 + ywidth] x [0.1, 0.9]; *np = m + nin. NULL out of memory. */
static inline double *eval_points(size_t m, const double *x, size_t nin, double ywidth,
                                  size_t *np)
{
    double *p = malloc((m + nin) * 3 * sizeof *p);
    if (!p) return NULL;
    memcpy(p, x, m * 3 * sizeof *p);
    for (size_t i = 0; i < nin; ++i) {
        double t = (double)i / (double)nin;
        p[3 * (m + i)] = 0.1 + 3.8 * t;
        p[3 * (m + i) + 1] = 0.1 + ywidth * fmod(7.0 * t, 1.0);
        p[3 * (m + i) + 2] = 0.1 + 0.8 * fmod(13.0 * t, 1.0);
    }
    *np = m + nin;
    return p;
}

static inline double range_of(size_t n, const double *v)
{
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        lo = fmin(lo, v[i]);
        hi = fmax(hi, v[i]);
    }
    return hi - lo;
}

static inline double max_diff(size_t n, const double *a, const double *b)
{
    double v = 0.0;
    for (size_t i = 0; i < n; ++i) v = fmax(v, fabs(a[i] - b[i]));
    return v;
}

#endif
