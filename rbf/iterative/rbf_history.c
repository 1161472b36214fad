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
