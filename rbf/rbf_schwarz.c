/* Two-level restricted additive Schwarz preconditioner for the r^3 + linear system (Beatson,
 * Light and Billings, "Fast solution of the radial basis function interpolation equations:
 * domain decomposition methods", SIAM J. Sci. Comput. 22, 2000; restricted variant of Cai
 * and Sarkis). The centres are split into kD-tree leaves; each leaf is grown to local_size
 * centres (the leaf first, then the centres nearest to its box) and the local interpolation
 * problem on that set is solved by the same null-space projected Cholesky as the dense path.
 * Only the leaf's own weights are kept (restricted), so the local inverses are stored as
 * their leaf rows only: G_l = Q2 (Q2' A_l Q2)^{-1} Q2' restricted to local x leaf, which is
 * m * local_size numbers over all leaves instead of sum local_size^2 for the factors, and
 * one application is one small matrix-vector product per leaf. A coarse space of
 * farthest-point centres is solved exactly first (multiplicative), so the local solves see
 * only the residual of the smooth, global part. */
#include "rbf_internal.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#define CM_RBF_COARSE_BASE_M 2e4

struct cm_rbf_schwarz {
    size_t m;
    size_t nmax;      /* largest local set */
    int nsub;
    size_t *sub_ptr;  /* nsub + 1: offsets into sub_idx */
    size_t *sub_idx;  /* centre indices of each local set, its n_in leaf centres first */
    int *n_in;        /* nsub: leaf centres of each local set */
    size_t *g_ptr;    /* nsub + 1: offsets into g32/g64 (local x n_in, col-major) */
    float *g32;       /* local inverse rows, float storage */
    double *g64;      /* or double storage */
    size_t nc;        /* coarse centres */
    size_t *c_idx;    /* nc */
    double *c_xyz;    /* 3 x nc SoA coordinates of the coarse centres */
    double *gc;       /* nc*nc + 8nc: projected Cholesky factor of the coarse system
                       * (projected_factor), solved at every application: forming the
                       * inverse would cost 3x the factorisation */
    int c_rk;
    double c_tau[4];
    int post;         /* 0: coarse then local; 1: coarse, local, coarse; 2: local, coarse */
    double fill;      /* largest distance from a centre to its nearest coarse centre */
    size_t bytes;
};

/* ---- kD-tree leaves ---- */

typedef struct leaf {
    size_t lo, hi;    /* range of perm */
    double bmin[3], bmax[3];
} leaf;

typedef struct tree_build {
    const double *c;  /* 3 x m SoA */
    size_t m;
    size_t *perm;
    leaf *leaves;
    int nleaves, cap;
    size_t leaf_size;
} tree_build;

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

static int split(tree_build *t, size_t lo, size_t hi)
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
    if (split(t, lo, mid) != 0) return -1;
    return split(t, mid, hi);
}

/* Squared distance from point x to box [bmin, bmax]. */
static double box_dist2(const double *x, const double *bmin, const double *bmax)
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

