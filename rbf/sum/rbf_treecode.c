/* Fast r^3 kernel sums: a barycentric Lagrange treecode (Wang, Tlupova & Krasny, "A
 * kernel-independent treecode based on barycentric Lagrange interpolation", 2020), with
 * targets in batches and an exact upward pass.
 *
 * Sources (the centres) sit in a kD tree (midpoint split of the longest side). A cluster
 * with more than P = (n+1)^3 centres carries n+1 Chebyshev points of the second kind per
 * axis on its box and, per sum, the proxy weights W_k = sum_{j in C} L_k(c_j) w_j (L_k the
 * tensor Lagrange basis): then sum_{j in C} w_j phi(|x - c_j|) ~ sum_k W_k phi(|x - y_k|),
 * exact for the degree-n tensor interpolant of phi(|x - .|) over the box. A batch of
 * targets (a leaf of a kD tree of the targets) takes a cluster's proxies when the cluster's
 * half-diagonal r_c and the distance D between the centres of batch and cluster satisfy
 * r_c / (D - r_b) <= theta (r_b: the batch's half-diagonal), and otherwise opens it, down to
 * direct sums with the leaves' centres. Every product then is a plain r^3 kernel sum, over
 * proxies or centres, with the targets of the batch in registers: on AVX-512 the direct
 * sums' hand-written block (rbf_sum_avx512.c, 1.2-1.4x the compiled loop at fast_tol
 * 1e-9..1e-12), elsewhere the compiled loops below.
 *
 * Why the upward pass is exact: a parent's proxy weights are computed from its children's
 * (W^P_K = sum_k L^P_K(y_k) W_k), and a child's interpolation reproduces every tensor
 * polynomial of degree n, among them the parent's L^P_K; so the result is the same as from
 * the centres, at (n+1)^4 instead of (n+1)^3 x |C| operations.
 *
 * Error bound. phi(|x - y|) = |x - y|^3, as a function of y on a box seen from x at ratio
 * rho = r_c / dist(x, box centre) < 1, continues analytically into a Bernstein ellipse
 * whose parameter grows as rho falls (its singularities are where |x - y|^2 = 0, as for 1/r),
 * so its Chebyshev interpolation errs by at most C(n) rho^(n+1) phi(dist) per unit weight
 * (the 1/r treecodes' bound times the growth of r^3 over the box). Summed over clusters:
 *     |fast_i - exact_i| <= C theta^(n+1) sum_j |w_j| phi_ij   (+ rounding, eps of the same).
 * The constant is measured: cm_rbf_tree_params' table is the (n, theta) that kept
 * max_i |err_i| / sum_j |w_j| phi_ij below tol on random weights (tests/rbf/
 * test_rbf_treecode.c checks it). The bound is relative to sum |w| phi, not to the result:
 * RBF weights cancel (sum |w| phi is up to 1e6..1e7 x the result on thin-walled parts), and
 * the loss is that factor. Hence the solver refines on exact residuals, and evaluation
 * checks the estimate (cm_rbf_tree_check) before it trusts a fast sum. */
#include "rbf_treecode.h"

#include "rbf_internal.h"
#include "rbf_sum_isa.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define CM_TREE_MAXN 14
#define CM_TREE_LEAF 160  /* centres per source leaf */
#define CM_TREE_BATCH 192 /* targets per batch */
#define NB 16             /* targets held in registers */
#define FB_J 128          /* more than 4 columns: entries of this many sources x NB kept */

typedef struct tnode {
    size_t begin, end;  /* range in tree order */
    int child[2];       /* -1: leaf */
    int proxy;          /* index of the proxy grid, -1: too few centres for one */
    int depth;
    double mid[3], half[3]; /* interpolation box (tight box, padded where flat) */
    double rad;             /* half-diagonal of the tight box */
} tnode;

typedef struct order {
    size_t *perm;  /* tree position -> input index */
    tnode *node;
    int nnode;
    int *leaf;     /* leaves (the batches, for targets) */
    int nleaf;
    int maxdepth;
} order;

struct cm_rbf_tree {
    size_t m;
    const double *c;
    int n, P;       /* order, (n+1)^3 */
    double theta;
    order src, self;
    double *xs;     /* 3 x m SoA: centres in tree order */
    int nprox;
    int *prox_node; /* proxy -> node */
    double *pxyz;   /* 3 x (nprox P) SoA: proxy points */
    double cheb[CM_TREE_MAXN + 1], bw[CM_TREE_MAXN + 1];
    int *depth_start; /* proxies sorted by depth: [depth_start[d], depth_start[d + 1]) */
    cm_rbf_isa isa;   /* code of the downward products (AUTO unless a test names one) */
    int comp;         /* 0 plain; 1 compensated products; 2 also double-double proxy weights */
};

/* (n, theta) measured to keep max_i err_i / sum_j |w_j| phi_ij below tol, with a margin of
 * 3..30, on random and on real weights (bench_rbf_treecode on bore 22.6k and bracket 59.4k,
 * RESULTS.md, RBF solvers): at theta 0.5 the error fell from 5e-6 (n = 3) to 2.5e-12
 * (n = 10), about 0.9 decades per order; real weights err up to 8x more relative to
 * sum |w| phi than random ones at the same point, hence the margin. Below 1e-14 rounding
 * (about 3e-16 x sum |w| phi) is the floor. */
void cm_rbf_tree_params(double tol, int *order, double *theta)
{
    static const struct { double tol; int n; double theta; } table[] = {
        {1e-3, 3, 0.5}, {1e-4, 4, 0.5}, {1e-5, 4, 0.5}, {1e-6, 5, 0.5}, {1e-7, 6, 0.5},
        {1e-8, 7, 0.45}, {1e-9, 8, 0.45}, {1e-10, 9, 0.45}, {1e-11, 10, 0.4},
        {1e-12, 11, 0.4}, {1e-13, 12, 0.4}, {1e-14, 13, 0.35}};
    const int nt = (int)(sizeof table / sizeof table[0]);
    int i = 0;
    while (i < nt - 1 && table[i].tol > tol) ++i;
    *order = table[i].n;
    *theta = table[i].theta;
}

