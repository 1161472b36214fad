/* The MLS space deformation of a mesh (paper sections 4-5, eq. 14): samples and cubature
 * points, the sparse matrices Phi (nodes), G and L (cubature points), the normal equations
 * factored by CHOLMOD once, one solve and one sparse product per displacement. */
#define _POSIX_C_SOURCE 200809L
#include "mls_internal.h"

#include <cholmod.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

struct cm_mls {
    size_t n_nodes, k;
    cm_mls_basis *basis;
    double *samples;
    /* Phi at every node, CSR */
    int64_t *row;
    int32_t *col;
    double *val;
    size_t n_con;
    int64_t *con; /* constrained nodes, ascending */
    unsigned char *is_con;
    double *wf; /* #constrained: fix weight of each (gamma_f / size of its group) */
    int keep_constrained;
    mls_blend blend; /* keep_constrained: the residual's way into the free nodes */
    double *rc;      /* #constrained x 3: the field's miss (scratch) */
    cholmod_common cc;
    cholmod_factor *factor;
    double *coef; /* k x 3 scratch */
    cm_mls_stats stats;
};

/* CPU seconds of the process (all threads): on a loaded machine the wall clock says little. */
static double cpu_seconds(void)
{
    struct timespec ts;
    return clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) ? 0 : (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cm_mls_options_init(cm_mls_options *opt)
{
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    opt->surface_share = 0.7;
    opt->cover = 5;
    opt->lloyd = 5;
    opt->surface_weight = 2;
    opt->stretch = 1;
    opt->bend = 1;
    opt->fix = 1000;
    opt->keep_constrained = 1;
    opt->blend = 1.5;
    opt->seed = 1;
    opt->graded = 0;
}

void cm_mls_destroy(cm_mls **mls)
{
    if (!mls || !*mls) return;
    cm_mls *m = *mls;
    cm_mls_basis_destroy(&m->basis);
    free(m->samples);
    free(m->row);
    free(m->col);
    free(m->val);
    free(m->con);
    free(m->is_con);
    free(m->wf);
    free(m->coef);
    free(m->rc);
    mls_blend_free(&m->blend);
    if (m->factor) cholmod_free_factor(&m->factor, &m->cc);
    cholmod_finish(&m->cc);
    free(m);
    *mls = NULL;
}

void cm_mls_get_stats(const cm_mls *mls, cm_mls_stats *stats)
{
    if (mls && stats) *stats = mls->stats;
}

const double *cm_mls_samples(const cm_mls *mls, size_t *k)
{
    if (k) *k = mls ? mls->k : 0;
    return mls ? mls->samples : NULL;
}

/* For the Shape-Up alternation (shapeup.c), which updates a copy of the factor. */
void mls_view_get(cm_mls *m, mls_view *v)
{
    v->n_nodes = m->n_nodes, v->k = m->k;
    v->row = m->row, v->col = m->col, v->val = m->val;
    v->n_con = m->n_con, v->con = m->con, v->wf = m->wf, v->is_con = m->is_con;
    v->keep_constrained = m->keep_constrained;
    v->factor = m->factor;
    v->blend = m->keep_constrained && m->blend.n ? &m->blend : NULL;
}

/* Sample and cubature positions (section 5): farthest points of the dense surface and
 * volume points, a combined Lloyd relaxation that weights the surface higher; cubature
 * points by Lloyd from a random subset of the integration domain's points, their volume
 * the share of dense points closest to them. */
static cm_status place_points(cm_context *ctx, const cm_mesh *mesh, const cm_mls_options *o,
                              size_t *k, size_t *k_s, size_t *nq, double **samples, double **q,
                              double **qv)
{
    size_t n3 = cm_mesh_count_dim(mesh, 3);
    size_t kk = *k, ks = n3 ? (size_t)(o->surface_share * (double)kk + 0.5) : kk;
    if (ks > kk) ks = kk;
    size_t kv = kk - ks, N = *nq;
    size_t ns = 20 * ks + (n3 ? 0 : 5 * N), nv = n3 ? (20 * kv > 5 * N ? 20 * kv : 5 * N) : 0;
    mls_dense d;
    double t0 = cm_wtime();
    cm_status s = mls_dense_create(ctx, mesh, ns, nv, o->graded, o->seed, &d);
    double t1 = cm_wtime();
    if (s < 0) return s;
    if (d.n_s == 0) kv = kk, ks = 0; /* no surface of positive area */
    if (d.n_v == 0) ks = kk, kv = 0;
    double *c = malloc(kk * 3 * sizeof *c), *w = malloc((d.n_s + d.n_v) * sizeof *w);
    double *qq = malloc(N * 3 * sizeof *qq), *mass = malloc(N * sizeof *mass);
    if (!c || !w || !qq || !mass) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory");
        goto fail;
    }
    if (o->graded > 0) {
        /* graded: the dense points follow the mesh's resolution, and so should the samples; a
         * farthest-point subset would spread them evenly again, so take the first ones (the
         * dense points are drawn at random: a random subset), Lloyd evens them out locally */
        memcpy(c, d.xyz, ks * 3 * sizeof *c);
        memcpy(c + 3 * ks, d.xyz + 3 * d.n_s, kv * 3 * sizeof *c);
    } else {
        if (ks) s = mls_farthest(ctx, d.xyz, d.n_s, ks, o->seed, c);
        if (s >= 0 && kv)
            s = mls_farthest(ctx, d.xyz + 3 * d.n_s, d.n_v, kv, o->seed + 1, c + 3 * ks);
    }
    for (size_t i = 0; i < d.n_s + d.n_v; ++i)
        w[i] = i < d.n_s ? o->surface_weight : 1;
    double t2 = cm_wtime();
    if (s >= 0) s = mls_lloyd(ctx, d.xyz, w, d.n_s + d.n_v, o->lloyd, kk, c, NULL);
    if (s < 0) goto fail;
    double t3 = cm_wtime();
    /* the cubature domain: the volume of a volume mesh, else the surface */
    const double *dom = d.n_v ? d.xyz + 3 * d.n_s : d.xyz;
    size_t nd = d.n_v ? d.n_v : d.n_s;
    double measure = d.n_v ? d.volume : d.area;
    if (N > nd) N = nd;
    {
        /* a random subset (stride through the random points: they are in random order) */
        for (size_t i = 0; i < N; ++i)
            memcpy(qq + 3 * i, dom + 3 * (i * (nd / N)), 3 * sizeof *qq);
    }
    s = mls_lloyd(ctx, dom, NULL, nd, o->lloyd, N, qq, mass);
    /* graded dense points are not uniform: each cubature point's volume is the measure its
     * closest dense points stand for (the positions still follow the points' density) */
    const double *dm = d.n_v ? d.measure + d.n_s : d.measure;
    if (s >= 0 && o->graded > 0) s = mls_lloyd(ctx, dom, dm, nd, 0, N, qq, mass);
    if (s < 0) goto fail;
    cm_log(ctx, CM_LOG_DEBUG,
           "cm_mls: sampling: %zu + %zu dense points %.3f s, farthest points %.3f s, Lloyd of the "
           "samples %.3f s, Lloyd of the %zu cubature points %.3f s",
           d.n_s, d.n_v, t1 - t0, t2 - t1, t3 - t2, N, cm_wtime() - t3);
    if (!(o->graded > 0))
        for (size_t i = 0; i < N; ++i)
            mass[i] *= measure / (double)nd;
    mls_dense_free(&d);
    free(w);
    *k = kk;
    *k_s = ks;
    *nq = N;
    *samples = c;
    *q = qq;
    *qv = mass;
    return CM_OK;
fail:
    mls_dense_free(&d);
    free(c);
    free(w);
    free(qq);
    free(mass);
    return s;
}

