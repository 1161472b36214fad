/* Two-level restricted additive Schwarz preconditioner for the r^3 + linear system (Beatson,
 * Light and Billings, "Fast solution of the radial basis function interpolation equations:
 * domain decomposition methods", SIAM J. Sci. Comput. 22, 2000; restricted variant of Cai
 * and Sarkis). The centres are split into kD-tree leaves; each leaf is grown to local_size
 * centres (the leaf first, then the centres nearest to its box) and the local interpolation
 * problem on that set is solved by the same null-space projected Cholesky as the dense path.
 * Only the leaf's own weights are kept (restricted), so the local inverses are stored as
 * their leaf rows only: G_l = Q2 (Q2' A_l Q2)^{-1} Q2' restricted to local x leaf, which is
 * m * local_size numbers over all leaves instead of sum local_size^2 for the factors, and
 * one application is one small matrix-vector product per leaf. A coarse space of
 * farthest-point centres is solved exactly first (multiplicative), so the local solves see
 * only the residual of the smooth, global part, and by default (coarse_post 1) once more
 * after them on what their correction left at the coarse centres: the residual then falls
 * ~30x per iteration instead of ~6x on the bracket (RESULTS.md, RBF solvers).
 * Storage (local_float): the rows can be kept in float at half the memory without costing
 * iterations, because the local linear fit is taken out of the data before the product
 * (G_l annihilates it in exact arithmetic, while its float rounding would multiply it).
 * Bodies (rbf_bodies.c): the local part of the correction keeps no linear moment on any
 * separate body before the coarse level sees it, so the bodies' relative motion is left to
 * the coarse level, which solves it.
 * Split set-up (rbf_petsc.c): a part builds and applies only its run of subdomains; the
 * parts' corrections add up to the whole one (and are projected after the sum). */
#include "rbf_internal.h"

#include <cblas.h>
#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#define CM_RBF_COARSE_BASE_M 2e4

struct cm_rbf_schwarz {
    size_t m;
    size_t nmax;      /* largest local set */
    int nsub;
    size_t *sub_ptr;  /* nsub + 1: offsets into sub_idx */
    size_t *sub_idx;  /* centre indices of each local set, its n_in leaf centres first */
    int *n_in;        /* nsub: leaf centres of each local set */
    /* local inverse rows of subdomain l, col-major local x n_in: the first hd[l] rows (its
     * own leaf's centres come first) in g64 + d_ptr[l], the rest in g32 + f_ptr[l] (float:
     * see store_local); only the subdomains of this part (l0 <= l < l1) are built */
    size_t *d_ptr;    /* nsub + 1 */
    size_t *f_ptr;    /* nsub + 1 */
    int *hd;          /* nsub */
    float *g32;
    double *g64;
    int l0, l1;       /* the subdomains this part owns (all: 0, nsub) */
    double *lq;       /* with float rows: nsub x nmax x 4, orthonormal basis of the linear
                       * polynomials on each own local set (idx order; zero columns past its
                       * rank), see cm_rbf_schwarz_apply_sum */
    size_t *q_ptr;    /* nsub + 1: offsets into lq */
    size_t nc;        /* coarse centres */
    size_t *c_idx;    /* nc */
    double *c_xyz;    /* 3 x nc SoA coordinates of the coarse centres */
    double *gc;       /* nc*nc + 8nc: projected Cholesky factor of the coarse system
                       * (cm_rbf_projected_factor), solved at every application: forming the
                       * inverse would cost 3x the factorisation */
    int c_rk;
    double c_tau[4];
    cm_rbf_coarse_inner *inner; /* coarse_inner > 0: the coarse problem solved by an inner
                       * Krylov method (rbf_schwarz_coarse.c) instead of gc */
    int post;         /* 0: coarse then local; 1: coarse, local, coarse; 2: local, coarse */
    cm_rbf_bodies *bodies; /* the separate bodies, see rbf_bodies.c */
    double fill;      /* largest distance from a centre to its nearest coarse centre */
    size_t bytes;
};

