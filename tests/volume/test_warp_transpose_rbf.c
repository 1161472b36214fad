/* cm_warp_apply_transpose of the RBF methods: the dot-product test <V, J D> = <J^T V, D> with
 * random D and V on tets and hexes, several components, a pinned interior node, r^3 and r,
 * the dense and the iterative solver (tight tolerance), and a gmsh mesh from tests/data; the
 * iterative reverse product against the dense one; 0 at unconstrained nodes; stopped on
 * request at each of its progress points, then the bits of an uninterrupted call. */
#include "cadmorph/warp.h"
#include "test_mesh.h"
#include "test_stopper.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;

static double dot_abs(size_t n, const double *a, const double *b)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i) s += fabs(a[i] * b[i]);
    return s;
}

/* The relative gap of <V, J D> and <J^T V, D> (relative to sum |V J D|, the size the rounding
 * of the sums is relative to) for a warp of m with the constrained nodes con; jtv (#nodes x 3)
 * receives J^T V. Also checks J^T V = 0 away from the constrained nodes. */
static double warp_gap(const cm_mesh *m, const cm_mesh_boundary *b, const unsigned char *con,
                       cm_warp_method method, cm_rbf_solver solver, double tol, uint64_t *seed,
                       const double *dfix, double *jtv)
{
    const size_t nn = m->n_nodes;
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = method;
    opt.solver = solver;
    opt.tolerance = tol;
    cm_warp *w = NULL;
    cm_status s = cm_warp_create(ctx, m, b, con, &opt, &w);
    CHECK_MSG(s >= 0 && w, "%s", cm_context_message(ctx));
    if (!w) return INFINITY;
    double *d = malloc(nn * 3 * sizeof *d), *v = malloc(nn * 3 * sizeof *v);
    for (size_t i = 0; i < nn * 3; ++i) {
        d[i] = con[i / 3] ? (dfix ? dfix[i] : test_rand(seed)) : NAN; /* apply reads none */
        v[i] = test_rand(seed);
    }
    double *d0 = malloc(nn * 3 * sizeof *d0);
    memcpy(d0, d, nn * 3 * sizeof *d0);
    s = cm_warp_apply(ctx, w, d);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    s = cm_warp_apply_transpose(ctx, w, v, jtv);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    long double a = 0.0L, bb = 0.0L;
    int zero = 1;
    for (size_t i = 0; i < nn * 3; ++i) {
        a += (long double)v[i] * d[i];
        if (con[i / 3])
            bb += (long double)jtv[i] * d0[i];
        else
            zero &= jtv[i] == 0.0;
    }
    CHECK(zero);
    const double gap = fabs((double)(a - bb)) / dot_abs(nn * 3, v, d);
    printf("  %s, %s, %zu nodes, %zu components: <V, J D> = %.15g, <J^T V, D> = %.15g, gap "
           "%.3g\n",
           cm_warp_method_name(method), solver == CM_RBF_SOLVER_DENSE ? "dense" : "iterative",
           nn, b->n_components, (double)a, (double)bb, gap);
    cm_warp_destroy(&w);
    free(d), free(v), free(d0);
    return gap;
}

