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
 * iteration counts here are small, so the extra orthogonalisation is cheap. The components
 * of the data run in lock step, so one kernel-sum pass serves up to four of them (and a
 * converged one leaves the pass). The Krylov products are relaxed (tuning relax, see
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

/* Lock-step state of up to four components. */
typedef struct krylov {
    size_t m;
    int R;          /* restart length */
    int g;          /* components */
    double *v[4];   /* (R+1) x m each */
    double *z[4];   /* R x m each */
    double *h[4];   /* (R+1) x R col-major */
    double cs[4][64], sn[4][64], gv[4][65];
    double *soa, *rowm, *aux; /* g x m scratch */
    double *wlo;    /* g x m: low parts of the weights (double-double accumulation) */
    double *awlo;   /* g x m: A wlo */
    const cm_rbf_tree *tree; /* fast matvecs (treecode) if set, else compensated direct */
    int relax;      /* relaxed products (direct-matvec solves only) */
    int relax_tree; /* the loose treecodes 0..relax_tree-1 may serve them */
    double diam3;   /* diam^3 of the centres: S(z) <= diam3 sum |z| */
    double eb[4][64]; /* bound on the error of each product of the cycle (max-norm) */
    double gv0[4][64]; /* |GMRES residual| before each step */
    double grow[4];   /* largest |y_i| / |r_{i-1}| of the solve so far, per component */
    int exact[4];     /* 1: the component's products stay compensated (a cycle's gap bound
                       * exceeded the budget: its Krylov space needs huge coefficients) */
    int *mv;        /* products by kind (MV_COMP, MV_PLAIN, MV_FAST) */
} krylov;

/* out_c = A in_c for the components in list (n of them, in: pointers to m-vectors). */
static void matvec(const cm_rbf *r, krylov *kr, int n, double *const *in, double *const *out,
                   int threads)
{
    const size_t m = kr->m;
    for (int c = 0; c < n; ++c) memcpy(kr->soa + (size_t)c * m, in[c], m * sizeof(double));
    if (!kr->tree || cm_rbf_tree_sum_self(kr->tree, kr->soa, n, kr->rowm, (size_t)n, threads))
        cm_rbf_kernel_sum_acc(m, r->c, kr->soa, n, m, r->c, m, kr->rowm, (size_t)n, threads);
    for (int c = 0; c < n; ++c)
        for (size_t i = 0; i < m; ++i) out[c][i] = kr->rowm[i * (size_t)n + (size_t)c];
    ++kr->mv[kr->tree ? MV_FAST : MV_COMP];
}

/* The same by a named kind: compensated or plain direct sums, or the loose treecode lev.
 * The treecode falls back to plain sums if it cannot be made (kept in r->iter: studies solve
 * again on the same centres). Returns the kind used. */
static int matvec_kind(const cm_rbf *r, krylov *kr, int kind, int lev, int n,
                       double *const *in, double *const *out, int threads)
{
    const size_t m = kr->m;
    cm_rbf_iter *it = r->iter;
    for (int c = 0; c < n; ++c) memcpy(kr->soa + (size_t)c * m, in[c], m * sizeof(double));
    if (kind == MV_FAST) {
        if (!it->rtree[lev]) {
            int order;
            double theta;
            cm_rbf_tree_params(relax_tree_tol[lev], &order, &theta);
            it->rtree[lev] = cm_rbf_tree_create(m, r->c, order, theta);
        }
        if (!it->rtree[lev] ||
            cm_rbf_tree_sum_self(it->rtree[lev], kr->soa, n, kr->rowm, (size_t)n, threads))
            kind = MV_PLAIN;
    }
    if (kind == MV_PLAIN)
        cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, r->c, kr->soa, n, m, r->c, m, kr->rowm,
                          (size_t)n, threads);
    else if (kind == MV_COMP)
        cm_rbf_kernel_sum_acc(m, r->c, kr->soa, n, m, r->c, m, kr->rowm, (size_t)n, threads);
    for (int c = 0; c < n; ++c)
        for (size_t i = 0; i < m; ++i) out[c][i] = kr->rowm[i * (size_t)n + (size_t)c];
    ++kr->mv[kind];
    return kind;
}

