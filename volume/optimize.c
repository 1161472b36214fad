/* Interior mesh optimisation (optimize.h): node-by-node minimisation of the sum of the
 * inverse mean ratios of the corner Jacobians around a free node (Knupp 2001, "Algebraic mesh
 * quality metrics"; Freitag & Knupp 2002 for the local, node-wise scheme Mesquite calls
 * FeasibleNewton), regularised by Escobar et al. 2003 ("Simultaneous untangling and
 * smoothing of tetrahedral meshes") so that inverted corners have a finite, decreasing cost.
 * Written from the published formulas; no code of Mesquite's. */
#include "cadmorph/optimize.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define MAX_CELL_NODES 8
#define MAX_CORNERS 8
/* Verdict's value for collapsed cells (+-1e30): worse than any real value here. */
#define COLLAPSED 1e29

/* Corner k of a cell: the node and its three neighbours along the cell's edges (VTK order).
 * A pyramid's apex has four edges and no corner Jacobian: its base corners carry it. */
typedef struct corner_table {
    int n;
    int c[MAX_CORNERS][4];
    double winv[MAX_CORNERS][9]; /* W^-1 of each corner in the ideal cell, column-major */
} corner_table;

static corner_table tables[4]; /* tet, hex, wedge, pyramid */
static int tables_ready;

static int table_index(cm_cell_type t)
{
    switch (t) {
    case CM_CELL_TET4: return 0;
    case CM_CELL_HEX8: return 1;
    case CM_CELL_WEDGE6: return 2;
    case CM_CELL_PYR5: return 3;
    default: return -1;
    }
}

/* A = [p_a - p_0, p_b - p_0, p_c - p_0], column-major. */
static void corner_matrix(const double *x, const int *c, double *a)
{
    for (int j = 0; j < 3; ++j)
        for (int d = 0; d < 3; ++d)
            a[3 * j + d] = x[3 * c[j + 1] + d] - x[3 * c[0] + d];
}

static double det3(const double *a)
{
    return a[0] * (a[4] * a[8] - a[7] * a[5]) - a[3] * (a[1] * a[8] - a[7] * a[2]) +
           a[6] * (a[1] * a[5] - a[4] * a[2]);
}

static void inv3(const double *a, double *r)
{
    double d = det3(a);
    r[0] = (a[4] * a[8] - a[5] * a[7]) / d;
    r[1] = (a[2] * a[7] - a[1] * a[8]) / d;
    r[2] = (a[1] * a[5] - a[2] * a[4]) / d;
    r[3] = (a[5] * a[6] - a[3] * a[8]) / d;
    r[4] = (a[0] * a[8] - a[2] * a[6]) / d;
    r[5] = (a[2] * a[3] - a[0] * a[5]) / d;
    r[6] = (a[3] * a[7] - a[4] * a[6]) / d;
    r[7] = (a[1] * a[6] - a[0] * a[7]) / d;
    r[8] = (a[0] * a[4] - a[1] * a[3]) / d;
}

/* The corner tables and, from the ideal cell of each type (regular tet, unit cube, right
 * prism on an equilateral triangle, pyramid with all edges equal), each corner's W^-1: the
 * measure is then 1 on the ideal cell whatever the orientation convention of the corner. */
static void init_tables(void)
{
    static const double s3 = 0.86602540378443864676, h = 0.70710678118654752440;
    static const double ideal[4][8][3] = {
        {{0, 0, 0}, {1, 0, 0}, {0.5, s3, 0}, {0.5, s3 / 3, 0.81649658092772603273}},
        {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
        {{0, 0, 0}, {0.5, s3, 0}, {1, 0, 0}, {0, 0, 1}, {0.5, s3, 1}, {1, 0, 1}},
        {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, h}}};
    static const corner_table base[4] = {
        {1, {{0, 1, 2, 3}}, {{0}}},
        {8,
         {{0, 1, 3, 4}, {1, 2, 0, 5}, {2, 3, 1, 6}, {3, 0, 2, 7},
          {4, 7, 5, 0}, {5, 4, 6, 1}, {6, 5, 7, 2}, {7, 6, 4, 3}},
         {{0}}},
        {6, {{0, 1, 2, 3}, {1, 2, 0, 4}, {2, 0, 1, 5}, {3, 5, 4, 0}, {4, 3, 5, 1}, {5, 4, 3, 2}},
         {{0}}},
        {4, {{0, 1, 3, 4}, {1, 2, 0, 4}, {2, 3, 1, 4}, {3, 0, 2, 4}}, {{0}}}};
    for (int t = 0; t < 4; ++t) {
        tables[t] = base[t];
        for (int k = 0; k < tables[t].n; ++k) {
            double w[9];
            corner_matrix(&ideal[t][0][0], tables[t].c[k], w);
            inv3(w, tables[t].winv[k]);
        }
    }
}

