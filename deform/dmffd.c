/* DM-FFD [SMB14 §2.2, eqs. 3-5 and 9-10] (design notes: docs/ffd.md, sections 4-5): the control
 * displacements C = Phi^+ H that move m handles by H, Phi_ip = N_p(u(h_i)), through an SVD
 * of Phi restricted to the control points some handle touches (the least-norm solution gives
 * the others exactly 0, and dropping them shrinks the SVD). Singular values <= eps sigma_max
 * are clamped - the paper's regularisation (Fig. 8), relative to sigma_max like numpy's pinv
 * rcond since the paper does not say. DM-FFD is least squares: the residual is reported, not
 * hidden. */
#include "ffd_internal.h"

#include "cadmorph/blas.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Dense Phi, U and V^T above cm_memory_budget() (half the RAM) are refused rather than
 * thrashing: on a 24 GB machine DM-FFD-15 on the 1M-cell car case's 83k boundary nodes
 * (4.2 GB) runs, DM-FFD-25 (15.5 GB) is refused. A machine that does not report its memory
 * gets the old fixed 2 GiB. */
static double max_doubles(void)
{
    const double budget = cm_memory_budget();
    return (budget > 0 ? budget : 2147483648.0) / sizeof(double);
}

struct cm_dmffd {
    const cm_ffd *ffd;
    size_t m, n_act, r, cap; /* cap: support entries per row */
    int64_t *row_idx;        /* m x cap control indices */
    double *row_w;           /* m x cap weights */
    size_t *row_n;           /* m: entries used */
    int64_t *act;            /* n_act: control index of each SVD column */
    int64_t *col;            /* #ctrl: SVD column of each control point, -1 if none */
    double *u, *s, *sinv, *vt; /* m x r, r, r, r x n_act */
    cm_dmffd_info info;
};

void cm_dmffd_options_init(cm_dmffd_options *opt)
{
    if (!opt) return;
    opt->eps = 1e-10;
    opt->floor = 0;
}

void cm_dmffd_destroy(cm_dmffd **dm)
{
    if (!dm || !*dm) return;
    cm_dmffd *d = *dm;
    free(d->row_idx);
    free(d->row_w);
    free(d->row_n);
    free(d->act);
    free(d->col);
    free(d->u);
    free(d->s);
    free(d->sinv);
    free(d->vt);
    free(d);
    *dm = NULL;
}

/* Rows of Phi at the handles; handles outside the lattice are an error naming the first. */
static cm_status build_rows(cm_context *ctx, cm_dmffd *d, const double *handles)
{
    const cm_ffd *f = d->ffd;
    size_t bad = (size_t)-1;
    int bad_kind = 0;
    int threads = cm_context_threads_for(ctx, d->m, 500);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t i = 0; i < d->m; ++i) {
        double u[3];
        int it, r = cm_ffd_locate(f, handles + 3 * i, u, &it);
        if (r != 1) {
#pragma omp critical(cm_dmffd_bad)
            if (i < bad) {
                bad = i;
                bad_kind = r;
            }
            d->row_n[i] = 0;
            continue;
        }
        d->row_n[i] = cm_ffd_basis_eval(f, u, d->row_idx + i * d->cap, d->row_w + i * d->cap);
    }
    if (bad != (size_t)-1)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_dmffd_create: handle %zu (%g, %g, %g) is %s the lattice", bad,
                        handles[3 * bad], handles[3 * bad + 1], handles[3 * bad + 2],
                        bad_kind == 0 ? "outside" : "not invertible in");
    return CM_OK;
}

