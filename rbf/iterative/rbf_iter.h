/* The iterative solver's state inside cm_rbf (r->iter), shared by its files: the set-up
 * (rbf_iterative.c), the FGMRES solve (rbf_fgmres.c) and the evaluation (rbf_evaluate.c).
 * Not a public header. */
#ifndef CADMORPH_RBF_ITER_H
#define CADMORPH_RBF_ITER_H

#include "rbf_internal.h"
#include "sum/rbf_treecode.h"

/* Earlier solutions of the fit, the starts of its next solves (options warm_start;
 * rbf_history.c). Fischer's projection [Fis98]: n pairs (w_j, b_j) with b_j = Pi A w_j
 * orthonormal (Pi: onto the null space of the polynomial block), so a column f starts from
 * w0 = sum_j (b_j . Pi f) w_j, the combination of earlier solutions whose product is nearest
 * Pi f in the 2-norm. Why more than the last solution: along a family of targets (a study's
 * G(t), an optimiser's steps) the data of a new target lie nearly in the span of the earlier
 * ones: on 20 bore variants (20,642 centres) a column's relative residual from the last 5
 * variants' 15 columns was 4e-7 (median; 1e-4 at most), from the same column of a variant 5
 * steps back, scaled, 2e-2 (RESULTS.md, Study). */
typedef struct cm_rbf_history {
    size_t m, cap, n; /* centres; the most pairs kept; pairs held */
    size_t next;      /* when full, the slot of the oldest pair (the next to give way) */
    double *w, *b;    /* cap x m each */
    double *scratch;  /* 2 m */
} cm_rbf_history;

/* A solution whose projected product keeps less than this fraction of its norm after the
 * orthogonalisation is not kept: b_j = Pi A w_j holds only to the rounding of the product
 * and of the combination (about eps sum |w| phi, 1e-13..1e-10 of |b| on real sets), and the
 * normalisation divides that by what is left, so a nearly dependent pair would start the
 * next solves from a w whose product is not its b (still safe: every start's residual is
 * checked by an exact product, but then no better). */
#define CM_RBF_HISTORY_DROP 1e-8

/* NULL out of memory (or for m or cap 0). */
cm_rbf_history *cm_rbf_history_create(size_t m, size_t cap);
void cm_rbf_history_destroy(cm_rbf_history **h);
/* w0 (m) = the start of the column whose projected data are pf (m); pf is overwritten (by
 * what the pairs leave of it); returns the pairs used (0: w0 = 0). */
size_t cm_rbf_history_start(const cm_rbf_history *h, double *pf, double *w0);
/* Adds the solution w (m) whose product, projected, is pb = Pi A w: orthonormalised against
 * the pairs kept (the oldest gives way when full); 1 if kept, 0 if its product lies within
 * CM_RBF_HISTORY_DROP of their span (or is zero). */
int cm_rbf_history_add(cm_rbf_history *h, const double *w, const double *pb);
size_t cm_rbf_history_bytes(const cm_rbf_history *h);
/* The order in which to solve nf fields of d columns each (warm groups: options
 * warm_groups): order[0..nf) a permutation of 0..nf-1 whose first picks fields are chosen one
 * by one, each the field whose data the history h (NULL: none) and the fields before it fit
 * worst, relative to its columns' scale (nf x d, 0: a column not counted); pf (nf x d
 * columns of m, field by field) holds the fields' projected data and is overwritten. Why:
 * each warm group starts from the history's combination, so its start is as near as its data
 * lie to the span of the groups before it; groups in list order extrapolate along a family,
 * these interpolate
 * (20 bore variants, 20,642 centres, groups of 5 at 1e-10: the warm groups' starts, relative
 * to their data, 2e-9..1.6e-6 in list order, 1e-10..1.5e-8 so; RESULTS.md, Study). */
void cm_rbf_history_order(const cm_rbf_history *h, size_t m, size_t nf, size_t d, size_t picks,
                          double *pf, const double *scale, size_t *order);

/* Plain direct sums err by at most this x S(z) = max_i sum_j |z_j| phi_ij (rbf_fgmres.c,
 * relaxed products); where a result need only be exact to a tolerance they may take this
 * share of it (the solve's exact residuals, rbf_fgmres.c and rbf_fgmres_solve.c; the
 * evaluation, rbf_evaluate.c). */
#define CM_RBF_PLAIN_ERR 1e-13
/* Relative rounding of one entry phi_ij = r2 sqrt(r2) (the differences, r2's three terms,
 * the root and the product), so compensated sums of the rounded entries err by up to about
 * this x eps sum_j |w_j| phi_ij against the true kernel (rbf_evaluate.c) */
