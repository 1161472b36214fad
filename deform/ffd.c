/* FFD in displacement form (paper section 2.1, eq. 2): d(x) = sum_p dc_p N_p(u(x)). Storing
 * displacements instead of moved control points makes zero displacements give d = 0 bit for
 * bit (PyGeM's position form leaves ~1e-15). */
#include "ffd_internal.h"

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