static void precondition(const cm_rbf *r, krylov *kr, int n, double *const *in,
                         double *const *out, int threads)
{
    const size_t m = kr->m;
    for (int c = 0; c < n; ++c) memcpy(kr->soa + (size_t)c * m, in[c], m * sizeof(double));
    cm_rbf_schwarz_apply(r->iter->pc, r, n, kr->soa, kr->aux, threads);
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

/* y = R^-1 g of component c over its first n steps (R, g: H and the right-hand side after
 * the rotations): the coefficients of the current FGMRES solution. */
static void ls_solve(const krylov *kr, int c, int n, double *y)
{
    const size_t ld = (size_t)(kr->R + 1);
    for (int i = n - 1; i >= 0; --i) {
        double s = kr->gv[c][i];
        for (int l = i + 1; l < n; ++l) s -= kr->h[c][(size_t)l * ld + (size_t)i] * y[l];
        y[i] = s / kr->h[c][(size_t)i * ld + (size_t)i];
    }
}

/* Solves components [c0, c0 + g) of f (nc x m SoA) into w + kr->wlo (high and low parts).
 * it/stop/floor per component. */
static cm_status solve_group(cm_context *ctx, const cm_rbf *r, krylov *kr, const double *f,
                             double fmax_all, double tol, double *w, double *aw, int *iters,
                             double *floor_rel, int *status, int threads)
{
    const size_t m = kr->m;
    const int g = kr->g, R = kr->R;
    const cm_rbf_options *o = &r->opt;
    double fnorm[4], prev[4], res[4], target[4], est[4] = {0, 0, 0, 0}, cycle0[4];
    double goal[4]; /* what the cycle must reach, max-norm: the relaxation's budget */
    double *res_v[4], *ax[4];
    int state[4]; /* 0 running, 1 converged, 2 floor, 3 stagnated, 4 max iterations */
    for (int c = 0; c < g; ++c) {
        fnorm[c] = fmax_all; /* relative to all the data, as the dense solver's residual */
        prev[c] = INFINITY;
        iters[c] = 0;
        floor_rel[c] = 0.0;
        state[c] = 0;
        res_v[c] = kr->v[c]; /* the residual is built in V_0 */
        ax[c] = aw + (size_t)c * m;
        memset(w + (size_t)c * m, 0, m * sizeof(double));
        memset(ax[c], 0, m * sizeof(double));
        memset(kr->wlo + (size_t)c * m, 0, m * sizeof(double));
        kr->grow[c] = 1.0;
        kr->exact[c] = 0;
    }
    for (int cycle = 0;; ++cycle) {
        /* true residual Pi(f - A w) of every running component */
        double *in[4], *out[4];
        int list[4], n = 0;
        for (int c = 0; c < g; ++c)
            if (state[c] == 0) {
                list[n] = c;
                in[n] = w + (size_t)c * m;
                out[n] = ax[c];
                ++n;
            }
        if (n == 0) break;
        if (cycle > 0) {
            /* A (w + wlo): the low parts carry what rounding w alone would lose */
            double *lin[4], *lout[4];
            for (int u = 0; u < n; ++u) {
                lin[u] = kr->wlo + (size_t)list[u] * m;
                lout[u] = kr->awlo + (size_t)u * m;
            }
            /* A w exactly (this is the check); A wlo, eps |w| small, by plain sums or the
             * loosest treecode (its error, 1e-6 S(wlo), is 1e-22 S(w)) */
            if (kr->tree) {
                matvec(r, kr, n, in, out, threads);
                matvec(r, kr, n, lin, lout, threads);
            } else {
                matvec_kind(r, kr, MV_COMP, 0, n, in, out, threads);
                matvec_kind(r, kr, kr->relax_tree ? MV_FAST : MV_PLAIN, 0, n, lin, lout, threads);
            }
            for (int u = 0; u < n; ++u)
                for (size_t i = 0; i < m; ++i) out[u][i] += lout[u][i];
        }
        int nfl = 0, fl[4];
        double *absw[4], *afl[4];
        for (int u = 0; u < n; ++u) {
            int c = list[u];
            double *rv = res_v[c];
            for (size_t i = 0; i < m; ++i) rv[i] = f[(size_t)c * m + i] - ax[c][i];
            project(r->iter->q1, m, r->k, rv);
            res[c] = fnorm[c] > 0.0 ? norm_inf(m, rv) / fnorm[c] : 0.0;
            if (res[c] <= tol) state[c] = 1;
            else if (cycle > 0) {
                fl[nfl] = c;
                ++nfl;
            }
        }
        /* the attainable floor: the rounding error of the sums A w themselves */
        if (nfl > 0) {
            for (int u = 0; u < nfl; ++u) {
                int c = fl[u];
                absw[u] = kr->z[c]; /* Z is free between cycles */
                afl[u] = kr->z[c] + m;
                for (size_t i = 0; i < m; ++i) absw[u][i] = fabs(w[(size_t)c * m + i]);
            }
            /* positive weights: plain sums are exact to ~1e-14 of the result, the loosest
             * treecode to 1e-6, enough for an estimate */
            if (kr->tree) matvec(r, kr, nfl, absw, afl, threads);
            else matvec_kind(r, kr, kr->relax_tree ? MV_FAST : MV_PLAIN, 0, nfl, absw, afl,
                             threads);
            for (int u = 0; u < nfl; ++u) {
                int c = fl[u];
                floor_rel[c] = DBL_EPSILON * norm_inf(m, afl[u]) / fnorm[c];
                /* a cycle that does not halve the residual has stagnated: at the floor if
                 * within CM_RBF_FLOOR_SLACK of it, else a failure to converge */
                if (res[c] > 0.5 * prev[c])
                    state[c] = res[c] <= CM_RBF_FLOOR_SLACK * floor_rel[c] ? 2 : 3;
                else if (iters[c] >= o->max_iterations)
                    state[c] = res[c] <= CM_RBF_FLOOR_SLACK * floor_rel[c] ? 2 : 4;
            }
        }
        for (int u = 0; u < n; ++u) {
            int c = list[u];
            cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: component %d, cycle %d: %d iterations, "
                   "residual %.3g (floor %.3g), 2-norm %.3g (GMRES estimate %.3g)", c, cycle,
                   iters[c], res[c], floor_rel[c], cblas_dnrm2((int)m, res_v[c], 1) / fnorm[c],
                   est[c] / fnorm[c]);
            prev[c] = res[c];
        }
        /* the inner loop stops on the 2-norm that GMRES minimises: aim for the max-norm
         * target through the ratio of the two norms at the restart */
        int act[4], na = 0;
        for (int c = 0; c < g; ++c) {
            if (state[c] != 0) continue;
            double *v0 = kr->v[c];
            double r2 = cblas_dnrm2((int)m, v0, 1), rinf = norm_inf(m, v0);
            target[c] = 0.5 * tol * fnorm[c] * (r2 / rinf);
            /* the cycle ends at CM_RBF_CYCLE_GAIN of its start if that comes first, and the
             * exact residual of the next start corrects what its products erred (in the
             * 2-norm, max-norm end / start was 1.2e-6 on two bodies 121k) */
            goal[c] = fmax(tol, CM_RBF_CYCLE_GAIN * res[c]) * fnorm[c];
            cblas_dscal((int)m, 1.0 / r2, v0, 1);
            memset(kr->gv[c], 0, sizeof kr->gv[c]);
            kr->gv[c][0] = r2;
            cycle0[c] = r2;
            act[na++] = c;
        }
        int jn[4] = {0, 0, 0, 0};
        for (int j = 0; j < R && na > 0; ++j) {
            double *vi[4], *zo[4], *wo[4];
            for (int u = 0; u < na; ++u) {
                int c = act[u];
                vi[u] = kr->v[c] + (size_t)j * m;
                zo[u] = kr->z[c] + (size_t)j * m;
                wo[u] = kr->v[c] + (size_t)(j + 1) * m;
            }
            precondition(r, kr, na, vi, zo, threads);
            /* between the preconditioner and the product too: each is 0.1-0.5 s from 10^5
             * centres (the caller may stop; w is its scratch) */
            {
                int most = 0;
                for (int c = 0; c < g; ++c) most = iters[c] > most ? iters[c] : most;
                cm_status ps = cm_progress(ctx, "rbf solve", (double)most, (double)o->max_iterations);
                if (ps < 0) return ps;
            }
            if (!kr->relax) matvec(r, kr, na, zo, wo, threads);
            else {
                /* the loosest kind whose error bound every component allows */
                double tau = INFINITY, sz[4], allow[4];
                for (int u = 0; u < na; ++u) {
                    int c = act[u];
                    sz[u] = kr->diam3 * cblas_dasum((int)m, zo[u], 1);
                    /* what the products so far cost of the budget, with the coefficients
                     * y of the current solution, and how far |y_i| exceeded |r_{i-1}| (the
                     * guess for the coming y_j): near 1 when the preconditioned operator is
                     * well conditioned, far above on the bracket's y component at 103k */
                    double rj = fabs(kr->gv[c][j]), used = 0.0, y[64];
                    kr->gv0[c][j] = rj;
                    ls_solve(kr, c, j, y);
                    for (int i = 0; i < j; ++i) {
                        used += fabs(y[i]) * kr->eb[c][i];
                        if (kr->gv0[c][i] > 0.0)
                            kr->grow[c] = fmax(kr->grow[c], fabs(y[i]) / kr->gv0[c][i]);
                    }
                    double left = fmax(0.0, CM_RBF_RELAX_BUDGET * goal[c] - used);
                    if (kr->exact[c]) left = 0.0;
                    allow[u] = 0.5 * left / (kr->grow[c] * (rj > 0.0 ? rj : 1.0));
                    tau = fmin(tau, sz[u] > 0.0 ? allow[u] / sz[u] : INFINITY);
                }
                int lev, kind = relax_pick(kr, tau, &lev), lev2;
                if (kr->relax_tree && !(kind == MV_FAST && lev == 0) &&
                    relax_pick(kr, tau * CM_RBF_S_SLACK, &lev2) != kind) {
                    /* the safe bound on S is a few times too large and a cheaper kind is
                     * within that: S itself, by the loosest treecode (positive weights, so
                     * exact to 1e-6 of the result), cheaper than the products it saves */
                    double *ab[4], *ao[4];
                    for (int u = 0; u < na; ++u) {
                        ab[u] = kr->aux + (size_t)u * m;
                        ao[u] = kr->awlo + (size_t)u * m;
                        for (size_t i = 0; i < m; ++i) ab[u][i] = fabs(zo[u][i]);
                    }
                    matvec_kind(r, kr, MV_FAST, 0, na, ab, ao, threads);
                    tau = INFINITY;
                    for (int u = 0; u < na; ++u) {
                        sz[u] = fmin(sz[u], 1.01 * norm_inf(m, ao[u]));
                        tau = fmin(tau, sz[u] > 0.0 ? allow[u] / sz[u] : INFINITY);
                    }
                    kind = relax_pick(kr, tau, &lev);
                }
                kind = matvec_kind(r, kr, kind, lev, na, zo, wo, threads);
                cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: cycle %d, step %d: %s product (error "
                       "allowed %.3g x diam^3 sum |z|)", cycle, j + 1,
                       kind == MV_COMP ? "compensated" : kind == MV_PLAIN ? "plain" : "treecode",
                       tau);
                /* compensated products are charged nothing (rel 0): against the operator
                 * the exact residual uses (the same rounded entries) they err only by their
                 * result's rounding, which the stored basis vectors of any floating-point
                 * GMRES have too. Charged as eps |A z_j| x |y_j| (the y_j huge where the
                 * preconditioned directions cancel) it filled the budget in the first cycle
                 * (brackets 60k / 103k, two bodies: 1e-10..2e-8 against 5e-11) and forbade
                 * relaxing from then on, with nothing of it in the exact residuals */
                const double rel = kind == MV_FAST ? relax_tree_tol[lev]
                                   : kind == MV_PLAIN ? CM_RBF_PLAIN_ERR : 0.0;
                for (int u = 0; u < na; ++u) kr->eb[act[u]][j] = rel * sz[u];
            }
            int keep = 0;
            for (int u = 0; u < na; ++u) {
                int c = act[u];
                double *wv = wo[u], *h = kr->h[c] + (size_t)j * (size_t)(R + 1);
                project(r->iter->q1, m, r->k, wv);
                for (int pass = 0; pass < 2; ++pass) /* classical Gram-Schmidt, twice */
                    for (int i = 0; i <= j; ++i) {
                        const double *vv = kr->v[c] + (size_t)i * m;
                        double s = cblas_ddot((int)m, vv, 1, wv, 1);
                        h[i] = (pass ? h[i] : 0.0) + s;
                        cblas_daxpy((int)m, -s, vv, 1, wv, 1);
                    }
                double hn = cblas_dnrm2((int)m, wv, 1);
                h[j + 1] = hn;
                if (hn > 0.0) cblas_dscal((int)m, 1.0 / hn, wv, 1);
                for (int i = 0; i < j; ++i) { /* earlier rotations */
                    double t = kr->cs[c][i] * h[i] + kr->sn[c][i] * h[i + 1];
                    h[i + 1] = -kr->sn[c][i] * h[i] + kr->cs[c][i] * h[i + 1];
                    h[i] = t;
                }
                double d = hypot(h[j], h[j + 1]);
                double cs = d > 0.0 ? h[j] / d : 1.0, sn = d > 0.0 ? h[j + 1] / d : 0.0;
                kr->cs[c][j] = cs;
                kr->sn[c][j] = sn;
                h[j] = d;
                h[j + 1] = 0.0;
                kr->gv[c][j + 1] = -sn * kr->gv[c][j];
                kr->gv[c][j] *= cs;
                jn[c] = j + 1;
                est[c] = fabs(kr->gv[c][j + 1]);
                ++iters[c];
                int done = fabs(kr->gv[c][j + 1]) <= target[c] || hn == 0.0 ||
                           fabs(kr->gv[c][j + 1]) <= CM_RBF_CYCLE_GAIN * cycle0[c] ||
                           iters[c] >= o->max_iterations;
                if (!done) act[keep++] = c;
            }
            na = keep;
            /* one preconditioned product per component and iteration done */
            int most = 0;
            for (int c = 0; c < g; ++c) most = iters[c] > most ? iters[c] : most;
            cm_status ps = cm_progress(ctx, "rbf solve", (double)most, (double)o->max_iterations);
            if (ps < 0) return ps;
        }
        /* w += Z y, H y = g (upper triangular after the rotations) */
        for (int c = 0; c < g; ++c) {
            if (jn[c] == 0) continue;
            double y[64];
            ls_solve(kr, c, jn[c], y);
            /* w += Z y in double-double: the terms y_i z_i are much larger than their sum
             * (the preconditioned directions cancel), and the rounding of a plain daxpy
             * then left the true residual of a cycle 10-100x above GMRES's estimate, which
             * cost a whole restart cycle (bracket 59k: 7 of 21 iterations) */
            if (kr->relax) { /* the bound on what the inexact products moved the residual */
                double gap = 0.0;
                for (int i = 0; i < jn[c]; ++i) {
                    gap += fabs(y[i]) * kr->eb[c][i];
                    if (kr->gv0[c][i] > 0.0)
                        kr->grow[c] = fmax(kr->grow[c], fabs(y[i]) / kr->gv0[c][i]);
                }
                /* past the budget (the relaxed products' bounds with a huge y_j): no more
                 * relaxing */
                if (gap > CM_RBF_RELAX_BUDGET * goal[c]) kr->exact[c] = 1;
                cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: component %d, cycle %d: gap bound of "
                       "the relaxed products %.3g (the cycle's goal %.3g)", c, cycle,
                       gap / fnorm[c], goal[c] / fnorm[c]);
            }
            double *wh = w + (size_t)c * m, *wl = kr->wlo + (size_t)c * m;
            for (int i = 0; i < jn[c]; ++i) {
                const double yi = y[i], *zi = kr->z[c] + (size_t)i * m;
                for (size_t u = 0; u < m; ++u) {
                    double p = yi * zi[u];
                    double pe = fma(yi, zi[u], -p);
                    double t = wh[u] + p, bv = t - wh[u];
                    double te = (wh[u] - (t - bv)) + (p - bv);
                    wh[u] = t;
                    wl[u] += te + pe;
                }
            }
        }
    }
    /* the low parts stay in kr->wlo for the caller to fold in (or to keep, in a refinement);
     * aw = A(w + wlo) from the last true residual */
    for (int c = 0; c < g; ++c) status[c] = state[c];
    return CM_OK;
}

