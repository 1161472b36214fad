/* The separate bodies of a centre set, as the Schwarz preconditioner's subdomains see them,
 * and the projection that keeps the local part of its correction free of linear moments on
 * each body (rbf_schwarz.c).
 * Why: the restricted local solves keep only their leaf's rows, so the weights they return
 * carry linear moments (sum w, sum w x) that their local sets' constraints do not cancel.
 * With two bodies, a moment on one body and the opposite one on the other satisfy the global
 * constraints, and r^3 carries them across the gap at D^3: the local part then answered a
 * residual that is linear on each body (which every local solve annihilates) with a field
 * 20 x that residual (two bracket copies of 43,664 centres; RESULTS.md, RBF solvers).
 * Removing those moments leaves the bodies' relative motion to the coarse level,
 * which solves it exactly: 121,242 centres in 9 iterations instead of 11-28. On one body the
 * global projection after the whole correction took them out, but only after the coarse
 * correction that follows the local solves had seen them: projected before it, the bracket
 * takes 7-8 iterations instead of 10 (21k-103k centres). */
#include "rbf_internal.h"

#include <stdlib.h>
#include <string.h>

struct cm_rbf_bodies {
    int n;          /* bodies */
    size_t *ptr;    /* n + 1: offsets into idx and q / 4 */
    size_t *idx;    /* m centre indices, body by body */
    double *q;      /* 4 per centre: each body's orthonormal linear basis (cm_rbf_poly_basis),
                     * body b's in q + 4 ptr[b], col-major with ld ptr[b+1] - ptr[b] */
    size_t bytes;
};

static int find(int *parent, int a)
{
    while (parent[a] != a) {
        parent[a] = parent[parent[a]]; /* path halving */
        a = parent[a];
    }
    return a;
}

cm_status cm_rbf_bodies_create(cm_context *ctx, const double *c, size_t m, int nsub,
                               const size_t *sub_ptr, const size_t *sub_idx, const int *n_in,
                               cm_rbf_bodies **bodies)
{
    *bodies = NULL;
    int *leaf_of = malloc(m * sizeof *leaf_of), *parent = malloc((size_t)nsub * sizeof *parent);
    int *body_of = malloc((size_t)nsub * sizeof *body_of);
    cm_status st = CM_OK;
    cm_rbf_bodies *b = NULL;
    double *work = NULL;
    size_t *fill = NULL, big = 0;
    if (!leaf_of || !parent || !body_of) goto nomem;
    for (int l = 0; l < nsub; ++l) {
        parent[l] = l;
        for (size_t u = 0; u < (size_t)n_in[l]; ++u) leaf_of[sub_idx[sub_ptr[l] + u]] = l;
    }
    /* a local set that reaches into another leaf joins the two */
    for (int l = 0; l < nsub; ++l)
        for (size_t u = sub_ptr[l] + (size_t)n_in[l]; u < sub_ptr[l + 1]; ++u) {
            int a = find(parent, l), e = find(parent, leaf_of[sub_idx[u]]);
            if (a != e) parent[a] = e;
        }
    int n = 0;
    for (int l = 0; l < nsub; ++l)
        if (find(parent, l) == l) body_of[l] = n++;
    for (size_t i = 0; i < m; ++i) leaf_of[i] = body_of[find(parent, leaf_of[i])]; /* now: body */
    b = calloc(1, sizeof *b);
    if (!b) goto nomem;
    b->n = n;
    b->ptr = calloc((size_t)n + 1, sizeof *b->ptr);
    b->idx = malloc(m * sizeof *b->idx);
    b->q = malloc(4 * m * sizeof *b->q);
    if (!b->ptr || !b->idx || !b->q) goto nomem;
    b->bytes = ((size_t)n + 1) * sizeof *b->ptr + m * (sizeof *b->idx + 4 * sizeof *b->q);
    /* counting sort of the centres by body */
    for (size_t i = 0; i < m; ++i) ++b->ptr[leaf_of[i] + 1];
    for (int k = 0; k < n; ++k) b->ptr[k + 1] += b->ptr[k];
    fill = calloc((size_t)n, sizeof *fill);
    if (!fill) goto nomem;
    for (size_t i = 0; i < m; ++i) b->idx[b->ptr[leaf_of[i]] + fill[leaf_of[i]]++] = i;
    for (int k = 0; k < n; ++k)
        if (b->ptr[k + 1] - b->ptr[k] > big) big = b->ptr[k + 1] - b->ptr[k];
    work = malloc(8 * big * sizeof *work);
    if (!work) goto nomem;
    for (int k = 0; k < n; ++k)
        if (cm_rbf_poly_basis(c, m, b->idx + b->ptr[k], b->ptr[k + 1] - b->ptr[k], work,
                              b->q + 4 * b->ptr[k]) != 0) {
            st = cm_error(ctx, CM_ERR_NUMERIC, "cm_rbf_create: the linear basis of body %d of "
                          "%d (%zu centres) failed", k, n, b->ptr[k + 1] - b->ptr[k]);
            goto done;
        }
    cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_create: Schwarz: %d separate bod%s (the largest %zu "
           "centres); the local corrections keep no linear moment on any", n, n > 1 ? "ies" : "y",
           big);
    goto done;
nomem:
    st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (bodies of the centres)");
done:
    if (st == CM_OK) *bodies = b;
    else cm_rbf_bodies_destroy(&b);
    free(leaf_of), free(parent), free(body_of), free(fill), free(work);
    return st;
}

void cm_rbf_bodies_destroy(cm_rbf_bodies **bodies)
{
    if (!bodies || !*bodies) return;
    free((*bodies)->ptr), free((*bodies)->idx), free((*bodies)->q);
    free(*bodies);
    *bodies = NULL;
}

int cm_rbf_bodies_count(const cm_rbf_bodies *bodies) { return bodies ? bodies->n : 0; }
size_t cm_rbf_bodies_bytes(const cm_rbf_bodies *bodies) { return bodies ? bodies->bytes : 0; }

void cm_rbf_bodies_project(const cm_rbf_bodies *bodies, int nc, size_t m, double *w)
{
    if (!bodies) return;
    for (int k = 0; k < bodies->n; ++k) {
        const size_t *idx = bodies->idx + bodies->ptr[k], n = bodies->ptr[k + 1] - bodies->ptr[k];
        const double *q = bodies->q + 4 * bodies->ptr[k];
        for (int c = 0; c < nc; ++c) {
            double *wc = w + (size_t)c * m;
            for (int a = 0; a < 4; ++a) { /* orthonormal columns: one pass each */
                const double *qa = q + (size_t)a * n;
                double t = 0.0;
                for (size_t i = 0; i < n; ++i) t += qa[i] * wc[idx[i]];
                for (size_t i = 0; i < n; ++i) wc[idx[i]] -= t * qa[i];
            }
        }
    }
}