/* Counts, then values: the shape functions at n points as CSR. */
static cm_status eval_rows(cm_context *ctx, const cm_mls_basis *b, size_t n, const double *x,
                           int64_t **row_out, int32_t **col_out, double **val_out, double **grad_out,
                           double **lap_out, size_t *uncovered)
{
    int64_t *row = calloc(n + 1, sizeof *row);
    if (!row) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory");
    int nt = cm_context_threads_for(ctx, n, 1000);
    size_t unc = 0;
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1) reduction(+ : unc)
    for (size_t i = 0; i < n; ++i) {
        int m = mls_basis_count(b, x + 3 * i); /* the row lengths: no evaluation needed */
        row[i + 1] = m;
        if (m == 0) ++unc;
    }
    *uncovered = unc;
    for (size_t i = 0; i < n; ++i)
        if (row[i + 1] < 0) {
            free(row);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory");
        }
    for (size_t i = 0; i < n; ++i)
        row[i + 1] += row[i];
    size_t nnz = (size_t)row[n];
    int32_t *col = malloc((nnz ? nnz : 1) * sizeof *col);
    double *val = malloc((nnz ? nnz : 1) * sizeof *val);
    double *grad = grad_out ? malloc((nnz ? nnz : 1) * 3 * sizeof *grad) : NULL;
    double *lap = lap_out ? malloc((nnz ? nnz : 1) * sizeof *lap) : NULL;
    if (!col || !val || (grad_out && !grad) || (lap_out && !lap)) {
        free(row), free(col), free(val), free(grad), free(lap);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory");
    }
    int fail = 0;
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1) reduction(| : fail)
    for (size_t i = 0; i < n; ++i) {
        int64_t p = row[i];
        int m = mls_basis_eval(b, x + 3 * i, col + p, val + p, grad ? grad + 3 * p : NULL,
                               lap ? lap + p : NULL);
        if (m != row[i + 1] - p) fail = 1;
    }
    if (fail) {
        free(row), free(col), free(val), free(grad), free(lap);
        return cm_error(ctx, CM_ERR_INTERNAL, "cm_mls_create: shape function count changed");
    }
    for (size_t i = 0; i < nnz; ++i)
        if (!isfinite(val[i]) || (grad && !(isfinite(grad[3 * i]) && isfinite(grad[3 * i + 1]) &&
                                            isfinite(grad[3 * i + 2]))) ||
            (lap && !isfinite(lap[i]))) {
            free(row), free(col), free(val), free(grad), free(lap);
            return cm_error(ctx, CM_ERR_NUMERIC, "cm_mls_create: non-finite shape function");
        }
    *row_out = row;
    *col_out = col;
    *val_out = val;
    if (grad_out) *grad_out = grad;
    if (lap_out) *lap_out = lap;
    return CM_OK;
}

