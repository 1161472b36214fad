/* LBWARP (Shontz & Vavasis 2003; Staten et al. 2011, paper section 5). In M0 every free node
 * x_i is written as a convex combination of its mesh neighbours (the other nodes of the
 * volume cells around it) with the log-barrier weights
 *     maximise sum_j log w_j  subject to  sum_j w_j x_j = x_i,  sum_j w_j = 1,
 * and the moved mesh keeps them: x'_i = sum_j w_ij x'_j, a sparse linear system in the free
 * nodes with the moved constrained nodes on the right. Since the weights sum to 1 and
 * reproduce x_i, the same system holds for displacements (what the warp interface hands).
 *
 * Weights: stationarity of the Lagrangian gives w_j = 1 / (mu + lambda . (x_j - x_i)), and
 * multiplying the constraints by the multipliers gives mu = n (the neighbour count), so the
 * 4 multipliers reduce to lambda, the maximiser of the concave F(lambda) = sum_j log(n +
 * lambda . d_j), found by damped Newton (backtracking that keeps every w_j positive). The
 * maximum exists iff x_i is strictly inside the convex hull of its neighbours; where it is
 * not (a badly shaped M0), Newton does not converge and the node falls back to the uniform
 * weights 1/n (Laplacian smoothing: positive, but no longer reproducing x_i, so such a node
 * breaks affine reproduction). Those nodes are counted (cm_warp_fallback_nodes, a
 * CM_LOG_WARNING).
 *
 * Solver: UMFPACK's sparse LU of I - W_II, factored once in create and reused by every apply
 * (absolute studies pay two triangular solves per step, as FEMWARP with CHOLMOD; the matrix
 * is not symmetric, so CHOLMOD does not apply), with a METIS ordering. A preconditioned Krylov
 * method (BiCGSTAB with ILU) would need less memory on very large meshes but a tolerance and an
 * iteration count per step; at the sizes of the paper's benchmarks the direct factor is cheaper
 * over a study.
 * Reverse product (docs/DESIGN.md, "Gradients"): apply is d_I = (I - W_II)^-1 W_IB d_B, linear
 * in d_B (the fallback nodes only change which weights enter the matrices), so
 * J^T v = v_B + W_IB^T (I - W_II)^-T v_I: a transposed solve with the kept LU factor per
 * component, then each free node hands its result back to its constrained neighbours with
 * its weights. */
#include "warp_method.h"

#include <umfpack.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct lbwarp {
    cm_warp_nodes *nodes;
    size_t n_fallback;
    /* W_IB by rows: free node i's constrained neighbours and weights */
    int64_t *ib_start; /* n_free + 1 */
    int64_t *ib_node;  /* node ids */
    double *ib_w;
    /* I - W_II in compressed columns, kept for UMFPACK's solve */
    SuiteSparse_long *ap, *ai;
    double *ax;
    void *numeric;
    double *b, *x; /* scratch: n_free */
} lbwarp;