static void ensure_tables(void)
{
    /* idempotent and racy-safe: every thread would write the same values */
#pragma omp critical(cm_optimize_tables)
    if (!tables_ready) {
        init_tables();
        tables_ready = 1;
    }
}

/* A (corner matrix) and S = A W^-1 of corner k; returns ||S||_F^2. */
static double corner_as(const corner_table *tb, int k, const double *x, double *a, double *s)
{
    corner_matrix(x, tb->c[k], a);
    const double *w = tb->winv[k];
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
            s[3 * j + i] = a[i] * w[3 * j] + a[3 + i] * w[3 * j + 1] + a[6 + i] * w[3 * j + 2];
    double f = 0;
    for (int i = 0; i < 9; ++i)
        f += s[i] * s[i];
    return f;
}

/* ||S||_F^2 and det S of S = A W^-1 for corner k. */
static void corner_s(const corner_table *tb, int k, const double *x, double *frob, double *det)
{
    double a[9], s[9];
    *frob = corner_as(tb, k, x, a, s);
    *det = det3(s);
}

/* Cost of corner k and its gradient with respect to the corner matrix A (3 x 3 column-major,
 * dA = d(cost)/dA): with S = A W^-1, f = ||S||^2, s = det S = det A det W^-1,
 *   cost = f / (3 h(s)^(2/3)),  d cost = df / (3 h^(2/3)) - 2 f h'(s) ds / (9 h^(5/3)),
 *   df/dA = 2 S W^-T,  ds/dA = det W^-1 cof(A), cof(A) = [a2 x a3, a3 x a1, a1 x a2]. */
static double corner_cost_grad(const corner_table *tb, int k, const double *x, double delta,
                               double *dA)
{
    double a[9], sm[9];
    const double f = corner_as(tb, k, x, a, sm);
    const double *w = tb->winv[k];
    const double dw = det3(w), sdet = det3(a) * dw;
    const double root = delta > 0 ? sqrt(sdet * sdet + 4 * delta * delta) : 0;
    const double hs = delta > 0 ? 0.5 * (sdet + root) : sdet;
    if (!(hs > 0)) {
        memset(dA, 0, 9 * sizeof *dA);
        return INFINITY;
    }
    const double dh = delta > 0 ? 0.5 * (1 + sdet / root) : 1;
    const double h23 = cbrt(hs * hs), c1 = 2.0 / (3.0 * h23), c2 = 2.0 * f * dh * dw / (9.0 * h23 * hs);
    const double *a1 = a, *a2 = a + 3, *a3 = a + 6;
    const double cof[9] = {a2[1] * a3[2] - a2[2] * a3[1], a2[2] * a3[0] - a2[0] * a3[2],
                           a2[0] * a3[1] - a2[1] * a3[0], a3[1] * a1[2] - a3[2] * a1[1],
                           a3[2] * a1[0] - a3[0] * a1[2], a3[0] * a1[1] - a3[1] * a1[0],
                           a1[1] * a2[2] - a1[2] * a2[1], a1[2] * a2[0] - a1[0] * a2[2],
                           a1[0] * a2[1] - a1[1] * a2[0]};
    /* (S W^-T)_{i,j} = sum_l S_{i,l} W^-1_{j,l} */
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
            double swt = sm[i] * w[j] + sm[3 + i] * w[3 + j] + sm[6 + i] * w[6 + j];
            dA[3 * j + i] = c1 * swt - c2 * cof[3 * j + i];
        }
    return f / (3.0 * h23);
}

