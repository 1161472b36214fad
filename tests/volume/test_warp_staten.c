/* Staten's comparators (volume/warp_femwarp.c, warp_lbwarp.c, warp_simplex.cpp): each method
 * reproduces an affine boundary motion inside (<= 1e-10 x diagonal) on tets, hexes, an
 * L-shaped (concave) block, polyhedra (FEMWARP) and gmsh's mixed mesh with wedges and
 * pyramids; zero motion leaves every node bit-identical; LBWARP's weights satisfy the
 * log-barrier optimality conditions; the simplex barycentrics reproduce the nodes and count
 * points outside every tet. argv[2]/staten/mixed.msh comes from warp_staten.py setup. */
#include "cadmorph/warp.h"
#include "test_util.h"
#include "warp_method.h"
#include "test_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static const cm_warp_method staten[3] = {CM_WARP_FEMWARP, CM_WARP_LBWARP, CM_WARP_SIMPLEX};

static double diagonal(const cm_mesh *m)
{
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (size_t v = 0; v < m->n_nodes; ++v)
        for (int d = 0; d < 3; ++d) {
            if (m->xyz[3 * v + d] < lo[d]) lo[d] = m->xyz[3 * v + d];
            if (m->xyz[3 * v + d] > hi[d]) hi[d] = m->xyz[3 * v + d];
        }
    return sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

/* d(x) = a x + t with entries in [-0.1, 0.1] (a motion the mesh survives) */
static void affine_disp(const double a[12], const double *x, double *d)
{
    for (int i = 0; i < 3; ++i)
        d[i] = a[3 * i] * x[0] + a[3 * i + 1] * x[1] + a[3 * i + 2] * x[2] + a[9 + i];
}

/* Affine boundary motion through cm_warp_create/apply: largest interior error / diagonal. */
static double affine_error(cm_mesh *m, cm_warp_method method, size_t *fallback)
{
    cm_mesh_boundary *b = NULL;
    cm_warp *w = NULL;
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = method;
    double err = INFINITY;
    if (cm_mesh_boundary_create(ctx, m, &b) < 0) return err;
    uint64_t seed = 7;
    double a[12];
    for (int i = 0; i < 12; ++i)
        a[i] = 0.1 * test_rand(&seed);
    double *d = malloc(3 * m->n_nodes * sizeof *d);
    unsigned char *mask = calloc(m->n_nodes, 1), *in_cell = calloc(m->n_nodes, 1);
    for (size_t i = 0; i < b->n_nodes; ++i)
        mask[b->nodes[i]] = 1;
    for (size_t c = 0; c < m->n_cells; ++c)
        if (b->cell_component[c] >= 0)
            for (int64_t p = m->offset[c]; p < m->offset[c + 1]; ++p)
                in_cell[m->conn[p]] = 1; /* polyhedra: counts and ids alike, harmless here */
    for (size_t v = 0; v < m->n_nodes; ++v) {
        if (mask[v])
            affine_disp(a, m->xyz + 3 * v, d + 3 * v);
        else
            d[3 * v] = d[3 * v + 1] = d[3 * v + 2] = NAN; /* apply must not read these */
    }
    cm_status s = cm_warp_create(ctx, m, b, mask, &opt, &w);
    CHECK_MSG(s == CM_OK, "%s: %s", cm_warp_method_name(method), cm_context_message(ctx));
    if (s == CM_OK && cm_warp_apply(ctx, w, d) == CM_OK) {
        err = 0;
        for (size_t v = 0; v < m->n_nodes; ++v) {
            if (!in_cell[v]) continue; /* nodes of no cell are left alone */
            double e[3];
            affine_disp(a, m->xyz + 3 * v, e);
            for (int k = 0; k < 3; ++k)
                err = fmax(err, fabs(e[k] - d[3 * v + k])); /* NaN left behind fails below */
            if (d[3 * v] != d[3 * v]) err = INFINITY;
        }
        err /= diagonal(m);
        *fallback = cm_warp_fallback_nodes(w);
        CHECK(cm_warp_residual(w) == 0);
    }
    cm_warp_destroy(&w);
    cm_mesh_boundary_destroy(&b);
    free(d);
    free(mask);
    free(in_cell);
    return err;
}

/* Zero motion through cm_warp_mesh: every coordinate keeps its bits. */
static void check_zero(const cm_mesh *m0, cm_warp_method method, const char *what)
{
    cm_mesh *m = NULL;
    if (cm_mesh_copy(ctx, m0, &m) < 0) return;
    double *d = calloc(3 * m->n_nodes, sizeof *d);
    cm_warp_options wo;
    cm_warp_options_init(&wo);
    wo.method = method;
    cm_status s = cm_warp_mesh(ctx, m, d, NULL, NULL, &wo, NULL, NULL, NULL);
    CHECK_MSG(s == CM_OK, "%s %s: %s", what, cm_warp_method_name(method), cm_context_message(ctx));
    CHECK_MSG(s == CM_OK && !memcmp(m->xyz, m0->xyz, 3 * m->n_nodes * sizeof *m->xyz),
              "%s %s: zero motion moved a node", what, cm_warp_method_name(method));
    free(d);
    cm_mesh_destroy(&m);
}

static void check_mesh(cm_mesh *m, const char *what, int methods)
{
    for (int k = 0; k < methods; ++k) {
        size_t fb = 0;
        double e = affine_error(m, staten[k], &fb);
        printf("%-9s %-8s affine error %.3g x diagonal, %zu fallback nodes\n", what,
               cm_warp_method_name(staten[k]), e, fb);
        CHECK_MSG(e <= 1e-10, "%s %s: affine error %g x diagonal", what,
                  cm_warp_method_name(staten[k]), e);
        CHECK_MSG(fb == 0, "%s %s: %zu fallback nodes on a valid mesh", what,
                  cm_warp_method_name(staten[k]), fb);
        check_zero(m, staten[k], what);
    }
}

static cm_mesh *block_mesh(int tets, int lshape)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    uint64_t seed = 42;
    test_block b = {6, 5, 4, {0, 0, 0}, {0.2, 0.25, 0.3}, tets, 0.25};
    test_add_block(ctx, m, &b, &seed);
    if (lshape) {
        /* a second block on top of half the first: the union is concave. It shares the
         * nodes of the interface by coordinates only, so merge them */
        test_block c = {3, 5, 3, {0, 0, 1.2}, {0.2, 0.25, 0.3}, tets, 0.25};
        size_t first = m->n_nodes;
        test_add_block(ctx, m, &c, &seed);
        int64_t *map = malloc(m->n_nodes * sizeof *map);
        for (size_t v = 0; v < m->n_nodes; ++v) {
            map[v] = (int64_t)v;
            if (v < first) continue;
            for (size_t u = 0; u < first; ++u)
                if (fabs(m->xyz[3 * u] - m->xyz[3 * v]) +
                        fabs(m->xyz[3 * u + 1] - m->xyz[3 * v + 1]) +
                        fabs(m->xyz[3 * u + 2] - m->xyz[3 * v + 2]) <
                    1e-12) {
                    map[v] = (int64_t)u;
                    break;
                }
        }
        for (int64_t p = 0; p < m->offset[m->n_cells]; ++p)
            m->conn[p] = map[m->conn[p]];
        free(map); /* the duplicate nodes stay, in no cell and unconstrained: left alone */
    }
    return m;
}

