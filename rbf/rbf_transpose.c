/* The reverse product of "solve at the centres, then evaluate at points" (cm_rbf_evaluate_
 * transpose), for adjoint gradients (docs/DESIGN.md, "Gradients").
 *
 * With A = [Phi P; P' 0] (symmetric), E the kernel values points x centres and Q the
 * polynomial basis at the points, evaluate(solve(d)) = [E Q] A^-1 [d; 0], so its transpose
 * is [I 0] A^-1 [E' v; Q' v]: the weights of one more solve of the same system. E' v is a
 * kernel sum with the roles swapped (sources at the points with weights v, targets the
 * centres), summed by the code evaluation uses (plain blocked sums for a dense fit,
 * compensated ones or the treecode for an iterative one).
 *
 * Why a particular solution: every solver (the projected Cholesky, FGMRES in the null space
 * of P', PETSc) solves with a zero polynomial right-hand side, while here h = Q' v is not
 * zero. A w0 with P' w0 = h on dim + 1 well-spread, affinely independent centres reduces
 * the system to the one they solve: [Phi P; P' 0] [w1; q] = [g - Phi w0; 0] has the
 * solution w = w0 + w1. w0 costs a (dim+1) x (dim+1) solve and Phi w0 (m (dim+1) kernel
 * values), so the reverse product costs one transposed evaluation and one solve, as apply.
 * The centres are picked greedily (farthest from the centroid, then farthest from the
 * point, the line, the plane so far), so the small system is as well conditioned as the
 * centres allow and w0 stays of the size of h; the unisolvency check of create guarantees
 * that they span.
 * Why the dense refinement goes further than apply's (CM_RBF_TRANSPOSE_REFINE_TOL): the
 * result is the weights of this solve, and a residual e moves them by A^-1 e, which the
 * forward product smooths away (E A^-1 e, bounded by the cardinal functions) but which is
 * here the output; the residual that is enough for apply (1e-11 of the data) left 2.5e-7
 * of max |J^T v| on a 3k-centre bore set.
 * All of it in the unit-box coordinates the fit uses (DESIGN, "Numerical
 * decisions"): the map is the same linear map of d whatever coordinates it is written in. */
#include "rbf_internal.h"
#include "iterative/rbf_iter.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The dense refinement of the reverse solve stops within this relative residual (apply's:
 * 1e-11): one step more than apply's where its first pass leaves 1e-13 (the pipe's O-grid,
 * 2,818 centres: 2.8e-13 -> 1e-15 in one step; a second to 8e-17 cost another 40 % of the
 * product for nothing a gradient sees). */
#define CM_RBF_TRANSPOSE_REFINE_TOL 1e-14

/* The distance of centre u (unit box) from the affine hull of the picked centres s[0..np),
 * squared, by Gram-Schmidt against the directions e (np - 1 orthonormal rows of 3). */
static double hull_dist2(const cm_rbf *r, size_t u, const size_t *s, int np, double e[][3])
{
    const size_t m = r->m;
    double x[3] = {0, 0, 0};
    for (int d = 0; d < r->dim; ++d) x[d] = r->c[(size_t)d * m + u] - r->c[(size_t)d * m + s[0]];
    for (int a = 0; a + 1 < np; ++a) {
        double t = x[0] * e[a][0] + x[1] * e[a][1] + x[2] * e[a][2];
        for (int d = 0; d < 3; ++d) x[d] -= t * e[a][d];
    }
    return x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
}

/* dim + 1 centres that span: the first farthest from the centroid, each next the farthest
 * from the affine hull of those before. 0, or -1 if they do not span (not after create). */
