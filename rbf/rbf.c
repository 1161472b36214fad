/* RBF interpolation with polyharmonic kernels and a linear polynomial ([SMB12 §3], 3D;
 * [SMB12 §4], 2D thin plate): fit by null-space projection + Cholesky, solve, evaluate.
 *
 * Why the projection: the saddle-point system [A P; P' 0] is indefinite, but A is
 * conditionally positive definite on the null space of P'. With P = QR (Householder),
 * Q = [Q1 Q2] and w = Q2 z, the system becomes (Q2' A Q2) z = Q2' f, SPD for r^3 and
 * r^2 log r, negative definite for r; then R q = Q1'(f - A w). Q = I - V T V' (compact WY),
 * so Q' A Q = A - V Z' - Z V' with W = A V and Z = W T - V (T' V' W T) / 2: one pass of
 * kernel sums for W and one pass that writes the projected block directly, so no m x m
 * copy of A is ever stored and the only O(m^3) step is the Cholesky factorisation. That
 * factor is kept in LAPACK's rectangular full packed format (dpftrf/dpftrs): half the
 * memory of full storage at the same BLAS-3 speed, which matters twice here: m = 20k takes
 * 1.6 GB instead of 3.2 GB, and first touch of fresh memory costs seconds per GB on the VMs
 * we run on. */
#include "rbf_internal.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Centres closer than this times the bounding-box diagonal are one centre. */
#define CM_RBF_MERGE_TOL 1e-12
/* |R_ii| below this times max |R_jj|: the polynomial block is singular. */
#define CM_RBF_UNISOLVENT_TOL 1e-10
/* Merged centres must carry values that agree to this, relative to the largest value. */
#define CM_RBF_VALUE_TOL 1e-8

/* OpenBLAS threads: many for the O(m^3) dpftrf only. Its idle workers spin (sched_yield)
 * for ~0.1 s after each threaded call and then compete with our OpenMP loops for the cores,
 * so the small O(m k) and O(m^2) LAPACK calls run on one thread. create and solve restore
 * the caller's setting before they return. */
static void blas_threads(int n) { openblas_set_num_threads(n > 0 ? n : 1); }

void cm_rbf_destroy(cm_rbf **rbf)
{
    if (!rbf || !*rbf) return;
    cm_rbf *r = *rbf;
    free(r->c);
    free(r->rep);
    free(r->first);
    free(r->qr);
    free(r->tau);
    free(r->chol);
    free(r->w);
    free(r->q);
    cm_rbf_petsc_destroy(&r->petsc);
    cm_rbf_iterative_destroy(&r->iter);
    free(r);
    *rbf = NULL;
}

size_t cm_rbf_centre_count(const cm_rbf *rbf) { return rbf ? rbf->m : 0; }

void cm_rbf_options_init(cm_rbf_options *opt)
{
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    opt->solver = CM_RBF_SOLVER_AUTO;
    opt->tolerance = CM_RBF_DEFAULT_TOL;
    opt->max_iterations = 300;
    opt->restart = 40;
    opt->fast_sum = -1;
    opt->warm_start = 1;
    opt->solves = 1;
}

void cm_rbf_tuning_init(cm_rbf_tuning *t)
{
    if (!t) return;
    memset(t, 0, sizeof *t);
    t->column_scale = 1e-3;
    t->warm_history = 64;
    t->leaf_size = 256;
    t->local_size = 700;
    t->coarse_size = 2000;
    t->coarse_post = 1;
    t->local_float = 1;
    t->coarse_grow = 1;
    t->coarse_max = 16000;
    t->coarse_inner_tol = 1e-2;
    t->overlap = 2.0;
    t->local_max = 2800;
    t->thin_cell = 0.25;
    t->thin_max = 2000;
    t->fast_tol = 1e-12;
    t->fast_refine = 3;
    t->fast_eval_tol = 1e-9;
    t->relax = 1;
}

void cm_rbf_get_stats(const cm_rbf *rbf, cm_rbf_stats *stats)
{
    if (!stats) return;
    if (!rbf) {
        memset(stats, 0, sizeof *stats);
        return;
    }
    *stats = rbf->stats;
    cm_rbf_iterative_stats(rbf, stats);
}