typedef struct keyed {
    double key;
    size_t idx;
} keyed;

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
static size_t grow_leaf(const tree_build *t, int l, size_t nloc, size_t nmin, double reach2,
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
            cand[nc].key = box_dist2(x, L->bmin, L->bmax);
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

/* ---- local projected inverses ---- */

/* g (n x n_in col-major) = Q2 (Q2' A Q2)^{-1} Q2' E, E the first n_in columns of the
 * identity: the weights of the local interpolant of unit data at each leaf centre, which by
 * symmetry are the leaf rows of the local inverse. The linear polynomial is rank-revealed
 * (dgeqp3), since a local set on one planar face is coplanar. work: n*n + 8n doubles.
 * Returns 0, or the failing Cholesky pivot (> 0), or -1 for a LAPACK argument error. */
/* The null-space projected Cholesky factor of the r^3 system on the n centres idx: in work
 * (n*n + 8n doubles) a = Q' A Q with the Cholesky factor of its trailing n - rk block, and
 * pq = the Householder vectors of P's rank-revealing QR (dgeqp3: a local set on one planar
 * face is coplanar), rank in *rk, tau (4). Returns 0, the failing pivot (> 0), or -1. */
static int projected_factor(const double *cg, size_t m, const size_t *idx, size_t n,
                            double *work, int *rk_out, double *tau)
{
    double *a = work, *xyz = a + n * n, *pq = xyz + 3 * n;
    lapack_int jpvt[4] = {0, 0, 0, 0};
    for (int d = 0; d < 3; ++d)
        for (size_t i = 0; i < n; ++i) xyz[(size_t)d * n + i] = cg[(size_t)d * m + idx[i]];
    for (size_t j = 0; j < n; ++j) {
        const double xj = xyz[j], yj = xyz[n + j], zj = xyz[2 * n + j];
        double *col = a + j * n;
        for (size_t i = 0; i < n; ++i) {
            double dx = xyz[i] - xj, dy = xyz[n + i] - yj, dz = xyz[2 * n + i] - zj;
            double r2 = dx * dx + dy * dy + dz * dz;
            col[i] = r2 * sqrt(r2);
        }
    }
    for (size_t i = 0; i < n; ++i) pq[i] = 1.0;
    memcpy(pq + n, xyz, 3 * n * sizeof *pq);
    const lapack_int ln = (lapack_int)n;
    if (LAPACKE_dgeqp3(LAPACK_COL_MAJOR, ln, 4, pq, ln, jpvt, tau) != 0) return -1;
    int rk = 0;
    const double r00 = fabs(pq[0]);
    while (rk < 4 && fabs(pq[(size_t)rk * n + (size_t)rk]) > 1e-9 * r00) ++rk;
    *rk_out = rk;
    if (LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', ln, ln, rk, pq, ln, tau, a, ln) != 0 ||
        LAPACKE_dormqr(LAPACK_COL_MAJOR, 'R', 'N', ln, ln, rk, pq, ln, tau, a, ln) != 0)
        return -1;
    const lapack_int n2 = (lapack_int)(n - (size_t)rk);
    lapack_int info = LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', n2, a + (size_t)rk * n + (size_t)rk, ln);
    return info < 0 ? -1 : (int)info;
}

/* x (n x nrhs col-major, ld n) := Q2 (Q2' A Q2)^{-1} Q2' x with the factor of
 * projected_factor: the weights of the interpolant of data x (linear part annihilated). */
static int projected_solve(const double *work, size_t n, int rk, const double *tau, size_t nrhs,
                           double *x)
{
    const double *a = work, *pq = work + n * n + 3 * n;
    const lapack_int ln = (lapack_int)n, lr = (lapack_int)nrhs;
    if (LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', ln, lr, rk, pq, ln, tau, x, ln) != 0 ||
        LAPACKE_dpotrs(LAPACK_COL_MAJOR, 'L', (lapack_int)(n - (size_t)rk), lr,
                       a + (size_t)rk * n + (size_t)rk, ln, x + rk, ln) != 0)
        return -1;
    for (size_t j = 0; j < nrhs; ++j)
        for (int i = 0; i < rk; ++i) x[j * n + (size_t)i] = 0.0;
    if (LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'N', ln, lr, rk, pq, ln, tau, x, ln) != 0)
        return -1;
    return 0;
}

/* g (n x n_in col-major) = Q2 (Q2' A Q2)^{-1} Q2' E, E the first n_in columns of the
 * identity: the weights of the local interpolant of unit data at each leaf centre, which by
 * symmetry are the leaf rows of the local inverse. work: n*n + 8n doubles.
 * Returns 0, or the failing Cholesky pivot (> 0), or -1 for a LAPACK argument error. */
static int local_inverse(const double *cg, size_t m, const size_t *idx, size_t n, size_t n_in,
                         double *work, double *g)
{
    double tau[4];
    int rk = 0;
    int info = projected_factor(cg, m, idx, n, work, &rk, tau);
    if (info != 0) return info;
    memset(g, 0, n * n_in * sizeof *g);
    for (size_t j = 0; j < n_in; ++j) g[j * n + j] = 1.0;
    return projected_solve(work, n, rk, tau, n_in, g);
}

/* Farthest-point sampling of nc centres (c: 3 x m SoA), starting at the centre nearest to
 * the centroid; spreads the coarse centres evenly over the whole set, every part included. */