/* Inverse mean ratio with the regularised determinant h(s). */
static double corner_cost(double frob, double det, double delta)
{
    double hs = delta > 0 ? 0.5 * (det + sqrt(det * det + 4 * delta * delta)) : det;
    if (!(hs > 0)) return INFINITY;
    return frob / (3.0 * cbrt(hs * hs));
}

double cm_optimize_cell_measure(cm_cell_type type, const double *xyz)
{
    int t = table_index(type);
    if (t < 0 || !xyz) return NAN;
    ensure_tables();
    double sum = 0;
    for (int k = 0; k < tables[t].n; ++k) {
        double f, d;
        corner_s(&tables[t], k, xyz, &f, &d);
        sum += corner_cost(f, d, 0);
    }
    return sum / tables[t].n;
}

void cm_optimize_options_init(cm_optimize_options *opt)
{
    if (!opt) return;
    opt->sweeps = 6;
    opt->target_sj = 0.3;
    opt->newton = 4;
}

/* Node -> volume cells (CSR), and what the passes share. */
typedef struct optimizer {
    cm_mesh *mesh;
    const cm_optimize_options *o;
    int64_t *start; /* #nodes + 1 */
    int64_t *cells; /* cells of node v: cells[start[v] .. start[v+1]) */
    double *sj;     /* #cells, kept up to date for the cells of moved nodes */
} optimizer;

static int supported(const cm_mesh *m, size_t c) { return table_index(m->type[c]) >= 0; }

static int is_volume(const cm_mesh *m, size_t c)
{
    const cm_cell_info *in = cm_cell_type_info((cm_cell_type)m->type[c]);
    return in && in->dim == 3;
}

static void gather(const cm_mesh *m, size_t c, double *x)
{
    int64_t b = m->offset[c], n = m->offset[c + 1] - b;
    for (int64_t i = 0; i < n && i < MAX_CELL_NODES; ++i)
        memcpy(x + 3 * i, m->xyz + 3 * m->conn[b + i], 3 * sizeof(double));
}

static double cell_sj(const cm_mesh *m, size_t c)
{
    double x[3 * MAX_CELL_NODES];
    gather(m, c, x);
    double q = cm_quality_scaled_jacobian((cm_cell_type)m->type[c], x);
    return fabs(q) >= COLLAPSED || isnan(q) ? -1.0 : q;
}

/* Smallest scaled Jacobian of the cells of node v (at the mesh's current coordinates). */
static double node_min_sj(const optimizer *op, int64_t v)
{
    double q = INFINITY;
    for (int64_t i = op->start[v]; i < op->start[v + 1]; ++i) {
        double s = cell_sj(op->mesh, (size_t)op->cells[i]);
        if (s < q) q = s;
    }
    return q;
}

/* The local objective of node v placed at p: the cost of every corner of its cells. */
static double node_cost(const optimizer *op, int64_t v, const double *p, double delta)
{
    const cm_mesh *m = op->mesh;
    double sum = 0;
    for (int64_t i = op->start[v]; i < op->start[v + 1]; ++i) {
        size_t c = (size_t)op->cells[i];
        double x[3 * MAX_CELL_NODES];
        gather(m, c, x);
        for (int64_t j = m->offset[c]; j < m->offset[c + 1]; ++j)
            if (m->conn[j] == v) memcpy(x + 3 * (j - m->offset[c]), p, 3 * sizeof(double));
        const corner_table *tb = &tables[table_index(m->type[c])];
        for (int k = 0; k < tb->n; ++k) {
            double f, d;
            corner_s(tb, k, x, &f, &d);
            sum += corner_cost(f, d, delta);
        }
    }
    return sum;
}