/* The hex block with every hex written as a polyhedron. */
static cm_mesh *polyhedron_mesh(void)
{
    cm_mesh *h = block_mesh(0, 0), *m = test_hexes_as_polyhedra(ctx, h);
    cm_mesh_destroy(&h);
    return m;
}

static void test_meshes(const char *work)
{
    const char *name[4] = {"hex", "tet", "hex-L", "tet-L"};
    for (int i = 0; i < 4; ++i) {
        cm_mesh *m = block_mesh(i & 1, i >= 2);
        check_mesh(m, name[i], 3);
        cm_mesh_destroy(&m);
    }
    cm_mesh *p = polyhedron_mesh();
    check_mesh(p, "polyhedra", 3);
    cm_mesh_destroy(&p);

    char path[1024];
    snprintf(path, sizeof path, "%s/staten/mixed.msh", work);
    cm_mesh *mixed = NULL;
    cm_status s = cm_mesh_read(ctx, path, &mixed);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (s != CM_OK) return;
    size_t count[CM_CELL_TYPE_COUNT] = {0};
    for (size_t c = 0; c < mixed->n_cells; ++c)
        ++count[mixed->type[c]];
    CHECK(count[CM_CELL_TET4] > 0 && count[CM_CELL_HEX8] > 0 && count[CM_CELL_WEDGE6] > 0 &&
          count[CM_CELL_PYR5] > 0);
    check_mesh(mixed, "mixed", 3);
    cm_mesh_destroy(&mixed);
}

