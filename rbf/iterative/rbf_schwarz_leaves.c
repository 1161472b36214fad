/* The Schwarz preconditioner's subdomains (rbf_internal.h, cm_rbf_leaves): the kD-tree of
 * the centres split into leaves, a leaf's local set (its own centres, then the nearest ones,
 * and a thinned far band), and the farthest-point coarse centres. rbf_schwarz.c builds the
 * local problems on them. */
#include "rbf_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef cm_rbf_leaves tree_build;
typedef cm_rbf_leaf leaf;
typedef cm_rbf_keyed keyed;

static double coord(const tree_build *t, size_t i, int d) { return t->c[(size_t)d * t->m + i]; }

/* Quickselect on perm[lo, hi) by coordinate d: perm[k] ends up the k-th smallest. */
static void select_kth(tree_build *t, size_t lo, size_t hi, size_t k, int d)
{
    size_t *p = t->perm;
    while (hi - lo > 1) {
        double pivot = coord(t, p[lo + (hi - lo) / 2], d);
        size_t i = lo, j = hi - 1;
        while (i <= j) {
            while (coord(t, p[i], d) < pivot) ++i;
            while (coord(t, p[j], d) > pivot) --j;
            if (i <= j) {
                size_t s = p[i];
                p[i] = p[j];
                p[j] = s;
                ++i;
                if (j == 0) break;
                --j;
            }
        }
        if (k <= j) hi = j + 1;
        else if (k >= i) lo = i;
        else return;
    }
}

/* After select_kth on perm[lo, hi) at mid by coordinate d: moves the split off the group of
 * centres tied with the median (within tol), so that the group goes to one side whole, and
 * returns the new split. Why: CAD boundary sets have thousands of centres on one axis-aligned
 * plane (a planar face), and a median inside that group handed each child an arbitrary
 * subset of the whole face. Such a leaf is a slab, its local set nearly coplanar, and its
 * local solve extrapolates off the plane: on one of two copies of the same bracket (the ties
 * are broken by the order the root split left) that put eigenvalues 0.09 and 1.9 into the
 * preconditioned operator, and the solve took 100 iterations instead of 11 (RESULTS.md,
 * RBF solvers). With the group kept whole, sibling boxes are disjoint. */
static size_t split_off_ties(tree_build *t, size_t lo, size_t hi, size_t mid, int d, double tol)
{
    size_t *p = t->perm;
    const double v = coord(t, p[mid], d);
    size_t a = lo, b = mid; /* [a, mid) and [mid, b): the tied centres on either side */
    for (size_t u = lo; u < mid; ++u)
        if (coord(t, p[u], d) < v - tol) {
            size_t s = p[a];
            p[a++] = p[u];
            p[u] = s;
        }
    for (size_t u = mid; u < hi; ++u)
        if (coord(t, p[u], d) <= v + tol) {
            size_t s = p[b];
            p[b++] = p[u];
            p[u] = s;
        }
    /* the nearer of the group's two ends that leaves both sides non-empty */
    size_t s = mid - a <= b - mid ? a : b;
    if (s == lo || s == hi) s = s == a ? b : a;
    return s == lo || s == hi ? mid : s; /* all tied: duplicates, which the local solves refuse */
}

int cm_rbf_leaves_split(tree_build *t, size_t lo, size_t hi)
{
    double bmin[3] = {INFINITY, INFINITY, INFINITY}, bmax[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t u = lo; u < hi; ++u)
        for (int d = 0; d < 3; ++d) {
            double x = coord(t, t->perm[u], d);
            bmin[d] = fmin(bmin[d], x);
            bmax[d] = fmax(bmax[d], x);
        }
    if (hi - lo <= t->leaf_size) {
        if (t->nleaves == t->cap) {
            int cap = t->cap ? 2 * t->cap : 64;
            leaf *nl = realloc(t->leaves, (size_t)cap * sizeof *nl);
            if (!nl) return -1;
            t->leaves = nl;
            t->cap = cap;
        }
        leaf *l = &t->leaves[t->nleaves++];
        l->lo = lo;
        l->hi = hi;
        memcpy(l->bmin, bmin, sizeof bmin);
        memcpy(l->bmax, bmax, sizeof bmax);
        return 0;
    }
    int d = 0;
    for (int e = 1; e < 3; ++e)
        if (bmax[e] - bmin[e] > bmax[d] - bmin[d]) d = e;
    size_t mid = lo + (hi - lo) / 2;
    select_kth(t, lo, hi, mid, d);
    mid = split_off_ties(t, lo, hi, mid, d, 1e-9 * (bmax[d] - bmin[d]));
    if (cm_rbf_leaves_split(t, lo, mid) != 0) return -1;
    return cm_rbf_leaves_split(t, mid, hi);
}

