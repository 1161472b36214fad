/* The coarse problem of the two-level Schwarz preconditioner (rbf_schwarz.c) solved
 * inexactly, for coarse spaces too large for a dense factor (8 coarse^2 bytes: 16,000
 * centres 2 GB, 60,000 centres 29 GB): a few iterations of an inner FGMRES on the projected
 * r^3 system of the coarse centres, preconditioned by a two-level Schwarz of their own (the
 * same construction, recursively, with its own dense coarse level of at most coarse_max
 * centres). The preconditioner is then no longer a fixed linear operator; the outer solver is
 * flexible GMRES, which allows a different preconditioner at every iteration.
 * The coarse-to-fine product (the coarse interpolant at all m centres) is nc x m pairs, as
 * much as m / nc matvecs of the coarse problem: from CM_COARSE_TREE_PAIRS on it goes through
 * the treecode (rbf_treecode.c), whose error is far below what a preconditioner needs. */
#include "rbf_internal.h"
#include "sum/rbf_treecode.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* coarse-to-fine products of at least this many pairs use the treecode */
#define CM_COARSE_TREE_PAIRS 2e9
/* its accuracy relative to sum_j |w_j| phi_ij: a preconditioner needs a few digits only */
#define CM_COARSE_TREE_TOL 1e-10

struct cm_rbf_coarse_inner {
    cm_rbf sub;          /* the coarse centres as an r^3 problem of their own (sub.c owned) */
    cm_rbf_schwarz *pc;  /* its two-level Schwarz */
    double *q1;          /* 4 x nc col-major: orthonormal basis of the linear polynomials at
                          * the coarse centres (columns past the rank zero) */
    int maxit;
    double tol;
    cm_rbf_tree *tree;   /* over the coarse centres, for the coarse-to-fine product; or NULL */
    size_t bytes;
    long *stat;          /* [0] inner solves, [1] inner iterations in all (mutable counters
                          * behind a const handle: the applications are serial) */
};

/* v -= Q1 (Q1' v), twice */
static void project4(const double *q1, size_t n, double *v)
{
    for (int pass = 0; pass < 2; ++pass)
        for (int a = 0; a < 4; ++a) {
            const double *qa = q1 + (size_t)a * n;
            double s = cblas_ddot((int)n, qa, 1, v, 1);
            if (s != 0.0) cblas_daxpy((int)n, -s, qa, 1, v, 1);
        }
}

cm_status cm_rbf_coarse_inner_create(cm_context *ctx, const cm_rbf *r, size_t nc,
                                     const double *c_xyz, size_t m_fine, int threads,
                                     cm_rbf_coarse_inner **out)
{
    *out = NULL;
    cm_rbf_coarse_inner *ci = calloc(1, sizeof *ci);
    if (!ci) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (coarse)");
    ci->maxit = r->tun.coarse_inner;
    ci->tol = r->tun.coarse_inner_tol;
    ci->sub.kernel = r->kernel;
    ci->sub.dim = 3;
    ci->sub.k = 4;
    ci->sub.m = ci->sub.m_in = nc;
    ci->sub.scale = 1.0;
    /* the inner levels take the standard coarse rule (sqrt growth, dense, capped): the
     * caller's counts describe the outer coarse space */
    ci->sub.opt = r->opt;
    ci->sub.tun = r->tun;
    ci->sub.tun.coarse_inner = 0;
    ci->sub.tun.coarse_post = 0;
    ci->sub.tun.coarse_size = 2000;
    ci->sub.tun.coarse_grow = 1;
    ci->sub.tun.coarse_max = 8000;
    ci->sub.c = malloc(3 * nc * sizeof *ci->sub.c);
    ci->q1 = calloc(4 * nc, sizeof *ci->q1);
    ci->stat = calloc(2, sizeof *ci->stat);
    double *pq = malloc(4 * nc * sizeof *pq);
    cm_status st = CM_OK;
    if (!ci->sub.c || !ci->q1 || !ci->stat || !pq) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (coarse)");
        goto fail;
    }
    memcpy(ci->sub.c, c_xyz, 3 * nc * sizeof *ci->sub.c);
    /* Q1: rank-revealing QR of [1 x y z] at the coarse centres */
    for (size_t i = 0; i < nc; ++i) pq[i] = 1.0;
    memcpy(pq + nc, c_xyz, 3 * nc * sizeof *pq);
    lapack_int jpvt[4] = {0, 0, 0, 0};
    double tau[4];
    const lapack_int ln = (lapack_int)nc;
    if (LAPACKE_dgeqp3(LAPACK_COL_MAJOR, ln, 4, pq, ln, jpvt, tau) != 0) {
        st = cm_error(ctx, CM_ERR_INTERNAL, "cm_rbf_create: dgeqp3 failed (coarse)");
        goto fail;
    }
    int rk = 0;
    const double r00 = fabs(pq[0]);
    while (rk < 4 && fabs(pq[(size_t)rk * nc + (size_t)rk]) > 1e-9 * r00) ++rk;
    if (rk > 0 && LAPACKE_dorgqr(LAPACK_COL_MAJOR, ln, rk, rk, pq, ln, tau) != 0) {
        st = cm_error(ctx, CM_ERR_INTERNAL, "cm_rbf_create: dorgqr failed (coarse)");
        goto fail;
    }
    memcpy(ci->q1, pq, (size_t)rk * nc * sizeof *pq);
    st = cm_rbf_schwarz_create(ctx, &ci->sub, threads, &ci->pc);
    if (st != CM_OK) goto fail;
    ci->bytes = 7 * nc * sizeof(double) + cm_rbf_schwarz_bytes(ci->pc);
    if ((double)nc * (double)m_fine >= CM_COARSE_TREE_PAIRS) {
        int order = 0;
        double theta = 0.0;
        cm_rbf_tree_params(CM_COARSE_TREE_TOL, &order, &theta);
        ci->tree = cm_rbf_tree_create(nc, ci->sub.c, order, theta); /* NULL: direct sums */
        if (ci->tree) ci->bytes += cm_rbf_tree_bytes(ci->tree);
    }
    free(pq);
    *out = ci;
    return CM_OK;
