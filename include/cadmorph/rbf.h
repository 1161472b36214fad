/* cadmorph RBF core: scattered-data interpolation with polyharmonic kernels plus a linear
 * polynomial [SMB12 §3]; the 2D variant for thin plates [SMB12 §4].
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
 * ITERATIVE (3D r^3 only): restarted FGMRES [Saad93] in the null space of the polynomial
 *   block, right-preconditioned by two-level restricted additive Schwarz [TW05] (kD-tree
 *   leaves grown into overlapping subdomains, each solved by the projected Cholesky of its
 *   own system, after a coarse solve on farthest-point centres). Matvecs are direct sums
 *   with compensated accumulation, or from 150,000 centres (fast_sum) a barycentric Lagrange
 *   treecode for r^3 [WK19], O(m log m), inside refinement steps on exact residuals, so the
 *   residual reported is the exact one. Memory O(m) times the subdomain size, time
 *   O(m^2) per iteration with direct sums. Evaluation of a large n x m takes the treecode
 *   where a sampled check shows its error within 1e-9 x max |data| (stats: eval_fast).
 * AUTO: a cost model from BLAS and kernel-sum rates timed once per process puts the
 *   crossover near 3,500 centres for one solve: dense below (while 4 m^2 bytes fit in half
 *   the memory), iterative above; dense for the other kernels. The model counts the solves
 *   the caller expects on the fit (options solves): the dense factorisation, paid once,
 *   wins to more centres when many solves share it.
 * PETSC: the ITERATIVE solver distributed over the MPI ranks of PETSC_COMM_WORLD through
 *   PETSc (only in builds with -DCADMORPH_WITH_PETSC=ON; otherwise create fails with
 *   CM_ERR_UNSUPPORTED): the kernel-sum rows and the Schwarz subdomains are split over the
 *   ranks. Create, solve and evaluate are then collective: every rank calls them with the
 *   same centres and values (each holds all centres and gets all weights); see
 *   cm_parallel_initialize (parallel.h).
 * cm_rbf_evaluate works for all; an iterative fit evaluates with compensated sums too (about
 * 1.5x the time of plain sums), so it reproduces the data at the centres to its residual,
 * where plain sums, as the dense path uses, stop at the floor in cm_rbf_stats; with plain
 * sums where their rounding is within a tenth of its tolerance (a loose one, such as 1e-6:
 * stats eval_plain). */
typedef enum cm_rbf_solver {
    CM_RBF_SOLVER_AUTO = 0,
    CM_RBF_SOLVER_DENSE = 1,
    CM_RBF_SOLVER_ITERATIVE = 2,
    CM_RBF_SOLVER_PETSC = 3
} cm_rbf_solver;

/* Options of cm_rbf_create_opt; cm_rbf_options_init fills the defaults (in brackets).
 * Fields other than solver matter only for the iterative solvers. */