/* Log-barrier weights of every free node of the jittered blocks: positive, sum 1, reproduce
 * x_i, and (w, lambda, mu) satisfy the Lagrangian's stationarity. A node outside the hull of
 * its neighbours is refused. */
static void test_lbwarp_weights(void)
{
    for (int tets = 0; tets < 2; ++tets) {
        cm_mesh *m = block_mesh(tets, 0);
        size_t nn = m->n_nodes, checked = 0;
        double worst_rep = 0, worst_sum = 0, worst_grad = 0, min_w = 1;
        unsigned char *adj = malloc(nn * nn);
        memset(adj, 0, nn * nn);
        for (size_t c = 0; c < m->n_cells; ++c)
            for (int64_t p = m->offset[c]; p < m->offset[c + 1]; ++p)
                for (int64_t q = m->offset[c]; q < m->offset[c + 1]; ++q)
                    adj[m->conn[p] * nn + m->conn[q]] = 1;
        double *d = malloc(3 * nn * sizeof *d), *w = malloc(nn * sizeof *w);
        for (size_t i = 0; i < nn; ++i) {
            size_t n = 0;
            for (size_t j = 0; j < nn; ++j) {
                if (j == i || !adj[i * nn + j]) continue;
                for (int k = 0; k < 3; ++k)
                    d[3 * n + k] = m->xyz[3 * j + k] - m->xyz[3 * i + k];
                ++n;
            }
            /* boundary nodes of the block are on its hull: only interior ones qualify */
            const double *x = m->xyz + 3 * i;
            if (x[0] < 1e-9 || x[1] < 1e-9 || x[2] < 1e-9 || x[0] > 1.2 - 1e-9 ||
                x[1] > 1.25 - 1e-9 || x[2] > 1.2 - 1e-9)
                continue;
            double lambda[3], mu, h = 0;
            int r = cm_lbwarp_weights(d, n, w, lambda, &mu);
            CHECK(r == 0);
            double sum = 0, rep[3] = {0, 0, 0};
            for (size_t j = 0; j < n; ++j) {
                h = fmax(h, sqrt(d[3 * j] * d[3 * j] + d[3 * j + 1] * d[3 * j + 1] +
                                 d[3 * j + 2] * d[3 * j + 2]));
                min_w = fmin(min_w, w[j]);
                sum += w[j];
                for (int k = 0; k < 3; ++k)
                    rep[k] += w[j] * d[3 * j + k];
                /* d/dw_j [sum log w - lambda.(sum w d) - mu (sum w - 1)], relative to 1/w_j */
                double g =
                    1 / w[j] - mu -
                    (lambda[0] * d[3 * j] + lambda[1] * d[3 * j + 1] + lambda[2] * d[3 * j + 2]);
                worst_grad = fmax(worst_grad, fabs(g) * w[j]);
            }
            worst_sum = fmax(worst_sum, fabs(sum - 1));
            worst_rep =
                fmax(worst_rep, sqrt(rep[0] * rep[0] + rep[1] * rep[1] + rep[2] * rep[2]) / h);
            ++checked;
        }
        printf("lbwarp weights (%s): %zu nodes, min w %.3g, |sum-1| %.3g, reproduction %.3g x "
               "h, Lagrangian gradient %.3g\n",
               tets ? "tets" : "hexes", checked, min_w, worst_sum, worst_rep, worst_grad);
        CHECK(checked > 20);
        CHECK(min_w > 0);
        CHECK(worst_sum <= 1e-14);
        CHECK(worst_rep <= 1e-12);
        CHECK(worst_grad <= 1e-10);
        free(adj);
        free(d);
        free(w);
        cm_mesh_destroy(&m);
    }
    /* x_i = 0 outside the hull of four points in the half-space z > 0: refused, uniform */
    double d[12] = {1, 0, 0.1, 0, 1, 0.2, -1, -1, 0.3, 0.5, 0.5, 1}, w[4], l[3], mu;
    CHECK(cm_lbwarp_weights(d, 4, w, l, &mu) == -1);
    CHECK(w[0] == 0.25 && w[3] == 0.25);
}