size_t cm_rbf_coarse_count(const cm_rbf_tuning *tu, size_t m)
{
    size_t nc = (size_t)tu->coarse_size;
    /* coarse_grow: coarse_size is the count at 2e4 centres, grown as sqrt(m) above, so that
     * the coarse spacing keeps closer to the fixed-size subdomains' reach (which shrinks as
     * m^-1/2) at O(m) memory for the coarse factor */
    if (tu->coarse_grow && (double)m > CM_RBF_COARSE_BASE_M)
        nc = (size_t)((double)nc * sqrt((double)m / CM_RBF_COARSE_BASE_M));
    if (tu->coarse_max > 0 && nc > (size_t)tu->coarse_max) nc = (size_t)tu->coarse_max;
    if (nc > m / 4) nc = m / 4; /* a coarse space as fine as the problem is no coarse space */
    return nc;
}

void cm_rbf_schwarz_destroy(cm_rbf_schwarz **pc)
{
    if (!pc || !*pc) return;
    cm_rbf_schwarz *p = *pc;
    free(p->sub_ptr);
    free(p->sub_idx);
    free(p->n_in);
    free(p->d_ptr);
    free(p->f_ptr);
    free(p->lq);
    free(p->q_ptr);
    free(p->hd);
    free(p->g32);
    free(p->g64);
    free(p->c_idx);
    free(p->c_xyz);
    free(p->gc);
    cm_rbf_coarse_inner_destroy(&p->inner);
    cm_rbf_bodies_destroy(&p->bodies);
    free(p);
    *pc = NULL;
}

size_t cm_rbf_schwarz_bytes(const cm_rbf_schwarz *pc) { return pc ? pc->bytes : 0; }
double cm_rbf_schwarz_fill(const cm_rbf_schwarz *pc) { return pc ? pc->fill : 0.0; }

const size_t *cm_rbf_schwarz_subdomain(const cm_rbf_schwarz *pc, int l, size_t *n, size_t *n_in)
{
    *n = *n_in = 0;
    if (!pc || l < 0 || l >= pc->nsub) return NULL;
    *n = pc->sub_ptr[l + 1] - pc->sub_ptr[l];
    *n_in = (size_t)pc->n_in[l];
    return pc->sub_idx + pc->sub_ptr[l];
}
int cm_rbf_schwarz_subdomains(const cm_rbf_schwarz *pc) { return pc ? pc->nsub : 0; }
int cm_rbf_schwarz_coarse(const cm_rbf_schwarz *pc) { return pc ? (int)pc->nc : 0; }
const cm_rbf_bodies *cm_rbf_schwarz_bodies(const cm_rbf_schwarz *pc) { return pc ? pc->bodies : NULL; }

static cm_status build_subdomains(cm_context *ctx, const cm_rbf *r, cm_rbf_schwarz *p,
                                  int threads)
{
    const size_t m = r->m;
    const cm_rbf_tuning *tu = &r->tun;
    cm_rbf_leaves t = {r->c, m, malloc(m * sizeof(size_t)), NULL, 0, 0, (size_t)tu->leaf_size};
    if (!t.perm) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (kD-tree)");
    for (size_t i = 0; i < m; ++i) t.perm[i] = i;
    cm_status st = CM_OK;
    if (cm_rbf_leaves_split(&t, 0, m) != 0) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (kD-tree)");
        goto done;
    }
    size_t nloc = (size_t)tu->local_size < m ? (size_t)tu->local_size : m;
    const size_t nmin = nloc;
    double reach2 = -1.0;
    if (tu->overlap > 0.0 && p->fill > 0.0 && tu->local_max > tu->local_size) {
        nloc = (size_t)tu->local_max < m ? (size_t)tu->local_max : m;
        reach2 = (tu->overlap * p->fill) * (tu->overlap * p->fill);
    }
    /* thinned far band (thin_reach): the near set above, then picks up to thin_max */
    const int thin = tu->thin_reach > 0.0 && p->fill > 0.0;
    const double far2 = (tu->thin_reach * p->fill) * (tu->thin_reach * p->fill);
    const size_t tcap = thin ? ((size_t)tu->thin_max < m ? (size_t)tu->thin_max : m) : 0;
    p->nsub = t.nleaves;
    p->sub_ptr = malloc(((size_t)t.nleaves + 1) * sizeof *p->sub_ptr);
    p->n_in = malloc((size_t)t.nleaves * sizeof *p->n_in);
    size_t stride = nloc > t.leaf_size ? nloc : t.leaf_size; /* compacted below */
    if (tcap > stride) stride = tcap;
    p->sub_idx = malloc((size_t)t.nleaves * stride * sizeof *p->sub_idx);
    if (!p->sub_ptr || !p->n_in || !p->sub_idx) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (subdomains)");
        goto done;
    }
    size_t *cnt = calloc((size_t)t.nleaves, sizeof *cnt);
    size_t *nnear = calloc((size_t)t.nleaves, sizeof *nnear);
    int fail = !nnear;
