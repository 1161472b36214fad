/* FEMWARP (Baker 2001; Staten et al. 2011, paper section 5): the displacement of the free
 * nodes solves the linear finite-element Laplace equation on M0 with the prescribed
 * displacement at the constrained nodes, K_II d_I = -K_IB d_B. Since linear elements
 * reproduce affine fields, this is the same system as Baker's for the new coordinates.
 * K_II is sparse SPD: CHOLMOD factors it once in create, every apply reuses the factor.
 *
 * Elements: tets P1 (one point, exact); hexes trilinear Q1 with 2x2x2 Gauss points; wedges
 * and pyramids as the hexahedron with collapsed nodes (wedge: nodes 0 1 2 2 3 4 5 5, the
 * linear wedge in Duffy form; pyramid: 0 1 2 3 4 4 4 4, exactly the standard rational linear
 * pyramid), with the same 2x2x2 rule: its integral of cof(J)^T grad N is exact, so every
 * element passes the patch test and affine motions are reproduced on mixed meshes.
 * Polyhedra: a centroid fan. Each face is fanned into triangles from its lowest-numbered
 * node (both cells of a shared face fan it the same way, so the tets conform), each
 * triangle with the cell's centroid (mean of its distinct nodes) gives a P1 tet; the
 * centroid is an extra unknown of the system, dropped after the solve.
 * Quadratic cells (tet10, hex20, ...) are not supported: their mid-side nodes are in no
 * linear element.
 * Reverse product (docs/DESIGN.md, "Gradients"): J_f = -K_II^-1 K_IB and K_II is symmetric,
 * so J^T v = v_B - K_IB^T K_II^-1 v_I: one solve with the kept factor, all three components
 * as the columns of one right-hand side, and one transposed product with the kept K_IB. */
#include "warp_method.h"

#include <cholmod.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct femwarp {
    cm_warp_nodes *nodes;
    size_t n_dof; /* free nodes, then one centroid per polyhedron */
    cholmod_common cc;
    int cc_started;
    cholmod_factor *L;
    cholmod_sparse *kib; /* n_dof x n_fixed */
    /* kept between applies: CHOLMOD reuses them instead of allocating per step */
    cholmod_dense *db, *rhs, *x, *y, *e;
} femwarp;

/* Growable triplets: (row, col, value). */
typedef struct triplets {
    size_t n, cap;
    SuiteSparse_long *i, *j;
    double *x;
} triplets;

static int trip_add(triplets *t, int64_t i, int64_t j, double x)
{
    if (t->n == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 4096;
        SuiteSparse_long *ni = realloc(t->i, cap * sizeof *ni);
        if (!ni) return -1;
        t->i = ni;
        SuiteSparse_long *nj = realloc(t->j, cap * sizeof *nj);
        if (!nj) return -1;
        t->j = nj;
        double *nx = realloc(t->x, cap * sizeof *nx);
        if (!nx) return -1;
        t->x = nx;
        t->cap = cap;
    }
    t->i[t->n] = (SuiteSparse_long)i;
    t->j[t->n] = (SuiteSparse_long)j;
    t->x[t->n++] = x;
    return 0;
}

static void trip_free(triplets *t)
{
    free(t->i);
    free(t->j);
    free(t->x);
    t->i = t->j = NULL;
    t->x = NULL;
    t->n = t->cap = 0;
}

/* 3x3 inverse of a (row-major); returns the determinant (0: a left untouched in inv). */
static double inv3(const double a[9], double inv[9])
{
    double c0 = a[4] * a[8] - a[5] * a[7], c1 = a[5] * a[6] - a[3] * a[8],
           c2 = a[3] * a[7] - a[4] * a[6];
    double det = a[0] * c0 + a[1] * c1 + a[2] * c2;
    if (det == 0) return 0;
    double r = 1 / det;
    inv[0] = c0 * r;
    inv[1] = (a[2] * a[7] - a[1] * a[8]) * r;
    inv[2] = (a[1] * a[5] - a[2] * a[4]) * r;
    inv[3] = c1 * r;
    inv[4] = (a[0] * a[8] - a[2] * a[6]) * r;
    inv[5] = (a[2] * a[3] - a[0] * a[5]) * r;
    inv[6] = c2 * r;
    inv[7] = (a[1] * a[6] - a[0] * a[7]) * r;
    inv[8] = (a[0] * a[4] - a[1] * a[3]) * r;
    return det;
}

