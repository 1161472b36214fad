/* The iterative solver's state (rbf_iter.h): the options check, the orthonormal basis Q1 of
 * the polynomials at the centres and the Schwarz preconditioner (rbf_schwarz.c), built once
 * per set of centres by cm_rbf_create and kept for every solve; and the treecodes the solve
 * and the evaluation share. */
#include "rbf_iter.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

const double *cm_rbf_iterative_q1(const cm_rbf *r) { return r->iter ? r->iter->q1 : NULL; }

const cm_rbf_schwarz *cm_rbf_iterative_pc(const cm_rbf *r) { return r->iter ? r->iter->pc : NULL; }

double cm_rbf_diam3(const cm_rbf *r, size_t n, const double *p)
{
    double d2 = 0.0;
    for (int d = 0; d < 3; ++d) {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < r->m; ++i) {
            lo = fmin(lo, r->c[(size_t)d * r->m + i]);
            hi = fmax(hi, r->c[(size_t)d * r->m + i]);
        }
        for (size_t i = 0; i < n; ++i) {
            lo = fmin(lo, p[(size_t)d * n + i]);
            hi = fmax(hi, p[(size_t)d * n + i]);
        }
        d2 += (hi - lo) * (hi - lo);
    }
    return d2 * sqrt(d2);
}

void cm_rbf_combine_dd(size_t m, int n, const double *x, const double *xlo, const double *c,
                       double *hi, double *lo)
{
    for (size_t q = 0; q < m; ++q) {
        double h = 0.0, l = 0.0;
        for (int j = 0; j < n; ++j) {
            const double xj = x[(size_t)j * m + q], p = c[j] * xj, pe = fma(c[j], xj, -p);
            const double t = h + p, bv = t - h;
            l += ((h - (t - bv)) + (p - bv)) + pe;
            if (xlo) l += c[j] * xlo[(size_t)j * m + q];
            h = t;
        }
        const double t = h + l; /* to double, the remainder kept */
        lo[q] = l - (t - h);
        hi[q] = t;
    }
}

int cm_rbf_iterative_scales_begin(cm_rbf *r, size_t nc, double fmax)
{
    cm_rbf_scales *s = &r->iter->next;
    s->fmax = fmax;
    s->n = 0;
    if (nc == 0) return 0;
    double *a = realloc(s->fnorm, 4 * nc * sizeof *a); /* fnorm, smax, smin, start: a block */
    if (!a) return -1;
    s->fnorm = a;
    s->smax = a + nc;
    s->smin = a + 2 * nc;
    s->start = a + 3 * nc;
    for (size_t c = 0; c < 2 * nc; ++c) a[c] = 0.0;
    for (size_t c = 2 * nc; c < 4 * nc; ++c) a[c] = -1.0;
    s->n = nc;
    return 0;
}

void cm_rbf_iterative_commit(cm_rbf *r)
{
    const cm_rbf_scales t = r->iter->scales;
    r->iter->scales = r->iter->next;
    r->iter->next = t;
}

void cm_rbf_iterative_destroy(cm_rbf_iter **it)
{
    if (!it || !*it) return;
    cm_rbf_schwarz_destroy(&(*it)->pc);
    cm_rbf_tree_destroy(&(*it)->tree);
    cm_rbf_tree_destroy(&(*it)->rtree[0]);
    cm_rbf_tree_destroy(&(*it)->rtree[1]);
    cm_rbf_tree_destroy(&(*it)->rtree[2]);
    free((*it)->q1);
    free((*it)->col_iters);
    free((*it)->scales.fnorm);
    free((*it)->next.fnorm);
    cm_rbf_history_destroy(&(*it)->hist);
    free(*it);
    *it = NULL;
}