static cm_status svd(cm_context *ctx, cm_dmffd *d, const cm_dmffd_options *opt)
{
    /* under an address-space limit OpenBLAS would spin in its buffer allocation (blas.h) */
    cm_status st = cm_blas_reserve(ctx, "cm_dmffd_create");
    if (st < 0) return st;
    size_t m = d->m, n = d->n_act, r = m < n ? m : n;
    d->r = r;
    double *phi = calloc(m * n + 1, sizeof *phi);
    double *phi2 = NULL;
    d->u = malloc((m * r + 1) * sizeof *d->u);
    d->s = malloc((r ? r : 1) * sizeof *d->s);
    d->sinv = malloc((r ? r : 1) * sizeof *d->sinv);
    d->vt = malloc((r * n + 1) * sizeof *d->vt);
    if (!phi || !d->u || !d->s || !d->sinv || !d->vt) {
        free(phi);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_dmffd_create: out of memory (Phi %zu x %zu)", m, n);
    }
    for (size_t i = 0; i < m; ++i)
        for (size_t q = 0; q < d->row_n[i]; ++q)
            phi[i * n + (size_t)d->col[d->row_idx[i * d->cap + q]]] += d->row_w[i * d->cap + q];
    /* dgesdd destroys Phi; keep a copy for the dgesvd fallback only if it is needed */
    lapack_int info = LAPACKE_dgesdd(LAPACK_ROW_MAJOR, 'S', (lapack_int)m, (lapack_int)n, phi,
                                     (lapack_int)n, d->s, d->u, (lapack_int)r, d->vt,
                                     (lapack_int)n);
    if (info > 0) {
        phi2 = calloc(m * n, sizeof *phi2);
        double *superb = malloc((r ? r : 1) * sizeof *superb);
        if (!phi2 || !superb) {
            free(phi);
            free(phi2);
            free(superb);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_dmffd_create: out of memory");
        }
        for (size_t i = 0; i < m; ++i)
            for (size_t q = 0; q < d->row_n[i]; ++q)
                phi2[i * n + (size_t)d->col[d->row_idx[i * d->cap + q]]] +=
                    d->row_w[i * d->cap + q];
        info = LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'S', 'S', (lapack_int)m, (lapack_int)n, phi2,
                              (lapack_int)n, d->s, d->u, (lapack_int)r, d->vt, (lapack_int)n,
                              superb);
        free(superb);
    }
    free(phi);
    free(phi2);
    if (info != 0)
        return cm_error(ctx, info < 0 ? CM_ERR_INTERNAL : CM_ERR_NUMERIC,
                        "cm_dmffd_create: SVD of Phi (%zu x %zu) failed (LAPACK info %d)", m, n,
                        (int)info);
    double smax = r ? d->s[0] : 0, tau = opt->eps * smax;
    size_t rank = 0;
    for (size_t i = 0; i < r; ++i) {
        if (d->s[i] > tau) {
            d->sinv[i] = 1 / d->s[i];
            ++rank;
        } else {
            d->sinv[i] = opt->floor && tau > 0 ? 1 / tau : 0;
        }
    }
    d->info.rank = rank;
    d->info.clamped = r - rank;
    d->info.sigma_max = smax;
    d->info.sigma_min = r ? d->s[r - 1] : 0;
    return CM_OK;
}