/* B^T (k x rows, CSC; a column per row of B = [sqrt(ws V) G; sqrt(wb V) L; sqrt(wf) Phi_c]):
 * CHOLMOD factors B^T B directly from it. */
static cm_status factor_system(cm_context *ctx, cm_mls *m, size_t N, const double *qv,
                               const int64_t *qrow, const int32_t *qcol, const double *qgrad,
                               const double *qlap, double ws, double wb)
{
    size_t ncols = 0, nnz = 0;
    for (size_t i = 0; i < N; ++i) {
        size_t c = (size_t)(qrow[i + 1] - qrow[i]);
        if (!(qv[i] > 0)) continue;
        if (ws > 0) ncols += 3, nnz += 3 * c;
        if (wb > 0) ncols += 1, nnz += c;
    }
    for (size_t i = 0; i < m->n_con; ++i)
        ncols += 1, nnz += (size_t)(m->row[m->con[i] + 1] - m->row[m->con[i]]);
    if (nnz > (size_t)INT32_MAX || ncols > (size_t)INT32_MAX)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mls_create: system too large (%zu entries)",
                        nnz);
    cholmod_sparse *bt = cholmod_allocate_sparse(m->k, ncols, nnz, 1, 1, 0, CHOLMOD_REAL, &m->cc);
    if (!bt) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory (CHOLMOD)");
    int *cp = bt->p, *ri = bt->i;
    double *vx = bt->x;
    size_t col = 0, e = 0;
    cp[0] = 0;
    for (size_t i = 0; i < N; ++i) {
        if (!(qv[i] > 0)) continue;
        if (ws > 0)
            for (int d = 0; d < 3; ++d) {
                double f = sqrt(ws * qv[i]);
                for (int64_t p = qrow[i]; p < qrow[i + 1]; ++p)
                    ri[e] = qcol[p], vx[e++] = f * qgrad[3 * p + d];
                cp[++col] = (int)e;
            }
        if (wb > 0) {
            double f = sqrt(wb * qv[i]);
            for (int64_t p = qrow[i]; p < qrow[i + 1]; ++p)
                ri[e] = qcol[p], vx[e++] = f * qlap[p];
            cp[++col] = (int)e;
        }
    }
    for (size_t i = 0; i < m->n_con; ++i) {
        int64_t v = m->con[i];
        double f = sqrt(m->wf[i]);
        for (int64_t p = m->row[v]; p < m->row[v + 1]; ++p)
            ri[e] = m->col[p], vx[e++] = f * m->val[p];
        cp[++col] = (int)e;
    }
    /* a tiny ridge: samples that no cubature point or constraint sees get 0, not a pivot
     * failure; 1e-14 of the mean diagonal changes nothing measurable elsewhere */
    double diag = 0;
    for (size_t i = 0; i < e; ++i)
        diag += vx[i] * vx[i];
    double beta[2] = {1e-14 * diag / (double)m->k, 0};
    m->factor = cholmod_analyze(bt, &m->cc);
    if (m->factor) cholmod_factorize_p(bt, beta, NULL, 0, m->factor, &m->cc);
    cholmod_free_sparse(&bt, &m->cc);
    if (!m->factor || m->cc.status != CHOLMOD_OK) {
        int st = m->cc.status;
        return cm_error(ctx, st == CHOLMOD_OUT_OF_MEMORY ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                        "cm_mls_create: CHOLMOD failed on the %zu x %zu normal equations "
                        "(status %d)",
                        m->k, m->k, st);
    }
    m->stats.factor_nonzeros = m->factor->is_super ? m->factor->xsize : m->factor->nzmax;
    return CM_OK;
}

