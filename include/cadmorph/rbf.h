/* cadmorph RBF core: scattered-data interpolation with polyharmonic kernels plus a linear
 * polynomial (paper: triharmonic-rbf-mesh-morphing, section 3; 2D variant section 4).
 *
 *   d(x) = sum_j w_j phi(|x - c_j|) + q_0 + q_1 x_1 + ... + q_dim x_dim,  sum_j w_j p(c_j) = 0
 *
 * The factorisation (dense) or preconditioner (iterative) depends only on the centres:
 * create once, then solve for any number of right-hand sides (an absolute sweep changes only
 * the values). Conventions: see core.h.
 */
#ifndef CADMORPH_RBF_H
#define CADMORPH_RBF_H

#include "cadmorph/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum cm_rbf_kernel {
    CM_RBF_TRIHARMONIC = 0, /* phi = r^3, 3D (the method's kernel) */
    CM_RBF_BIHARMONIC = 1,  /* phi = r, 3D (the paper's comparison) */
    CM_RBF_THIN_PLATE = 2   /* phi = r^2 log r, phi(0) = 0, 2D */
} cm_rbf_kernel;

typedef struct cm_rbf cm_rbf;

/* How the system is solved.
 * DENSE: null-space projected Cholesky of the m x m system: 4 m^2 bytes, O(m^3) time, any
 *   kernel, m <= 60000.
 * ITERATIVE (3D r^3 only): restarted FGMRES in the null space of the polynomial block,
 *   right-preconditioned by two-level restricted additive Schwarz: kD-tree leaves of
 *   leaf_size/2..leaf_size centres, each grown to local_size centres (more, up to
 *   local_max, where centres within overlap x the coarse fill distance are left) and solved
 *   by the projected Cholesky of its own r^3 system, after a coarse solve on coarse_size
 *   farthest-point centres (grown as sqrt(m) above 2e4 centres). Matvecs are direct sums
 *   with compensated accumulation (the preconditioned vectors cancel too much for plain
 *   sums; rbf_sum_acc.c), the weights are accumulated in double-double. Memory about
 *   4 m (mean subdomain size) bytes (local_float 0: 8) plus the coarse factor (8 coarse^2)
 *   and the Krylov basis, 16 m restart bytes per component; time O(m local^2) to set up,
 *   O(m^2) per iteration. From 150,000 centres (fast_sum) the Krylov matvecs are fast sums
 *   instead (a barycentric Lagrange treecode for r^3, O(m log m), error at most fast_tol x
 *   sum_j |w_j| phi_ij), wrapped in 1..fast_refine refinement steps on exact (compensated
 *   direct; plain where their error bound is below 10 % of a tolerance of 1e-8 or
 *   looser, and the bound is added before the comparison) residuals, so the residual
 *   reported is still the exact one (or within that bound of it); evaluation of
 *   large n x m uses the treecode where a sampled check shows its error within
 *   fast_eval_tol x max |data| (or within the direct sums' own rounding, if that is
 *   larger), direct sums otherwise (stats: eval_fast, eval_error); a cheaper treecode
 *   than the bound asks for is taken where its error on a pilot (a few of the same target
 *   batches) already passes that check (stats: eval_order, eval_theta).
 * AUTO: a cost model measured on this project's machine kind (rbf_iterative.c) puts the
 *   crossover near 3,500 centres: dense below (while 4 m^2 bytes fit in half the memory),
 *   iterative above; dense for the other kernels.
 * PETSC: the ITERATIVE solver distributed over the MPI ranks of PETSC_COMM_WORLD through
 *   PETSc (only in builds with -DCADMORPH_WITH_PETSC=ON; otherwise create fails with
 *   CM_ERR_UNSUPPORTED): KSPFGMRES on a MatShell whose rows (the r^3 kernel sums) are split
 *   over the ranks, the same Schwarz preconditioner as a PCSHELL (each rank factorises
 *   and applies only its share of the subdomains, the coarse solve on all). Create, solve and
 *   evaluate are then collective: every rank calls them with the same centres and values
 *   (each holds all centres and gets all weights); see cm_parallel_initialize (parallel.h).
 * cm_rbf_evaluate works for both; an iterative fit evaluates with compensated sums too
 * (about 1.5x the time of plain sums with the AVX-512 kernels), so it reproduces the data at the centres to its
 * residual, where plain sums, as the dense path uses, stop at the floor in cm_rbf_stats. */
typedef enum cm_rbf_solver {
    CM_RBF_SOLVER_AUTO = 0,
    CM_RBF_SOLVER_DENSE = 1,
    CM_RBF_SOLVER_ITERATIVE = 2,
    CM_RBF_SOLVER_PETSC = 3
} cm_rbf_solver;

/* Options of cm_rbf_create_opt; cm_rbf_options_init fills the defaults (in brackets).
 * Fields other than solver matter only for the iterative solver. */
