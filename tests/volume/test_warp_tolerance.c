/* The RBF warp's tolerance from the mesh (cm_warp_options.tolerance 0; docs/DESIGN.md, "The
 * warp's tolerance"): 1e-3 x the shortest constrained-to-free spacing of a cell over the
 * constrained nodes' diagonal, within [1e-10, 1e-6], the same on tets, hexes and the hexes as
 * polyhedra; a tolerance given is taken as it is; and what the rule promises: on blocks whose
 * wall layer is 1e-4 and 1e-5 thick, for a motion of the size of the block, the iterative warp
 * at that tolerance changes no vector between two nodes of a cell by more than 1e-3 of its
 * length against the same warp solved to 1e-12 (itself checked against the dense solver where
 * that resolves the layer); the reverse product not loosened with it. */
#include "cadmorph/warp.h"
#include "test_mesh.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static cm_context *ctx;

/* measured 5.6e-12; 8.4e-7 when the reverse solve stops at the forward 1e-6 */
#define REVERSE_GAP 1e-9

/* A block of 6^3 cells of 0.2 (tets or hexes; polyhedra: the hexes as polyhedra), its lowest
 * layer of cells `first` thick instead (0: as the others); lone > 0: instead one free node
 * (0.6, 0.6, 0.2) that near the wall. */
static cm_mesh *block(int tets, int poly, double first, double lone)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    uint64_t seed = 5;
    test_block b = {6, 6, 6, {0.0, 0.0, 0.0}, {0.2, 0.2, 0.2}, tets, 0.0};
    CHECK(m && test_add_block(ctx, m, &b, &seed) >= 0);
    for (size_t i = 0; m && i < m->n_nodes; ++i) {
        double *x = m->xyz + 3 * i;
        if (fabs(x[2] - 0.2) > 1e-12) continue;
        if (first > 0) x[2] = first;
        if (lone > 0 && fabs(x[0] - 0.6) < 1e-12 && fabs(x[1] - 0.6) < 1e-12) x[2] = lone;
    }
    if (m && poly) {
        cm_mesh *p = test_hexes_as_polyhedra(ctx, m);
        cm_mesh_destroy(&m);
        m = p;
    }
    return m;
}

/* The warp of m with the given solver and tolerance option; NULL on failure (checked). */
static cm_warp *warp_of(const cm_mesh *m, const cm_mesh_boundary *b, cm_rbf_solver solver,
                        double tol)
{
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.solver = solver;
    opt.tolerance = tol;
    cm_warp *w = NULL;
    cm_status s = cm_warp_create(ctx, m, b, NULL, &opt, &w);
    CHECK_MSG(s >= 0 && w, "%s", cm_context_message(ctx));
    return w;
}

/* What the rule should give on m, found by brute force over every constrained-free pair (on
 * these blocks the nearest pair shares a cell). */
static double expected(const cm_mesh *m, const cm_mesh_boundary *b)
{
    unsigned char *con = calloc(m->n_nodes, 1);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < b->n_nodes; ++i) {
        con[b->nodes[i]] = 1;
        for (int a = 0; a < 3; ++a) {
            lo[a] = fmin(lo[a], m->xyz[3 * b->nodes[i] + a]);
            hi[a] = fmax(hi[a], m->xyz[3 * b->nodes[i] + a]);
        }
    }
    double h = INFINITY;
    for (size_t i = 0; i < m->n_nodes; ++i)
        for (size_t j = 0; con[i] && j < m->n_nodes; ++j)
            if (!con[j]) {
                double d2 = 0;
                for (int a = 0; a < 3; ++a)
                    d2 += (m->xyz[3 * i + a] - m->xyz[3 * j + a]) *
                          (m->xyz[3 * i + a] - m->xyz[3 * j + a]);
                h = fmin(h, sqrt(d2));
            }
    free(con);
    const double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) +
                             (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    return fmax(1e-10, fmin(1e-6, 1e-3 * h / diag));
}

