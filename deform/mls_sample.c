/* Sampling for the MLS deformation (paper sections 4-5, Figure 2): dense random points on the
 * surface and in the volume, a farthest-point subset, Lloyd relaxation. Volume cells are cut
 * into tets and faces into triangles, each sampled uniformly by measure. */
#include "mls_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static uint64_t rng_next(uint64_t *s)
{
    /* xorshift64*: reproducible across platforms, unlike rand() */
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return *s * 2685821657736338717ull;
}

static double rng_uniform(uint64_t *s) { return (double)(rng_next(s) >> 11) * 0x1.0p-53; }

void mls_dense_free(mls_dense *d)
{
    free(d->xyz);
    free(d->measure);
    memset(d, 0, sizeof *d);
}

/* Simplices (3 or 4 node ids) with measures. */
typedef struct simplex_list {
    size_t n, cap;
    int nv;
    int64_t *v;
    double *cdf; /* running sum of measures */
} simplex_list;

static int list_push(simplex_list *l, const int64_t *v, double measure)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 1024;
        int64_t *nv = realloc(l->v, cap * (size_t)l->nv * sizeof *nv);
        if (!nv) return -1;
        l->v = nv;
        double *nc = realloc(l->cdf, cap * sizeof *nc);
        if (!nc) return -1;
        l->cdf = nc;
        l->cap = cap;
    }
    memcpy(l->v + l->n * (size_t)l->nv, v, (size_t)l->nv * sizeof *v);
    l->cdf[l->n] = (l->n ? l->cdf[l->n - 1] : 0) + measure;
    ++l->n;
    return 0;
}