#pragma omp parallel num_threads(threads) if (t.nleaves > 8 && threads > 1)
    {
        cm_rbf_keyed *lk = malloc((size_t)t.nleaves * sizeof *lk);
        cm_rbf_keyed *cand = malloc(m * sizeof *cand);
#pragma omp for schedule(dynamic, 4)
        for (int l = 0; l < t.nleaves; ++l) {
            if (!lk || !cand || !cnt) {
#pragma omp atomic write
                fail = 1;
                continue;
            }
            size_t *out = p->sub_idx + (size_t)l * stride;
            cnt[l] = cm_rbf_leaves_grow(&t, l, nloc, nmin, reach2, lk, cand, out);
            if (thin) {
                nnear[l] = cnt[l];
                cnt[l] = cm_rbf_leaves_thin(&t, l, cnt[l], far2, p->fill, tu->thin_cell, tcap,
                                            cand, out);
                if (cnt[l] == 0) {
#pragma omp atomic write
                    fail = 1;
                }
            }
        }
        free(lk);
        free(cand);
    }
    if (fail) {
        free(cnt);
        free(nnear);
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (subdomains)");
        goto done;
    }
    double near_sum = 0.0, reach_sum = 0.0;
    p->sub_ptr[0] = 0;
    for (int l = 0; l < t.nleaves; ++l) {
        size_t *sub = p->sub_idx + (size_t)l * stride, last = sub[cnt[l] - 1];
        const double xl[3] = {r->c[last], r->c[m + last], r->c[2 * m + last]};
        near_sum += (double)nnear[l];
        reach_sum += sqrt(cm_rbf_box_dist2(xl, t.leaves[l].bmin, t.leaves[l].bmax));
        memmove(p->sub_idx + p->sub_ptr[l], sub, cnt[l] * sizeof *p->sub_idx);
        p->sub_ptr[l + 1] = p->sub_ptr[l] + cnt[l];
        p->n_in[l] = (int)(t.leaves[l].hi - t.leaves[l].lo);
    }
    free(cnt);
    free(nnear);
    st = cm_rbf_bodies_create(ctx, r->c, m, p->nsub, p->sub_ptr, p->sub_idx, p->n_in, &p->bodies);
    if (st != CM_OK) goto done;
    p->bytes += cm_rbf_bodies_bytes(p->bodies);
    if (thin)
        cm_log(ctx, CM_LOG_DEBUG,
               "cm_rbf_create: Schwarz thinned overlap: mean %.0f near + %.0f far centres "
               "(cap %zu), mean reach %.2f H (thin_reach %g H, cell %g x distance)",
               near_sum / t.nleaves, (double)p->sub_ptr[t.nleaves] / t.nleaves - near_sum / t.nleaves,
               tcap, reach_sum / t.nleaves / p->fill, tu->thin_reach, tu->thin_cell);
    else
        cm_log(ctx, CM_LOG_DEBUG, "cm_rbf_create: Schwarz overlap: mean reach %.2f H",
               p->fill > 0.0 ? reach_sum / t.nleaves / p->fill : 0.0);
done:
    free(t.perm);
    free(t.leaves);
    return st;
}

/* Rows of the local inverse kept in double for a subdomain of n centres, n_in of its own:
 * local_float 0 all, 1 none, 2 the leaf's own rows (mixed: the overlap rows in float). */
static int double_rows(int local_float, size_t n, size_t n_in)
{
    return local_float == 1 ? 0 : local_float == 2 ? (int)n_in : (int)n;
}

/* The owned subdomains [l0, l1) of part `part` of `parts`: contiguous runs of kD-tree
 * leaves (so a part is a compact region) of about equal set-up cost, n^3 per subdomain. */
