/* MLS shape functions with a linear basis (paper section 4): weight
 * w(r) = cos(pi r / sigma) / 2 + 1/2 for r < sigma, a radius per sample so that every given
 * point is covered by at least s samples, the moment matrix by its pseudo-inverse (4x4 SVD,
 * so that coplanar samples are not singular), analytic gradients and Laplacians. */
#include "mls_internal.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Supports reach a little beyond the s-th nearest sample so that its weight is not ~0. */
#define MLS_SUPPORT_MARGIN 1.25
#define MLS_PI 3.14159265358979323846
/* Singular values below this fraction of the largest are treated as 0 (pseudo-inverse). */
#define MLS_PINV_RTOL 1e-10

void cm_mls_basis_destroy(cm_mls_basis **b)
{
    if (!b || !*b) return;
    free((*b)->c);
    free((*b)->sigma);
    free((*b)->start);
    free((*b)->items);
    free(*b);
    *b = NULL;
}

/* Lists each sample in every grid cell its support box overlaps: a point's candidates are
 * then its own cell's list. */
static cm_status build_support_grid(cm_context *ctx, cm_mls_basis *b)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double mean = 0;
    for (size_t j = 0; j < b->k; ++j) {
        for (int a = 0; a < 3; ++a) {
            lo[a] = fmin(lo[a], b->c[3 * j + a] - b->sigma[j]);
            hi[a] = fmax(hi[a], b->c[3 * j + a] + b->sigma[j]);
        }
        mean += b->sigma[j];
    }
    mean /= (double)b->k;
    double h = mean;
    for (;;) {
        double cells = 1;
        for (int a = 0; a < 3; ++a)
            cells *= floor((hi[a] - lo[a]) / h) + 1;
        if (cells <= 2e6) break;
        h *= 1.5;
    }
    size_t nc = 1;
    for (int a = 0; a < 3; ++a) {
        b->lo[a] = lo[a];
        b->n[a] = (int)floor((hi[a] - lo[a]) / h) + 1;
        nc *= (size_t)b->n[a];
    }
    b->h = h;
    b->start = calloc(nc + 1, sizeof *b->start);
    if (!b->start) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls: out of memory (support grid)");
    for (int pass = 0; pass < 2; ++pass) {
        int32_t *fill = NULL;
        if (pass == 1) {
            for (size_t c = 0; c < nc; ++c)
                b->start[c + 1] += b->start[c];
            if ((size_t)b->start[nc] > (size_t)INT32_MAX / 2)
                return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mls: support grid too large");
            b->items = malloc(((size_t)b->start[nc] + 1) * sizeof *b->items);
            fill = malloc(nc * sizeof *fill);
            if (!b->items || !fill) {
                free(fill);
                return cm_error(ctx, CM_ERR_NOMEM, "cm_mls: out of memory (support grid)");
            }
            memcpy(fill, b->start, nc * sizeof *fill);
        }
        for (size_t j = 0; j < b->k; ++j) {
            int c0[3], c1[3];
            for (int a = 0; a < 3; ++a) {
                c0[a] = (int)floor((b->c[3 * j + a] - b->sigma[j] - lo[a]) / h);
                c1[a] = (int)floor((b->c[3 * j + a] + b->sigma[j] - lo[a]) / h);
                if (c0[a] < 0) c0[a] = 0;
                if (c1[a] >= b->n[a]) c1[a] = b->n[a] - 1;
            }
            for (int z = c0[2]; z <= c1[2]; ++z)
                for (int y = c0[1]; y <= c1[1]; ++y)
                    for (int x = c0[0]; x <= c1[0]; ++x) {
                        size_t c = ((size_t)z * b->n[1] + y) * b->n[0] + x;
                        if (pass == 0)
                            ++b->start[c + 1];
                        else
                            b->items[fill[c]++] = (int32_t)j;
                    }
        }
        free(fill);
    }
    b->max_list = 0;
    for (size_t c = 0; c < nc; ++c)
        if (b->start[c + 1] - b->start[c] > b->max_list) b->max_list = b->start[c + 1] - b->start[c];
    return CM_OK;
}

cm_status cm_mls_basis_create(cm_context *ctx, size_t k, const double *centres, size_t n_points,
                              const double *points, int cover, cm_mls_basis **out)
{
    if (!out) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_basis_create: out is NULL");
    *out = NULL;
    if (!centres || (n_points && !points))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_basis_create: centres or points is NULL");
    if (cover < 1) cover = 1;
    if (k < 4 || k < (size_t)cover)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_mls_basis_create: %zu samples, need at least 4 and the cover %d", k,
                        cover);
    if (k > (size_t)INT32_MAX)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mls_basis_create: too many samples");
    cm_mls_basis *b = calloc(1, sizeof *b);
    if (!b) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_basis_create: out of memory");
    b->k = k;
    b->c = malloc(k * 3 * sizeof *b->c);
    b->sigma = calloc(k, sizeof *b->sigma);
    int32_t *nidx = malloc(((n_points ? n_points : 1) * (size_t)cover) * sizeof *nidx);
    double *ndist = malloc(((n_points ? n_points : 1) * (size_t)cover) * sizeof *ndist);
    mls_grid g = {0};
    cm_status s = CM_OK;
    if (!b->c || !b->sigma || !nidx || !ndist) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_basis_create: out of memory");
        goto done;
    }
    memcpy(b->c, centres, k * 3 * sizeof *b->c);
    s = mls_grid_build(ctx, &g, k, b->c, 2.0);
    if (s < 0) goto done;
    /* sigma_j: the farthest point that has sample j among its s nearest, with a margin */
    int nt = cm_context_threads_for(ctx, n_points, 2000);