static double tri_area(const double *x, const int64_t *v)
{
    const double *a = x + 3 * v[0], *b = x + 3 * v[1], *c = x + 3 * v[2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    return 0.5 * sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

static double tet_volume(const double *x, const int64_t *v)
{
    const double *a = x + 3 * v[0], *b = x + 3 * v[1], *c = x + 3 * v[2], *d = x + 3 * v[3];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double z[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    return fabs(u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) +
                u[2] * (w[0] * z[1] - w[1] * z[0])) /
           6;
}

static int push_polygon(simplex_list *l, const double *xyz, const int64_t *p, int64_t n)
{
    for (int64_t i = 1; i + 1 < n; ++i) {
        int64_t t[3] = {p[0], p[i], p[i + 1]};
        if (list_push(l, t, tri_area(xyz, t))) return -1;
    }
    return 0;
}

/* Tets of the linear volume cells in VTK corner order (polyhedra are not sampled). */
static int push_cell_tets(simplex_list *l, const double *xyz, cm_cell_type lin, const int64_t *c)
{
    static const int tet[1][4] = {{0, 1, 2, 3}};
    static const int hex[5][4] = {{0, 1, 3, 4}, {1, 2, 3, 6}, {1, 4, 5, 6}, {3, 4, 6, 7}, {1, 3, 4, 6}};
    static const int wedge[3][4] = {{0, 1, 2, 3}, {1, 2, 3, 4}, {2, 3, 4, 5}};
    static const int pyr[2][4] = {{0, 1, 2, 4}, {0, 2, 3, 4}};
    const int(*d)[4] = NULL;
    int n = 0;
    switch (lin) {
    case CM_CELL_TET4: d = tet, n = 1; break;
    case CM_CELL_HEX8: d = hex, n = 5; break;
    case CM_CELL_WEDGE6: d = wedge, n = 3; break;
    case CM_CELL_PYR5: d = pyr, n = 2; break;
    default: return 0;
    }
    for (int i = 0; i < n; ++i) {
        int64_t t[4] = {c[d[i][0]], c[d[i][1]], c[d[i][2]], c[d[i][3]]};
        if (list_push(l, t, tet_volume(xyz, t))) return -1;
    }
    return 0;
}

/* m points drawn from the simplices of l, each simplex with probability proportional to
 * measure^power (cdf: scratch of l->n entries, used when power != 1); measure[i]: the share
 * of the total measure point i stands for, measure_s / (m p_s), so that the sum over the
 * points estimates the total for any power. */
static void sample_list(const simplex_list *l, const double *xyz, size_t m, double power,
                        double *cdf, uint64_t *rng, double *out, double *measure)
{
    const double *c = l->cdf;
    if (power != 1) {
        for (size_t i = 0; i < l->n; ++i) {
            double mi = l->cdf[i] - (i ? l->cdf[i - 1] : 0);
            cdf[i] = (i ? cdf[i - 1] : 0) + (mi > 0 ? pow(mi, power) : 0);
        }
        c = cdf;
    }
    double total = c[l->n - 1], whole = l->cdf[l->n - 1];
    for (size_t i = 0; i < m; ++i) {
        double t = rng_uniform(rng) * total;
        size_t lo = 0, hi = l->n - 1;
        while (lo < hi) {
            size_t mid = (lo + hi) / 2;
            if (c[mid] < t)
                lo = mid + 1;
            else
                hi = mid;
        }
        double ps = (c[lo] - (lo ? c[lo - 1] : 0)) / total;
        double ms = l->cdf[lo] - (lo ? l->cdf[lo - 1] : 0);
        measure[i] = power == 1 || !(ps > 0) ? whole / (double)m : ms / ((double)m * ps);
        const int64_t *v = l->v + lo * (size_t)l->nv;
        double b[4];
        if (l->nv == 3) {
            double r1 = sqrt(rng_uniform(rng)), r2 = rng_uniform(rng);
            b[0] = 1 - r1, b[1] = r1 * (1 - r2), b[2] = r1 * r2;
        } else {
            /* uniform in a tet: normalised exponentials (a flat Dirichlet) */
            double s = 0;
            for (int q = 0; q < 4; ++q)
                s += b[q] = -log(1 - rng_uniform(rng));
            for (int q = 0; q < 4; ++q)
                b[q] /= s;
        }
        for (int a = 0; a < 3; ++a) {
            double x = 0;
            for (int q = 0; q < l->nv; ++q)
                x += b[q] * xyz[3 * v[q] + a];
            out[3 * i + a] = x;
        }
    }
}

cm_status mls_dense_create(cm_context *ctx, const cm_mesh *mesh, size_t n_surface,
                           size_t n_volume, double graded, uint64_t seed, mls_dense *d)
{
    double *cdf = NULL;
    memset(d, 0, sizeof *d);
    simplex_list tri = {0, 0, 3, NULL, NULL}, tet = {0, 0, 4, NULL, NULL};
    cm_mesh_boundary *bnd = NULL;
    cm_status s = CM_OK;
    int fail = 0;
    size_t n3 = cm_mesh_count_dim(mesh, 3);
    for (size_t c = 0; c < mesh->n_cells && !fail; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        const int64_t *cn = mesh->conn + mesh->offset[c];
        int64_t len = mesh->offset[c + 1] - mesh->offset[c];
        if (!info) continue;
        if (info->dim == 3)
            fail = push_cell_tets(&tet, mesh->xyz, info->linear, cn);
        else if (info->dim == 2 && n3 == 0)
            fail = push_polygon(&tri, mesh->xyz, cn, info->corners > 0 ? info->corners : len);
    }
    if (!fail && n3) {
        s = cm_mesh_boundary_create(ctx, mesh, &bnd);
        if (s < 0) goto done;
        s = CM_OK;
        for (size_t f = 0; f < bnd->n_faces && !fail; ++f)
            fail = push_polygon(&tri, mesh->xyz, bnd->face_nodes + bnd->face_offset[f],
                                bnd->face_offset[f + 1] - bnd->face_offset[f]);
    }
    if (fail) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls: out of memory (sampling)");
        goto done;
    }
    d->area = tri.n ? tri.cdf[tri.n - 1] : 0;
    d->volume = tet.n ? tet.cdf[tet.n - 1] : 0;
    if (!(d->area > 0)) n_surface = 0;
    if (!(d->volume > 0)) n_volume = 0;
    if (n_surface + n_volume == 0) {
        s = cm_error(ctx, CM_ERR_UNSUPPORTED,
                     "cm_mls: the mesh has no faces or volume cells of positive measure to sample");
        goto done;
    }
    d->xyz = malloc((n_surface + n_volume) * 3 * sizeof *d->xyz);
    d->measure = malloc((n_surface + n_volume) * sizeof *d->measure);
    if (graded > 0) cdf = malloc((tri.n > tet.n ? tri.n : tet.n) * sizeof *cdf);
    if (!d->xyz || !d->measure || (graded > 0 && !cdf)) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls: out of memory (sampling)");
        goto done;
    }
    uint64_t rng = seed * 0x9E3779B97F4A7C15ull + 1;
    double power = 1 - (graded > 1 ? 1 : graded > 0 ? graded : 0);
    if (n_surface) sample_list(&tri, mesh->xyz, n_surface, power, cdf, &rng, d->xyz, d->measure);
    if (n_volume)
        sample_list(&tet, mesh->xyz, n_volume, power, cdf, &rng, d->xyz + 3 * n_surface,
                    d->measure + n_surface);
    d->n_s = n_surface;
    d->n_v = n_volume;
done:
    free(cdf);
    cm_mesh_boundary_destroy(&bnd);
    free(tri.v);
    free(tri.cdf);
    free(tet.v);
    free(tet.cdf);
    if (s < 0) mls_dense_free(d);
    return s;
}

