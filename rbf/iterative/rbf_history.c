/* The iterative fit's earlier solutions, the starts of its next solves (rbf_iter.h,
 * cm_rbf_history): Fischer's projection [Fis98] in the residual norm. */
#include "rbf_iter.h"

#include <cblas.h>
#include <math.h>
#include <stdlib.h>

void cm_rbf_history_destroy(cm_rbf_history **h)
{
    if (!h || !*h) return;
    free((*h)->w);
    free((*h)->b);
    free((*h)->scratch);
    free(*h);
    *h = NULL;
}

cm_rbf_history *cm_rbf_history_create(size_t m, size_t cap)
{
    if (m == 0 || cap == 0) return NULL;
    cm_rbf_history *h = calloc(1, sizeof *h);
    if (!h) return NULL;
    h->m = m;
    h->cap = cap;
    h->w = malloc(cap * m * sizeof *h->w);
    h->b = malloc(cap * m * sizeof *h->b);
    h->scratch = malloc(2 * m * sizeof *h->scratch);
    if (!h->w || !h->b || !h->scratch) cm_rbf_history_destroy(&h);
    return h;
}

size_t cm_rbf_history_start(const cm_rbf_history *h, double *pf, double *w0)
{
    const size_t m = h->m;
    for (size_t i = 0; i < m; ++i) w0[i] = 0.0;
    /* the b_j are orthonormal: the coefficients of the nearest combination are dot products,
     * taken of what is left (modified Gram-Schmidt: the residual stays accurate) */
    for (size_t j = 0; j < h->n; ++j) {
        const double c = cblas_ddot((int)m, h->b + j * m, 1, pf, 1);
        cblas_daxpy((int)m, -c, h->b + j * m, 1, pf, 1);
        cblas_daxpy((int)m, c, h->w + j * m, 1, w0, 1);
    }
    return h->n;
}

int cm_rbf_history_add(cm_rbf_history *h, const double *w, const double *pb)
{
    const size_t m = h->m;
    /* when full, the oldest pair gives way: the others stay orthonormal without it */
    const size_t slot = h->n < h->cap ? h->n : h->next;
    double *nw = h->scratch, *nb = h->scratch + m;
    for (size_t i = 0; i < m; ++i) nw[i] = w[i], nb[i] = pb[i];
    const double b0 = cblas_dnrm2((int)m, nb, 1);
    if (!(b0 > 0.0) || !isfinite(b0)) return 0;
    /* Gram-Schmidt against the kept b_j, twice (the second pass removes what round-off left
     * of the first), with the same combination applied to w, so that b stays Pi A w */
    for (int pass = 0; pass < 2; ++pass)
        for (size_t j = 0; j < h->n; ++j) {
            if (j == slot) continue;
            const double c = cblas_ddot((int)m, h->b + j * m, 1, nb, 1);
            cblas_daxpy((int)m, -c, h->b + j * m, 1, nb, 1);
            cblas_daxpy((int)m, -c, h->w + j * m, 1, nw, 1);
        }
    const double bn = cblas_dnrm2((int)m, nb, 1);
    if (!(bn > CM_RBF_HISTORY_DROP * b0)) return 0;
    for (size_t i = 0; i < m; ++i) {
        h->w[slot * m + i] = nw[i] / bn;
        h->b[slot * m + i] = nb[i] / bn;
    }
    if (h->n < h->cap) ++h->n;
    else h->next = (h->next + 1) % h->cap;
    return 1;
}

size_t cm_rbf_history_bytes(const cm_rbf_history *h)
{
    return h ? (2 * h->cap + 2) * h->m * sizeof(double) : 0;
}

/* Greedy, as a block QR with pivoting, done on the Gram matrix of what the history leaves of
 * the columns (a pivoted Cholesky by whole fields): a column's squared norm outside the span
 * so far is G_cc - sum_k L_ck^2. The squares lose what lies below 1e-8 of a column, where
 * its start is good whatever the order. A few BLAS-3 calls instead of a Gram-Schmidt pass per
 * pair of columns: bore, 60 columns of 20,642, 0.08 s that way. */
void cm_rbf_history_order(const cm_rbf_history *h, size_t m, size_t nf, size_t d, size_t picks,
                          double *pf, const double *scale, size_t *order)
{
    const size_t nc = nf * d;
    for (size_t f = 0; f < nf; ++f) order[f] = f;
    double *g = malloc(nc * nc * sizeof *g), *l = malloc(nc * nc * sizeof *l);
    double *e = malloc(nc * sizeof *e);
    double *c = h && h->n > 0 ? malloc(h->n * nc * sizeof *c) : NULL;
    if (!g || !l || !e || (h && h->n > 0 && !c)) { /* out of memory: the order as given */
        free(g), free(l), free(e), free(c);
        return;
    }
    if (c) { /* pf -= B (B' pf): what the history's orthonormal b_j leave */
        cblas_dgemm(CblasColMajor, CblasTrans, CblasNoTrans, (int)h->n, (int)nc, (int)m, 1.0,
                    h->b, (int)m, pf, (int)m, 0.0, c, (int)h->n);
        cblas_dgemm(CblasColMajor, CblasNoTrans, CblasNoTrans, (int)m, (int)nc, (int)h->n, -1.0,
                    h->b, (int)m, c, (int)h->n, 1.0, pf, (int)m);
    }
    cblas_dsyrk(CblasColMajor, CblasUpper, CblasTrans, (int)nc, (int)m, 1.0, pf, (int)m, 0.0, g,
                (int)nc);
    for (size_t u = 0; u < nc; ++u) {
        e[u] = g[u * nc + u];
        for (size_t v = 0; v < u; ++v) g[v * nc + u] = g[u * nc + v]; /* the lower half */
    }
    size_t rank = 0;
    if (picks > nf) picks = nf;
    for (size_t p = 0; p < picks; ++p) {
        /* the remaining field whose data the span fits worst, relative to their scales */
        size_t best = p;
        double worst = -1.0;
        for (size_t q = p; q < nf; ++q) {
            double r = 0.0;
            for (size_t j = 0; j < d; ++j) {
                const size_t u = order[q] * d + j;
                if (scale[u] > 0.0) r = fmax(r, sqrt(fmax(e[u], 0.0)) / scale[u]);
            }
            if (r > worst * (1.0 + 1e-9)) worst = r, best = q; /* ties: the first */
        }
        const size_t f = order[best];
        order[best] = order[p];
        order[p] = f;
        /* its columns join the span: a column of L each */
        for (size_t j = 0; j < d; ++j) {
            const size_t u = f * d + j;
            const double piv = e[u], lim = CM_RBF_HISTORY_DROP * scale[u];
            if (!(piv > lim * lim)) continue;
            double *lk = l + rank * nc;
            for (size_t v = 0; v < nc; ++v) {
                double t = g[u * nc + v];
                for (size_t k = 0; k < rank; ++k) t -= l[k * nc + v] * l[k * nc + u];
                lk[v] = t / sqrt(piv);
            }
            for (size_t v = 0; v < nc; ++v) e[v] -= lk[v] * lk[v];
            e[u] = 0.0;
            ++rank;
        }
    }
    free(g), free(l), free(e), free(c);
}
