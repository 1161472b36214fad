/* Iterative solver for the r^3 + linear RBF system: restarted FGMRES [Saad93] in the null space of
 * the polynomial block, right-preconditioned by two-level restricted Schwarz
 * (rbf_schwarz.c), with compensated direct-summation matvecs (rbf_sum_acc.c) or, for large
 * m, fast ones (the r^3 treecode, rbf_treecode.c) inside an outer refinement on exact
 * residuals (refine_group says why).
 *
 * Why the null space: with Pi = I - Q1 Q1' (Q1 an orthonormal basis of the polynomials at
 * the centres), the weights are the solution of Pi A w = Pi f with Pi w = w, and Pi A Pi is
 * SPD there. Every Krylov vector is kept in range(Pi), so the polynomial coefficients never
 * enter the iteration; they follow at the end from R q = Q1'(f - A w), and Pi(f - A w) is
 * then exactly the residual at the centres, f - A w - P q. Why FGMRES rather than CG: the
 * restricted Schwarz preconditioner is not symmetric (and is stored in float), so CG's
 * short recurrence does not hold; GMRES needs one matvec per iteration like CG, and the
 * iteration counts here are small, so the extra orthogonalisation is cheap. All the
 * columns of the data (a study's variants) run at once, each in its own Krylov space: one
 * kernel-sum pass and one preconditioner application per iteration serve every column still
 * running, and a converged one leaves at once. The Krylov products are relaxed (tuning relax, see
 * CM_RBF_RELAX_BUDGET): compensated while the residual is large, plain or loose treecode
 * sums as it falls; the exact residual at the end of a cycle decides. */
#include "rbf_iter.h"

#include <cblas.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The rounding error of one direct sum A w is at most about eps sum_j |w_j phi_ij|; the
 * error of a whole solve, observed, stays within this factor of that estimate. */
#define CM_RBF_FLOOR_SLACK 10.0

/* fast_sum = -1 (auto): treecode matvecs from this many centres, evaluation from this many
 * point-centre pairs. A fast fit costs about 22 treecode products + 4 exact (compensated)
 * residuals where direct matvecs take 12 compensated products (bracket 59k; RESULTS.md, RBF
 * solvers), so it pays once one compensated product costs more than 22 / (12 - 4) = 2.75
 * treecode products at fast_tol 1e-12. Measured with the treecode on the AVX-512 block
 * (RESULTS.md, RBF solvers; bracket sets, one product, CPU s): 1.9 at 59k, 2.6 at 103k, 3.6 at
 * 201k, 6.6 at 479k; 2.75 falls near 1.15e5. But on real data the refinement costs more than
 * at 59k: bracket 148k (real displacements), fast 46 iterations, 65 products, 253 CPU s;
 * direct 16 iterations, 22 products, 221 CPU s (RESULTS.md, RBF solvers). So it was 2e5. Since
 * the preconditioner keeps the bodies free of linear moments (rbf_bodies.c) the fast solve
 * needs as many iterations as the direct one (Zen 5, fit CPU s fast / direct: bracket 102,890
 * 54.2 / 47.2, bracket 150,137 99.1 / 109.3, two bodies 164,820 108.0 / 118.9; RESULTS.md, RBF
 * solvers): 1.5e5, just under the first real single-body set where it wins. */
#define CM_RBF_FAST_MIN_M 150000
/* an inner (fast-matvec) solve of a refinement step aims for this reduction of its own
 * right-hand side, or the final tolerance if that is nearer: the treecode's operator
 * differs from A by about fast_tol x (sum |w| phi / |A w|), 1e-8..1e-5 on real sets, so
 * going further in one step would only polish the wrong operator */
#define CM_RBF_REFINE_GAIN 1e-7
/* a restart cycle also ends once GMRES's estimate has fallen this far below the cycle's
 * start, so that the true residual is formed again: on real data the estimate and the true
 * residual part in long cycles (bracket 148k, y: after 40 iterations estimate 3e-7, true
 * 3e-6 in the 2-norm; 48 iterations in all), and a fresh start costs the refinement-free
 * two products plus the floor's. With it: 16 iterations there, 13 instead of 16 at 103k,
 * 18 instead of 17 on two bodies 119k, the same below 1e5 (RESULTS.md, RBF solvers) */
#define CM_RBF_CYCLE_GAIN 1e-6
/* Relaxed products (tuning relax). Inexact Krylov (Simoncini & Szyld 2003, van den Eshof &
 * Sleijpen 2004): with E_j = (A~ - A) z_j the error of the j-th product, the true residual
 * differs from the one GMRES sees by E y = sum_j y_j E_j, and |y_j| <= |r_{j-1}| /
 * sigma_min(H). So step j may err by about target x sigma / |r_{j-1}|, growing as the
 * residual falls. The error of a sum is
 * bounded through S(z) = max_i sum_j |z_j| phi_ij <= diam^3 sum_j |z_j| (safe, a few times
 * too large): plain sums err by at most CM_RBF_PLAIN_ERR x S (measured 1.2e-14..1.4e-14 x S
 * with 3 weight vectors on the bracket and the two bodies, RESULTS.md, RBF solvers),
 * the treecode at tol by tol x S (its bound, margin 3-30), compensated ones by nothing
 * that counts (their result's rounding, see where eb is set).
 * Each step may take half of what is left of a budget of CM_RBF_RELAX_BUDGET x the cycle's
 * goal for sum_j |y_j| err_j (so the sum stays within it; |y_j| of the coming step guessed as
 * |r_{j-1}| times the largest |y_i| / |r_{i-1}| so far, the stand-in for 1 / sigma), the inner
 * loop stopping at 0.5 x target. The goal is the target, or CM_RBF_CYCLE_GAIN x the cycle's
 * starting residual if larger: such a cycle ends there, and the exact residual at the next
 * start sees what its products erred, as a refinement step would (two bodies 121k: the
 * first cycle's last two products plain instead of compensated). The gap bound with the
 * final y is logged after each cycle; the exact residual at the cycle's end decides as
 * before (RESULTS.md, RBF solvers: on the real sets plain sums become
 * admissible only after the residual fell by 1e6..1e8, as the weights cancel). */
#define CM_RBF_RELAX_BUDGET 0.5
/* the safe bound diam^3 sum |z| was 3.2-3.8 x S(z) on the bore (22.6k) */
#define CM_RBF_S_SLACK 5.0
#define CM_RBF_PLAIN_ERR 1e-13
/* loose treecode products at 1e-6 from this many centres, at 1e-9 and 1e-11 from the other
 * counts: where each is cheaper than a plain direct product, which since the symmetric self
 * product (rbf_sum_self_avx512.c) is about half the general one. Measured (bench_rbf_treecode
 * on real weights, 2 threads, model-167 Xeon, RESULTS.md, RBF solvers), CPU s of one
 * product at 60.6k / 121k centres: treecode 1e-6 0.61 / 1.56, 1e-9 1.14 / 3.03, 1e-11 1.85 /
 * 3.95; plain general 1.62 / 5.38 there, so the self product (1.7-2.2x that in bench_kernel)
 * ~0.8 / ~2.7. Above CM_RBF_FAST_MIN_M the fast solve takes over. */
#define CM_RBF_RELAX_TREE_M 50000
#define CM_RBF_RELAX_TREE9_M 200000
#define CM_RBF_RELAX_TREE11_M 400000
#define CM_RBF_RELAX_LEVELS 3
static const double relax_tree_tol[CM_RBF_RELAX_LEVELS] = {1e-6, 1e-9, 1e-11};