static void split_parts(cm_rbf_schwarz *p, int part, int parts)
{
    p->l0 = 0;
    p->l1 = p->nsub;
    if (parts <= 1 || part < 0 || part >= parts) return;
    double total = 0.0;
    for (int l = 0; l < p->nsub; ++l) {
        double n = (double)(p->sub_ptr[l + 1] - p->sub_ptr[l]);
        total += n * n * n;
    }
    double acc = 0.0;
    int l0 = -1, l1 = p->nsub;
    for (int l = 0; l < p->nsub; ++l) {
        /* subdomain l goes to the part its cost's midpoint falls in */
        double n = (double)(p->sub_ptr[l + 1] - p->sub_ptr[l]), c = n * n * n;
        int q = (int)((acc + 0.5 * c) / total * parts);
        if (q > parts - 1) q = parts - 1;
        if (q == part && l0 < 0) l0 = l;
        if (q > part) {
            l1 = l;
            break;
        }
        acc += c;
    }
    p->l0 = l0 < 0 ? l1 : l0;
    p->l1 = l0 < 0 ? l1 : l1;
}

static cm_status build_local(cm_context *ctx, const cm_rbf *r, cm_rbf_schwarz *p, int threads)
{
    const size_t m = r->m;
    const int mode = r->tun.local_float;
    p->d_ptr = malloc(((size_t)p->nsub + 1) * sizeof *p->d_ptr);
    p->f_ptr = malloc(((size_t)p->nsub + 1) * sizeof *p->f_ptr);
    p->hd = malloc(((size_t)p->nsub + 1) * sizeof *p->hd);
    if (!p->d_ptr || !p->f_ptr || !p->hd)
        return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    size_t nmax = 0, inmax = 0;
    p->d_ptr[0] = p->f_ptr[0] = 0;
    for (int l = 0; l < p->nsub; ++l) {
        size_t n = p->sub_ptr[l + 1] - p->sub_ptr[l], nin = (size_t)p->n_in[l];
        int own = l >= p->l0 && l < p->l1;
        p->hd[l] = double_rows(mode, n, nin);
        p->d_ptr[l + 1] = p->d_ptr[l] + (own ? (size_t)p->hd[l] * nin : 0);
        p->f_ptr[l + 1] = p->f_ptr[l] + (own ? (n - (size_t)p->hd[l]) * nin : 0);
        if (n > nmax) nmax = n;
        if (nin > inmax) inmax = nin;
    }
    const size_t nd = p->d_ptr[p->nsub], nf = p->f_ptr[p->nsub];
    p->nmax = nmax;
    /* filled below by the threads, each its own subdomains: faulted in by them */
    p->g64 = cm_alloc_large(nd * sizeof *p->g64, 0);
    p->g32 = cm_alloc_large(nf * sizeof *p->g32, 0);
    if (!p->g32 || !p->g64)
        return cm_error(ctx, CM_ERR_NOMEM,
                        "cm_rbf_create: out of memory for the local solves (%.3g GB)",
                        ((double)nd * 8.0 + (double)nf * 4.0) / 1e9);
    p->bytes += nd * 8 + nf * 4;
    if (nf > 0) { /* float rows: the local polynomial bases, see cm_rbf_schwarz_apply_sum */
        p->q_ptr = malloc(((size_t)p->nsub + 1) * sizeof *p->q_ptr);
        if (!p->q_ptr) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
        p->q_ptr[0] = 0;
        for (int l = 0; l < p->nsub; ++l) {
            int own = l >= p->l0 && l < p->l1;
            p->q_ptr[l + 1] = p->q_ptr[l] + (own ? 4 * (p->sub_ptr[l + 1] - p->sub_ptr[l]) : 0);
        }
        p->lq = malloc((p->q_ptr[p->nsub] ? p->q_ptr[p->nsub] : 1) * sizeof *p->lq);
        if (!p->lq) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
        p->bytes += p->q_ptr[p->nsub] * 8;
    }
    /* one subdomain per thread with single-threaded BLAS: the local problems are too small
     * for threaded LAPACK to pay off */
    const int saved = openblas_get_num_threads();
    openblas_set_num_threads(1);
    int bad = 0, bad_info = 0, done = 0, stop = 0; /* stop: the caller asked (its thread) */
    const int nown = p->l1 - p->l0;
#pragma omp parallel num_threads(threads) if (threads > 1)
    {
        double *work = malloc((nmax * nmax + 24 * nmax) * sizeof *work);
        double *g = malloc(nmax * inmax * sizeof *g);
#pragma omp for schedule(dynamic, 1)
        for (int l = p->l0; l < p->l1; ++l) {
            int stopped;
#pragma omp atomic read
            stopped = stop;
            if (stopped) continue;
            if (!work || !g) {
#pragma omp atomic write
                bad = -1;
                continue;
            }
            size_t n = p->sub_ptr[l + 1] - p->sub_ptr[l], nin = (size_t)p->n_in[l];
            const size_t *idx = p->sub_idx + p->sub_ptr[l];
            int info = cm_rbf_local_inverse_fast(r->c, m, idx, n, nin, work, g);
            if (info == -2) info = cm_rbf_local_inverse(r->c, m, idx, n, nin, work, g);
            if (info != 0) {
#pragma omp critical
                {
                    bad = l + 1;
                    bad_info = info;
                }
                continue;
            }
            if (p->lq && info == 0) info = cm_rbf_poly_basis(r->c, m, idx, n, work, p->lq + p->q_ptr[l]);
            if (info != 0) {
#pragma omp critical
                {
                    bad = l + 1;
                    bad_info = info;
                }
                continue;
            }
            /* column j: rows [0, hd) in double, [hd, n) in float */
            const size_t hd = (size_t)p->hd[l], hf = n - hd;
            double *gd = p->g64 + p->d_ptr[l];
            float *gf = p->g32 + p->f_ptr[l];
            for (size_t j = 0; j < nin; ++j) {
                const double *col = g + j * n;
                memcpy(gd + j * hd, col, hd * sizeof *col);
                for (size_t i = 0; i < hf; ++i) gf[j * hf + i] = (float)col[hd + i];
            }
            int d;
#pragma omp atomic capture
            d = ++done;
#ifdef _OPENMP
            if (omp_get_thread_num() == 0) /* the caller's thread: callbacks need not be reentrant */
#endif
                if (cm_progress(ctx, "rbf local solves", (double)d, (double)nown) < 0) {
#pragma omp atomic write
                    stop = 1;
                }
        }
        free(work);
        free(g);
    }
    openblas_set_num_threads(saved);
    if (stop) return CM_ERR_INTERRUPTED; /* the message is cm_progress's */
    if (bad < 0) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (local solves)");
    if (bad > 0)
        return cm_error(ctx, CM_ERR_NUMERIC,
                        "cm_rbf_create: the local r^3 system of subdomain %d (%zu centres) "
                        "failed (LAPACK info %d): near-duplicate centres?",
                        bad - 1, p->sub_ptr[bad] - p->sub_ptr[bad - 1], bad_info);
    return CM_OK;
}

