/* Internal state of cm_rbf and the kernel-sum primitives shared by fit, solve and evaluation
 * ([SMB12 §3] for 3D, [SMB12 §4] for the 2D thin-plate warp). Not a public header. */
#ifndef CADMORPH_RBF_INTERNAL_H
#define CADMORPH_RBF_INTERNAL_H

#include "cadmorph/rbf.h"
#include "rbf_tuning.h"
#include "cm_platform.h" /* BLAS threads, large buffers (cm_platform) */

#include <stddef.h>

/* Below this many point-centre pairs a loop runs on one thread: forking costs more. */
#define CM_RBF_PARALLEL_MIN_PAIRS 200000.0

typedef struct cm_rbf_iter cm_rbf_iter;
typedef struct cm_rbf_petsc cm_rbf_petsc;

struct cm_rbf {
    cm_rbf_kernel kernel;
    int dim;          /* 2 or 3 */
    int k;            /* polynomial terms, dim + 1 */
    size_t m_in;      /* centres given to create */
    size_t m;         /* centres after merging duplicates */
    double shift[3];  /* unit-box map: s = (x - shift) * scale */
    double scale;
    double *c;        /* dim x m, SoA, unit-box coordinates of the merged centres */
    size_t *rep;      /* m_in: merged index of each input centre */
    size_t *first;    /* m: first input index that maps to each merged centre */
    double *qr;       /* m x k col-major: dgeqrf of P (Householder vectors below, R above) */
    double *tau;      /* k */
    double sign;      /* +1 (r^3, r^2 log r) or -1 (r): chol holds sign * Q2' A Q2 */
    double *chol;     /* (m-k)(m-k+1)/2, RFP ('N', 'L'): Cholesky factor of sign * Q2' A Q2 */
    int ncomp;        /* components of the current weights, 0 before the first solve */
    double *w;        /* ncomp x m, SoA: kernel weights */
    double *q;        /* ncomp x k: polynomial coefficients in unit-box coordinates */
    cm_rbf_options opt;
    cm_rbf_tuning tun;  /* the internal knobs (rbf_tuning.h) */
    cm_rbf_stats stats;
    cm_rbf_iter *iter; /* iterative solver state, NULL for dense (then chol is set) */
    cm_rbf_petsc *petsc; /* PETSC solver (rbf_petsc.c): set with iter, NULL otherwise */
    int warm_ok;      /* set by cm_rbf_solve around its solve: it may start from the fit's
                       * history of solutions and joins it (not the transposed solve: its
                       * data, a gradient, lie far from the displacements the history spans
                       * and would only take their places) */
    int pc_part, pc_parts; /* Schwarz set-up split over ranks (rbf_petsc.c): this part of
                            * pc_parts builds only its subdomains; 0, 0: all */
};

/* Threads for a leaf loop: the context's count, or all that OpenMP offers for 0. */
int cm_rbf_threads(const cm_context *ctx);

/* Progress of a long loop that runs in chunks (evaluations, assembly), so that
 * cm_context_interrupt stops it between two chunks: cm_rbf_tick_add after each chunk
 * reports (cm_progress) at most every CM_RBF_TICK_SECONDS, which keeps callbacks rare on
 * large sums and absent on small ones (work of one chunk: no report at all). Chunks are
 * whole blocks of the parallel loops, cut outside their parallel regions, so the sums are
 * the same bits as in one pass. */
typedef struct cm_rbf_tick {
    cm_context *ctx;
    const char *stage;
    double done, total; /* units of work (point-centre pairs, batches) */
    double last;        /* cm_wtime of the start or of the last report */
    int reported;       /* a report was made (the last one then says done = total) */
    cm_status status;   /* CM_ERR_INTERRUPTED once a report returned it */
    double chunk_pairs; /* pairs in a chunk of a kernel sum (CM_RBF_TICK_PAIRS) */
    int tree_chunks;    /* chunks of a treecode sum (CM_RBF_TICK_TREE_CHUNKS); tests set
                           both lower to cut small sums into many chunks */
} cm_rbf_tick;
#define CM_RBF_TICK_SECONDS 0.05
/* point-centre pairs of one chunk of a kernel sum: ~0.02-0.05 s of one core */
#define CM_RBF_TICK_PAIRS 3e7
/* chunks of batches of a treecode sum (each batch costs differently: a fraction of the sum) */
#define CM_RBF_TICK_TREE_CHUNKS 64
void cm_rbf_tick_init(cm_rbf_tick *t, cm_context *ctx, const char *stage, double total);
/* Starts over with another total (another pass over the work), keeping the rest. */
void cm_rbf_tick_restart(cm_rbf_tick *t, double total);
/* Adds work done; reports when due (not when done reaches total). Nonzero: stop (t->status
 * is CM_ERR_INTERRUPTED, with its message in the context). A NULL t never stops. */