/* v -= Q1 (Q1' v), twice (the second pass removes what round-off left of the first). */
/* The kernel sums take at most this many columns per call (rbf_internal.h may raise it):
 * product() below is the one place that cuts the active columns into such chunks. */
#ifndef CM_RBF_SUM_MAX_NC
#define CM_RBF_SUM_MAX_NC 4
#endif

enum { MV_COMP = 0, MV_PLAIN = 1, MV_FAST = 2 };

/* v -= Q1 (Q1' v), twice (the second pass removes what round-off left of the first). */
static void project(const double *q1, size_t m, int k, double *v)
{
    for (int pass = 0; pass < 2; ++pass)
        for (int a = 0; a < k; ++a) {
            const double *qa = q1 + (size_t)a * m;
            double s = cblas_ddot((int)m, qa, 1, v, 1);
            cblas_daxpy((int)m, -s, qa, 1, v, 1);
        }
}

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
    double grow;    /* largest |y_i| / |r_{i-1}| of the solve so far */
    int exact;      /* 1: the products stay compensated (a cycle's gap bound exceeded the
                     * budget: its Krylov space needs huge coefficients) */
    /* the solve */
    double fnorm;   /* the column's scale (CM_RBF_COL_SCALE) */
    double tol;     /* relative tolerance of this (inner) solve */
    double prev, res, target, est, cycle0, goal, floor;
    double sz, allow, tau; /* relaxed product of the current step */
    int kind, lev;
    int state;      /* 0 running, 1 converged, 2 floor, 3 stagnated, 4 max iterations */
    int jn, iters;
    int warm;       /* in: w holds a start to try */
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
    double *pin, *aux;  /* g x m: the preconditioner's input and output; scratch */
    double *wlo;    /* g x m: low parts of the weights (double-double accumulation) */
    double *awlo;   /* g x m: A wlo; scratch during the steps */
    int *ia, *ib, *ic; /* g: column lists */
    double **pa, **pb, **pc, **pd, **pe, **pf; /* g: vector lists */
    const cm_rbf_tree *tree; /* fast matvecs (treecode) if set, else compensated direct */
    int relax;      /* relaxed products (direct-matvec solves only) */
    int relax_tree; /* the loose treecodes 0..relax_tree-1 may serve them */
    double diam3;   /* diam^3 of the centres: S(z) <= diam3 sum |z| */
    int *mv;        /* products by kind (MV_COMP, MV_PLAIN, MV_FAST) */
} krylov;

/* out_u = A in_u for n columns: kind MV_FAST by tree (if that fails: fallback, or zeros
 * for fallback < 0), MV_PLAIN or MV_COMP by direct sums. The one place where the columns
 * are cut into the chunks the kernel sums take. Returns the kind used (the fallback's if a
 * chunk fell back). */
static int product(const cm_rbf *r, krylov *kr, int kind, const cm_rbf_tree *tree, int fallback,
                   int n, double *const *in, double *const *out, int threads)
{
    const size_t m = kr->m;
    int used = kind;
    for (int c0 = 0; c0 < n; c0 += CM_RBF_SUM_MAX_NC) {
        const int b = n - c0 < CM_RBF_SUM_MAX_NC ? n - c0 : CM_RBF_SUM_MAX_NC;
        for (int u = 0; u < b; ++u)
            memcpy(kr->soa + (size_t)u * m, in[c0 + u], m * sizeof(double));
        int k = kind;
        if (k == MV_FAST &&
            (!tree || cm_rbf_tree_sum_self(tree, kr->soa, b, kr->rowm, (size_t)b, threads)))
            k = fallback;
        if (k == MV_PLAIN)
            cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, r->c, kr->soa, b, m, r->c, m, kr->rowm,
                              (size_t)b, threads);
        else if (k == MV_COMP)
            cm_rbf_kernel_sum_acc(m, r->c, kr->soa, b, m, r->c, m, kr->rowm, (size_t)b, threads);
        else if (k < 0)
            memset(kr->rowm, 0, (size_t)b * m * sizeof(double));
        if (k != kind) used = k;
        for (int u = 0; u < b; ++u)
            for (size_t i = 0; i < m; ++i) out[c0 + u][i] = kr->rowm[i * (size_t)b + (size_t)u];
    }
    return used;
}

/* out_u = A in_u for the n columns of the list (in: pointers to m-vectors): the fast
 * solve's treecode (compensated sums if it fails), else compensated sums. */
static void matvec(const cm_rbf *r, krylov *kr, int n, double *const *in, double *const *out,
                   int threads)
{
    if (n <= 0) return;
    product(r, kr, kr->tree ? MV_FAST : MV_COMP, kr->tree, MV_COMP, n, in, out, threads);
    ++kr->mv[kr->tree ? MV_FAST : MV_COMP];
}

/* The same by a named kind: compensated or plain direct sums, or the loose treecode lev.
 * The treecode falls back to plain sums if it cannot be made (kept in r->iter: studies solve
 * again on the same centres). Returns the kind used. */
static int matvec_kind(const cm_rbf *r, krylov *kr, int kind, int lev, int n,
                       double *const *in, double *const *out, int threads)
{
    if (n <= 0) return kind;
    cm_rbf_iter *it = r->iter;
    if (kind == MV_FAST && !it->rtree[lev]) {
        int order;
        double theta;
        cm_rbf_tree_params(relax_tree_tol[lev], &order, &theta);
        it->rtree[lev] = cm_rbf_tree_create(kr->m, r->c, order, theta);
    }
    kind = product(r, kr, kind, kind == MV_FAST ? it->rtree[lev] : NULL, MV_PLAIN, n, in, out,
                   threads);
    ++kr->mv[kind];
    return kind;
}

/* out_u = Pi M in_u for n columns: one application of the preconditioner to all of them */
static void precondition(const cm_rbf *r, krylov *kr, int n, double *const *in,
                         double *const *out, int threads)
{
    const size_t m = kr->m;
    for (int c = 0; c < n; ++c) memcpy(kr->pin + (size_t)c * m, in[c], m * sizeof(double));
    cm_rbf_schwarz_apply(r->iter->pc, r, n, kr->pin, kr->aux, threads);
    for (int c = 0; c < n; ++c) {
        memcpy(out[c], kr->aux + (size_t)c * m, m * sizeof(double));
        project(r->iter->q1, m, r->k, out[c]);
    }
}

static double norm_inf(size_t m, const double *v)
{
    double s = 0.0;
    for (size_t i = 0; i < m; ++i) s = fmax(s, fabs(v[i]));
    return s;
}

/* The cheapest product kind whose error bound, relative to S(z), is within tau. */
static int relax_pick(const krylov *kr, double tau, int *lev)
{
    *lev = 0;
    for (int l = 0; l < kr->relax_tree; ++l)
        if (tau >= relax_tree_tol[l]) {
            *lev = l;
            return MV_FAST;
        }
    return tau >= CM_RBF_PLAIN_ERR ? MV_PLAIN : MV_COMP;
}

/* y = R^-1 g of column c over its first n steps (R, g: H and the right-hand side after
 * the rotations): the coefficients of the current FGMRES solution. */
static void ls_solve(const krylov *kr, int c, int n, double *y)
{
    const size_t ld = (size_t)(kr->R + 1);
    const kcol *k = &kr->col[c];
    for (int i = n - 1; i >= 0; --i) {
        double s = k->gv[i];
        for (int l = i + 1; l < n; ++l) s -= k->h[(size_t)l * ld + (size_t)i] * y[l];
        y[i] = s / k->h[(size_t)i * ld + (size_t)i];
    }
}