/* ---- tree construction ---- */

static void tight_box(const double *p, size_t ld, const size_t *perm, size_t b, size_t e,
                      double lo[3], double hi[3])
{
    for (int d = 0; d < 3; ++d) lo[d] = INFINITY, hi[d] = -INFINITY;
    for (size_t i = b; i < e; ++i)
        for (int d = 0; d < 3; ++d) {
            double v = p[(size_t)d * ld + perm[i]];
            lo[d] = fmin(lo[d], v);
            hi[d] = fmax(hi[d], v);
        }
}

static const double *g_sort_p; /* only for the rare median split (qsort has no context) */
static int cmp_coord(const void *a, const void *b)
{
    double x = g_sort_p[*(const size_t *)a], y = g_sort_p[*(const size_t *)b];
    return (x > y) - (x < y);
}

/* kD ordering of n points (3 x n SoA, stride ld) with leaves of at most leaf points, nodes
 * in breadth-first order (so by depth). 0, or -1 on allocation failure. */
static int build_order(size_t n, const double *p, size_t ld, size_t leaf, order *o)
{
    memset(o, 0, sizeof *o);
    o->perm = malloc((n ? n : 1) * sizeof *o->perm);
    int cap = 64;
    o->node = malloc((size_t)cap * sizeof *o->node);
    if (!o->perm || !o->node) return -1;
    for (size_t i = 0; i < n; ++i) o->perm[i] = i;
    o->node[0] = (tnode){.begin = 0, .end = n, .child = {-1, -1}, .proxy = -1, .depth = 0};
    o->nnode = 1;
    for (int q = 0; q < o->nnode; ++q) {
        tnode *t = &o->node[q];
        double lo[3], hi[3];
        tight_box(p, ld, o->perm, t->begin, t->end, lo, hi);
        double r2 = 0.0, ext = 0.0;
        int dim = 0;
        for (int d = 0; d < 3; ++d) {
            double e = hi[d] - lo[d];
            if (!(e >= 0.0)) e = 0.0, lo[d] = hi[d] = 0.0; /* empty range */
            t->mid[d] = 0.5 * (lo[d] + hi[d]);
            t->half[d] = 0.5 * e;
            r2 += 0.25 * e * e;
            if (e > ext) ext = e, dim = d;
        }
        t->rad = sqrt(r2);
        /* flat clusters (a planar face) get a thin box: the interpolation needs a width */
        for (int d = 0; d < 3; ++d) t->half[d] = fmax(t->half[d], 1e-3 * 0.5 * ext + 1e-300);
        if (t->depth > o->maxdepth) o->maxdepth = t->depth;
        const size_t cnt = t->end - t->begin;
        if (cnt <= leaf || ext == 0.0) continue;
        const double cut = t->mid[dim], *pd = p + (size_t)dim * ld;
        size_t i = t->begin, j = t->end;
        while (i < j) {
            if (pd[o->perm[i]] < cut) ++i;
            else {
                --j;
                size_t s = o->perm[i];
                o->perm[i] = o->perm[j];
                o->perm[j] = s;
            }
        }
        if (i == t->begin || i == t->end) { /* cannot happen for ext > 0, kept for safety */
            g_sort_p = pd;
            qsort(o->perm + t->begin, cnt, sizeof *o->perm, cmp_coord);
            i = t->begin + cnt / 2;
        }
        if (o->nnode + 2 > cap) {
            cap *= 2;
            tnode *nn = realloc(o->node, (size_t)cap * sizeof *nn);
            if (!nn) return -1;
            o->node = nn;
            t = &o->node[q];
        }
        size_t b = t->begin, e = t->end;
        int dp = t->depth + 1;
        t->child[0] = o->nnode;
        t->child[1] = o->nnode + 1;
        o->node[o->nnode++] = (tnode){.begin = b, .end = i, .child = {-1, -1}, .proxy = -1, .depth = dp};
        o->node[o->nnode++] = (tnode){.begin = i, .end = e, .child = {-1, -1}, .proxy = -1, .depth = dp};
    }
    o->leaf = malloc((size_t)o->nnode * sizeof *o->leaf);
    if (!o->leaf) return -1;
    for (int q = 0; q < o->nnode; ++q)
        if (o->node[q].child[0] < 0) o->leaf[o->nleaf++] = q;
    return 0;
}

static void free_order(order *o)
{
    free(o->perm);
    free(o->node);
    free(o->leaf);
    memset(o, 0, sizeof *o);
}

void cm_rbf_tree_destroy(cm_rbf_tree **t)
{
    if (!t || !*t) return;
    free_order(&(*t)->src);
    free_order(&(*t)->self);
    free((*t)->xs);
    free((*t)->prox_node);
    free((*t)->pxyz);
    free((*t)->depth_start);
    free(*t);
    *t = NULL;
}

