/* The internal knobs of the RBF solvers (not a public header): what a caller of rbf.h does
 * not choose, but tests and benchmarks vary. cm_rbf_tuning_init fills the defaults (in
 * brackets), which are the ones every cm_rbf_create / cm_rbf_create_opt uses; the figures
 * below are the measurements behind them (benchmarks/RESULTS.md, RBF solvers). All but
 * fast_eval_tol matter only for the iterative solver (ITERATIVE, or AUTO above its
 * crossover, and PETSC). */
#ifndef CADMORPH_RBF_TUNING_H
#define CADMORPH_RBF_TUNING_H

#include "cadmorph/rbf.h"

typedef struct cm_rbf_tuning {
    int leaf_size;        /* [256] kD-tree leaf size: leaves hold leaf_size/2..leaf_size
                           * centres and are the disjoint cores of the Schwarz subdomains */
    int local_size;       /* [700] centres per overlapping subdomain at least (the leaf
                           * plus the centres nearest to its box; overlap below may add
                           * more): the overlap is the knob that matters on thin walls.
                           * 700 rather than 1,400: below ~3e4 centres the set-up (n^3 per
                           * subdomain) outweighs the products, and halving n costs 0-1
                           * iterations (bore 9.9k / 20.6k, pipe 17.8k, bracket 22.1k: fit
                           * 1.3-2.2x less CPU); from ~6e4 the overlap rule sets n anyway */
    int coarse_size;      /* [2000] farthest-point centres of the coarse space (at m <= 2e4,
                           * see coarse_grow), 0: none */
    int local_float;      /* [1] storage of the local inverse rows: 1 float (4 instead of
                           * 8 bytes x m x local_size; the local linear fit is taken out of
                           * the data first, so float rounding costs no iterations: bracket
                           * 21k / 59k and bore 22.6k take the same counts as in double),
                           * 0 double, 2 the leaf's own rows in double, the overlap in float */
    int coarse_post;      /* [1] order of the coarse correction: 1 before and after the
                           * local solves (symmetric multiplicative: 10 instead of 13
                           * iterations on the bracket at 103k, 11 instead of 14 on two
                           * bodies at 121k, for a product of the correction with the coarse
                           * centres per application), 0 before them only, 2 after them
                           * only */
    double overlap;       /* [2] overlap measured in distance: a subdomain also takes every
                           * centre within overlap x H of its leaf's box (H: the coarse
                           * space's fill distance), up to local_max centres; 0: by count
                           * only. Grows the subdomains where the nodes are dense (edges,
                           * thin features): bracket 59k, first cycle 9-10 iterations
                           * instead of 12-13 at 1,501 centres on average instead of 1,400
                           * (by count). 2 rather than 3 with subdomains of 700: the same
                           * iterations from 1e4 to 1e5 centres (+1 at 1.2e5 and 1.5e5) at
                           * 1/2-1/3 of the set-up (bracket 103k: fit 18.2 instead of 22
                           * products' CPU); above ~2e5 more is needed (4.5 with local_max
                           * 4000 at 2.3e5) */
    int local_max;        /* [2800] cap on a subdomain's centres for overlap > 0 */
    double thin_reach;    /* [0] thinned overlap: beyond its near set (the leaf plus
                           * local_size / overlap / local_max as above, all kept), a subdomain
                           * also takes a thinned sample of the centres up to thin_reach x H
                           * from its leaf's box: one per voxel, the voxel growing with the
                           * distance (thin_cell), at most thin_max centres in all; the
                           * local solve is on that set, only the leaf rows are kept as ever.
                           * A geometric reach at a bounded centre count; 0: off. Measured
                           * (RESULTS.md, RBF solvers): better than no far band and than
                           * the same count of nearest centres, worse than the overlap rule's
                           * full 3 H (bracket 234k, 1,000 + 543 to 5.9 H: 5.6e-5 after 30
                           * iterations, 1,543 nearest 1.7e-3, the defaults' 1,821 3e-7;
                           * 103k: 40 iterations for 13) */
    double thin_cell;     /* [0.25] voxel edge / distance from the leaf's box in the thinned
                           * band (the distance rounded down to d0 2^k, d0 the near set's
                           * reach): larger thins more */
    int thin_max;         /* [2000] cap on a subdomain's centres with thin_reach > 0 (the far
                           * picks nearest to the leaf are kept first) */
    int coarse_grow;      /* [1] coarse_size is the count at 2e4 centres; above, it grows as
                           * sqrt(m) (coarse factor 8 coarse^2 bytes, O(m)): bracket 59k,
                           * 5,000 coarse centres: 17 iterations instead of 21 */
    int coarse_max;       /* [16000] cap on the coarse centres (0: none but m/4); the
                           * sqrt rule reaches 8,000 at 3.2e5 centres and 16,000 at
                           * 1.28e6. 16,000 rather than 8,000: a finer coarse space keeps
                           * the subdomains (overlap x H) small; 955k surface centres:
                           * set-up 163 s instead of 333, 8.6 instead of 10.1 GB, 479k:
                           * 6 iterations instead of 7 */
    int coarse_inner;     /* [0] 0: the coarse problem is solved exactly by its dense
                           * projected Cholesky factor (8 coarse^2 bytes, so coarse_max
                           * stays near 8,000-16,000); N > 0: by at most N iterations of an
                           * inner FGMRES preconditioned by a two-level Schwarz of its own on
                           * the coarse centres (O(coarse) memory, so the coarse space can
                           * grow with m: set coarse_size / coarse_grow / coarse_max) */
    double coarse_inner_tol; /* [1e-2] the inner solve stops when the coarse residual's
                           * 2-norm is reduced by this factor (or after coarse_inner steps) */
    double fast_tol;      /* [1e-12] treecode accuracy in the Krylov loop (fast_sum),
                           * relative to sum_j |w_j| phi_ij (its error bound; measured on
                           * random weights). RBF weights cancel (sum |w| phi is 1e4..1e7 x
                           * the result), so the error relative to the result is that much
                           * larger: the solver corrects it by refinement on exact residuals
                           * (fast_refine) */
    int fast_refine;      /* [3] outer refinement steps on exact (direct: compensated, or
                           * plain if they err by at most 10 % of a tolerance of 1e-8 or more)
                           * residuals around the fast-matvec Krylov solve; 0: none (the final
                           * residual is then the treecode's, cheaper but not exact) */
    double fast_eval_tol; /* [1e-9] evaluation takes the fast sum only if its estimated error
                           * is at most fast_eval_tol x max |data|, or at most the rounding
                           * that direct sums have too (eval_error; else direct compensated
                           * sums) */
    int relax;            /* [1] relaxed-accuracy Krylov products (direct-matvec solves):
                           * compensated sums while the residual is large, then plain sums and,
                           * from 5e4 centres unless fast_sum = 0, loose treecode sums, as the
                           * GMRES residual falls (an error of about tolerance / residual in a
                           * product is harmless: inexact Krylov); the residual is still
                           * checked exactly at the end, and a restart follows if it fails.
                           * 0: every Krylov product compensated; 2: as 1 with the treecode at
                           * any m (for tests) */
    double column_scale;  /* [1e-3] each column of an iterative solve is held to the
                           * tolerance x max(max |f_c|, column_scale x max |f| of all columns)
                           * (rbf_fgmres.c says why); 1: all to max |f| of all columns (a
                           * column's stopping test then depends on its batch-mates) */
    double krylov_budget; /* [0] bytes the iterative solve's per-column storage may take
                           * (the Krylov bases of all columns solved at once); columns beyond
                           * it are solved in groups (stats column_groups). 0: half the
                           * machine's memory (cm_memory_budget) */
    int warm_history;     /* [64] earlier solutions an iterative fit keeps for the starts of
                           * its next solves (options warm_start; rbf_iter.h, cm_rbf_history),
                           * at most what an eighth of cm_memory_budget holds (2 m doubles
                           * each); the oldest gives way */
} cm_rbf_tuning;

void cm_rbf_tuning_init(cm_rbf_tuning *tuning);

/* cm_rbf_create_opt with these knobs (tuning NULL: the defaults; opt NULL: the default
 * options). Errors as cm_rbf_create_opt; CM_ERR_ARGUMENT for a knob out of its range. */
cm_status cm_rbf_create_tuned(cm_context *ctx, cm_rbf_kernel kernel, int dim, size_t m,
                              const double *centres, const cm_rbf_options *opt,
                              const cm_rbf_tuning *tuning, cm_rbf **rbf);

#endif