/* Step j's relaxed products wo_u = A~ zo_u for the na columns act[]. Each column picks the
 * loosest kind its own budget allows, and the columns are grouped by kind: one pass per
 * kind present (at most the five kinds; columns of one study fall alike, so mostly one or
 * two). Why not the most exact kind any column wants, for all: then a column's products,
 * and so its iterates and its result, would depend on its batch-mates; grouped, each column
 * gets the products of its solo solve (bit for bit where the sums are the same bits per
 * column whatever the chunk), at the cost of a pass's fixed part (the distances) per
 * extra kind. */
static void relaxed_products(cm_context *ctx, const cm_rbf *r, krylov *kr, int cycle, int j,
                             int na, const int *act, double *const *zo, double *const *wo,
                             int threads)
{
    const size_t m = kr->m;
    int *sel = kr->ic;
    double **pi = kr->pe, **po = kr->pf;
    for (int u = 0; u < na; ++u) {
        kcol *k = &kr->col[act[u]];
        k->sz = kr->diam3 * cblas_dasum((int)m, zo[u], 1);
        /* what the products so far cost of the budget, with the coefficients y of the
         * current solution, and how far |y_i| exceeded |r_{i-1}| (the guess for the coming
         * y_j): near 1 when the preconditioned operator is well conditioned, far above on
         * the bracket's y component at 103k */
        double rj = fabs(k->gv[j]), used = 0.0, y[64];
        k->gv0[j] = rj;
        ls_solve(kr, act[u], j, y);
        for (int i = 0; i < j; ++i) {
            used += fabs(y[i]) * k->eb[i];
            if (k->gv0[i] > 0.0) k->grow = fmax(k->grow, fabs(y[i]) / k->gv0[i]);
        }
        double left = fmax(0.0, CM_RBF_RELAX_BUDGET * k->goal - used);
        if (k->exact) left = 0.0;
        k->allow = 0.5 * left / (k->grow * (rj > 0.0 ? rj : 1.0));
        k->tau = k->sz > 0.0 ? k->allow / k->sz : INFINITY;
        k->kind = relax_pick(kr, k->tau, &k->lev);
    }
    /* the safe bound on S is a few times too large: where a cheaper kind is within that, S
     * itself, by the loosest treecode (positive weights, so exact to 1e-6 of the result),
     * cheaper than the products it saves */
    int nb = 0;
    for (int u = 0; u < na; ++u) {
        kcol *k = &kr->col[act[u]];
        int lev2;
        if (kr->relax_tree && !(k->kind == MV_FAST && k->lev == 0) &&
            relax_pick(kr, k->tau * CM_RBF_S_SLACK, &lev2) != k->kind) {
            pi[nb] = kr->aux + (size_t)nb * m;
            po[nb] = kr->awlo + (size_t)nb * m;
            for (size_t i = 0; i < m; ++i) pi[nb][i] = fabs(zo[u][i]);
            sel[nb++] = u;
        }
    }
    matvec_kind(r, kr, MV_FAST, 0, nb, pi, po, threads);
    for (int v = 0; v < nb; ++v) {
        kcol *k = &kr->col[act[sel[v]]];
        k->sz = fmin(k->sz, 1.01 * norm_inf(m, po[v]));
        k->tau = k->sz > 0.0 ? k->allow / k->sz : INFINITY;
        k->kind = relax_pick(kr, k->tau, &k->lev);
    }
    static const int kinds[5][2] = {
        {MV_COMP, 0}, {MV_PLAIN, 0}, {MV_FAST, 0}, {MV_FAST, 1}, {MV_FAST, 2}};
    for (int q = 0; q < 5; ++q) {
        int n = 0;
        for (int u = 0; u < na; ++u) {
            const kcol *k = &kr->col[act[u]];
            if (k->kind == kinds[q][0] && (k->kind != MV_FAST || k->lev == kinds[q][1])) {
                pi[n] = zo[u];
                po[n] = wo[u];
                sel[n++] = u;
            }
        }
        if (n == 0) continue;
        const int lev = kinds[q][1];
        const int kind = matvec_kind(r, kr, kinds[q][0], lev, n, pi, po, threads);
        cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: cycle %d, step %d: %s products for %d "
               "columns", cycle, j + 1,
               kind == MV_COMP ? "compensated" : kind == MV_PLAIN ? "plain" : "treecode", n);
        /* compensated products are charged nothing (rel 0): against the operator the exact
         * residual uses (the same rounded entries) they err only by their result's
         * rounding, which the stored basis vectors of any floating-point GMRES have too.
         * Charged as eps |A z_j| x |y_j| (the y_j huge where the preconditioned directions
         * cancel) it filled the budget in the first cycle (brackets 60k / 103k, two bodies:
         * 1e-10..2e-8 against 5e-11) and forbade relaxing from then on, with nothing of it
         * in the exact residuals */
        const double rel = kind == MV_FAST ? relax_tree_tol[lev]
                           : kind == MV_PLAIN ? CM_RBF_PLAIN_ERR : 0.0;
        for (int v = 0; v < n; ++v) {
            kcol *k = &kr->col[act[sel[v]]];
            k->eb[j] = rel * k->sz;
        }
    }
}

/* Solves the ns columns sel[] of f (g x m SoA) into w + kr->wlo (high and low parts), each
 * to its own col[c].tol relative to col[c].fnorm; a column with col[c].warm starts from the
 * w it holds if that leaves a residual below |f_c| (else from zero, and warm is cleared).
 * Per column: iters, floor, state. aw = A(w + wlo) from the last true residual. */