int cm_rbf_tick_add(cm_rbf_tick *t, double work);
/* After the loop: reports done = total if anything was reported (so that a progress line
 * ends at 100 %); returns t->status or that report's. */
cm_status cm_rbf_tick_finish(cm_rbf_tick *t);
/* Items (of per_item pairs each) in one chunk of a loop of `items` on `threads`: all of them
 * without a tick, else about CM_RBF_TICK_PAIRS worth but at least 8 per thread. */
long cm_rbf_tick_chunk(const cm_rbf_tick *tick, double per_item, long items, int threads);

/* The most columns (weight vectors) one kernel-sum pass shares its entries phi_ij with:
 * every sum of rbf/sum (plain, compensated, self product, treecode) takes any nc >= 1 and
 * runs more than this in passes of this many. Each column's sum is the same bits whether
 * it runs alone or with others (the columns ride along on the same entries, each in its
 * own order of j), so callers may batch right-hand sides freely. Bounds the work space of
 * a pass (the self product keeps about 2 (threads + 1) nc m doubles). */
#define CM_RBF_SUM_MAX_NC 64

/* cm_rbf_options.tolerance's default, and the loosest the reverse product solves to
 * (rbf_transpose.c) */
#define CM_RBF_DEFAULT_TOL 1e-10

/* out[i * ldo + c] = sum_j phi(|p_i - c_j|) w[c * m + j] for c < nc (any nc >= 1), i < n.
 * p: dim x n SoA with stride ldp (p + d * ldp is coordinate d), centres as in rbf (SoA,
 * stride m). The sum over j runs in the same order for every i whatever the thread count,
 * except in the r^3 self product on AVX-512 (p = c, n = m >= CM_RBF_SELF_MIN_M), which
 * sums each row in parts (rbf_sum_self_avx512.c): there the thread count changes the last
 * bits. */
void cm_rbf_kernel_sum(cm_rbf_kernel kernel, int dim, size_t m, const double *c,
                       const double *w, int nc, size_t n, const double *p, size_t ldp,
                       double *out, size_t ldo, int threads);

/* cm_rbf_kernel_sum of r's kernel and centres for any number of components (w: ncomp x m
 * SoA), all in one pass (passes of CM_RBF_SUM_MAX_NC); out: n x ncomp. */
void cm_rbf_kernel_sum_all(const cm_rbf *r, const double *w, int ncomp, size_t n,
                           const double *p, size_t ldp, double *out, int threads);
/* The same in chunks of points with tick (NULL: as cm_rbf_kernel_sum_all); nonzero when the
 * tick said stop (out then partly written). */
int cm_rbf_kernel_sum_all_tick(const cm_rbf *r, const double *w, int ncomp, size_t n,
                               const double *p, size_t ldp, double *out, int threads,
                               cm_rbf_tick *tick);
/* cm_rbf_kernel_sum in chunks of points with tick (NULL: one pass), for any sources c (m of
 * them, dim x m SoA with stride m): the transposed evaluation sums with the points as
 * sources and the centres as targets. Nonzero when the tick said stop. */
int cm_rbf_kernel_sum_tick(cm_rbf_kernel kernel, int dim, size_t m, const double *c,
                           const double *w, int nc, size_t n, const double *p, size_t ldp,
                           double *out, size_t ldo, int threads, cm_rbf_tick *tick);
/* "triharmonic", "biharmonic", "thin-plate" (for messages) */
const char *cm_rbf_kernel_name(cm_rbf_kernel k);

/* cm_rbf_kernel_sum for r^3 in 3D with compensated (double-double) accumulation: error about
 * eps |result| instead of eps sum_j |w_j phi_ij| (rbf_sum_acc.c says why). */
