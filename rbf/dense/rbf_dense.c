/* The dense path: the null-space projected system sign * Q2' A Q2 assembled in packed
 * storage and factored (cholesky_blocked.c, cholesky_lookahead.c), and one projected solve
 * with that factor. rbf.c says why the projection and the packed format. */
#include "rbf_internal.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* OpenBLAS back on one thread after a threaded call (rbf.c says why) */
static void blas_threads(int n) { openblas_set_num_threads(n > 0 ? n : 1); }

/* For the message when the Cholesky factorisation fails: two centres closer than 1e-6 of the unit box (input
 * indices a, b; dist in unit-box units). Returns 0 if there are none. */
static int closest_pair(const cm_rbf *r, size_t *a, size_t *b, double *dist)
{
    int found = 0;
    size_t *rep = malloc(r->m * sizeof *rep), *first = malloc(r->m * sizeof *first);
    if (rep && first && cm_rbf_merge_duplicates(r->dim, r->m, r->c, 1e-6, rep, first) < (long)r->m) {
        for (size_t u = 0; u < r->m && !found; ++u) {
            size_t v = first[rep[u]];
            if (v == u) continue;
            double d2 = 0.0;
            for (int d = 0; d < r->dim; ++d) {
                double t = r->c[(size_t)d * r->m + u] - r->c[(size_t)d * r->m + v];
                d2 += t * t;
            }
            *a = r->first[v];
            *b = r->first[u];
            *dist = sqrt(d2);
            found = 1;
        }
    }
    free(rep);
    free(first);
    return found;
}

/* Builds sign * Q2' A Q2 (lower triangle, packed) and factors it. */
cm_status cm_rbf_dense_factor(cm_context *ctx, cm_rbf *r, int threads)
{
    const size_t m = r->m;
    const int k = r->k;
    const size_t n2 = m - (size_t)k;
    if (n2 == 0) return CM_OK; /* k centres: the interpolant is the linear polynomial */
    /* LAPACK's 32-bit indices address the packed factor up to n(n+1)/2 < 2^31 */
    if (n2 > 60000)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_rbf_create: %zu centres is too many for one dense system (at most "
                        "60000; split the mesh into components)",
                        m);

    cm_status st = CM_OK;
    double *v = calloc(m * (size_t)k, sizeof *v);
    double *wv = malloc(m * (size_t)k * sizeof *wv);
    double *z = malloc(m * (size_t)k * sizeof *z);
    double t[16] = {0}, s[16] = {0}, vw[16] = {0}, tmp[16] = {0};
    double ta = cm_wtime();
    /* populated in one call: cheaper than faulting it in page by page while it is assembled */
    r->chol = cm_alloc_large(n2 * (n2 + 1) / 2 * sizeof(double), 1);
    ta = cm_wtime() - ta;
    if (!v || !wv || !z || !r->chol) {
        st = cm_error(ctx, CM_ERR_NOMEM,
                      "cm_rbf_create: out of memory for the %zu x %zu system (%.2f GB)", n2, n2,
                      (double)n2 * (double)(n2 + 1) * 4e-9);
        goto done;
    }
    /* explicit V: unit diagonal, zeros above */
    for (int q = 0; q < k; ++q) {
        v[(size_t)q * m + (size_t)q] = 1.0;
        for (size_t i = (size_t)q + 1; i < m; ++i) v[(size_t)q * m + i] = r->qr[(size_t)q * m + i];
    }
    lapack_int info = LAPACKE_dlarft(LAPACK_COL_MAJOR, 'F', 'C', (lapack_int)m, k, v,
                                     (lapack_int)m, r->tau, t, k);
    if (info != 0) {
        st = cm_error(ctx, CM_ERR_INTERNAL, "cm_rbf_create: dlarft failed (info %d)", (int)info);
        goto done;
    }
    double t0 = cm_wtime();
    /* W = A V (row-major m x k), by kernel sums: A is never stored */
    cm_rbf_kernel_sum(r->kernel, r->dim, m, r->c, v, k, m, r->c, m, wv, (size_t)k, threads);
    /* vw = V' W (k x k), s = T' vw T */
    for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) {
            double acc = 0.0;
            for (size_t i = 0; i < m; ++i) acc += v[(size_t)a * m + i] * wv[i * (size_t)k + (size_t)b];
            vw[a * k + b] = acc;
        }
    for (int a = 0; a < k; ++a) /* tmp = vw T; t is col-major upper: T(i,j) = t[i + j k] */
        for (int b = 0; b < k; ++b) {
            double acc = 0.0;
            for (int c = 0; c < k; ++c) acc += vw[a * k + c] * t[c + b * k];
            tmp[a * k + b] = acc;
        }
    for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b) {
            double acc = 0.0;
            for (int c = 0; c < k; ++c) acc += t[c + a * k] * tmp[c * k + b];
            s[a * k + b] = acc;
        }
    /* Z = W T - V s / 2 (col-major m x k) */
    for (size_t i = 0; i < m; ++i)
        for (int b = 0; b < k; ++b) {
            double acc = 0.0;
            for (int c = 0; c < k; ++c)
                acc += wv[i * (size_t)k + (size_t)c] * t[c + b * k] - 0.5 * v[(size_t)c * m + i] * s[c * k + b];
            z[(size_t)b * m + i] = acc;
        }
    /* in chunks of columns with progress: at 20k centres the assembly is seconds */
    cm_rbf_tick tick;
    cm_rbf_tick_init(&tick, ctx, "rbf assemble", (double)n2 * (double)(n2 + 1) / 2);
    cm_rbf_assemble_projected_tick(r->kernel, r->dim, m, r->c, k, v, z, r->sign, r->chol, threads,
                                   &tick);
    if ((st = cm_rbf_tick_finish(&tick)) < 0) goto done;
    double t1 = cm_wtime();

    int blas_n = 1;
    st = cm_blas_threads(ctx, "cm_rbf_create", threads, &blas_n);
    if (st != CM_OK) goto done;
    /* dpftrf's arithmetic, panel by panel, so that progress moves (cholesky_blocked.c) */
    info = cm_rbf_cholesky_rfp(ctx, (int)n2, r->chol, 0);
    double t2 = cm_wtime();
    blas_threads(1);
    cm_log(ctx, CM_LOG_DEBUG,
           "cm_rbf_create: %zu centres, %d threads (BLAS %d): memory %.3f s, projection + "
           "assembly %.3f s, cholesky %.3f s",
           m, threads, blas_n, ta, t1 - t0, t2 - t1);
    if (info == CM_RBF_CHOLESKY_INTERRUPTED) {
        st = CM_ERR_INTERRUPTED; /* the message is cm_progress's */
    } else if (info > 0) {
        size_t a, b;
        double dist;
        if (closest_pair(r, &a, &b, &dist))
            st = cm_error(ctx, CM_ERR_NUMERIC,
                          "cm_rbf_create: Cholesky of the projected %zu x %zu %s system failed "
                          "at pivot %d (not definite): centres %zu and %zu are only %.3g apart "
                          "(%.2g of the bounding box), too close to resolve but not close "
                          "enough to merge; merge or remove near-duplicate centres",
                          n2, n2, cm_rbf_kernel_name(r->kernel), (int)info, a, b, dist / r->scale,
                          dist);
        else
            st = cm_error(ctx, CM_ERR_NUMERIC,
                          "cm_rbf_create: Cholesky of the projected %zu x %zu %s system failed "
                          "at pivot %d (not definite): most likely near-duplicate centres "
                          "(closer than about 1e-6 of the bounding box but not merged)",
                          n2, n2, cm_rbf_kernel_name(r->kernel), (int)info);
    } else if (info < 0) {
        st = cm_error(ctx, CM_ERR_INTERNAL, "cm_rbf_create: Cholesky argument %d invalid",
                      (int)-info);
    }