int cm_lbwarp_weights(const double *d, size_t n, double *w, double lambda[3], double *mu)
{
    /* scale the offsets to unit mean length: the Newton tolerances are then absolute */
    double h = 0;
    for (size_t j = 0; j < n; ++j)
        h += sqrt(d[3 * j] * d[3 * j] + d[3 * j + 1] * d[3 * j + 1] + d[3 * j + 2] * d[3 * j + 2]);
    h /= (double)(n ? n : 1);
    double l[3] = {0, 0, 0}, dn = (double)n;
    int ok = n >= 4 && h > 0;
    double f = dn * log(dn); /* F(0) */
    for (int it = 0; ok && it < 100; ++it) {
        double g[3] = {0, 0, 0}, H[6] = {0, 0, 0, 0, 0, 0};
        for (size_t j = 0; j < n; ++j) {
            double e[3] = {d[3 * j] / h, d[3 * j + 1] / h, d[3 * j + 2] / h};
            double t = dn + l[0] * e[0] + l[1] * e[1] + l[2] * e[2], r = 1 / t, r2 = r * r;
            for (int k = 0; k < 3; ++k)
                g[k] += e[k] * r;
            H[0] += e[0] * e[0] * r2, H[1] += e[0] * e[1] * r2, H[2] += e[0] * e[2] * r2;
            H[3] += e[1] * e[1] * r2, H[4] += e[1] * e[2] * r2, H[5] += e[2] * e[2] * r2;
        }
        double gn = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (gn <= 1e-15 * dn) break;
        /* step = (-Hessian)^-1 g, -Hessian = [H] SPD: Cholesky */
        double a = H[0], b = H[1], c = H[2], e = H[3], fh = H[4], k5 = H[5];
        double l11 = sqrt(a);
        if (!(l11 > 0)) {
            ok = 0;
            break;
        }
        double l21 = b / l11, l31 = c / l11, l22s = e - l21 * l21;
        if (!(l22s > 0)) {
            ok = 0;
            break;
        }
        double l22 = sqrt(l22s), l32 = (fh - l31 * l21) / l22, l33s = k5 - l31 * l31 - l32 * l32;
        if (!(l33s > 0)) {
            ok = 0;
            break;
        }
        double l33 = sqrt(l33s);
        double y1 = g[0] / l11, y2 = (g[1] - l21 * y1) / l22,
               y3 = (g[2] - l31 * y1 - l32 * y2) / l33;
        double s3 = y3 / l33, s2 = (y2 - l32 * s3) / l22, s1 = (y1 - l21 * s2 - l31 * s3) / l11;
        double step[3] = {s1, s2, s3}, slope = g[0] * s1 + g[1] * s2 + g[2] * s3;
        /* backtracking: every n + lambda.e_j > 0 and sufficient increase of F */
        double alpha = 1, fnew = 0;
        for (;;) {
            double lt[3] = {l[0] + alpha * s1, l[1] + alpha * s2, l[2] + alpha * s3};
            int feasible = 1;
            fnew = 0;
            for (size_t j = 0; j < n && feasible; ++j) {
                double t =
                    dn + (lt[0] * d[3 * j] + lt[1] * d[3 * j + 1] + lt[2] * d[3 * j + 2]) / h;
                if (t > 0)
                    fnew += log(t);
                else
                    feasible = 0;
            }
            if (feasible && fnew >= f + 1e-4 * alpha * slope - 1e-13 * fabs(f)) break;
            alpha *= 0.5;
            if (alpha < 1e-12) break;
        }
        if (alpha < 1e-12) break; /* no progress: converged to round-off, checked below */
        for (int k = 0; k < 3; ++k)
            l[k] += alpha * step[k];
        f = fnew;
        if (sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]) > 1e12) {
            ok = 0; /* F unbounded: x_i is not inside the hull of its neighbours */
            break;
        }
    }
    double sum = 0, g[3] = {0, 0, 0};
    for (size_t j = 0; ok && j < n; ++j) {
        double t = dn + (l[0] * d[3 * j] + l[1] * d[3 * j + 1] + l[2] * d[3 * j + 2]) / h;
        if (!(t > 0)) {
            ok = 0;
            break;
        }
        w[j] = 1 / t;
        sum += w[j];
        for (int k = 0; k < 3; ++k)
            g[k] += w[j] * d[3 * j + k];
    }
    /* accept only a converged maximiser: the weights reproduce x_i to round-off */
    if (ok && sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) > 1e-12 * h) ok = 0;
    if (!ok) {
        for (size_t j = 0; j < n; ++j)
            w[j] = 1 / (dn ? dn : 1);
        lambda[0] = lambda[1] = lambda[2] = 0;
        *mu = dn;
        return -1;
    }
    /* sum is 1 - lambda.g / n: at convergence 1 to round-off; normalising keeps it exact */
    for (size_t j = 0; j < n; ++j)
        w[j] /= sum;
    for (int k = 0; k < 3; ++k)
        lambda[k] = l[k] / h * sum;
    *mu = dn * sum;
    return 0;
}

static void lbwarp_destroy(void *state)
{
    lbwarp *w = state;
    if (!w) return;
    if (w->numeric) umfpack_dl_free_numeric(&w->numeric);
    cm_warp_nodes_destroy(&w->nodes);
    free(w->ib_start);
    free(w->ib_node);
    free(w->ib_w);
    free(w->ap);
    free(w->ai);
    free(w->ax);
    free(w->b);
    free(w->x);
    free(w);
}

static size_t lbwarp_fallback_nodes(const void *state)
{
    return state ? ((const lbwarp *)state)->n_fallback : 0;
}

