/* cm_kdtree: the nearest point of random queries equals a brute-force scan (exact search),
 * k-nearest come sorted, and argument errors are reported, not crashed on. */
#include "cadmorph/kdtree.h"
#include "test_rng.h"
#include "test_util.h"

#include <stdint.h>
#include <stdlib.h>

static double rnd(uint64_t *s) { return test_rng_uniform(s); }

int main(void)
{
    cm_context *ctx = NULL;
    CHECK(cm_context_create(&ctx) == CM_OK);
    uint64_t seed = 42;
    enum { N = 20000, M = 2000, K = 4 };
    double *pts = malloc(3 * N * sizeof *pts), *q = malloc(3 * M * sizeof *q);
    /* clustered points on a sphere shell plus noise: not a uniform grid, to exercise the tree */
    for (int i = 0; i < N; ++i) {
        double x = rnd(&seed) * 2 - 1, y = rnd(&seed) * 2 - 1, z = rnd(&seed) * 2 - 1;
        double r = sqrt(x * x + y * y + z * z) + 1e-12;
        double s = (i % 3 ? 1.0 : 0.3) / r;
        pts[3 * i] = x * s;
        pts[3 * i + 1] = y * s;
        pts[3 * i + 2] = z * s + (i % 7 == 0 ? 2.0 : 0.0);
    }
    for (int i = 0; i < 3 * M; ++i) q[i] = rnd(&seed) * 3 - 1.5;

    cm_kdtree *tree = NULL;
    CHECK(cm_kdtree_create(ctx, pts, N, &tree) == CM_OK);
    CHECK(cm_kdtree_size(tree) == N);
    int64_t *idx = malloc(M * K * sizeof *idx);
    double *d2 = malloc(M * K * sizeof *d2);
    CHECK(cm_kdtree_nearest(ctx, tree, q, M, K, idx, d2) == CM_OK);
    int wrong = 0, unsorted = 0;
    for (int j = 0; j < M; ++j) {
        double best = INFINITY;
        for (int i = 0; i < N; ++i) {
            double dx = pts[3 * i] - q[3 * j], dy = pts[3 * i + 1] - q[3 * j + 1],
                   dz = pts[3 * i + 2] - q[3 * j + 2];
            double d = dx * dx + dy * dy + dz * dz;
            if (d < best) best = d;
        }
        if (fabs(d2[j * K] - best) > 1e-12 * (1 + best)) ++wrong;
        const double *p = pts + 3 * idx[j * K];
        double dx = p[0] - q[3 * j], dy = p[1] - q[3 * j + 1], dz = p[2] - q[3 * j + 2];
        if (fabs(dx * dx + dy * dy + dz * dz - best) > 1e-12 * (1 + best)) ++wrong;
        for (int k = 1; k < K; ++k)
            if (d2[j * K + k] < d2[j * K + k - 1]) ++unsorted;
    }
    CHECK_MSG(wrong == 0, "%d of %d queries differ from brute force", wrong, M);
    CHECK(unsorted == 0);

    /* single-thread run gives the same answer */
    cm_context_set_threads(ctx, 1);
    int64_t *idx1 = malloc(M * sizeof *idx1);
    CHECK(cm_kdtree_nearest(ctx, tree, q, M, 1, idx1, NULL) == CM_OK);
    int diff = 0;
    for (int j = 0; j < M; ++j) diff += idx1[j] != idx[j * K];
    CHECK(diff == 0);

    /* errors */
    CHECK(cm_kdtree_nearest(ctx, tree, q, M, 0, idx, d2) == CM_ERR_ARGUMENT);
    CHECK(cm_kdtree_nearest(ctx, tree, q, M, N + 1, idx, d2) == CM_ERR_ARGUMENT);
    cm_kdtree *bad = NULL;
    CHECK(cm_kdtree_create(ctx, pts, 0, &bad) == CM_ERR_ARGUMENT && bad == NULL);
    pts[5] = NAN;
    CHECK(cm_kdtree_create(ctx, pts, N, &bad) == CM_ERR_NUMERIC && bad == NULL);
    CHECK(cm_context_message(ctx)[0] != '\0');

    cm_kdtree_destroy(&tree);
    CHECK(tree == NULL);
    cm_kdtree_destroy(&tree);
    cm_kdtree_destroy(NULL);
    free(pts), free(q), free(idx), free(d2), free(idx1);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