cm_rbf_tree *cm_rbf_tree_create(size_t m, const double *c, int n, double theta)
{
    if (n < 2) n = 2;
    if (n > CM_TREE_MAXN) n = CM_TREE_MAXN;
    cm_rbf_tree *t = calloc(1, sizeof *t);
    if (!t) return NULL;
    t->m = m;
    t->c = c;
    t->n = n;
    t->P = (n + 1) * (n + 1) * (n + 1);
    t->theta = theta;
    for (int k = 0; k <= n; ++k) {
        t->cheb[k] = cos(3.14159265358979323846 * k / n);
        t->bw[k] = (k % 2 ? -1.0 : 1.0) * (k == 0 || k == n ? 0.5 : 1.0);
    }
    if (build_order(m, c, m, CM_TREE_LEAF, &t->src) || build_order(m, c, m, CM_TREE_BATCH, &t->self))
        goto fail;
    t->xs = malloc(3 * (m ? m : 1) * sizeof *t->xs);
    if (!t->xs) goto fail;
    for (int d = 0; d < 3; ++d)
        for (size_t i = 0; i < m; ++i) t->xs[(size_t)d * m + i] = c[(size_t)d * m + t->src.perm[i]];
    for (int q = 0; q < t->src.nnode; ++q)
        if (t->src.node[q].end - t->src.node[q].begin > (size_t)t->P) t->src.node[q].proxy = t->nprox++;
    const size_t P = (size_t)t->P, np = (size_t)t->nprox;
    t->prox_node = malloc((np ? np : 1) * sizeof *t->prox_node);
    t->pxyz = malloc(3 * (np ? np : 1) * P * sizeof *t->pxyz);
    t->depth_start = calloc((size_t)t->src.maxdepth + 2, sizeof *t->depth_start);
    if (!t->prox_node || !t->pxyz || !t->depth_start) goto fail;
    const int n1 = n + 1;
    for (int q = 0; q < t->src.nnode; ++q) {
        const tnode *u = &t->src.node[q];
        if (u->proxy < 0) continue;
        t->prox_node[u->proxy] = q;
        ++t->depth_start[u->depth + 1];
        double *px = t->pxyz + (size_t)u->proxy * P, *py = px + np * P, *pz = py + np * P;
        for (int a = 0; a < n1; ++a)
            for (int b = 0; b < n1; ++b)
                for (int g = 0; g < n1; ++g) {
                    size_t k = (size_t)((a * n1 + b) * n1 + g);
                    px[k] = u->mid[0] + u->half[0] * t->cheb[a];
                    py[k] = u->mid[1] + u->half[1] * t->cheb[b];
                    pz[k] = u->mid[2] + u->half[2] * t->cheb[g];
                }
    }
    /* proxies were numbered in breadth-first order, so by depth */
    for (int d = 0; d <= t->src.maxdepth; ++d) t->depth_start[d + 1] += t->depth_start[d];
    return t;
fail:
    cm_rbf_tree_destroy(&t);
    return NULL;
}

size_t cm_rbf_tree_bytes(const cm_rbf_tree *t)
{
    if (!t) return 0;
    return (size_t)(t->src.nnode + t->self.nnode) * (sizeof(tnode) + sizeof(int)) +
           2 * t->m * sizeof(size_t) + 3 * t->m * sizeof(double) +
           (size_t)t->nprox * ((size_t)t->P * 3 * sizeof(double) + sizeof(int));
}

/* ---- upward pass: proxy weights ---- */

/* l[k] = L_k(u) for the n+1 Chebyshev points on [-1, 1], barycentric (second form) */
static void lagrange(const cm_rbf_tree *t, double u, double *l)
{
    const int n = t->n;
    double s = 0.0;
    for (int k = 0; k <= n; ++k) {
        double d = u - t->cheb[k];
        if (d == 0.0) {
            for (int i = 0; i <= n; ++i) l[i] = i == k ? 1.0 : 0.0;
            return;
        }
        l[k] = t->bw[k] / d;
        s += l[k];
    }
    for (int k = 0; k <= n; ++k) l[k] /= s;
}

/* The Lagrange basis of node u at tree position j: lx along x, lyz[b n1 + g] = L_b(y) L_g(z) */
static void point_basis(const cm_rbf_tree *t, const tnode *u, size_t j, double *lx, double *lyz)
{
    const int n1 = t->n + 1;
    const size_t m = t->m;
    double ly[CM_TREE_MAXN + 1], lz[CM_TREE_MAXN + 1];
    lagrange(t, (t->xs[j] - u->mid[0]) / u->half[0], lx);
    lagrange(t, (t->xs[m + j] - u->mid[1]) / u->half[1], ly);
    lagrange(t, (t->xs[2 * m + j] - u->mid[2]) / u->half[2], lz);
    for (int bb = 0; bb < n1; ++bb)
        for (int g = 0; g < n1; ++g) lyz[bb * n1 + g] = ly[bb] * lz[g];
}

/* W (nc x P, stride ldW) += the weights ws (stride m) of tree positions [b, e) */
static void p2m(const cm_rbf_tree *t, const tnode *u, const double *ws, int nc, size_t b,
                size_t e, double *W, size_t ldW)
{
    const int n1 = t->n + 1;
    const size_t m = t->m;
    double lx[CM_TREE_MAXN + 1], lyz[(CM_TREE_MAXN + 1) * (CM_TREE_MAXN + 1)];
    for (size_t j = b; j < e; ++j) {
        point_basis(t, u, j, lx, lyz);
        for (int q = 0; q < nc; ++q) {
            const double wq = ws[(size_t)q * m + j];
            double *Wq = W + (size_t)q * ldW;
            for (int a = 0; a < n1; ++a) {
                const double f = wq * lx[a];
                double *row = Wq + (size_t)a * (size_t)(n1 * n1);
                for (int k = 0; k < n1 * n1; ++k) row[k] += f * lyz[k];
            }
        }
    }
}

/* parent grid W (stride ldW) += child's grid Wc interpolated: three 1D contractions */
static void m2m(const cm_rbf_tree *t, const tnode *par, const tnode *ch, const double *Wc,
                int nc, double *W, size_t ldW)
{
    const int n1 = t->n + 1;
    double L[3][(CM_TREE_MAXN + 1) * (CM_TREE_MAXN + 1)]; /* L[d][A * n1 + a] */
    double l[CM_TREE_MAXN + 1];
    for (int d = 0; d < 3; ++d)
        for (int a = 0; a < n1; ++a) {
            double x = ch->mid[d] + ch->half[d] * t->cheb[a];
            lagrange(t, (x - par->mid[d]) / par->half[d], l);
            for (int A = 0; A < n1; ++A) L[d][A * n1 + a] = l[A];
        }
    const int P = t->P;
    double *t1 = malloc(2 * (size_t)P * sizeof *t1);
    if (!t1) return; /* never with P <= 3375; the caller's sizes are fixed */
    double *t2 = t1 + P;
    for (int q = 0; q < nc; ++q) {
        const double *w = Wc + (size_t)q * ldW;
        /* t1[A][b][g] = sum_a Lx[A][a] w[a][b][g] */
        memset(t1, 0, (size_t)P * sizeof *t1);
        for (int A = 0; A < n1; ++A)
            for (int a = 0; a < n1; ++a) {
                const double f = L[0][A * n1 + a];
                for (int k = 0; k < n1 * n1; ++k) t1[A * n1 * n1 + k] += f * w[a * n1 * n1 + k];
            }
        /* t2[A][B][g] = sum_b Ly[B][b] t1[A][b][g] */
        memset(t2, 0, (size_t)P * sizeof *t2);
        for (int A = 0; A < n1; ++A)
            for (int B = 0; B < n1; ++B)
                for (int b = 0; b < n1; ++b) {
                    const double f = L[1][B * n1 + b];
                    const double *src = t1 + (A * n1 + b) * n1;
                    double *dst = t2 + (A * n1 + B) * n1;
                    for (int g = 0; g < n1; ++g) dst[g] += f * src[g];
                }
        /* W[A][B][G] += sum_g Lz[G][g] t2[A][B][g] */
        double *Wq = W + (size_t)q * ldW;
        for (int AB = 0; AB < n1 * n1; ++AB)
            for (int G = 0; G < n1; ++G) {
                double s = 0.0;
                for (int g = 0; g < n1; ++g) s += L[2][G * n1 + g] * t2[AB * n1 + g];
                Wq[AB * n1 + G] += s;
            }
    }
    free(t1);
}