static cm_status solve_group(cm_context *ctx, const cm_rbf *r, krylov *kr, const double *f,
                             int ns, const int *sel, double *w, double *aw, int threads)
{
    const size_t m = kr->m;
    const int R = kr->R;
    const cm_rbf_options *o = &r->opt;
    int *list = kr->ia, *act = kr->ib, *fl = kr->ic;
    double **in = kr->pa, **out = kr->pb, **p3 = kr->pc, **p4 = kr->pd;
    for (int s = 0; s < ns; ++s) {
        const int c = sel[s];
        kcol *k = &kr->col[c];
        k->prev = INFINITY;
        k->iters = 0;
        k->floor = 0.0;
        k->state = 0;
        k->est = 0.0;
        k->grow = 1.0;
        k->exact = 0;
        k->jn = 0;
        if (!k->warm) memset(w + (size_t)c * m, 0, m * sizeof(double));
        memset(aw + (size_t)c * m, 0, m * sizeof(double));
        memset(kr->wlo + (size_t)c * m, 0, m * sizeof(double));
    }
    for (int cycle = 0;; ++cycle) {
        int n = 0;
        for (int s = 0; s < ns; ++s)
            if (kr->col[sel[s]].state == 0) list[n++] = sel[s];
        if (n == 0) break;
        /* A w: of every running column after a cycle, of a warm one at the start */
        int nw = 0;
        for (int u = 0; u < n; ++u) {
            const int c = list[u];
            if (cycle == 0 && !kr->col[c].warm) continue;
            in[nw] = w + (size_t)c * m;
            out[nw] = aw + (size_t)c * m;
            p3[nw] = kr->wlo + (size_t)c * m;
            p4[nw] = kr->awlo + (size_t)c * m;
            ++nw;
        }
        if (nw > 0) {
            /* A w exactly (this is the check); A wlo (after a cycle: a start has none), eps
             * |w| small, by plain sums or the loosest treecode (its error, 1e-6 S(wlo), is
             * 1e-22 S(w)) */
            if (kr->tree) matvec(r, kr, nw, in, out, threads);
            else matvec_kind(r, kr, MV_COMP, 0, nw, in, out, threads);
            if (cycle > 0) {
                if (kr->tree) matvec(r, kr, nw, p3, p4, threads);
                else matvec_kind(r, kr, kr->relax_tree ? MV_FAST : MV_PLAIN, 0, nw, p3, p4,
                                 threads);
                for (int u = 0; u < nw; ++u)
                    for (size_t i = 0; i < m; ++i) out[u][i] += p4[u][i];
            }
        }
        int nfl = 0;
        for (int u = 0; u < n; ++u) {
            const int c = list[u];
            kcol *k = &kr->col[c];
            double *rv = k->v, *ax = aw + (size_t)c * m; /* the residual is built in V_0 */
            const double *fc = f + (size_t)c * m;
            for (size_t i = 0; i < m; ++i) rv[i] = fc[i] - ax[i];
            project(r->iter->q1, m, r->k, rv);
            double rn = norm_inf(m, rv);
            if (cycle == 0 && k->warm) {
                /* the start is kept if its residual is below the zero start's |f| */
                const double fn = norm_inf(m, fc);
                if (rn < fn) k->warm_res = rn / fn, k->took = 1;
                else {
                    k->warm = 0;
                    memset(w + (size_t)c * m, 0, m * sizeof(double));
                    memset(ax, 0, m * sizeof(double));
                    memcpy(rv, fc, m * sizeof(double));
                    project(r->iter->q1, m, r->k, rv);
                    rn = norm_inf(m, rv);
                }
            }
            k->res = k->fnorm > 0.0 ? rn / k->fnorm : 0.0;
            if (k->res <= k->tol) k->state = 1;
            else if (cycle > 0) fl[nfl++] = c;
        }
        /* the attainable floor: the rounding error of the sums A w themselves */
        if (nfl > 0) {
            for (int u = 0; u < nfl; ++u) {
                const int c = fl[u];
                p3[u] = kr->col[c].z; /* Z is free between cycles */
                p4[u] = kr->col[c].z + m;
                for (size_t i = 0; i < m; ++i) p3[u][i] = fabs(w[(size_t)c * m + i]);
            }
            /* positive weights: plain sums are exact to ~1e-14 of the result, the loosest
             * treecode to 1e-6, enough for an estimate */
            if (kr->tree) matvec(r, kr, nfl, p3, p4, threads);
            else matvec_kind(r, kr, kr->relax_tree ? MV_FAST : MV_PLAIN, 0, nfl, p3, p4,
                             threads);
            for (int u = 0; u < nfl; ++u) {
                kcol *k = &kr->col[fl[u]];
                k->floor = DBL_EPSILON * norm_inf(m, p4[u]) / k->fnorm;
                /* a cycle that does not halve the residual has stagnated: at the floor if
                 * within CM_RBF_FLOOR_SLACK of it, else a failure to converge */
                if (k->res > 0.5 * k->prev)
                    k->state = k->res <= CM_RBF_FLOOR_SLACK * k->floor ? 2 : 3;
                else if (k->iters >= o->max_iterations)
                    k->state = k->res <= CM_RBF_FLOOR_SLACK * k->floor ? 2 : 4;
            }
        }
        int na = 0;
        for (int u = 0; u < n; ++u) {
            const int c = list[u];
            kcol *k = &kr->col[c];
            cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: column %d, cycle %d: %d iterations, "
                   "residual %.3g (floor %.3g), 2-norm %.3g (GMRES estimate %.3g)", c, cycle,
                   k->iters, k->res, k->floor, cblas_dnrm2((int)m, k->v, 1) / k->fnorm,
                   k->est / k->fnorm);
            k->prev = k->res;
            k->jn = 0;
            if (k->state != 0) continue;
            /* the inner loop stops on the 2-norm that GMRES minimises: aim for the max-norm
             * target through the ratio of the two norms at the restart */
            double *v0 = k->v;
            double r2 = cblas_dnrm2((int)m, v0, 1), rinf = norm_inf(m, v0);
            k->target = 0.5 * k->tol * k->fnorm * (r2 / rinf);
            /* the cycle ends at CM_RBF_CYCLE_GAIN of its start if that comes first, and the
             * exact residual of the next start corrects what its products erred (in the
             * 2-norm, max-norm end / start was 1.2e-6 on two bodies 121k) */
            k->goal = fmax(k->tol, CM_RBF_CYCLE_GAIN * k->res) * k->fnorm;
            cblas_dscal((int)m, 1.0 / r2, v0, 1);
            memset(k->gv, 0, sizeof k->gv);
            k->gv[0] = r2;
            k->cycle0 = r2;
            act[na++] = c;
        }
        for (int j = 0; j < R && na > 0; ++j) {
            for (int u = 0; u < na; ++u) {
                kcol *k = &kr->col[act[u]];
                in[u] = k->v + (size_t)j * m;
                out[u] = k->z + (size_t)j * m;
                p3[u] = k->v + (size_t)(j + 1) * m;
            }
            precondition(r, kr, na, in, out, threads);
            /* between the preconditioner and the product too: each is 0.1-0.5 s from 10^5
             * centres (the caller may stop; w is its scratch) */
            {
                int most = 0;
                for (int c = 0; c < kr->g; ++c) most = kr->col[c].iters > most ? kr->col[c].iters : most;
                cm_status ps = cm_progress(ctx, "rbf solve", (double)most, (double)o->max_iterations);
                if (ps < 0) return ps;
            }
            if (!kr->relax) matvec(r, kr, na, out, p3, threads);
            else relaxed_products(ctx, r, kr, cycle, j, na, act, out, p3, threads);
            int keep = 0;
            for (int u = 0; u < na; ++u) {
                const int c = act[u];
                kcol *k = &kr->col[c];
                double *wv = p3[u], *h = k->h + (size_t)j * (size_t)(R + 1);
                project(r->iter->q1, m, r->k, wv);
                for (int pass = 0; pass < 2; ++pass) /* classical Gram-Schmidt, twice */
                    for (int i = 0; i <= j; ++i) {
                        const double *vv = k->v + (size_t)i * m;
                        double s = cblas_ddot((int)m, vv, 1, wv, 1);
                        h[i] = (pass ? h[i] : 0.0) + s;
                        cblas_daxpy((int)m, -s, vv, 1, wv, 1);
                    }
                double hn = cblas_dnrm2((int)m, wv, 1);
                h[j + 1] = hn;
                if (hn > 0.0) cblas_dscal((int)m, 1.0 / hn, wv, 1);
                for (int i = 0; i < j; ++i) { /* earlier rotations */
                    double t = k->cs[i] * h[i] + k->sn[i] * h[i + 1];
                    h[i + 1] = -k->sn[i] * h[i] + k->cs[i] * h[i + 1];
                    h[i] = t;
                }
                double d = hypot(h[j], h[j + 1]);
                double cs = d > 0.0 ? h[j] / d : 1.0, sn = d > 0.0 ? h[j + 1] / d : 0.0;
                k->cs[j] = cs;
                k->sn[j] = sn;
                h[j] = d;
                h[j + 1] = 0.0;
                k->gv[j + 1] = -sn * k->gv[j];
                k->gv[j] *= cs;
                k->jn = j + 1;
                k->est = fabs(k->gv[j + 1]);
                ++k->iters;
                /* a converged column leaves the active set at once */
                int done = fabs(k->gv[j + 1]) <= k->target || hn == 0.0 ||
                           fabs(k->gv[j + 1]) <= CM_RBF_CYCLE_GAIN * k->cycle0 ||
                           k->iters >= o->max_iterations;
                if (!done) act[keep++] = c;
            }
            na = keep;
            /* one preconditioned product per column and iteration done */
            int most = 0;
            for (int c = 0; c < kr->g; ++c) most = kr->col[c].iters > most ? kr->col[c].iters : most;
            cm_status ps = cm_progress(ctx, "rbf solve", (double)most, (double)o->max_iterations);
            if (ps < 0) return ps;
        }
        /* w += Z y, H y = g (upper triangular after the rotations) */
        for (int u = 0; u < n; ++u) {
            const int c = list[u];
            kcol *k = &kr->col[c];
            if (k->jn == 0) continue;
            double y[64];
            ls_solve(kr, c, k->jn, y);
            /* w += Z y in double-double: the terms y_i z_i are much larger than their sum
             * (the preconditioned directions cancel), and the rounding of a plain daxpy
             * then left the true residual of a cycle 10-100x above GMRES's estimate, which
             * cost a whole restart cycle (bracket 59k: 7 of 21 iterations) */
            if (kr->relax) { /* the bound on what the inexact products moved the residual */
                double gap = 0.0;
                for (int i = 0; i < k->jn; ++i) {
                    gap += fabs(y[i]) * k->eb[i];
                    if (k->gv0[i] > 0.0) k->grow = fmax(k->grow, fabs(y[i]) / k->gv0[i]);
                }
                /* past the budget (the relaxed products' bounds with a huge y_j): no more
                 * relaxing */
                if (gap > CM_RBF_RELAX_BUDGET * k->goal) k->exact = 1;
                cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: column %d, cycle %d: gap bound of "
                       "the relaxed products %.3g (the cycle's goal %.3g)", c, cycle,
                       gap / k->fnorm, k->goal / k->fnorm);
            }
            double *wh = w + (size_t)c * m, *wl = kr->wlo + (size_t)c * m;
            for (int i = 0; i < k->jn; ++i) {
                const double yi = y[i], *zi = k->z + (size_t)i * m;
                for (size_t q = 0; q < m; ++q) {
                    double p = yi * zi[q];
                    double pe = fma(yi, zi[q], -p);
                    double t = wh[q] + p, bv = t - wh[q];
                    double te = (wh[q] - (t - bv)) + (p - bv);
                    wh[q] = t;
                    wl[q] += te + pe;
                }
            }
        }
    }
    /* the low parts stay in kr->wlo for the caller to fold in (or to keep, in a refinement) */
    return CM_OK;
}