/* P1 stiffness of a tet: K = V grad N grad N^T. x: 4 x 3. */
static void tet_stiffness(const double x[4][3], double k[8][8])
{
    double j[9], ji[9];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            j[3 * r + c] = x[c + 1][r] - x[0][r]; /* column c: edge 0 -> c+1 */
    double det = inv3(j, ji);
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
            k[a][b] = 0;
    if (det == 0) return; /* a flat tet of M0 carries no stiffness */
    double g[4][3];       /* rows of J^-1 are the gradients of N1..N3 */
    for (int d = 0; d < 3; ++d) {
        g[0][d] = 0;
        for (int a = 1; a < 4; ++a) {
            g[a][d] = ji[3 * (a - 1) + d];
            g[0][d] -= g[a][d];
        }
    }
    double v = fabs(det) / 6;
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
            k[a][b] = v * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]);
}

/* Q1 stiffness of a (possibly collapsed) hexahedron, 2x2x2 Gauss. x: 8 x 3, VTK order. */
static void hex_stiffness(const double x[8][3], double k[8][8])
{
    static const double s[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                   {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    const double q = 1 / sqrt(3.0);
    for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b)
            k[a][b] = 0;
    for (int gp = 0; gp < 8; ++gp) {
        double p[3] = {s[gp][0] * q, s[gp][1] * q, s[gp][2] * q};
        double dn[8][3], j[9] = {0}, ji[9];
        for (int a = 0; a < 8; ++a) {
            double f[3];
            for (int d = 0; d < 3; ++d)
                f[d] = 1 + s[a][d] * p[d];
            dn[a][0] = s[a][0] * f[1] * f[2] / 8;
            dn[a][1] = s[a][1] * f[0] * f[2] / 8;
            dn[a][2] = s[a][2] * f[0] * f[1] / 8;
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c)
                    j[3 * r + c] += x[a][r] * dn[a][c];
        }
        double det = inv3(j, ji);
        if (det == 0) continue;
        double g[8][3]; /* grad N = J^-T dN */
        for (int a = 0; a < 8; ++a)
            for (int d = 0; d < 3; ++d)
                g[a][d] = ji[d] * dn[a][0] + ji[3 + d] * dn[a][1] + ji[6 + d] * dn[a][2];
        double w = fabs(det);
        for (int a = 0; a < 8; ++a)
            for (int b = a; b < 8; ++b)
                k[a][b] += w * (g[a][0] * g[b][0] + g[a][1] * g[b][1] + g[a][2] * g[b][2]);
    }
    for (int a = 0; a < 8; ++a)
        for (int b = 0; b < a; ++b)
            k[a][b] = k[b][a];
}

/* Degrees of freedom of an element's nodes: a free dof (>= 0) or a fixed index (-(1+k)). */
typedef struct assembly {
    const cm_warp_nodes *nodes;
    triplets kii, kib;
} assembly;

static int64_t dof_of_node(const cm_warp_nodes *n, int64_t v)
{
    return n->free_index[v] >= 0 ? n->free_index[v] : -1 - n->fixed_index[v];
}

/* Adds element matrix k (ne x ne) on dofs; repeated dofs (collapsed nodes) add up. */
static int add_element(assembly *as, int ne, const int64_t *dof, double k[8][8])
{
    for (int a = 0; a < ne; ++a) {
        if (dof[a] < 0) continue; /* rows of fixed nodes are not part of the system */
        for (int b = 0; b < ne; ++b) {
            if (k[a][b] == 0) continue;
            if (dof[b] >= 0) {
                if (dof[a] <= dof[b] && trip_add(&as->kii, dof[a], dof[b], k[a][b])) return -1;
            } else if (trip_add(&as->kib, dof[a], -1 - dof[b], k[a][b])) {
                return -1;
            }
        }
    }
    return 0;
}

