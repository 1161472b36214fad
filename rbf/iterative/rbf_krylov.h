/* The state of the iterative solve shared by its two files: the Krylov iteration of many
 * columns at once (rbf_fgmres.c) and the driver around it, with the refinement of the fast
 * solve and the memory groups (rbf_fgmres_solve.c). Not a public header. */
#ifndef CADMORPH_RBF_KRYLOV_H
#define CADMORPH_RBF_KRYLOV_H

#include "rbf_iter.h"

/* The rounding error of one direct sum A w is at most about eps sum_j |w_j phi_ij|; the
 * error of a whole solve, observed, stays within this factor of that estimate. */
#define CM_RBF_FLOOR_SLACK 10.0
/* The kernel sums take at most CM_RBF_SUM_MAX_NC columns per call (rbf_internal.h):
 * cm_krylov_product() is the one place that cuts the active columns into such chunks. */

enum { MV_COMP = 0, MV_PLAIN = 1, MV_FAST = 2 };

/* A sum of positive terms by cm_krylov_matvec_loose (the loosest treecode errs by 1e-6 of
 * it, plain sums by 1e-14) is at least this x its value */
#define CM_RBF_LOOSE_LOW (1.0 - 1e-5)

/* One column's Krylov space and state: every column runs its own FGMRES (its own basis,
 * Hessenberg, rotations, relaxation budget and stopping test), so its iterates are those of
 * a solve of that column alone; the columns share only the passes of the kernel sums and of
 * the preconditioner. */
typedef struct kcol {
    double *v;      /* (R+1) x m */
    double *z;      /* R x m */
    double *h;      /* (R+1) x R col-major */
    double cs[64], sn[64], gv[65];
    double eb[64];  /* bound on the error of each product of the cycle (max-norm) */
    double gv0[64]; /* |GMRES residual| before each step */
    double an[64];  /* |A z_j|_2 of each product of the cycle (before its projection) */
    double qaz[64][4]; /* Q1' A z_j: the part of each product the projection removes */
    double grow;    /* largest |y_i| / |r_{i-1}| of the solve so far */
    int exact;      /* 1: the products stay compensated (a cycle's gap bound exceeded the
                     * budget: its Krylov space needs huge coefficients) */
    /* the solve */
    double fnorm;   /* the column's scale (CM_RBF_COL_SCALE) */
    double cb;      /* bound on the error of the last exact residual (a plain check, and the
                     * step products added since), else 0 */
    double smax;    /* max_i sum_j |w_j| phi_ij of w at the last check (a bound after a step
                     * product), -1 if not summed */
    double smin;    /* ... a bound from below, -1 if none */
    double sbound;  /* a bound on S(w) of the start, from the fit's earlier weights (the
                     * caller's; -1: none): its plain check then sums w alone */
    double slow;    /* ... and one from below (-1: none): above the plain bound, its check
                     * is compensated at once */
    int has_aw;     /* aw holds A w from a check of this solve (exactly, within cb), so the
                     * next check may add the product of the cycle's step (kr->aux) */
    int comp_only;  /* its checks in this solve are compensated (a plain one was not exact
                     * enough) */
    double tol;     /* relative tolerance of this (inner) solve */
    double prev, res, target, est, cycle0, goal, floor;
    int cut;        /* this cycle ends at CM_RBF_CYCLE_GAIN of its start (the tolerance is
                     * further), else at the tolerance */
    double sz, allow, tau; /* relaxed product of the current step */
    int kind, lev;
    int state;      /* 0 running, 1 converged, 2 floor, 3 stagnated, 4 max iterations */
    int jn, iters;
    int warm;       /* in: w holds a start to try */
    int preset;     /* in (with warm): the start's A w is in aw and its low part in wlo,
                     * within cb (cm_rbf_exact_start): no check of the start */
    int took;       /* the start was taken (set by the solve, cleared by the caller) */
    double warm_res; /* |f - A w0| / |f| of a start taken */
    /* the refinement (fast sums) */
    int done, last, total_it, status;
    double rprev, pb, rres;
} kcol;

typedef struct krylov {
    size_t m;
    int R;          /* restart length */
    int g;          /* columns of this group */
    kcol *col;      /* g */
    double *soa, *rowm; /* CM_RBF_SUM_MAX_NC x m: one chunk of a kernel sum */
    double *pin, *aux;  /* g x m: the preconditioner's input and output; scratch; from a
                         * cycle's update to the next check, each column's step dw */
    double *wlo;    /* g x m: low parts of the weights (double-double accumulation) */
    double *awlo;   /* g x m: A wlo; scratch during the steps and the update */
    int *ia, *ib, *ic; /* g: column lists */
    double **pa, **pb, **pc, **pd, **pe, **pf; /* g: vector lists */
    const cm_rbf_tree *tree; /* fast matvecs (treecode) if set, else compensated direct */
    int relax;      /* relaxed products (direct-matvec solves only) */
    int relax_tree; /* the loose treecodes 0..relax_tree-1 may serve them */
    double diam3;   /* diam^3 of the centres: S(z) <= diam3 sum |z| */
    int *mv;        /* products by kind (MV_COMP, MV_PLAIN, MV_FAST) */
    size_t before, all; /* the solve's progress: columns of the groups before this one, all */
    double shown;       /* the progress reported so far (in columns) */
} krylov;

