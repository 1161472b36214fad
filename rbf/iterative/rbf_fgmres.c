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
#include "rbf_krylov.h"

#include <cblas.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

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
#define CM_RBF_RELAX_LEVELS 3
static const double relax_tree_tol[CM_RBF_RELAX_LEVELS] = {1e-6, 1e-9, 1e-11};

/* v -= Q1 (Q1' v), twice (the second pass removes what round-off left of the first). */
void cm_krylov_project(const double *q1, size_t m, int k, double *v)
{
    for (int pass = 0; pass < 2; ++pass)
        for (int a = 0; a < k; ++a) {
            const double *qa = q1 + (size_t)a * m;
            double s = cblas_ddot((int)m, qa, 1, v, 1);
            cblas_daxpy((int)m, -s, qa, 1, v, 1);
        }
}

double cm_krylov_residual(const cm_rbf *r, size_t m, const double *f, const double *aw,
                          double *rv)
{
    for (size_t i = 0; i < m; ++i) rv[i] = f[i] - aw[i];
    cm_krylov_project(r->iter->q1, m, r->k, rv);
    return cm_krylov_norm_inf(m, rv);
}

/* out_u = A in_u for n columns: kind MV_FAST by tree (if that fails: fallback, or zeros
 * for fallback < 0), MV_PLAIN or MV_COMP by direct sums. The one place where the columns
 * are cut into the chunks the kernel sums take. Returns the kind used (the fallback's if a
 * chunk fell back). */
