/* The driver of the iterative solve (rbf_fgmres.c has the Krylov iteration): the columns
 * in groups that fit the memory budget, warm starts, the fast solve's refinement on exact
 * residuals, the polynomial part, the floor and the figures. */
#include "rbf_krylov.h"

#include <cblas.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* The bound, relative to the column's scale, on the error of plain direct sums of A w if it
 * is at most CM_RBF_PLAIN_RES_SHARE of the tolerance, else -1 (compensated sums are needed),
 * into col[c].pb for the n columns list[]. Plain sums err by at most CM_RBF_PLAIN_ERR x S(w),
 * S(w) = max_i sum_j |w_j| phi_ij (by the loosest treecode on |w|). Why: a loose solve does
 * not need the compensated product, which costs 1.5-2x a plain one (the fixed-binade update
 * per entry and component, rbf_r3_avx512.h); at 10^6 centres to 1e-6 it was the one exact
 * residual, 320 of 1,044 CPU s on Zen 5, where S(w) is 1.9e5 x max |f| and the bound 1.9e-8
 * (measured plain errors are 7x below it; RESULTS.md, RBF solvers). The caller adds the
 * bound to the residual it compares with the tolerance. Only tried from a relative
 * tolerance of CM_RBF_PLAIN_RES_TOL (rbf_iter.h). absw, out: g x m scratch. */
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
    if (cm_krylov_matvec_kind(r, kr, MV_FAST, 0, n, in, res, threads) != MV_FAST) return;
    for (int u = 0; u < n; ++u) {
        kcol *k = &kr->col[list[u]];
        if (!(k->fnorm > 0.0)) continue;
        k->pb = cm_rbf_plain_bound(cm_krylov_norm_inf(m, res[u]), k->fnorm, tol);
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
        cm_krylov_matvec_kind(r, kr, MV_COMP, 0, nw, kr->pa, kr->pb, threads);
        for (int u = 0; u < nw; ++u) {
            const int c = sel[u];
            kcol *k = &kr->col[c];
            const size_t o0 = (size_t)c * m;
            const double rn = cm_krylov_residual(r, m, f + o0, aw + o0, rhs + o0);
            const double fn = cm_krylov_norm_inf(m, f + o0);
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
            const double rn = cm_krylov_norm_inf(m, rhs + (size_t)c * m);
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
            st = cm_krylov_solve_group(ctx, r, kr, rhs, ns, sel, dw, adw, threads);
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
            cm_krylov_add_dd(m, w + o0, wl + o0, dw + o0, kr->wlo + o0); /* w += dw + dw_lo */
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
            cm_krylov_matvec_kind(r, kr, kind, 0, nk, kr->pa, kr->pb, threads);
        }
        for (int u = 0; u < n; ++u) {
            kr->pa[u] = wl + (size_t)sel[u] * m;
            kr->pb[u] = adw + (size_t)sel[u] * m;
        }
        cm_krylov_product(r, kr, MV_FAST, tree, -1, n, kr->pa, kr->pb, threads);
        ++kr->mv[MV_FAST];
        ++*steps;
        int nstop = 0;
        for (int u = 0; u < n; ++u) {
            const int c = sel[u];
            kcol *k = &kr->col[c];
            const size_t o0 = (size_t)c * m;
            double *rv = rhs + o0;
            for (size_t i = 0; i < m; ++i) aw[o0 + i] += adw[o0 + i];
            const double rn = cm_krylov_residual(r, m, f + o0, aw + o0, rv);
            const double res = k->fnorm > 0.0 ? rn / k->fnorm : 0.0;
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
            if (cm_krylov_product(r, kr, MV_FAST, tree, -1, nstop, kr->pa, kr->pb, threads) == MV_FAST) {
                ++kr->mv[MV_FAST];
                for (int u = 0; u < nstop; ++u) {
                    kcol *k = &kr->col[stop[u]];
                    const double s = cm_krylov_norm_inf(m, kr->pb[u]);
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

/* Centres at which a solve that met a tolerance below CM_RBF_PLAIN_RES_TOL estimates S(w)
 * for the reported floor (spread over them; all of them below this many) */
#define CM_RBF_FLOOR_SAMPLES 1024

/* Bounds on S(w0) = max_i sum_j |w0_j| phi_ij of a start w0 (m): the one from above returned,
 * the one from below in *low (-1: none). S is subadditive and phi_ij <= diam^3, so for any of
 * the fit's last weights v whose S its solve knew (cm_rbf_scales), or of this solve's
 * earlier groups (wnow, now: their nnow columns), S(w0) <= S(v) + diam^3
 * sum |w0 - v| (the nearest v taken) and S(w0) >= S_min(v) - diam^3 sum |w0 - v|. Why: a
 * start's plain check summed |w0| beside w0 to bound its rounding, half of the check's
 * columns; the starts of a study's batch lie near the last batch's solutions (bore, 20.6k
 * centres: 1.05-1.5x S(w0), RESULTS.md, Study), and the check needs S only within the plain
 * bound's margin. Where even the bound from below forbids plain sums, a plain check would go
 * for nothing (rbf_fgmres.c, check_products). */
/* The bounds of start_s_bounds from the n columns of weights wv (m each) whose S sc knew:
 * the least from above into *best, the largest from below into *low (both -1: none yet). */
static void nearest_bounds(const double *w0, size_t m, double diam3, const double *wv,
                           const cm_rbf_scales *sc, size_t n, double *best, double *low)
{
    for (size_t v = 0; v < n; ++v) {
        if (!(sc->smax[v] >= 0.0)) continue;
        double l1 = 0.0;
        for (size_t i = 0; i < m; ++i) l1 += fabs(w0[i] - wv[v * m + i]);
        /* smax: plain sums of |w| or the loosest treecode's (1e-6 of the sums) */
        const double b = 1.01 * sc->smax[v] + diam3 * l1;
        if (*best < 0.0 || b < *best) *best = b;
        if (sc->smin[v] >= 0.0) *low = fmax(*low, sc->smin[v] - diam3 * l1);
    }
}

static double start_s_bounds(const cm_rbf *r, const double *w0, double diam3,
                             const double *wnow, const cm_rbf_scales *now, size_t nnow,
                             double *low)
{
    double best = -1.0;
    *low = -1.0;
    const cm_rbf_scales *last = &r->iter->scales;
    if (r->w && last->n == (size_t)r->ncomp)
        nearest_bounds(w0, r->m, diam3, r->w, last, last->n, &best, low);
    if (now) nearest_bounds(w0, r->m, diam3, wnow, now, nnow, &best, low);
    return best;
}

/* The polynomial part of the g columns at c0, R q = Q1'(f - A w), then their residual at
 * the centres, exactly (from A w): the largest, relative to fscale. */
static double finish_columns(const cm_rbf *r, krylov *kr, const double *f, const double *aw,
                             double *q, size_t c0, int g, double fscale)
{
    const size_t m = r->m, k = (size_t)r->k;
    double worst = 0.0;
    for (size_t c = c0; c < c0 + (size_t)g; ++c) {
        const double *fc = f + c * m, *ac = aw + c * m;
        double *qc = q + c * k, t[4];
        double *d = kr->pin;
        for (size_t i = 0; i < m; ++i) d[i] = fc[i] - ac[i];
        for (size_t a = 0; a < k; ++a) t[a] = cblas_ddot((int)m, r->iter->q1 + a * m, 1, d, 1);
        for (int i = (int)k - 1; i >= 0; --i) {
            double s = t[i];
            for (size_t j = (size_t)i + 1; j < k; ++j) s -= r->qr[j * m + (size_t)i] * qc[j];
            qc[i] = s / r->qr[(size_t)i * m + (size_t)i];
        }
        double e = 0.0;
        for (size_t i = 0; i < m; ++i) {
            double p = qc[0] + qc[1] * r->c[i] + qc[2] * r->c[m + i] + qc[3] * r->c[2 * m + i];
            e = fmax(e, fabs(d[i] - p));
        }
        worst = fmax(worst, fscale > 0.0 ? e / fscale : 0.0);
    }
    return worst;
}

/* The attainable exactness of plain direct sums of the g columns' weights at c0: S(w) =
 * max_i sum_j |w_j| phi_ij, in one pass for those whose checks did not sum or bound it: the
 * floor, eps S(w), and each column's smax (whether the evaluation may sum plainly, and the
 * bound on the next starts near these weights, start_s_bounds). An estimate: the treecode's
 * error on positive weights is fast_tol (or, the loosest relaxed one, 1e-6) of the sum;
 * counted with the products. sampled (every column met a tolerance below
 * CM_RBF_PLAIN_RES_TOL, where the evaluation sums compensated whatever smax): the floor is
 * only reported, estimated at CM_RBF_FLOOR_SAMPLES of the centres, and smax left unknown, a
 * pass fewer per solve (0.1 s of a 1.4 s warm solve of 15 columns on the bore, 20.6k
 * centres). Returns the largest eps S(w) relative to fscale. */
static double s_pass(const cm_rbf *r, krylov *kr, const double *w, size_t c0, int g,
                     cm_rbf_scales *scales, int sampled, double fscale, int threads)
{
    const size_t m = r->m;
    double floor_max = 0.0;
    int ns = 0;
    for (int u = 0; u < g; ++u) {
        if (scales && scales->smax[c0 + (size_t)u] >= 0.0) continue;
        kr->pa[ns] = kr->aux + (size_t)ns * m;
        kr->pb[ns] = kr->awlo + (size_t)ns * m;
        for (size_t i = 0; i < m; ++i) kr->pa[ns][i] = fabs(w[(c0 + (size_t)u) * m + i]);
        ++ns;
    }
    /* the full sums into kr->pb[], or the sampled maxima into kr->awlo[0..ns) */
    if (!sampled) cm_krylov_matvec_loose(r, kr, ns, kr->pa, kr->pb, threads);
    else if (ns > 0 && cm_rbf_abs_sums(r, kr->aux, ns, m, r->c, CM_RBF_FLOOR_SAMPLES,
                                       kr->awlo, threads) != 0)
        memset(kr->awlo, 0, (size_t)ns * sizeof *kr->awlo); /* out of memory: none */
    for (int u = 0, v = 0; u < g; ++u) {
        double *sp = scales ? &scales->smax[c0 + (size_t)u] : NULL;
        double sm;
        if (sp && *sp >= 0.0) sm = *sp;
        else if (sampled) sm = kr->awlo[v++];
        else {
            sm = cm_krylov_norm_inf(m, kr->pb[v++]);
            if (sp) {
                *sp = sm;
                scales->smin[c0 + (size_t)u] = CM_RBF_LOOSE_LOW * sm;
            }
        }
        if (fscale > 0.0) floor_max = fmax(floor_max, DBL_EPSILON * sm / fscale);
    }
    return floor_max;
}

/* The fit's history of solutions, made on first use: warm_history pairs, at most what an
 * eighth of the memory budget holds; NULL if none (warm_history 0, out of memory). */
static cm_rbf_history *history_of(cm_rbf *r)
{
    cm_rbf_iter *it = r->iter;
    if (!it->hist && r->tun.warm_history > 0) {
        const double budget = cm_memory_budget(), pair = 2.0 * (double)r->m * sizeof(double);
        size_t cap = (size_t)r->tun.warm_history;
        if (budget > 0.0 && (double)cap * pair > budget / 8.0) cap = (size_t)(budget / 8.0 / pair);
        it->hist = cm_rbf_history_create(r->m, cap);
    }
    return it->hist;
}

int cm_rbf_iterative_column_iterations(const cm_rbf *r, size_t c)
{
    if (!r || !r->iter || c >= r->iter->col_n) return -1;
    return r->iter->col_iters[c];
}

/* The solve's Krylov restart, whether it takes fast sums, and its columns per group: what
 * fits the memory budget (half the machine's by default, per_col bytes a column), and with
 * warm groups (options warm_groups) fields of dim columns each, in groups that each start
 * from the solutions of the groups before them. */
static size_t column_groups(const cm_rbf *r, size_t nc, int *R, int *fast, double *per_col)
{
    const cm_rbf_options *o = &r->opt;
    const double budget =
        r->tun.krylov_budget > 0.0 ? r->tun.krylov_budget : cm_memory_budget();
    *R = o->restart < 63 ? o->restart : 63;
    *fast = o->fast_sum == 1 || (o->fast_sum < 0 && r->m >= CM_RBF_FAST_MIN_M);
    *per_col = bytes_per_column(r->m, *R, *fast);
    size_t gsize = nc;
    if (budget > 0.0 && (double)nc * *per_col > budget)
        gsize = budget / *per_col >= 1.0 ? (size_t)(budget / *per_col) : 1;
    if (o->warm_start && o->warm_groups > 1 && nc > 1) {
        const size_t d = r->dim > 0 ? (size_t)r->dim : 1, ng = (size_t)o->warm_groups;
        size_t per = (nc + ng - 1) / ng;
        per = (per + d - 1) / d * d;
        if (per < gsize) gsize = per;
    }
    return gsize;
}

/* The solve of the nc columns f (m each) in groups of consecutive columns. */
static cm_status solve_in_order(cm_context *ctx, cm_rbf *r, size_t nc, const double *f,
                                double *w, double *q, int threads)
{
    const size_t m = r->m, k = (size_t)r->k;
    const cm_rbf_options *o = &r->opt;
    const cm_rbf_tuning *tu = &r->tun;
    int R, fast;
    double per_col;
    const size_t gsize = column_groups(r, nc, &R, &fast, &per_col);
    krylov kr;
    memset(&kr, 0, sizeof kr);
    kr.m = m;
    kr.R = R;
    kr.all = nc;
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
    const double fmax_all = cm_krylov_norm_inf(nc * m, f);
    /* out of memory there only costs the evaluation its plain sums */
    cm_rbf_scales *scales =
        cm_rbf_iterative_scales_begin(r, nc, fmax_all) == 0 ? &r->iter->next : NULL;
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
    kr.diam3 = cm_rbf_diam3(r, 0, NULL);
    /* warm starts: each column from the combination of the earlier solutions that fits its
     * data best (rbf_iter.h, cm_rbf_history; tried in the first cycle, kept if it leaves a
     * residual below the data's) */
    cm_rbf_history *hist = o->warm_start && r->warm_ok ? history_of(r) : NULL;
    size_t basis = 0;
    int maxit = 0, floor_hit = 0, stagnated = 0, maxed = 0, steps = 0, direct = 0, groups = 0;
    int nwarm = 0, exact = 0;
    cm_rbf_exact_starts es;
    memset(&es, 0, sizeof es);
    double floor_max = 0.0, first = 0.0, warm_worst = 0.0, worst = 0.0;
    for (size_t c0 = 0; c0 < nc; c0 += gsize) {
        const int g = nc - c0 < gsize ? (int)(nc - c0) : (int)gsize;
        const int gall = kr.g;
        kr.g = g;
        kr.before = c0;
        ++groups;
        const double tg = cm_wtime();
        const int mv0 = mvk[MV_COMP] + mvk[MV_PLAIN] + mvk[MV_FAST];
        basis = hist ? hist->n : 0;
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
            kc->fnorm = fmax(cm_krylov_norm_inf(m, f + o0), tu->column_scale * fmax_all);
            kc->tol = o->tolerance;
            kc->warm = basis > 0;
            kc->sbound = kc->slow = -1.0;
            kc->took = 0;
            kc->warm_res = 0.0;
            kc->preset = 0;
            if (es.n > 0) { /* a start whose product is known: taken if known well enough */
                const double b = cm_rbf_exact_start(r, &es, f + o0, kc->v, w + o0,
                                                    kr.wlo + (size_t)c * m, aw + o0);
                if (b >= 0.0 && b <= CM_RBF_PLAIN_RES_SHARE * kc->tol * kc->fnorm) {
                    kc->warm = kc->preset = 1;
                    kc->cb = b / kc->fnorm;
                    kc->smax = kc->smin = -1.0;
                    ++exact;
                    continue;
                }
            }
            if (basis > 0) {
                double *pf = kc->v; /* scratch until the solve */
                memcpy(pf, f + o0, m * sizeof *pf);
                cm_krylov_project(r->iter->q1, m, r->k, pf);
                cm_rbf_history_start(hist, pf, w + o0);
                cm_krylov_project(r->iter->q1, m, r->k, w + o0);
                if (o->tolerance >= CM_RBF_PLAIN_RES_TOL && !fast)
                    kc->sbound = start_s_bounds(r, w + o0, kr.diam3, w, scales, c0, &kc->slow);
            }
        }
        if (fast)
            st = refine_group(ctx, r, &kr, f + c0 * m, w + c0 * m, aw + c0 * m, &steps, &first,
                              &direct, threads);
        else {
            int *sel = malloc((size_t)g * sizeof *sel);
            if (!sel) st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_solve: out of memory");
            else {
                for (int c = 0; c < g; ++c) sel[c] = c;
                st = cm_krylov_solve_group(ctx, r, &kr, f + c0 * m, g, sel, w + c0 * m, aw + c0 * m,
                                 threads);
                free(sel);
            }
            /* the first group's weights and products, the later groups' starts where their
             * checks would be compensated (rbf_exact_start.c) */
            if (st == CM_OK && c0 == 0 && (size_t)g < nc && hist &&
                o->tolerance < CM_RBF_PLAIN_RES_TOL)
                cm_rbf_exact_starts_make(r, &kr, g, w, kr.wlo, aw, &es);
            for (size_t i = 0; i < (size_t)g * m; ++i) w[c0 * m + i] += kr.wlo[i];
        }
        kr.g = gall;
        if (st != CM_OK) goto done;
        cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: group %d: %d columns, %d products, %.3f s; %d "
               "starts from the first group's products, unchecked", groups, g,
               mvk[MV_COMP] + mvk[MV_PLAIN] + mvk[MV_FAST] - mv0, cm_wtime() - tg, exact);
        exact = 0;
        /* the group's solutions join the history (their exact products: a pair is right
         * whatever the residual of its solve), so the next group starts from them, but for
         * those that took no step: such a w is the history's own combination, so what
         * Gram-Schmidt leaves of its product is rounding alone, and normalised that would be
         * a pair whose product is not its w's (on the bore at 1e-6 it made the fourth
         * batch's starts err by 1e-6 of |f|) */
        for (int c = 0; hist && c < g; ++c) {
            if (kr.col[c].iters == 0) continue;
            double *pb = kr.pin;
            memcpy(pb, aw + (c0 + (size_t)c) * m, m * sizeof *pb);
            cm_krylov_project(r->iter->q1, m, r->k, pb);
            cm_rbf_history_add(hist, w + (c0 + (size_t)c) * m, pb);
        }
        const double gworst = finish_columns(r, &kr, f, aw, q, c0, g, fmax_all);
        worst = fmax(worst, gworst);
        for (int c = 0; c < g; ++c) {
            const kcol *kc = &kr.col[c];
            col_iters[c0 + (size_t)c] = kc->iters;
            if (scales) { /* S(w) if a plain check summed it (not an inner solve's) */
                scales->fnorm[c0 + (size_t)c] = kc->fnorm;
                scales->smax[c0 + (size_t)c] = fast ? -1.0 : kc->smax;
                scales->smin[c0 + (size_t)c] = fast ? -1.0 : kc->smin;
                scales->start[c0 + (size_t)c] = kc->took ? kc->iters : -1.0;
            }
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
        const int sampled = gworst <= o->tolerance && o->tolerance < CM_RBF_PLAIN_RES_TOL;
        floor_max = fmax(floor_max, s_pass(r, &kr, w, c0, g, scales, sampled, fmax_all,
                                           threads));
    }
    /* the end (a column met at a restart's check took no step that reported it) */
    if (kr.shown < (double)nc) {
        const cm_status ps = cm_progress(ctx, "rbf solve", (double)nc, (double)nc);
        if (ps < 0) {
            st = ps;
            goto done;
        }
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
                            cm_rbf_tree_bytes(r->iter->rtree[2]) +
                            cm_rbf_history_bytes(r->iter->hist) + cm_rbf_exact_starts_bytes(&es);
    r->stats.column_groups = groups;
    r->stats.warm_columns = nwarm;
    r->stats.warm_residual = warm_worst;
    r->stats.warm_basis = (int)basis;
    if (worst > o->tolerance && !r->stats.floor_limited)
        st = cm_error(ctx, CM_WARNING,
                      "cm_rbf_solve: the iterative solver %s after %d iterations at a relative "
                      "residual of %.3g (tolerance %.3g, attainable floor %.3g)",
                      stagnated ? "stagnated" : maxed ? "reached max_iterations" : "stopped",
                      maxit, worst, o->tolerance, floor_max);
done:
    cm_rbf_exact_starts_free(&es);
    krylov_free(&kr);
    free(aw);
    return st;
}

/* a (nf fields of d entries of size bytes each, field i the caller's order[i]) into the
 * caller's order, through t (as large) */
static void fields_back(void *a, size_t size, const size_t *order, size_t nf, size_t d, void *t)
{
    const size_t fb = d * size;
    for (size_t i = 0; i < nf; ++i) memcpy((char *)t + order[i] * fb, (char *)a + i * fb, fb);
    memcpy(a, t, nf * fb);
}

/* The columns in the order of cm_rbf_history_order when they are solved in groups with warm
 * starts (each whole field of dim columns in one group, the fields that span the others first),
 * else as given. The results (w, q, the columns' iterations and scales) in the callers' order. */
cm_status cm_rbf_iterative_solve(cm_context *ctx, cm_rbf *r, size_t nc, const double *f,
                                 double *w, double *q, int threads)
{
    const size_t m = r->m, k = (size_t)r->k, d = r->dim > 0 ? (size_t)r->dim : 1;
    int R, fast;
    double per_col;
    const size_t gsize = column_groups(r, nc, &R, &fast, &per_col);
    cm_rbf_history *hist = r->opt.warm_start && r->warm_ok ? history_of(r) : NULL;
    if (!hist || gsize >= nc || nc % d != 0) return solve_in_order(ctx, r, nc, f, w, q, threads);
    /* the fields before the last group's start are picked; the rest is the last group */
    const size_t nf = nc / d, picks = ((nc - 1) / gsize * gsize + d - 1) / d;
    double *fp = malloc(2 * nc * m * sizeof *fp), *wp = fp ? fp + nc * m : NULL;
    double *qp = malloc(nc * k * sizeof *qp), *scale = malloc(nc * sizeof *scale);
    size_t *order = malloc(nf * sizeof *order);
    if (!fp || !qp || !scale || !order) { /* out of memory: the columns as they come */
        free(fp), free(qp), free(scale), free(order);
        return solve_in_order(ctx, r, nc, f, w, q, threads);
    }
    const double t0 = cm_wtime(), fmax_all = cm_krylov_norm_inf(nc * m, f);
    for (size_t c = 0; c < nc; ++c) {
        memcpy(fp + c * m, f + c * m, m * sizeof *fp);
        cm_krylov_project(r->iter->q1, m, r->k, fp + c * m);
        /* the columns' own scales, as the solve's tolerances (a column of round-off none) */
        const double fn = cm_krylov_norm_inf(m, f + c * m);
        scale[c] = fn >= r->tun.column_scale * fmax_all ? cblas_dnrm2((int)m, fp + c * m, 1) : 0.0;
    }
    cm_rbf_history_order(hist, m, nf, d, picks, fp, scale, order);
    char line[120] = "";
    int len = 0;
    for (size_t i = 0; i < nf && len < (int)sizeof line - 24; ++i)
        len += snprintf(line + len, sizeof line - (size_t)len, " %zu", order[i]);
    cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_solve: groups of %zu columns, the fields in the order%s%s "
           "(the columns below numbered in it; %.3f s)", gsize, line,
           len >= (int)sizeof line - 24 ? " ..." : "", cm_wtime() - t0);
    for (size_t i = 0; i < nf; ++i)
        memcpy(fp + i * d * m, f + order[i] * d * m, d * m * sizeof *fp);
    cm_status st = solve_in_order(ctx, r, nc, fp, wp, qp, threads);
    if (st == CM_OK || st == CM_WARNING) {
        r->stats.memory_bytes += (2 * nc * m + nc * k) * sizeof(double); /* the copies */
        for (size_t i = 0; i < nf; ++i) {
            memcpy(w + order[i] * d * m, wp + i * d * m, d * m * sizeof *w);
            memcpy(q + order[i] * d * k, qp + i * d * k, d * k * sizeof *q);
        }
        cm_rbf_scales *sc = &r->iter->next;
        double *by_column[4] = {sc->fnorm, sc->smax, sc->smin, sc->start};
        for (int a = 0; a < 4 && sc->n == nc; ++a)
            fields_back(by_column[a], sizeof(double), order, nf, d, fp);
        fields_back(r->iter->col_iters, sizeof(int), order, nf, d, fp);
    }
    free(fp), free(qp), free(scale), free(order);
    return st;
}