/* The bound, relative to the column's scale, on the error of plain direct sums of A w if it
 * is at most CM_RBF_PLAIN_RES_SHARE of the tolerance, else -1 (compensated sums are needed),
 * into col[c].pb for the n columns list[]. Plain sums err by at most CM_RBF_PLAIN_ERR x S(w),
 * S(w) = max_i sum_j |w_j| phi_ij (by the loosest treecode on |w|). Why: a loose solve does
 * not need the compensated product, which costs 1.5-2x a plain one (the fixed-binade update
 * per entry and component, rbf_r3_avx512.h); at 10^6 centres to 1e-6 it was the one exact
 * residual, 320 of 1,044 CPU s on Zen 5, where S(w) is 1.9e5 x max |f| and the bound 1.9e-8
 * (measured plain errors are 7x below it; RESULTS.md, RBF solvers). The caller adds the
 * bound to the residual it compares with the tolerance. Only tried from a relative
 * tolerance of CM_RBF_PLAIN_RES_TOL: on real sets S(w) is 1e4..1e9 x max |f|, so below it
 * the loose treecode's product on |w| would be spent for nothing. absw, out: g x m scratch. */
#define CM_RBF_PLAIN_RES_TOL 1e-8
#define CM_RBF_PLAIN_RES_SHARE 0.1
static void plain_bounds(const cm_rbf *r, krylov *kr, int n, const int *list, const double *w,
                         double tol, double *absw, double *out, int threads)
{
    const size_t m = kr->m;
    double **in = kr->pa, **res = kr->pb;
    for (int u = 0; u < n; ++u) kr->col[list[u]].pb = -1.0;
    if (!(tol >= CM_RBF_PLAIN_RES_TOL) || n == 0) return;
    for (int u = 0; u < n; ++u) {
        const size_t o = (size_t)list[u] * m;
        in[u] = absw + o;
        res[u] = out + o;
        for (size_t i = 0; i < m; ++i) absw[o + i] = fabs(w[o + i]);
    }
    /* positive weights: the loosest treecode (1e-6 of the sums) is enough for a bound */
    if (matvec_kind(r, kr, MV_FAST, 0, n, in, res, threads) != MV_FAST) return;
    for (int u = 0; u < n; ++u) {
        kcol *k = &kr->col[list[u]];
        if (!(k->fnorm > 0.0)) continue;
        const double bound = CM_RBF_PLAIN_ERR * norm_inf(m, res[u]) / k->fnorm;
        k->pb = bound <= CM_RBF_PLAIN_RES_SHARE * tol ? bound : -1.0;
    }
}

/* solve_group with fast (treecode) matvecs inside the Krylov loop, wrapped in iterative
 * refinement on exact residuals: w += solve(f - A w) with A w summed directly and
 * compensated (and A w_lo, the low parts, by the treecode: they are eps |w|). Why: the
 * treecode's error is relative to sum |w| phi, which the cancelling RBF weights make 1e4..1e7
 * x |A w|, so the first solve is exact only to fast_tol times that (measured: 1e-8..1e-5 on
 * the real sets); each step multiplies the residual by about that factor again. The
 * residual the caller sees is the exact one. But where the Krylov space needs huge
 * coefficients, the fast Krylov solve itself stalls: its residual by the treecode stays far
 * above GMRES's estimate, and every further fast step stalls there again. It did on two
 * bodies far apart (121k centres: 4.8e-5 against 2.1e-7, then 4.5e-5 after a second step of
 * 40 iterations; RESULTS.md, RBF solvers) until the
 * preconditioner stopped giving the bodies linear moments (rbf_bodies.c: then
 * 10 iterations, no fallback). A column whose fast solve stagnated, or whose steps stopped
 * above the tolerance and above its floor, is then solved afresh with direct (compensated,
 * relaxed) matvecs (*direct = 1): the fast work is lost, but the cost is bounded by one
 * direct solve. Each column refines on its own (its own inner tolerances, its own switch to
 * direct products), so that its result does not depend on its batch-mates; the columns of a
 * step share the passes, the fast ones and the direct ones in two groups. A column with
 * col[c].warm starts from the w it holds if that leaves a residual below |f_c|. steps:
 * exact residuals formed; first: the residual after the first solve. */