cm_status cm_rbf_iterative_setup(cm_context *ctx, cm_rbf *r, int threads)
{
    const size_t m = r->m, k = (size_t)r->k;
    const cm_rbf_options *o = &r->opt;
    const cm_rbf_tuning *tu = &r->tun;
    if (r->kernel != CM_RBF_TRIHARMONIC || r->dim != 3)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_rbf_create: the iterative solver handles the 3D r^3 kernel only");
    if (!(o->tolerance > 0.0) || o->max_iterations < 1 || o->restart < 2 || tu->leaf_size < 8 ||
        tu->local_size < tu->leaf_size || tu->coarse_size < 0 || tu->coarse_post < 0 ||
        tu->coarse_post > 2 || !(tu->overlap >= 0.0) || tu->local_max < 0 || tu->coarse_max < 0 ||
        tu->local_float < 0 || tu->local_float > 2 || o->fast_sum < -1 || o->fast_sum > 1 ||
        !(tu->fast_tol > 0.0 && tu->fast_tol <= 1e-3) || tu->fast_refine < 0 ||
        tu->fast_refine > 10 || !(tu->fast_eval_tol > 0.0) || tu->relax < 0 || tu->relax > 2 ||
        tu->warm_history < 0 ||
        !(tu->thin_reach >= 0.0) || (tu->thin_reach > 0.0 && (!(tu->thin_cell > 0.0) ||
                                                            tu->thin_max < tu->leaf_size)))
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_rbf_create: bad iterative options (tolerance %g, max_iterations %d, "
                        "restart %d, leaf_size %d, local_size %d, coarse_size %d, coarse_post "
                        "%d, overlap %g, local_max %d, coarse_max %d, fast_sum %d, fast_tol %g, "
                        "fast_refine %d, fast_eval_tol %g, relax %d, thin_reach %g, "
                        "thin_cell %g, thin_max %d, warm_history %d)",
                        o->tolerance, o->max_iterations, o->restart, tu->leaf_size,
                        tu->local_size, tu->coarse_size, tu->coarse_post, tu->overlap, tu->local_max,
                        tu->coarse_max, o->fast_sum, tu->fast_tol, tu->fast_refine,
                        tu->fast_eval_tol, tu->relax, tu->thin_reach, tu->thin_cell, tu->thin_max,
                        tu->warm_history);
    cm_rbf_iter *it = calloc(1, sizeof *it);
    if (!it) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    it->q1 = malloc(m * k * sizeof *it->q1);
    if (!it->q1) {
        free(it);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    }
    memcpy(it->q1, r->qr, m * k * sizeof *it->q1);
    lapack_int info = LAPACKE_dorgqr(LAPACK_COL_MAJOR, (lapack_int)m, (lapack_int)k,
                                     (lapack_int)k, it->q1, (lapack_int)m, r->tau);
    cm_status st = info == 0 ? CM_OK
                             : cm_error(ctx, CM_ERR_INTERNAL, "cm_rbf_create: dorgqr failed (info %d)",
                                        (int)info);
    if (st == CM_OK) st = cm_rbf_schwarz_create(ctx, r, threads, &it->pc);
    if (st != CM_OK) {
        cm_rbf_iterative_destroy(&it);
        return st;
    }
    r->iter = it;
    r->stats.subdomains = cm_rbf_schwarz_subdomains(it->pc);
    r->stats.coarse_size = cm_rbf_schwarz_coarse(it->pc);
    r->stats.memory_bytes = cm_rbf_schwarz_bytes(it->pc) + m * k * sizeof(double);
    return CM_OK;
}

cm_rbf_tree *cm_rbf_iterative_tree(const cm_rbf *r, int order, double theta)
{
    cm_rbf_iter *it = r->iter;
    if (it->tree && it->tree_order == order && it->tree_theta == theta) return it->tree;
    cm_rbf_tree_destroy(&it->tree);
    it->tree = cm_rbf_tree_create(r->m, r->c, order, theta);
    it->tree_order = order;
    it->tree_theta = theta;
    return it->tree;
}