/* The farthest point of one grid cell: its largest squared distance to the centres so far
 * and the lowest index that has it. */
typedef struct fps_key {
    double d;
    size_t i;
} fps_key;

/* The order of the plain scan: the larger distance first, the lower index on a tie. */
static int fps_above(const fps_key *a, const fps_key *b)
{
    return a->d > b->d || (a->d == b->d && a->i < b->i);
}

/* A max-heap of the non-empty cells by their key; pos: each cell's place (keys only drop, so
 * an update sifts down). */
typedef struct fps_heap {
    int32_t *cell, *pos;
    fps_key *key; /* per cell */
    size_t n;
} fps_heap;

static void fps_sift_down(fps_heap *h, size_t i)
{
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, m = i;
        if (l < h->n && fps_above(&h->key[h->cell[l]], &h->key[h->cell[m]])) m = l;
        if (r < h->n && fps_above(&h->key[h->cell[r]], &h->key[h->cell[m]])) m = r;
        if (m == i) return;
        int32_t t = h->cell[i];
        h->cell[i] = h->cell[m], h->cell[m] = t;
        h->pos[h->cell[i]] = (int32_t)i, h->pos[h->cell[m]] = (int32_t)m;
        i = m;
    }
}

static fps_key cell_key(const mls_grid *g, const double *dmin, size_t cell)
{
    fps_key k = {-1, 0};
    for (int32_t q = g->start[cell]; q < g->start[cell + 1]; ++q) {
        size_t i = (size_t)g->items[q]; /* ascending within a cell */
        if (dmin[i] > k.d) k.d = dmin[i], k.i = i;
    }
    return k;
}

/* Farthest-point sampling, exact: the same picks as scanning all n points per pick (the
 * definition), but a pick only visits the grid cells within the current largest distance of
 * the new centre - no point farther away can come closer to it than to its own nearest
 * centre - and the largest distance comes from a heap of the cells' farthest points. The scan
 * costs n per pick (n k in all: 8,000 samples over 270k dense points was a quarter of the
 * set-up); this costs about the points within that radius, which shrinks as k^(-1/3). */