/* One standard cell: tet, hex, wedge or pyramid (corners only). */
static int add_cell(assembly *as, const cm_mesh *mesh, cm_cell_type t, const int64_t *c)
{
    static const int wedge[8] = {0, 1, 2, 2, 3, 4, 5, 5}, pyr[8] = {0, 1, 2, 3, 4, 4, 4, 4},
                     hex[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    double x[8][3], k[8][8];
    int64_t dof[8];
    if (t == CM_CELL_TET4) {
        for (int a = 0; a < 4; ++a) {
            memcpy(x[a], mesh->xyz + 3 * c[a], sizeof x[a]);
            dof[a] = dof_of_node(as->nodes, c[a]);
        }
        tet_stiffness((const double(*)[3])x, k);
        return add_element(as, 4, dof, k);
    }
    const int *m = t == CM_CELL_HEX8 ? hex : t == CM_CELL_WEDGE6 ? wedge : pyr;
    for (int a = 0; a < 8; ++a) {
        memcpy(x[a], mesh->xyz + 3 * c[m[a]], sizeof x[a]);
        dof[a] = dof_of_node(as->nodes, c[m[a]]);
    }
    hex_stiffness((const double(*)[3])x, k);
    return add_element(as, 8, dof, k);
}

/* A polyhedron: the centroid fan described at the top; centroid dof `cdof`. */
static int add_polyhedron(assembly *as, const cm_mesh *mesh, size_t cell, int64_t cdof,
                          int64_t *scratch)
{
    size_t nv = cm_warp_cell_nodes(mesh, cell, scratch);
    double ctr[3] = {0, 0, 0};
    for (size_t i = 0; i < nv; ++i)
        for (int d = 0; d < 3; ++d)
            ctr[d] += mesh->xyz[3 * scratch[i] + d] / (double)nv;
    const int64_t *conn = mesh->conn;
    int64_t b = mesh->offset[cell], e = mesh->offset[cell + 1], p = b + 1;
    for (int64_t f = 0; f < conn[b] && p < e; ++f) {
        int64_t n = conn[p++];
        const int64_t *fn = conn + p;
        p += n;
        if (n < 3 || p > e) continue;
        int64_t s = 0;
        for (int64_t i = 1; i < n; ++i)
            if (fn[i] < fn[s]) s = i;
        for (int64_t i = 1; i + 1 < n; ++i) {
            int64_t v[3] = {fn[s], fn[(s + i) % n], fn[(s + i + 1) % n]};
            double x[4][3], k[8][8];
            int64_t dof[4];
            memcpy(x[0], ctr, sizeof ctr);
            dof[0] = cdof;
            for (int a = 0; a < 3; ++a) {
                memcpy(x[a + 1], mesh->xyz + 3 * v[a], sizeof x[a + 1]);
                dof[a + 1] = dof_of_node(as->nodes, v[a]);
            }
            tet_stiffness((const double(*)[3])x, k);
            if (add_element(as, 4, dof, k)) return -1;
        }
    }
    return 0;
}

static void femwarp_destroy(void *state)
{
    femwarp *w = state;
    if (!w) return;
    if (w->cc_started) {
        cholmod_l_free_factor(&w->L, &w->cc);
        cholmod_l_free_dense(&w->db, &w->cc);
        cholmod_l_free_dense(&w->rhs, &w->cc);
        cholmod_l_free_dense(&w->x, &w->cc);
        cholmod_l_free_dense(&w->y, &w->cc);
        cholmod_l_free_dense(&w->e, &w->cc);
        cholmod_l_free_sparse(&w->kib, &w->cc);
        cholmod_l_finish(&w->cc);
    }
    cm_warp_nodes_destroy(&w->nodes);
    free(w);
}

static cholmod_sparse *to_sparse(triplets *t, size_t nrow, size_t ncol, int stype,
                                 cholmod_common *cc)
{
    cholmod_triplet *T =
        cholmod_l_allocate_triplet(nrow, ncol, t->n ? t->n : 1, stype, CHOLMOD_REAL, cc);
    if (!T) return NULL;
    memcpy(T->i, t->i, t->n * sizeof *t->i);
    memcpy(T->j, t->j, t->n * sizeof *t->j);
    memcpy(T->x, t->x, t->n * sizeof *t->x);
    T->nnz = t->n;
    cholmod_sparse *A = cholmod_l_triplet_to_sparse(T, 0, cc);
    cholmod_l_free_triplet(&T, cc);
    return A;
}

static cm_status cholmod_failed(cm_context *ctx, const cholmod_common *cc, const char *what)
{
    return cm_error(ctx, cc->status == CHOLMOD_OUT_OF_MEMORY ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                    "cm_warp_create: femwarp: CHOLMOD %s failed (status %d)", what, cc->status);
}

static cm_status femwarp_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                                const unsigned char *constrained, const cm_warp_options *opt,
                                void **state)
{
    (void)opt;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (!cm_warp_is_volume_cell(mesh, c)) continue;
        cm_cell_type t = (cm_cell_type)mesh->type[c];
        if (t != CM_CELL_TET4 && t != CM_CELL_HEX8 && t != CM_CELL_WEDGE6 && t != CM_CELL_PYR5 &&
            t != CM_CELL_POLYHEDRON)
            return cm_error(ctx, CM_ERR_UNSUPPORTED,
                            "cm_warp_create: femwarp: cell %zu is %s; only linear cells "
                            "(tet4, hex8, wedge6, pyr5, polyhedra) have FEMWARP elements",
                            c, cm_cell_type_info(t)->name);
    }
    femwarp *w = calloc(1, sizeof *w);
    if (!w) return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
    cm_status s = cm_warp_nodes_create(ctx, mesh, b, constrained, &w->nodes);
    if (s < 0) {
        free(w);
        return s;
    }
    size_t n_poly = 0, max_len = 1;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (!cm_warp_is_volume_cell(mesh, c)) continue;
        size_t len = (size_t)(mesh->offset[c + 1] - mesh->offset[c]);
        if (len > max_len) max_len = len;
        n_poly += mesh->type[c] == CM_CELL_POLYHEDRON;
    }
    w->n_dof = w->nodes->n_free + n_poly;
    *state = w;
    if (w->n_dof == 0) return CM_OK; /* every node prescribed */

    double t0 = cm_wtime();
    assembly as = {w->nodes, {0}, {0}};
    int64_t *scratch = malloc(max_len * sizeof *scratch);
    int bad = !scratch;
    size_t ip = 0;
    for (size_t c = 0; c < mesh->n_cells && !bad; ++c) {
        if (!cm_warp_is_volume_cell(mesh, c)) continue;
        if (mesh->type[c] == CM_CELL_POLYHEDRON)
            bad = add_polyhedron(&as, mesh, c, (int64_t)(w->nodes->n_free + ip++), scratch);
        else
            bad = add_cell(&as, mesh, (cm_cell_type)mesh->type[c], mesh->conn + mesh->offset[c]);
    }
    free(scratch);
    if (bad) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
        goto fail;
    }
    if ((s = cm_progress(ctx, "femwarp assemble", 1, 1)) < 0) goto fail;

    cholmod_l_start(&w->cc);
    w->cc_started = 1;
    w->cc.print = 0; /* the library never prints; failures come back as a status */
    w->cc.error_handler = NULL;
    /* CHOLMOD's default ordering (AMD, then METIS when AMD's fill is large) picks METIS on
     * these 3D meshes: L nnz 44M against AMD's 103M at 115k unknowns (RESULTS.md) */
    cholmod_sparse *kii = to_sparse(&as.kii, w->n_dof, w->n_dof, 1, &w->cc);
    w->kib = to_sparse(&as.kib, w->n_dof, w->nodes->n_fixed ? w->nodes->n_fixed : 1, 0, &w->cc);
    trip_free(&as.kii);
    trip_free(&as.kib);
    if (!kii || !w->kib) {
        cholmod_l_free_sparse(&kii, &w->cc);
        s = cholmod_failed(ctx, &w->cc, "assembly");
        goto fail;
    }
    double t1 = cm_wtime();
    w->L = cholmod_l_analyze(kii, &w->cc);
    double t2 = cm_wtime();
    /* between the ordering and the factorisation, each one CHOLMOD call that cannot stop */
    s = w->L ? cm_progress(ctx, "femwarp factorise", 0, 1) : CM_OK;
    if (w->L && s >= 0) cholmod_l_factorize(kii, w->L, &w->cc);
    double t3 = cm_wtime();
    cholmod_l_free_sparse(&kii, &w->cc);
    if (s < 0) goto fail;
    if (!w->L || w->cc.status < 0) {
        s = cholmod_failed(ctx, &w->cc, "factorisation");
        goto fail;
    }
    if ((s = cm_progress(ctx, "femwarp factorise", 1, 1)) < 0) goto fail;
    if (w->cc.status == CHOLMOD_NOT_POSDEF || (size_t)w->L->minor < w->n_dof) {
        s = cm_error(ctx, CM_ERR_NUMERIC,
                     "cm_warp_create: femwarp: K_II is not positive definite (pivot %ld of %zu): "
                     "a component without constrained nodes?",
                     (long)w->L->minor, w->n_dof);
        goto fail;
    }
    cm_log(ctx, CM_LOG_DEBUG,
           "femwarp: %zu unknowns (%zu polyhedron centroids), L nnz %.0f (%s): assembly %.3f s, "
           "ordering %.3f s, factorisation %.3f s",
           w->n_dof, n_poly, w->cc.lnz, w->L->is_super ? "supernodal" : "simplicial", t1 - t0,
           t2 - t1, t3 - t2);
    return CM_OK;