cm_status cm_dmffd_create(cm_context *ctx, const cm_ffd *ffd, size_t m, const double *handles,
                          const cm_dmffd_options *opt, cm_dmffd **dm)
{
    if (!dm) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_dmffd_create: dm is NULL");
    *dm = NULL;
    if (!ffd || (m && !handles))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_dmffd_create: NULL input");
    if (m == 0) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_dmffd_create: no handles");
    cm_dmffd_options defaults;
    cm_dmffd_options_init(&defaults);
    if (!opt) opt = &defaults;
    if (!(opt->eps >= 0) || !isfinite(opt->eps))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_dmffd_create: eps %g is not >= 0", opt->eps);
    cm_dmffd *d = calloc(1, sizeof *d);
    if (!d) return cm_error(ctx, CM_ERR_NOMEM, "cm_dmffd_create: out of memory");
    d->ffd = ffd;
    d->m = m;
    d->cap = cm_ffd_support_size(ffd);
    size_t nc = cm_ffd_control_count(ffd);
    cm_status s = CM_OK;
    if ((double)m * (double)d->cap > max_doubles()) {
        s = cm_error(ctx, CM_ERR_UNSUPPORTED,
                     "cm_dmffd_create: %zu handles x %zu support entries exceed the memory limit",
                     m, d->cap);
        goto fail;
    }
    d->row_idx = malloc(m * d->cap * sizeof *d->row_idx);
    d->row_w = malloc(m * d->cap * sizeof *d->row_w);
    d->row_n = malloc(m * sizeof *d->row_n);
    d->col = malloc(nc * sizeof *d->col);
    if (!d->row_idx || !d->row_w || !d->row_n || !d->col) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_dmffd_create: out of memory");
        goto fail;
    }
    s = build_rows(ctx, d, handles);
    if (s < 0) goto fail;
    /* active columns, in control-index order so that the result does not depend on threads */
    for (size_t p = 0; p < nc; ++p)
        d->col[p] = -1;
    for (size_t i = 0; i < m; ++i)
        for (size_t q = 0; q < d->row_n[i]; ++q)
            d->col[d->row_idx[i * d->cap + q]] = 0;
    for (size_t p = 0; p < nc; ++p)
        if (d->col[p] == 0) d->col[p] = (int64_t)d->n_act++;
    d->act = malloc((d->n_act ? d->n_act : 1) * sizeof *d->act);
    if (!d->act) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_dmffd_create: out of memory");
        goto fail;
    }
    for (size_t p = 0; p < nc; ++p)
        if (d->col[p] >= 0) d->act[d->col[p]] = (int64_t)p;
    {
        double r = (double)(m < d->n_act ? m : d->n_act);
        double need = (double)m * d->n_act + (double)m * r + r * d->n_act;
        if (need > max_doubles()) {
            s = cm_error(ctx, CM_ERR_UNSUPPORTED,
                         "cm_dmffd_create: the SVD of Phi (%zu handles x %zu control points) "
                         "needs %.1f GB; use a coarser lattice or fewer handles",
                         m, d->n_act, need * 8 / 1e9);
            goto fail;
        }
    }
    /* the SVD is one LAPACK call that cannot stop: the points around it are where the
     * caller can (cm_context_interrupt) */
    if ((s = cm_progress(ctx, "dmffd svd", 0, 1)) < 0) goto fail;
    {
        int saved = openblas_get_num_threads();
        int threads = cm_context_threads(ctx);
        openblas_set_num_threads(threads > 0 ? threads : saved);
        s = svd(ctx, d, opt);
        openblas_set_num_threads(saved);
    }
    if (s < 0) goto fail;
    if ((s = cm_progress(ctx, "dmffd svd", 1, 1)) < 0) goto fail;
    d->info.handles = m;
    d->info.active = d->n_act;
    *dm = d;
    return CM_OK;
fail:
    cm_dmffd_destroy(&d);
    return s;
}

cm_status cm_dmffd_solve(cm_context *ctx, cm_dmffd *d, const double *h, double *dc)
{
    if (!d || !h || !dc) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_dmffd_solve: NULL input");
    size_t m = d->m, n = d->n_act, r = d->r, nc = cm_ffd_control_count(d->ffd);
    double *t = malloc((r ? r : 1) * 3 * sizeof *t);
    double *c = malloc((n ? n : 1) * 3 * sizeof *c);
    if (!t || !c) {
        free(t);
        free(c);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_dmffd_solve: out of memory");
    }
    for (size_t i = 0; i < 3 * m; ++i)
        if (!isfinite(h[i])) {
            free(t);
            free(c);
            return cm_error(ctx, CM_ERR_ARGUMENT,
                            "cm_dmffd_solve: displacement of handle %zu is not finite", i / 3);
        }
    /* C = V diag(sinv) U^T H */
    cblas_dgemm(CblasRowMajor, CblasTrans, CblasNoTrans, (int)r, 3, (int)m, 1.0, d->u, (int)r, h,
                3, 0.0, t, 3);
    for (size_t i = 0; i < r; ++i)
        for (int k = 0; k < 3; ++k)
            t[3 * i + k] *= d->sinv[i];
    cblas_dgemm(CblasRowMajor, CblasTrans, CblasNoTrans, (int)n, 3, (int)r, 1.0, d->vt, (int)n, t,
                3, 0.0, c, 3);
    memset(dc, 0, nc * 3 * sizeof *dc);
    double cmax = 0;
    for (size_t j = 0; j < n; ++j) {
        memcpy(dc + 3 * d->act[j], c + 3 * j, 3 * sizeof *c);
        cmax = fmax(cmax, sqrt(c[3 * j] * c[3 * j] + c[3 * j + 1] * c[3 * j + 1] +
                               c[3 * j + 2] * c[3 * j + 2]));
    }
    free(t);
    free(c);
    /* the paper's precision: how far Phi C misses H */
    double res = 0, hmax = 0;
    for (size_t i = 0; i < m; ++i) {
        double e[3] = {-h[3 * i], -h[3 * i + 1], -h[3 * i + 2]};
        for (size_t q = 0; q < d->row_n[i]; ++q) {
            const double *p = dc + 3 * d->row_idx[i * d->cap + q];
            double w = d->row_w[i * d->cap + q];
            e[0] += w * p[0];
            e[1] += w * p[1];
            e[2] += w * p[2];
        }
        for (int k = 0; k < 3; ++k) {
            res = fmax(res, fabs(e[k]));
            hmax = fmax(hmax, fabs(h[3 * i + k]));
        }
    }
    d->info.residual_abs = res;
    d->info.residual = hmax > 0 ? res / hmax : 0;
    d->info.max_control = cmax;
    return CM_OK;
}