/* Barycentrics of points inside a jittered cloud reproduce them; points beyond it are
 * counted as outside and extrapolated from a tet. */
static void test_simplex_locate(void)
{
    enum { NP = 300, NQ = 200, NOUT = 7 };
    uint64_t seed = 3;
    double pts[3 * NP], q[3 * (NQ + NOUT)], bary[4 * (NQ + NOUT)];
    int64_t corner[4 * (NQ + NOUT)];
    /* the 8 corners of the unit cube, then random points inside */
    for (int i = 0; i < NP; ++i)
        for (int k = 0; k < 3; ++k)
            pts[3 * i + k] = i < 8 ? (double)((i >> k) & 1) : 0.5 + 0.5 * test_rand(&seed);
    for (int i = 0; i < NQ; ++i)
        for (int k = 0; k < 3; ++k)
            q[3 * i + k] = 0.5 + 0.499 * test_rand(&seed);
    for (int i = NQ; i < NQ + NOUT; ++i)
        for (int k = 0; k < 3; ++k)
            q[3 * i + k] = k == i % 3 ? 1.3 : 0.5 + 0.3 * test_rand(&seed);
    size_t n_out = 0;
    cm_status s = cm_simplex_locate(ctx, pts, NP, q, NQ + NOUT, corner, bary, &n_out);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    double worst = 0, most_negative = 0;
    for (int i = 0; i < NQ + NOUT; ++i) {
        double r[3] = {0, 0, 0}, sum = 0;
        for (int c = 0; c < 4; ++c) {
            sum += bary[4 * i + c];
            for (int k = 0; k < 3; ++k)
                r[k] += bary[4 * i + c] * pts[3 * corner[4 * i + c] + k];
            if (i < NQ) most_negative = fmin(most_negative, bary[4 * i + c]);
        }
        for (int k = 0; k < 3; ++k)
            worst = fmax(worst, fabs(r[k] - q[3 * i + k]) / sqrt(3.0));
        CHECK_NEAR(sum, 1, 1e-12);
    }
    printf("simplex: %d queries, reproduction %.3g x diagonal, smallest inside coordinate %.3g, "
           "%zu outside (of %d)\n",
           NQ + NOUT, worst, most_negative, n_out, NOUT);
    CHECK(worst <= 1e-12);
    CHECK(most_negative >= -1e-12);
    CHECK(n_out == NOUT);
    /* coplanar constrained nodes: no tet, an error that says so */
    double flat[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    s = cm_simplex_locate(ctx, flat, 4, q, 1, corner, bary, &n_out);
    CHECK(s == CM_ERR_NUMERIC);
    for (int i = 0; i < 4; ++i) /* the same on a tilted plane z = x + y */
        flat[3 * i + 2] = flat[3 * i] + flat[3 * i + 1];
    s = cm_simplex_locate(ctx, flat, 4, q, 1, corner, bary, &n_out);
    CHECK(s == CM_ERR_NUMERIC);
}

/* FEMWARP has linear elements only; a component without constrained nodes is singular. */
static void test_errors(void)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    cm_mesh_resize_nodes(ctx, m, 10, 0);
    for (int i = 0; i < 30; ++i)
        m->xyz[i] = (i % 3 == i / 3 % 3) ? 1 : 0.1 * i;
    int64_t t10[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    cm_mesh_add_cell(ctx, m, CM_CELL_TET10, t10, 10, 0, 0, 0);
    cm_mesh_boundary *b = NULL;
    cm_mesh_boundary_create(ctx, m, &b);
    unsigned char mask[10] = {1, 1, 1, 1, 0, 0, 0, 0, 0, 0};
    cm_warp *w = NULL;
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = CM_WARP_FEMWARP;
    CHECK(cm_warp_create(ctx, m, b, mask, &opt, &w) == CM_ERR_UNSUPPORTED && !w);
    CHECK(strstr(cm_context_message(ctx), "tet10") != NULL);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);

    m = block_mesh(1, 0);
    cm_mesh_boundary_create(ctx, m, &b);
    unsigned char *none = calloc(m->n_nodes, 1);
    for (int k = 0; k < 2; ++k) {
        opt.method = k ? CM_WARP_LBWARP : CM_WARP_FEMWARP;
        cm_status s = cm_warp_create(ctx, m, b, none, &opt, &w);
        CHECK_MSG(s == CM_ERR_NUMERIC && !w, "%s: %d %s", cm_warp_method_name(opt.method), s,
                  cm_context_message(ctx));
        cm_warp_destroy(&w);
    }
    free(none);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* A tangled M0: one interior node dragged outside the block. LBWARP cannot give it positive
 * weights, simplex finds it outside every Delaunay tet; both count it (cm_warp_fallback_nodes)
 * and still move it (a finite displacement); the other nodes keep their weights. */
static void test_fallbacks(void)
{
    cm_mesh *m = block_mesh(1, 0);
    /* the interior node (3, 2, 2) of the 7 x 6 x 5 node grid */
    int64_t v = 3 + 7 * (2 + 6 * 2);
    m->xyz[3 * v + 2] = 5.0; /* the block ends at z = 1.2 */
    cm_mesh_boundary *b = NULL;
    cm_mesh_boundary_create(ctx, m, &b);
    for (int k = 1; k < 3; ++k) {
        cm_warp *w = NULL;
        cm_warp_options opt;
        cm_warp_options_init(&opt);
        opt.method = staten[k];
        cm_status s = cm_warp_create(ctx, m, b, NULL, &opt, &w);
        CHECK_MSG(s >= 0, "%s: %s", cm_warp_method_name(staten[k]), cm_context_message(ctx));
        if (s < 0) continue;
        size_t fb = cm_warp_fallback_nodes(w);
        printf("tangled M0: %s: %zu fallback nodes\n", cm_warp_method_name(staten[k]), fb);
        CHECK_MSG(fb >= 1 && fb <= 10, "%s: %zu", cm_warp_method_name(staten[k]), fb);
        double *d = calloc(3 * m->n_nodes, sizeof *d);
        for (size_t i = 0; i < b->n_nodes; ++i)
            d[3 * b->nodes[i]] = 0.01;
        CHECK(cm_warp_apply(ctx, w, d) == CM_OK && isfinite(d[3 * v]));
        free(d);
        cm_warp_destroy(&w);
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

int main(int argc, char **argv)
{
    cm_context_create(&ctx);
    test_lbwarp_weights();
    test_simplex_locate();
    test_errors();
    test_fallbacks();
    test_meshes(argc > 2 ? argv[2] : ".");
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