static double farthest_points(const double *c, size_t m, size_t nc, size_t *out, double *d2,
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
    const int parallel = (double)m > 2e4 && threads > 1;
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

size_t cm_rbf_coarse_count(const cm_rbf_options *o, size_t m)
{
    size_t nc = (size_t)o->coarse_size;
    /* coarse_grow: coarse_size is the count at 2e4 centres, grown as sqrt(m) above, so that
     * the coarse spacing keeps closer to the fixed-size subdomains' reach (which shrinks as
     * m^-1/2) at O(m) memory for the coarse factor */
    if (o->coarse_grow && (double)m > CM_RBF_COARSE_BASE_M)
        nc = (size_t)((double)nc * sqrt((double)m / CM_RBF_COARSE_BASE_M));
    if (o->coarse_max > 0 && nc > (size_t)o->coarse_max) nc = (size_t)o->coarse_max;
    if (nc > m / 4) nc = m / 4; /* a coarse space as fine as the problem is no coarse space */
    return nc;
}

void cm_rbf_schwarz_destroy(cm_rbf_schwarz **pc)
{
    if (!pc || !*pc) return;
    cm_rbf_schwarz *p = *pc;
    free(p->sub_ptr);
    free(p->sub_idx);
    free(p->n_in);
    free(p->g_ptr);
    free(p->g32);
    free(p->g64);
    free(p->c_idx);
    free(p->c_xyz);
    free(p->gc);
    free(p);
    *pc = NULL;
}

size_t cm_rbf_schwarz_bytes(const cm_rbf_schwarz *pc) { return pc ? pc->bytes : 0; }
int cm_rbf_schwarz_subdomains(const cm_rbf_schwarz *pc) { return pc ? pc->nsub : 0; }
int cm_rbf_schwarz_coarse(const cm_rbf_schwarz *pc) { return pc ? (int)pc->nc : 0; }

static cm_status build_subdomains(cm_context *ctx, const cm_rbf *r, cm_rbf_schwarz *p,
                                  int threads)
{
    const size_t m = r->m;
    const cm_rbf_options *o = &r->opt;
    tree_build t = {r->c, m, malloc(m * sizeof(size_t)), NULL, 0, 0, (size_t)o->leaf_size};
    if (!t.perm) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (kD-tree)");
    for (size_t i = 0; i < m; ++i) t.perm[i] = i;
    cm_status st = CM_OK;
    if (split(&t, 0, m) != 0) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (kD-tree)");
        goto done;
    }
    size_t nloc = (size_t)o->local_size < m ? (size_t)o->local_size : m;
    const size_t nmin = nloc;
    double reach2 = -1.0;
    if (o->overlap > 0.0 && p->fill > 0.0 && o->local_max > o->local_size) {
        nloc = (size_t)o->local_max < m ? (size_t)o->local_max : m;
        reach2 = (o->overlap * p->fill) * (o->overlap * p->fill);
    }
    p->nsub = t.nleaves;
    p->sub_ptr = malloc(((size_t)t.nleaves + 1) * sizeof *p->sub_ptr);
    p->n_in = malloc((size_t)t.nleaves * sizeof *p->n_in);
    const size_t stride = nloc > t.leaf_size ? nloc : t.leaf_size; /* compacted below */
    p->sub_idx = malloc((size_t)t.nleaves * stride * sizeof *p->sub_idx);
    if (!p->sub_ptr || !p->n_in || !p->sub_idx) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (subdomains)");
        goto done;
    }
    size_t *cnt = calloc((size_t)t.nleaves, sizeof *cnt);
    int fail = 0;