#define CM_RBF_PHI_ROUND 4.0
#define CM_RBF_PLAIN_RES_SHARE 0.1
/* ... tried only from this relative tolerance: on real sets S(w) is 1e4..1e9 x max |f|, so
 * below it the product on |w| that bounds them would be spent for nothing */
#define CM_RBF_PLAIN_RES_TOL 1e-8
/* The rule all three go by: the bound on the error of plain sums of weights whose
 * max_i sum_j |w_j| phi_ij is smax, relative to scale (a column's data), if it is within
 * CM_RBF_PLAIN_RES_SHARE of tol; else -1 (compensated sums are needed). */
static inline double cm_rbf_plain_bound(double smax, double scale, double tol)
{
    const double b = scale > 0.0 ? CM_RBF_PLAIN_ERR * smax / scale : 0.0;
    return b <= CM_RBF_PLAIN_RES_SHARE * tol ? b : -1.0;
}

/* What the evaluation needs to know of a solve's weights, by column: the data scale its
 * tolerances are relative to, and how far plain direct sums of the weights can be trusted.
 * A solve writes them into cm_rbf_iter.next; cm_rbf_solve commits them to .scales with the
 * weights (cm_rbf_iterative_commit), so a solve that fails or that is not the fit's (the
 * transposed one) leaves the evaluation as it was. */
typedef struct cm_rbf_scales {
    double fmax;   /* max |data| over all columns: the scale of fast_eval_tol */
    size_t n;      /* columns below; 0 if unknown (a PETSc solve) */
    double *fnorm; /* column c: the scale of its tolerance (max |data_c|, or the share
                    * column_scale of fmax if that is larger) */
    double *smax;  /* column c: max_i sum_j |w_j| phi_ij at the centres (or a bound on it),
                    * the scale of the rounding of plain sums (rbf_evaluate.c); -1 if the
                    * solve did not sum it (below CM_RBF_PLAIN_RES_TOL: compensated sums) */
    double *smin;  /* column c: a bound from below on that sum, -1 if none (the next solve's
                    * starts near these weights judge by it whether plain sums can serve) */
    double *start; /* column c: the iterations its solve took from a warm start, -1 if it
                    * started from zero (the evaluation through the span of others,
                    * rbf_evaluate_span.c) */
} cm_rbf_scales;

struct cm_rbf_iter {
    cm_rbf_schwarz *pc;
    double *q1; /* m x k col-major, orthonormal basis of the polynomials at the centres */
    cm_rbf_tree *tree; /* treecode on the centres, for the order below (NULL: none yet) */
    int tree_order;
    double tree_theta;
    cm_rbf_scales scales; /* of the fit's weights (committed by cm_rbf_solve) */
    cm_rbf_scales next;   /* of the last solve's, until committed */
    int eval_fast;     /* the last evaluation's choice and estimate (evaluation gets a
                        * const cm_rbf, the iterative state is where it can leave them) */
    int eval_plain;    /* the last evaluation by plain direct sums */
    double eval_error;
    int eval_order;    /* the row it took */
    double eval_theta;
    int transpose_fast; /* the last transposed evaluation took the treecode (for tests) */
    cm_rbf_tree *rtree[3]; /* loose treecodes for relaxed products (relax_tree_tol) */
    int *col_iters;    /* the last solve's Krylov iterations per column (col_n of them) */
    size_t col_n;
    cm_rbf_history *hist; /* NULL until a solve with warm_start records its solutions */
    int eval_combined;    /* the last evaluation's columns combined from the cold ones' */
};

/* fast_sum = -1 (auto): evaluation by the treecode from this many point-centre pairs
 * (rbf_evaluate_tree.c, rbf_evaluate.c) */
#define CM_RBF_FAST_EVAL_PAIRS 2e9
/* samples for the a-posteriori error estimate of a fast evaluation, and the factor on the
 * largest sampled error (the sampled max was within it of the true max on the real sets).
 * The treecode's errors are spiky below its finest orders: over 32,768 of the two-body
 * interior points at order 10, every 256-point subset found at least 1/6.4 of their
 * largest error, every 1,024-point one 1/2.2 (RESULTS.md, RBF solvers); 1,024
 * compensated sums cost ~1 % of a 10^6-point evaluation */
#define CM_RBF_FAST_SAMPLES 1024
#define CM_RBF_FAST_SAFETY 4.0