fail:
    trip_free(&as.kii);
    trip_free(&as.kib);
    femwarp_destroy(w);
    *state = NULL;
    return s;
}

static cm_status femwarp_apply(cm_context *ctx, void *state, double *disp, double *residual)
{
    femwarp *w = state;
    *residual = 0;
    if (w->n_dof == 0) return CM_OK;
    const cm_warp_nodes *n = w->nodes;
    size_t nb = n->n_fixed ? n->n_fixed : 1;
    if (!w->db) w->db = cholmod_l_zeros(nb, 3, CHOLMOD_REAL, &w->cc);
    if (!w->rhs) w->rhs = cholmod_l_zeros(w->n_dof, 3, CHOLMOD_REAL, &w->cc);
    int ok = w->db && w->rhs;
    if (ok) {
        double *d = w->db->x;
        for (size_t j = 0; j < n->n_fixed; ++j)
            for (int k = 0; k < 3; ++k)
                d[j + k * nb] = disp[3 * n->fixed_nodes[j] + k];
        double minus_one[2] = {-1, 0}, zero[2] = {0, 0};
        ok = cholmod_l_sdmult(w->kib, 0, minus_one, zero, w->db, w->rhs, &w->cc) &&
             cholmod_l_solve2(CHOLMOD_A, w->L, w->rhs, NULL, &w->x, NULL, &w->y, &w->e, &w->cc);
    }
    if (!ok)
        return cm_error(ctx, w->cc.status == CHOLMOD_OUT_OF_MEMORY ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                        "cm_warp_apply: femwarp: CHOLMOD solve failed (status %d)", w->cc.status);
    const double *xv = w->x->x;
    for (size_t i = 0; i < n->n_free; ++i)
        for (int k = 0; k < 3; ++k)
            disp[3 * n->free_nodes[i] + k] = xv[i + k * w->n_dof];
    return CM_OK;
}