static cm_status refine_group(cm_context *ctx, const cm_rbf *r, krylov *kr, const double *f,
                              double *w, double *aw, int *steps, double *first, int *direct,
                              int threads)
{
    const size_t m = kr->m;
    const int g = kr->g;
    const cm_rbf_options *o = &r->opt;
    const cm_rbf_tuning *tu = &r->tun;
    const size_t gm = (size_t)g * m;
    double *rhs = malloc(gm * sizeof *rhs), *dw = malloc(gm * sizeof *dw);
    double *adw = malloc(gm * sizeof *adw), *wl = calloc(gm, sizeof *wl);
    int *sel = malloc((size_t)g * sizeof *sel), *stop = malloc((size_t)g * sizeof *stop);
    if (!rhs || !dw || !adw || !wl || !sel || !stop) {
        free(rhs), free(dw), free(adw), free(wl), free(sel), free(stop);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_solve: out of memory for the refinement");
    }
    const cm_rbf_tree *tree = kr->tree; /* restored with relax after a direct step */
    const int relax = kr->relax;
    cm_status st = CM_OK;
    memcpy(rhs, f, gm * sizeof *rhs);
    /* warm starts: kept where the exact residual of the start is below |f_c| */
    int nw = 0;
    for (int c = 0; c < g; ++c) {
        kcol *k = &kr->col[c];
        k->done = k->last = k->total_it = 0;
        k->status = 0;
        k->rprev = INFINITY;
        k->warm_res = 0.0;
        if (k->warm) {
            kr->pa[nw] = w + (size_t)c * m;
            kr->pb[nw] = aw + (size_t)c * m;
            sel[nw++] = c;
        } else memset(w + (size_t)c * m, 0, m * sizeof *w);
    }
    if (nw > 0) {
        matvec_kind(r, kr, MV_COMP, 0, nw, kr->pa, kr->pb, threads);
        for (int u = 0; u < nw; ++u) {
            const int c = sel[u];
            kcol *k = &kr->col[c];
            const size_t o0 = (size_t)c * m;
            for (size_t i = 0; i < m; ++i) rhs[o0 + i] = f[o0 + i] - aw[o0 + i];
            project(r->iter->q1, m, r->k, rhs + o0);
            const double fn = norm_inf(m, f + o0), rn = norm_inf(m, rhs + o0);
            if (rn < fn) k->warm_res = rn / fn, k->took = 1;
            else {
                memcpy(rhs + o0, f + o0, m * sizeof *rhs);
                memset(w + o0, 0, m * sizeof *w);
            }
        }
    }
    for (int c = 0; c < g; ++c) kr->col[c].warm = 0; /* the corrections start from zero */
    for (int step = 0;; ++step) {
        int nopen = 0;
        for (int c = 0; c < g; ++c) {
            kcol *k = &kr->col[c];
            if (k->done) continue;
            const double rn = norm_inf(m, rhs + (size_t)c * m);
            k->tol = tu->fast_refine > 0 && !k->last
                         ? fmax(o->tolerance, CM_RBF_REFINE_GAIN * rn / k->fnorm)
                         : o->tolerance;
            ++nopen;
        }
        if (nopen == 0) break;
        for (int pass = 0; pass < 2; ++pass) { /* the fast columns, then the direct ones */
            int ns = 0;
            for (int c = 0; c < g; ++c)
                if (!kr->col[c].done && kr->col[c].last == pass) sel[ns++] = c;
            if (ns == 0) continue;
            kr->tree = pass ? NULL : tree;
            kr->relax = pass ? tu->relax : relax;
            if (pass) *direct = 1;
            st = solve_group(ctx, r, kr, rhs, ns, sel, dw, adw, threads);
            kr->tree = tree;
            kr->relax = relax;
            if (st < 0) goto done; /* interrupted */
        }
        int n = 0;
        for (int c = 0; c < g; ++c) {
            kcol *k = &kr->col[c];
            if (k->done) continue;
            sel[n++] = c;
            const size_t o0 = (size_t)c * m;
            for (size_t i = o0; i < o0 + m; ++i) { /* w += dw + dw_lo in double-double */
                double t = w[i] + dw[i], bv = t - w[i];
                wl[i] += (w[i] - (t - bv)) + (dw[i] - bv) + kr->wlo[i];
                w[i] = t;
            }
            k->total_it += k->iters;
        }
        if (tu->fast_refine == 0) { /* the treecode's own residual: A w = A dw here */
            for (int u = 0; u < n; ++u) {
                kcol *k = &kr->col[sel[u]];
                memcpy(aw + (size_t)sel[u] * m, adw + (size_t)sel[u] * m, m * sizeof *aw);
                k->status = k->state;
                k->done = 1;
            }
            break;
        }
        /* the exact residual f - A w_hi - A w_lo; A w_hi plainly where that is exact enough
         * (then within pb of the exact one) */
        plain_bounds(r, kr, n, sel, w, o->tolerance, dw, adw, threads);
        for (int kind = MV_COMP; kind <= MV_PLAIN; ++kind) {
            int nk = 0;
            for (int u = 0; u < n; ++u) {
                const int c = sel[u];
                if ((kr->col[c].pb >= 0.0) != (kind == MV_PLAIN)) continue;
                kr->pa[nk] = w + (size_t)c * m;
                kr->pb[nk] = aw + (size_t)c * m;
                ++nk;
            }
            matvec_kind(r, kr, kind, 0, nk, kr->pa, kr->pb, threads);
        }
        for (int u = 0; u < n; ++u) {
            kr->pa[u] = wl + (size_t)sel[u] * m;
            kr->pb[u] = adw + (size_t)sel[u] * m;
        }
        product(r, kr, MV_FAST, tree, -1, n, kr->pa, kr->pb, threads);
        ++kr->mv[MV_FAST];
        ++*steps;
        int nstop = 0;
        for (int u = 0; u < n; ++u) {
            const int c = sel[u];
            kcol *k = &kr->col[c];
            const size_t o0 = (size_t)c * m;
            double *rv = rhs + o0;
            for (size_t i = 0; i < m; ++i) {
                aw[o0 + i] += adw[o0 + i];
                rv[i] = f[o0 + i] - aw[o0 + i];
            }
            project(r->iter->q1, m, r->k, rv);
            const double res = k->fnorm > 0.0 ? norm_inf(m, rv) / k->fnorm : 0.0;
            if (step == 0) *first = fmax(*first, res);
            cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: column %d, refinement %d: %d "
                   "iterations (%s matvecs), exact residual %.3g", c, step + 1, k->iters,
                   k->last ? "direct" : "fast", res);
            if (res + fmax(k->pb, 0.0) <= o->tolerance) k->done = 1, k->status = 1;
            /* state 3: the fast Krylov solve itself stagnated above its floor (see above) */
            else if (k->last || step + 1 >= tu->fast_refine || res > 0.5 * k->rprev ||
                     k->state == 3) {
                k->done = 1, k->status = k->state == 1 ? 3 : k->state;
                if (!k->last) stop[nstop++] = c;
            }
            k->rprev = res;
            k->rres = res;
        }
        if (nstop > 0) {
            /* stopped above the tolerance: at the floor of w (the rounding of its own sums,
             * eps max_i sum_j |w_j| phi_ij, by the treecode on |w|), or short of it */
            for (int u = 0; u < nstop; ++u) {
                const size_t o0 = (size_t)stop[u] * m;
                kr->pa[u] = dw + o0;
                kr->pb[u] = adw + o0;
                for (size_t i = 0; i < m; ++i) dw[o0 + i] = fabs(w[o0 + i]);
            }
            if (product(r, kr, MV_FAST, tree, -1, nstop, kr->pa, kr->pb, threads) == MV_FAST) {
                ++kr->mv[MV_FAST];
                for (int u = 0; u < nstop; ++u) {
                    kcol *k = &kr->col[stop[u]];
                    const double s = norm_inf(m, kr->pb[u]);
                    /* reopened: solved afresh with direct matvecs, relaxed as in a direct
                     * solve. Afresh, not as a correction: what the fast steps leave is what
                     * the preconditioner handles worst (two bodies: 47 iterations for the
                     * correction of 4.8e-5, 11 for the whole solve) */
                    if (k->rres > CM_RBF_FLOOR_SLACK * DBL_EPSILON * s / k->fnorm) {
                        const size_t o0 = (size_t)stop[u] * m;
                        k->done = 0, k->last = 1;
                        memcpy(rhs + o0, f + o0, m * sizeof *rhs);
                        memset(w + o0, 0, m * sizeof *w);
                        memset(wl + o0, 0, m * sizeof *wl);
                    }
                }
            }
        }
    }
    for (int c = 0; c < g; ++c) {
        kcol *k = &kr->col[c];
        k->iters = k->total_it;
        k->state = k->status;
    }
    for (size_t i = 0; i < gm; ++i) w[i] += wl[i];