cm_status cm_mls_create(cm_context *ctx, const cm_mesh *mesh, const unsigned char *constrained,
                        const cm_mls_options *opt, cm_mls **out)
{
    if (!out) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_create: out is NULL");
    *out = NULL;
    if (!mesh || !constrained)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_create: mesh or constrained is NULL");
    cm_mls_options o;
    if (opt)
        o = *opt;
    else
        cm_mls_options_init(&o);
    if (!(o.graded >= 0 && o.graded <= 1))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_create: graded %g: need 0..1", o.graded);
    if (!(o.blend >= 0))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_create: blend %g: need >= 0", o.blend);
    if (!(o.stretch >= 0) || !(o.bend >= 0) || !(o.fix > 0) || o.stretch + o.bend <= 0)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_mls_create: weights stretch %g, bend %g, fix %g: need stretch, bend "
                        ">= 0 (not both 0) and fix > 0",
                        o.stretch, o.bend, o.fix);
    size_t n = mesh->n_nodes;
    cm_mls *m = calloc(1, sizeof *m);
    if (!m) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory");
    cholmod_start(&m->cc);
    m->n_nodes = n;
    m->keep_constrained = o.keep_constrained;
    double *q = NULL, *qv = NULL, *qval = NULL, *qgrad = NULL, *qlap = NULL, *cover = NULL;
    int64_t *qrow = NULL;
    int32_t *qcol = NULL;
    cm_status s = CM_OK;
    m->is_con = calloc(n ? n : 1, 1);
    m->con = malloc((n ? n : 1) * sizeof *m->con);
    if (!m->is_con || !m->con) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; ++i)
        if (constrained[i]) m->is_con[i] = 1, m->con[m->n_con++] = (int64_t)i;
    if (m->n_con == 0) {
        s = cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_create: no constrained node");
        goto done;
    }
    double t0 = cm_wtime(), c0 = cpu_seconds();
    size_t k = o.samples ? o.samples : (n / 50 > 500 ? n / 50 : 500);
    if (k > n) k = n;
    if (k < 4) {
        s = cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mls_create: %zu nodes, need at least 4", n);
        goto done;
    }
    size_t ks = 0, N = o.cubature ? o.cubature : 4 * k;
    s = place_points(ctx, mesh, &o, &k, &ks, &N, &m->samples, &q, &qv);
    if (s < 0) goto done;
    m->k = k;
    double t1 = cm_wtime(), c1 = cpu_seconds();
    cover = malloc((n + N) * 3 * sizeof *cover);
    if (!cover) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory");
        goto done;
    }
    memcpy(cover, mesh->xyz, n * 3 * sizeof *cover);
    memcpy(cover + 3 * n, q, N * 3 * sizeof *cover);
    s = cm_mls_basis_create(ctx, k, m->samples, n + N, cover, o.cover, &m->basis);
    if (s < 0) goto done;
    size_t unc = 0, qunc = 0;
    s = eval_rows(ctx, m->basis, n, mesh->xyz, &m->row, &m->col, &m->val, NULL, NULL, &unc);
    if (s < 0) goto done;
    s = eval_rows(ctx, m->basis, N, q, &qrow, &qcol, &qval, o.stretch > 0 ? &qgrad : NULL,
                  o.bend > 0 ? &qlap : NULL, &qunc);
    if (s < 0) goto done;
    if (unc || qunc) {
        s = cm_error(ctx, CM_ERR_INTERNAL, "cm_mls_create: %zu nodes, %zu cubature points uncovered",
                     unc, qunc);
        goto done;
    }
    double t2 = cm_wtime(), c2 = cpu_seconds();
    /* the length that makes the three terms comparable: the mean support radius, i.e. the
     * resolution of the subspace (the bounding box would let bending swamp the constraints
     * of any feature smaller than the model) */
    double L = 0, V = 0;
    const double *radius = cm_mls_basis_radii(m->basis);
    for (size_t j = 0; j < k; ++j)
        L += radius[j] / (double)k;
    for (size_t i = 0; i < N; ++i)
        V += qv[i];
    if (!(L > 0) || !(V > 0)) {
        s = cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mls_create: degenerate mesh (radius %g, measure %g)",
                     L, V);
        goto done;
    }
    {
        size_t group[256] = {0};
        for (size_t i = 0; i < m->n_con; ++i)
            ++group[constrained[m->con[i]]];
        m->wf = malloc(m->n_con * sizeof *m->wf);
        if (!m->wf) {
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory");
            goto done;
        }
        for (size_t i = 0; i < m->n_con; ++i)
            m->wf[i] = o.fix / (double)group[constrained[m->con[i]]];
    }
    s = factor_system(ctx, m, N, qv, qrow, qcol, qgrad, qlap, o.stretch * L * L / V,
                      o.bend * L * L * L * L / V);
    if (s < 0) goto done;
    if (m->keep_constrained && o.blend > 0) {
        s = mls_blend_create(ctx, n, mesh->xyz, m->is_con, m->n_con, m->con, o.blend * L, &m->blend);
        if (s < 0) goto done;
        m->stats.blend_nodes = m->blend.n;
    }
    m->coef = malloc(k * 3 * sizeof *m->coef);
    m->rc = malloc(m->n_con * 3 * sizeof *m->rc);
    if (!m->coef || !m->rc) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_create: out of memory");
        goto done;
    }
    m->stats.samples = k;
    m->stats.surface_samples = ks;
    m->stats.cubature = N;
    m->stats.constrained = m->n_con;
    m->stats.phi_nonzeros = (size_t)m->row[n];
    m->stats.t_sample = t1 - t0;
    m->stats.t_basis = t2 - t1;
    m->stats.t_factor = cm_wtime() - t2;
    m->stats.c_sample = c1 - c0;
    m->stats.c_basis = c2 - c1;
    m->stats.c_factor = cpu_seconds() - c2;
