/* The mesh-based thin-shell deformation of the paper's section 3 (eq. 10), the ground truth the
 * MLS subspace is measured against: piecewise-linear displacements on the triangles minimising
 * gs sum_t A_t |grad d|^2 + gb sum_i A_i |lap d_i|^2 + gf sum_{H u F} A_i |d_i - dbar_i|^2,
 * with the cotangent operators. CHOLMOD factors W^T W from W^T directly (W: the rows of the
 * three terms), as for eq. 14. Quads and polygons are fanned into triangles. */
#include "cadmorph/mls.h"

#include <cholmod.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct tri_list {
    size_t n;
    int64_t *v; /* n x 3 */
} tri_list;

/* A face with a repeated corner or no area is bad input, not a system to factor: its rows
 * would repeat an index in one CHOLMOD column (CHOLMOD refuses the matrix) or leave its nodes
 * without area (a singular system). The caller knows the file and adds it. */
static cm_status check_face(cm_context *ctx, const cm_mesh *mesh, size_t c, const cm_cell_info *info,
                            const int64_t *p, int64_t len)
{
    for (int64_t i = 0; i < len; ++i)
        for (int64_t j = i + 1; j < len; ++j)
            if (p[i] == p[j])
                return cm_error(ctx, CM_ERR_FORMAT,
                                "cell %zu (0-based, %s): corners %lld and %lld are the same node %lld: "
                                "a degenerate face",
                                c, info->name, (long long)i + 1, (long long)j + 1, (long long)p[i]);
    /* the area vector of the fan, against the square of the longest edge: a face whose corners
     * are (to round-off) on one line has none */
    const double *X = mesh->xyz, *o = X + 3 * p[0];
    double n[3] = {0, 0, 0}, e2 = 0;
    for (int64_t i = 0; i < len; ++i) {
        const double *a = X + 3 * p[i], *b = X + 3 * p[(i + 1) % len];
        const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        e2 = fmax(e2, d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (i == 0 || i + 1 == len) continue;
        const double u[3] = {a[0] - o[0], a[1] - o[1], a[2] - o[2]};
        const double v[3] = {b[0] - o[0], b[1] - o[1], b[2] - o[2]};
        n[0] += u[1] * v[2] - u[2] * v[1];
        n[1] += u[2] * v[0] - u[0] * v[2];
        n[2] += u[0] * v[1] - u[1] * v[0];
    }
    const double a2 = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(a2 > 1e-14 * e2))
        return cm_error(ctx, CM_ERR_FORMAT,
                        "cell %zu (0-based, %s, nodes %lld %lld %lld%s): the face has no area: a "
                        "degenerate face",
                        c, info->name, (long long)p[0], (long long)p[1], (long long)p[2], len > 3 ? " ..." : "");
    return CM_OK;
}

static cm_status collect(cm_context *ctx, const cm_mesh *mesh, tri_list *t)
{
    size_t cap = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!info || info->dim != 2) continue;
        int64_t len = info->corners > 0 ? info->corners : mesh->offset[c + 1] - mesh->offset[c];
        if (len >= 3) cap += (size_t)(len - 2);
    }
    t->n = 0;
    t->v = malloc((cap ? cap : 1) * 3 * sizeof *t->v);
    if (!t->v) return cm_error(ctx, CM_ERR_NOMEM, "cm_mls_shell: out of memory");
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!info || info->dim != 2) continue;
        const int64_t *p = mesh->conn + mesh->offset[c];
        int64_t len = info->corners > 0 ? info->corners : mesh->offset[c + 1] - mesh->offset[c];
        cm_status s = check_face(ctx, mesh, c, info, p, len);
        if (s < 0) {
            free(t->v);
            t->v = NULL;
            return s;
        }
        for (int64_t f = 1; f + 1 < len; ++f) {
            t->v[3 * t->n] = p[0], t->v[3 * t->n + 1] = p[f], t->v[3 * t->n + 2] = p[f + 1];
            ++t->n;
        }
    }
    return CM_OK;
}