static int pick_support(const cm_rbf *r, size_t *s)
{
    const size_t m = r->m;
    const int dim = r->dim;
    double mean[3] = {0, 0, 0}, e[3][3];
    for (int d = 0; d < dim; ++d) {
        for (size_t u = 0; u < m; ++u) mean[d] += r->c[(size_t)d * m + u];
        mean[d] /= (double)m;
    }
    double best = -1.0;
    for (size_t u = 0; u < m; ++u) {
        double d2 = 0.0;
        for (int d = 0; d < dim; ++d) {
            double t = r->c[(size_t)d * m + u] - mean[d];
            d2 += t * t;
        }
        if (d2 > best) best = d2, s[0] = u;
    }
    for (int np = 1; np <= dim; ++np) {
        best = 0.0;
        for (size_t u = 0; u < m; ++u) {
            double d2 = hull_dist2(r, u, s, np, e);
            if (d2 > best) best = d2, s[np] = u;
        }
        if (!(best > 0.0)) return -1;
        /* the new direction, orthonormalised against the earlier ones */
        double x[3] = {0, 0, 0};
        for (int d = 0; d < dim; ++d)
            x[d] = r->c[(size_t)d * m + s[np]] - r->c[(size_t)d * m + s[0]];
        for (int a = 0; a + 1 < np; ++a) {
            double t = x[0] * e[a][0] + x[1] * e[a][1] + x[2] * e[a][2];
            for (int d = 0; d < 3; ++d) x[d] -= t * e[a][d];
        }
        double nx = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        for (int d = 0; d < 3; ++d) e[np - 1][d] = x[d] / nx;
    }
    return 0;
}