/* Unit-box map and merging; fills r->c, rep, first, m. */
static cm_status place_centres(cm_context *ctx, cm_rbf *r, const double *centres)
{
    const int dim = r->dim;
    const size_t m_in = r->m_in;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (size_t i = 0; i < m_in; ++i) {
        for (int d = 0; d < dim; ++d) {
            double x = centres[i * (size_t)dim + (size_t)d];
            if (!isfinite(x))
                return cm_error(ctx, CM_ERR_NUMERIC,
                                "cm_rbf_create: centre %zu coordinate %d is not finite", i, d);
            if (i == 0 || x < lo[d]) lo[d] = x;
            if (i == 0 || x > hi[d]) hi[d] = x;
        }
    }
    double extent = 0.0, diag2 = 0.0;
    for (int d = 0; d < dim; ++d) {
        extent = fmax(extent, hi[d] - lo[d]);
        diag2 += (hi[d] - lo[d]) * (hi[d] - lo[d]);
    }
    if (!(extent > 0.0))
        return cm_error(ctx, CM_ERR_NUMERIC,
                        "cm_rbf_create: all %zu centres coincide; a linear polynomial needs "
                        "%d centres in general position",
                        m_in, dim + 1);
    /* one scale for all axes keeps distances (and so the kernel) isotropic */
    r->scale = 1.0 / extent;
    for (int d = 0; d < 3; ++d) r->shift[d] = d < dim ? lo[d] : 0.0;

    double *tmp = malloc(m_in * (size_t)dim * sizeof *tmp);
    r->rep = malloc(m_in * sizeof *r->rep);
    r->first = malloc(m_in * sizeof *r->first);
    if (!tmp || !r->rep || !r->first) {
        free(tmp);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory for %zu centres", m_in);
    }
    for (size_t i = 0; i < m_in; ++i)
        for (int d = 0; d < dim; ++d)
            tmp[(size_t)d * m_in + i] = (centres[i * (size_t)dim + (size_t)d] - lo[d]) * r->scale;

    const double tol = CM_RBF_MERGE_TOL * sqrt(diag2) * r->scale;
    long mm = cm_rbf_merge_duplicates(dim, m_in, tmp, tol, r->rep, r->first);
    if (mm < 0) {
        free(tmp);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory merging centres");
    }
    r->m = (size_t)mm;
    r->c = malloc(r->m * (size_t)dim * sizeof *r->c);
    if (!r->c) {
        free(tmp);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory for %zu centres", r->m);
    }
    for (int d = 0; d < dim; ++d)
        for (size_t u = 0; u < r->m; ++u)
            r->c[(size_t)d * r->m + u] = tmp[(size_t)d * m_in + r->first[u]];
    free(tmp);
    if (r->m < m_in)
        cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_create: merged %zu duplicate centres (%zu left)",
               m_in - r->m, r->m);
    return CM_OK;
}

/* P = QR and the unisolvency check. */
static cm_status factor_polynomial(cm_context *ctx, cm_rbf *r)
{
    const size_t m = r->m;
    const int k = r->k;
    r->qr = malloc(m * (size_t)k * sizeof *r->qr);
    r->tau = malloc((size_t)k * sizeof *r->tau);
    if (!r->qr || !r->tau) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    for (size_t i = 0; i < m; ++i) r->qr[i] = 1.0;
    memcpy(r->qr + m, r->c, m * (size_t)r->dim * sizeof *r->qr);
    blas_threads(1);
    lapack_int info = LAPACKE_dgeqrf(LAPACK_COL_MAJOR, (lapack_int)m, k, r->qr, (lapack_int)m,
                                     r->tau);
    if (info != 0)
        return cm_error(ctx, CM_ERR_INTERNAL, "cm_rbf_create: dgeqrf failed (info %d)",
                        (int)info);
    double rmax = 0.0;
    for (int i = 0; i < k; ++i) rmax = fmax(rmax, fabs(r->qr[(size_t)i * m + (size_t)i]));
    for (int i = 0; i < k; ++i) {
        if (!(fabs(r->qr[(size_t)i * m + (size_t)i]) > CM_RBF_UNISOLVENT_TOL * rmax))
            return cm_error(ctx, CM_ERR_NUMERIC,
                            "cm_rbf_create: the %zu centres are all %s, so the linear "
                            "polynomial is not determined (|R_%d%d| = %.3g vs max %.3g)",
                            m, r->dim == 3 ? "coplanar (or collinear)" : "collinear", i, i,
                            fabs(r->qr[(size_t)i * m + (size_t)i]), rmax);
    }
    return CM_OK;
}

cm_status cm_rbf_create(cm_context *ctx, cm_rbf_kernel kernel, int dim, size_t m,
                        const double *centres, cm_rbf **rbf)
{
    return cm_rbf_create_opt(ctx, kernel, dim, m, centres, NULL, rbf);
}