#pragma omp parallel num_threads(threads) if (t.nleaves > 8 && threads > 1)
    {
        keyed *lk = malloc((size_t)t.nleaves * sizeof *lk);
        keyed *cand = malloc(m * sizeof *cand);
#pragma omp for schedule(dynamic, 4)
        for (int l = 0; l < t.nleaves; ++l) {
            if (!lk || !cand || !cnt) {
#pragma omp atomic write
                fail = 1;
                continue;
            }
            cnt[l] = grow_leaf(&t, l, nloc, nmin, reach2, lk, cand,
                               p->sub_idx + (size_t)l * stride);
        }
        free(lk);
        free(cand);
    }
    if (fail) {
        free(cnt);
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (subdomains)");
        goto done;
    }
    p->sub_ptr[0] = 0;
    for (int l = 0; l < t.nleaves; ++l) {
        memmove(p->sub_idx + p->sub_ptr[l], p->sub_idx + (size_t)l * stride,
                cnt[l] * sizeof *p->sub_idx);
        p->sub_ptr[l + 1] = p->sub_ptr[l] + cnt[l];
        p->n_in[l] = (int)(t.leaves[l].hi - t.leaves[l].lo);
    }
    free(cnt);
done:
    free(t.perm);
    free(t.leaves);
    return st;
}

static cm_status build_local(cm_context *ctx, const cm_rbf *r, cm_rbf_schwarz *p, int threads)
{
    const size_t m = r->m;
    p->g_ptr = malloc(((size_t)p->nsub + 1) * sizeof *p->g_ptr);
    if (!p->g_ptr) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    size_t nmax = 0, inmax = 0;
    p->g_ptr[0] = 0;
    for (int l = 0; l < p->nsub; ++l) {
        size_t n = p->sub_ptr[l + 1] - p->sub_ptr[l];
        p->g_ptr[l + 1] = p->g_ptr[l] + n * (size_t)p->n_in[l];
        if (n > nmax) nmax = n;
        if ((size_t)p->n_in[l] > inmax) inmax = (size_t)p->n_in[l];
    }
    const size_t total = p->g_ptr[p->nsub];
    p->nmax = nmax;
    if (r->opt.local_float) p->g32 = malloc(total * sizeof *p->g32);
    else p->g64 = malloc(total * sizeof *p->g64);
    if (!p->g32 && !p->g64)
        return cm_error(ctx, CM_ERR_NOMEM,
                        "cm_rbf_create: out of memory for the local solves (%.3g GB)",
                        (double)total * (r->opt.local_float ? 4.0 : 8.0) / 1e9);
    p->bytes += total * (r->opt.local_float ? 4 : 8);
    /* one subdomain per thread with single-threaded BLAS: the local problems are too small
     * for threaded LAPACK to pay off */
    const int saved = openblas_get_num_threads();
    openblas_set_num_threads(1);
    int bad = 0, bad_info = 0, done = 0;
#pragma omp parallel num_threads(threads) if (threads > 1)
    {
        double *work = malloc((nmax * nmax + 8 * nmax) * sizeof *work);
        double *g = malloc(nmax * inmax * sizeof *g);
#pragma omp for schedule(dynamic, 1)
        for (int l = 0; l < p->nsub; ++l) {
            if (!work || !g) {
#pragma omp atomic write
                bad = -1;
                continue;
            }
            size_t n = p->sub_ptr[l + 1] - p->sub_ptr[l], nin = (size_t)p->n_in[l];
            int info = local_inverse(r->c, m, p->sub_idx + p->sub_ptr[l], n, nin, work, g);
            if (info != 0) {
#pragma omp critical
                {
                    bad = l + 1;
                    bad_info = info;
                }
                continue;
            }
            size_t off = p->g_ptr[l];
            if (p->g32)
                for (size_t i = 0; i < n * nin; ++i) p->g32[off + i] = (float)g[i];
            else
                memcpy(p->g64 + off, g, n * nin * sizeof *g);
            int d;
#pragma omp atomic capture
            d = ++done;
#ifdef _OPENMP
            if (omp_get_thread_num() == 0) /* the caller's thread: callbacks need not be reentrant */
#endif
                cm_progress(ctx, "rbf local solves", (double)d, (double)p->nsub);
        }
        free(work);
        free(g);
    }
    openblas_set_num_threads(saved);
    if (bad < 0) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (local solves)");
    if (bad > 0)
        return cm_error(ctx, CM_ERR_NUMERIC,
                        "cm_rbf_create: the local r^3 system of subdomain %d (%zu centres) "
                        "failed (LAPACK info %d): near-duplicate centres?",
                        bad - 1, p->sub_ptr[bad] - p->sub_ptr[bad - 1], bad_info);
    return CM_OK;
}