void cm_rbf_kernel_sum_acc(size_t m, const double *c, const double *w, int nc, size_t n,
                           const double *p, size_t ldp, double *out, size_t ldo, int threads);
/* The same in chunks of points with tick (NULL: one pass); nonzero when the tick said stop. */
int cm_rbf_kernel_sum_acc_tick(size_t m, const double *c, const double *w, int nc, size_t n,
                               const double *p, size_t ldp, double *out, size_t ldo,
                               int threads, cm_rbf_tick *tick);

/* Which code runs the kernel sums. The library passes AUTO (the fastest this CPU runs);
 * tests and benchmarks name one to compare them: GENERIC (baseline x86-64 or any CPU), AVX2
 * (AVX2 + FMA, compiler-vectorised), AVX512_AUTOVEC (the generic loops compiled for AVX-512,
 * the kernel before the hand-written one), AVX512 (rbf_sum_avx512.c for r^3 in 3D; the other
 * kernels as AVX512_AUTOVEC). */
typedef enum cm_rbf_isa {
    CM_RBF_ISA_AUTO = 0,
    CM_RBF_ISA_GENERIC,
    CM_RBF_ISA_AVX2,
    CM_RBF_ISA_AVX512_AUTOVEC,
    CM_RBF_ISA_AVX512
} cm_rbf_isa;

/* 1 if this CPU runs isa (AUTO and GENERIC always do). */
int cm_rbf_isa_supported(cm_rbf_isa isa);
/* The ISA that AUTO resolves to here. */
cm_rbf_isa cm_rbf_isa_auto(void);
/* cm_rbf_kernel_sum and cm_rbf_kernel_sum_acc through the code of isa (which must be
 * supported: cm_rbf_isa_supported). */
void cm_rbf_kernel_sum_isa(cm_rbf_isa isa, cm_rbf_kernel kernel, int dim, size_t m,
                           const double *c, const double *w, int nc, size_t n, const double *p,
                           size_t ldp, double *out, size_t ldo, int threads);
void cm_rbf_kernel_sum_acc_isa(cm_rbf_isa isa, size_t m, const double *c, const double *w,
                               int nc, size_t n, const double *p, size_t ldp, double *out,
                               size_t ldo, int threads);

/* Lower triangle of B = sign * (A - V Z' - Z V') restricted to rows/columns k..m-1, into
 * rfp (n = m - k; n(n+1)/2 doubles, LAPACK rectangular full packed, TRANSR 'N', UPLO 'L').
 * A_ij = phi(|c_i - c_j|); v and z: m x k col-major. */
void cm_rbf_assemble_projected(cm_rbf_kernel kernel, int dim, size_t m, const double *c,
                               int k, const double *v, const double *z, double sign,
                               double *rfp, int threads);
/* The same in chunks of columns with tick (NULL: one pass); nonzero when the tick said stop. */
int cm_rbf_assemble_projected_tick(cm_rbf_kernel kernel, int dim, size_t m, const double *c,
                                   int k, const double *v, const double *z, double sign,
                                   double *rfp, int threads, cm_rbf_tick *tick);

/* Merges centres closer than tol (unit-box coordinates, dim x m_in SoA in c). Fills rep
 * (m_in) and returns the number of merged centres; first (>= that many) gets the first input
 * index of each. -1 on allocation failure. */
long cm_rbf_merge_duplicates(int dim, size_t m_in, const double *c, double tol, size_t *rep,
                             size_t *first);

/* The solve of cm_rbf_solve on data at the merged centres (f: m x nc col-major) by r's
 * solver (dense with its refinement, iterative or PETSc) into w (nc x m SoA) and q (nc x k);
 * fills the solve's figures in r->stats. The weights kept in r are not touched. The dense
 * refinement stops once the relative residual is within refine_tol (cm_rbf_solve: 1e-11),
 * when a step no longer halves it, or after three steps. */
cm_status cm_rbf_solve_merged(cm_context *ctx, cm_rbf *r, size_t nc, const double *f,
                              double refine_tol, double *w, double *q);

/* ---- the dense path (dense/) ---- */

/* Builds sign * Q2' A Q2 (lower triangle, packed: r->chol) for the centres in r (placed, P
 * factored) and factors it on `threads` BLAS threads (rbf_dense.c). */
