/* Interior optimisation (volume/optimize.c): the measure is 1 on ideal cells and infinite on
 * inverted ones; on blocks of tets and hexes with interior nodes pushed through their
 * neighbours the optimiser untangles every cell, never moves a boundary node, never lowers
 * the minimum scaled Jacobian, and gives the same coordinates with 1 and 2 threads. */
#include "cadmorph/optimize.h"
#include "test_util.h"
#include "test_mesh.h"

#include <math.h>
#include <stdio.h>

static void test_measure(void)
{
    const double s3 = sqrt(3.0) / 2;
    const double tet[] = {0, 0, 0, 1, 0, 0, 0.5, s3, 0, 0.5, s3 / 3, sqrt(2.0 / 3.0)};
    const double hex[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
    const double wedge[] = {0, 0, 0, 0.5, s3, 0, 1, 0, 0, 0, 0, 1, 0.5, s3, 1, 1, 0, 1};
    const double pyr[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, sqrt(0.5)};
    const cm_cell_type types[4] = {CM_CELL_TET4, CM_CELL_HEX8, CM_CELL_WEDGE6, CM_CELL_PYR5};
    const double *cells[4] = {tet, hex, wedge, pyr};
    for (int t = 0; t < 4; ++t) {
        double q = cm_optimize_cell_measure(types[t], cells[t]);
        double sj = cm_quality_scaled_jacobian(types[t], cells[t]);
        CHECK_MSG(fabs(q - 1) < 1e-12 && fabs(sj - 1) < 1e-12, "type %d: measure %.15g, SJ %.15g",
                  t, q, sj);
        /* scaled and moved: the same measure; stretched: worse */
        double x[24];
        int n = t == 0 ? 4 : t == 1 ? 8 : t == 2 ? 6 : 5;
        for (int i = 0; i < 3 * n; ++i)
            x[i] = 3.5 * cells[t][i] + (i % 3 == 1 ? -2.0 : 0.25);
        CHECK(fabs(cm_optimize_cell_measure(types[t], x) - 1) < 1e-12);
        for (int i = 0; i < n; ++i)
            x[3 * i] *= 3;
        CHECK(cm_optimize_cell_measure(types[t], x) > 1.2);
    }
    double flat[12];
    memcpy(flat, tet, sizeof flat);
    flat[11] = -0.1; /* apex through the base */
    CHECK(isinf(cm_optimize_cell_measure(CM_CELL_TET4, flat)));
    CHECK(isnan(cm_optimize_cell_measure(CM_CELL_TRI3, flat)));
}

/* A block whose interior nodes are jittered, then a few pushed across their neighbours. */
static cm_mesh *tangled_block(cm_context *ctx, int tets, size_t *pushed)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block blk = {6, 5, 4, {0, 0, 0}, {1.0, 1.2, 0.9}, tets, 0.15};
    uint64_t seed = 12345;
    CHECK(test_add_block(ctx, m, &blk, &seed) == 0);
    /* interior node (i,j,k) = i + 7 (j + 6 k): push three of them by most of a cell */
    const int64_t nodes[3] = {2 + 7 * (2 + 6 * 2), 4 + 7 * (3 + 6 * 1), 3 + 7 * (1 + 6 * 3)};
    const double push[3][3] = {{1.3, 0.4, 0.2}, {-0.3, 1.5, 0.1}, {0.2, -0.2, -1.2}};
    for (int k = 0; k < 3; ++k)
        for (int d = 0; d < 3; ++d)
            m->xyz[3 * nodes[k] + d] += push[k][d];
    *pushed = 3;
    return m;
}

static void test_untangle(cm_context *ctx, int tets)
{
    size_t pushed;
    cm_mesh *m = tangled_block(ctx, tets, &pushed);
    cm_mesh *copy = NULL;
    CHECK(cm_mesh_copy(ctx, m, &copy) == CM_OK);
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    cm_optimize_stats st;
    cm_context_set_threads(ctx, 2);
    cm_status s = cm_mesh_optimize(ctx, m, NULL, NULL, &st);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    printf("%s: inverted %zu -> %zu, min SJ %.4f -> %.4f, %zu nodes, %zu moves, %d passes\n",
           tets ? "tets" : "hexes", st.inverted_before, st.inverted_after, st.min_sj_before,
           st.min_sj_after, st.nodes_selected, st.moves, st.sweeps);
    CHECK(st.inverted_before > 0);
    CHECK_MSG(st.inverted_after == 0, "%zu cells still inverted", st.inverted_after);
    CHECK(st.min_sj_after >= st.min_sj_before);
    size_t boundary_moved = 0;
    for (size_t i = 0; i < b->n_nodes; ++i)
        boundary_moved += memcmp(m->xyz + 3 * b->nodes[i], copy->xyz + 3 * b->nodes[i],
                                 3 * sizeof(double)) != 0;
    CHECK(boundary_moved == 0);
    /* one thread: the same coordinates */
    cm_context_set_threads(ctx, 1);
    s = cm_mesh_optimize(ctx, copy, NULL, NULL, NULL);
    CHECK(s == CM_OK);
    double diff = 0;
    for (size_t i = 0; i < 3 * m->n_nodes; ++i)
        if (fabs(m->xyz[i] - copy->xyz[i]) > diff) diff = fabs(m->xyz[i] - copy->xyz[i]);
    CHECK_MSG(diff <= 1e-12, "1 vs 2 threads differ by %.3g", diff);
    /* an optimised mesh stays valid when optimised again, and fixed nodes never move */
    unsigned char *fixed = calloc(m->n_nodes, 1);
    for (size_t i = 0; i < m->n_nodes; i += 3)
        fixed[i] = 1;
    memcpy(copy->xyz, m->xyz, 3 * m->n_nodes * sizeof(double));
    CHECK(cm_mesh_optimize(ctx, m, fixed, NULL, &st) == CM_OK && st.inverted_after == 0);
    size_t fixed_moved = 0;
    for (size_t i = 0; i < m->n_nodes; i += 3)
        fixed_moved += memcmp(m->xyz + 3 * i, copy->xyz + 3 * i, 3 * sizeof(double)) != 0;
    CHECK(fixed_moved == 0);
    free(fixed);
    cm_context_set_threads(ctx, 0);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&copy);
    cm_mesh_destroy(&m);
}

int main(void)
{
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_measure();
    test_untangle(ctx, 1);
    test_untangle(ctx, 0);
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    CHECK(cm_mesh_optimize(ctx, m, NULL, NULL, NULL) == CM_ERR_UNSUPPORTED);
    cm_mesh_destroy(&m);
    CHECK(cm_mesh_optimize(ctx, NULL, NULL, NULL, NULL) == CM_ERR_ARGUMENT);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