fail:
    free(pq);
    cm_rbf_coarse_inner_destroy(&ci);
    return st;
}

void cm_rbf_coarse_inner_destroy(cm_rbf_coarse_inner **pci)
{
    if (!pci || !*pci) return;
    cm_rbf_coarse_inner *ci = *pci;
    cm_rbf_schwarz_destroy(&ci->pc);
    cm_rbf_tree_destroy(&ci->tree);
    free(ci->sub.c);
    free(ci->q1);
    free(ci->stat);
    free(ci);
    *pci = NULL;
}

size_t cm_rbf_coarse_inner_bytes(const cm_rbf_coarse_inner *ci) { return ci ? ci->bytes : 0; }

const cm_rbf_schwarz *cm_rbf_coarse_inner_pc(const cm_rbf_coarse_inner *ci)
{
    return ci ? ci->pc : NULL;
}

void cm_rbf_coarse_inner_stats(const cm_rbf_coarse_inner *ci, long *solves, long *iterations)
{
    *solves = ci ? ci->stat[0] : 0;
    *iterations = ci ? ci->stat[1] : 0;
}

/* Lock-step FGMRES for ncomp components, at most maxit iterations, no restart: stops when
 * every component's residual 2-norm is below tol x its start. x: ncomp x nc SoA, the data
 * in, the weights out (null space of P'). Returns 0, or -1 on allocation failure (x then
 * holds zero weights: the caller's correction is then the local part alone). */