cm_status cm_rbf_dense_factor(cm_context *ctx, cm_rbf *r, int threads);
/* One pass of the projected solve: f (m x nc col-major) -> w (nc x m SoA, i.e. m x nc
 * col-major) and q (nc x k); aw receives A w (row-major m x nc), g is m x nc scratch. */
cm_status cm_rbf_dense_solve_pass(cm_context *ctx, const cm_rbf *r, size_t nc, const double *f,
                                  double *w, double *q, double *aw, double *g, int threads);

/* Cholesky factorisation of the n x n SPD matrix in a (n(n+1)/2 doubles, RFP with TRANSR 'N',
 * UPLO 'L', as dpftrf), in place, panel by panel of `block` columns (0: the default), with
 * cm_progress(ctx, "rbf factor", done, total) after every panel (done in flops, monotonic).
 * Returns dpftrf's info: 0, or i > 0 if the leading minor of order i is not positive definite,
 * or CM_RBF_CHOLESKY_INTERRUPTED when a progress point returned CM_ERR_INTERRUPTED (its
 * message is in ctx; a holds a partial factor).
 * BLAS threads: as the caller set them (cm_blas_threads); on T > 1 of them and n in
 * [CM_LOOKAHEAD_MIN_N, CM_LOOKAHEAD_MAX_N] outside a parallel region, the look-ahead path
 * below on T OpenMP threads, else the panel-by-panel one (both: the same factor to rounding,
 * the same info and progress). */
int cm_rbf_cholesky_rfp(cm_context *ctx, int n, double *a, int block);
#define CM_RBF_CHOLESKY_INTERRUPTED (-0x7fff)
/* The two paths, for benchmarks and tests. panels (cholesky_blocked.c): one panel after the
 * other, each BLAS call on the caller's BLAS threads. lookahead (cholesky_lookahead.c):
 * `threads` OpenMP threads each calling one-thread BLAS (OpenBLAS's count is set to 1 during
 * the call and restored), the next panel factored while the others update; block 0: its
 * own default. */
int cm_rbf_cholesky_rfp_panels(cm_context *ctx, int n, double *a, int block);
int cm_rbf_cholesky_rfp_lookahead(cm_context *ctx, int n, double *a, int block, int threads);
/* cm_rbf_cholesky_rfp's range for the look-ahead path (benchmarks/RESULTS.md, RBF solvers):
 * its schedule, replayed from per-task CPU times, beats the threaded panels from 5k to 20k;
 * below 4k a factorisation takes < 0.15 s, and on a loaded machine, where each of its barriers
 * can wait a time slice for a preempted thread, it lost to them (3k: 1.28 x their time, 2k:
 * 1.9 x). */
#define CM_LOOKAHEAD_MIN_N 4000
#define CM_LOOKAHEAD_MAX_N 60000
/* The look-ahead path's most update chunks per step. */
#define CM_LOOKAHEAD_MAX_CHUNKS 64
/* For the schedule model of benchmarks/rbf/bench_cholesky.c: while set (NULL in normal use;
 * set it only between factorisations), every task of the look-ahead path reports its step
 * (-1: outside the steps), its kind (0: the look-ahead panel, q > 0: update chunk q - 1) and
 * its CPU seconds by its thread's clock. Called from the OpenMP threads concurrently. */
extern void (*cm_lookahead_trace_hook)(int step, int kind, double cpu_seconds);

/* ---- the timing probes' leaf (sum/rbf_probe.c) ---- */

/* CPU seconds of the calling thread (CLOCK_THREAD_CPUTIME_ID; wall time if it fails): what
 * the once-per-process probes time, as a loaded machine delays them without biasing them. */
double cm_rbf_thread_seconds(void);
/* The probes' problem: m centres (3 x m SoA) with 3 weight vectors (3 x m), n points (3 x n)
 * spread over the unit cube by a fixed sequence. */
void cm_rbf_probe_data(size_t m, double *c, double *w, size_t n, double *p);

/* ---- iterative solver (iterative/) ---- */

/* 1 if AUTO picks the dense solver for m centres of this kernel (cost model) when the fit
 * will serve `solves` solves (cm_rbf_options.solves; <= 1: one). */