static cm_status femwarp_apply_transpose(cm_context *ctx, void *state, const double *v, double *out)
{
    femwarp *w = state;
    const cm_warp_nodes *n = w->nodes;
    cm_warp_nodes_add_identity(n, v, out);
    if (w->n_dof == 0) return CM_OK;
    size_t nb = n->n_fixed ? n->n_fixed : 1;
    /* apply's buffers: the two products never run at once on one warp (warp.h) */
    if (!w->db) w->db = cholmod_l_zeros(nb, 3, CHOLMOD_REAL, &w->cc);
    if (!w->rhs) w->rhs = cholmod_l_zeros(w->n_dof, 3, CHOLMOD_REAL, &w->cc);
    int ok = w->db && w->rhs;
    if (ok) {
        double *r = w->rhs->x;
        /* the polyhedron centroids are dropped by apply: nothing of v reaches them */
        memset(r, 0, 3 * w->n_dof * sizeof *r);
        for (size_t i = 0; i < n->n_free; ++i)
            for (int k = 0; k < 3; ++k)
                r[i + k * w->n_dof] = v[3 * n->free_nodes[i] + k];
        double minus_one[2] = {-1, 0}, zero[2] = {0, 0};
        ok = cholmod_l_solve2(CHOLMOD_A, w->L, w->rhs, NULL, &w->x, NULL, &w->y, &w->e, &w->cc) &&
             cholmod_l_sdmult(w->kib, 1, minus_one, zero, w->x, w->db, &w->cc);
    }
    if (!ok)
        return cm_error(ctx, w->cc.status == CHOLMOD_OUT_OF_MEMORY ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                        "cm_warp_apply_transpose: femwarp: CHOLMOD solve failed (status %d)",
                        w->cc.status);
    const double *g = w->db->x;
    for (size_t j = 0; j < n->n_fixed; ++j)
        for (int k = 0; k < 3; ++k)
            out[3 * n->fixed_nodes[j] + k] += g[j + k * nb];
    return CM_OK;
}

const cm_warp_method_ops cm_warp_femwarp = {
    "femwarp", femwarp_create, femwarp_apply, femwarp_destroy, NULL, femwarp_apply_transpose,
    NULL, NULL};