cm_status cm_rbf_evaluate_transpose(cm_context *ctx, cm_rbf *rbf, size_t n, const double *points,
                                    int ncomp, const double *v, double *out)
{
    if (!rbf || ncomp < 1 || !out || (n > 0 && (!points || !v)))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_rbf_evaluate_transpose: %s",
                        !rbf      ? "rbf is NULL"
                        : ncomp < 1 ? "ncomp < 1"
                        : !out    ? "out is NULL"
                        : !points ? "points is NULL"
                                  : "v is NULL");
    const size_t m = rbf->m, nc = (size_t)ncomp, k = (size_t)rbf->k;
    const int dim = rbf->dim, threads = cm_rbf_threads(ctx);
    memset(out, 0, rbf->m_in * nc * sizeof *out);
    if (n == 0) return CM_OK;
    cm_status st = CM_OK;
    /* The iterative reverse solve never stops looser than the RBF's default tolerance, for
     * the reason above: a tolerance chosen for the forward field (a study's 1e-6, the warp's
     * from the mesh: docs/DESIGN.md, "The warp's tolerance") moves a forward result by about
     * itself, but the reverse result by itself times the growth of the weights. Restored at
     * the end. */
    const double forward_tol = rbf->opt.tolerance;
    rbf->opt.tolerance = fmin(forward_tol, CM_RBF_DEFAULT_TOL);
    double *p = malloc(n * (size_t)dim * sizeof *p); /* dim x n SoA, unit-box coordinates */
    double *vs = malloc(n * nc * sizeof *vs);        /* nc x n SoA */
    double *g = malloc(m * nc * sizeof *g);          /* m x nc row-major: E' v, then Phi w0 */
    double *f = malloc(m * nc * sizeof *f);          /* m x nc col-major */
    double *w = malloc(m * nc * sizeof *w), *q = malloc(k * nc * sizeof *q);
    double *h = calloc(k * nc, sizeof *h); /* k x nc col-major: Q' v, then w0 */
    if (!p || !vs || !g || !f || !w || !q || !h) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_evaluate_transpose: out of memory for %zu "
                      "points", n);
        goto done;
    }
    for (size_t i = 0; i < n; ++i) {
        for (int d = 0; d < dim; ++d)
            p[(size_t)d * n + i] = (points[i * (size_t)dim + (size_t)d] - rbf->shift[d]) * rbf->scale;
        for (size_t c = 0; c < nc; ++c) {
            const double x = v[i * nc + c];
            if (!isfinite(x)) {
                st = cm_error(ctx, CM_ERR_NUMERIC,
                              "cm_rbf_evaluate_transpose: value %zu of point %zu is not finite",
                              c, i);
                goto done;
            }
            vs[c * n + i] = x;
        }
    }
    /* h = Q' v: the moments of v against 1 and the unit-box coordinates */
    for (size_t c = 0; c < nc; ++c)
        for (size_t i = 0; i < n; ++i) {
            const double x = vs[c * n + i];
            h[c * k] += x;
            for (int d = 0; d < dim; ++d) h[c * k + 1 + (size_t)d] += x * p[(size_t)d * n + i];
        }
    /* g = E' v, in chunks with progress as evaluate */
    const double t0 = cm_wtime();
    cm_rbf_tick tick;
    cm_rbf_tick_init(&tick, ctx, "rbf evaluate", (double)((nc + 3) / 4) * (double)n * (double)m);
    if (rbf->petsc && cm_rbf_petsc_evaluate_transpose(rbf, n, p, ncomp, vs, g, threads))
        ; /* collective: each rank its block of centres */
    else if (rbf->iter)
        cm_rbf_iterative_evaluate_transpose(rbf, n, p, ncomp, vs, g, threads, &tick);
    else
        for (size_t c0 = 0; c0 < nc; c0 += 4) {
            int gc = nc - c0 < 4 ? (int)(nc - c0) : 4;
            if (cm_rbf_kernel_sum_tick(rbf->kernel, dim, n, p, vs + c0 * n, gc, m, rbf->c, m,
                                       g + c0, nc, threads, &tick))
                break;
        }
    if ((st = cm_rbf_tick_finish(&tick)) < 0) goto done;
    st = CM_OK;
    const double t_sum = cm_wtime() - t0;

    /* the particular solution w0 (P' w0 = h) on the support s */
    size_t s[4];
    double pm[16], cs[12], w0s[16];
    if (pick_support(rbf, s) < 0) {
        st = cm_error(ctx, CM_ERR_INTERNAL,
                      "cm_rbf_evaluate_transpose: no %d centres span the polynomials", (int)k);
        goto done;
    }
    for (size_t j = 0; j < k; ++j) {
        pm[j * k] = 1.0; /* column j: the basis at centre s[j] */
        for (int d = 0; d < dim; ++d) {
            pm[j * k + 1 + (size_t)d] = rbf->c[(size_t)d * m + s[j]];
            cs[(size_t)d * k + j] = rbf->c[(size_t)d * m + s[j]];
        }
    }
    lapack_int ipiv[4];
    lapack_int info = LAPACKE_dgesv(LAPACK_COL_MAJOR, (lapack_int)k, (lapack_int)nc, pm,
                                    (lapack_int)k, ipiv, h, (lapack_int)k);
    if (info != 0) {
        st = cm_error(ctx, CM_ERR_NUMERIC,
                      "cm_rbf_evaluate_transpose: the polynomial system on the support is "
                      "singular (info %d)", (int)info);
        goto done;
    }
    /* f = E' v - Phi w0 (m (dim + 1) kernel values), the data of a zero-moment solve */
    for (size_t c0 = 0; c0 < nc; c0 += 4) {
        int gc = nc - c0 < 4 ? (int)(nc - c0) : 4;
        for (int a = 0; a < gc; ++a)
            memcpy(w0s + (size_t)a * k, h + (c0 + (size_t)a) * k, k * sizeof *w0s);
        cm_rbf_kernel_sum(rbf->kernel, dim, k, cs, w0s, gc, m, rbf->c, m, f, nc, 1);
        for (size_t u = 0; u < m; ++u)
            for (int a = 0; a < gc; ++a) {
                const size_t c = c0 + (size_t)a;
                g[u * nc + c] -= f[u * nc + (size_t)a];
            }
    }
    for (size_t u = 0; u < m; ++u)
        for (size_t c = 0; c < nc; ++c) f[c * m + u] = g[u * nc + c];
    /* (its scales are not committed: evaluate behaves as after the last cm_rbf_solve) */
    st = cm_rbf_solve_merged(ctx, rbf, nc, f, CM_RBF_TRANSPOSE_REFINE_TOL, w, q);
    if (st < 0) goto done;
    cm_log(ctx, CM_LOG_DEBUG,
           "cm_rbf_evaluate_transpose: %zu points x %zu centres: transposed sums %.3f s (%s), "
           "solve %.3f s",
           n, m, t_sum,
           rbf->iter && cm_rbf_iterative_transpose_was_fast(rbf) ? "treecode"
           : rbf->iter                                         ? "compensated"
                                                               : "plain",
           rbf->stats.solve_seconds);
    for (size_t c = 0; c < nc; ++c)
        for (size_t j = 0; j < k; ++j) w[c * m + s[j]] += h[c * k + j];
    /* merged duplicates: the solve took the value of the first input centre of each */
    for (size_t u = 0; u < m; ++u)
        for (size_t c = 0; c < nc; ++c) out[rbf->first[u] * nc + c] = w[c * m + u];
done:
    rbf->opt.tolerance = forward_tol;
    free(p), free(vs), free(g), free(f), free(w), free(q), free(h);
    return st;
}