/* Squared distance from point x to box [bmin, bmax]. */
double cm_rbf_box_dist2(const double *x, const double *bmin, const double *bmax)
{
    double s = 0.0;
    for (int d = 0; d < 3; ++d) {
        double e = x[d] < bmin[d] ? bmin[d] - x[d] : x[d] > bmax[d] ? x[d] - bmax[d] : 0.0;
        s += e * e;
    }
    return s;
}

static double boxbox_dist2(const leaf *a, const leaf *b)
{
    double s = 0.0;
    for (int d = 0; d < 3; ++d) {
        double e = a->bmin[d] > b->bmax[d] ? a->bmin[d] - b->bmax[d]
                   : b->bmin[d] > a->bmax[d] ? b->bmin[d] - a->bmax[d] : 0.0;
        s += e * e;
    }
    return s;
}

static int cmp_keyed(const void *a, const void *b)
{
    double x = ((const keyed *)a)->key, y = ((const keyed *)b)->key;
    if (x < y) return -1;
    if (x > y) return 1;
    size_t i = ((const keyed *)a)->idx, j = ((const keyed *)b)->idx;
    return (i > j) - (i < j);
}

/* The local set of leaf l: its own centres, then the nloc - n_in centres nearest to its box
 * (leaves visited by box-box distance until no unvisited leaf can hold a nearer centre).
 * out: nloc indices. Scratch: lk (nleaves), cand (m). */
size_t cm_rbf_leaves_grow(const tree_build *t, int l, size_t nloc, size_t nmin, double reach2,
                          keyed *lk, keyed *cand, size_t *out)
{
    const leaf *L = &t->leaves[l];
    size_t nin = L->hi - L->lo, n = 0;
    for (size_t u = L->lo; u < L->hi; ++u) out[n++] = t->perm[u];
    if (nloc > t->m) nloc = t->m;
    if (nloc <= nin) return nin;
    for (int b = 0; b < t->nleaves; ++b) {
        lk[b].key = b == l ? INFINITY : boxbox_dist2(L, &t->leaves[b]);
        lk[b].idx = (size_t)b;
    }
    qsort(lk, (size_t)t->nleaves, sizeof *lk, cmp_keyed);
    const size_t need = nloc - nin;
    size_t nc = 0;
    double kth = INFINITY;
    for (int b = 0; b < t->nleaves - 1; ++b) {
        if (nc >= need && lk[b].key > kth) break;
        const leaf *B = &t->leaves[lk[b].idx];
        for (size_t u = B->lo; u < B->hi; ++u) {
            size_t i = t->perm[u];
            double x[3] = {coord(t, i, 0), coord(t, i, 1), coord(t, i, 2)};
            cand[nc].key = cm_rbf_box_dist2(x, L->bmin, L->bmax);
            cand[nc].idx = i;
            ++nc;
        }
        if (nc >= need) {
            qsort(cand, nc, sizeof *cand, cmp_keyed);
            nc = need; /* the farther ones can never come back */
            kth = cand[need - 1].key;
        }
    }
    if (nc > need) {
        qsort(cand, nc, sizeof *cand, cmp_keyed);
        nc = need;
    }
    /* nloc is the cap: keep at least nmin in all, beyond that only those within reach */
    size_t keep = nmin > nin ? nmin - nin : 0;
    while (keep < nc && cand[keep].key <= reach2) ++keep;
    if (keep < nc) nc = keep;
    for (size_t u = 0; u < nc; ++u) out[n++] = cand[u].idx;
    return n;
}

/* The thinned far band of leaf l's local set (thin_reach): out holds its n near centres,
 * sorted by distance to the box as cm_rbf_leaves_grow leaves them; appended are picks among all
 * centres farther than those, up to far2 (squared) from the box, by cm_rbf_thin_pick with
 * cells growing from d0 = max(near reach, fill), until cap centres in all. Returns the new
 * count, or 0 out of memory. Scratch: cand (m). */