/* Node -> volume cells incidence, compressed rows. */
static cm_status node_cells(cm_context *ctx, const cm_mesh *mesh, int64_t **start, int64_t **cells,
                            size_t *max_len)
{
    size_t nn = mesh->n_nodes;
    int64_t *st = calloc(nn + 1, sizeof *st), *buf = NULL, *cl = NULL;
    size_t cap = 0, total = 0;
    *max_len = 1;
    if (!st) goto nomem;
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t c = 0; c < mesh->n_cells; ++c) {
            if (!cm_warp_is_volume_cell(mesh, c)) continue;
            size_t len = (size_t)(mesh->offset[c + 1] - mesh->offset[c]);
            if (len > cap) {
                free(buf);
                cap = 2 * len;
                if (!(buf = malloc(cap * sizeof *buf))) goto nomem;
            }
            size_t k = cm_warp_cell_nodes(mesh, c, buf);
            if (k > *max_len) *max_len = k;
            for (size_t i = 0; i < k; ++i) {
                if (pass == 0)
                    ++st[buf[i] + 1];
                else
                    cl[st[buf[i]]++] = (int64_t)c;
            }
        }
        if (pass == 0) {
            for (size_t v = 0; v < nn; ++v)
                st[v + 1] += st[v];
            total = (size_t)st[nn];
            if (!(cl = malloc((total ? total : 1) * sizeof *cl))) goto nomem;
        } else {
            for (size_t v = nn; v > 0; --v)
                st[v] = st[v - 1];
            st[0] = 0;
        }
    }
    free(buf);
    *start = st;
    *cells = cl;
    return CM_OK;
nomem:
    free(st);
    free(buf);
    free(cl);
    return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
}

static cm_status umfpack_failed(cm_context *ctx, const char *what, int status)
{
    return cm_error(ctx, status == UMFPACK_ERROR_out_of_memory ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                    "cm_warp_create: lbwarp: UMFPACK %s failed (status %d%s)", what, status,
                    status == UMFPACK_WARNING_singular_matrix
                        ? ": singular, a component without constrained nodes?"
                        : "");
}