done:
    kr->tree = tree;
    kr->relax = relax;
    free(rhs), free(dw), free(adw), free(wl), free(sel), free(stop);
    return st;
}

/* Bytes of the solve per column: the Krylov basis V and Z, the weights' low parts and their
 * products, the preconditioner's input, output and scratch, A w, and with fast sums the
 * refinement's four vectors (the header's per-column figure, cm_rbf_options). */
static double bytes_per_column(size_t m, int R, int fast)
{
    return ((double)(2 * R + 1) + 8.0 + (fast ? 4.0 : 0.0)) * (double)m * sizeof(double) +
           (double)sizeof(kcol);
}

static void krylov_free(krylov *kr)
{
    if (kr->col)
        for (int c = 0; c < kr->g; ++c)
            free(kr->col[c].v), free(kr->col[c].z), free(kr->col[c].h);
    free(kr->col);
    free(kr->soa), free(kr->rowm), free(kr->pin), free(kr->aux), free(kr->wlo), free(kr->awlo);
    free(kr->ia), free(kr->ib), free(kr->ic);
    free(kr->pa), free(kr->pb), free(kr->pc), free(kr->pd), free(kr->pe), free(kr->pf);
}

/* kr->g = g columns of storage; 0 or -1 out of memory (kr then for krylov_free). */
static int krylov_alloc(krylov *kr, int g)
{
    const size_t m = kr->m, gm = (size_t)g * m;
    const int R = kr->R;
    kr->g = 0;
    kr->col = calloc((size_t)g, sizeof *kr->col);
    if (!kr->col) return -1;
    kr->g = g;
    int ok = 1;
    for (int c = 0; c < g && ok; ++c) {
        kcol *k = &kr->col[c];
        k->v = cm_alloc_large((size_t)(R + 1) * m * sizeof(double), 0);
        k->z = cm_alloc_large((size_t)R * m * sizeof(double), 0);
        k->h = calloc((size_t)(R + 1) * (size_t)R, sizeof(double));
        ok = k->v && k->z && k->h;
    }
    const size_t sm = (size_t)CM_RBF_SUM_MAX_NC * m;
    kr->soa = malloc(sm * sizeof(double));
    kr->rowm = malloc(sm * sizeof(double));
    kr->pin = malloc(gm * sizeof(double));
    kr->aux = malloc(gm * sizeof(double));
    kr->wlo = malloc(gm * sizeof(double));
    kr->awlo = malloc(gm * sizeof(double));
    kr->ia = malloc((size_t)g * sizeof(int));
    kr->ib = malloc((size_t)g * sizeof(int));
    kr->ic = malloc((size_t)g * sizeof(int));
    double ***pp[6] = {&kr->pa, &kr->pb, &kr->pc, &kr->pd, &kr->pe, &kr->pf};
    for (int i = 0; i < 6; ++i) {
        *pp[i] = malloc((size_t)g * sizeof(double *));
        ok = ok && *pp[i];
    }
    return ok && kr->soa && kr->rowm && kr->pin && kr->aux && kr->wlo && kr->awlo && kr->ia &&
                   kr->ib && kr->ic
               ? 0
               : -1;
}

int cm_rbf_iterative_column_iterations(const cm_rbf *r, size_t c)
{
    if (!r || !r->iter || c >= r->iter->col_n) return -1;
    return r->iter->col_iters[c];
}

