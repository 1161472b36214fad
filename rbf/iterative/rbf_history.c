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

/* Greedy, as a block QR with pivoting: the fields' columns are kept orthogonal to the span
 * so far (modified Gram-Schmidt, in place), so a remaining column's norm is what the span
 * leaves of it. */
void cm_rbf_history_order(const cm_rbf_history *h, size_t m, size_t nf, size_t d, size_t picks,
                          double *pf, const double *scale, size_t *order)
{
    const size_t nc = nf * d;
    for (size_t c = 0; c < nc; ++c)
        for (size_t j = 0; h && j < h->n; ++j) {
            double *pc = pf + c * m;
            const double t = cblas_ddot((int)m, h->b + j * m, 1, pc, 1);
            cblas_daxpy((int)m, -t, h->b + j * m, 1, pc, 1);
        }
    for (size_t f = 0; f < nf; ++f) order[f] = f;
    if (picks > nf) picks = nf;
    for (size_t p = 0; p < picks; ++p) {
        /* the remaining field whose data the span fits worst, relative to their scales */
        size_t best = p;
        double worst = -1.0;
        for (size_t q = p; q < nf; ++q) {
            double e = 0.0;
            for (size_t j = 0; j < d; ++j) {
                const size_t c = order[q] * d + j;
                if (scale[c] > 0.0) e = fmax(e, cblas_dnrm2((int)m, pf + c * m, 1) / scale[c]);
            }
            if (e > worst) worst = e, best = q;
        }
        const size_t f = order[best];
        order[best] = order[p];
        order[p] = f;
        /* its columns join the span: normalised, and taken out of the fields after it */
        for (size_t j = 0; j < d; ++j) {
            double *u = pf + (f * d + j) * m;
            const double un = cblas_dnrm2((int)m, u, 1);
            if (!(un > CM_RBF_HISTORY_DROP * scale[f * d + j])) continue;
            cblas_dscal((int)m, 1.0 / un, u, 1);
            for (size_t jj = j + 1; jj < d; ++jj) {
                double *v = pf + (f * d + jj) * m;
                cblas_daxpy((int)m, -cblas_ddot((int)m, u, 1, v, 1), u, 1, v, 1);
            }
            for (size_t q = p + 1; q < nf; ++q)
                for (size_t jj = 0; jj < d; ++jj) {
                    double *v = pf + (order[q] * d + jj) * m;
                    cblas_daxpy((int)m, -cblas_ddot((int)m, u, 1, v, 1), u, 1, v, 1);
                }
        }
    }
}