static cm_status build_coarse(cm_context *ctx, const cm_rbf *r, cm_rbf_schwarz *p, int threads)
{
    const size_t m = r->m;
    size_t nc = cm_rbf_coarse_count(&r->tun, m); /* a coarse space as fine as the problem is no coarse space */
    if (nc < 16) return CM_OK;
    p->nc = nc;
    p->c_idx = malloc(nc * sizeof *p->c_idx);
    p->c_xyz = malloc(3 * nc * sizeof *p->c_xyz);
    const int inner = r->tun.coarse_inner > 0;
    p->gc = inner ? NULL : cm_alloc_large((nc * nc + 8 * nc) * sizeof *p->gc, 0);
    double *d2 = malloc(m * sizeof *d2);
    cm_status st = CM_OK;
    if (!p->c_idx || !p->c_xyz || (!inner && !p->gc) || !d2) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory (coarse space: %zu centres%s)",
                      nc, inner ? "" : ", dense factor");
        goto done;
    }
    p->bytes += (inner ? 0 : nc * nc * 8) + nc * 32;
    p->fill = cm_rbf_farthest_points(r->c, m, nc, p->c_idx, d2, threads);
    for (int d = 0; d < 3; ++d)
        for (size_t a = 0; a < nc; ++a) p->c_xyz[(size_t)d * nc + a] = r->c[(size_t)d * m + p->c_idx[a]];
    if (inner) {
        st = cm_rbf_coarse_inner_create(ctx, r, nc, p->c_xyz, m, threads, &p->inner);
        if (st == CM_OK) p->bytes += cm_rbf_coarse_inner_bytes(p->inner);
        goto done;
    }
    /* between choosing the coarse centres and their dense factor (one LAPACK sequence) */
    if ((st = cm_progress(ctx, "rbf coarse", 0.5, 1)) < 0) goto done;
    const int saved = openblas_get_num_threads();
    openblas_set_num_threads(threads);
    int info = cm_rbf_projected_factor(r->c, m, p->c_idx, nc, p->gc, &p->c_rk, p->c_tau);
    openblas_set_num_threads(saved);
    if (info != 0)
        st = cm_error(ctx, CM_ERR_NUMERIC,
                      "cm_rbf_create: the coarse r^3 system (%zu centres) failed (LAPACK "
                      "info %d)",
                      nc, info);