cm_status cm_rbf_iterative_solve(cm_context *ctx, cm_rbf *r, size_t nc, const double *f,
                                 double *w, double *q, int threads)
{
    const size_t m = r->m, k = (size_t)r->k;
    const cm_rbf_options *o = &r->opt;
    const cm_rbf_tuning *tu = &r->tun;
    const int R = o->restart < 63 ? o->restart : 63;
    /* put back if the solve fails or stops: the weights stay the last solve's */
    const double fmax_before = r->iter->fmax;
    const int fast = o->fast_sum == 1 || (o->fast_sum < 0 && m >= CM_RBF_FAST_MIN_M);
    /* the columns in groups that fit the memory budget (half the machine's by default) */
    const double budget = tu->krylov_budget > 0.0 ? tu->krylov_budget : cm_memory_budget();
    const double per_col = bytes_per_column(m, R, fast);
    size_t gsize = nc;
    if (budget > 0.0 && (double)nc * per_col > budget)
        gsize = budget / per_col >= 1.0 ? (size_t)(budget / per_col) : 1;
    krylov kr;
    memset(&kr, 0, sizeof kr);
    kr.m = m;
    kr.R = R;
    double *aw = malloc(nc * m * sizeof *aw);
    int *col_iters = realloc(r->iter->col_iters, nc * sizeof *col_iters);
    if (col_iters) {
        r->iter->col_iters = col_iters;
        r->iter->col_n = nc;
    }
    cm_status st = CM_OK;
    if (krylov_alloc(&kr, (int)gsize) != 0 || !aw || !col_iters) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_solve: out of memory for the Krylov basis "
                      "(%.3g GB for %zu columns)", per_col * (double)gsize * 1e-9, gsize);
        goto done;
    }
    const double fmax_all = norm_inf(nc * m, f);
    cm_rbf_iterative_set_scale(r, fmax_all);
    if (fast) {
        int order;
        double theta;
        cm_rbf_tree_params(tu->fast_tol, &order, &theta);
        kr.tree = cm_rbf_iterative_tree(r, order, theta);
        if (!kr.tree) {
            st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_solve: out of memory for the treecode");
            goto done;
        }
    }
    int mvk[3] = {0, 0, 0};
    kr.mv = mvk;
    /* relaxed products in the direct-matvec solve (the fast one refines on its own, but
     * relaxes in its direct restart, refine_group) */
    kr.relax = tu->relax && !fast;
    kr.relax_tree = o->fast_sum == 0 || !tu->relax ? 0
                    : m >= CM_RBF_RELAX_TREE11_M || tu->relax == 2 ? 3
                    : m >= CM_RBF_RELAX_TREE9_M ? 2
                    : m >= CM_RBF_RELAX_TREE_M ? 1 : 0;
    {
        double d2 = 0.0;
        for (int d = 0; d < 3; ++d) {
            double lo = INFINITY, hi = -INFINITY;
            for (size_t i = 0; i < m; ++i) {
                lo = fmin(lo, r->c[(size_t)d * m + i]);
                hi = fmax(hi, r->c[(size_t)d * m + i]);
            }
            d2 += (hi - lo) * (hi - lo);
        }
        kr.diam3 = d2 * sqrt(d2);
    }
    /* warm starts: the previous solve's weights of the same column, when cm_rbf_solve comes
     * again with as many columns (tried in the first cycle, kept if they leave a residual
     * below the data's) */
    const int warm = o->warm_start && r->warm_ok && r->w && (size_t)r->ncomp == nc;
    int maxit = 0, floor_hit = 0, stagnated = 0, maxed = 0, steps = 0, direct = 0, groups = 0;
    int nwarm = 0;
    double floor_max = 0.0, first = 0.0, warm_worst = 0.0;
    for (size_t c0 = 0; c0 < nc; c0 += gsize) {
        const int g = nc - c0 < gsize ? (int)(nc - c0) : (int)gsize;
        const int gall = kr.g;
        kr.g = g;
        ++groups;
        for (int c = 0; c < g; ++c) {
            kcol *kc = &kr.col[c];
            const size_t o0 = (c0 + (size_t)c) * m;
            /* each column to the tolerance relative to its own scale, max |f_c|, or the
             * fraction column_scale of max |f| over all columns if that is larger: so a
             * column's iterates do not depend on its batch-mates of similar size (a batch
             * of variants solves each as alone), while a column of round-off (a
             * displacement component that is zero up to 1e-17) is not chased to its own
             * relative tolerance. Either way the residual is within the tolerance x max |f|
             * of all columns, as the header promises */
            kc->fnorm = fmax(norm_inf(m, f + o0), tu->column_scale * fmax_all);
            kc->tol = o->tolerance;
            kc->warm = warm;
            kc->took = 0;
            kc->warm_res = 0.0;
            if (warm) {
                memcpy(w + o0, r->w + o0, m * sizeof *w);
                project(r->iter->q1, m, r->k, w + o0);
            }
            kr.ia[c] = c;
        }
        if (fast)
            st = refine_group(ctx, r, &kr, f + c0 * m, w + c0 * m, aw + c0 * m, &steps, &first,
                              &direct, threads);
        else {
            int *sel = malloc((size_t)g * sizeof *sel);
            if (!sel) st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_solve: out of memory");
            else {
                for (int c = 0; c < g; ++c) sel[c] = c;
                st = solve_group(ctx, r, &kr, f + c0 * m, g, sel, w + c0 * m, aw + c0 * m,
                                 threads);
                free(sel);
            }
            for (size_t i = 0; i < (size_t)g * m; ++i) w[c0 * m + i] += kr.wlo[i];
        }
        kr.g = gall;
        if (st != CM_OK) goto done;
        for (int c = 0; c < g; ++c) {
            const kcol *kc = &kr.col[c];
            col_iters[c0 + (size_t)c] = kc->iters;
            if (kc->iters > maxit) maxit = kc->iters;
            if (kc->floor * kc->fnorm > floor_max * fmax_all)
                floor_max = fmax_all > 0.0 ? kc->floor * kc->fnorm / fmax_all : 0.0;
            floor_hit |= kc->state == 2;
            stagnated |= kc->state == 3;
            maxed |= kc->state == 4;
            if (kc->took) {
                ++nwarm;
                warm_worst = fmax(warm_worst, kc->warm_res);
            }
        }
    }
    /* polynomial: R q = Q1'(f - A w); then the residual at the centres, exactly */
    double worst = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        const double *fc = f + c * m, *ac = aw + c * m;
        double *qc = q + c * k, t[4];
        double *g = kr.pin;
        for (size_t i = 0; i < m; ++i) g[i] = fc[i] - ac[i];
        for (size_t a = 0; a < k; ++a) t[a] = cblas_ddot((int)m, r->iter->q1 + a * m, 1, g, 1);
        for (int i = (int)k - 1; i >= 0; --i) {
            double s = t[i];
            for (size_t j = (size_t)i + 1; j < k; ++j) s -= r->qr[j * m + (size_t)i] * qc[j];
            qc[i] = s / r->qr[(size_t)i * m + (size_t)i];
        }
        double fn = fmax_all, e = 0.0;
        for (size_t i = 0; i < m; ++i) {
            double p = qc[0] + qc[1] * r->c[i] + qc[2] * r->c[m + i] + qc[3] * r->c[2 * m + i];
            e = fmax(e, fabs(g[i] - p));
        }
        worst = fmax(worst, fn > 0.0 ? e / fn : 0.0);
    }
    /* the attainable exactness of plain direct sums of these weights (what cm_rbf_evaluate
     * gives at the centres): eps max_i sum_j |w_j| phi_ij, for all columns in one pass (per
     * group of the memory budget). An estimate: the treecode's error on positive weights is
     * fast_tol (or, the loosest relaxed one, 1e-6) of the sum; counted with the products */
    for (size_t c0 = 0; c0 < nc; c0 += gsize) {
        const int g = nc - c0 < gsize ? (int)(nc - c0) : (int)gsize;
        for (int u = 0; u < g; ++u) {
            kr.pa[u] = kr.aux + (size_t)u * m;
            kr.pb[u] = kr.awlo + (size_t)u * m;
            for (size_t i = 0; i < m; ++i) kr.pa[u][i] = fabs(w[(c0 + (size_t)u) * m + i]);
        }
        if (kr.tree) matvec(r, &kr, g, kr.pa, kr.pb, threads);
        else matvec_kind(r, &kr, kr.relax_tree ? MV_FAST : MV_PLAIN, 0, g, kr.pa, kr.pb, threads);
        if (fmax_all > 0.0)
            floor_max = fmax(floor_max, DBL_EPSILON * norm_inf((size_t)g * m, kr.awlo) / fmax_all);
    }
    r->stats.iterations = maxit;
    r->stats.matvecs = mvk[MV_COMP] + mvk[MV_PLAIN] + mvk[MV_FAST];
    r->stats.matvecs_compensated = mvk[MV_COMP];
    r->stats.matvecs_plain = mvk[MV_PLAIN];
    r->stats.matvecs_fast = mvk[MV_FAST];
    r->stats.residual = worst;
    r->stats.floor = floor_max;
    /* with fast sums the stop at the floor is seen on the exact residuals, after the loop */
    r->stats.floor_limited = (floor_hit || (fast && stagnated)) && worst > o->tolerance &&
                             (!fast || worst <= CM_RBF_FLOOR_SLACK * floor_max);
    r->stats.fast_sum = fast;
    r->stats.refinements = steps;
    r->stats.fast_direct = direct;
    r->stats.fast_residual = fast ? first : 0.0;
    r->stats.fast_bound = fast ? tu->fast_tol * floor_max / DBL_EPSILON : 0.0;
    r->stats.memory_bytes = cm_rbf_schwarz_bytes(r->iter->pc) + m * k * sizeof(double) +
                            (size_t)(per_col * (double)gsize) +
                            cm_rbf_tree_bytes(kr.tree) +
                            cm_rbf_tree_bytes(r->iter->rtree[0]) +
                            cm_rbf_tree_bytes(r->iter->rtree[1]) +
                            cm_rbf_tree_bytes(r->iter->rtree[2]);
    r->stats.column_groups = groups;
    r->stats.warm_columns = nwarm;
    r->stats.warm_residual = warm_worst;
    if (worst > o->tolerance && !r->stats.floor_limited)
        st = cm_error(ctx, CM_WARNING,
                      "cm_rbf_solve: the iterative solver %s after %d iterations at a relative "
                      "residual of %.3g (tolerance %.3g, attainable floor %.3g)",
                      stagnated ? "stagnated" : maxed ? "reached max_iterations" : "stopped",
                      maxit, worst, o->tolerance, floor_max);
done:
    if (st < 0) cm_rbf_iterative_set_scale(r, fmax_before);
    krylov_free(&kr);
    free(aw);
    return st;
}