int cm_krylov_product(const cm_rbf *r, krylov *kr, int kind, const cm_rbf_tree *tree, int fallback,
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
void cm_krylov_matvec(const cm_rbf *r, krylov *kr, int n, double *const *in, double *const *out,
                   int threads)
{
    if (n <= 0) return;
    cm_krylov_product(r, kr, kr->tree ? MV_FAST : MV_COMP, kr->tree, MV_COMP, n, in, out, threads);
    ++kr->mv[kr->tree ? MV_FAST : MV_COMP];
}

void cm_krylov_matvec_loose(const cm_rbf *r, krylov *kr, int n, double *const *in,
                            double *const *out, int threads)
{
    if (kr->tree) cm_krylov_matvec(r, kr, n, in, out, threads);
    else cm_krylov_matvec_kind(r, kr, kr->relax_tree ? MV_FAST : MV_PLAIN, 0, n, in, out, threads);
}

/* The same by a named kind: compensated or plain direct sums, or the loose treecode lev.
 * The treecode falls back to plain sums if it cannot be made (kept in r->iter: studies solve
 * again on the same centres). Returns the kind used. */
int cm_krylov_matvec_kind(const cm_rbf *r, krylov *kr, int kind, int lev, int n,
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
    kind = cm_krylov_product(r, kr, kind, kind == MV_FAST ? it->rtree[lev] : NULL, MV_PLAIN, n, in, out,
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
        cm_krylov_project(r->iter->q1, m, r->k, out[c]);
    }
}

double cm_krylov_norm_inf(size_t m, const double *v)
{
    double s = 0.0;
    for (size_t i = 0; i < m; ++i) s = fmax(s, fabs(v[i]));
    return s;
}

void cm_krylov_add_dd(size_t m, double *wh, double *wl, const double *dh, const double *dl)
{
    for (size_t q = 0; q < m; ++q) {
        const double t = wh[q] + dh[q], bv = t - wh[q];
        wl[q] += ((wh[q] - (t - bv)) + (dh[q] - bv)) + dl[q];
        wh[q] = t;
    }
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
    cm_krylov_matvec_kind(r, kr, MV_FAST, 0, nb, pi, po, threads);
    for (int v = 0; v < nb; ++v) {
        kcol *k = &kr->col[act[sel[v]]];
        k->sz = fmin(k->sz, 1.01 * cm_krylov_norm_inf(m, po[v]));
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
        const int kind = cm_krylov_matvec_kind(r, kr, kinds[q][0], lev, n, pi, po, threads);
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

/* t (n + 1) = the coefficients in V_{n+1} of the residual GMRES has after n steps of column
 * k: Q' (0, .., 0, g_n), the rotations Q undone */
static void gmres_residual_coefs(const kcol *k, int n, double *t)
{
    for (int i = 0; i < n; ++i) t[i] = 0.0;
    t[n] = k->gv[n];
    for (int i = n - 1; i >= 0; --i) {
        const double a = t[i], b = t[i + 1];
        t[i] = k->cs[i] * a - k->sn[i] * b;
        t[i + 1] = k->sn[i] * a + k->cs[i] * b;
    }
}

/* The max-norm of the residual GMRES has after step j of column k, V_{j+1} Q' (0, .., 0,
 * g_{j+1}) (Q: the Givens rotations, undone), in O(j m) (a product is O(m^2)). Why: the
 * tolerance is on the max-norm, GMRES minimises the 2-norm, and their ratio changes as the
 * residual falls. A 2-norm target scaled by the ratio at the cycle's start ended cycles 5x
 * above the tolerance (bore 20.6k, a cold start at 1e-6: ratio 39 at the start, 7.5 at the
 * end), each costing a restart whose lost Krylov space took 4 more iterations, and others
 * 10-100x below it (the same at 1e-10: its last cycle, ratio 7 to 14). RESULTS.md, Study. */
static double gmres_residual_inf(const krylov *kr, const kcol *k, int j)
{
    const size_t m = kr->m;
    double t[66];
    gmres_residual_coefs(k, j + 1, t);
    double mx = 0.0;
    for (size_t q = 0; q < m; ++q) {
        double s = 0.0;
        for (int i = 0; i <= j + 1; ++i) s += t[i] * k->v[(size_t)i * m + q];
        mx = fmax(mx, fabs(s));
    }
    return mx;
}

/* A w exactly for the n columns cols[] (in, out: their w and A w), the check of a start or of
 * a cycle's end: compensated, or plain where that is exact enough. A loose tolerance does not
 * need the compensated product (1.5-2x a plain one): from CM_RBF_PLAIN_RES_TOL, w and |w| are
 * summed plainly in one pass (|w| rides along on the same kernel entries), and a column
 * keeps its plain product if its bound, CM_RBF_PLAIN_ERR x S(w) / fnorm, is within
 * CM_RBF_PLAIN_RES_SHARE of its tolerance (col.cb: its residual is judged with the bound
 * added); the others are summed again, compensated, and so are their later checks in this
 * solve (col.comp_only: S(w) changes little from cycle to cycle). S(w) (col.smax) then gives
 * the floor and the evaluation's scale without a pass of their own. A start whose bound on
 * S(w) (col.sbound) already allows plain sums is summed without |w|: half the columns of a
 * warm start's check; one whose estimate from below (col.slow) already forbids them is
 * summed compensated at once (the bracket at 1e-6: S(w) 1e7 x |f|, where the plain pass of w
 * and |w| went for nothing). Returns the columns whose S(w) it summed; *at_once: those. */
static int check_products(const cm_rbf *r, krylov *kr, int n, const int *cols,
                          double *const *in, double *const *out, int *at_once, int threads)
{
    const size_t m = kr->m;
    const int plain = r->opt.tolerance >= CM_RBF_PLAIN_RES_TOL && kr->R >= 2;
    *at_once = 0;
    double **pi = plain ? malloc(6 * (size_t)n * sizeof *pi) : NULL;
    int *at = plain ? malloc((size_t)n * sizeof *at) : NULL;
    if (!pi || !at) {
        free(pi), free(at);
        cm_krylov_matvec_kind(r, kr, MV_COMP, 0, n, in, out, threads);
        return 0;
    }
    double **po = pi + 2 * n, **ci = pi + 4 * n, **co = pi + 5 * n;
    int np = 0, nc = 0, na = 0;
    for (int u = 0; u < n; ++u) { /* the columns tried plainly: w, then |w| (in Z) */
        kcol *k = &kr->col[cols[u]];
        if (k->slow >= 0.0 && cm_rbf_plain_bound(k->slow, k->fnorm, k->tol) < 0.0) {
            k->comp_only = 1;
            k->smin = k->slow;
            ++*at_once;
        }
        if (!k->comp_only) at[np++] = u;
    }
    for (int v = 0; v < np; ++v) {
        kcol *k = &kr->col[cols[at[v]]];
        pi[v] = in[at[v]];
        po[v] = out[at[v]];
        /* S(w) is summed unless a start's bound on it already allows plain sums */
        if (k->sbound >= 0.0 && cm_rbf_plain_bound(k->sbound, k->fnorm, k->tol) >= 0.0) continue;
        k->sbound = -1.0;
        pi[np + na] = k->z; /* Z is free between cycles */
        po[np + na++] = k->z + m;
        for (size_t i = 0; i < m; ++i) k->z[i] = fabs(in[at[v]][i]);
    }
    cm_krylov_matvec_kind(r, kr, MV_PLAIN, 0, np + na, pi, po, threads);
    for (int u = 0, v = 0, a = 0; u < n; ++u) {
        kcol *k = &kr->col[cols[u]];
        if (v < np && at[v] == u) {
            ++v;
            k->smax = k->sbound >= 0.0 ? k->sbound : cm_krylov_norm_inf(m, po[np + a++]);
            k->smin = k->sbound >= 0.0 ? -1.0 : k->smax; /* plain sums of |w|: exact to 1e-14 */
            const double bound = cm_rbf_plain_bound(k->smax, k->fnorm, k->tol);
            if (bound >= 0.0) {
                k->cb = bound;
                continue;
            }
            k->comp_only = 1;
        }
        ci[nc] = in[u];
        co[nc++] = out[u];
    }
    cm_krylov_matvec_kind(r, kr, MV_COMP, 0, nc, ci, co, threads);
    free(pi), free(at);
    return na;
}

/* S(w + dw) between S(w) - S(dw) and S(w) + S(dw), S(dw) <= diam^3 sum |dw| = diam3 l1 */
static void step_s(const krylov *kr, kcol *k, double l1)
{
    if (k->smax >= 0.0) k->smax += kr->diam3 * l1;
    if (k->smin >= 0.0) k->smin = k->smin > kr->diam3 * l1 ? k->smin - kr->diam3 * l1 : -1.0;
}

/* The rounding of the Arnoldi relation A Z y = V H y + Q1 Q1' A Z y in the max-norm, per
 * product and step: at most this x (steps + 2) x eps x |A z_j|_2 (classical Gram-Schmidt
 * twice, the projection, the rotations; a safe multiple of the textbook bound) */
#define CM_RBF_ARNOLDI_ROUND 4.0

/* A w += A dw for column c without a pass, from the cycle's own products: its step dw = Z y
 * has A dw = V_{jn+1} Hbar y + Q1 (Q1' A Z) y, and V Hbar y = r0 - r_jn, the cycle's starting
 * residual less GMRES's own (V_{jn+1} times the rotations undone on (0.., g_jn)). What that
 * errs by: the products' own errors, sum_j |y_j| eb_j (relaxed products; compensated ones
 * count nothing, as in the relaxation's budget), and the rounding of the relation. 1 if that,
 * added to col.cb, stays within CM_RBF_PLAIN_RES_SHARE of the tolerance (aw, cb and smax
 * updated), else 0. Why: a step's plain product is a pass over the kernel's m^2 pairs for
 * what the cycle already summed (the bore's and the bracket's warm solves take nearly all
 * their checks after a cycle this way: RESULTS.md, Study). l1: sum |dw| (the step's high
 * part). */
static int arnoldi_step(const cm_rbf *r, const krylov *kr, int c, double *aw, double l1)
{
    const size_t m = kr->m;
    kcol *k = &kr->col[c];
    const int jn = k->jn;
    double y[64];
    ls_solve(kr, c, jn, y);
    double err = 0.0;
    for (int i = 0; i < jn; ++i)
        err += fabs(y[i]) * ((kr->relax ? k->eb[i] : 0.0) +
                             CM_RBF_ARNOLDI_ROUND * (jn + 2) * DBL_EPSILON * k->an[i]);
    const double cb = k->cb + err / k->fnorm;
    if (!(cb <= CM_RBF_PLAIN_RES_SHARE * k->tol)) return 0;
    /* t: GMRES's residual in the basis V_{jn+1}, less the start's (cycle0 v_0) */
    double t[66], qa[4] = {0, 0, 0, 0};
    gmres_residual_coefs(k, jn, t);
    t[0] -= k->cycle0;
    for (int i = 0; i < jn; ++i)
        for (int a = 0; a < r->k; ++a) qa[a] += y[i] * k->qaz[i][a];
    double *ac = aw + (size_t)c * m;
    for (size_t q = 0; q < m; ++q) {
        double s = 0.0;
        for (int i = 0; i <= jn; ++i) s += t[i] * k->v[(size_t)i * m + q];
        ac[q] -= s;
    }
    for (int a = 0; a < r->k; ++a) cblas_daxpy((int)m, qa[a], r->iter->q1 + (size_t)a * m, 1, ac, 1);
    k->cb = cb;
    step_s(kr, k, l1);
    return 1;
}

/* The checks of the n columns list[] that have an exact A w from an earlier check (has_aw)
 * and whose step dw (its high part, kr->aux) is small: A w += A dw from the cycle's own
 * products (arnoldi_step) where its bound fits, else by plain sums, their error bounded by
 * CM_RBF_PLAIN_ERR x S(dw) <= CM_RBF_PLAIN_ERR x diam^3 sum |dw| (and the step's low part,
 * A dl, by eps x that), added to col.cb where that stays within CM_RBF_PLAIN_RES_SHARE of
 * the tolerance. Why: near the tolerance a step is 1e-8..1e-6 of w, so its product needs no
 * compensated sums even at 1e-10, where the whole w's does (S(w) is 1e4..1e9 x |f|); on the
 * bore (20.6k centres) a warm solve's last check went from a compensated product of w plus a
 * plain one of its low part to one plain product, then to none. The others lose has_aw (a
 * full check). Returns the checks by the Arnoldi relation. */
static int step_products(const cm_rbf *r, krylov *kr, int n, const int *list, double *aw,
                         int threads)
{
    const size_t m = kr->m;
    double **in = kr->pe, **out = kr->pf;
    int *plain = kr->ic; /* the columns summed plainly (fl of the caller, not yet in use) */
    int ns = 0, na = 0;
    for (int u = 0; u < n; ++u) {
        kcol *k = &kr->col[list[u]];
        if (!k->has_aw) continue;
        const double *dw = kr->aux + (size_t)list[u] * m;
        double l1 = 0.0;
        for (size_t i = 0; i < m; ++i) l1 += fabs(dw[i]);
        if (k->jn > 0 && arnoldi_step(r, kr, list[u], aw, l1)) {
            ++na;
            continue;
        }
        const double b = cm_rbf_plain_bound(kr->diam3 * l1, k->fnorm, k->tol);
        const double cb = k->cb + b + 2.0 * DBL_EPSILON * kr->diam3 * l1 / k->fnorm;
        if (k->jn == 0 || b < 0.0 || cb > CM_RBF_PLAIN_RES_SHARE * k->tol) {
            k->has_aw = 0;
            continue;
        }
        k->cb = cb;
        step_s(kr, k, l1);
        in[ns] = kr->aux + (size_t)list[u] * m;
        out[ns] = kr->awlo + (size_t)list[u] * m;
        plain[ns++] = list[u];
    }
    cm_krylov_matvec_kind(r, kr, MV_PLAIN, 0, ns, in, out, threads);
    for (int v = 0; v < ns; ++v) {
        double *a = aw + (size_t)plain[v] * m;
        for (size_t i = 0; i < m; ++i) a[i] += out[v][i];
    }
    return na;
}

/* The solve's progress (stage "rbf solve", in columns): each of the ns columns sel[] counts
 * log(its residual) / log(its tolerance) done (from zero 0, converged 1; a warm start comes
 * in part done), those of the groups before it whole; never less than shown before (an
 * exact residual after a restart may lie above GMRES's estimate). Why not iterations: how
 * many a solve takes is not known ahead, while its residual falls about geometrically. */
static cm_status solve_progress(cm_context *ctx, krylov *kr, int ns, const int *sel)
{
    double done = (double)kr->before;
    for (int s = 0; s < ns; ++s) {
        const kcol *k = &kr->col[sel[s]];
        /* the cycle's start residual, less what GMRES has taken of it since */
        double res = k->res;
        if (k->jn > 0 && k->cycle0 > 0.0) res *= fabs(k->gv[k->jn]) / k->cycle0;
        done += k->state != 0 || res <= k->tol ? 1.0
                : res >= 1.0 || !(k->tol > 0.0) ? 0.0 : log(res) / log(k->tol);
    }
    if (done > kr->shown) kr->shown = fmin(done, (double)kr->all);
    return cm_progress(ctx, "rbf solve", kr->shown, (double)kr->all);
}

/* Solves the ns columns sel[] of f (g x m SoA) into w + kr->wlo (high and low parts), each
 * to its own col[c].tol relative to col[c].fnorm; a column with col[c].warm starts from the
 * w it holds if that leaves a residual below |f_c| (else from zero, and warm is cleared).
 * Per column: iters, floor, state. aw = A(w + wlo) from the last true residual. */
cm_status cm_krylov_solve_group(cm_context *ctx, const cm_rbf *r, krylov *kr, const double *f,
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
        k->comp_only = 0;
        k->jn = 0;
        k->has_aw = k->warm && k->preset; /* its start's A w given, within cb */
        if (!k->warm) memset(w + (size_t)c * m, 0, m * sizeof(double));
        if (!k->has_aw) {
            memset(aw + (size_t)c * m, 0, m * sizeof(double));
            memset(kr->wlo + (size_t)c * m, 0, m * sizeof(double));
        }
    }
    for (int cycle = 0;; ++cycle) {
        int n = 0;
        for (int s = 0; s < ns; ++s)
            if (kr->col[sel[s]].state == 0) list[n++] = sel[s];
        if (n == 0) break;
        /* A w: of every running column after a cycle (of its step where that is small), of
         * a warm one at the start (exactly: the history's own residual is good to the
         * rounding of its pairs only, which their combination amplifies: 3e-9 of |f| on the
         * bore, above the tolerance) */
        if (!kr->tree && cycle > 0) {
            const int na = step_products(r, kr, n, list, aw, threads);
            cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: cycle %d: %d checks by the Arnoldi "
                   "relation", cycle, na);
        }
        int nw = 0;
        for (int u = 0; u < n; ++u) {
            const int c = list[u];
            if (kr->col[c].has_aw) continue; /* summed by its step */
            kr->col[c].cb = 0.0;
            kr->col[c].smax = kr->col[c].smin = -1.0;
            if (cycle == 0 && !kr->col[c].warm) continue;
            in[nw] = w + (size_t)c * m;
            out[nw] = aw + (size_t)c * m;
            p3[nw] = kr->wlo + (size_t)c * m;
            p4[nw] = kr->awlo + (size_t)c * m;
            fl[nw] = c;
            ++nw;
        }
        if (nw > 0) {
            /* A w exactly (this is the check); A wlo (after a cycle: a start has none), eps
             * |w| small, by plain sums or the loosest treecode (its error, 1e-6 S(wlo), is
             * 1e-22 S(w)) */
            if (kr->tree) cm_krylov_matvec(r, kr, nw, in, out, threads);
            else {
                int once;
                const int nsum = check_products(r, kr, nw, fl, in, out, &once, threads);
                if (cycle == 0 && r->opt.tolerance >= CM_RBF_PLAIN_RES_TOL)
                    cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: the check of %d starts summed "
                           "S(w) for %d, bounded it by the fit's last weights for %d, and was "
                           "compensated at once for %d (S too large for plain sums)", nw, nsum,
                           nw - nsum - once, once);
            }
            if (cycle > 0) {
                cm_krylov_matvec_loose(r, kr, nw, p3, p4, threads);
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
            double rn = cm_krylov_residual(r, m, fc, ax, rv);
            k->sbound = k->slow = -1.0; /* of the start only */
            /* a zero start's A w is exactly zero: its first cycle's check may come from the
             * Arnoldi relation too (bore, 20.6k centres, 1e-6: a cold batch's last check
             * for all its columns; its S(w), unknown, is summed after the solve) */
            k->has_aw = !kr->tree;
            if (cycle == 0 && k->warm) {
                /* the start is kept if its residual is below the zero start's |f| */
                const double fn = cm_krylov_norm_inf(m, fc);
                if (rn < fn) k->warm_res = rn / fn, k->took = 1;
                else {
                    k->warm = 0;
                    k->cb = 0.0;
                    memset(w + (size_t)c * m, 0, m * sizeof(double));
                    memset(kr->wlo + (size_t)c * m, 0, m * sizeof(double));
                    memset(ax, 0, m * sizeof(double));
                    rn = cm_krylov_residual(r, m, fc, ax, rv);
                }
            }
            k->res = k->fnorm > 0.0 ? rn / k->fnorm : 0.0;
            if (k->res + k->cb <= k->tol) k->state = 1;
            else if (cycle > 0) fl[nfl++] = c;
        }
        /* the attainable floor: the rounding error of the sums A w themselves (S(w) of a
         * plain check is already summed) */
        if (nfl > 0) {
            int ns = 0;
            for (int u = 0; u < nfl; ++u) {
                const kcol *k = &kr->col[fl[u]];
                if (k->smax >= 0.0) continue;
                p3[ns] = k->z; /* Z is free between cycles */
                p4[ns] = k->z + m;
                for (size_t i = 0; i < m; ++i) p3[ns][i] = fabs(w[(size_t)fl[u] * m + i]);
                ++ns;
            }
            /* positive weights: plain sums are exact to ~1e-14 of the result, the loosest
             * treecode to 1e-6, enough for an estimate */
            cm_krylov_matvec_loose(r, kr, ns, p3, p4, threads);
            for (int u = 0, v = 0; u < nfl; ++u) {
                kcol *k = &kr->col[fl[u]];
                if (k->smax < 0.0) {
                    k->smax = cm_krylov_norm_inf(m, p4[v++]);
                    k->smin = CM_RBF_LOOSE_LOW * k->smax;
                }
                k->floor = DBL_EPSILON * k->smax / k->fnorm;
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
            /* a cycle cut short stops on the 2-norm that GMRES minimises: aim for the
             * max-norm target through the ratio of the two norms at the restart */
            double *v0 = k->v;
            double r2 = cblas_dnrm2((int)m, v0, 1), rinf = cm_krylov_norm_inf(m, v0);
            k->target = 0.5 * k->tol * k->fnorm * (r2 / rinf);
            /* the cycle ends at CM_RBF_CYCLE_GAIN of its start if that comes first, and the
             * exact residual of the next start corrects what its products erred (in the
             * 2-norm, max-norm end / start was 1.2e-6 on two bodies 121k) */
            k->goal = fmax(k->tol, CM_RBF_CYCLE_GAIN * k->res) * k->fnorm;
            k->cut = k->tol < CM_RBF_CYCLE_GAIN * k->res;
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
            cm_status ps = solve_progress(ctx, kr, ns, sel);
            if (ps < 0) return ps;
            if (!kr->relax) cm_krylov_matvec(r, kr, na, out, p3, threads);
            else relaxed_products(ctx, r, kr, cycle, j, na, act, out, p3, threads);
            int keep = 0;
            for (int u = 0; u < na; ++u) {
                const int c = act[u];
                kcol *k = &kr->col[c];
                double *wv = p3[u], *h = k->h + (size_t)j * (size_t)(R + 1);
                /* what a check by the Arnoldi relation needs of the product (arnoldi_step) */
                k->an[j] = cblas_dnrm2((int)m, wv, 1);
                for (int a = 0; a < r->k; ++a)
                    k->qaz[j][a] = cblas_ddot((int)m, r->iter->q1 + (size_t)a * m, 1, wv, 1);
                cm_krylov_project(r->iter->q1, m, r->k, wv);
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
                /* a converged column leaves the active set at once: a cycle that aims at
                 * the tolerance itself where GMRES's own residual meets half of it in the
                 * max-norm, one that ends short of it at CM_RBF_CYCLE_GAIN of its start (or
                 * at the 2-norm target, if that comes first) */
                const double g2 = fabs(k->gv[j + 1]);
                int done = hn == 0.0 || k->iters >= o->max_iterations;
                if (!done && k->cut)
                    done = g2 <= k->target || g2 <= CM_RBF_CYCLE_GAIN * k->cycle0;
                else if (!done)
                    done = gmres_residual_inf(kr, k, j) <= 0.5 * k->tol * k->fnorm;
                if (!done) act[keep++] = c;
            }
            na = keep;
            /* one preconditioned product per column and iteration done */
            if ((ps = solve_progress(ctx, kr, ns, sel)) < 0) return ps;
        }
        /* w += Z y, H y = g (upper triangular after the rotations) */
        for (int u = 0; u < n; ++u) {
            const int c = list[u];
            kcol *k = &kr->col[c];
            if (k->jn == 0) continue;
            double y[64];
            ls_solve(kr, c, k->jn, y);
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
            /* the step dw = Z y (high part in aux, for the next check; low part in awlo,
             * free until then), added to w = wh + wl */
            double *wh = w + (size_t)c * m, *wl = kr->wlo + (size_t)c * m;
            double *dh = kr->aux + (size_t)c * m, *dl = kr->awlo + (size_t)c * m;
            /* in double-double (cm_rbf_combine_dd): the terms are much larger than their
             * sum (the preconditioned directions cancel), and a plain sum's rounding left the
             * true residual of a cycle 10-100x above GMRES's estimate, which cost a whole
             * restart cycle (bracket 59k: 7 of 21 iterations) */
            cm_rbf_combine_dd(m, k->jn, k->z, NULL, y, dh, dl);
            cm_krylov_add_dd(m, wh, wl, dh, dl);
        }
    }
    /* the low parts stay in kr->wlo for the caller to fold in (or to keep, in a refinement) */
    return CM_OK;
}