done:
    free(q), free(qv), free(qval), free(qgrad), free(qlap), free(qrow), free(qcol), free(cover);
    if (s < 0)
        cm_mls_destroy(&m);
    else
        *out = m;
    return s;
}

cm_status cm_mls_apply(cm_context *ctx, cm_mls *m, double *disp, double *residual)
{
    if (!m || !disp) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_apply: NULL argument");
    double t0 = cm_wtime(), c0 = cpu_seconds();
    size_t k = m->k;
    cholmod_dense *b = cholmod_zeros(k, 3, CHOLMOD_REAL, &m->cc);
    if (!b) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_apply: out of memory");
    double *bx = b->x;
    for (size_t i = 0; i < m->n_con; ++i) {
        int64_t v = m->con[i];
        for (int64_t p = m->row[v]; p < m->row[v + 1]; ++p)
            for (int d = 0; d < 3; ++d)
                bx[d * k + (size_t)m->col[p]] += m->wf[i] * m->val[p] * disp[3 * v + d];
    }
    cholmod_dense *x = cholmod_solve(CHOLMOD_A, m->factor, b, &m->cc);
    cholmod_free_dense(&b, &m->cc);
    if (!x) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_apply: CHOLMOD solve failed");
    const double *xx = x->x;
    for (size_t j = 0; j < k; ++j)
        for (int d = 0; d < 3; ++d)
            m->coef[3 * j + d] = xx[d * k + j];
    cholmod_free_dense(&x, &m->cc);
    double res = 0;
    int nt = cm_context_threads_for(ctx, m->n_nodes, 5000);
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1) reduction(max : res)
    for (size_t i = 0; i < m->n_nodes; ++i) {
        double d[3] = {0, 0, 0};
        for (int64_t p = m->row[i]; p < m->row[i + 1]; ++p)
            for (int a = 0; a < 3; ++a)
                d[a] += m->val[p] * m->coef[3 * (size_t)m->col[p] + a];
        if (m->is_con[i]) {
            double e = sqrt((d[0] - disp[3 * i]) * (d[0] - disp[3 * i]) +
                            (d[1] - disp[3 * i + 1]) * (d[1] - disp[3 * i + 1]) +
                            (d[2] - disp[3 * i + 2]) * (d[2] - disp[3 * i + 2]));
            if (e > res) res = e;
            if (m->keep_constrained) continue;
        }
        for (int a = 0; a < 3; ++a)
            disp[3 * i + a] = d[a];
    }
    if (!isfinite(res))
        return cm_error(ctx, CM_ERR_NUMERIC, "cm_mls_apply: non-finite displacement");
    if (m->keep_constrained && m->blend.n) {
        /* the miss at each constrained node (its disp is the prescribed value), then into the
         * band of free nodes around them */
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
        for (size_t i = 0; i < m->n_con; ++i) {
            int64_t v = m->con[i];
            double d[3] = {0, 0, 0};
            for (int64_t p = m->row[v]; p < m->row[v + 1]; ++p)
                for (int a = 0; a < 3; ++a)
                    d[a] += m->val[p] * m->coef[3 * (size_t)m->col[p] + a];
            for (int a = 0; a < 3; ++a)
                m->rc[3 * i + a] = disp[3 * v + a] - d[a];
        }
        mls_blend_apply(&m->blend, m->rc, disp, nt);
    }
    if (residual) *residual = res;
    m->stats.t_apply = cm_wtime() - t0;
    m->stats.c_apply = cpu_seconds() - c0;
    return CM_OK;
}