/* The local objective and its gradient g (3) with respect to the position p of node v. */
static double node_cost_grad(const optimizer *op, int64_t v, const double *p, double delta,
                             double *g)
{
    const cm_mesh *m = op->mesh;
    double sum = 0;
    g[0] = g[1] = g[2] = 0;
    for (int64_t i = op->start[v]; i < op->start[v + 1]; ++i) {
        size_t c = (size_t)op->cells[i];
        double x[3 * MAX_CELL_NODES];
        gather(m, c, x);
        int local = -1;
        for (int64_t j = m->offset[c]; j < m->offset[c + 1]; ++j)
            if (m->conn[j] == v) {
                local = (int)(j - m->offset[c]);
                memcpy(x + 3 * local, p, 3 * sizeof(double));
            }
        const corner_table *tb = &tables[table_index(m->type[c])];
        for (int k = 0; k < tb->n; ++k) {
            const int *cn = tb->c[k];
            if (cn[0] != local && cn[1] != local && cn[2] != local && cn[3] != local) continue;
            double dA[9];
            sum += corner_cost_grad(tb, k, x, delta, dA);
            for (int j = 0; j < 3; ++j)
                if (cn[j + 1] == local)
                    for (int d = 0; d < 3; ++d)
                        g[d] += dA[3 * j + d];
            if (cn[0] == local)
                for (int d = 0; d < 3; ++d)
                    g[d] -= dA[d] + dA[3 + d] + dA[6 + d];
        }
    }
    return sum;
}

/* delta of Escobar et al.: 0 when every corner around v is valid, else grows with the worst
 * (most negative) determinant, relative to the corners' typical size. */
static double node_delta(const optimizer *op, int64_t v, double *length)
{
    const cm_mesh *m = op->mesh;
    double dmin = INFINITY, dsum = 0;
    int n = 0;
    for (int64_t i = op->start[v]; i < op->start[v + 1]; ++i) {
        size_t c = (size_t)op->cells[i];
        double x[3 * MAX_CELL_NODES];
        gather(m, c, x);
        const corner_table *tb = &tables[table_index(m->type[c])];
        for (int k = 0; k < tb->n; ++k) {
            double f, d;
            corner_s(tb, k, x, &f, &d);
            if (d < dmin) dmin = d;
            dsum += sqrt(f / 3.0);
            ++n;
        }
    }
    double len = n ? dsum / n : 0; /* a typical edge length of the corners */
    *length = len;
    double eps = 1e-3 * len * len * len;
    return dmin > eps ? 0 : sqrt(eps * (eps - dmin));
}

/* Damped Newton on the node's objective with finite-difference derivatives (the objective is
 * cheap and local); the move is kept only if it raises or keeps the node's worst cell. */
