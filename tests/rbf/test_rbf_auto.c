/* AUTO's cost model (cm_rbf_auto_dense in rbf/iterative/rbf_auto.c, the probe in rbf_auto_probe.c):
 * the probe measures positive rates; the model's costs grow as they must (dense ~ m^3,
 * iterative ~ m to m^2); the choice is dense for small sets, iterative for large ones, with a
 * single crossover in between, and always dense for the kernels the iterative solver does not
 * handle. No timing is asserted: the rates depend on the machine. */
#include "rbf_internal.h"
#include "test_util.h"

int main(void)
{
    double g = 0.0, kp = 0.0, ka = 0.0;
    cm_blas_threads(NULL, "test_rbf_auto", 1, NULL); /* as cm_rbf_create decides */
    cm_rbf_auto_rates(&g, &kp, &ka);
    printf("probe: dgemm %.3g flop/s, plain %.3g, compensated %.3g pairs/s\n", g, kp, ka);
    CHECK(g > 1e8 && kp > 1e7 && ka > 1e7);
    CHECK(kp >= 0.5 * ka); /* compensation never makes a sum much faster */
    double d1, i1, d2, i2;
    CHECK(cm_rbf_auto_costs(4000, &d1, &i1) == 1);
    cm_rbf_auto_costs(8000, &d2, &i2);
    CHECK_MSG(d2 > 7.0 * d1 && d2 < 9.0 * d1, "dense cost 4k -> 8k: x%.3g (m^3: 8)", d2 / d1);
    CHECK_MSG(i2 > 1.9 * i1 && i2 < 4.1 * i1, "iterative cost 4k -> 8k: x%.3g", i2 / i1);
    CHECK(cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 500));
    CHECK(cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 2000));
    CHECK(!cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 40000));
    CHECK(!cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, 100000));
    CHECK(cm_rbf_auto_dense(CM_RBF_BIHARMONIC, 40000));
    int switches = 0, prev = 1;
    for (size_t m = 1000; m <= 60000; m += 500) {
        const int d = cm_rbf_auto_dense(CM_RBF_TRIHARMONIC, m);
        switches += d != prev;
        prev = d;
    }
    CHECK_MSG(switches == 1, "%d switches between dense and iterative over 1k..60k", switches);
    return TEST_REPORT();
}