/* Blocks of tets or hexes, each its own component; one interior node of the first pinned. */
static void test_blocks(int tets)
{
    uint64_t seed = 99 + (unsigned)tets;
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block b1 = {6, 4, 3, {0.0, 0.0, 0.0}, {0.25, 0.3, 0.2}, tets, tets ? 0.2 : 0.1};
    test_block b2 = {3, 3, 5, {3.0, 0.0, 0.0}, {0.2, 0.2, 0.15}, tets, 0.1};
    test_block b3 = {4, 2, 2, {0.0, 3.0, 1.0}, {0.3, 0.3, 0.3}, tets, 0.0};
    test_add_block(ctx, m, &b1, &seed);
    test_add_block(ctx, m, &b2, &seed);
    test_add_block(ctx, m, &b3, &seed);
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    if (!b) {
        cm_mesh_destroy(&m);
        return;
    }
    CHECK(b->n_components == 3);
    unsigned char *con = calloc(m->n_nodes, 1);
    for (size_t i = 0; i < b->n_nodes; ++i) con[b->nodes[i]] = 1;
    con[1 + 7 * (1 + 5 * 1)] = 1; /* node (1, 1, 1) of the first block: inside */
    double *jtv = malloc(m->n_nodes * 3 * sizeof *jtv), *jtv_it = malloc(m->n_nodes * 3 * sizeof *jtv);
    printf("%s blocks:\n", tets ? "tet" : "hex");
    CHECK(warp_gap(m, b, con, CM_WARP_RBF, CM_RBF_SOLVER_DENSE, 0, &seed, NULL, jtv) <= 1e-10);
    CHECK(warp_gap(m, b, con, CM_WARP_RBF_BIHARMONIC, CM_RBF_SOLVER_DENSE, 0, &seed, NULL, jtv) <=
          1e-10);
    /* the iterative solver at 1e-13: the dot-product test, and its J^T V against the dense
     * one for the same V (same seed) as a functional of a smooth D, to the tolerance */
    uint64_t s1 = seed, s2 = seed;
    double *smooth = malloc(m->n_nodes * 3 * sizeof *smooth);
    for (size_t i = 0; i < m->n_nodes; ++i)
        for (int c = 0; c < 3; ++c)
            smooth[3 * i + c] = sin(m->xyz[3 * i] + c) * cos(0.7 * m->xyz[3 * i + 1]) + m->xyz[3 * i + 2];
    CHECK(warp_gap(m, b, con, CM_WARP_RBF, CM_RBF_SOLVER_ITERATIVE, 1e-13, &s1, smooth, jtv_it) <=
          1e-10);
    CHECK(warp_gap(m, b, con, CM_WARP_RBF, CM_RBF_SOLVER_DENSE, 0, &s2, smooth, jtv) <= 1e-10);
    long double diff = 0.0L;
    double scale = 0.0;
    for (size_t i = 0; i < m->n_nodes * 3; ++i)
        if (con[i / 3]) {
            diff += (long double)(jtv_it[i] - jtv[i]) * smooth[i];
            scale += fabs(jtv[i] * smooth[i]);
        }
    printf("  iterative vs dense: |<J^T V - dense, D>| / sum |dense D| = %.3g\n",
           fabs((double)diff) / scale);
    CHECK(fabs((double)diff) <= 1e-12 * scale);
    free(smooth), free(jtv), free(jtv_it), free(con);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* A gmsh tet mesh of a box with a hole (tests/data/msh). */
static void test_file(const char *data)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/msh/box_hole_22.msh", data);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    if (!m) return;
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) >= 0);
    if (b) {
        uint64_t seed = 5;
        unsigned char *con = calloc(m->n_nodes, 1);
        for (size_t i = 0; i < b->n_nodes; ++i) con[b->nodes[i]] = 1;
        double *jtv = malloc(m->n_nodes * 3 * sizeof *jtv);
        printf("%s:\n", path);
        CHECK(warp_gap(m, b, con, CM_WARP_RBF, CM_RBF_SOLVER_DENSE, 0, &seed, NULL, jtv) <= 1e-10);
        CHECK(warp_gap(m, b, con, CM_WARP_RBF, CM_RBF_SOLVER_ITERATIVE, 1e-13, &seed, NULL, jtv) <=
              1e-10);
        free(jtv), free(con);
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* Stopped on request (cm_context_interrupt) at its k-th progress point: CM_ERR_INTERRUPTED,
 * and the next call on the same warp gives the bits of the first. */
static void test_interrupt(void)
{
    uint64_t seed = 3;
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block b1 = {5, 4, 3, {0.0, 0.0, 0.0}, {0.25, 0.3, 0.2}, 1, 0.2};
    test_block b2 = {3, 3, 4, {3.0, 0.0, 0.0}, {0.2, 0.2, 0.15}, 0, 0.1};
    test_add_block(ctx, m, &b1, &seed);
    test_add_block(ctx, m, &b2, &seed);
    cm_mesh_boundary *b = NULL;
    cm_warp *w = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    CHECK(b && cm_warp_create(ctx, m, b, NULL, NULL, &w) == CM_OK);
    const size_t n3 = 3 * m->n_nodes;
    double *v = malloc(n3 * sizeof *v), *want = malloc(n3 * sizeof *want);
    double *got = malloc(n3 * sizeof *got);
    for (size_t i = 0; i < n3; ++i) v[i] = test_rand(&seed);
    stopper st = {ctx, 0, 0, ""};
    cm_context_set_progress(ctx, on_progress, &st);
    arm(&st, 0);
    CHECK(w && cm_warp_apply_transpose(ctx, w, v, want) == CM_OK);
    const int calls = st.calls;
    CHECK_MSG(calls >= 2, "%d progress points", calls);
    for (int k = 1; w && k <= calls; ++k) {
        arm(&st, k);
        cm_status s = cm_warp_apply_transpose(ctx, w, v, got);
        CHECK_MSG(interrupted(ctx, s), "stopped at %d (%s): status %d", k, st.stage, (int)s);
        cm_context_clear(ctx);
        arm(&st, 0);
        CHECK(cm_warp_apply_transpose(ctx, w, v, got) == CM_OK &&
              !memcmp(got, want, n3 * sizeof *got));
    }
    cm_context_set_progress(ctx, NULL, NULL);
    cm_warp_destroy(&w);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
    free(v), free(want), free(got);
}

int main(int argc, char **argv)
{
    if (cm_context_create(&ctx) != CM_OK) return 1;
    test_blocks(1);
    test_blocks(0);
    if (argc > 1) test_file(argv[1]);
    test_interrupt();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