static cm_status lbwarp_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                               const unsigned char *constrained, const cm_warp_options *opt,
                               void **state)
{
    (void)opt;
    lbwarp *w = calloc(1, sizeof *w);
    if (!w) return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
    int64_t *nc_start = NULL, *nc_cells = NULL, *stamp = NULL, *nb = NULL, *cellbuf = NULL;
    SuiteSparse_long *ti = NULL, *tj = NULL;
    double *tx = NULL, *dxyz = NULL, *wt = NULL;
    void *symbolic = NULL;
    size_t max_len = 1, ii = 0, nt = 0, cap_t = 0, cap_ib = 0;
    cm_status s = cm_warp_nodes_create(ctx, mesh, b, constrained, &w->nodes);
    if (s < 0) goto fail;
    const cm_warp_nodes *nd = w->nodes;
    size_t nf = nd->n_free;
    if (nf == 0) {
        *state = w;
        return CM_OK;
    }
    double t0 = cm_wtime(), t1 = 0, t2 = 0;
    if ((s = node_cells(ctx, mesh, &nc_start, &nc_cells, &max_len)) < 0) goto fail;
    stamp = malloc(mesh->n_nodes * sizeof *stamp);
    w->ib_start = malloc((nf + 1) * sizeof *w->ib_start);
    cellbuf = malloc(max_len * sizeof *cellbuf);
    if (!stamp || !w->ib_start || !cellbuf) goto nomem;
    for (size_t v = 0; v < mesh->n_nodes; ++v)
        stamp[v] = -1;
    w->ib_start[0] = 0;
    size_t nb_cap = 0;
    for (size_t i = 0; i < nf; ++i) {
        int64_t v = nd->free_nodes[i];
        /* neighbours: the distinct other nodes of the cells around v */
        size_t n = 0;
        for (int64_t p = nc_start[v]; p < nc_start[v + 1]; ++p) {
            size_t k = cm_warp_cell_nodes(mesh, (size_t)nc_cells[p], cellbuf);
            for (size_t q = 0; q < k; ++q) {
                int64_t u = cellbuf[q];
                if (u == v || stamp[u] == (int64_t)i) continue;
                stamp[u] = (int64_t)i;
                if (n == nb_cap) {
                    nb_cap = nb_cap ? 2 * nb_cap : 64;
                    int64_t *a = realloc(nb, nb_cap * sizeof *a);
                    double *c = realloc(dxyz, 3 * nb_cap * sizeof *c);
                    if (a) nb = a;
                    if (c) dxyz = c;
                    double *e = realloc(wt, nb_cap * sizeof *e);
                    if (e) wt = e;
                    if (!a || !c || !e) goto nomem;
                }
                nb[n++] = u;
            }
        }
        for (size_t j = 0; j < n; ++j)
            for (int k = 0; k < 3; ++k)
                dxyz[3 * j + k] = mesh->xyz[3 * nb[j] + k] - mesh->xyz[3 * v + k];
        double lambda[3], mu;
        if (cm_lbwarp_weights(dxyz, n, wt, lambda, &mu) < 0) ++w->n_fallback;
        /* row i of I - W_II (triplets) and of W_IB */
        if (nt + n + 1 > cap_t || ii + n > cap_ib) {
            size_t ct = 2 * (nt + n + 1), cb = 2 * (ii + n);
            SuiteSparse_long *a = realloc(ti, ct * sizeof *a);
            if (a) ti = a;
            SuiteSparse_long *c = realloc(tj, ct * sizeof *c);
            if (c) tj = c;
            double *e = realloc(tx, ct * sizeof *e);
            if (e) tx = e;
            int64_t *g = realloc(w->ib_node, cb * sizeof *g);
            if (g) w->ib_node = g;
            double *h = realloc(w->ib_w, cb * sizeof *h);
            if (h) w->ib_w = h;
            if (!a || !c || !e || !g || !h) goto nomem;
            cap_t = ct;
            cap_ib = cb;
        }
        ti[nt] = tj[nt] = (SuiteSparse_long)i;
        tx[nt++] = 1;
        for (size_t j = 0; j < n; ++j) {
            int64_t fj = nd->free_index[nb[j]];
            if (fj >= 0) {
                ti[nt] = (SuiteSparse_long)i;
                tj[nt] = (SuiteSparse_long)fj;
                tx[nt++] = -wt[j];
            } else {
                w->ib_node[ii] = nb[j];
                w->ib_w[ii++] = wt[j];
            }
        }
        w->ib_start[i + 1] = (int64_t)ii;
    }
    if ((s = cm_progress(ctx, "lbwarp weights", 1, 1)) < 0) goto fail;
    t1 = cm_wtime();
    if (w->n_fallback)
        cm_log(ctx, CM_LOG_WARNING,
               "cm_warp_create: lbwarp: %zu of %zu free nodes are not strictly inside the convex "
               "hull of their neighbours; they use uniform (Laplacian) weights",
               w->n_fallback, nf);

    w->ap = malloc((nf + 1) * sizeof *w->ap);
    w->ai = malloc((nt ? nt : 1) * sizeof *w->ai);
    w->ax = malloc((nt ? nt : 1) * sizeof *w->ax);
    w->b = malloc(nf * sizeof *w->b);
    w->x = malloc(nf * sizeof *w->x);
    if (!w->ap || !w->ai || !w->ax || !w->b || !w->x) goto nomem;
    SuiteSparse_long st =
        umfpack_dl_triplet_to_col((SuiteSparse_long)nf, (SuiteSparse_long)nf, (SuiteSparse_long)nt,
                                  ti, tj, tx, w->ap, w->ai, w->ax, NULL);
    if (st != UMFPACK_OK) {
        s = umfpack_failed(ctx, "assembly", (int)st);
        goto fail;
    }
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
    umfpack_dl_defaults(control);
    control[UMFPACK_PRL] = 0; /* the library never prints */
    /* METIS instead of the default AMD: on 3D meshes less than half the fill, and 5x faster
     * (115k unknowns: LU nnz 89M against 207M, 18 s against 87 s; RESULTS.md) */
    control[UMFPACK_ORDERING] = UMFPACK_ORDERING_METIS;
    st = umfpack_dl_symbolic((SuiteSparse_long)nf, (SuiteSparse_long)nf, w->ap, w->ai, w->ax,
                             &symbolic, control, info);
    if (st != UMFPACK_OK) {
        s = umfpack_failed(ctx, "symbolic analysis", (int)st);
        goto fail;
    }
    t2 = cm_wtime();
    /* UMFPACK's factorisation is one call that cannot stop: the last point before it */
    if ((s = cm_progress(ctx, "lbwarp factorise", 0, 1)) < 0) goto fail;
    st = umfpack_dl_numeric(w->ap, w->ai, w->ax, symbolic, &w->numeric, control, info);
    if (st != UMFPACK_OK) {
        s = umfpack_failed(ctx, "factorisation", (int)st);
        goto fail;
    }
    cm_log(ctx, CM_LOG_DEBUG,
           "lbwarp: %zu unknowns, %zu nonzeros, LU nnz %.0f: weights %.3f s, ordering %.3f s, "
           "factorisation %.3f s",
           nf, nt, info[UMFPACK_LNZ] + info[UMFPACK_UNZ], t1 - t0, t2 - t1, cm_wtime() - t2);
    umfpack_dl_free_symbolic(&symbolic);
    symbolic = NULL;
    if ((s = cm_progress(ctx, "lbwarp factorise", 1, 1)) < 0) goto fail;
    free(nc_start);
    free(nc_cells);
    free(stamp);
    free(nb);
    free(cellbuf);
    free(ti);
    free(tj);
    free(tx);
    free(dxyz);
    free(wt);
    *state = w;
    return CM_OK;
nomem:
    s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
fail:
    if (symbolic) umfpack_dl_free_symbolic(&symbolic);
    free(nc_start);
    free(nc_cells);
    free(stamp);
    free(nb);
    free(cellbuf);
    free(ti);
    free(tj);
    free(tx);
    free(dxyz);
    free(wt);
    lbwarp_destroy(w);
    return s;
}