static int optimise_node(const optimizer *op, int64_t v)
{
    cm_mesh *m = op->mesh;
    double *xv = m->xyz + 3 * v, x0[3];
    memcpy(x0, xv, sizeof x0);
    double len;
    double delta = node_delta(op, v, &len);
    if (!(len > 0)) return 0;
    double before = node_min_sj(op, v);
    double p[3] = {x0[0], x0[1], x0[2]};
    double f = node_cost(op, v, p, delta);
    if (!isfinite(f)) return 0;
    const double hstep = 1e-4 * len;
    for (int it = 0; it < op->o->newton; ++it) {
        /* analytic gradient; Hessian from forward differences of the gradient */
        double g[3], H[9], q[3], gq[3];
        node_cost_grad(op, v, p, delta, g);
        for (int i = 0; i < 3; ++i) {
            memcpy(q, p, sizeof q);
            q[i] += hstep;
            node_cost_grad(op, v, q, delta, gq);
            for (int j = 0; j < 3; ++j)
                H[3 * i + j] = (gq[j] - g[j]) / hstep;
        }
        for (int i = 0; i < 3; ++i)
            for (int j = i + 1; j < 3; ++j)
                H[3 * i + j] = H[3 * j + i] = 0.5 * (H[3 * i + j] + H[3 * j + i]);
        if (!(isfinite(g[0]) && isfinite(g[1]) && isfinite(g[2]))) break;
        /* Newton direction if H is positive definite (Cholesky), else steepest descent
         * scaled to a tenth of the local length */
        double d[3], l00 = H[0], l10, l11, l20, l21, l22;
        int newton = 0;
        if (l00 > 0) {
            l00 = sqrt(l00);
            l10 = H[1] / l00;
            l20 = H[2] / l00;
            l11 = H[4] - l10 * l10;
            if (l11 > 0) {
                l11 = sqrt(l11);
                l21 = (H[5] - l20 * l10) / l11;
                l22 = H[8] - l20 * l20 - l21 * l21;
                if (l22 > 0) {
                    l22 = sqrt(l22);
                    double y0 = -g[0] / l00, y1 = (-g[1] - l10 * y0) / l11,
                           y2 = (-g[2] - l20 * y0 - l21 * y1) / l22;
                    d[2] = y2 / l22;
                    d[1] = (y1 - l21 * d[2]) / l11;
                    d[0] = (y0 - l10 * d[1] - l20 * d[2]) / l00;
                    newton = 1;
                }
            }
        }
        if (!newton) {
            double gn = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
            if (!(gn > 0)) break;
            for (int i = 0; i < 3; ++i)
                d[i] = -g[i] / gn * 0.1 * len;
        }
        /* never more than half the local length in one step */
        double dn = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (dn > 0.5 * len)
            for (int i = 0; i < 3; ++i)
                d[i] *= 0.5 * len / dn;
        double alpha = 1, fn = INFINITY;
        for (int ls = 0; ls < 12; ++ls, alpha *= 0.5) {
            for (int i = 0; i < 3; ++i)
                q[i] = p[i] + alpha * d[i];
            fn = node_cost(op, v, q, delta);
            if (fn < f) break;
        }
        if (!(fn < f)) break;
        double moved = alpha * dn;
        memcpy(p, q, sizeof p);
        f = fn;
        if (moved < 1e-9 * len) break;
    }
    memcpy(xv, p, sizeof p);
    double after = node_min_sj(op, v);
    if (after >= before && (p[0] != x0[0] || p[1] != x0[1] || p[2] != x0[2])) return 1;
    memcpy(xv, x0, sizeof x0); /* never lower the worst cell around the node */
    return 0;
}

static cm_status build_adjacency(cm_context *ctx, optimizer *op)
{
    const cm_mesh *m = op->mesh;
    size_t nn = m->n_nodes;
    op->start = calloc(nn + 1, sizeof *op->start);
    if (!op->start) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_optimize: out of memory");
    for (size_t c = 0; c < m->n_cells; ++c)
        if (supported(m, c))
            for (int64_t j = m->offset[c]; j < m->offset[c + 1]; ++j)
                ++op->start[m->conn[j] + 1];
    for (size_t v = 0; v < nn; ++v)
        op->start[v + 1] += op->start[v];
    op->cells = malloc(((size_t)op->start[nn] ? (size_t)op->start[nn] : 1) * sizeof *op->cells);
    int64_t *fill = malloc((nn ? nn : 1) * sizeof *fill);
    if (!op->cells || !fill) {
        free(fill);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_optimize: out of memory");
    }
    memcpy(fill, op->start, nn * sizeof *fill);
    for (size_t c = 0; c < m->n_cells; ++c)
        if (supported(m, c))
            for (int64_t j = m->offset[c]; j < m->offset[c + 1]; ++j)
                op->cells[fill[m->conn[j]]++] = (int64_t)c;
    free(fill);
    return CM_OK;
}

/* Free nodes of the cells below the target and of their neighbouring cells; a node is free
 * if not fixed and every volume cell it belongs to is of a supported type. */