static cm_status build_coarse(cm_context *ctx, const cm_rbf *r, cm_rbf_schwarz *p, int threads)
{
    const size_t m = r->m;
    size_t nc = cm_rbf_coarse_count(&r->opt, m); /* a coarse space as fine as the problem is no coarse space */
    if (nc < 16) return CM_OK;
    p->nc = nc;
    p->c_idx = malloc(nc * sizeof *p->c_idx);
    p->c_xyz = malloc(3 * nc * sizeof *p->c_xyz);
    p->gc = malloc((nc * nc + 8 * nc) * sizeof *p->gc);
    double *d2 = malloc(m * sizeof *d2);
    cm_status st = CM_OK;
    if (!p->c_idx || !p->c_xyz || !p->gc || !d2) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (coarse space)");
        goto done;
    }
    p->bytes += nc * nc * 8 + nc * 32;
    p->fill = farthest_points(r->c, m, nc, p->c_idx, d2, threads);
    for (int d = 0; d < 3; ++d)
        for (size_t a = 0; a < nc; ++a) p->c_xyz[(size_t)d * nc + a] = r->c[(size_t)d * m + p->c_idx[a]];
    const int saved = openblas_get_num_threads();
    openblas_set_num_threads(threads);
    int info = projected_factor(r->c, m, p->c_idx, nc, p->gc, &p->c_rk, p->c_tau);
    openblas_set_num_threads(saved);
    if (info != 0)
        st = cm_error(ctx, CM_ERR_NUMERIC,
                      "cm_rbf_create: the coarse r^3 system (%zu centres) failed (LAPACK "
                      "info %d)",
                      nc, info);
done:
    free(d2);
    return st;
}

cm_status cm_rbf_schwarz_create(cm_context *ctx, const cm_rbf *r, int threads,
                                cm_rbf_schwarz **pc)
{
    *pc = NULL;
    cm_rbf_schwarz *p = calloc(1, sizeof *p);
    if (!p) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    p->m = r->m;
    p->post = r->opt.coarse_post;
    /* the coarse space first: its fill distance sets the overlap when measured in distance */
    double t0 = cm_wtime();
    cm_status st = build_coarse(ctx, r, p, threads);
    double t1 = cm_wtime();
    if (st == CM_OK) st = build_subdomains(ctx, r, p, threads);
    double t2 = cm_wtime();
    if (st == CM_OK) st = build_local(ctx, r, p, threads);
    double t3 = cm_wtime();
    if (st != CM_OK) {
        cm_rbf_schwarz_destroy(&p);
        return st;
    }
    p->bytes += p->sub_ptr[p->nsub] * sizeof *p->sub_idx + (size_t)p->nsub * 24;
    cm_log(ctx, CM_LOG_DEBUG,
           "cm_rbf_create: Schwarz: %d subdomains of <= %zu centres (mean %.0f, leaves <= %d), "
           "coarse %zu (fill distance %.3g); coarse %.3f s, tree + overlap %.3f s, local %.3f "
           "s, %.1f MB",
           p->nsub, p->nmax, (double)p->sub_ptr[p->nsub] / (double)p->nsub, r->opt.leaf_size,
           p->nc, p->fill, t1 - t0, t2 - t1, t3 - t2, (double)p->bytes / 1e6);
    *pc = p;
    return CM_OK;
}