/* The passes of the kernel sums over nc columns (CM_RBF_SUM_MAX_NC at a time) */
static inline size_t cm_rbf_sum_passes(size_t nc)
{
    return (nc + CM_RBF_SUM_MAX_NC - 1) / CM_RBF_SUM_MAX_NC;
}
/* (the diameter of the box around the centres and the n points p, 3 x n SoA)^3: no phi_ij
 * between them exceeds it (rbf_iterative.c) */
double cm_rbf_diam3(const cm_rbf *r, size_t n, const double *p);
/* hi + lo = sum_j c_j (x_j + xlo_j) over n columns of m (x, xlo: n x m; xlo NULL: none), in
 * double-double: each term c_j x_j by TwoProduct, their sum by TwoSum, the low parts' terms
 * added to the remainder; hi is the sum rounded to double. Off the exact combination by a
 * few eps^2 sum_j |c_j x_j| per entry (rbf_iterative.c). For sums whose terms are much
 * larger than the result: a Krylov step (rbf_fgmres.c), a start combined from earlier
 * weights (rbf_exact_start.c). */
void cm_rbf_combine_dd(size_t m, int n, const double *x, const double *xlo, const double *c,
                       double *hi, double *lo);
/* The direct sums of the nc columns w (m each) at the n points p into out (n x nc), plain or
 * compensated, in passes of CM_RBF_SUM_MAX_NC; tick as the kernel sums'. Nonzero: stopped
 * (rbf_evaluate_tree.c). */
int cm_rbf_iterative_sum_direct(const cm_rbf *r, const double *w, size_t nc, size_t n,
                                const double *p, int plain, double *out, int threads,
                                cm_rbf_tick *tick);

/* How an evaluation sums the kernel: plain direct sums (the tolerance allows them), compensated
 * ones, or the treecode (rbf_evaluate.c) */
enum { CM_RBF_SUMS_PLAIN, CM_RBF_SUMS_COMPENSATED, CM_RBF_SUMS_FAST };

/* The sums of cm_rbf_iterative_evaluate by kind (CM_RBF_SUMS_*) into out (n x ncomp), a
 * column whose solve started warm as its least-squares combination of a basis of other
 * columns, plus what the combination leaves by the same sums or not at all, where that is
 * within the sums' bound on the column (rbf_evaluate_span.c); s: the columns' sum_j |w_j|
 * phi_ij at sampled points (cm_rbf_abs_sums). 0 done, 1 stopped (tick), -1 not taken (no
 * column to combine or none to combine from, no column gains, out of memory). */
int cm_rbf_iterative_evaluate_span(const cm_rbf *r, size_t n, const double *p, const double *s,
                                   int kind, double *out, int threads, cm_rbf_tick *tick);
/* 1 if an evaluation at n points tries the treecode (fast_sum, and n x m large) */
int cm_rbf_iterative_takes_fast(const cm_rbf *r, size_t n);
/* The error the treecode's result must be shown within, for weights whose sampled sum_j |w_j|
 * phi_ij is at most smax: fast_eval_tol x the data scale, or the direct sums' own rounding
 * if larger; 0 if the treecode is not to be tried */
double cm_rbf_iterative_fast_accept(const cm_rbf *r, double smax);
/* The treecode sums of the nc columns w (m each) at the n points p into out (n x nc), its row
 * chosen for that error after a pilot and the result checked at sampled points (rbf_evaluate.c):
 * 1 if accepted, 0 if direct sums must do it (or tick, if not NULL, said stop: then
 * tick->status < 0). Sets the fit's eval_fast, eval_error, eval_order, eval_theta. */
int cm_rbf_iterative_sum_fast(const cm_rbf *r, const double *w, size_t nc, double smax,
                              size_t n, const double *p, double *out, int threads,
                              cm_rbf_tick *tick);

/* The treecode on the centres of r for (order, theta), made on first use and kept in
 * r->iter (studies solve and evaluate again on the same centres); NULL out of memory. */
cm_rbf_tree *cm_rbf_iterative_tree(const cm_rbf *r, int order, double theta);
/* s[c] = max over ns of the n points p (SoA, spread over them; all of them if ns >= n) of
 * sum_j a_cj phi(|p - c_j|), for the nc columns of a (nc x m, non-negative: |w|); -1 out of
 * memory. */
int cm_rbf_abs_sums(const cm_rbf *r, const double *a, int nc, size_t n, const double *p,
                    size_t ns, double *s, int threads);

#endif