static size_t select_nodes(const optimizer *op, const unsigned char *fixed, unsigned char *frozen,
                           int64_t *list)
{
    const cm_mesh *m = op->mesh;
    size_t nn = m->n_nodes;
    for (size_t c = 0; c < m->n_cells; ++c)
        if (is_volume(m, c) && !supported(m, c))
            for (int64_t j = m->offset[c]; j < m->offset[c + 1]; ++j)
                if (m->conn[j] >= 0 && (size_t)m->conn[j] < nn) frozen[m->conn[j]] = 1;
    unsigned char *bad_node = calloc(nn ? nn : 1, 1);
    unsigned char *pick = calloc(nn ? nn : 1, 1);
    size_t n = 0;
    if (!bad_node || !pick) goto done;
    for (size_t c = 0; c < m->n_cells; ++c)
        if (supported(m, c) && op->sj[c] < op->o->target_sj)
            for (int64_t j = m->offset[c]; j < m->offset[c + 1]; ++j)
                bad_node[m->conn[j]] = 1;
    /* every node of every cell that touches a node of a bad cell */
    for (size_t v = 0; v < nn; ++v) {
        if (!bad_node[v]) continue;
        for (int64_t i = op->start[v]; i < op->start[v + 1]; ++i) {
            size_t c = (size_t)op->cells[i];
            for (int64_t j = m->offset[c]; j < m->offset[c + 1]; ++j)
                pick[m->conn[j]] = 1;
        }
    }
    for (size_t v = 0; v < nn; ++v)
        if (pick[v] && !fixed[v] && !frozen[v] && op->start[v + 1] > op->start[v])
            list[n++] = (int64_t)v;
done:
    free(bad_node);
    free(pick);
    return n;
}

/* Greedy colouring: nodes of one colour share no cell, so they can move at the same time
 * without reading each other's positions. Deterministic (ascending node order). */
static int colour_nodes(const optimizer *op, const int64_t *list, size_t n, int *colour,
                        size_t nn)
{
    const cm_mesh *m = op->mesh;
    int *node_colour = malloc((nn ? nn : 1) * sizeof *node_colour);
    if (!node_colour) return -1;
    for (size_t v = 0; v < nn; ++v)
        node_colour[v] = -1;
    int ncol = 0;
    for (size_t k = 0; k < n; ++k) {
        int64_t v = list[k];
        uint64_t used = 0; /* colours of neighbours, up to 64; more falls back to a scan */
        int col = -1;
        for (int64_t i = op->start[v]; i < op->start[v + 1]; ++i) {
            size_t c = (size_t)op->cells[i];
            for (int64_t j = m->offset[c]; j < m->offset[c + 1]; ++j) {
                int u = node_colour[m->conn[j]];
                if (u >= 0 && u < 64) used |= (uint64_t)1 << u;
            }
        }
        for (int t = 0; t < 64; ++t)
            if (!(used & ((uint64_t)1 << t))) {
                col = t;
                break;
            }
        if (col < 0) col = 64 + (int)k; /* never in practice: its own colour */
        node_colour[v] = col;
        colour[k] = col;
        if (col + 1 > ncol) ncol = col + 1;
    }
    free(node_colour);
    return ncol;
}

static void summarize(cm_context *ctx, const cm_mesh *m, const double *sj, double *min,
                      size_t *inverted)
{
    cm_quality_stats all;
    if (cm_quality_summarize(ctx, m, sj, NULL, &all) >= 0) {
        *min = all.min;
        *inverted = all.inverted;
    }
}

