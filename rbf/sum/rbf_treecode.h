/* Fast summation of r^3 kernel sums: a barycentric Lagrange treecode (rbf_treecode.c).
 * Not a public header. */
#ifndef CADMORPH_RBF_TREECODE_H
#define CADMORPH_RBF_TREECODE_H

#include "rbf_internal.h"

#include <stddef.h>

typedef struct cm_rbf_tree cm_rbf_tree;

/* Parameters for a requested accuracy: order n (n + 1 Chebyshev points per axis and
 * cluster) and opening angle theta such that, measured on random weights, the error of
 * every sum is at most tol x sum_j |w_j| phi_ij (rbf_treecode.c has the table and the bound).
 * tol is clamped to [CM_RBF_TREE_TOL_MIN, 1e-3]. */
void cm_rbf_tree_params(double tol, int *order, double *theta);
#define CM_RBF_TREE_TOL_MIN 1e-14

/* Source tree over the m centres c (3 x m SoA, stride m; kept by pointer, must outlive the
 * tree) for order (2..14) and theta (0.1..0.9). Also orders the centres themselves as target
 * batches, for cm_rbf_tree_sum_self. NULL on allocation failure. */
cm_rbf_tree *cm_rbf_tree_create(size_t m, const double *c, int order, double theta);
void cm_rbf_tree_destroy(cm_rbf_tree **t);
size_t cm_rbf_tree_bytes(const cm_rbf_tree *t);

/* The code of the products against proxies and centres: AUTO (the default: the
 * hand-written AVX-512 block of the direct sums where the CPU has it, else the compiled
 * AVX2 or baseline loops), or a named one, which must be supported (cm_rbf_isa_supported):
 * for tests and benchmarks. AVX512_AUTOVEC is the compiled loop built for AVX-512. */
void cm_rbf_tree_set_isa(cm_rbf_tree *t, cm_rbf_isa isa);

/* Rounding of the sums (default 0: plain accumulation, an error of about eps x sum |w|
 * phi besides the approximation). 1: the products against proxies and centres accumulate
 * by TwoSum (the compensated block of the direct sums); 2: also the proxy weights in
 * double-double. Only where the AVX-512 block runs (the isa above); elsewhere plain. For
 * evaluations whose weights cancel far more than the approximation error leaves room for
 * (RESULTS.md, RBF solvers, says what it buys). */
void cm_rbf_tree_set_compensated(cm_rbf_tree *t, int level);

/* out[i * ldo + q] ~ sum_j phi(|p_i - c_j|) w[q * m + j] for q < nc (any nc >= 1: the
 * proxy interpolation and every entry of the products shared by all columns, each column the
 * same bits whatever columns ride along), i < n; p: 3 x n
 * SoA with stride ldp. 0 on success, -1 on allocation failure (out untouched). */
int cm_rbf_tree_sum(const cm_rbf_tree *t, const double *w, int nc, size_t n, const double *p,
                    size_t ldp, double *out, size_t ldo, int threads);
/* The targets of cm_rbf_tree_sum in their batches (a kD tree of the points, leaves of a
 * few hundred), kept for several sums over the same points: p (3 x n SoA, stride ldp) is
 * kept by pointer and must outlive it. NULL on allocation failure. */
typedef struct cm_rbf_tree_targets cm_rbf_tree_targets;
cm_rbf_tree_targets *cm_rbf_tree_targets_create(size_t n, const double *p, size_t ldp);
void cm_rbf_tree_targets_destroy(cm_rbf_tree_targets **tg);
/* A pilot: every *stride-th batch (stride chosen for at most `batches` of them) and, in idx,
 * up to `per` target indices spread over each (capacity batches x per); returns their count.
 * The sums of cm_rbf_tree_sum_targets over those batches are what the whole sum gives
 * there: the same batches open the same clusters. */
size_t cm_rbf_tree_targets_pilot(const cm_rbf_tree_targets *tg, size_t batches, size_t per,
                                 size_t *idx, size_t *stride);
/* cm_rbf_tree_sum over the targets of every stride-th batch (1: all); out is written at
 * those targets only. */
int cm_rbf_tree_sum_targets(const cm_rbf_tree *t, const cm_rbf_tree_targets *tg,
                            size_t stride, const double *w, int nc, double *out, size_t ldo,
                            int threads);
/* The same in chunks of batches with tick (NULL: one pass; rbf_internal.h), whose work is
 * counted in whole sums (1 for this one); -2 when the tick said stop (out partly written). */
int cm_rbf_tree_sum_targets_tick(const cm_rbf_tree *t, const cm_rbf_tree_targets *tg,
                                 size_t stride, const double *w, int nc, double *out,
                                 size_t ldo, int threads, cm_rbf_tick *tick);
/* The same with the targets = the centres of the tree (their batches are cached). */
int cm_rbf_tree_sum_self(const cm_rbf_tree *t, const double *w, int nc, double *out,
                         size_t ldo, int threads);

/* A posteriori check of a fast sum: at `samples` of the targets (the indices idx, or, for
 * idx NULL, spread over p: i = k n / samples), the largest |out - exact| with exact by
 * compensated direct summation, and (max_abs_sum not NULL) the largest sum_j |w_j| phi_ij
 * there (the scale the error bound is relative to), both over the nc components. */
void cm_rbf_tree_check(const cm_rbf_tree *t, const double *w, int nc, size_t n,
                       const double *p, size_t ldp, const double *out, size_t ldo,
                       size_t samples, const size_t *idx, double *max_err,
                       double *max_abs_sum, int threads);

#endif