/* The bound, relative to fmax, on the error of plain direct sums of A w if it is at most
 * CM_RBF_PLAIN_RES_SHARE of the tolerance, else -1 (compensated sums are needed). Plain sums
 * err by at most CM_RBF_PLAIN_ERR x S(w), S(w) = max_i sum_j |w_j| phi_ij (by the loosest
 * treecode on |w|). Why: a loose solve does not need the compensated product,
 * which costs 1.5-2x a plain one (the fixed-binade update per entry and component,
 * rbf_r3_avx512.h); at 10^6 centres to 1e-6 it was the one exact residual, 320 of 1,044 CPU
 * s on Zen 5, where S(w) is 1.9e5 x max |f| and the bound 1.9e-8 (measured plain errors are
 * 7x below it; RESULTS.md, RBF solvers). The caller adds the
 * bound to the residual it compares with the tolerance. Only tried from a relative
 * tolerance of CM_RBF_PLAIN_RES_TOL: on real sets S(w) is 1e4..1e9 x max |f|, so below it
 * the loose treecode's product on |w| would be spent for nothing. absw, out: g x m scratch
 * (kr->soa and kr->rowm are the product's). */
#define CM_RBF_PLAIN_RES_TOL 1e-8
#define CM_RBF_PLAIN_RES_SHARE 0.1
static double plain_bound(const cm_rbf *r, krylov *kr, const double *w, double tol,
                          double fmax, double *absw, double *out, int threads)
{
    const size_t m = kr->m, gm = (size_t)kr->g * m;
    if (!(tol >= CM_RBF_PLAIN_RES_TOL) || !(fmax > 0.0)) return -1.0;
    double *in[4], *res[4];
    for (int c = 0; c < kr->g; ++c) in[c] = absw + (size_t)c * m, res[c] = out + (size_t)c * m;
    for (size_t i = 0; i < gm; ++i) absw[i] = fabs(w[i]);
    /* positive weights: the loosest treecode (1e-6 of the sums) is enough for a bound */
    if (matvec_kind(r, kr, MV_FAST, 0, kr->g, in, res, threads) != MV_FAST) return -1.0;
    const double bound = CM_RBF_PLAIN_ERR * norm_inf(gm, out) / fmax;
    return bound <= CM_RBF_PLAIN_RES_SHARE * tol ? bound : -1.0;
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
 * 10 iterations, no fallback). A component whose fast solve stagnated, or whose
 * steps stopped above the tolerance and above its floor, is then solved afresh with direct
 * (compensated, relaxed) matvecs
 * (*direct = 1): the fast work is lost, but the cost is bounded by one direct solve. steps:
 * exact residuals formed; first: the residual after the first solve. */