typedef struct cm_rbf_options {
    cm_rbf_solver solver; /* [AUTO] */
    double tolerance;     /* [1e-10] stop when max_i |f_i - s(c_i)| <= tolerance * max |f|
                           * (max over all components), or at the attainable floor if that
                           * is higher (see stats). The iterative solvers hold each component
                           * to its own max |f_c| (at least 1e-3 max |f|), so that a
                           * component's result does not depend on the others solved with
                           * it */
    int max_iterations;   /* [300] Krylov iterations per component, over all restarts */
    int restart;          /* [40] FGMRES restart length (at most 63) */
    int fast_sum;         /* [-1] fast summation (the r^3 treecode) for the Krylov matvecs
                           * and for evaluation: 0 never (direct sums), 1 always, -1 auto
                           * (matvecs from 150,000 centres, evaluation from 2e9 point-centre
                           * pairs where its checked error is small enough) */
    int warm_start;       /* [1] iterative solvers: the fit keeps its solutions (the last
                           * 64 components, fewer if they would take more than an eighth of
                           * the memory budget) and every cm_rbf_solve starts each component
                           * from the combination of them that fits its data best (least
                           * squares), where that leaves a residual below |data| (else from
                           * zero). Along a family of targets (a study, an optimiser's
                           * steps) this saves most of the iterations; any component count.
                           * 0: always from zero, nothing kept (stats: warm_columns) */
    int warm_groups;      /* [1] iterative solvers with warm_start: a cm_rbf_solve of several
                           * fields (ncomp a multiple of dim, each field's dim components side
                           * by side) solves them in this many groups of whole fields, in
                           * order, each group starting from the solutions of those before it
                           * as successive solves would, and keeps them all for one
                           * evaluation (whose kernel sums cost less per column the more
                           * columns they carry). <= 1: all at once */
    int solves;           /* [1] AUTO only: how many right-hand sides the caller expects to
                           * solve on this fit over its life, one cm_rbf_solve of k sets of
                           * components (k displacement fields side by side) counting k. The
                           * dense factorisation is paid once and then each solve is cheap;
                           * the iterative set-up is cheap and each solve costs Krylov
                           * iterations (fewer when warm): more solves move the crossover up
                           * (an absolute study counts its variants). <= 1: one solve */
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
    size_t memory_bytes;   /* factor or preconditioner + Krylov storage of the last solve +
                            * the solutions kept for warm starts */
    int iterations;        /* last solve: Krylov iterations (largest over components);
                            * dense: refinement steps */
    int matvecs;           /* last solve: kernel-sum passes over the m x m matrix of every
                            * kind (one per iteration and product kind in use, none to two
                            * at a restart, plus one for the floor estimate unless the
                            * solve met a tolerance below 1e-8, all running
                            * components together; PETSC: the
                            * components one after the other, each counted; fast sums: the
                            * treecode's products plus two exact ones per refinement step);
                            * the split by kind is in matvecs_compensated/plain/fast below */
    double residual;       /* last solve: max_i |f_i - s(c_i)| / max |f| over all components
                            * (exactness at the centres, by direct summation after the solve;
                            * iterative: with compensated sums) */
    double floor;          /* iterative: eps max_i sum_j |w_j| phi(|c_i - c_j|) / max |f|, the
                            * rounding error of plain direct sums of these weights, so about
                            * how exactly cm_rbf_evaluate reproduces the data at the centres
                            * (for either solver: the weights are the same); the max over
                            * 1,024 of the centres if the solve met a tolerance below 1e-8 */
    int floor_limited;     /* 1 if the solve stagnated above the tolerance but within 10x
                            * the floor: the attainable accuracy, not a failure */
    int fast_sum;          /* iterative: 1 if the last solve's Krylov matvecs were fast sums */
    int refinements;       /* last solve with fast sums: outer steps (each one Krylov solve
                            * with fast matvecs, then one exact residual) */
    int fast_direct;       /* last solve with fast sums: 1 if the fast steps stalled above
                            * the tolerance and above the floor, and the solve was done again
                            * with direct matvecs (one more step in refinements) */
    double fast_residual;  /* last solve with fast sums: residual after the first Krylov
                            * solve, by exact sums (what the treecode alone reached) */
    double fast_bound;     /* last solve with fast sums: the treecode's error bound on a
                            * product with these weights, relative to the data */
    int eval_fast;         /* last cm_rbf_evaluate: 1 if it used the fast sum */
    int eval_plain;        /* last cm_rbf_evaluate of an iterative fit: 1 if by plain direct
                            * sums (the tolerance allowed them), 0 compensated or fast */
    int eval_combined;     /* ... its components whose values were combined from those of the
                            * components the solve started from zero (they started from
                            * earlier solutions: warm_start), with what that leaves summed
                            * plainly or within the tolerance; the others were summed */
    double eval_error;     /* last cm_rbf_evaluate that tried the fast sum: its estimated
                            * max error / max |data| (sampled against compensated direct
                            * sums, x4). The fast sum is taken if this is within 1e-9 or
                            * within the direct sums' own rounding (about 4 eps sum_j |w_j|
                            * phi_ij / max |data|: weights that cancel 1e8-fold leave 1e-8
                            * there, for any summation in doubles) */
    int eval_order;        /* ... and the treecode's order and opening angle it took (the */
    double eval_theta;     /* cheapest whose error on a pilot passed the same test) */
    int matvecs_compensated; /* last iterative solve: matvecs split by kind (they add up to */
    int matvecs_plain;       /* matvecs): compensated direct sums (~1.45x a plain one), plain */
    int matvecs_fast;        /* direct sums, treecode sums (a loose one: ~0.1-0.3x) */
    int column_groups;     /* last iterative solve: groups its components were solved in (1:
                            * all at once; more when their Krylov storage, see cm_rbf_solve,
                            * exceeded half the machine's memory) */
    int warm_columns;      /* last iterative solve: components that started from earlier
                            * solutions (options warm_start) */
    double warm_residual;  /* ... the largest |f_c - A w0| / |f_c| they started from */
    int warm_basis;        /* ... and the independent earlier solutions they were combined
                            * from */
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
 * the weights in rbf, replacing earlier ones. The iterative solvers solve all ncomp
 * components at once (one kernel pass per iteration for all, each converging on its own),
 * keeping about (2 restart + 9) x 8 bytes per centre and component (with fast sums 4 x 8
 * more): callers that choose how many components to hand over at once can size batches by
 * that; past half the machine's memory they are solved in groups. Merged duplicate centres
 * whose values differ by more than 1e-8 of the largest value are an error naming both
 * indices (smaller differences are round-off, e.g. of projections that put two nodes on one
 * point). */
CM_API cm_status cm_rbf_solve(cm_context *ctx, cm_rbf *rbf, int ncomp, const double *values);

/* Evaluates the current interpolant at n points (points: n x dim) into out (n x ncomp).
 * OpenMP-parallel over points; no n x m matrix is formed. Same for both solvers. */
CM_API cm_status cm_rbf_evaluate(cm_context *ctx, const cm_rbf *rbf, size_t n, const double *points,
                          double *out);

/* The reverse product of "solve at the centres, then evaluate at n points", for adjoint
 * gradients (docs/DESIGN.md, "Gradients"). J is the linear map from values d at the m
 * centres given to create (m x ncomp) to what cm_rbf_evaluate gives at points (n x dim)
 * after cm_rbf_solve(d); this computes out = J^T v (out: m x ncomp, v: n x ncomp, both
 * row-major), so that <v, J d> = <out, d> for every d. One solve of the same system with
 * the factorisation or preconditioner of create, the right-hand side [E^T v; P^T v] (E: the
 * kernel values from the centres to the points) summed as evaluate sums (an iterative fit:
 * compensated sums, or the treecode where its checked error is within the tolerance).
 * Exact as cm_rbf_solve is: to rounding (dense), to the tolerance (iterative, PETSc), but
 * never looser than 1e-10: a residual moves these weights by itself times their growth, where
 * it moves an evaluation by about itself.
 * Merged duplicate centres: all of a merged centre's share goes to the first of its input
 * centres (the one whose value the solve takes), 0 to the others.
 * Keeps the weights of the last cm_rbf_solve (evaluate still uses them; none are needed
 * here); the solve figures of cm_rbf_stats become this solve's. PETSC: collective, as
 * solve. A solve that stagnates returns CM_WARNING with out written, as cm_rbf_solve. */
CM_API cm_status cm_rbf_evaluate_transpose(cm_context *ctx, cm_rbf *rbf, size_t n,
                                           const double *points, int ncomp, const double *v,
                                           double *out);

/* Centres after merging duplicates. */
CM_API size_t cm_rbf_centre_count(const cm_rbf *rbf);

#ifdef __cplusplus
}
#endif
#endif