cm_status cm_mesh_optimize(cm_context *ctx, cm_mesh *mesh, const unsigned char *fixed,
                           const cm_optimize_options *opt, cm_optimize_stats *stats)
{
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_optimize: mesh is NULL");
    cm_optimize_options defaults;
    cm_optimize_options_init(&defaults);
    if (!opt) opt = &defaults;
    ensure_tables();
    cm_optimize_stats st;
    memset(&st, 0, sizeof st);
    size_t nn = mesh->n_nodes;
    optimizer op = {mesh, opt, NULL, NULL, NULL};
    unsigned char *own_fixed = NULL, *frozen = calloc(nn ? nn : 1, 1);
    int64_t *list = malloc((nn ? nn : 1) * sizeof *list);
    int *colour = malloc((nn ? nn : 1) * sizeof *colour);
    int64_t *order = malloc((nn ? nn : 1) * sizeof *order);
    op.sj = malloc((mesh->n_cells ? mesh->n_cells : 1) * sizeof *op.sj);
    cm_mesh_boundary *b = NULL;
    cm_status s = frozen && list && colour && order && op.sj
                      ? CM_OK
                      : cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_optimize: out of memory");
    if (s >= 0 && !fixed) {
        s = cm_mesh_boundary_create(ctx, mesh, &b);
        if (s >= 0 && b->n_components == 0)
            s = cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_optimize: no volume cells");
        own_fixed = s >= 0 ? calloc(nn ? nn : 1, 1) : NULL;
        if (s >= 0 && !own_fixed) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_optimize: out of memory");
        if (s >= 0) {
            for (size_t i = 0; i < b->n_nodes; ++i)
                own_fixed[b->nodes[i]] = 1;
            fixed = own_fixed;
        }
    }
    if (s >= 0) s = build_adjacency(ctx, &op);
    if (s >= 0) s = cm_mesh_quality(ctx, mesh, op.sj);
    if (s >= 0) {
        summarize(ctx, mesh, op.sj, &st.min_sj_before, &st.inverted_before);
        for (size_t c = 0; c < mesh->n_cells; ++c)
            if (fabs(op.sj[c]) >= COLLAPSED) op.sj[c] = -1;
        size_t n = select_nodes(&op, fixed, frozen, list);
        st.nodes_selected = n;
        int ncol = colour_nodes(&op, list, n, colour, nn);
        if (ncol < 0) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_optimize: out of memory");
        /* nodes sorted by colour, ascending node within a colour (counting sort) */
        size_t *cstart = s >= 0 ? calloc((size_t)ncol + 1, sizeof *cstart) : NULL;
        if (s >= 0 && !cstart) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_optimize: out of memory");
        if (s >= 0) {
            for (size_t k = 0; k < n; ++k)
                ++cstart[colour[k] + 1];
            for (int c = 0; c < ncol; ++c)
                cstart[c + 1] += cstart[c];
            size_t *fill = malloc(((size_t)ncol + 1) * sizeof *fill);
            if (!fill) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_optimize: out of memory");
            if (fill) {
                memcpy(fill, cstart, ((size_t)ncol + 1) * sizeof *fill);
                for (size_t k = 0; k < n; ++k)
                    order[fill[colour[k]]++] = list[k];
                free(fill);
            }
        }
        /* the coordinates before the sweeps, put back if the caller stops them: an
         * interrupted call leaves the mesh as it found it */
        double *xyz0 = s >= 0 && opt->sweeps > 0 ? malloc(3 * (nn ? nn : 1) * sizeof *xyz0) : NULL;
        if (s >= 0 && opt->sweeps > 0 && !xyz0)
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_optimize: out of memory");
        if (xyz0) memcpy(xyz0, mesh->xyz, 3 * nn * sizeof *xyz0);
        double last = cm_wtime();
        for (int sweep = 0; s >= 0 && sweep < opt->sweeps; ++sweep) {
            size_t moved = 0;
            for (int c = 0; c < ncol && s >= 0; ++c) {
                size_t lo = cstart[c], hi = cstart[c + 1];
                int threads = cm_context_threads_for(ctx, hi - lo, 64);
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads) reduction(+ : moved)
                for (size_t k = lo; k < hi; ++k)
                    moved += (size_t)optimise_node(&op, order[k]);
                /* a sweep of a large mesh is seconds: a point between colours too, at most
                 * every 0.05 s */
                if (c + 1 < ncol && cm_wtime() - last >= 0.05) {
                    last = cm_wtime();
                    s = cm_progress(ctx, "optimize", sweep + (double)(c + 1) / ncol, opt->sweeps);
                }
            }
            if (s < 0) break;
            st.moves += moved;
            st.sweeps = sweep + 1;
            s = cm_progress(ctx, "optimize", sweep + 1, opt->sweeps);
            last = cm_wtime();
            if (!moved) break;
        }
        if (s < 0 && xyz0) memcpy(mesh->xyz, xyz0, 3 * nn * sizeof *xyz0);
        free(xyz0);
        free(cstart);
    }
    if (s >= 0) s = cm_mesh_quality(ctx, mesh, op.sj);
    if (s >= 0) summarize(ctx, mesh, op.sj, &st.min_sj_after, &st.inverted_after);
    cm_mesh_boundary_destroy(&b);
    free(own_fixed);
    free(frozen);
    free(list);
    free(colour);
    free(order);
    free(op.start);
    free(op.cells);
    free(op.sj);
    if (s >= 0 && stats) *stats = st;
    return s;
}