/* ---- double-double proxy weights (cm_rbf_tree_set_compensated level 2) ----
 * The plain upward pass rounds every accumulation: W_k errs by about eps sum_j |L_k(c_j)
 * w_j|, i.e. eps x sum |w| over the cluster, where the weights cancel to a much smaller
 * W_k. Here every accumulation is a TwoSum into (hi, lo); the products are rounded once
 * (a relative eps per term, which does not accumulate). No contraction in these: TwoSum
 * needs every rounding where it is written (this file is built with -ffp-contract=fast). */
#define CM_DD __attribute__((optimize("fp-contract=off")))

/* (*h, *l) += a * (bh + bl) */
CM_DD static inline void dd_madd(double *h, double *l, double a, double bh, double bl)
{
    const double p = a * bh, pe = fma(a, bh, -p);
    const double s = *h + p, bv = s - *h;
    const double e = (*h - (s - bv)) + (p - bv);
    *h = s;
    *l += e + pe + a * bl;
}

CM_DD static void p2m_dd(const cm_rbf_tree *t, const tnode *u, const double *ws, int nc,
                         size_t b, size_t e, double *W, double *Wl, size_t ldW)
{
    const int n1 = t->n + 1;
    const size_t m = t->m;
    double lx[CM_TREE_MAXN + 1], lyz[(CM_TREE_MAXN + 1) * (CM_TREE_MAXN + 1)];
    for (size_t j = b; j < e; ++j) {
        point_basis(t, u, j, lx, lyz);
        for (int q = 0; q < nc; ++q) {
            const double wq = ws[(size_t)q * m + j];
            double *Wq = W + (size_t)q * ldW, *Lq = Wl + (size_t)q * ldW;
            for (int a = 0; a < n1; ++a) {
                const double f = wq * lx[a];
                const size_t o = (size_t)a * (size_t)(n1 * n1);
                for (int k = 0; k < n1 * n1; ++k) dd_madd(Wq + o + k, Lq + o + k, f, lyz[k], 0.0);
            }
        }
    }
}

CM_DD static void m2m_dd(const cm_rbf_tree *t, const tnode *par, const tnode *ch,
                         const double *Wc, const double *Wcl, int nc, double *W, double *Wl,
                         size_t ldW)
{
    const int n1 = t->n + 1, P = t->P;
    double L[3][(CM_TREE_MAXN + 1) * (CM_TREE_MAXN + 1)];
    double l[CM_TREE_MAXN + 1];
    for (int d = 0; d < 3; ++d)
        for (int a = 0; a < n1; ++a) {
            double x = ch->mid[d] + ch->half[d] * t->cheb[a];
            lagrange(t, (x - par->mid[d]) / par->half[d], l);
            for (int A = 0; A < n1; ++A) L[d][A * n1 + a] = l[A];
        }
    double *t1 = malloc(4 * (size_t)P * sizeof *t1);
    if (!t1) return; /* never with P <= 3375 */
    double *t1l = t1 + P, *t2 = t1l + P, *t2l = t2 + P;
    for (int q = 0; q < nc; ++q) {
        const double *w = Wc + (size_t)q * ldW, *wl = Wcl + (size_t)q * ldW;
        memset(t1, 0, 4 * (size_t)P * sizeof *t1);
        for (int A = 0; A < n1; ++A)
            for (int a = 0; a < n1; ++a)
                for (int k = 0; k < n1 * n1; ++k)
                    dd_madd(t1 + A * n1 * n1 + k, t1l + A * n1 * n1 + k, L[0][A * n1 + a],
                            w[a * n1 * n1 + k], wl[a * n1 * n1 + k]);
        for (int A = 0; A < n1; ++A)
            for (int B = 0; B < n1; ++B)
                for (int b = 0; b < n1; ++b)
                    for (int g = 0; g < n1; ++g) {
                        const int src = (A * n1 + b) * n1 + g, dst = (A * n1 + B) * n1 + g;
                        dd_madd(t2 + dst, t2l + dst, L[1][B * n1 + b], t1[src], t1l[src]);
                    }
        double *Wq = W + (size_t)q * ldW, *Lq = Wl + (size_t)q * ldW;
        for (int AB = 0; AB < n1 * n1; ++AB)
            for (int G = 0; G < n1; ++G)
                for (int g = 0; g < n1; ++g)
                    dd_madd(Wq + AB * n1 + G, Lq + AB * n1 + G, L[2][G * n1 + g],
                            t2[AB * n1 + g], t2l[AB * n1 + g]);
    }
    free(t1);
}

