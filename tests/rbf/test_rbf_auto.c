/* AUTO's cost model (cm_rbf_auto_dense in rbf/iterative/rbf_auto.c, the probe in rbf_auto_probe.c):
 * the probe measures positive rates; the model's costs grow as they must (dense ~ m^3,
 * iterative ~ m to m^2); the choice is dense for small sets, iterative for large ones, with a
 * single crossover in between, and always dense for the kernels the iterative solver does not
 * handle. The count of solves (cm_rbf_options.solves): one solve (and 0, and negative counts)
 * is the choice without the count; more solves move the crossover up, monotonically, and the
 * caps (below 1,000 centres dense, above 60,000 iterative) stay. No timing is asserted: the
 * rates depend on the machine. */
#include "rbf_internal.h"
#include "test_util.h"

/* The first m (steps of 250 from 1,000) where AUTO takes the iterative solver for `solves`
 * solves; 0 if none up to 60,000. Also counts the switches between the two. */
static size_t crossover(int solves, int *switches)
{
    size_t first = 0;
    int prev = 1;
    *switches = 0;
    for (size_t m = 1000; m <= 60000; m += 250) {
        const int d = cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, m, solves);
        *switches += d != prev;
        if (!d && !first) first = m;
        prev = d;
    }
    return first;
}

int main(void)
{
    double g = 0.0, kp = 0.0, ka = 0.0;
    cm_blas_threads(NULL, "test_rbf_auto", 1, NULL); /* as cm_rbf_create decides */
    cm_rbf_auto_rates(&g, &kp, &ka);
    printf("probe: dgemm %.3g flop/s, plain %.3g, compensated %.3g pairs/s\n", g, kp, ka);
    CHECK(g > 1e8 && kp > 1e7 && ka > 1e7);
    CHECK(kp >= 0.5 * ka); /* compensation never makes a sum much faster */
    double d1, i1, d2, i2;
    CHECK(cm_rbf_auto_costs(4000, 1, &d1, &i1) == 1);
    cm_rbf_auto_costs(8000, 1, &d2, &i2);
    CHECK_MSG(d2 > 7.0 * d1 && d2 < 9.0 * d1, "dense cost 4k -> 8k: x%.3g (m^3: 8)", d2 / d1);
    CHECK_MSG(i2 > 1.9 * i1 && i2 < 4.1 * i1, "iterative cost 4k -> 8k: x%.3g", i2 / i1);
    CHECK(cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 500, 1));
    CHECK(cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 2000, 1));
    CHECK(!cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 40000, 1));
    CHECK(!cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 100000, 1));
    CHECK(cm_rbf_auto_dense(CM_RBF_BIHARMONIC, 40000, 1));

    /* one solve: 0 and negative counts mean one, and the costs are those without a count */
    double d0, i0, dn, in;
    cm_rbf_auto_costs(8000, 0, &d0, &i0);
    cm_rbf_auto_costs(8000, -5, &dn, &in);
    CHECK(d0 == d2 && i0 == i2 && dn == d2 && in == i2);
    int sw1 = 0, sw0 = 0;
    const size_t x1 = crossover(1, &sw1), x0 = crossover(0, &sw0);
    CHECK_MSG(sw1 == 1 && x1 > 1000, "%d switches over 1k..60k for one solve", sw1);
    CHECK_MSG(x0 == x1 && sw0 == sw1, "0 solves: crossover %zu, one solve %zu", x0, x1);

    /* more solves: each further one costs both solvers, the iterative one more (a warm Krylov
     * solve against two triangular solves and a refinement) */
    double d20, i20;
    cm_rbf_auto_costs(8000, 20, &d20, &i20);
    CHECK_MSG(d20 > d2 && i20 > i2 && i20 - i2 > d20 - d2,
              "20 solves at 8k: dense +%.3g s, iterative +%.3g s", d20 - d2, i20 - i2);
    size_t prev = x1;
    const int counts[] = {2, 5, 20, 100, 1000};
    for (size_t q = 0; q < sizeof counts / sizeof *counts; ++q) {
        int sw = 0;
        const size_t x = crossover(counts[q], &sw);
        printf("solves %d: iterative from %zu centres\n", counts[q], x ? x : (size_t)60250);
        CHECK_MSG(sw <= 1, "%d switches for %d solves", sw, counts[q]);
        CHECK_MSG((x ? x : 60250) >= prev, "%d solves: crossover %zu below %zu", counts[q], x,
                  prev);
        prev = x ? x : 60250;
    }
    /* 20 solves (a study of 20 variants) take dense on fits just above the one-solve
     * crossover, and the crossover moves well up (the model: 3,500 -> ~5,750 centres;
     * benchmarks/RESULTS.md, "AUTO solver choice") */
    int sw20 = 0;
    const size_t x20 = crossover(20, &sw20);
    CHECK_MSG(x20 >= 1.3 * (double)x1, "20 solves: crossover %zu, one solve %zu", x20, x1);
    CHECK(!cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, x1, 1));
    CHECK(cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, x1, 20));
    /* the caps stay whatever the count */
    CHECK(cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 900, 1));
    CHECK(!cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 70000, 1000000));
    CHECK(cm_rbf_auto_dense(CM_RBF_BIHARMONIC, 70000, 1));
    return TEST_REPORT();
}