done:
    free(v);
    free(wv);
    free(z);
    return st;
}

/* One pass of the projected solve: f (m x nc col-major) -> w (nc x m SoA, i.e. m x nc
 * col-major) and q (nc x k); aw receives A w (row-major m x nc), g is m x nc scratch. */
cm_status cm_rbf_dense_solve_pass(cm_context *ctx, const cm_rbf *r, size_t nc, const double *f,
                            double *w, double *q, double *aw, double *g, int threads)
{
    const size_t m = r->m;
    const int k = r->k;
    const size_t n2 = m - (size_t)k;
    memcpy(w, f, m * nc * sizeof *w);
    lapack_int info = LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)m, (lapack_int)nc,
                                     k, r->qr, (lapack_int)m, r->tau, w, (lapack_int)m);
    if (info == 0 && n2 > 0) {
        /* on the factorisation's BLAS threads: the packed triangular solves stream the
         * factor, more than one core's bandwidth (10k, 3 components: 0.086 -> 0.066 s) */
        int blas_n = 1;
        cm_status st = cm_blas_threads(ctx, "cm_rbf_solve", threads, &blas_n);
        if (st != CM_OK) return st;
        info = LAPACKE_dpftrs_work(LAPACK_COL_MAJOR, 'N', 'L', (lapack_int)n2, (lapack_int)nc,
                                   r->chol, w + k, (lapack_int)m);
        blas_threads(1);
    }
    /* w = Q [0; sign z] */
    for (size_t c = 0; c < nc && info == 0; ++c) {
        for (int i = 0; i < k; ++i) w[c * m + (size_t)i] = 0.0;
        for (size_t i = (size_t)k; i < m; ++i) w[c * m + i] *= r->sign;
    }
    if (info == 0)
        info = LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'N', (lapack_int)m, (lapack_int)nc, k,
                              r->qr, (lapack_int)m, r->tau, w, (lapack_int)m);
    if (info != 0)
        return cm_error(ctx, CM_ERR_INTERNAL, "cm_rbf_solve: LAPACK failed (info %d)", (int)info);
    /* R q = Q1'(f - A w), with A w by kernel sums at the centres */
    cm_rbf_kernel_sum_all(r, w, (int)nc, m, r->c, m, aw, threads);
    for (size_t u = 0; u < m; ++u)
        for (size_t c = 0; c < nc; ++c) g[c * m + u] = f[c * m + u] - aw[u * nc + c];
    info = LAPACKE_dormqr(LAPACK_COL_MAJOR, 'L', 'T', (lapack_int)m, (lapack_int)nc, k, r->qr,
                          (lapack_int)m, r->tau, g, (lapack_int)m);
    if (info != 0)
        return cm_error(ctx, CM_ERR_INTERNAL, "cm_rbf_solve: dormqr failed (info %d)", (int)info);
    for (size_t c = 0; c < nc; ++c) {
        for (int i = k - 1; i >= 0; --i) {
            double acc = g[c * m + (size_t)i];
            for (int j = i + 1; j < k; ++j)
                acc -= r->qr[(size_t)j * m + (size_t)i] * q[c * (size_t)k + (size_t)j];
            q[c * (size_t)k + (size_t)i] = acc / r->qr[(size_t)i * m + (size_t)i];
        }
    }
    return CM_OK;
}