cm_status cm_rbf_create_opt(cm_context *ctx, cm_rbf_kernel kernel, int dim, size_t m,
                            const double *centres, const cm_rbf_options *opt, cm_rbf **rbf)
{
    return cm_rbf_create_tuned(ctx, kernel, dim, m, centres, opt, NULL, rbf);
}

cm_status cm_rbf_create_tuned(cm_context *ctx, cm_rbf_kernel kernel, int dim, size_t m,
                              const double *centres, const cm_rbf_options *opt,
                              const cm_rbf_tuning *tuning, cm_rbf **rbf)
{
    const double t_start = cm_wtime();
    if (!rbf) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_rbf_create: rbf is NULL");
    *rbf = NULL;
    if (kernel != CM_RBF_TRIHARMONIC && kernel != CM_RBF_BIHARMONIC &&
        kernel != CM_RBF_THIN_PLATE)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_rbf_create: unknown kernel %d", (int)kernel);
    int want = kernel == CM_RBF_THIN_PLATE ? 2 : 3;
    if (dim != want)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_rbf_create: the %s kernel needs dim %d, got %d",
                        cm_rbf_kernel_name(kernel), want, dim);
    if (m > 0 && !centres) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_rbf_create: centres is NULL");
    if (m < (size_t)dim + 1)
        return cm_error(ctx, CM_ERR_NUMERIC,
                        "cm_rbf_create: %zu centres, but a linear polynomial in %d dimensions "
                        "needs at least %d",
                        m, dim, dim + 1);

    cm_rbf *r = calloc(1, sizeof *r);
    if (!r) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    r->kernel = kernel;
    r->dim = dim;
    r->k = dim + 1;
    r->m_in = m;
    r->sign = kernel == CM_RBF_BIHARMONIC ? -1.0 : 1.0;
    if (opt) r->opt = *opt;
    else cm_rbf_options_init(&r->opt);
    if (tuning) r->tun = *tuning;
    else cm_rbf_tuning_init(&r->tun);
    const int threads = cm_rbf_threads(ctx);
    const int saved_blas_threads = openblas_get_num_threads();

    /* before the first LAPACK call: OpenBLAS hangs, not fails, without its buffer */
    cm_status st = cm_blas_threads(ctx, "cm_rbf_create", 1, NULL);
    if (st == CM_OK) st = place_centres(ctx, r, centres);
    if (st == CM_OK && r->m < (size_t)r->k)
        st = cm_error(ctx, CM_ERR_NUMERIC,
                      "cm_rbf_create: only %zu distinct centres after merging duplicates; a "
                      "linear polynomial in %d dimensions needs at least %d",
                      r->m, dim, dim + 1);
    if (st == CM_OK) st = factor_polynomial(ctx, r);
    cm_rbf_solver solver = r->opt.solver;
    if (solver == CM_RBF_SOLVER_AUTO)
        solver = cm_rbf_auto_dense(kernel, r->m, r->opt.solves) ? CM_RBF_SOLVER_DENSE
                                                                 : CM_RBF_SOLVER_ITERATIVE;
    r->stats.solver = solver;
    r->stats.centres = r->m;
    if (st == CM_OK)
        st = solver == CM_RBF_SOLVER_ITERATIVE ? cm_rbf_iterative_setup(ctx, r, threads)
             : solver == CM_RBF_SOLVER_PETSC   ? cm_rbf_petsc_setup(ctx, r, threads)
                                               : cm_rbf_dense_factor(ctx, r, threads);
    if (st == CM_OK && solver == CM_RBF_SOLVER_DENSE)
        r->stats.memory_bytes = (r->m - (size_t)r->k) * (r->m - (size_t)r->k + 1) / 2 * 8;
    r->stats.setup_seconds = cm_wtime() - t_start;
    openblas_set_num_threads(saved_blas_threads);
    if (st != CM_OK) {
        cm_rbf_destroy(&r);
        return st;
    }
    *rbf = r;
    return CM_OK;
}

/* Refuses merged centres whose values disagree. */
static cm_status check_merged_values(cm_context *ctx, const cm_rbf *r, int ncomp,
                                     const double *values)
{
    double vmax = 0.0;
    for (size_t i = 0; i < r->m_in * (size_t)ncomp; ++i) {
        if (!isfinite(values[i]))
            return cm_error(ctx, CM_ERR_NUMERIC,
                            "cm_rbf_solve: value %d of centre %zu is not finite",
                            (int)(i % (size_t)ncomp), i / (size_t)ncomp);
        vmax = fmax(vmax, fabs(values[i]));
    }
    const double tol = CM_RBF_VALUE_TOL * vmax;
    for (size_t i = 0; i < r->m_in; ++i) {
        size_t j = r->first[r->rep[i]];
        if (j == i) continue;
        for (int q = 0; q < ncomp; ++q) {
            double a = values[j * (size_t)ncomp + (size_t)q];
            double b = values[i * (size_t)ncomp + (size_t)q];
            if (fabs(a - b) > tol)
                return cm_error(ctx, CM_ERR_NUMERIC,
                                "cm_rbf_solve: centres %zu and %zu coincide (merged as "
                                "duplicates) but their values differ: component %d is %.17g "
                                "vs %.17g",
                                j, i, q, a, b);
        }
    }
    return CM_OK;
}