/* The tolerance taken on a block (first, lone as in block) against the rule, and with one
 * given. */
static void test_rule(int tets, int poly, double first, double lone)
{
    cm_mesh *m = block(tets, poly, first, lone);
    cm_mesh_boundary *b = NULL;
    CHECK(m && cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    if (!b) goto done;
    const double want = expected(m, b);
    cm_warp *w = warp_of(m, b, CM_RBF_SOLVER_AUTO, 0);
    const double got = cm_warp_tolerance(w);
    printf("  %s, wall spacing %g: tolerance %.6g (the rule %.6g)\n",
           poly ? "polyhedra" : tets ? "tets" : "hexes", lone > 0 ? lone : first > 0 ? first : 0.2,
           got, want);
    CHECK(fabs(got - want) <= 1e-12 * want);
    cm_warp_destroy(&w);
    w = warp_of(m, b, CM_RBF_SOLVER_AUTO, 3e-8); /* given: taken as it is */
    CHECK(cm_warp_tolerance(w) == 3e-8);
    cm_warp_destroy(&w);
done:
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* The block's nodes moved by a smooth motion as large as its diagonal, by warp w: disp. */
static void move(const cm_mesh *m, const cm_mesh_boundary *b, cm_warp *w, double *disp)
{
    const double diag = 1.2 * sqrt(3.0);
    for (size_t i = 0; i < 3 * m->n_nodes; ++i) disp[i] = 0;
    for (size_t i = 0; i < b->n_nodes; ++i) {
        const double *x = m->xyz + 3 * b->nodes[i];
        double *d = disp + 3 * b->nodes[i];
        d[0] = 0.6 * diag * sin(2.0 * x[0] + x[1]);
        d[1] = 0.6 * diag * cos(1.5 * x[1] * x[2]);
        d[2] = 0.4 * diag * x[0] * (x[2] - 0.5);
    }
    CHECK(w && cm_warp_apply(ctx, w, disp) == CM_OK);
}

/* The largest |(a_i - a_j) - (b_i - b_j)| / |x_i - x_j| over two nodes i, j of a cell: how
 * much more one field than the other stretches or turns any cell's edges and diagonals. */
static double strain(const cm_mesh *m, const double *a, const double *b)
{
    double worst = 0;
    for (size_t c = 0; c < m->n_cells; ++c)
        for (int64_t p = m->offset[c]; p < m->offset[c + 1]; ++p)
            for (int64_t q = p + 1; q < m->offset[c + 1]; ++q) {
                const int64_t i = m->conn[p], j = m->conn[q];
                double de = 0, dx = 0;
                for (int k = 0; k < 3; ++k) {
                    const double e = (a[3 * i + k] - b[3 * i + k]) - (a[3 * j + k] - b[3 * j + k]);
                    const double x = m->xyz[3 * i + k] - m->xyz[3 * j + k];
                    de += e * e, dx += x * x;
                }
                if (dx > 0) worst = fmax(worst, sqrt(de / dx));
            }
    return worst;
}

/* On tets whose wall layer is `first` thick: the iterative warp at the tolerance from the
 * mesh against the same solved to 1e-12, in strain; that reference against the dense warp
 * where the dense one resolves the layer (dense_too). */
static void test_promise(double first, int dense_too)
{
    cm_mesh *m = block(1, 0, first, 0);
    cm_mesh_boundary *b = NULL;
    CHECK(m && cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    if (!b) goto done;
    const size_t n3 = 3 * m->n_nodes;
    double *got = malloc(n3 * sizeof *got), *ref = malloc(n3 * sizeof *ref);
    double *dense = malloc(n3 * sizeof *dense);
    cm_warp *w = warp_of(m, b, CM_RBF_SOLVER_ITERATIVE, 0);
    const double tol = cm_warp_tolerance(w);
    move(m, b, w, got);
    cm_warp_destroy(&w);
    w = warp_of(m, b, CM_RBF_SOLVER_ITERATIVE, 1e-12);
    move(m, b, w, ref);
    cm_warp_destroy(&w);
    const double s = strain(m, got, ref);
    printf("  wall layer %g, tolerance %.3g: the cells' edges and diagonals within %.3g of their "
           "length of the warp to 1e-12\n", first, tol, s);
    CHECK(s <= 1e-3);
    if (dense_too) {
        w = warp_of(m, b, CM_RBF_SOLVER_DENSE, 0);
        move(m, b, w, dense);
        cm_warp_destroy(&w);
        const double sd = strain(m, ref, dense);
        printf("  ... the warp to 1e-12 within %.3g of the dense one\n", sd);
        CHECK(sd <= 1e-6);
    }
    free(got), free(ref), free(dense);
done:
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* The reverse product of the warp at the tolerance from the mesh (1e-6 on the coarse block)
 * against the dense one's: it solves to 1e-10 whatever the forward tolerance (rbf.h,
 * cm_rbf_evaluate_transpose), since a residual moves its weights by itself times their
 * growth. Returns the largest difference relative to the largest entry. */
static double reverse_gap(void)
{
    cm_mesh *m = block(1, 0, 0, 0);
    cm_mesh_boundary *b = NULL;
    double gap = INFINITY;
    CHECK(m && cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    if (!b) goto done;
    const size_t n3 = 3 * m->n_nodes;
    double *v = malloc(n3 * sizeof *v), *ri = malloc(n3 * sizeof *ri), *rd = malloc(n3 * sizeof *rd);
    uint64_t seed = 11;
    for (size_t i = 0; i < n3; ++i) v[i] = test_rand(&seed);
    cm_warp *wi = warp_of(m, b, CM_RBF_SOLVER_ITERATIVE, 0);
    cm_warp *wd = warp_of(m, b, CM_RBF_SOLVER_DENSE, 0);
    CHECK(cm_warp_tolerance(wi) == 1e-6);
    CHECK(wi && wd && cm_warp_apply_transpose(ctx, wi, v, ri) == CM_OK &&
          cm_warp_apply_transpose(ctx, wd, v, rd) == CM_OK);
    double d = 0, big = 0;
    for (size_t i = 0; i < n3; ++i) d = fmax(d, fabs(ri[i] - rd[i])), big = fmax(big, fabs(rd[i]));
    gap = d / big;
    printf("  reverse product at the tolerance from the mesh (%.3g): within %.3g of the dense "
           "one\n", cm_warp_tolerance(wi), gap);
    cm_warp_destroy(&wi);
    cm_warp_destroy(&wd);
    free(v), free(ri), free(rd);
done:
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
    return gap;
}

int main(void)
{
    if (cm_context_create(&ctx) != CM_OK) return 1;
    for (int t = 0; t < 3; ++t) {
        test_rule(t == 0, t == 2, 0, 0);    /* 1e-3 x 0.2 / 2.08: above 1e-6, so 1e-6 */
        test_rule(t == 0, t == 2, 1e-4, 0); /* 4.8e-8 */
        test_rule(t == 0, t == 2, 0, 1e-8); /* 4.8e-12: below 1e-10, so 1e-10 */
    }
    test_promise(1e-4, 1);
    test_promise(1e-5, 0); /* the dense solve errs by 1e-7 here: its side-wall centres are
                              1e-5 apart */
    CHECK(reverse_gap() <= REVERSE_GAP);
    /* methods without an iterative solve have none */
    cm_mesh *m = block(1, 0, 0, 0);
    cm_mesh_boundary *b = NULL;
    CHECK(m && cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = CM_WARP_FEMWARP;
    cm_warp *w = NULL;
    CHECK(b && cm_warp_create(ctx, m, b, NULL, &opt, &w) == CM_OK && cm_warp_tolerance(w) == 0);
    CHECK(cm_warp_tolerance(NULL) == 0);
    cm_warp_destroy(&w);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