done:
    free(d2);
    return st;
}

cm_status cm_rbf_schwarz_create(cm_context *ctx, const cm_rbf *r, int threads,
                                cm_rbf_schwarz **pc)
{
    *pc = NULL;
    cm_rbf_schwarz *p = calloc(1, sizeof *p);
    if (!p) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_create: out of memory");
    p->m = r->m;
    p->post = r->tun.coarse_post;
    if (r->tun.coarse_inner < 0 || r->tun.coarse_inner > 200 ||
        (r->tun.coarse_inner > 0 && !(r->tun.coarse_inner_tol > 0.0 && r->tun.coarse_inner_tol < 1.0))) {
        free(p);
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_rbf_create: bad coarse_inner %d / coarse_inner_tol %g (expected "
                        "0..200 iterations and a tolerance in (0, 1))",
                        r->tun.coarse_inner, r->tun.coarse_inner_tol);
    }
    /* the coarse space first: its fill distance sets the overlap when measured in distance */
    double t0 = cm_wtime();
    /* progress points around the coarse level (its dense factor is one LAPACK call) and the
     * subdomains: where the caller can stop before the local solves report */
    cm_status st = cm_progress(ctx, "rbf coarse", 0, 1);
    if (st == CM_OK) st = build_coarse(ctx, r, p, threads);
    if (st == CM_OK) st = cm_progress(ctx, "rbf coarse", 1, 1);
    double t1 = cm_wtime();
    if (st == CM_OK) st = build_subdomains(ctx, r, p, threads);
    if (st == CM_OK) split_parts(p, r->pc_part, r->pc_parts);
    if (st == CM_OK) st = cm_progress(ctx, "rbf subdomains", 1, 1);
    double t2 = cm_wtime();
    if (st == CM_OK) st = build_local(ctx, r, p, threads);
    double t3 = cm_wtime();
    if (st != CM_OK) {
        cm_rbf_schwarz_destroy(&p);
        return st;
    }
    p->bytes += p->sub_ptr[p->nsub] * sizeof *p->sub_idx + (size_t)p->nsub * 24;
    if (p->inner) {
        const cm_rbf_schwarz *q = cm_rbf_coarse_inner_pc(p->inner);
        cm_log(ctx, CM_LOG_DEBUG,
               "cm_rbf_create: Schwarz coarse level: %zu centres solved by <= %d inner FGMRES "
               "iterations (to %g) with %d subdomains (mean %.0f) and a dense coarse of %zu, "
               "%.1f MB",
               p->nc, r->tun.coarse_inner, r->tun.coarse_inner_tol, q->nsub,
               (double)q->sub_ptr[q->nsub] / (double)q->nsub, q->nc,
               (double)cm_rbf_coarse_inner_bytes(p->inner) / 1e6);
    }
    cm_log(ctx, CM_LOG_DEBUG,
           "cm_rbf_create: Schwarz: %d subdomains of <= %zu centres (mean %.0f, leaves <= %d), "
           "coarse %zu (fill distance %.3g); coarse %.3f s, tree + overlap %.3f s, local %.3f "
           "s (%d subdomains built here), %.1f MB",
           p->nsub, p->nmax, (double)p->sub_ptr[p->nsub] / (double)p->nsub, r->tun.leaf_size,
           p->nc, p->fill, t1 - t0, t2 - t1, t3 - t2, p->l1 - p->l0, (double)p->bytes / 1e6);
    *pc = p;
    return CM_OK;
}

/* wc (nc x ncs SoA): coarse data in, coarse weights out, exactly (dense factor) or by the
 * inner Krylov solve */