cm_status cm_dmffd_solve_transpose(cm_context *ctx, const cm_dmffd *d, const double *gdc,
                                   double *gh)
{
    if (!d || !gdc || !gh)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_dmffd_solve_transpose: NULL input");
    size_t m = d->m, n = d->n_act, r = d->r;
    double *t = malloc((r ? r : 1) * 3 * sizeof *t);
    double *c = malloc((n ? n : 1) * 3 * sizeof *c);
    if (!t || !c) {
        free(t);
        free(c);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_dmffd_solve_transpose: out of memory");
    }
    for (size_t j = 0; j < n; ++j)
        memcpy(c + 3 * j, gdc + 3 * d->act[j], 3 * sizeof *c);
    /* (V diag(sinv) U^T)^T = U diag(sinv) V^T, the same factors as solve */
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, (int)r, 3, (int)n, 1.0, d->vt, (int)n, c,
                3, 0.0, t, 3);
    for (size_t i = 0; i < r; ++i)
        for (int k = 0; k < 3; ++k)
            t[3 * i + k] *= d->sinv[i];
    cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, (int)m, 3, (int)r, 1.0, d->u, (int)r, t,
                3, 0.0, gh, 3);
    free(t);
    free(c);
    return CM_OK;
}

void cm_dmffd_get_info(const cm_dmffd *dm, cm_dmffd_info *info)
{
    if (dm && info) *info = dm->info;
}

cm_status cm_dmffd_precompute(cm_context *ctx, const cm_dmffd *d, size_t k, const double *x,
                              double **b)
{
    if (!b) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_dmffd_precompute: b is NULL");
    *b = NULL;
    if (!d || (k && !x)) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_dmffd_precompute: NULL input");
    size_t m = d->m, n = d->n_act, r = d->r;
    if ((double)k * (double)(m + r) > max_doubles())
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_dmffd_precompute: B (%zu x %zu) exceeds the memory limit", k, m);
    /* W = V diag(sinv) (n_act x r); B = (M W) U^T */
    double *w = malloc((n * r + 1) * sizeof *w);
    double *mw = calloc(k * r + 1, sizeof *mw);
    double *out = malloc((k * m + 1) * sizeof *out);
    if (!w || !mw || !out) {
        free(w);
        free(mw);
        free(out);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_dmffd_precompute: out of memory");
    }
    for (size_t j = 0; j < n; ++j)
        for (size_t i = 0; i < r; ++i)
            w[j * r + i] = d->vt[i * n + j] * d->sinv[i];
    size_t cap = d->cap;
    int threads = cm_context_threads_for(ctx, k, 200);
    int fail = 0;
#pragma omp parallel num_threads(threads)
    {
        int64_t *idx = malloc(cap * sizeof *idx);
        double *wt = malloc(cap * sizeof *wt);
        if (!idx || !wt) {
#pragma omp atomic write
            fail = 1;
        }
#pragma omp for schedule(static)
        for (size_t i = 0; i < k; ++i) {
            double u[3];
            int it;
            if (!idx || !wt || cm_ffd_locate(d->ffd, x + 3 * i, u, &it) != 1) continue;
            size_t q = cm_ffd_basis_eval(d->ffd, u, idx, wt);
            double *row = mw + i * r;
            for (size_t e = 0; e < q; ++e) {
                int64_t c = d->col[idx[e]];
                if (c < 0) continue;
                const double *wr = w + (size_t)c * r;
                for (size_t l = 0; l < r; ++l)
                    row[l] += wt[e] * wr[l];
            }
        }
        free(idx);
        free(wt);
    }
    if (!fail && k && m)
        cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasTrans, (int)k, (int)m, (int)r, 1.0, mw,
                    (int)r, d->u, (int)r, 0.0, out, (int)m);
    free(w);
    free(mw);
    if (fail) {
        free(out);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_dmffd_precompute: out of memory");
    }
    *b = out;
    return CM_OK;
}