int cm_rbf_auto_dense(cm_rbf_kernel kernel, size_t m, int solves);
/* dgemm flops per second and r^3 kernel-sum pairs per second (plain, compensated; 3 weight
 * vectors) of one thread, timed once per process (rbf_auto_probe.c); 0 if the probe could
 * not allocate its 3.6 MB. cm_rbf_create calls it with one BLAS thread set. */
void cm_rbf_auto_rates(double *gemm, double *plain, double *acc);
/* The model's seconds (of one thread) for m centres and `solves` solves (<= 1: one), dense
 * and iterative; returns 1 if they come from the measured rates, 0 from the fixed fallback
 * constants. */
int cm_rbf_auto_costs(size_t m, int solves, double *dense, double *iter);

/* Builds r->iter (preconditioner) for the centres in r (placed, P factored). */
cm_status cm_rbf_iterative_setup(cm_context *ctx, cm_rbf *r, int threads);
/* f: nc x m SoA (merged centres) -> w (nc x m SoA), q (nc x k); fills r->stats. */
cm_status cm_rbf_iterative_solve(cm_context *ctx, cm_rbf *r, size_t nc, const double *f,
                                 double *w, double *q, int threads);
void cm_rbf_iterative_destroy(cm_rbf_iter **it);
/* The last iterative solve's Krylov iterations of column c (over all its restarts and
 * refinement steps), -1 if there is no such column (tests). */
int cm_rbf_iterative_column_iterations(const cm_rbf *r, size_t c);
/* out (n x ncomp) = sum_j w_j phi(|p_i - c_j|) by compensated sums; p: 3 x n SoA. tick
 * (NULL: none) reports the sums in chunks; nonzero when it said stop (out partly written). */
int cm_rbf_iterative_evaluate(const cm_rbf *r, size_t n, const double *p, double *out,
                              int threads, cm_rbf_tick *tick);
/* The transposed evaluation of an iterative fit: out (m x nc row-major) = sum_i phi(|c_j -
 * p_i|) v[q * n + i] for the n points p (3 x n SoA) with weights v (nc x n SoA): the
 * treecode over the points where cm_rbf_iterative_evaluate would take it and its sampled
 * error is within the solve's tolerance x max |out| (rbf_evaluate.c says why), else
 * compensated direct sums. tick as there; nonzero when it said stop. */
int cm_rbf_iterative_evaluate_transpose(const cm_rbf *r, size_t n, const double *p, int nc,
                                        const double *v, double *out, int threads,
                                        cm_rbf_tick *tick);
/* 1 if the last transposed evaluation of r took the treecode (tests). */
int cm_rbf_iterative_transpose_was_fast(const cm_rbf *r);
/* Its fast path alone: 1 if out holds the accepted treecode result, 0 if direct sums must do
 * it (or tick said stop), as cm_rbf_iterative_evaluate_fast. */
int cm_rbf_iterative_transpose_fast(const cm_rbf *r, size_t n, const double *p, int nc,
                                    const double *v, double *out, int threads,
                                    cm_rbf_tick *tick);
/* Its fast path alone (the treecode where n x m is large and its error is within
 * fast_eval_tol x the data scale): 1 if out holds the accepted result, 0 if direct sums must
 * do it (or tick, if not NULL, said stop: then tick->status < 0). Deterministic for given
 * weights, so every rank that calls it gets the same out. */
int cm_rbf_iterative_evaluate_fast(const cm_rbf *r, size_t n, const double *p, double *out,
                                   int threads, cm_rbf_tick *tick);
/* The last evaluation's figures (eval_fast, eval_plain, eval_error, eval_order, eval_theta)
 * into stats; nothing for a dense fit. */
void cm_rbf_iterative_stats(const cm_rbf *r, cm_rbf_stats *stats);
/* The scales of a solve's weights that the evaluation goes by (rbf_iter.h, cm_rbf_scales):
 * a solve begins them with the data scale fmax that fast_eval_tol is relative to (the serial
 * solve and the PETSc one alike, so that both evaluate alike) and, for nc > 0, room for its
 * columns' scales, which it then fills (0 out of memory: -1, and none by column; PETSc: nc
 * 0). cm_rbf_solve commits them with the weights it keeps. */
int cm_rbf_iterative_scales_begin(cm_rbf *r, size_t nc, double fmax);
void cm_rbf_iterative_commit(cm_rbf *r);

typedef struct cm_rbf_schwarz cm_rbf_schwarz;