/* proxy weights of every cluster: nc x (nprox P); with Wl (not NULL) in double-double */
static void upward(const cm_rbf_tree *t, const double *ws, int nc, double *W, double *Wl,
                   int threads)
{
    const size_t P = (size_t)t->P, ldW = (size_t)t->nprox * P;
    for (int d = t->src.maxdepth; d >= 0; --d) {
        const long b = t->depth_start[d], e = t->depth_start[d + 1];
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (e - b > 1 && threads > 1)
        for (long x = b; x < e; ++x) {
            const tnode *u = &t->src.node[t->prox_node[x]];
            double *Wx = W + (size_t)x * P, *Lx = Wl ? Wl + (size_t)x * P : NULL;
            for (int q = 0; q < nc; ++q) {
                memset(Wx + (size_t)q * ldW, 0, P * sizeof *Wx);
                if (Lx) memset(Lx + (size_t)q * ldW, 0, P * sizeof *Lx);
            }
            for (int s = 0; s < 2; ++s) {
                const tnode *ch = u->child[0] < 0 ? u : &t->src.node[u->child[s]];
                if (ch != u && ch->proxy >= 0) {
                    const size_t o = (size_t)ch->proxy * P;
                    if (Lx) m2m_dd(t, u, ch, W + o, Wl + o, nc, Wx, Lx, ldW);
                    else m2m(t, u, ch, W + o, nc, Wx, ldW);
                } else if (Lx) {
                    p2m_dd(t, u, ws, nc, ch->begin, ch->end, Wx, Lx, ldW);
                } else {
                    p2m(t, u, ws, nc, ch->begin, ch->end, Wx, ldW);
                }
                if (ch == u) break; /* a leaf with proxies: its own centres, once */
            }
        }
    }
}

/* ---- downward: batches against clusters ---- */

typedef struct seg {
    const double *x, *y, *z, *w; /* w: component q at w + q * ldw; y = x + ldc, z = y + ldc */
    size_t ldc, ldw, n;
    int direct; /* centres (1) or proxies (0) */
} seg;

static inline __attribute__((always_inline)) void block_sum(const int hf, const int nc,
                                                            const seg *s, int ns,
                                                            const double *tx, const double *ty,
                                                            const double *tz, double *out)
{
    double x[NB], y[NB], z[NB], a[4][NB];
    for (int l = 0; l < NB; ++l) {
        x[l] = tx[l];
        y[l] = ty[l];
        z[l] = tz[l];
        for (int q = 0; q < 4; ++q) a[q][l] = 0.0;
    }
    for (int g = 0; g < ns; ++g) {
        const double *restrict sx = s[g].x, *restrict sy = s[g].y, *restrict sz = s[g].z;
        const double *restrict sw = s[g].w;
        const size_t ldw = s[g].ldw, cnt = s[g].n;
        for (size_t j = 0; j < cnt; ++j) {
            const double xj = sx[j], yj = sy[j], zj = sz[j];
            double wj[4];
            for (int q = 0; q < nc; ++q) wj[q] = sw[q * ldw + j];
            for (int l = 0; l < NB; ++l) {
                double dx = x[l] - xj, dy = y[l] - yj, dz = z[l] - zj;
                double r2 = dx * dx + dy * dy + dz * dz;
                double f = r2 * sqrt(r2);
                for (int q = 0; q < nc; ++q)
                    a[q][l] = hf ? fma(wj[q], f, a[q][l]) : a[q][l] + wj[q] * f;
            }
        }
    }
    for (int q = 0; q < nc; ++q)
        for (int l = 0; l < NB; ++l) out[q * NB + l] = a[q][l];
}

/* Columns [0, nc) (nc <= 4) of jn sources (coordinates sx.. or, keep = 2, their entries
 * left in fb) against NB targets, sums in out (nc x NB): the same multiply-add per entry
 * and column as block_sum, in the same order, so a column's sum does not depend on the
 * columns beside it. keep = 1: also leave the entries in fb. */
static inline __attribute__((always_inline)) void seg_part(const int hf, const int nc,
                                                           const int keep,
                                                           const double *sx, const double *sy,
                                                           const double *sz, const double *sw,
                                                           size_t ldw, size_t jn,
                                                           const double *tx, const double *ty,
                                                           const double *tz, double *fb,
                                                           double *out)
{
    double x[NB], y[NB], z[NB], a[4][NB];
    for (int l = 0; l < NB; ++l) {
        x[l] = tx[l];
        y[l] = ty[l];
        z[l] = tz[l];
        for (int q = 0; q < nc; ++q) a[q][l] = out[q * NB + l];
    }
    for (size_t j = 0; j < jn; ++j) {
        double wj[4];
        for (int q = 0; q < nc; ++q) wj[q] = sw[q * ldw + j];
        for (int l = 0; l < NB; ++l) {
            double f;
            if (keep == 2) {
                f = fb[j * NB + l];
            } else {
                double dx = x[l] - sx[j], dy = y[l] - sy[j], dz = z[l] - sz[j];
                double r2 = dx * dx + dy * dy + dz * dz;
                f = r2 * sqrt(r2);
                if (keep) fb[j * NB + l] = f;
            }
            for (int q = 0; q < nc; ++q)
                a[q][l] = hf ? fma(wj[q], f, a[q][l]) : a[q][l] + wj[q] * f;
        }
    }
    for (int q = 0; q < nc; ++q)
        for (int l = 0; l < NB; ++l) out[q * NB + l] = a[q][l];
}

/* block_sum for more than 4 columns: per stretch of FB_J sources the first 4 columns
 * compute the entries (kept in fb) and the others run over them 4 at a time. */
static inline __attribute__((always_inline)) void block_many(const int hf, int nc,
                                                             const seg *s, int ns,
                                                             const double *tx, const double *ty,
                                                             const double *tz, double *out)
{
    double fb[FB_J * NB];
    memset(out, 0, (size_t)nc * NB * sizeof *out);
    for (int g = 0; g < ns; ++g)
        for (size_t j0 = 0; j0 < s[g].n; j0 += FB_J) {
            const size_t jb = s[g].n - j0 < FB_J ? s[g].n - j0 : FB_J, ldw = s[g].ldw;
            const double *sx = s[g].x + j0, *sy = s[g].y + j0, *sz = s[g].z + j0;
            const double *sw = s[g].w + j0;
            seg_part(hf, 4, 1, sx, sy, sz, sw, ldw, jb, tx, ty, tz, fb, out);
            for (int k = 4; k < nc; k += 4) {
                const double *wk = sw + (size_t)k * ldw;
                double *ok = out + (size_t)k * NB;
                switch (nc - k) {
                case 1: seg_part(hf, 1, 2, sx, sy, sz, wk, ldw, jb, tx, ty, tz, fb, ok); break;
                case 2: seg_part(hf, 2, 2, sx, sy, sz, wk, ldw, jb, tx, ty, tz, fb, ok); break;
                case 3: seg_part(hf, 3, 2, sx, sy, sz, wk, ldw, jb, tx, ty, tz, fb, ok); break;
                default: seg_part(hf, 4, 2, sx, sy, sz, wk, ldw, jb, tx, ty, tz, fb, ok); break;
                }
            }
        }
}