/* v -= Q1 (Q1' v), twice (the second pass removes what round-off left of the first). */
void cm_krylov_project(const double *q1, size_t m, int k, double *v);
double cm_krylov_norm_inf(size_t m, const double *v);
/* (wh, wl) += (dh, dl), m entries: double-double weights plus a double-double step (TwoSum of
 * the high parts, the rest into wl) */
void cm_krylov_add_dd(size_t m, double *wh, double *wl, const double *dh, const double *dl);
/* rv = Pi (f - aw), the projected residual of a column whose product is aw (m each); returns
 * its max-norm. */
double cm_krylov_residual(const cm_rbf *r, size_t m, const double *f, const double *aw,
                          double *rv);
/* out_u = A in_u for n columns: kind MV_FAST by tree (if that fails: fallback, or zeros
 * for fallback < 0), MV_PLAIN or MV_COMP by direct sums. The one place where the columns
 * are cut into the chunks the kernel sums take. Returns the kind used. Counts nothing. */
int cm_krylov_product(const cm_rbf *r, krylov *kr, int kind, const cm_rbf_tree *tree,
                      int fallback, int n, double *const *in, double *const *out, int threads);
/* The fast solve's treecode (compensated sums if it fails), else compensated sums; counted. */
void cm_krylov_matvec(const cm_rbf *r, krylov *kr, int n, double *const *in,
                      double *const *out, int threads);
/* A product whose result need only be good to ~1e-6 of the sums (A |w| for the floor, A wlo
 * of the low parts, both from positive or tiny weights): the fast solve's treecode if it
 * has one, else the loosest relaxed treecode where the solve uses them, else plain sums;
 * counted. */
void cm_krylov_matvec_loose(const cm_rbf *r, krylov *kr, int n, double *const *in,
                            double *const *out, int threads);
/* By a named kind (the loose treecode lev for MV_FAST, plain sums if it cannot be made);
 * counted; returns the kind used. */
int cm_krylov_matvec_kind(const cm_rbf *r, krylov *kr, int kind, int lev, int n,
                          double *const *in, double *const *out, int threads);
/* Solves the ns columns sel[] of f (g x m SoA) into w + kr->wlo (high and low parts), each
 * to its own col[c].tol relative to col[c].fnorm; a column with col[c].warm starts from the
 * w it holds if that leaves a residual below |f_c| (then col[c].took = 1; else from zero).
 * Per column: iters, floor, state. aw = A(w + wlo) from the last true residual. CM_OK, or
 * the status of a progress report that said stop. */
cm_status cm_krylov_solve_group(cm_context *ctx, const cm_rbf *r, krylov *kr, const double *f,
                                int ns, const int *sel, double *w, double *aw, int threads);

/* The first group's solutions with the products its solve ended on, from which the later
 * warm groups start with a residual known without a pass (rbf_exact_start.c). Why: at a
 * tolerance below CM_RBF_PLAIN_RES_TOL a warm start is checked by a compensated product of
 * its column, about 45 % of a warm group of 15 columns on the bore (20.6k centres); a
 * combination of solutions whose products are known within the solve's own bounds (cb) has
 * the combination of those products as its own, within their bounds times its coefficients
 * (on the bore 2e-14..7e-12 of the data, against a tolerance of 1e-10). */
#define CM_RBF_EXACT_MAX 64 /* the most columns kept */
typedef struct cm_rbf_exact_starts {
    size_t m;
    int n;                   /* columns kept (0: none) */
    double *whi, *wlo, *aw;  /* n x m each: the weights' high and low parts, A (whi + wlo) */
    double *err;             /* n: per unit of a coefficient, the bound a column adds to a
                              * start's |A (whi + wlo) - aw|_inf */
    double *qr, *tau;        /* LAPACK's pivoted QR of Pi aw (m x n), its reflectors' factors */
    int rank;                /* the columns it found independent: col[0..rank) */
    int col[CM_RBF_EXACT_MAX];
} cm_rbf_exact_starts;

/* Keeps the n columns whi + wlo (m each: the first group's weights, the group's columns of
 * kr) and their products aw with the bounds the group's solve kept on them; the starts
 * combine those the pivoted QR of the products finds independent. 0, or -1 out of memory or
 * for more than CM_RBF_EXACT_MAX columns (es->n = 0: no exact starts). */
int cm_rbf_exact_starts_make(const cm_rbf *r, const krylov *kr, int n, const double *whi,
                             const double *wlo, const double *aw, cm_rbf_exact_starts *es);
void cm_rbf_exact_starts_free(cm_rbf_exact_starts *es);
size_t cm_rbf_exact_starts_bytes(const cm_rbf_exact_starts *es);
/* The start of a column with data f (m): the combination of the kept columns whose product
 * fits Pi f best, as whi + wlo (m each), its product aw (m); y: m scratch. Returns the bound
 * on |A (whi + wlo) - aw|_inf, or -1 if LAPACK failed. */
double cm_rbf_exact_start(const cm_rbf *r, const cm_rbf_exact_starts *es, const double *f,
                          double *y, double *whi, double *wlo, double *aw);

#endif