/* The iterative state's Q1 (m x k col-major, orthonormal basis of the polynomials at the
 * centres) and preconditioner, for the PETSc bridge; NULL before cm_rbf_iterative_setup. */
const double *cm_rbf_iterative_q1(const cm_rbf *r);
const cm_rbf_schwarz *cm_rbf_iterative_pc(const cm_rbf *r);

/* Two-level restricted additive Schwarz for the r^3 system on the centres of r. */
cm_status cm_rbf_schwarz_create(cm_context *ctx, const cm_rbf *r, int threads,
                                cm_rbf_schwarz **pc);
void cm_rbf_schwarz_destroy(cm_rbf_schwarz **pc);
/* out = M in for nc vectors (any number), nc x m SoA each: coarse solve, coarse residual, then
 * the restricted local solves. out is not projected onto the null space of P'. */
void cm_rbf_schwarz_apply(const cm_rbf_schwarz *pc, const cm_rbf *r, int nc, const double *in,
                          double *out, int threads);
/* Adds the other parts' local corrections into out (n doubles) in place, as MPI_Allreduce
 * with MPI_SUM: 0, or nonzero on failure. */
typedef int (*cm_rbf_schwarz_sum)(void *arg, double *out, size_t n);
/* cm_rbf_schwarz_apply for a preconditioner built for one part of several (r->pc_parts):
 * the local solves of its own subdomains, then sum() (called by every part, once per
 * application), then the coarse terms; out is then the whole M in on every part, bit for
 * bit the single-part result. sum NULL: as cm_rbf_schwarz_apply. 0, or -1 if sum failed. */
int cm_rbf_schwarz_apply_sum(const cm_rbf_schwarz *pc, const cm_rbf *r, int nc,
                             const double *in, double *out, int threads, cm_rbf_schwarz_sum sum,
                             void *arg);

/* Null-space projected factorisations of local systems (rbf_local_inverse.c), on the n
 * centres idx of the 3 x m SoA cg. projected_factor: in work (n*n + 8n doubles) the factor
 * of Q'AQ's trailing block and the Householder vectors of the polynomials' rank-revealing
 * QR (rank in *rk, tau: 4); returns 0, the failing pivot (> 0) or -1. projected_solve: x (n x
 * nrhs) := Q2 (Q2'AQ2)^{-1} Q2' x with that factor. local_inverse: g (n x n_in) = the leaf
 * rows of the local inverse (the leaf: the first n_in of idx); local_inverse_fast the same
 * at ~0.6x the flops (work: n*n + 24n doubles), -2 if the set has no more overlap centres
 * than polynomial terms (then use local_inverse). */
int cm_rbf_projected_factor(const double *cg, size_t m, const size_t *idx, size_t n,
                            double *work, int *rk, double *tau);
int cm_rbf_projected_solve(const double *work, size_t n, int rk, const double *tau,
                           size_t nrhs, double *x);
/* The same with each column's arithmetic in an order that does not depend on nrhs (a
 * column's result is the same bits alone or with others), its columns over threads; the
 * coarse solve of the Schwarz preconditioner, whose columns are a batch's right-hand sides
 * (rbf_schwarz_rows.c). */
void cm_rbf_projected_solve_cols(const double *work, size_t n, int rk, const double *tau,
                                 size_t nrhs, double *x, int threads);
/* The local solves of the Schwarz preconditioner for one subdomain (rbf_schwarz_rows.c):
 * out[c * ldo + idx[j]] += sum_i G_ji x[c * n + i] for its nin leaf rows j and nc columns c,
 * row j of G being hd doubles at gd + j hd, then hf = n - hd floats at gf + j hf. Each
 * column the same bits whatever nc. */
void cm_rbf_local_rows(const double *gd, const float *gf, size_t hd, size_t hf, size_t nin,
                       const double *x, size_t n, int nc, double *out, size_t ldo,
                       const size_t *idx);
int cm_rbf_local_inverse(const double *cg, size_t m, const size_t *idx, size_t n, size_t n_in,
                         double *work, double *g);
int cm_rbf_local_inverse_fast(const double *cg, size_t m, const size_t *idx, size_t n,
                              size_t n_in, double *work, double *g);
/* q (n x 4 col-major): an orthonormal basis of the linear polynomials on the n centres idx,
 * by the same rank-revealing QR (columns past the rank zero); work: 8n doubles. 0 or -1. */