static cm_status refine_group(cm_context *ctx, const cm_rbf *r, krylov *kr, const double *f,
                              double fmax_all, double *w, double *aw, int *iters,
                              double *floor_rel, int *status, int *steps, double *first,
                              int *direct, int threads)
{
    const size_t m = kr->m;
    const int g = kr->g;
    const cm_rbf_options *o = &r->opt;
    const cm_rbf_tuning *tu = &r->tun;
    const size_t gm = (size_t)g * m;
    double *rhs = malloc(gm * sizeof *rhs), *dw = malloc(gm * sizeof *dw);
    double *adw = malloc(gm * sizeof *adw), *wl = calloc(gm, sizeof *wl);
    double *soa = malloc(gm * sizeof *soa), *rowm = malloc(gm * sizeof *rowm);
    if (!rhs || !dw || !adw || !wl || !soa || !rowm) {
        free(rhs), free(dw), free(adw), free(wl), free(soa), free(rowm);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_solve: out of memory for the refinement");
    }
    memcpy(rhs, f, gm * sizeof *rhs);
    memset(w, 0, gm * sizeof *w);
    for (int c = 0; c < g; ++c) iters[c] = 0;
    double prev[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
    int done[4] = {0, 0, 0, 0}, last = 0; /* last: this step is the direct one */
    const cm_rbf_tree *tree = kr->tree; /* restored with relax after a direct step */
    const int relax = kr->relax;
    for (int step = 0;; ++step) {
        double rn = 0.0;
        for (int c = 0; c < g; ++c)
            if (!done[c]) rn = fmax(rn, norm_inf(m, rhs + (size_t)c * m));
        double tol = tu->fast_refine > 0 && !last
                         ? fmax(o->tolerance, CM_RBF_REFINE_GAIN * rn / fmax_all)
                         : o->tolerance;
        int it[4], stt[4];
        cm_status sg = solve_group(ctx, r, kr, rhs, fmax_all, tol, dw, adw, it, floor_rel, stt,
                                   threads);
        if (sg < 0) { /* interrupted */
            kr->tree = tree;
            kr->relax = relax;
            free(rhs), free(dw), free(adw), free(wl), free(soa), free(rowm);
            return sg;
        }
        for (size_t i = 0; i < gm; ++i) { /* w += dw + dw_lo in double-double (TwoSum) */
            double t = w[i] + dw[i], bv = t - w[i];
            wl[i] += (w[i] - (t - bv)) + (dw[i] - bv) + kr->wlo[i];
            w[i] = t;
        }
        for (int c = 0; c < g; ++c) iters[c] += it[c];
        if (tu->fast_refine == 0) { /* the treecode's own residual: A w = A dw here */
            memcpy(aw, adw, gm * sizeof *aw);
            for (int c = 0; c < g; ++c) status[c] = stt[c];
            break;
        }
        /* the exact residual f - A w_hi - A w_lo; A w_hi plainly where that is exact enough
         * (then within pb of the exact one) */
        const double pb = plain_bound(r, kr, w, o->tolerance, fmax_all, dw, adw, threads);
        double *wc[4], *awc[4];
        for (int c = 0; c < g; ++c) wc[c] = w + (size_t)c * m, awc[c] = aw + (size_t)c * m;
        matvec_kind(r, kr, pb >= 0.0 ? MV_PLAIN : MV_COMP, 0, g, wc, awc, threads);
        if (cm_rbf_tree_sum_self(tree, wl, g, rowm, (size_t)g, threads) == 0)
            for (int c = 0; c < g; ++c)
                for (size_t i = 0; i < m; ++i) aw[(size_t)c * m + i] += rowm[i * (size_t)g + (size_t)c];
        ++kr->mv[MV_FAST];
        ++*steps;
        int running = 0, stop[4], nstop = 0;
        double res[4];
        for (int c = 0; c < g; ++c) {
            double *rv = rhs + (size_t)c * m;
            for (size_t i = 0; i < m; ++i) rv[i] = f[(size_t)c * m + i] - aw[(size_t)c * m + i];
            project(r->iter->q1, m, r->k, rv);
            res[c] = norm_inf(m, rv) / fmax_all;
            if (step == 0) *first = fmax(*first, res[c]);
            cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: component %d, refinement %d: %d "
                   "iterations (%s matvecs), exact residual %.3g", c, step + 1, it[c],
                   last ? "direct" : "fast", res[c]);
            if (done[c]) continue;
            if (res[c] + fmax(pb, 0.0) <= o->tolerance) done[c] = 1, status[c] = 1;
            /* stt 3: the fast Krylov solve itself stagnated above its floor (see above) */
            else if (last || step + 1 >= tu->fast_refine || res[c] > 0.5 * prev[c] ||
                     stt[c] == 3) {
                done[c] = 1, status[c] = stt[c] == 1 ? 3 : stt[c];
                if (!last) stop[nstop++] = c;
            }
            prev[c] = res[c];
        }
        if (nstop > 0) {
            /* stopped above the tolerance: at the floor of w (the rounding of its own sums,
             * eps max_i sum_j |w_j| phi_ij, by the treecode on |w|), or short of it */
            for (size_t i = 0; i < gm; ++i) dw[i] = fabs(w[i]);
            if (cm_rbf_tree_sum_self(tree, dw, g, rowm, (size_t)g, threads) == 0) {
                ++kr->mv[MV_FAST];
                for (int u = 0; u < nstop; ++u) {
                    const int c = stop[u];
                    double s = 0.0;
                    for (size_t i = 0; i < m; ++i) s = fmax(s, rowm[i * (size_t)g + (size_t)c]);
                    if (res[c] > CM_RBF_FLOOR_SLACK * DBL_EPSILON * s / fmax_all)
                        done[c] = 0, last = 1;
                }
            }
        }
        for (int c = 0; c < g; ++c) running += !done[c];
        if (!running) break;
        if (last) { /* a component reopened above: every open one is solved afresh with
                     * direct matvecs, relaxed as in a direct solve (one step for the group,
                     * then all are done). Afresh, not as a correction: what the fast steps
                     * leave is what the preconditioner handles worst (two bodies: 47
                     * iterations for the correction of 4.8e-5, 11 for the whole solve) */
            kr->tree = NULL;
            kr->relax = tu->relax;
            *direct = 1;
            for (int c = 0; c < g; ++c)
                if (!done[c]) {
                    const size_t o0 = (size_t)c * m;
                    memcpy(rhs + o0, f + o0, m * sizeof *rhs);
                    memset(w + o0, 0, m * sizeof *w);
                    memset(wl + o0, 0, m * sizeof *wl);
                }
        }
        for (int c = 0; c < g; ++c) /* converged components: nothing more to add */
            if (done[c]) memset(rhs + (size_t)c * m, 0, m * sizeof *rhs);
    }
    kr->tree = tree;
    kr->relax = relax;
    for (size_t i = 0; i < gm; ++i) w[i] += wl[i];
    free(rhs), free(dw), free(adw), free(wl), free(soa), free(rowm);
    return CM_OK;
}