void cm_rbf_schwarz_apply(const cm_rbf_schwarz *p, const cm_rbf *r, int nc, const double *in,
                          double *out, int threads)
{
    const size_t m = r->m, ncs = p->nc;
    memset(out, 0, (size_t)nc * m * sizeof *out);
    const double *res = in;
    double *r1 = NULL, *rc = NULL, *ac = NULL;
    if (ncs > 0 && p->post == 2) { /* local solves first, coarse after them only */
        rc = calloc(2 * ncs * (size_t)nc, sizeof *rc);
        r1 = rc; /* marks the coarse correction below as possible */
    } else if (ncs > 0) {
        rc = calloc(2 * ncs * (size_t)nc, sizeof *rc);
        ac = malloc(m * (size_t)nc * sizeof *ac);
        r1 = malloc(m * (size_t)nc * sizeof *r1);
        if (!rc || !ac || !r1) { /* no coarse correction: still a valid preconditioner */
            free(rc), free(ac), free(r1);
            r1 = rc = ac = NULL;
        } else {
            double *wc = rc + ncs * (size_t)nc;
            for (int c = 0; c < nc; ++c)
                for (size_t a = 0; a < ncs; ++a) rc[(size_t)c * ncs + a] = in[(size_t)c * m + p->c_idx[a]];
            memcpy(wc, rc, ncs * (size_t)nc * sizeof *wc);
            projected_solve(p->gc, ncs, p->c_rk, p->c_tau, (size_t)nc, wc);
            for (int c = 0; c < nc; ++c)
                for (size_t a = 0; a < ncs; ++a) out[(size_t)c * m + p->c_idx[a]] = wc[(size_t)c * ncs + a];
            /* the local solves see the residual of the coarse interpolant; its polynomial
             * part is left in, as the local solves annihilate linear functions exactly */
            cm_rbf_kernel_sum(r->kernel, 3, ncs, p->c_xyz, wc, nc, m, r->c, m, ac, (size_t)nc,
                              threads);
            for (int c = 0; c < nc; ++c)
                for (size_t i = 0; i < m; ++i)
                    r1[(size_t)c * m + i] = in[(size_t)c * m + i] - ac[i * (size_t)nc + (size_t)c];
            res = r1;
        }
    }
    /* leaves are disjoint, so the scatter into out needs no synchronisation */
#pragma omp parallel num_threads(threads) if (threads > 1 && p->nsub > 1)
    {
        double *loc = malloc(p->nmax * (size_t)nc * sizeof *loc);
#pragma omp for schedule(dynamic, 4)
        for (int l = 0; l < p->nsub; ++l) {
            const size_t *idx = p->sub_idx + p->sub_ptr[l];
            const size_t n = p->sub_ptr[l + 1] - p->sub_ptr[l], nin = (size_t)p->n_in[l];
            double *x = loc;
            if (!x) continue; /* out of memory: a weaker preconditioner, not a wrong result */
            for (int c = 0; c < nc; ++c)
                for (size_t i = 0; i < n; ++i) x[(size_t)c * n + i] = res[(size_t)c * m + idx[i]];
            for (size_t j = 0; j < nin; ++j) {
                for (int c = 0; c < nc; ++c) {
                    const double *xc = x + (size_t)c * n;
                    double acc = 0.0;
                    if (p->g32) {
                        const float *g = p->g32 + p->g_ptr[l] + j * n;
                        for (size_t i = 0; i < n; ++i) acc += (double)g[i] * xc[i];
                    } else {
                        const double *g = p->g64 + p->g_ptr[l] + j * n;
                        for (size_t i = 0; i < n; ++i) acc += g[i] * xc[i];
                    }
                    out[(size_t)c * m + idx[j]] += acc;
                }
            }
        }
        free(loc);
    }
    /* multiplicative coarse correction after the local solves: out += G_c (in - A out) at
     * the coarse centres, so the coarse residual of the whole correction is zero */
    if (r1 && p->post) {
        double *wc = rc + ncs * (size_t)nc;
        double *aout = malloc(ncs * (size_t)nc * sizeof *aout);
        if (aout) {
            cm_rbf_kernel_sum(r->kernel, 3, m, r->c, out, nc, ncs, p->c_xyz, ncs, aout,
                              (size_t)nc, threads);
            for (int c = 0; c < nc; ++c)
                for (size_t a = 0; a < ncs; ++a)
                    rc[(size_t)c * ncs + a] = in[(size_t)c * m + p->c_idx[a]] -
                                              aout[a * (size_t)nc + (size_t)c];
            memcpy(wc, rc, ncs * (size_t)nc * sizeof *wc);
            projected_solve(p->gc, ncs, p->c_rk, p->c_tau, (size_t)nc, wc);
            for (int c = 0; c < nc; ++c)
                for (size_t a = 0; a < ncs; ++a)
                    out[(size_t)c * m + p->c_idx[a]] += wc[(size_t)c * ncs + a];
            free(aout);
        }
    }
    if (r1 != rc) free(r1);
    free(rc);
    free(ac);
}