#define CM_TREE_DISPATCH                                                                       \
    switch (nc) {                                                                              \
    case 1: block_sum(hf, 1, s, ns, tx, ty, tz, out); break;                                       \
    case 2: block_sum(hf, 2, s, ns, tx, ty, tz, out); break;                                       \
    case 3: block_sum(hf, 3, s, ns, tx, ty, tz, out); break;                                       \
    case 4: block_sum(hf, 4, s, ns, tx, ty, tz, out); break;                                       \
    default: block_many(hf, nc, s, ns, tx, ty, tz, out); break;                                    \
    }

typedef void (*block_fn)(int nc, const seg *s, int ns, const double *tx, const double *ty,
                         const double *tz, double *out);

static void block_generic(int nc, const seg *s, int ns, const double *tx, const double *ty,
                          const double *tz, double *out)
{
    const int hf = 0; /* a + w f rounded twice; one FMA where built for it (as rbf_sum.c) */
    CM_TREE_DISPATCH
}

__attribute__((target("avx2,fma"))) static void block_avx2(int nc, const seg *s, int ns,
                                                            const double *tx, const double *ty,
                                                            const double *tz, double *out)
{
    const int hf = 1;
    CM_TREE_DISPATCH
}

__attribute__((target("avx512f,avx512dq,avx512vl,avx2,fma"))) static void
block_avx512(int nc, const seg *s, int ns, const double *tx, const double *ty, const double *tz,
             double *out)
{
    const int hf = 1;
    CM_TREE_DISPATCH
}

static block_fn pick_block(cm_rbf_isa isa)
{
    if (isa == CM_RBF_ISA_AUTO) isa = cm_rbf_isa_auto();
    switch (isa) {
    case CM_RBF_ISA_AVX512_AUTOVEC: return block_avx512;
    case CM_RBF_ISA_AVX2: return block_avx2;
    case CM_RBF_ISA_AVX512: return NULL; /* the hand-written block, batch-wise (batch_avx512) */
    default: return block_generic;
    }
}

/* A whole batch (cnt targets, 3 x CM_TREE_BATCH SoA in pt, padded to a multiple of 8 with
 * its last target) against every segment, by the AVX-512 block of the direct sums
 * (rbf_sum_avx512.c): per segment the 32 targets in registers stream its centres or
 * proxies tile by tile, so a segment (<= 512 per tile, 3 + nc rows) stays in L1 while the
 * batch's groups pass over it. Each target adds the segments in the same order as the
 * compiled loops do. acc: nc x CM_TREE_BATCH. */
static void batch_avx512(int nc, const seg *s, int ns, size_t cnt, const double *pt,
                         double *acc)
{
    memset(acc, 0, (size_t)nc * CM_TREE_BATCH * sizeof *acc);
    for (int g = 0; g < ns; ++g)
        cm_rbf_r3_strided_avx512(nc, s[g].n, s[g].x, s[g].ldc, s[g].w, s[g].ldw, cnt, pt,
                                 CM_TREE_BATCH, acc);
}

/* The same with compensated (TwoSum) accumulation: hi, lo nc x CM_TREE_BATCH (any nc: the
 * block shares each entry among the columns) */
static void batch_acc_avx512(int nc, const seg *s, int ns, size_t cnt, const double *pt,
                             double *hi, double *lo)
{
    memset(hi, 0, (size_t)nc * CM_TREE_BATCH * sizeof *hi);
    memset(lo, 0, (size_t)nc * CM_TREE_BATCH * sizeof *lo);
    for (int g = 0; g < ns; ++g)
        cm_rbf_r3_acc_strided_avx512(nc, s[g].n, s[g].x, s[g].ldc, s[g].w, s[g].ldw, cnt, pt,
                                     CM_TREE_BATCH, hi, lo);
    for (size_t i = 0; i < (size_t)nc * CM_TREE_BATCH; ++i) hi[i] += lo[i];
}

void cm_rbf_tree_set_compensated(cm_rbf_tree *t, int level)
{
    if (t) t->comp = level < 0 ? 0 : level > 2 ? 2 : level;
}

void cm_rbf_tree_set_isa(cm_rbf_tree *t, cm_rbf_isa isa)
{
    if (t) t->isa = isa;
}

/* The sums for targets ordered by tg (batches = its leaves), at the targets of every
 * stride-th batch (stride 1: all of them). */