cm_status cm_mls_shell(cm_context *ctx, const cm_mesh *mesh, const unsigned char *constrained,
                       double stretch, double bend, double fix, double *disp)
{
    if (!mesh || !constrained || !disp)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_shell: NULL argument");
    if (!(stretch >= 0) || !(bend >= 0) || !(fix > 0) || stretch + bend <= 0)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mls_shell: weights %g %g %g", stretch, bend, fix);
    size_t n = mesh->n_nodes;
    tri_list t = {0, NULL};
    cm_status s = collect(ctx, mesh, &t);
    if (s < 0) return s;
    if (t.n == 0) {
        free(t.v);
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mls_shell: the mesh has no faces");
    }
    cholmod_common cc;
    cholmod_start(&cc);
    cholmod_triplet *kt = cholmod_allocate_triplet(n, n, 9 * t.n, 0, CHOLMOD_REAL, &cc);
    double *area = calloc(n ? n : 1, sizeof *area), *grad = malloc(t.n * 9 * sizeof *grad);
    double *tarea = malloc(t.n * sizeof *tarea);
    cholmod_sparse *K = NULL, *wt = NULL;
    cholmod_factor *L = NULL;
    cholmod_dense *b = NULL, *x = NULL;
    if (!kt || !area || !grad || !tarea) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_shell: out of memory");
        goto done;
    }
    const double *X = mesh->xyz;
    int *ti = kt->i, *tj = kt->j;
    double *tx = kt->x;
    for (size_t f = 0; f < t.n; ++f) {
        const int64_t *v = t.v + 3 * f;
        double e[3][3], nrm[3];
        for (int q = 0; q < 3; ++q)
            for (int a = 0; a < 3; ++a)
                e[q][a] = X[3 * v[(q + 2) % 3] + a] - X[3 * v[(q + 1) % 3] + a];
        nrm[0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
        nrm[1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
        nrm[2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
        double a2 = sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
        tarea[f] = a2 / 2;
        for (int q = 0; q < 9; ++q)
            grad[9 * f + q] = 0;
        if (!(a2 > 0)) continue; /* a degenerate triangle adds nothing */
        for (int q = 0; q < 3; ++q) {
            area[v[q]] += a2 / 6;
            /* grad of the hat function of v[q]: n x e_q / (2A), e_q the opposite edge */
            double u[3] = {nrm[0] / a2, nrm[1] / a2, nrm[2] / a2};
            double g[3] = {u[1] * e[q][2] - u[2] * e[q][1], u[2] * e[q][0] - u[0] * e[q][2],
                           u[0] * e[q][1] - u[1] * e[q][0]};
            for (int a = 0; a < 3; ++a)
                grad[9 * f + 3 * q + a] = g[a] / a2;
        }
        /* K_ij = A_t grad_i . grad_j */
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                const double *gi = grad + 9 * f + 3 * i, *gj = grad + 9 * f + 3 * j;
                ti[kt->nnz] = (int)v[i], tj[kt->nnz] = (int)v[j];
                tx[kt->nnz++] = tarea[f] * (gi[0] * gj[0] + gi[1] * gj[1] + gi[2] * gj[2]);
            }
    }
    K = cholmod_triplet_to_sparse(kt, 0, &cc); /* sums duplicates, CSC, sorted */
    if (!K) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_shell: out of memory (CHOLMOD)");
        goto done;
    }
    /* W^T: columns = rows of W: 3 per triangle (sqrt(gs A_t) grad), 1 per node
     * (sqrt(gb / A_i) K_i: the area-weighted Laplacian row), 1 per constrained node */
    size_t ncon = 0, ncol = 0, nnz = 0;
    for (size_t i = 0; i < n; ++i)
        ncon += constrained[i] != 0;
    if (stretch > 0) ncol += 3 * t.n, nnz += 9 * t.n;
    if (bend > 0) ncol += n, nnz += (size_t)((int *)K->p)[n];
    ncol += ncon, nnz += ncon;
    wt = cholmod_allocate_sparse(n, ncol, nnz, 1, 1, 0, CHOLMOD_REAL, &cc);
    if (!wt) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_shell: out of memory (CHOLMOD)");
        goto done;
    }
    int *cp = wt->p, *ri = wt->i, *kp = K->p, *ki = K->i;
    double *vx = wt->x, *kx = K->x;
    size_t col = 0, e = 0;
    cp[0] = 0;
    if (stretch > 0)
        for (size_t f = 0; f < t.n; ++f)
            for (int a = 0; a < 3; ++a) {
                /* the three vertex ids in ascending order: CHOLMOD wants sorted columns */
                int64_t v[3] = {t.v[3 * f], t.v[3 * f + 1], t.v[3 * f + 2]};
                int o[3] = {0, 1, 2};
                for (int p = 0; p < 3; ++p)
                    for (int q = p + 1; q < 3; ++q)
                        if (v[o[q]] < v[o[p]]) {
                            int tmp = o[p];
                            o[p] = o[q], o[q] = tmp;
                        }
                double w = sqrt(stretch * tarea[f]);
                for (int p = 0; p < 3; ++p)
                    ri[e] = (int)v[o[p]], vx[e++] = w * grad[9 * f + 3 * o[p] + a];
                cp[++col] = (int)e;
            }
    if (bend > 0)
        for (size_t i = 0; i < n; ++i) {
            /* K is symmetric: column i is row i */
            double w = area[i] > 0 ? sqrt(bend / area[i]) : 0;
            for (int p = kp[i]; p < kp[i + 1]; ++p)
                ri[e] = ki[p], vx[e++] = w * kx[p];
            cp[++col] = (int)e;
        }
    for (size_t i = 0; i < n; ++i)
        if (constrained[i]) {
            ri[e] = (int)i, vx[e++] = sqrt(fix * area[i]);
            cp[++col] = (int)e;
        }
    L = cholmod_analyze(wt, &cc);
    if (L) cholmod_factorize(wt, L, &cc);
    if (!L || cc.status != CHOLMOD_OK) {
        s = cm_error(ctx, CM_ERR_NUMERIC,
                     "cm_mls_shell: CHOLMOD failed (status %d): a component without a "
                     "constrained node?",
                     cc.status);
        goto done;
    }
    b = cholmod_zeros(n, 3, CHOLMOD_REAL, &cc);
    if (!b) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_shell: out of memory");
        goto done;
    }
    double *bx = b->x;
    for (size_t i = 0; i < n; ++i)
        if (constrained[i])
            for (int a = 0; a < 3; ++a)
                bx[a * n + i] = fix * area[i] * disp[3 * i + a];
    x = cholmod_solve(CHOLMOD_A, L, b, &cc);
    if (!x) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mls_shell: CHOLMOD solve failed");
        goto done;
    }
    const double *xx = x->x;
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a)
            disp[3 * i + a] = xx[a * n + i];
done:
    cholmod_free_dense(&x, &cc);
    cholmod_free_dense(&b, &cc);
    cholmod_free_factor(&L, &cc);
    cholmod_free_sparse(&wt, &cc);
    cholmod_free_sparse(&K, &cc);
    cholmod_free_triplet(&kt, &cc);
    cholmod_finish(&cc);
    free(area), free(grad), free(tarea), free(t.v);
    return s;
}
