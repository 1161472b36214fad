/* Thinned far band of a Schwarz subdomain (option thin_reach, rbf_schwarz.c): beyond the
 * near set, whose centres are all kept, a subdomain takes one centre per voxel of a grid whose
 * cell grows with the distance from the leaf's box, so that its reach is geometric while its
 * centre count stays bounded. Why voxels that grow with the distance: the local inverse's leaf
 * rows need the far residual only at the resolution at which it still moves the leaf's
 * weights, which coarsens with the distance; on a surface a cell proportional to the distance
 * gives the same number of picks per octave of distance (about 3 pi / cell^2), so the count
 * grows only as the logarithm of the reach. */
#include "rbf_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

typedef struct voxel {
    int64_t ix, iy, iz;
    int band;      /* -1: empty slot */
    size_t count;  /* candidates in the voxel */
    double sum[3]; /* their coordinates' sum, then their centroid */
    size_t pos;    /* the candidate nearest to the centroid */
    double best;   /* its squared distance to the centroid */
} voxel;

static uint64_t voxel_hash(int64_t x, int64_t y, int64_t z, int band)
{
    uint64_t h = (uint64_t)x * 0x9E3779B97F4A7C15u;
    h ^= (uint64_t)y * 0xC2B2AE3D27D4EB4Fu + (h << 6) + (h >> 2);
    h ^= (uint64_t)z * 0x165667B19E3779F9u + (h << 6) + (h >> 2);
    h ^= (uint64_t)band * 0x27D4EB2F165667C5u;
    return h ^ (h >> 29);
}

/* The table slot of candidate u's voxel (inserted if new). */
static size_t voxel_of(voxel *tab, size_t tsize, const double *c, size_t m,
                       const cm_rbf_keyed *cu, double d0, double cell, const double org[3])
{
    const size_t i = cu->idx;
    const double d = sqrt(cu->key);
    /* band k: d in [d0 2^k, d0 2^(k+1)), cell d0 2^k x cell, so between cell / 2 and cell of
     * the distance; bands nest, the grids of two bands never mix in one voxel */
    int band = d > d0 ? (int)floor(log2(d / d0)) : 0;
    if (band > 60) band = 60;
    const double h = cell * d0 * ldexp(1.0, band);
    int64_t v[3];
    for (int q = 0; q < 3; ++q) v[q] = (int64_t)floor((c[(size_t)q * m + i] - org[q]) / h);
    size_t s = (size_t)(voxel_hash(v[0], v[1], v[2], band) & (tsize - 1));
    while (tab[s].band >= 0 &&
           !(tab[s].band == band && tab[s].ix == v[0] && tab[s].iy == v[1] && tab[s].iz == v[2]))
        s = (s + 1) & (tsize - 1);
    if (tab[s].band < 0) tab[s] = (voxel){v[0], v[1], v[2], band, 0, {0, 0, 0}, 0, INFINITY};
    return s;
}

long cm_rbf_thin_pick(const double *c, size_t m, const cm_rbf_keyed *cand, size_t nc,
                      double d0, double cell, const double org[3], size_t cap, size_t *out)
{
    if (nc == 0 || cap == 0) return 0;
    size_t tsize = 64;
    while (tsize < 2 * nc) tsize *= 2;
    voxel *tab = malloc(tsize * sizeof *tab);
    size_t *vs = malloc(nc * sizeof *vs);
    if (!tab || !vs) {
        free(tab), free(vs);
        return -1;
    }
    for (size_t s = 0; s < tsize; ++s) tab[s].band = -1;
    for (size_t u = 0; u < nc; ++u) {
        voxel *v = &tab[vs[u] = voxel_of(tab, tsize, c, m, &cand[u], d0, cell, org)];
        ++v->count;
        for (int q = 0; q < 3; ++q) v->sum[q] += c[(size_t)q * m + cand[u].idx];
    }
    for (size_t s = 0; s < tsize; ++s)
        if (tab[s].band >= 0)
            for (int q = 0; q < 3; ++q) tab[s].sum[q] /= (double)tab[s].count;
    /* the pick stands for its voxel: the candidate nearest to the voxel's centroid (a pick's
     * voxel-mean residual instead of its own was measured worse: RESULTS.md, RBF solvers) */
    for (size_t u = 0; u < nc; ++u) {
        voxel *v = &tab[vs[u]];
        double e2 = 0.0;
        for (int q = 0; q < 3; ++q) {
            double e = c[(size_t)q * m + cand[u].idx] - v->sum[q];
            e2 += e * e;
        }
        if (e2 < v->best) v->best = e2, v->pos = u;
    }
    /* the nearest picks first: the cap cuts the reach, not the resolution near the leaf */
    size_t n = 0;
    for (size_t u = 0; u < nc && n < cap; ++u)
        if (tab[vs[u]].pos == u) out[n++] = cand[u].idx;
    free(tab), free(vs);
    return (long)n;
}