static int tree_sum(const cm_rbf_tree *t, const order *tg, size_t stride, const double *w,
                    int nc, size_t n, const double *p, size_t ldp, double *out, size_t ldo,
                    int threads, cm_rbf_tick *tick)
{
    if (nc > CM_RBF_SUM_MAX_NC) { /* passes of CM_RBF_SUM_MAX_NC: the same bits per column */
        for (int g = 0; g < nc; g += CM_RBF_SUM_MAX_NC) {
            const int st = tree_sum(t, tg, stride, w + (size_t)g * t->m,
                                    nc - g < CM_RBF_SUM_MAX_NC ? nc - g : CM_RBF_SUM_MAX_NC, n, p,
                                    ldp, out + g, ldo, threads, tick);
            if (st) return st;
        }
        return 0;
    }
    const size_t m = t->m, P = (size_t)t->P, np = (size_t)t->nprox;
    double *ws = malloc((size_t)nc * (m ? m : 1) * sizeof *ws);
    /* compensated products only by the AVX-512 block; elsewhere the plain ones (callers
     * check the error of what they get) */
    const int comp = t->comp > 0 && !pick_block(t->isa) ? t->comp : 0;
    double *W = malloc((comp == 2 ? 2 : 1) * (size_t)nc * (np ? np : 1) * P * sizeof *W);
    double *Wl = comp == 2 ? W + (size_t)nc * (np ? np : 1) * P : NULL;
    if (!ws || !W) {
        free(ws), free(W);
        return -1;
    }
    for (int q = 0; q < nc; ++q)
        for (size_t j = 0; j < m; ++j) ws[(size_t)q * m + j] = w[(size_t)q * m + t->src.perm[j]];
    upward(t, ws, nc, W, Wl, threads);
    const block_fn fn = pick_block(t->isa);
    const double *px = t->pxyz, *py = px + np * P, *pz = py + np * P;
    const double *xs = t->xs, *ys = xs + m, *zs = ys + m;
    int failed = 0;
    /* a stride past the last batch visits batch 0 alone */
    const int step = stride == 0 ? 1
                     : stride < (size_t)tg->nleaf ? (int)stride
                                                  : (tg->nleaf > 0 ? tg->nleaf : 1);
    /* batches per chunk between two ticks: tick->tree_chunks chunks of whole strides (one
     * without a tick, or when there are too few batches to keep the threads busy in each) */
    int span = tg->nleaf > 0 ? tg->nleaf : 1;
    const int nch = tick && tick->tree_chunks > 1 ? tick->tree_chunks : 1;
    if (nch > 1 && tg->nleaf / step >= nch * 8 * (threads > 0 ? threads : 1))
        span = (tg->nleaf / step + nch - 1) / nch * step;
    for (int lo = 0; lo < tg->nleaf && !failed; lo += span) {
        const int hi = tg->nleaf - lo < span ? tg->nleaf : lo + span;
#pragma omp parallel num_threads(threads) if (threads > 1 && (double)n / step * (double)m > CM_RBF_PARALLEL_MIN_PAIRS)
        {
            int cap = 256;
            seg *sg = malloc((size_t)cap * sizeof *sg);
            int stack[512];
            double tx[CM_TREE_BATCH + NB], ty[CM_TREE_BATCH + NB], tz[CM_TREE_BATCH + NB];
            double pt[3 * CM_TREE_BATCH];
            /* the sums of a batch, any number of columns: acc nc x NB, bacc and blo nc x
             * CM_TREE_BATCH */
            double *acc = malloc((size_t)nc * (NB + 2 * CM_TREE_BATCH) * sizeof *acc);
            double *bacc = acc ? acc + (size_t)nc * NB : NULL;
            double *blo = bacc ? bacc + (size_t)nc * CM_TREE_BATCH : NULL;
            if (!acc) {
                free(sg);
                sg = NULL;
            }
            if (!sg) {
#pragma omp atomic write
                failed = 1;
            }
#pragma omp for schedule(dynamic, 1)
            for (int bi = lo; bi < hi; bi += step) {
                if (!sg) continue;
                const tnode *b = &tg->node[tg->leaf[bi]];
                const size_t cnt = b->end - b->begin;
                int ns = 0, sp = 0;
                stack[sp++] = 0;
                while (sp > 0 && m > 0) {
                    const tnode *u = &t->src.node[stack[--sp]];
                    double D2 = 0.0;
                    for (int d = 0; d < 3; ++d) {
                        double dd = u->mid[d] - b->mid[d];
                        D2 += dd * dd;
                    }
                    const double D = sqrt(D2);
                    const int far = u->proxy >= 0 && D > b->rad && u->rad <= t->theta * (D - b->rad);
                    if (!far && u->child[0] >= 0 && u->proxy >= 0) {
                        stack[sp++] = u->child[1];
                        stack[sp++] = u->child[0];
                        continue;
                    }
                    if (ns + 2 > cap) { /* room for two: proxies and their low parts */
                        seg *nsg = realloc(sg, 2 * (size_t)cap * sizeof *nsg);
                        if (!nsg) {
#pragma omp atomic write
                            failed = 1;
                            break;
                        }
                        sg = nsg;
                        cap *= 2;
                    }
                    if (far) {
                        const size_t o0 = (size_t)u->proxy * P;
                        sg[ns++] = (seg){px + o0, py + o0, pz + o0, W + o0, np * P, np * P, P, 0};
                        if (Wl) /* the low parts: the same proxies once more */
                            sg[ns++] = (seg){px + o0, py + o0, pz + o0, Wl + o0, np * P, np * P, P, 0};
                    } else if (ns > 0 && sg[ns - 1].direct &&
                               sg[ns - 1].x + sg[ns - 1].n == xs + u->begin) {
                        sg[ns - 1].n += u->end - u->begin; /* adjacent centres: one stretch */
                    } else {
                        const size_t o0 = u->begin;
                        sg[ns++] = (seg){xs + o0, ys + o0, zs + o0, ws + o0, m, m, u->end - u->begin, 1};
                    }
                }
                for (size_t l = 0; l < cnt + NB; ++l) {
                    size_t i = tg->perm[b->begin + (l < cnt ? l : cnt - 1)];
                    tx[l] = p[i];
                    ty[l] = p[ldp + i];
                    tz[l] = p[2 * ldp + i];
                }
                if (!fn) {
                    for (size_t l = 0; l < CM_TREE_BATCH; ++l) {
                        pt[l] = tx[l < cnt ? l : cnt - 1];
                        pt[CM_TREE_BATCH + l] = ty[l < cnt ? l : cnt - 1];
                        pt[2 * CM_TREE_BATCH + l] = tz[l < cnt ? l : cnt - 1];
                    }
                    if (comp) batch_acc_avx512(nc, sg, ns, cnt, pt, bacc, blo);
                    else batch_avx512(nc, sg, ns, cnt, pt, bacc);
                    for (size_t l = 0; l < cnt; ++l) {
                        size_t i = tg->perm[b->begin + l];
                        for (int q = 0; q < nc; ++q)
                            out[i * ldo + (size_t)q] = bacc[(size_t)q * CM_TREE_BATCH + l];
                    }
                    continue;
                }
                for (size_t l0 = 0; l0 < cnt; l0 += NB) {
                    fn(nc, sg, ns, tx + l0, ty + l0, tz + l0, acc);
                    for (size_t l = l0; l < cnt && l < l0 + NB; ++l) {
                        size_t i = tg->perm[b->begin + l];
                        for (int q = 0; q < nc; ++q) out[i * ldo + (size_t)q] = acc[q * NB + (l - l0)];
                    }
                }
            }
            free(sg);
            free(acc);
        }
        /* in units of whole sums */
        if (cm_rbf_tick_add(tick, (double)(hi - lo) / (double)tg->nleaf)) break;
    }
    free(ws);
    free(W);
    return failed ? -1 : tick && tick->status < 0 ? -2 : 0;
}