size_t cm_rbf_leaves_thin(const tree_build *t, int l, size_t n, double far2, double fill,
                          double cell, size_t cap, keyed *cand, size_t *out)
{
    const leaf *L = &t->leaves[l];
    if (n >= cap) return n;
    const size_t last = out[n - 1];
    const double xl[3] = {coord(t, last, 0), coord(t, last, 1), coord(t, last, 2)};
    const double dn2 = n > L->hi - L->lo ? cm_rbf_box_dist2(xl, L->bmin, L->bmax) : 0.0;
    if (dn2 >= far2) return n;
    size_t nc = 0;
    for (int b = 0; b < t->nleaves; ++b) {
        if (b == l || boxbox_dist2(L, &t->leaves[b]) > far2) continue;
        const leaf *B = &t->leaves[b];
        for (size_t u = B->lo; u < B->hi; ++u) {
            size_t i = t->perm[u];
            double x[3] = {coord(t, i, 0), coord(t, i, 1), coord(t, i, 2)};
            double k = cm_rbf_box_dist2(x, L->bmin, L->bmax);
            /* strictly beyond the near set: a tie with its last centre may be lost, never
             * doubled */
            if (k > dn2 && k <= far2) {
                cand[nc].key = k;
                cand[nc].idx = i;
                ++nc;
            }
        }
    }
    qsort(cand, nc, sizeof *cand, cmp_keyed);
    const double d0 = fmax(sqrt(dn2), fill);
    long got = cm_rbf_thin_pick(t->c, t->m, cand, nc, d0, cell, L->bmin, cap - n, out + n);
    return got < 0 ? 0 : n + (size_t)got;
}

/* Farthest-point sampling of nc centres (c: 3 x m SoA), starting at the centre nearest to
 * the centroid; spreads the coarse centres evenly over the whole set, every part included. */
double cm_rbf_farthest_points(const double *c, size_t m, size_t nc, size_t *out, double *d2,
                              int threads)
{
    double g[3] = {0, 0, 0};
    for (int d = 0; d < 3; ++d) {
        for (size_t i = 0; i < m; ++i) g[d] += c[(size_t)d * m + i];
        g[d] /= (double)m;
    }
    for (size_t i = 0; i < m; ++i) {
        double s = 0.0;
        for (int d = 0; d < 3; ++d) s += (c[(size_t)d * m + i] - g[d]) * (c[(size_t)d * m + i] - g[d]);
        d2[i] = -s; /* so that the first pick below is the point nearest the centroid */
    }
    size_t next = 0;
    for (size_t i = 1; i < m; ++i)
        if (d2[i] > d2[next]) next = i;
    for (size_t i = 0; i < m; ++i) d2[i] = INFINITY;
    /* one parallel region per pick: below ~2e5 centres a pick is ~0.1 ms of work, less than
     * a fork and join costs on a loaded machine (bore 20.6k, 2,031 picks: 9.7 s wall in
     * parallel, 0.17 s serial with the coarse factorisation) */
    const int parallel = (double)m > 2e5 && threads > 1;
    double fill2 = 0.0;
    for (size_t k = 0; k < nc; ++k) {
        out[k] = next;
        const double x = c[next], y = c[m + next], z = c[2 * m + next];
        size_t best = 0;
        double bestd = -1.0;
#pragma omp parallel num_threads(threads) if (parallel)
        {
            size_t lb = 0;
            double ld = -1.0;
#pragma omp for schedule(static)
            for (long li = 0; li < (long)m; ++li) {
                size_t i = (size_t)li;
                double dx = c[i] - x, dy = c[m + i] - y, dz = c[2 * m + i] - z;
                double s = dx * dx + dy * dy + dz * dz;
                if (s < d2[i]) d2[i] = s;
                if (d2[i] > ld) {
                    ld = d2[i];
                    lb = i;
                }
            }
#pragma omp critical
            if (ld > bestd || (ld == bestd && lb < best)) {
                bestd = ld;
                best = lb;
            }
        }
        next = best;
        fill2 = bestd;
    }
    return sqrt(fill2);
}