static void coarse_solve(const cm_rbf_schwarz *p, int nc, double *wc, int threads)
{
    /* the inner Krylov solve runs its columns in lock step (stopping when all are done), so
     * it gets one column at a time: a column's correction then does not depend on its
     * batch-mates */
    if (p->inner)
        for (int c = 0; c < nc; ++c)
            cm_rbf_coarse_inner_solve(p->inner, 1, wc + (size_t)c * p->nc, threads);
    else cm_rbf_projected_solve_cols(p->gc, p->nc, p->c_rk, p->c_tau, (size_t)nc, wc, threads);
}

const cm_rbf_coarse_inner *cm_rbf_schwarz_inner(const cm_rbf_schwarz *pc)
{
    return pc ? pc->inner : NULL;
}

/* Kernel sums of nc columns in chunks the sums take (rbf_internal.h); with inner (the
 * multilevel coarse space) each chunk first by its treecode to the fine centres (p = the
 * centres, n = ldp), as one call of up to CM_RBF_SUM_MAX_NC columns would */
static void sum_chunked(const cm_rbf_coarse_inner *inner, cm_rbf_kernel kernel, size_t ms,
                        const double *cs, const double *w, int nc, size_t n, const double *p,
                        size_t ldp, double *out, size_t ldo, int threads)
{
    for (int c0 = 0; c0 < nc; c0 += CM_RBF_SUM_MAX_NC) {
        const int b = nc - c0 < CM_RBF_SUM_MAX_NC ? nc - c0 : CM_RBF_SUM_MAX_NC;
        if (b == nc) { /* one chunk: straight into out */
            if (!inner || cm_rbf_coarse_inner_to_fine(inner, nc, w, n, p, out, threads) != 0)
                cm_rbf_kernel_sum(kernel, 3, ms, cs, w, nc, n, p, ldp, out, ldo, threads);
            return;
        }
        double *tmp = malloc(n * (size_t)b * sizeof *tmp);
        if (!tmp) { /* out of memory: one column at a time in place is no option; zero */
            for (size_t i = 0; i < n; ++i)
                for (int u = 0; u < b; ++u) out[i * ldo + (size_t)(c0 + u)] = 0.0;
            continue;
        }
        if (!inner ||
            cm_rbf_coarse_inner_to_fine(inner, b, w + (size_t)c0 * ms, n, p, tmp, threads) != 0)
            cm_rbf_kernel_sum(kernel, 3, ms, cs, w + (size_t)c0 * ms, b, n, p, ldp, tmp,
                              (size_t)b, threads);
        for (size_t i = 0; i < n; ++i)
            for (int u = 0; u < b; ++u) out[i * ldo + (size_t)(c0 + u)] = tmp[i * (size_t)b + (size_t)u];
        free(tmp);
    }
}