#pragma omp parallel for schedule(static) num_threads(nt) if (nt > 1)
    for (size_t i = 0; i < n_points; ++i) {
        int m = mls_grid_nearest(&g, points + 3 * i, cover, nidx + i * cover, ndist + i * cover);
        for (int q = m; q < cover; ++q) {
            nidx[i * cover + q] = -1;
            ndist[i * cover + q] = 0;
        }
    }
    for (size_t i = 0; i < n_points * (size_t)cover; ++i)
        if (nidx[i] >= 0 && ndist[i] > b->sigma[nidx[i]]) b->sigma[nidx[i]] = ndist[i];
    /* a sample no point chose still needs a support: its own s-th nearest sample */
    for (size_t j = 0; j < k; ++j) {
        int32_t id[64];
        double di[64];
        int want = cover + 1 < 64 ? cover + 1 : 64;
        int m = mls_grid_nearest(&g, b->c + 3 * j, want, id, di);
        double own = m ? di[m - 1] : 0;
        if (b->sigma[j] < own) b->sigma[j] = own;
        b->sigma[j] *= MLS_SUPPORT_MARGIN;
        if (!(b->sigma[j] > 0)) {
            s = cm_error(ctx, CM_ERR_NUMERIC,
                         "cm_mls_basis_create: sample %zu has a zero support (coincident samples)",
                         j);
            goto done;
        }
    }
    s = build_support_grid(ctx, b);
done:
    mls_grid_free(&g);
    free(nidx);
    free(ndist);
    if (s < 0)
        cm_mls_basis_destroy(&b);
    else
        *out = b;
    return s;
}

size_t cm_mls_basis_max_support(const cm_mls_basis *b) { return b ? (size_t)b->max_list : 0; }
const double *cm_mls_basis_radii(const cm_mls_basis *b) { return b ? b->sigma : NULL; }

/* M+ of a symmetric 4x4 (row-major) by SVD: V S+ U^T. */
static void pinv4(const double *m, double *out)
{
    double a[16], s[4], u[16], vt[16], superb[3];
    memcpy(a, m, sizeof a);
    if (LAPACKE_dgesvd(LAPACK_ROW_MAJOR, 'A', 'A', 4, 4, a, 4, s, u, 4, vt, 4, superb) != 0) {
        memset(out, 0, 16 * sizeof *out);
        return;
    }
    double tol = MLS_PINV_RTOL * s[0];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double v = 0;
            for (int q = 0; q < 4; ++q)
                if (s[q] > tol) v += vt[4 * q + i] * u[4 * j + q] / s[q];
            out[4 * i + j] = v;
        }
}

static void mv4(const double *m, const double *x, double *y)
{
    for (int i = 0; i < 4; ++i)
        y[i] = m[4 * i] * x[0] + m[4 * i + 1] * x[1] + m[4 * i + 2] * x[2] + m[4 * i + 3] * x[3];
}

static double dot4(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
}

/* Basis in coordinates local to x, p(y) = (1, (y - x)/rho): the MLS shape functions do not
 * depend on an affine change of the polynomial basis, so x may be held fixed while
 * differentiating, and M stays well conditioned far from the origin. With
 * gamma = M+ p(x): phi_j = w_j gamma.P_j, gamma_,k = M+ (p_,k - M_,k gamma),
 * lap gamma = -M+ (lap M gamma + 2 sum_k M_,k gamma_,k) (p is linear). */
int mls_basis_count(const cm_mls_basis *b, const double x[3])
{
    int ci[3];
    for (int a = 0; a < 3; ++a) {
        double t = floor((x[a] - b->lo[a]) / b->h);
        if (!(t >= 0) || t >= b->n[a]) return 0;
        ci[a] = (int)t;
    }
    size_t c = ((size_t)ci[2] * b->n[1] + ci[1]) * b->n[0] + ci[0];
    int m = 0;
    for (int32_t p = b->start[c]; p < b->start[c + 1]; ++p) {
        int32_t j = b->items[p];
        const double *cj = b->c + 3 * (size_t)j;
        double d2 = (x[0] - cj[0]) * (x[0] - cj[0]) + (x[1] - cj[1]) * (x[1] - cj[1]) +
                    (x[2] - cj[2]) * (x[2] - cj[2]);
        m += d2 < b->sigma[j] * b->sigma[j];
    }
    return m;
}

