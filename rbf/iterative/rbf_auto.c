/* AUTO's choice between the dense and the iterative solver: a cost model in seconds of one
 * thread, from the rates rbf_auto_probe.c times once per process, for the count of solves
 * the caller expects on the fit. */
#include "rbf_internal.h"

/* Cost model for AUTO, in seconds of one thread, from rates timed in this process
 * (cm_rbf_auto_rates: G dgemm flops/s, Kp and Ka plain and compensated kernel pairs/s):
 *   dense     ~ m^3/3 / (E G) + D m^2 / Kp: the Cholesky factorisation at E times the dgemm
 *               rate, assembly and the refinement's kernel sums;
 *   iterative ~ S m / G + N m^2 / Ka: the Schwarz set-up (local and coarse factorisations,
 *               S flops per centre at the dgemm rate) and N compensated sums of m^2 pairs
 *               (FGMRES matvecs, the final residual, evaluation at the centres).
 * E, S and N were fitted to bench_rbf runs of both solvers at m = 5k, 10k, 20k in one
 * window (RESULTS.md, RBF solvers); S and N again with subdomains of 700 centres and an
 * overlap of 2 H (Zen 4:
 * S 1.9e7 -> 3.0e6, N 12 -> 8.6; crossover ~3,500 centres, where real boundary sets agree:
 * iterative ahead on bore 3.3k and pipe 4.7k, dense on bracket 1.8k).
 * Why rates and not seconds: the old constants (crossover ~7,500 centres) came from
 * Haswell kernels under load; with the AVX-512 dgemm the dense path is 2x faster and with the
 * hand-written AVX-512 sums the iterative one too, and the crossover follows their ratio.
 * Without rates (the probe could not allocate) the old constants stand. Dense is also
 * refused when its factor (4 m^2 bytes) would take more than half the physical memory.
 * Below 1,000 centres dense always wins and above 60,000 its factorisation alone takes
 * minutes and 7 GB, so those skip the probe. */
#define CM_RBF_AUTO_E 1.0
#define CM_RBF_AUTO_D 3.0
#define CM_RBF_AUTO_S 3.0e6
#define CM_RBF_AUTO_N 8.6
#define CM_RBF_COST_DENSE_M3 7.9e-12
#define CM_RBF_COST_ITER_M 5.5e-5 /* the old 3.5e-4 and 1.3e-8 scaled as S and N */
#define CM_RBF_COST_ITER_M2 9e-9
/* Each further solve on the same fit (cm_rbf_options.solves: the right-hand sides a caller
 * expects, an absolute study's variants): dense DS plain passes of m^2 pairs (the packed
 * triangular solves streaming the factor, the residual's kernel sums, one refinement step),
 * iterative NW compensated passes (a warm Krylov solve from the fit's earlier solutions:
 * 3-4 iterations instead of 6-7, and the final residual). Fitted to the bore studies of 20
 * variants in batches of 5 on 5.7k, 10.7k and 20.6k centres (benchmarks/RESULTS.md, "AUTO
 * solver choice", Counting the solves): a variant's share of the batches' solves after the
 * first, relative to the factorisation's time measured in the same runs, times the model's
 * factorisation: DS 3.2-4.2, NW 4.0-4.7. Why relative to the factorisation, not to the
 * cold iterative solve (NW 2.8-3.4 that way): the one-solve model weighs the factorisation
 * 1.2-1.7x heavier against a Krylov solve than these runs do, and the choice for many solves
 * is factorisation against solves; so fitted, the model's dense/iterative ratio of a whole
 * study is within 10 % of the measured one at all three sizes (crossover for 20 variants
 * near 5,500 centres: at 5.7k the two tie). For one solve nothing changes. */
#define CM_RBF_AUTO_DS 3.7
#define CM_RBF_AUTO_NW 4.3
/* the fallback's: as the passes of its m^2 term, a plain pass at 0.55 of a compensated one
 * (the probe's ratio of the two rates) */
#define CM_RBF_COST_DENSE_M2 (0.55 * CM_RBF_AUTO_DS * CM_RBF_COST_ITER_M2 / CM_RBF_AUTO_N)
#define CM_RBF_COST_WARM_M2 (CM_RBF_AUTO_NW * CM_RBF_COST_ITER_M2 / CM_RBF_AUTO_N)

int cm_rbf_auto_costs(size_t m, int solves, double *dense, double *iter)
{
    const double x = (double)m, more = solves > 1 ? (double)(solves - 1) : 0.0;
    double g, kp, ka;
    cm_rbf_auto_rates(&g, &kp, &ka);
    if (g > 0.0 && kp > 0.0 && ka > 0.0) {
        *dense = x * x * x / 3.0 / (CM_RBF_AUTO_E * g) + CM_RBF_AUTO_D * x * x / kp +
                 more * CM_RBF_AUTO_DS * x * x / kp;
        *iter = CM_RBF_AUTO_S * x / g + CM_RBF_AUTO_N * x * x / ka +
                more * CM_RBF_AUTO_NW * x * x / ka;
        return 1;
    }
    *dense = CM_RBF_COST_DENSE_M3 * x * x * x + more * CM_RBF_COST_DENSE_M2 * x * x;
    *iter = CM_RBF_COST_ITER_M * x + CM_RBF_COST_ITER_M2 * x * x +
            more * CM_RBF_COST_WARM_M2 * x * x;
    return 0;
}

int cm_rbf_auto_dense(cm_rbf_kernel kernel, size_t m, int solves)
{
    if (kernel != CM_RBF_TRIHARMONIC) return 1;
    const double x = (double)m;
    const double budget = cm_memory_budget();
    if (budget > 0 && 4.0 * x * x > budget) return 0;
    if (m < 1000) return 1;
    if (m > 60000) return 0;
    double dense, iter;
    cm_rbf_auto_costs(m, solves, &dense, &iter);
    return dense <= iter;
}