/* res = f - A w - P q at the centres (col-major m x nc); returns max |res|. */
static double residual(const cm_rbf *r, size_t nc, const double *f, const double *aw,
                       const double *q, double *res)
{
    const size_t m = r->m, k = (size_t)r->k;
    double worst = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        for (size_t u = 0; u < m; ++u) {
            double p = q[c * k];
            for (int d = 0; d < r->dim; ++d) p += q[c * k + (size_t)d + 1] * r->c[(size_t)d * m + u];
            double e = f[c * m + u] - aw[u * nc + c] - p;
            res[c * m + u] = e;
            worst = fmax(worst, fabs(e));
        }
    }
    return worst;
}

/* Refinement runs only while the residual at the centres is above this, relative to the
 * data: smooth data on well-spread centres (1e-12 after one pass) skip it and save two
 * O(m^2) packed triangular solves; dense or noisy sets (1e-10 seen) get one or two steps. */
#define CM_RBF_REFINE_TOL 1e-11
#define CM_RBF_REFINE_STEPS 3

cm_status cm_rbf_solve_merged(cm_context *ctx, cm_rbf *rbf, size_t nc, const double *f,
                              double refine_tol, double *w, double *q)
{
    const size_t m = rbf->m, k = (size_t)rbf->k;
    const int threads = cm_rbf_threads(ctx);
    cm_status st = CM_OK;
    double *res = malloc(m * nc * sizeof *res);
    double *g = malloc(m * nc * sizeof *g);
    double *dw = malloc(m * nc * sizeof *dw);
    double *aw = malloc(m * nc * sizeof *aw); /* row-major m x nc */
    double *adw = malloc(m * nc * sizeof *adw);
    double *dq = malloc(k * nc * sizeof *dq);
    if (!res || !g || !dw || !aw || !adw || !dq) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_solve: out of memory");
        goto done;
    }
    double fmaxabs = 0.0;
    for (size_t i = 0; i < m * nc; ++i) fmaxabs = fmax(fmaxabs, fabs(f[i]));
    const int saved_blas_threads = openblas_get_num_threads();
    blas_threads(1);
    const double t_start = cm_wtime();
    st = rbf->petsc  ? cm_rbf_petsc_solve(ctx, rbf, nc, f, w, q)
         : rbf->iter ? cm_rbf_iterative_solve(ctx, rbf, nc, f, w, q, threads)
                     : cm_rbf_dense_solve_pass(ctx, rbf, nc, f, w, q, aw, g, threads);
    /* Iterative refinement with the same factorisation: the cubic kernel's system is badly
     * conditioned for dense centres, and one or two cheap O(m^2) passes recover digits the
     * O(m^3) factorisation lost. Skipped when the first residual is already tiny. */
    double prev = INFINITY, first = -1.0, e = 0.0;
    int steps = 0;
    for (; st == CM_OK && !rbf->iter; ++steps) {
        e = residual(rbf, nc, f, aw, q, res) / (fmaxabs > 0.0 ? fmaxabs : 1.0);
        if (first < 0.0) first = e;
        if (e <= refine_tol || !(e < 0.5 * prev) || steps == CM_RBF_REFINE_STEPS) break;
        prev = e;
        /* a pass of a large fit streams the factor and sums m^2 pairs (20k centres: ~1 s):
         * the caller may stop between passes (the weights stay the last solve's) */
        if ((double)m * (double)m * (double)nc >= CM_RBF_TICK_PAIRS &&
            (st = cm_progress(ctx, "rbf solve", steps + 1, CM_RBF_REFINE_STEPS + 1)) < 0)
            break;
        st = cm_rbf_dense_solve_pass(ctx, rbf, nc, res, dw, dq, adw, g, threads);
        if (st != CM_OK) break;
        for (size_t i = 0; i < m * nc; ++i) {
            w[i] += dw[i];
            aw[i] += adw[i]; /* A is linear: no further kernel sums */
        }
        for (size_t i = 0; i < k * nc; ++i) q[i] += dq[i];
    }
    rbf->stats.solve_seconds = cm_wtime() - t_start;
    if (st == CM_OK && !rbf->iter) {
        rbf->stats.residual = e;
        rbf->stats.iterations = steps;
    }
    if (st == CM_OK && !rbf->iter)
        cm_log(ctx, CM_LOG_DEBUG,
               "cm_rbf_solve: relative residual at the centres %.2g, after %d refinement "
               "steps %.2g",
               first, steps, e);
    openblas_set_num_threads(saved_blas_threads);