int cm_rbf_poly_basis(const double *cg, size_t m, const size_t *idx, size_t n, double *work,
                      double *q);

/* The bodies of a centre set as the Schwarz subdomains see them (rbf_bodies.c): leaves
 * joined when one's local set holds a centre of the other. nsub subdomains, each
 * sub_idx[sub_ptr[l] ..] with its n_in[l] leaf centres first (every centre in one leaf). */
typedef struct cm_rbf_bodies cm_rbf_bodies;
cm_status cm_rbf_bodies_create(cm_context *ctx, const double *c, size_t m, int nsub,
                               const size_t *sub_ptr, const size_t *sub_idx, const int *n_in,
                               cm_rbf_bodies **bodies);
void cm_rbf_bodies_destroy(cm_rbf_bodies **bodies);
int cm_rbf_bodies_count(const cm_rbf_bodies *bodies);
size_t cm_rbf_bodies_bytes(const cm_rbf_bodies *bodies);
/* w (nc x m SoA) -= its part in the linear polynomials of each body (the weights keep no
 * linear moment on any body) */
void cm_rbf_bodies_project(const cm_rbf_bodies *bodies, int nc, size_t m, double *w);

/* A centre index with a sort key (the squared distance to a leaf's box). */
typedef struct cm_rbf_keyed {
    double key;
    size_t idx;
} cm_rbf_keyed;
/* The Schwarz preconditioner's subdomains (rbf_schwarz_leaves.c): the centres c (3 x m SoA)
 * split by a kD-tree into leaves of at most leaf_size, each leaf a range of perm and its
 * bounding box. */
typedef struct cm_rbf_leaf {
    size_t lo, hi; /* range of perm */
    double bmin[3], bmax[3];
} cm_rbf_leaf;
typedef struct cm_rbf_leaves {
    const double *c; /* 3 x m SoA */
    size_t m;
    size_t *perm;
    cm_rbf_leaf *leaves;
    int nleaves, cap;
    size_t leaf_size;
} cm_rbf_leaves;
/* Splits perm[lo, hi) into leaves (recursively, at the median of the widest box side);
 * 0, or -1 out of memory. */
int cm_rbf_leaves_split(cm_rbf_leaves *t, size_t lo, size_t hi);
/* Squared distance from the point x to the box [bmin, bmax]. */
double cm_rbf_box_dist2(const double *x, const double *bmin, const double *bmax);
/* The local set of leaf l: its own centres, then up to nloc in all of the centres nearest its
 * box (at least nmin, beyond that those within reach2 of it), into out; returns the count.
 * Scratch: lk (nleaves), cand (m). */
size_t cm_rbf_leaves_grow(const cm_rbf_leaves *t, int l, size_t nloc, size_t nmin,
                          double reach2, cm_rbf_keyed *lk, cm_rbf_keyed *cand, size_t *out);
/* The thinned far band of leaf l's local set, appended to its n near centres in out (the
 * thin_reach option; cm_rbf_thin_pick); returns the new count, 0 out of memory. */
size_t cm_rbf_leaves_thin(const cm_rbf_leaves *t, int l, size_t n, double far2, double fill,
                          double cell, size_t cap, cm_rbf_keyed *cand, size_t *out);
/* Farthest-point sampling of nc of the m centres c into out (d2: m scratch); returns the
 * largest distance from a centre to its nearest pick (the fill distance). */
double cm_rbf_farthest_points(const double *c, size_t m, size_t nc, size_t *out, double *d2,
                              int threads);
/* The thinned far band of a subdomain (rbf_thin.c): of the nc candidates cand (sorted by
 * key ascending, each at distance d >= d0 > 0 from the leaf's box; c: 3 x m SoA), one per
 * voxel of the grid of cell cell x d0 x 2^k in distance band k = floor(log2(d / d0)) (grid
 * origin org), the one nearest to the voxel's centroid; at most cap of them, the nearest
 * first, into out. Returns the count, or -1 out of memory. */
long cm_rbf_thin_pick(const double *c, size_t m, const cm_rbf_keyed *cand, size_t nc,
                      double d0, double cell, const double org[3], size_t cap, size_t *out);
/* Coarse centres for m centres under the tuning (coarse_size, coarse_grow, coarse_max;
 * at most m / 4). */