int cm_rbf_coarse_inner_solve(const cm_rbf_coarse_inner *ci, int ncomp, double *x, int threads)
{
    const size_t n = ci->sub.m, blk = (size_t)ncomp * n;
    const int R = ci->maxit;
    double *v = malloc((size_t)(R + 1) * blk * sizeof *v);
    double *z = malloc((size_t)R * blk * sizeof *z);
    double *av = malloc(blk * sizeof *av);
    double *h = calloc((size_t)ncomp * (size_t)(R + 1) * (size_t)R, sizeof *h);
    double *cs = malloc((size_t)ncomp * 3 * (size_t)(R + 1) * sizeof *cs);
    if (!v || !z || !av || !h || !cs) {
        free(v), free(z), free(av), free(h), free(cs);
        memset(x, 0, blk * sizeof *x);
        return -1;
    }
    double *sn = cs + (size_t)ncomp * (size_t)(R + 1), *gv = sn + (size_t)ncomp * (size_t)(R + 1);
    double beta[4];
    for (int c = 0; c < ncomp; ++c) {
        double *v0 = v + (size_t)c * n;
        memcpy(v0, x + (size_t)c * n, n * sizeof *v0);
        project4(ci->q1, n, v0);
        beta[c] = cblas_dnrm2((int)n, v0, 1);
        if (beta[c] > 0.0) cblas_dscal((int)n, 1.0 / beta[c], v0, 1);
        for (int j = 0; j <= R; ++j) gv[(size_t)c * (size_t)(R + 1) + (size_t)j] = 0.0;
        gv[(size_t)c * (size_t)(R + 1)] = beta[c];
    }
    int jn = 0;
    for (int j = 0; j < R; ++j) {
        double *vj = v + (size_t)j * blk, *zj = z + (size_t)j * blk, *vn = vj + blk;
        cm_rbf_schwarz_apply(ci->pc, &ci->sub, ncomp, vj, zj, threads);
        for (int c = 0; c < ncomp; ++c) project4(ci->q1, n, zj + (size_t)c * n);
        /* plain sums: their rounding, eps sum |z| phi, is far below what is asked here */
        cm_rbf_kernel_sum(ci->sub.kernel, 3, n, ci->sub.c, zj, ncomp, n, ci->sub.c, n, av,
                          (size_t)ncomp, threads);
        int done = 1;
        for (int c = 0; c < ncomp; ++c) {
            double *w = vn + (size_t)c * n, *hc = h + ((size_t)c * (size_t)R + (size_t)j) * (size_t)(R + 1);
            double *csc = cs + (size_t)c * (size_t)(R + 1), *snc = sn + (size_t)c * (size_t)(R + 1);
            double *g = gv + (size_t)c * (size_t)(R + 1);
            for (size_t i = 0; i < n; ++i) w[i] = av[i * (size_t)ncomp + (size_t)c];
            if (beta[c] == 0.0) {
                memset(w, 0, n * sizeof *w);
                hc[j] = 1.0; /* a harmless pivot: g is zero for this component */
                csc[j] = 1.0, snc[j] = 0.0;
                continue;
            }
            project4(ci->q1, n, w);
            for (int pass = 0; pass < 2; ++pass) /* classical Gram-Schmidt, twice */
                for (int i = 0; i <= j; ++i) {
                    const double *vi = v + (size_t)i * blk + (size_t)c * n;
                    double s = cblas_ddot((int)n, vi, 1, w, 1);
                    hc[i] = (pass ? hc[i] : 0.0) + s;
                    cblas_daxpy((int)n, -s, vi, 1, w, 1);
                }
            double hn = cblas_dnrm2((int)n, w, 1);
            hc[j + 1] = hn;
            if (hn > 0.0) cblas_dscal((int)n, 1.0 / hn, w, 1);
            for (int i = 0; i < j; ++i) {
                double t = csc[i] * hc[i] + snc[i] * hc[i + 1];
                hc[i + 1] = -snc[i] * hc[i] + csc[i] * hc[i + 1];
                hc[i] = t;
            }
            double d = hypot(hc[j], hc[j + 1]);
            csc[j] = d > 0.0 ? hc[j] / d : 1.0;
            snc[j] = d > 0.0 ? hc[j + 1] / d : 0.0;
            hc[j] = d > 0.0 ? d : 1.0;
            hc[j + 1] = 0.0;
            g[j + 1] = -snc[j] * g[j];
            g[j] *= csc[j];
            if (fabs(g[j + 1]) > ci->tol * beta[c] && hn > 0.0) done = 0;
        }
        jn = j + 1;
        if (done) break;
    }
    /* x = Z y, H y = g */
    memset(x, 0, blk * sizeof *x);
    for (int c = 0; c < ncomp; ++c) {
        if (beta[c] == 0.0) continue;
        double y[64], *yy = jn <= 64 ? y : malloc((size_t)jn * sizeof *yy);
        if (!yy) continue;
        const double *g = gv + (size_t)c * (size_t)(R + 1);
        for (int i = jn - 1; i >= 0; --i) {
            double s = g[i];
            for (int l = i + 1; l < jn; ++l)
                s -= h[((size_t)c * (size_t)R + (size_t)l) * (size_t)(R + 1) + (size_t)i] * yy[l];
            yy[i] = s / h[((size_t)c * (size_t)R + (size_t)i) * (size_t)(R + 1) + (size_t)i];
        }
        double *xc = x + (size_t)c * n;
        for (int i = 0; i < jn; ++i)
            cblas_daxpy((int)n, yy[i], z + (size_t)i * blk + (size_t)c * n, 1, xc, 1);
        if (yy != y) free(yy);
    }
    ci->stat[0] += 1;
    ci->stat[1] += jn;
    free(v), free(z), free(av), free(h), free(cs);
    return 0;
}

int cm_rbf_coarse_inner_to_fine(const cm_rbf_coarse_inner *ci, int ncomp, const double *w,
                                size_t m, const double *c, double *out, int threads)
{
    if (!ci || !ci->tree) return 1;
    return cm_rbf_tree_sum(ci->tree, w, ncomp, m, c, m, out, (size_t)ncomp, threads) == 0 ? 0 : 1;
}