cm_status cm_rbf_iterative_solve(cm_context *ctx, cm_rbf *r, size_t nc, const double *f,
                                 double *w, double *q, int threads)
{
    const size_t m = r->m, k = (size_t)r->k;
    const cm_rbf_options *o = &r->opt;
    const cm_rbf_tuning *tu = &r->tun;
    const int R = o->restart < 63 ? o->restart : 63;
    const int gmax = nc < 4 ? (int)nc : 4;
    /* put back if the solve fails or stops: the weights stay the last solve's */
    const double fmax_before = r->iter->fmax;
    krylov kr;
    memset(&kr, 0, sizeof kr);
    kr.m = m;
    kr.R = R;
    int ok = 1;
    for (int c = 0; c < gmax; ++c) {
        kr.v[c] = cm_alloc_large((size_t)(R + 1) * m * sizeof(double), 0);
        kr.z[c] = cm_alloc_large((size_t)R * m * sizeof(double), 0);
        kr.h[c] = calloc((size_t)(R + 1) * (size_t)R, sizeof(double));
        ok = ok && kr.v[c] && kr.z[c] && kr.h[c];
    }
    kr.soa = malloc((size_t)gmax * m * sizeof(double));
    kr.rowm = malloc((size_t)gmax * m * sizeof(double));
    kr.aux = malloc((size_t)gmax * m * sizeof(double));
    kr.wlo = malloc((size_t)gmax * m * sizeof(double));
    kr.awlo = malloc((size_t)gmax * m * sizeof(double));
    double *aw = malloc(nc * m * sizeof *aw);
    cm_status st = CM_OK;
    if (!ok || !kr.soa || !kr.rowm || !kr.aux || !kr.wlo || !kr.awlo || !aw) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_solve: out of memory for the Krylov basis "
                      "(%.3g GB)", (double)(2 * R + 1) * (double)m * gmax * 8e-9);
        goto done;
    }
    const double fmax_all = norm_inf(nc * m, f);
    cm_rbf_iterative_set_scale(r, fmax_all);
    const int fast = o->fast_sum == 1 || (o->fast_sum < 0 && m >= CM_RBF_FAST_MIN_M);
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
    int maxit = 0, floor_hit = 0, stagnated = 0, maxed = 0, steps = 0, direct = 0;
    double floor_max = 0.0, first = 0.0;
    for (size_t c0 = 0; c0 < nc; c0 += 4) {
        kr.g = nc - c0 < 4 ? (int)(nc - c0) : 4;
        int iters[4], status[4];
        double fl[4];
        if (fast)
            st = refine_group(ctx, r, &kr, f + c0 * m, fmax_all, w + c0 * m, aw + c0 * m, iters,
                              fl, status, &steps, &first, &direct, threads);
        else {
            st = solve_group(ctx, r, &kr, f + c0 * m, fmax_all, o->tolerance, w + c0 * m,
                             aw + c0 * m, iters, fl, status, threads);
            for (size_t i = 0; i < (size_t)kr.g * m; ++i) w[c0 * m + i] += kr.wlo[i];
        }
        if (st != CM_OK) goto done;
        for (int c = 0; c < kr.g; ++c) {
            if (iters[c] > maxit) maxit = iters[c];
            if (fl[c] > floor_max) floor_max = fl[c];
            floor_hit |= status[c] == 2;
            stagnated |= status[c] == 3;
            maxed |= status[c] == 4;
        }
    }
    /* polynomial: R q = Q1'(f - A w); then the residual at the centres, exactly */
    double worst = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        const double *fc = f + c * m, *ac = aw + c * m;
        double *qc = q + c * k, t[4];
        double *g = kr.soa;
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
     * gives at the centres): eps max_i sum_j |w_j| phi_ij, for all components at once */
    for (size_t c0 = 0; c0 < nc; c0 += 4) {
        int g = nc - c0 < 4 ? (int)(nc - c0) : 4;
        /* an estimate: the treecode's error on positive weights is fast_tol (or, the loosest
         * relaxed one, 1e-6) of the sum; counted with the products */
        double *ab[4], *ao[4];
        for (int u = 0; u < g; ++u) {
            ab[u] = kr.aux + (size_t)u * m;
            ao[u] = kr.awlo + (size_t)u * m;
            for (size_t i = 0; i < m; ++i) ab[u][i] = fabs(w[(c0 + (size_t)u) * m + i]);
        }
        if (kr.tree) matvec(r, &kr, g, ab, ao, threads);
        else matvec_kind(r, &kr, kr.relax_tree ? MV_FAST : MV_PLAIN, 0, g, ab, ao, threads);
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
                            (size_t)gmax * (size_t)(2 * R + 6) * m * sizeof(double) +
                            (fast ? cm_rbf_tree_bytes(kr.tree) + (size_t)gmax * 6 * m * sizeof(double) : 0) +
                            cm_rbf_tree_bytes(r->iter->rtree[0]) +
                            cm_rbf_tree_bytes(r->iter->rtree[1]) +
                            cm_rbf_tree_bytes(r->iter->rtree[2]);
    if (worst > o->tolerance && !r->stats.floor_limited)
        st = cm_error(ctx, CM_WARNING,
                      "cm_rbf_solve: the iterative solver %s after %d iterations at a relative "
                      "residual of %.3g (tolerance %.3g, attainable floor %.3g)",
                      stagnated ? "stagnated" : maxed ? "reached max_iterations" : "stopped",
                      maxit, worst, o->tolerance, floor_max);
done:
    if (st < 0) cm_rbf_iterative_set_scale(r, fmax_before);
    for (int c = 0; c < 4; ++c) free(kr.v[c]), free(kr.z[c]), free(kr.h[c]);
    free(kr.soa), free(kr.rowm), free(kr.aux), free(kr.wlo), free(kr.awlo), free(aw);
    return st;
}