/* apply's steps turned round, in reverse order: the blend, the evaluation, the solve (the
 * normal equations are symmetric), the right-hand side. */
cm_status cm_mls_apply_transpose(cm_context *ctx, cm_mls *m, const double *v, double *out)
{
    if (!m || !v || !out)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_apply_transpose: NULL argument");
    size_t k = m->k, n = m->n_nodes;
    cholmod_dense *g = cholmod_zeros(k, 3, CHOLMOD_REAL, &m->cc);
    if (!g) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_apply_transpose: out of memory");
    double *gx = g->x;
    memset(out, 0, 3 * n * sizeof *out);
    /* the blend: disp_j += sum_b w_jb rc_b, rc = prescribed - field at the constrained nodes */
    if (m->keep_constrained && m->blend.n) {
        memset(m->rc, 0, 3 * m->n_con * sizeof *m->rc);
        const mls_blend *b = &m->blend;
        for (size_t j = 0; j < b->n; ++j)
            for (int64_t p = b->row[j]; p < b->row[j + 1]; ++p)
                for (int a = 0; a < 3; ++a)
                    m->rc[3 * (size_t)b->col[p] + a] += b->val[p] * v[3 * (size_t)b->node[j] + a];
    }
    /* the evaluation d_i = Phi_i coef at the nodes that get the field's value */
    for (size_t i = 0; i < n; ++i) {
        if (m->is_con[i] && m->keep_constrained) continue;
        for (int64_t p = m->row[i]; p < m->row[i + 1]; ++p)
            for (int d = 0; d < 3; ++d)
                gx[d * k + (size_t)m->col[p]] += m->val[p] * v[3 * i + d];
    }
    if (m->keep_constrained)
        for (size_t c = 0; c < m->n_con; ++c) {
            int64_t vc = m->con[c];
            for (int d = 0; d < 3; ++d) {
                double r = m->blend.n ? m->rc[3 * c + d] : 0;
                out[3 * vc + d] += v[3 * vc + d] + r;
                for (int64_t p = m->row[vc]; p < m->row[vc + 1] && r != 0; ++p)
                    gx[d * k + (size_t)m->col[p]] -= m->val[p] * r;
            }
        }
    cholmod_dense *y = cholmod_solve(CHOLMOD_A, m->factor, g, &m->cc);
    cholmod_free_dense(&g, &m->cc);
    if (!y) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_apply_transpose: CHOLMOD solve failed");
    const double *yx = y->x;
    /* the right-hand side b = sum_c wf_c Phi_c^T D_c */
    for (size_t c = 0; c < m->n_con; ++c) {
        int64_t vc = m->con[c];
        for (int64_t p = m->row[vc]; p < m->row[vc + 1]; ++p)
            for (int d = 0; d < 3; ++d)
                out[3 * vc + d] += m->wf[c] * m->val[p] * yx[d * k + (size_t)m->col[p]];
    }
    cholmod_free_dense(&y, &m->cc);
    return CM_OK;
}