static cm_status lbwarp_apply(cm_context *ctx, void *state, double *disp, double *residual)
{
    lbwarp *w = state;
    *residual = 0;
    const cm_warp_nodes *nd = w->nodes;
    size_t nf = nd->n_free;
    if (nf == 0) return CM_OK;
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
    umfpack_dl_defaults(control);
    control[UMFPACK_PRL] = 0;
    /* no iterative refinement: each step would cost a product and a solve more, and the
     * factor alone reproduces affine motions to ~1e-16 (test_warp_staten) */
    control[UMFPACK_IRSTEP] = 0;
    for (int k = 0; k < 3; ++k) {
        for (size_t i = 0; i < nf; ++i) {
            double s = 0;
            for (int64_t p = w->ib_start[i]; p < w->ib_start[i + 1]; ++p)
                s += w->ib_w[p] * disp[3 * w->ib_node[p] + k];
            w->b[i] = s;
        }
        SuiteSparse_long st =
            umfpack_dl_solve(UMFPACK_A, w->ap, w->ai, w->ax, w->x, w->b, w->numeric, control, info);
        if (st != UMFPACK_OK)
            return cm_error(ctx, CM_ERR_NUMERIC,
                            "cm_warp_apply: lbwarp: UMFPACK solve failed "
                            "(status %ld)",
                            (long)st);
        for (size_t i = 0; i < nf; ++i)
            disp[3 * nd->free_nodes[i] + k] = w->x[i];
        cm_status p = cm_progress(ctx, "warp", k + 1, 3); /* a solve per coordinate */
        if (p < 0) return p;
    }
    return CM_OK;
}

static cm_status lbwarp_apply_transpose(cm_context *ctx, void *state, const double *v, double *out)
{
    lbwarp *w = state;
    const cm_warp_nodes *nd = w->nodes;
    cm_warp_nodes_add_identity(nd, v, out);
    size_t nf = nd->n_free;
    if (nf == 0) return CM_OK;
    double control[UMFPACK_CONTROL], info[UMFPACK_INFO];
    umfpack_dl_defaults(control);
    control[UMFPACK_PRL] = 0;
    control[UMFPACK_IRSTEP] = 0; /* as apply: the factor alone, so the two stay transposes */
    for (int k = 0; k < 3; ++k) {
        for (size_t i = 0; i < nf; ++i)
            w->b[i] = v[3 * nd->free_nodes[i] + k];
        /* UMFPACK_At solves A^T x = b with the factor of A (real: the same as UMFPACK_Aat) */
        SuiteSparse_long st = umfpack_dl_solve(UMFPACK_At, w->ap, w->ai, w->ax, w->x, w->b,
                                               w->numeric, control, info);
        if (st != UMFPACK_OK)
            return cm_error(ctx, CM_ERR_NUMERIC,
                            "cm_warp_apply_transpose: lbwarp: UMFPACK solve failed (status %ld)",
                            (long)st);
        for (size_t i = 0; i < nf; ++i)
            for (int64_t p = w->ib_start[i]; p < w->ib_start[i + 1]; ++p)
                out[3 * w->ib_node[p] + k] += w->ib_w[p] * w->x[i];
        cm_status p = cm_progress(ctx, "warp transpose", k + 1, 3);
        if (p < 0) return p;
    }
    return CM_OK;
}

const cm_warp_method_ops cm_warp_lbwarp = {
    "lbwarp",       lbwarp_create,         lbwarp_apply,
    lbwarp_destroy, lbwarp_fallback_nodes, lbwarp_apply_transpose,
    NULL, NULL};