int cm_rbf_schwarz_apply_sum(const cm_rbf_schwarz *p, const cm_rbf *r, int nc,
                             const double *in, double *out, int threads, cm_rbf_schwarz_sum sum,
                             void *arg)
{
    const size_t m = r->m, ncs = p->nc;
    memset(out, 0, (size_t)nc * m * sizeof *out);
    const double *res = in;
    double *r1 = NULL, *rc = NULL, *ac = NULL, *wc = NULL;
    int failed = 0;
    if (ncs > 0 && p->post == 2) { /* local solves first, coarse after them only */
        rc = calloc(2 * ncs * (size_t)nc, sizeof *rc);
        r1 = rc; /* marks the coarse correction below as possible */
    } else if (ncs > 0) {
        rc = calloc(2 * ncs * (size_t)nc, sizeof *rc);
        ac = malloc(m * (size_t)nc * sizeof *ac);
        r1 = malloc(m * (size_t)nc * sizeof *r1);
        if (!rc || !ac || !r1) { /* no coarse correction: still a valid preconditioner */
            free(rc), free(ac), free(r1);
            r1 = rc = ac = NULL;
        } else {
            wc = rc + ncs * (size_t)nc;
            for (int c = 0; c < nc; ++c)
                for (size_t a = 0; a < ncs; ++a) rc[(size_t)c * ncs + a] = in[(size_t)c * m + p->c_idx[a]];
            memcpy(wc, rc, ncs * (size_t)nc * sizeof *wc);
            coarse_solve(p, nc, wc, threads);
            /* the local solves see the residual of the coarse interpolant; its polynomial
             * part is left in, as the local solves annihilate linear functions exactly */
            sum_chunked(p->inner, r->kernel, ncs, p->c_xyz, wc, nc, m, r->c, m, ac, (size_t)nc,
                        threads);
            for (int c = 0; c < nc; ++c)
                for (size_t i = 0; i < m; ++i)
                    r1[(size_t)c * m + i] = in[(size_t)c * m + i] - ac[i * (size_t)nc + (size_t)c];
            res = r1;
        }
    }
    /* leaves are disjoint, so the scatter into out needs no synchronisation; each leaf
     * centre receives exactly one sum (and a coarse centre its coarse weight below, in
     * either order the same two numbers), so the parts of a split preconditioner added
     * together give this one bit for bit */
#pragma omp parallel num_threads(threads) if (threads > 1 && p->l1 - p->l0 > 1)
    {
        double *loc = malloc(p->nmax * (size_t)nc * sizeof *loc);
#pragma omp for schedule(dynamic, 4)
        for (int l = p->l0; l < p->l1; ++l) {
            const size_t *idx = p->sub_idx + p->sub_ptr[l];
            const size_t n = p->sub_ptr[l + 1] - p->sub_ptr[l], nin = (size_t)p->n_in[l];
            const size_t hd = (size_t)p->hd[l], hf = n - hd;
            double *x = loc;
            if (!x) continue; /* out of memory: a weaker preconditioner, not a wrong result */
            for (int c = 0; c < nc; ++c)
                for (size_t i = 0; i < n; ++i) x[(size_t)c * n + i] = res[(size_t)c * m + idx[i]];
            if (p->lq) {
                /* float rows: the local inverse annihilates linear data, so taking the local
                 * linear fit out first changes nothing in exact arithmetic, but the float
                 * rounding of G (about 6e-8 |G|) then multiplies only what is left, not the
                 * linear part, which on a small set dominates the data */
                const double *q = p->lq + p->q_ptr[l];
                for (int c = 0; c < nc; ++c) {
                    double *xc = x + (size_t)c * n;
                    for (int a = 0; a < 4; ++a) {
                        const double *qa = q + (size_t)a * n;
                        double t = 0.0;
                        for (size_t i = 0; i < n; ++i) t += qa[i] * xc[i];
                        for (size_t i = 0; i < n; ++i) xc[i] -= t * qa[i];
                    }
                }
            }
            cm_rbf_local_rows(p->g64 + p->d_ptr[l], p->g32 + p->f_ptr[l], hd, hf, nin, x, n, nc,
                              out, m, idx);
        }
        free(loc);
    }
    if (sum && sum(arg, out, (size_t)nc * m) != 0) failed = 1;
    cm_rbf_bodies_project(p->bodies, nc, m, out);
    if (wc)
        for (int c = 0; c < nc; ++c)
            for (size_t a = 0; a < ncs; ++a) out[(size_t)c * m + p->c_idx[a]] += wc[(size_t)c * ncs + a];
    /* multiplicative coarse correction after the local solves: out += G_c (in - A out) at
     * the coarse centres, so the coarse residual of the whole correction is zero */
    if (r1 && p->post) {
        wc = rc + ncs * (size_t)nc;
        double *aout = malloc(ncs * (size_t)nc * sizeof *aout);
        if (aout) {
            sum_chunked(NULL, r->kernel, m, r->c, out, nc, ncs, p->c_xyz, ncs, aout, (size_t)nc,
                        threads);
            for (int c = 0; c < nc; ++c)
                for (size_t a = 0; a < ncs; ++a)
                    rc[(size_t)c * ncs + a] = in[(size_t)c * m + p->c_idx[a]] -
                                              aout[a * (size_t)nc + (size_t)c];
            memcpy(wc, rc, ncs * (size_t)nc * sizeof *wc);
            coarse_solve(p, nc, wc, threads);
            for (int c = 0; c < nc; ++c)
                for (size_t a = 0; a < ncs; ++a)
                    out[(size_t)c * m + p->c_idx[a]] += wc[(size_t)c * ncs + a];
            free(aout);
        }
    }
    if (r1 != rc) free(r1);
    free(rc);
    free(ac);
    return failed ? -1 : 0;
}

void cm_rbf_schwarz_apply(const cm_rbf_schwarz *p, const cm_rbf *r, int nc, const double *in,
                          double *out, int threads)
{
    cm_rbf_schwarz_apply_sum(p, r, nc, in, out, threads, NULL, NULL);
}