struct cm_rbf_tree_targets {
    size_t n, ldp;
    const double *p;
    order o;
};

cm_rbf_tree_targets *cm_rbf_tree_targets_create(size_t n, const double *p, size_t ldp)
{
    cm_rbf_tree_targets *tg = calloc(1, sizeof *tg);
    if (!tg) return NULL;
    *tg = (cm_rbf_tree_targets){.n = n, .ldp = ldp, .p = p};
    if (build_order(n, p, ldp, CM_TREE_BATCH, &tg->o)) cm_rbf_tree_targets_destroy(&tg);
    return tg;
}

void cm_rbf_tree_targets_destroy(cm_rbf_tree_targets **tg)
{
    if (!tg || !*tg) return;
    free_order(&(*tg)->o);
    free(*tg);
    *tg = NULL;
}

size_t cm_rbf_tree_targets_pilot(const cm_rbf_tree_targets *tg, size_t batches, size_t per,
                                 size_t *idx, size_t *stride)
{
    const size_t nl = (size_t)tg->o.nleaf;
    *stride = batches > 0 && nl > batches ? (nl + batches - 1) / batches : 1;
    size_t k = 0;
    for (size_t bi = 0; bi < nl; bi += *stride) {
        const tnode *b = &tg->o.node[tg->o.leaf[bi]];
        const size_t cnt = b->end - b->begin, take = cnt < per ? cnt : per;
        for (size_t l = 0; l < take; ++l) idx[k++] = tg->o.perm[b->begin + l * cnt / take];
    }
    return k;
}

int cm_rbf_tree_sum_targets(const cm_rbf_tree *t, const cm_rbf_tree_targets *tg,
                            size_t stride, const double *w, int nc, double *out, size_t ldo,
                            int threads)
{
    if (tg->n == 0) return 0;
    return tree_sum(t, &tg->o, stride, w, nc, tg->n, tg->p, tg->ldp, out, ldo, threads, NULL);
}

int cm_rbf_tree_sum_targets_tick(const cm_rbf_tree *t, const cm_rbf_tree_targets *tg,
                                 size_t stride, const double *w, int nc, double *out,
                                 size_t ldo, int threads, cm_rbf_tick *tick)
{
    if (tg->n == 0) return 0;
    return tree_sum(t, &tg->o, stride, w, nc, tg->n, tg->p, tg->ldp, out, ldo, threads, tick);
}

int cm_rbf_tree_sum(const cm_rbf_tree *t, const double *w, int nc, size_t n, const double *p,
                    size_t ldp, double *out, size_t ldo, int threads)
{
    if (n == 0) return 0;
    cm_rbf_tree_targets *tg = cm_rbf_tree_targets_create(n, p, ldp);
    int st = tg ? cm_rbf_tree_sum_targets(t, tg, 1, w, nc, out, ldo, threads) : -1;
    cm_rbf_tree_targets_destroy(&tg);
    return st;
}

int cm_rbf_tree_sum_self(const cm_rbf_tree *t, const double *w, int nc, double *out,
                         size_t ldo, int threads)
{
    return tree_sum(t, &t->self, 1, w, nc, t->m, t->c, t->m, out, ldo, threads, NULL);
}

void cm_rbf_tree_check(const cm_rbf_tree *t, const double *w, int nc, size_t n,
                       const double *p, size_t ldp, const double *out, size_t ldo,
                       size_t samples, const size_t *idx, double *max_err,
                       double *max_abs_sum, int threads)
{
    *max_err = 0.0;
    if (max_abs_sum) *max_abs_sum = 0.0;
    if (samples > n && !idx) samples = n;
    if (samples == 0) return;
    const size_t m = t->m;
    size_t *at = malloc(samples * sizeof *at);
    double *sp = malloc(3 * samples * sizeof *sp);
    double *ex = malloc(2 * samples * (size_t)nc * sizeof *ex);
    double *aw = max_abs_sum ? malloc((size_t)nc * m * sizeof *aw) : NULL;
    if (!at || !sp || !ex || (max_abs_sum && !aw)) {
        *max_err = INFINITY; /* unknown: the caller falls back to direct sums */
        free(at), free(sp), free(ex), free(aw);
        return;
    }
    double *ab = ex + samples * (size_t)nc;
    for (size_t k = 0; k < samples; ++k) {
        at[k] = idx ? idx[k] : (size_t)((double)k * (double)n / (double)samples);
        for (int d = 0; d < 3; ++d) sp[(size_t)d * samples + k] = p[(size_t)d * ldp + at[k]];
    }
    cm_rbf_kernel_sum_acc(m, t->c, w, nc, samples, sp, samples, ex, (size_t)nc, threads);
    if (max_abs_sum) {
        for (size_t j = 0; j < (size_t)nc * m; ++j) aw[j] = fabs(w[j]);
        cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, t->c, aw, nc, samples, sp, samples, ab,
                          (size_t)nc, threads);
    }
    for (size_t k = 0; k < samples; ++k)
        for (int q = 0; q < nc; ++q) {
            const size_t e = k * (size_t)nc + (size_t)q;
            *max_err = fmax(*max_err, fabs(out[at[k] * ldo + (size_t)q] - ex[e]));
            if (max_abs_sum) *max_abs_sum = fmax(*max_abs_sum, ab[e]);
        }
    free(at), free(sp), free(ex), free(aw);
}