size_t cm_rbf_coarse_count(const cm_rbf_tuning *tu, size_t m);
/* The coarse problem solved inexactly (rbf_schwarz_coarse.c, options coarse_inner and
 * coarse_inner_tol): an inner FGMRES on the nc coarse centres (c_xyz: 3 x nc SoA; m_fine:
 * the outer centres, for the choice of the coarse-to-fine product) preconditioned by a
 * two-level Schwarz of their own. */
typedef struct cm_rbf_coarse_inner cm_rbf_coarse_inner;
cm_status cm_rbf_coarse_inner_create(cm_context *ctx, const cm_rbf *r, size_t nc,
                                     const double *c_xyz, size_t m_fine, int threads,
                                     cm_rbf_coarse_inner **out);
void cm_rbf_coarse_inner_destroy(cm_rbf_coarse_inner **ci);
/* x (ncomp x nc SoA): the coarse data in, approximate projected weights out; 0 or -1 */
int cm_rbf_coarse_inner_solve(const cm_rbf_coarse_inner *ci, int ncomp, double *x, int threads);
/* out[i * ncomp + q] ~ sum_a phi(|c_i - coarse_a|) w[q * nc + a] by the treecode (c: 3 x m
 * SoA): 0, or 1 if the direct sum is to be used instead */
int cm_rbf_coarse_inner_to_fine(const cm_rbf_coarse_inner *ci, int ncomp, const double *w,
                                size_t m, const double *c, double *out, int threads);
size_t cm_rbf_coarse_inner_bytes(const cm_rbf_coarse_inner *ci);
const cm_rbf_schwarz *cm_rbf_coarse_inner_pc(const cm_rbf_coarse_inner *ci);
/* inner solves so far and their iterations in all */
void cm_rbf_coarse_inner_stats(const cm_rbf_coarse_inner *ci, long *solves, long *iterations);
/* The preconditioner's inner coarse solver, NULL if its coarse problem is factored densely */
const cm_rbf_coarse_inner *cm_rbf_schwarz_inner(const cm_rbf_schwarz *pc);
size_t cm_rbf_schwarz_bytes(const cm_rbf_schwarz *pc);
/* Subdomain l's centre indices (into r->c; its *n_in leaf centres first), *n in all; and
 * the coarse fill distance H (0 without a coarse space). For tests. */
const size_t *cm_rbf_schwarz_subdomain(const cm_rbf_schwarz *pc, int l, size_t *n, size_t *n_in);
double cm_rbf_schwarz_fill(const cm_rbf_schwarz *pc);
int cm_rbf_schwarz_subdomains(const cm_rbf_schwarz *pc);
int cm_rbf_schwarz_coarse(const cm_rbf_schwarz *pc);
const cm_rbf_bodies *cm_rbf_schwarz_bodies(const cm_rbf_schwarz *pc);

/* ---- the distributed solver (rbf_petsc.c; rbf_petsc_none.c without PETSc) ---- */

/* cm_rbf_iterative_setup, then the PETSc objects on PETSC_COMM_WORLD (collective). */
cm_status cm_rbf_petsc_setup(cm_context *ctx, cm_rbf *r, int threads);
/* As cm_rbf_iterative_solve, rows split over the ranks; w and q complete on every rank. */
cm_status cm_rbf_petsc_solve(cm_context *ctx, cm_rbf *r, size_t nc, const double *f, double *w,
                             double *q);
void cm_rbf_petsc_destroy(cm_rbf_petsc **ps);
/* With more than one rank: out (n x ncomp) as cm_rbf_iterative_evaluate: its fast path on
 * every rank if it is taken (the treecode is cheap, and all ranks then hold the serial
 * result for these weights), else each rank summing its block of points directly, gathered
 * to all; returns 1, or 0 if it did nothing (one rank). */
int cm_rbf_petsc_evaluate(const cm_rbf *r, size_t n, const double *p, double *out, int threads);
/* The same for cm_rbf_iterative_evaluate_transpose (out: m x nc, the centres split over the
 * ranks): 1, or 0 if it did nothing (one rank). */
int cm_rbf_petsc_evaluate_transpose(const cm_rbf *r, size_t n, const double *p, int nc,
                                    const double *v, double *out, int threads);

#endif
