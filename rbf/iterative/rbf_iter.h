/* The iterative solver's state inside cm_rbf (r->iter), shared by its files: the set-up
 * (rbf_iterative.c), the FGMRES solve (rbf_fgmres.c) and the evaluation (rbf_evaluate.c).
 * Not a public header. */
#ifndef CADMORPH_RBF_ITER_H
#define CADMORPH_RBF_ITER_H

#include "rbf_internal.h"
#include "sum/rbf_treecode.h"

struct cm_rbf_iter {
    cm_rbf_schwarz *pc;
    double *q1; /* m x k col-major, orthonormal basis of the polynomials at the centres */
    cm_rbf_tree *tree; /* treecode on the centres, for the order below (NULL: none yet) */
    int tree_order;
    double tree_theta;
    double fmax;       /* max |data| of the last solve: the scale of fast_eval_tol */
    int eval_fast;     /* the last evaluation's choice and estimate (evaluation gets a
                        * const cm_rbf, the iterative state is where it can leave them) */
    double eval_error;
    int eval_order;    /* the row it took */
    double eval_theta;
    int transpose_fast; /* the last transposed evaluation took the treecode (for tests) */
    cm_rbf_tree *rtree[3]; /* loose treecodes for relaxed products (relax_tree_tol) */
    int *col_iters;    /* the last solve's Krylov iterations per column (col_n of them) */
    size_t col_n;
};

/* The treecode on the centres of r for (order, theta), made on first use and kept in
 * r->iter (studies solve and evaluate again on the same centres); NULL out of memory. */
cm_rbf_tree *cm_rbf_iterative_tree(const cm_rbf *r, int order, double theta);

#endif
