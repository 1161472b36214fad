/* FFD in displacement form (paper section 2.1, eq. 2): d(x) = sum_p dc_p N_p(u(x)). Storing
 * displacements instead of moved control points makes zero displacements give d = 0 bit for
 * bit (PyGeM's position form leaves ~1e-15). */
#include "ffd_internal.h"

#include <stdlib.h>
#include <string.h>

/* d = sum_p dc_p N_p(u) over the support of u. */
static void eval_point(const cm_ffd *f, const double *dc, const double u[3], double d[3])
{
    double nv[3][CM_FFD_MAX_AXIS];
    int first[3], cnt[3];
    for (int a = 0; a < 3; ++a)
        first[a] = cm_ffd_axis_basis(f, a, u[a], nv[a], NULL, &cnt[a]);
    double s0 = 0, s1 = 0, s2 = 0;
    for (int i = 0; i < cnt[0]; ++i)
        for (int j = 0; j < cnt[1]; ++j) {
            double wij = nv[0][i] * nv[1][j];
            const double *c =
                dc + 3 * (((size_t)(first[0] + i) * f->n[1] + first[1] + j) * f->n[2] + first[2]);
            for (int k = 0; k < cnt[2]; ++k) {
                double w = wij * nv[2][k];
                s0 += w * c[3 * k];
                s1 += w * c[3 * k + 1];
                s2 += w * c[3 * k + 2];
            }
        }
    d[0] = s0;
    d[1] = s1;
    d[2] = s2;
}

cm_status cm_ffd_deform(cm_context *ctx, const cm_ffd *ffd, const double *dc, size_t n,
                        const double *x, double *d, cm_ffd_stats *stats)
{
    if (!ffd || !dc || (n && (!x || !d)))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_deform: NULL input");
    size_t nin = 0, nout = 0, nfail = 0;
    int maxit = 0;
    int threads = cm_context_threads_for(ctx, n, 2000);
#pragma omp parallel for schedule(static) num_threads(threads) reduction(+ : nin, nout, nfail) \
    reduction(max : maxit)
    for (size_t i = 0; i < n; ++i) {
        double u[3];
        int it, r = cm_ffd_locate(ffd, x + 3 * i, u, &it);
        if (it > maxit) maxit = it;
        if (r == 1) {
            eval_point(ffd, dc, u, d + 3 * i);
            ++nin;
        } else {
            d[3 * i] = d[3 * i + 1] = d[3 * i + 2] = 0;
            nout += r == 0;
            nfail += r == 2;
        }
    }
    if (stats) {
        stats->inside = nin;
        stats->outside = nout;
        stats->failed = nfail;
        stats->max_iterations = maxit;
    }
    if (nfail)
        return cm_error(ctx, CM_WARNING,
                        "cm_ffd_deform: Newton did not invert %zu of %zu points (folded lattice?); "
                        "they are not moved",
                        nfail, n);
    return CM_OK;
}

/* gdc += sum_p N_p(u) v over the support of u: eval_point's loops, the product turned round. */
static void scatter_point(const cm_ffd *f, const double v[3], const double u[3], double *gdc)
{
    double nv[3][CM_FFD_MAX_AXIS];
    int first[3], cnt[3];
    for (int a = 0; a < 3; ++a)
        first[a] = cm_ffd_axis_basis(f, a, u[a], nv[a], NULL, &cnt[a]);
    for (int i = 0; i < cnt[0]; ++i)
        for (int j = 0; j < cnt[1]; ++j) {
            double wij = nv[0][i] * nv[1][j];
            double *c =
                gdc + 3 * (((size_t)(first[0] + i) * f->n[1] + first[1] + j) * f->n[2] + first[2]);
            for (int k = 0; k < cnt[2]; ++k) {
                double w = wij * nv[2][k];
                c[3 * k] += w * v[0];
                c[3 * k + 1] += w * v[1];
                c[3 * k + 2] += w * v[2];
            }
        }
}

cm_status cm_ffd_deform_transpose(cm_context *ctx, const cm_ffd *ffd, size_t n, const double *x,
                                  const double *v, double *gdc, cm_ffd_stats *stats)
{
    if (!ffd || !gdc || (n && (!x || !v)))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_deform_transpose: NULL input");
    double *u = malloc((n ? n : 1) * 3 * sizeof *u);
    unsigned char *in = malloc(n ? n : 1);
    if (!u || !in) {
        free(u);
        free(in);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_ffd_deform_transpose: out of memory");
    }
    /* the location in parallel (Newton on a moved lattice is the cost), the scatter in point
     * order: many points share a control point, and the sum does not depend on threads */
    cm_ffd_stats st;
    cm_status s = cm_ffd_local_coords(ctx, ffd, n, x, u, in, &st);
    memset(gdc, 0, ffd->n_ctrl * 3 * sizeof *gdc);
    for (size_t i = 0; i < n && s >= 0; ++i)
        if (in[i] == 1) scatter_point(ffd, v + 3 * i, u + 3 * i, gdc);
    free(u);
    free(in);
    if (s == CM_WARNING)
        s = cm_error(ctx, CM_WARNING,
                     "cm_ffd_deform_transpose: Newton did not invert %zu of %zu points (folded "
                     "lattice?); they send nothing",
                     st.failed, n);
    if (stats) *stats = st;
    return s;
}