int mls_basis_eval(const cm_mls_basis *b, const double x[3], int32_t *idx, double *phi,
                   double *grad, double *lap)
{
    int ci[3];
    for (int a = 0; a < 3; ++a) {
        double t = floor((x[a] - b->lo[a]) / b->h);
        if (!(t >= 0) || t >= b->n[a]) return 0; /* outside every support (or NaN) */
        ci[a] = (int)t;
    }
    size_t c = ((size_t)ci[2] * b->n[1] + ci[1]) * b->n[0] + ci[0];
    int m = 0;
    double rho = 0;
    for (int32_t p = b->start[c]; p < b->start[c + 1]; ++p) {
        int32_t j = b->items[p];
        const double *cj = b->c + 3 * (size_t)j;
        double d2 = (x[0] - cj[0]) * (x[0] - cj[0]) + (x[1] - cj[1]) * (x[1] - cj[1]) +
                    (x[2] - cj[2]) * (x[2] - cj[2]);
        if (d2 < b->sigma[j] * b->sigma[j]) {
            idx[m++] = j;
            if (b->sigma[j] > rho) rho = b->sigma[j];
        }
    }
    if (m == 0) return 0;
    /* per neighbour: P (4), w, grad w (3), lap w; kept in phi/grad/lap scratch afterwards */
    double M[16] = {0}, Mk[3][16] = {{0}}, ML[16] = {0};
    enum { STRIDE = 9 };
    double stack[STRIDE * 64];
    double *tmp = m <= 64 ? stack : malloc((size_t)m * STRIDE * sizeof *tmp);
    if (!tmp) return -1;
    for (int q = 0; q < m; ++q) {
        const double *cj = b->c + 3 * (size_t)idx[q];
        double sg = b->sigma[idx[q]];
        double dx[3] = {x[0] - cj[0], x[1] - cj[1], x[2] - cj[2]};
        double r = sqrt(dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
        double a = MLS_PI * r / sg;
        double sinc = a > 1e-4 ? sin(a) / a : 1 - a * a / 6;
        double cs = cos(a);
        double w = 0.5 * cs + 0.5;
        double k2 = MLS_PI * MLS_PI / (2 * sg * sg);
        double wr = -k2 * sinc; /* w'(r) / r */
        double *t = tmp + STRIDE * q;
        t[0] = 1;
        for (int d = 0; d < 3; ++d)
            t[1 + d] = -dx[d] / rho;
        t[4] = w;
        for (int d = 0; d < 3; ++d)
            t[5 + d] = wr * dx[d];
        t[8] = -k2 * (cs + 2 * sinc);
        if (grad || lap)
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j) {
                    double pp = t[i] * t[j];
                    M[4 * i + j] += w * pp;
                    for (int d = 0; d < 3; ++d)
                        Mk[d][4 * i + j] += t[5 + d] * pp;
                    ML[4 * i + j] += t[8] * pp;
                }
        else /* values only (the nodes): the derivative moments are not needed */
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j)
                    M[4 * i + j] += w * (t[i] * t[j]);
    }
    double Mi[16], g[4], e1[4] = {1, 0, 0, 0}, gk[3][4], lg[4];
    pinv4(M, Mi);
    mv4(Mi, e1, g);
    if (grad || lap)
        for (int d = 0; d < 3; ++d) {
            double v[4], mg[4];
            mv4(Mk[d], g, mg);
            for (int i = 0; i < 4; ++i)
                v[i] = (i == d + 1 ? 1 / rho : 0) - mg[i];
            mv4(Mi, v, gk[d]);
        }
    if (lap) {
        double v[4], t4[4];
        mv4(ML, g, v);
        for (int d = 0; d < 3; ++d) {
            mv4(Mk[d], gk[d], t4);
            for (int i = 0; i < 4; ++i)
                v[i] += 2 * t4[i];
        }
        mv4(Mi, v, lg);
        for (int i = 0; i < 4; ++i)
            lg[i] = -lg[i];
    }
    for (int q = 0; q < m; ++q) {
        const double *t = tmp + STRIDE * q;
        double gp = dot4(g, t);
        phi[q] = t[4] * gp;
        if (grad)
            for (int d = 0; d < 3; ++d)
                grad[3 * q + d] = t[4] * dot4(gk[d], t) + t[5 + d] * gp;
        if (lap) {
            double v = t[4] * dot4(lg, t) + t[8] * gp;
            for (int d = 0; d < 3; ++d)
                v += 2 * t[5 + d] * dot4(gk[d], t);
            lap[q] = v;
        }
    }
    if (tmp != stack) free(tmp);
    return m;
}

cm_status cm_mls_basis_eval(cm_context *ctx, const cm_mls_basis *b, const double x[3],
                            size_t max, size_t *count, int32_t *idx, double *phi, double *grad,
                            double *lap)
{
    if (!b || !x || !count || !idx || !phi)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_basis_eval: NULL argument");
    if (max < (size_t)b->max_list)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_mls_basis_eval: room for %zu entries, cm_mls_basis_max_support is %d",
                        max, b->max_list);
    int m = mls_basis_eval(b, x, idx, phi, grad, lap);
    if (m < 0) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_basis_eval: out of memory");
    *count = (size_t)m;
    return CM_OK;
}