typedef struct cm_rbf_options {
    cm_rbf_solver solver; /* [AUTO] */
    double tolerance;     /* [1e-10] stop when max_i |f_i - s(c_i)| <= tolerance * max |f|
                           * (max over all components), or at the attainable floor if that
                           * is higher (see stats) */
    int max_iterations;   /* [300] Krylov iterations per component, over all restarts */
    int restart;          /* [40] FGMRES restart length (at most 63); a cycle also ends when
                           * its residual estimate has fallen 1e6-fold (rbf_iterative.c) */
    int leaf_size;        /* [256] kD-tree leaf size: leaves hold leaf_size/2..leaf_size
                           * centres and are the disjoint cores of the subdomains */
    int local_size;       /* [700] centres per overlapping subdomain at least (the leaf
                           * plus the centres nearest to its box; overlap below may add
                           * more): the overlap is the knob that matters on thin walls.
                           * 700 rather than 1,400: below ~3e4 centres the set-up (n^3 per
                           * subdomain) outweighs the products, and halving n costs 0-1
                           * iterations (bore 9.9k / 20.6k, pipe 17.8k, bracket 22.1k: fit
                           * 1.3-2.2x less CPU); from ~6e4 the overlap rule sets n anyway
                           * (RESULTS.md, issue 10, sixth session) */
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
                           * (by count). 2 rather than 3 since subdomains of 700: the same
                           * iterations from 1e4 to 1e5 centres (+1 at 1.2e5 and 1.5e5) at
                           * 1/2-1/3 of the set-up (bracket 103k: fit 18.2 instead of 22
                           * products' CPU; RESULTS.md, issue 10, sixth session); above ~2e5
                           * more is needed (4.5 with local_max 4000 at 2.3e5, fourth
                           * session) */
    int local_max;        /* [2800] cap on a subdomain's centres for overlap > 0 */
    double thin_reach;    /* [0] thinned overlap: beyond its near set (the leaf plus
                           * local_size / overlap / local_max as above, all kept), a subdomain
                           * also takes a thinned sample of the centres up to thin_reach x H
                           * from its leaf's box: one per voxel, the voxel growing with the
                           * distance (thin_cell), at most thin_max centres in all; the
                           * local solve is on that set, only the leaf rows are kept as ever.
                           * A geometric reach at a bounded centre count; 0: off. Measured
                           * (RESULTS.md, "Thinned overlap"): better than no far band and than
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
                           * 6 iterations instead of 7 (RESULTS.md, fourteenth session) */
    int coarse_inner;     /* [0] 0: the coarse problem is solved exactly by its dense
                           * projected Cholesky factor (8 coarse^2 bytes, so coarse_max
                           * stays near 8,000-16,000); N > 0: by at most N iterations of an
                           * inner FGMRES preconditioned by a two-level Schwarz of its own on
                           * the coarse centres (O(coarse) memory, so the coarse space can
                           * grow with m: set coarse_size / coarse_grow / coarse_max) */
    double coarse_inner_tol; /* [1e-2] the inner solve stops when the coarse residual's
                           * 2-norm is reduced by this factor (or after coarse_inner steps) */
    int fast_sum;         /* [-1] fast summation (barycentric Lagrange treecode for r^3,
                           * rbf_treecode.c) for the Krylov matvecs and for evaluation:
                           * 0 never (direct sums), 1 always, -1 auto (matvecs at m >= 150,000;
                           * evaluation when n x m >= 2e9 pairs and the treecode's
                           * a-posteriori error estimate is within fast_eval_tol) */
    double fast_tol;      /* [1e-12] treecode accuracy in the Krylov loop, relative to
                           * sum_j |w_j| phi_ij (its error bound; measured on random weights).
                           * RBF weights cancel (sum |w| phi is 1e4..1e7 x the result), so the
                           * error relative to the result is that much larger: the solver
                           * corrects it by refinement on exact residuals (fast_refine) */
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
} cm_rbf_options;

CM_API void cm_rbf_options_init(cm_rbf_options *opt);

/* Figures of the last create and solve (cm_rbf_stats). */
typedef struct cm_rbf_stats {
    cm_rbf_solver solver;  /* the one used: DENSE, ITERATIVE or PETSC */
    size_t centres;        /* after merging duplicates */
    int subdomains;        /* iterative: Schwarz subdomains; 0 for dense */
    int coarse_size;       /* iterative: coarse centres */
    double setup_seconds;  /* create: factorisation or preconditioner set-up */
    double solve_seconds;  /* last solve */
    size_t memory_bytes;   /* factor or preconditioner + Krylov storage of the last solve */
    int iterations;        /* last solve: Krylov iterations (largest over components);
                            * dense: refinement steps */
    int matvecs;           /* last solve: kernel-sum passes over the m x m matrix of every
                            * kind (one per iteration, two at a restart plus one for the
                            * floor estimate, all running components together; PETSC: the
                            * components one after the other, each counted; fast_sum: the
                            * treecode's products plus two exact ones per refinement step;
                            * relax: also the S(z) estimates); the split by kind and so the
                            * cost is in matvecs_compensated/plain/fast below */
    double residual;       /* last solve: max_i |f_i - s(c_i)| / max |f| over all components
                            * (exactness at the centres, by direct summation after the solve;
                            * iterative: with compensated sums) */
    double floor;          /* iterative: eps max_i sum_j |w_j| phi(|c_i - c_j|) / max |f|, the
                            * rounding error of plain direct sums of these weights, so about
                            * how exactly cm_rbf_evaluate reproduces the data at the centres
                            * (for either solver: the weights are the same; on the bracket
                            * and on two bodies far apart it is 1e-9 .. 1e-8) */
    int floor_limited;     /* 1 if the solve stagnated above the tolerance but within 10x
                            * the floor: the attainable accuracy, not a failure */
    int fast_sum;          /* iterative: 1 if the last solve's Krylov matvecs were fast sums */
    int refinements;       /* last solve with fast sums: outer steps (each one Krylov solve
                            * with fast matvecs, then one exact residual) */
    int fast_direct;       /* last solve with fast sums: 1 if the fast steps stalled above
                            * the tolerance and above the floor, and the solve was done again
                            * with direct matvecs (one more step in refinements) */
    double fast_residual;  /* last solve with fast sums and fast_refine > 0: residual after
                            * the first Krylov solve, by exact sums (what the treecode alone
                            * reached). With fast_refine = 0, residual above is the
                            * treecode's own (of its operator), and this bound is the guide: */
    double fast_bound;     /* last solve with fast sums: fast_tol x max_i sum_j |w_j| phi_ij /
                            * max |data|, the treecode's error bound on a product with these
                            * weights relative to the data */
    int eval_fast;         /* last cm_rbf_evaluate: 1 if it used the fast sum */
    double eval_error;     /* last cm_rbf_evaluate that tried the fast sum: its estimated
                            * max error / max |data| (sampled against compensated direct
                            * sums, x4). The fast sum is taken if this is within
                            * fast_eval_tol or within the direct sums' own rounding (about
                            * 4 eps sum_j |w_j| phi_ij / max |data|: weights that cancel
                            * 1e8-fold leave 1e-8 there, for any summation in doubles) */
    int eval_order;        /* ... and the treecode's order and opening angle it took (the */
    double eval_theta;     /* cheapest whose error on a pilot passed the same test) */
    int matvecs_compensated; /* last iterative solve: matvecs split by kind (they add up to */
    int matvecs_plain;       /* matvecs): compensated direct sums (~1.45x a plain one), plain */
    int matvecs_fast;        /* direct sums, treecode sums (a loose one: ~0.1-0.3x) */
} cm_rbf_stats;

CM_API void cm_rbf_get_stats(const cm_rbf *rbf, cm_rbf_stats *stats);

/* Fits the system for m centres (centres: m x dim row-major; dim 3 for the triharmonic and
 * biharmonic kernels, 2 for thin plate) and keeps its factorisation. Centres closer than
 * 1e-12 x the bounding-box diagonal are merged (their values must then agree, see solve).
 * Errors: CM_ERR_NUMERIC if the centres leave the polynomial block singular (all coplanar
 * in 3D, collinear in 2D) or the factorisation fails (the message has the pivot).
 * Uses the AUTO solver (see cm_rbf_solver). */
CM_API cm_status cm_rbf_create(cm_context *ctx, cm_rbf_kernel kernel, int dim, size_t m,
                        const double *centres, cm_rbf **rbf);
/* cm_rbf_create with options (NULL: the defaults). With the iterative solver, create builds
 * the preconditioner (the costly step, reused by every solve on these centres); a solve
 * that stops above the tolerance because it stagnates returns CM_WARNING (weights kept,
 * the message and stats have the residual); one that stops at the attainable floor
 * returns CM_OK with stats.floor_limited = 1. CM_ERR_UNSUPPORTED for ITERATIVE with a
 * kernel other than r^3. */
CM_API cm_status cm_rbf_create_opt(cm_context *ctx, cm_rbf_kernel kernel, int dim, size_t m,
                            const double *centres, const cm_rbf_options *opt, cm_rbf **rbf);
CM_API void cm_rbf_destroy(cm_rbf **rbf);

/* Solves for values at the m centres given to create (values: m x ncomp row-major) and keeps
 * the weights in rbf, replacing earlier ones. Merged duplicate centres whose values differ
 * by more than 1e-8 of the largest value are an error naming both indices (smaller
 * differences are round-off, e.g. of projections that put two nodes on one point). */
CM_API cm_status cm_rbf_solve(cm_context *ctx, cm_rbf *rbf, int ncomp, const double *values);

/* Evaluates the current interpolant at n points (points: n x dim) into out (n x ncomp).
 * OpenMP-parallel over points; no n x m matrix is formed. Same for both solvers. */
CM_API cm_status cm_rbf_evaluate(cm_context *ctx, const cm_rbf *rbf, size_t n, const double *points,
                          double *out);

/* Centres after merging duplicates. */
CM_API size_t cm_rbf_centre_count(const cm_rbf *rbf);

#ifdef __cplusplus
}
#endif
#endif