cm_status mls_farthest(cm_context *ctx, const double *xyz, size_t n, size_t k, uint64_t seed,
                       double *out)
{
    if (k > n) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls: %zu samples from %zu points", k, n);
    if (k == 0) return CM_OK;
    mls_grid g;
    cm_status s = mls_grid_build(ctx, &g, n, xyz, 8.0);
    if (s < 0) return s;
    size_t nc = (size_t)g.n[0] * (size_t)g.n[1] * (size_t)g.n[2];
    double *dmin = malloc(n * sizeof *dmin);
    fps_heap h = {malloc(nc * sizeof(int32_t)), malloc(nc * sizeof(int32_t)), malloc(nc * sizeof(fps_key)), 0};
    if (!dmin || !h.cell || !h.pos || !h.key) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls: out of memory (farthest points)");
        goto done;
    }
    uint64_t rng = seed * 0x2545F4914F6CDD1Dull + 7;
    size_t cur = (size_t)(rng_next(&rng) % n);
    /* the first centre: every point's distance, then the heap of all cells */
    const double *c = xyz + 3 * cur;
    for (size_t i = 0; i < n; ++i) {
        const double *p = xyz + 3 * i;
        dmin[i] = (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) + (p[2] - c[2]) * (p[2] - c[2]);
    }
    for (size_t cell = 0; cell < nc; ++cell) {
        h.pos[cell] = -1;
        if (g.start[cell] == g.start[cell + 1]) continue;
        h.key[cell] = cell_key(&g, dmin, cell);
        h.pos[cell] = (int32_t)h.n;
        h.cell[h.n++] = (int32_t)cell;
    }
    for (size_t i = h.n / 2; i-- > 0;) fps_sift_down(&h, i);
    memcpy(out, c, 3 * sizeof *out);
    for (size_t j = 1; j < k; ++j) {
        cur = h.key[h.cell[0]].i;
        double r = sqrt(h.key[h.cell[0]].d) * (1 + 1e-9); /* a hair more: cells in floating point */
        c = xyz + 3 * cur;
        memcpy(out + 3 * j, c, 3 * sizeof *out);
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = (int)floor((c[a] - r - g.lo[a]) / g.h), hi[a] = (int)floor((c[a] + r - g.lo[a]) / g.h);
            if (lo[a] < 0) lo[a] = 0;
            if (hi[a] >= g.n[a]) hi[a] = g.n[a] - 1;
        }
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) {
                    size_t cell = ((size_t)z * g.n[1] + y) * g.n[0] + x;
                    int changed = 0;
                    for (int32_t q = g.start[cell]; q < g.start[cell + 1]; ++q) {
                        size_t i = (size_t)g.items[q];
                        const double *p = xyz + 3 * i;
                        double d = (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                                   (p[2] - c[2]) * (p[2] - c[2]);
                        if (d < dmin[i]) dmin[i] = d, changed = 1;
                    }
                    if (!changed) continue;
                    h.key[cell] = cell_key(&g, dmin, cell);
                    fps_sift_down(&h, (size_t)h.pos[cell]);
                }
    }
done:
    mls_grid_free(&g);
    free(dmin), free(h.cell), free(h.pos), free(h.key);
    return s;
}

cm_status mls_lloyd(cm_context *ctx, const double *xyz, const double *weight, size_t n,
                    int iterations, size_t k, double *centres, double *mass)
{
    double *acc = malloc(k * 4 * sizeof *acc);
    int32_t *near = malloc((n ? n : 1) * sizeof *near);
    if (!acc || !near) {
        free(acc);
        free(near);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mls: out of memory (Lloyd)");
    }
    cm_status s = CM_OK;
    int nt = cm_context_threads_for(ctx, n, 5000);
    for (int it = 0; it <= iterations; ++it) {
        mls_grid g;
        s = mls_grid_build(ctx, &g, k, centres, 2.0);
        if (s < 0) break;
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
        for (size_t i = 0; i < n; ++i) {
            double dd;
            mls_grid_nearest(&g, xyz + 3 * i, 1, near + i, &dd);
        }
        mls_grid_free(&g);
        memset(acc, 0, k * 4 * sizeof *acc);
        for (size_t i = 0; i < n; ++i) {
            double w = weight ? weight[i] : 1;
            double *a = acc + 4 * (size_t)near[i];
            a[0] += w * xyz[3 * i], a[1] += w * xyz[3 * i + 1], a[2] += w * xyz[3 * i + 2];
            a[3] += w;
        }
        if (mass)
            for (size_t j = 0; j < k; ++j)
                mass[j] = acc[4 * j + 3];
        if (it == iterations) break; /* the last pass only measures */
        for (size_t j = 0; j < k; ++j)
            if (acc[4 * j + 3] > 0)
                for (int a = 0; a < 3; ++a)
                    centres[3 * j + a] = acc[4 * j + a] / acc[4 * j + 3];
    }
    free(acc);
    free(near);
    return s;
}
