/* Icosphere and cotangent mean curvature for the deform benchmarks (see surface.h). */
#include "surface.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void bench_surface_free(bench_surface *s)
{
    free(s->xyz);
    free(s->tri);
    memset(s, 0, sizeof *s);
}

/* Edge midpoint cache: a hash of (min, max) vertex pairs. */
typedef struct edge_map {
    size_t cap;
    int64_t *key_a, *key_b, *val;
} edge_map;

static int64_t midpoint(edge_map *m, double *xyz, size_t *nv, int64_t a, int64_t b)
{
    if (a > b) {
        int64_t t = a;
        a = b;
        b = t;
    }
    size_t h = ((size_t)a * 73856093u ^ (size_t)b * 19349663u) % m->cap;
    while (m->val[h] >= 0) {
        if (m->key_a[h] == a && m->key_b[h] == b) return m->val[h];
        h = (h + 1) % m->cap;
    }
    int64_t v = (int64_t)(*nv)++;
    double p[3], n = 0;
    for (int k = 0; k < 3; ++k) {
        p[k] = xyz[3 * a + k] + xyz[3 * b + k];
        n += p[k] * p[k];
    }
    n = sqrt(n);
    for (int k = 0; k < 3; ++k)
        xyz[3 * v + k] = p[k] / n;
    m->key_a[h] = a;
    m->key_b[h] = b;
    m->val[h] = v;
    return v;
}

int bench_icosphere(int level, const double c[3], double r, bench_surface *s)
{
    const double t = (1 + sqrt(5.0)) / 2;
    double v0[12][3] = {{-1, t, 0}, {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                        {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    int f0[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                     {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                     {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                     {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    size_t nt = 20, nv = 12;
    for (int l = 0; l < level; ++l)
        nt *= 4;
    size_t maxv = 10 * (nt / 20) + 2;
    double *xyz = malloc(maxv * 3 * sizeof *xyz);
    int64_t *tri = malloc(nt * 3 * sizeof *tri), *tmp = malloc(nt * 3 * sizeof *tmp);
    if (!xyz || !tri || !tmp) return -1;
    for (int i = 0; i < 12; ++i) {
        double n = sqrt(v0[i][0] * v0[i][0] + v0[i][1] * v0[i][1] + v0[i][2] * v0[i][2]);
        for (int k = 0; k < 3; ++k)
            xyz[3 * i + k] = v0[i][k] / n;
    }
    for (int i = 0; i < 60; ++i)
        tri[i] = f0[i / 3][i % 3];
    size_t cur = 20;
    for (int l = 0; l < level; ++l) {
        edge_map m;
        m.cap = 6 * cur + 7;
        m.key_a = malloc(m.cap * sizeof *m.key_a);
        m.key_b = malloc(m.cap * sizeof *m.key_b);
        m.val = malloc(m.cap * sizeof *m.val);
        for (size_t i = 0; i < m.cap; ++i)
            m.val[i] = -1;
        for (size_t f = 0; f < cur; ++f) {
            int64_t a = tri[3 * f], b = tri[3 * f + 1], cc = tri[3 * f + 2];
            int64_t ab = midpoint(&m, xyz, &nv, a, b), bc = midpoint(&m, xyz, &nv, b, cc),
                    ca = midpoint(&m, xyz, &nv, cc, a);
            int64_t q[12] = {a, ab, ca, b, bc, ab, cc, ca, bc, ab, bc, ca};
            memcpy(tmp + 12 * f, q, sizeof q);
        }
        free(m.key_a);
        free(m.key_b);
        free(m.val);
        cur *= 4;
        memcpy(tri, tmp, cur * 3 * sizeof *tri);
    }
    free(tmp);
    for (size_t i = 0; i < nv; ++i)
        for (int k = 0; k < 3; ++k)
            xyz[3 * i + k] = c[k] + r * xyz[3 * i + k];
    s->nv = nv;
    s->nt = nt;
    s->xyz = xyz;
    s->tri = tri;
    return 0;
}

void bench_mean_curvature(const bench_surface *s, const double *xyz, double *h)
{
    double *lap = calloc(s->nv * 3, sizeof *lap), *area = calloc(s->nv, sizeof *area);
    for (size_t f = 0; f < s->nt; ++f) {
        const int64_t *t = s->tri + 3 * f;
        const double *p[3] = {xyz + 3 * t[0], xyz + 3 * t[1], xyz + 3 * t[2]};
        double e[3][3], cr[3];
        for (int k = 0; k < 3; ++k) /* e[k] = p[k+2] - p[k+1]: the edge opposite vertex k */
            for (int d = 0; d < 3; ++d)
                e[k][d] = p[(k + 2) % 3][d] - p[(k + 1) % 3][d];
        cr[0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
        cr[1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
        cr[2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
        double a2 = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]); /* 2 x area */
        for (int k = 0; k < 3; ++k) {
            area[t[k]] += a2 / 6;
            /* the angle at vertex k is between -e[k+1] and e[k+2] */
            const double *u = e[(k + 1) % 3], *w = e[(k + 2) % 3];
            double dot = -(u[0] * w[0] + u[1] * w[1] + u[2] * w[2]);
            double cot = a2 > 0 ? dot / a2 : 0;
            int64_t i = t[(k + 1) % 3], j = t[(k + 2) % 3];
            for (int d = 0; d < 3; ++d) {
                lap[3 * i + d] += cot * (xyz[3 * j + d] - xyz[3 * i + d]);
                lap[3 * j + d] += cot * (xyz[3 * i + d] - xyz[3 * j + d]);
            }
        }
    }
    for (size_t i = 0; i < s->nv; ++i) {
        double n = sqrt(lap[3 * i] * lap[3 * i] + lap[3 * i + 1] * lap[3 * i + 1] +
                        lap[3 * i + 2] * lap[3 * i + 2]);
        h[i] = area[i] > 0 ? n / (4 * area[i]) : 0;
    }
    free(lap);
    free(area);
}