done:
    free(res), free(g), free(dw), free(aw), free(adw), free(dq);
    return st;
}

cm_status cm_rbf_solve(cm_context *ctx, cm_rbf *rbf, int ncomp, const double *values)
{
    if (!rbf || !values || ncomp < 1)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_rbf_solve: %s",
                        !rbf ? "rbf is NULL" : !values ? "values is NULL" : "ncomp < 1");
    cm_status st = check_merged_values(ctx, rbf, ncomp, values);
    if (st != CM_OK) return st;

    const size_t m = rbf->m, nc = (size_t)ncomp, k = (size_t)rbf->k;
    double *f = malloc(m * nc * sizeof *f); /* m x nc col-major */
    double *w = malloc(m * nc * sizeof *w);
    double *q = malloc(k * nc * sizeof *q);
    if (!f || !w || !q) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_solve: out of memory");
        goto done;
    }
    for (size_t u = 0; u < m; ++u)
        for (size_t c = 0; c < nc; ++c) f[c * m + u] = values[rbf->first[u] * nc + c];
    rbf->warm_ok = 1; /* this solve may start from earlier solutions (options warm_start) */
    st = cm_rbf_solve_merged(ctx, rbf, nc, f, CM_RBF_REFINE_TOL, w, q);
    rbf->warm_ok = 0;
    if (st >= CM_OK) { /* a warning keeps the weights: the message says how good they are */
        free(rbf->w);
        free(rbf->q);
        rbf->w = w;
        rbf->q = q;
        rbf->ncomp = ncomp;
        if (rbf->iter) cm_rbf_iterative_commit(rbf);
        w = q = NULL;
    }
done:
    free(f), free(w), free(q);
    return st;
}

cm_status cm_rbf_evaluate(cm_context *ctx, const cm_rbf *rbf, size_t n, const double *points,
                          double *out)
{
    if (!rbf || (n > 0 && (!points || !out)))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_rbf_evaluate: %s",
                        !rbf ? "rbf is NULL" : !points ? "points is NULL" : "out is NULL");
    if (rbf->ncomp == 0)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_rbf_evaluate: no weights yet; call cm_rbf_solve first");
    if (n == 0) return CM_OK;
    const int dim = rbf->dim, k = rbf->k, ncomp = rbf->ncomp;
    double *p = malloc(n * (size_t)dim * sizeof *p); /* dim x n SoA, unit-box coordinates */
    if (!p) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_evaluate: out of memory for %zu points", n);
    for (size_t i = 0; i < n; ++i)
        for (int d = 0; d < dim; ++d)
            p[(size_t)d * n + i] = (points[i * (size_t)dim + (size_t)d] - rbf->shift[d]) * rbf->scale;
    /* in chunks with progress, so that cm_context_interrupt stops a large evaluation */
    cm_rbf_tick tick;
    cm_rbf_tick_init(&tick, ctx, "rbf evaluate",
                     (double)((ncomp + 3) / 4) * (double)n * (double)rbf->m);
    if (rbf->petsc && cm_rbf_petsc_evaluate(rbf, n, p, out, cm_rbf_threads(ctx)))
        ; /* collective: each rank its block of points */
    else if (rbf->iter) /* compensated sums: see cm_rbf_iterative_evaluate */
        cm_rbf_iterative_evaluate(rbf, n, p, out, cm_rbf_threads(ctx), &tick);
    else
        cm_rbf_kernel_sum_all_tick(rbf, rbf->w, ncomp, n, p, n, out, cm_rbf_threads(ctx), &tick);
    if (cm_rbf_tick_finish(&tick) < 0) {
        free(p);
        return tick.status;
    }
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < ncomp; ++c) {
            const double *qc = rbf->q + (size_t)c * (size_t)k;
            double acc = qc[0];
            for (int d = 0; d < dim; ++d) acc += qc[d + 1] * p[(size_t)d * n + i];
            out[i * (size_t)ncomp + (size_t)c] += acc;
        }
    }
    free(p);
    return CM_OK;
}
