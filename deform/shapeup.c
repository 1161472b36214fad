/* Shape-Up in the MLS deformation (paper section 6, eq. 17; section 6.1's sparse C):
 * alternate the projections of every constraint set (local step) with the MLS normal
 * equations plus gamma_c Phi^T C^T C Phi (global step). The matrix is the same in every
 * iteration, so it is factored once from the MLS factor and the columns sqrt(gamma_t) Phi^T c_r
 * (one per row c_r of C): afresh with its own ordering, or by CHOLMOD's rank update of the MLS
 * factor; each iteration is one solve. Optional Anderson acceleration of the alternation. */
#include "mls_internal.h"

#include "cadmorph/shapeup.h"

#include <cholmod.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

struct cm_shapeup {
    mls_view v;
    const double *xyz; /* the mesh's nodes */
    double diag;       /* bounding-box diagonal of the mesh */
    size_t n_sets, n_tot;
    cm_shape_type *type;
    size_t *off;    /* n_sets + 1 offsets into nodes */
    int64_t *nodes; /* n_tot */
    size_t *pivot;  /* the subtracted point of each set (local index), sparse formulation */
    double *gamma;  /* gamma_c / n_t */
    double *ref;    /* n_tot x 3 initial positions */
    double *fit;    /* 7 per set: the last cylinder, a warm start */
    unsigned char *has_fit;
    cm_shapeup_options opt;
    cholmod_common cc;
    cholmod_factor *factor;
    size_t c_nnz, u_nnz, l_nnz, l0_nnz;
    double t_factor;
};

const char *cm_shape_type_name(cm_shape_type t)
{
    switch (t) {
    case CM_SHAPE_PLANE: return "plane";
    case CM_SHAPE_CIRCLE: return "circle";
    case CM_SHAPE_CYLINDER: return "cylinder";
    case CM_SHAPE_LINE: return "line";
    case CM_SHAPE_RIGID: return "rigid";
    case CM_SHAPE_CONE: return "cone";
    }
    return NULL;
}

cm_status cm_shape_type_parse(cm_context *ctx, const char *name, cm_shape_type *t)
{
    for (int i = CM_SHAPE_PLANE; i <= CM_SHAPE_CONE; ++i)
        if (name && strcmp(name, cm_shape_type_name((cm_shape_type)i)) == 0) {
            *t = (cm_shape_type)i;
            return CM_OK;
        }
    return cm_error(ctx, CM_ERR_ARGUMENT,
                    "constraint type '%s': expected plane, circle, cylinder, line or rigid",
                    name ? name : "(null)");
}

void cm_shapeup_options_init(cm_shapeup_options *opt)
{
    if (!opt) return;
    opt->weight = 10;
    opt->max_iterations = 10000;
    opt->tolerance = 1e-9;
    opt->sparse = 1;
    opt->snap = 0;
    opt->anderson = 0;
    opt->reorder = 1;
}

void cm_shapeup_destroy(cm_shapeup **su)
{
    if (!su || !*su) return;
    cm_shapeup *s = *su;
    free(s->type), free(s->off), free(s->nodes), free(s->pivot), free(s->gamma);
    free(s->ref), free(s->fit), free(s->has_fit);
    if (s->factor) cholmod_free_factor(&s->factor, &s->cc);
    cholmod_finish(&s->cc);
    free(s);
    *su = NULL;
}

static size_t min_nodes(cm_shape_type t)
{
    return t == CM_SHAPE_CONE ? 6 : t == CM_SHAPE_CYLINDER ? 5 : (t == CM_SHAPE_LINE || t == CM_SHAPE_RIGID) ? 2 : 3;
}

/* A sparse column under construction: a dense accumulator over the k samples plus the list
 * of touched entries. */
typedef struct column_acc {
    double *val;
    int32_t *list;
    unsigned char *mark;
    size_t n;
} column_acc;

static void acc_add_row(column_acc *a, const mls_view *v, int64_t node, double f)
{
    for (int64_t p = v->row[node]; p < v->row[node + 1]; ++p) {
        int32_t j = v->col[p];
        if (!a->mark[j]) a->mark[j] = 1, a->list[a->n++] = j, a->val[j] = 0;
        a->val[j] += f * v->val[p];
    }
}

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* The update U (k x rows of C): column r = sqrt(gamma_t) Phi^T c_r with its rows permuted
 * as the factor is (CHOLMOD updates L D L^T = P A P^T by P U). */
static cm_status build_update(cm_context *ctx, cm_shapeup *s, const int *perm, cholmod_sparse **out)
{
    const mls_view *v = &s->v;
    size_t k = v->k, ncols = 0;
    for (size_t t = 0; t < s->n_sets; ++t) {
        size_t n = s->off[t + 1] - s->off[t];
        ncols += s->opt.sparse ? n - 1 : n;
        s->c_nnz += s->opt.sparse ? 2 * (n - 1) : n * n;
    }
    int *iperm = malloc(k * sizeof *iperm);
    column_acc a = {malloc(k * sizeof(double)), malloc(k * sizeof(int32_t)), calloc(k, 1), 0};
    double *mean = malloc(k * sizeof *mean);
    int32_t *mlist = malloc(k * sizeof *mlist);
    size_t cap = 1024, nnz = 0;
    int *ri = malloc(cap * sizeof *ri), *cp = malloc((ncols + 1) * sizeof *cp);
    double *vx = malloc(cap * sizeof *vx);
    cm_status st = CM_OK;
    if (!iperm || !a.val || !a.list || !a.mark || !mean || !mlist || !ri || !cp || !vx) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_shapeup_create: out of memory");
        goto done;
    }
    for (size_t i = 0; i < k; ++i)
        iperm[perm ? perm[i] : (int)i] = (int)i;
    size_t col = 0;
    cp[0] = 0;
    for (size_t t = 0; t < s->n_sets; ++t) {
        size_t o = s->off[t], n = s->off[t + 1] - o, nm = 0;
        double g = sqrt(s->gamma[t]);
        if (!s->opt.sparse) {
            /* the mean of Phi over the set: what makes the mean-centred C dense */
            a.n = 0;
            for (size_t i = 0; i < n; ++i)
                acc_add_row(&a, v, s->nodes[o + i], 1.0 / (double)n);
            for (size_t q = 0; q < a.n; ++q)
                mean[a.list[q]] = a.val[a.list[q]], mlist[q] = a.list[q], a.mark[a.list[q]] = 0;
            nm = a.n;
        }
        for (size_t i = 0; i < n; ++i) {
            if (s->opt.sparse && i == s->pivot[t]) continue;
            a.n = 0;
            acc_add_row(&a, v, s->nodes[o + i], g);
            if (s->opt.sparse)
                acc_add_row(&a, v, s->nodes[o + s->pivot[t]], -g);
            else
                for (size_t q = 0; q < nm; ++q) {
                    int32_t j = mlist[q];
                    if (!a.mark[j]) a.mark[j] = 1, a.list[a.n++] = j, a.val[j] = 0;
                    a.val[j] -= g * mean[j];
                }
            if (nnz + a.n > cap) {
                while (nnz + a.n > cap)
                    cap *= 2;
                int *r2 = realloc(ri, cap * sizeof *ri);
                if (r2) ri = r2;
                double *v2 = realloc(vx, cap * sizeof *vx);
                if (v2) vx = v2;
                if (!r2 || !v2) {
                    st = cm_error(ctx, CM_ERR_NOMEM, "cm_shapeup_create: out of memory (%zu entries)",
                                  cap);
                    goto done;
                }
            }
            int *rows = ri + nnz;
            for (size_t q = 0; q < a.n; ++q)
                rows[q] = iperm[a.list[q]];
            qsort(rows, a.n, sizeof *rows, cmp_int);
            for (size_t q = 0; q < a.n; ++q) {
                int32_t j = perm ? perm[rows[q]] : rows[q];
                vx[nnz + q] = a.val[j];
                a.mark[j] = 0;
            }
            nnz += a.n;
            if (nnz > (size_t)INT32_MAX) {
                st = cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_shapeup_create: update too large");
                goto done;
            }
            cp[++col] = (int)nnz;
        }
    }
    cholmod_sparse *u = cholmod_allocate_sparse(k, ncols, nnz ? nnz : 1, 1, 1, 0, CHOLMOD_REAL, &s->cc);
    if (!u) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_shapeup_create: out of memory (CHOLMOD)");
        goto done;
    }
    memcpy(u->p, cp, (ncols + 1) * sizeof *cp);
    memcpy(u->i, ri, nnz * sizeof *ri);
    memcpy(u->x, vx, nnz * sizeof *vx);
    s->u_nnz = nnz;
    *out = u;
done:
    free(iperm), free(a.val), free(a.list), free(a.mark), free(mean), free(mlist);
    free(ri), free(cp), free(vx);
    return st;
}

static int cmp_pair(const void *a, const void *b)
{
    const int64_t *x = a, *y = b;
    return (x[0] > y[0]) - (x[0] < y[0]);
}

/* The constrained matrix A + U U^T factored afresh, with a fill-reducing ordering of its own:
 * A = P^T L L^T P from the MLS factor (its rows, which the MLS object does not keep, are not
 * needed), so CHOLMOD factors F F^T with F = [P^T L, U] (U in the original ordering). */
static cm_status refactor(cm_context *ctx, cm_shapeup *s, cholmod_factor *f0, cholmod_sparse *u)
{
    cholmod_common *cc = &s->cc;
    size_t k = s->v.k;
    cholmod_factor *lc = cholmod_copy_factor(f0, cc);
    cholmod_sparse *ls = NULL, *f = NULL;
    int64_t *pair = NULL;
    cm_status st = CM_OK;
    if (!lc || !cholmod_change_factor(CHOLMOD_REAL, 1, 0, 1, 1, lc, cc) ||
        !(ls = cholmod_factor_to_sparse(lc, cc))) {
        st = cm_error(ctx, cc->status == CHOLMOD_OUT_OF_MEMORY ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                      "cm_shapeup_create: the MLS factor as a matrix (CHOLMOD status %d)", cc->status);
        goto done;
    }
    const int *perm = f0->Perm, *lp = ls->p, *li = ls->i, *up = u->p, *ui = u->i;
    const double *lx = ls->x, *ux = u->x;
    size_t nl = (size_t)lp[ls->ncol], nu = (size_t)up[u->ncol], ncol = ls->ncol + u->ncol;
    s->l0_nnz = nl;
    f = cholmod_allocate_sparse(k, ncol, nl + nu, 1, 1, 0, CHOLMOD_REAL, cc);
    pair = malloc((k ? k : 1) * 2 * sizeof *pair);
    if (!f || !pair) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_shapeup_create: out of memory (%zu entries)", nl + nu);
        goto done;
    }
    int *fp = f->p, *fi = f->i;
    double *fx = f->x;
    size_t e = 0;
    fp[0] = 0;
    for (size_t j = 0; j < ls->ncol; ++j) {
        /* the rows of P^T L: row i of L is row perm[i] of A's ordering; sorted per column */
        size_t m = 0;
        for (int q = lp[j]; q < lp[j + 1]; ++q) {
            pair[2 * m] = perm ? perm[li[q]] : li[q];
            memcpy(pair + 2 * m + 1, lx + q, sizeof(double));
            ++m;
        }
        qsort(pair, m, 2 * sizeof *pair, cmp_pair);
        for (size_t q = 0; q < m; ++q, ++e) {
            fi[e] = (int)pair[2 * q];
            memcpy(fx + e, pair + 2 * q + 1, sizeof(double));
        }
        fp[j + 1] = (int)e;
    }
    for (size_t j = 0; j < u->ncol; ++j) {
        for (int q = up[j]; q < up[j + 1]; ++q, ++e)
            fi[e] = ui[q], fx[e] = ux[q];
        fp[ls->ncol + j + 1] = (int)e;
    }
    s->factor = cholmod_analyze(f, cc);
    if (s->factor) cholmod_factorize(f, s->factor, cc);
    if (!s->factor || cc->status != CHOLMOD_OK)
        st = cm_error(ctx, cc->status == CHOLMOD_OUT_OF_MEMORY ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                      "cm_shapeup_create: CHOLMOD failed on the constrained %zu x %zu system "
                      "(status %d)",
                      k, k, cc->status);
done:
    free(pair);
    if (f) cholmod_free_sparse(&f, cc);
    if (ls) cholmod_free_sparse(&ls, cc);
    if (lc) cholmod_free_factor(&lc, cc);
    return st;
}

cm_status cm_shapeup_create(cm_context *ctx, cm_mls *mls, const cm_mesh *mesh, size_t n_sets,
                            const cm_shape_set *sets, const cm_shapeup_options *opt, cm_shapeup **out)
{
    const char *who = "cm_shapeup_create";
    if (!out) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: out is NULL", who);
    *out = NULL;
    if (!mls || !mesh || (n_sets && !sets))
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL argument", who);
    cm_shapeup *s = calloc(1, sizeof *s);
    if (!s) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
    cholmod_start(&s->cc);
    mls_view_get(mls, &s->v);
    if (opt)
        s->opt = *opt;
    else
        cm_shapeup_options_init(&s->opt);
    cm_status st = CM_OK;
    cholmod_sparse *u = NULL;
    if (s->v.n_nodes != mesh->n_nodes) {
        st = cm_error(ctx, CM_ERR_MISMATCH, "%s: the mesh has %zu nodes, the MLS deformation %zu",
                      who, mesh->n_nodes, s->v.n_nodes);
        goto done;
    }
    if (!(s->opt.weight > 0) || s->opt.max_iterations < 0 || !(s->opt.tolerance >= 0) ||
        s->opt.anderson < 0 || s->opt.anderson > 64) {
        st = cm_error(ctx, CM_ERR_ARGUMENT,
                      "%s: weight %g, iterations %d, tolerance %g, anderson %d: need weight > 0, "
                      "iterations >= 0, tolerance >= 0, 0 <= anderson <= 64",
                      who, s->opt.weight, s->opt.max_iterations, s->opt.tolerance, s->opt.anderson);
        goto done;
    }
    s->xyz = mesh->xyz;
    {
        double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
        for (size_t i = 0; i < mesh->n_nodes; ++i)
            for (int a = 0; a < 3; ++a) {
                double x = mesh->xyz[3 * i + a];
                lo[a] = x < lo[a] ? x : lo[a], hi[a] = x > hi[a] ? x : hi[a];
            }
        s->diag = mesh->n_nodes ? sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                       (hi[2] - lo[2]) * (hi[2] - lo[2]))
                                : 0;
    }
    s->n_sets = n_sets;
    for (size_t t = 0; t < n_sets; ++t) {
        if (!cm_shape_type_name(sets[t].type)) {
            st = cm_error(ctx, CM_ERR_ARGUMENT, "%s: set %zu: unknown type %d", who, t, (int)sets[t].type);
            goto done;
        }
        if (sets[t].n < min_nodes(sets[t].type) || !sets[t].nodes) {
            st = cm_error(ctx, CM_ERR_ARGUMENT, "%s: set %zu (%s): %zu nodes, need at least %zu", who,
                          t, cm_shape_type_name(sets[t].type), sets[t].n, min_nodes(sets[t].type));
            goto done;
        }
        s->n_tot += sets[t].n;
    }
    size_t nt = s->n_tot ? s->n_tot : 1, ns = n_sets ? n_sets : 1;
    s->type = malloc(ns * sizeof *s->type);
    s->off = malloc((ns + 1) * sizeof *s->off);
    s->nodes = malloc(nt * sizeof *s->nodes);
    s->pivot = malloc(ns * sizeof *s->pivot);
    s->gamma = malloc(ns * sizeof *s->gamma);
    s->ref = malloc(nt * 3 * sizeof *s->ref);
    s->fit = malloc(ns * 7 * sizeof *s->fit);
    s->has_fit = calloc(ns, 1);
    if (!s->type || !s->off || !s->nodes || !s->pivot || !s->gamma || !s->ref || !s->fit || !s->has_fit) {
        st = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
        goto done;
    }
    s->off[0] = 0;
    for (size_t t = 0; t < n_sets; ++t) {
        size_t o = s->off[t], n = sets[t].n;
        s->type[t] = sets[t].type;
        s->off[t + 1] = o + n;
        s->gamma[t] = s->opt.weight / (double)n;
        double m[3] = {0, 0, 0};
        for (size_t i = 0; i < n; ++i) {
            int64_t v = sets[t].nodes[i];
            if (v < 0 || (size_t)v >= mesh->n_nodes) {
                st = cm_error(ctx, CM_ERR_ARGUMENT, "%s: set %zu: node %lld of a mesh of %zu nodes", who,
                              t, (long long)v, mesh->n_nodes);
                goto done;
            }
            s->nodes[o + i] = v;
            for (int a = 0; a < 3; ++a)
                s->ref[3 * (o + i) + a] = mesh->xyz[3 * v + a], m[a] += mesh->xyz[3 * v + a] / (double)n;
        }
        /* section 6.1: the subtracted point is the one nearest the mean */
        double best = DBL_MAX;
        for (size_t i = 0; i < n; ++i) {
            const double *x = s->ref + 3 * (o + i);
            double d = (x[0] - m[0]) * (x[0] - m[0]) + (x[1] - m[1]) * (x[1] - m[1]) +
                       (x[2] - m[2]) * (x[2] - m[2]);
            if (d < best) best = d, s->pivot[t] = i;
        }
    }
    double t0 = cm_wtime();
    cholmod_factor *f0 = s->v.factor;
    if (s->n_tot && s->opt.reorder) {
        st = build_update(ctx, s, NULL, &u);
        if (st >= 0) st = refactor(ctx, s, f0, u);
        if (st < 0) goto done;
    } else {
        s->factor = cholmod_copy_factor(f0, &s->cc);
        if (!s->factor) {
            st = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory (copy of the MLS factor)", who);
            goto done;
        }
    }
    if (s->n_tot && !s->opt.reorder) {
        st = build_update(ctx, s, s->factor->Perm, &u);
        if (st < 0) goto done;
        if (!cholmod_updown(1, u, s->factor, &s->cc) || s->cc.status != CHOLMOD_OK) {
            int cs = s->cc.status;
            st = cm_error(ctx, cs == CHOLMOD_OUT_OF_MEMORY ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                          "%s: CHOLMOD's update of the %zu x %zu factor by %zu columns failed (status %d)",
                          who, s->v.k, s->v.k, u->ncol, cs);
            goto done;
        }
    }
    s->t_factor = cm_wtime() - t0;
    /* entries of L (CHOLMOD's count from the analysis; a supernodal xsize would count the
     * supernodes' zeros too) */
    if (s->n_tot && s->opt.reorder)
        s->l_nnz = (size_t)s->cc.lnz;
    else if (s->factor->is_super)
        s->l_nnz = s->factor->xsize;
    else {
        const int *nz = s->factor->nz;
        for (size_t j = 0; j < s->factor->n; ++j)
            s->l_nnz += (size_t)nz[j];
    }
done:
    if (u) cholmod_free_sparse(&u, &s->cc);
    if (st < 0)
        cm_shapeup_destroy(&s);
    else
        *out = s;
    return st;
}

/* Anderson acceleration of the fixed-point map w -> G(w) = one alternation (Walker and Ni
 * 2011; for Shape-Up-like local/global solvers: Peng et al. 2018): the next iterate combines
 * the last m images so that the linearised residual G(w) - w is least; the history restarts
 * whenever the residual grows (the plain alternation's step is then taken). */
typedef struct anderson {
    size_t n;
    int m, count, head, have_prev;
    double *wp, *f, *g, *fprev, *gprev; /* n each */
    double *df, *dg;                    /* m x n rings */
    double fprev_norm;
} anderson;

static anderson *anderson_create(size_t n, int m)
{
    anderson *a = calloc(1, sizeof *a);
    if (!a) return NULL;
    a->n = n, a->m = m;
    a->wp = malloc(n * sizeof *a->wp), a->f = malloc(n * sizeof *a->f), a->g = malloc(n * sizeof *a->g);
    a->fprev = malloc(n * sizeof *a->fprev), a->gprev = malloc(n * sizeof *a->gprev);
    a->df = malloc((size_t)m * n * sizeof *a->df), a->dg = malloc((size_t)m * n * sizeof *a->dg);
    if (!a->wp || !a->f || !a->g || !a->fprev || !a->gprev || !a->df || !a->dg) {
        free(a->wp), free(a->f), free(a->g), free(a->fprev), free(a->gprev), free(a->df), free(a->dg);
        free(a);
        return NULL;
    }
    return a;
}

static void anderson_destroy(anderson *a)
{
    if (!a) return;
    free(a->wp), free(a->f), free(a->g), free(a->fprev), free(a->gprev), free(a->df), free(a->dg);
    free(a);
}

/* w: in G(wp), out the accelerated iterate */
static void anderson_step(anderson *a, double *w)
{
    size_t n = a->n;
    double fn = 0;
    for (size_t i = 0; i < n; ++i)
        a->g[i] = w[i], a->f[i] = w[i] - a->wp[i], fn += a->f[i] * a->f[i];
    fn = sqrt(fn);
    if (a->have_prev && fn > a->fprev_norm) {
        a->count = 0; /* the residual grew: restart, plain step */
    } else if (a->have_prev) {
        double *df = a->df + (size_t)a->head * n, *dg = a->dg + (size_t)a->head * n;
        for (size_t i = 0; i < n; ++i)
            df[i] = a->f[i] - a->fprev[i], dg[i] = a->g[i] - a->gprev[i];
        a->head = (a->head + 1) % a->m;
        if (a->count < a->m) ++a->count;
        /* theta = argmin |f - dF theta|, by the m x m normal equations with a small ridge */
        int c = a->count;
        double ata[64 * 64], atb[64], tr = 0;
        for (int i = 0; i < c; ++i) {
            const double *di = a->df + (size_t)i * n;
            double sb = 0;
            for (size_t q = 0; q < n; ++q)
                sb += di[q] * a->f[q];
            atb[i] = sb;
            for (int j = 0; j <= i; ++j) {
                const double *dj = a->df + (size_t)j * n;
                double sa = 0;
                for (size_t q = 0; q < n; ++q)
                    sa += di[q] * dj[q];
                ata[i * c + j] = ata[j * c + i] = sa;
            }
            tr += ata[i * c + i];
        }
        for (int i = 0; i < c; ++i)
            ata[i * c + i] += 1e-10 * tr / c + 1e-300;
        /* Cholesky */
        int ok = 1;
        for (int j = 0; j < c && ok; ++j) {
            double d = ata[j * c + j];
            for (int l = 0; l < j; ++l)
                d -= ata[j * c + l] * ata[j * c + l];
            if (!(d > 0)) {
                ok = 0;
                break;
            }
            ata[j * c + j] = sqrt(d);
            for (int i = j + 1; i < c; ++i) {
                double e = ata[i * c + j];
                for (int l = 0; l < j; ++l)
                    e -= ata[i * c + l] * ata[j * c + l];
                ata[i * c + j] = e / ata[j * c + j];
            }
        }
        if (ok) {
            for (int i = 0; i < c; ++i) {
                double e = atb[i];
                for (int l = 0; l < i; ++l)
                    e -= ata[i * c + l] * atb[l];
                atb[i] = e / ata[i * c + i];
            }
            for (int i = c - 1; i >= 0; --i) {
                double e = atb[i];
                for (int l = i + 1; l < c; ++l)
                    e -= ata[l * c + i] * atb[l];
                atb[i] = e / ata[i * c + i];
            }
            for (int i = 0; i < c; ++i) {
                const double *gi = a->dg + (size_t)i * n;
                for (size_t q = 0; q < n; ++q)
                    w[q] -= atb[i] * gi[q];
            }
        } else {
            a->count = 0;
        }
    }
    memcpy(a->fprev, a->f, n * sizeof *a->f);
    memcpy(a->gprev, a->g, n * sizeof *a->g);
    a->fprev_norm = fn;
    a->have_prev = 1;
}

/* positions of the set nodes under the coefficients w (k x 3, row-major) */
static void set_positions(const cm_shapeup *s, const double *w, double *y)
{
    const mls_view *v = &s->v;
    for (size_t i = 0; i < s->n_tot; ++i) {
        int64_t node = s->nodes[i];
        double d[3] = {0, 0, 0};
        for (int64_t p = v->row[node]; p < v->row[node + 1]; ++p)
            for (int a = 0; a < 3; ++a)
                d[a] += v->val[p] * w[3 * (size_t)v->col[p] + a];
        for (int a = 0; a < 3; ++a)
            y[3 * i + a] = s->ref[3 * i + a] + d[a];
    }
}

/* The positions of the set nodes in a result disp (#nodes x 3). */
static void set_final(const cm_shapeup *s, const double *disp, double *y)
{
    for (size_t i = 0; i < s->n_tot; ++i)
        for (int a = 0; a < 3; ++a)
            y[3 * i + a] = s->ref[3 * i + a] + disp[3 * (size_t)s->nodes[i] + a];
}

static cm_status project_all(cm_context *ctx, cm_shapeup *s, const double *y, double *p)
{
    for (size_t t = 0; t < s->n_sets; ++t) {
        size_t o = s->off[t], n = s->off[t + 1] - o;
        const double *yt = y + 3 * o;
        double *pt = p + 3 * o;
        cm_status st = CM_OK;
        switch (s->type[t]) {
        case CM_SHAPE_PLANE: st = cm_shape_project_plane(ctx, n, yt, pt, NULL); break;
        case CM_SHAPE_CIRCLE: st = cm_shape_project_circle(ctx, n, yt, pt, NULL); break;
        case CM_SHAPE_CYLINDER:
            st = cm_shape_project_cylinder(ctx, n, yt, s->has_fit[t] ? s->fit + 7 * t : NULL, pt,
                                           s->fit + 7 * t);
            if (st >= 0) s->has_fit[t] = 1;
            break;
        case CM_SHAPE_CONE:
            st = cm_shape_project_cone(ctx, n, yt, s->has_fit[t] ? s->fit + 7 * t : NULL, pt,
                                       s->fit + 7 * t);
            if (st >= 0) s->has_fit[t] = 1;
            break;
        case CM_SHAPE_LINE: st = cm_shape_project_similar(ctx, n, s->ref + 3 * o, yt, 1, pt); break;
        case CM_SHAPE_RIGID: st = cm_shape_project_similar(ctx, n, s->ref + 3 * o, yt, 0, pt); break;
        }
        if (st < 0)
            return cm_error_prefix(ctx, st, "cm_shapeup_apply: set %zu (%s)", t,
                                   cm_shape_type_name(s->type[t]));
    }
    return CM_OK;
}

static void set_residuals(const cm_shapeup *s, const double *y, const double *p, double *res)
{
    for (size_t t = 0; t < s->n_sets; ++t) {
        double m = 0;
        for (size_t i = s->off[t]; i < s->off[t + 1]; ++i) {
            double e = sqrt((y[3 * i] - p[3 * i]) * (y[3 * i] - p[3 * i]) +
                            (y[3 * i + 1] - p[3 * i + 1]) * (y[3 * i + 1] - p[3 * i + 1]) +
                            (y[3 * i + 2] - p[3 * i + 2]) * (y[3 * i + 2] - p[3 * i + 2]));
            if (e > m) m = e;
        }
        res[t] = m;
    }
}

/* w (k x 3 row-major) = F^-1 b (CHOLMOD's k x 3 column-major) */
static cm_status solve(cm_context *ctx, cm_shapeup *s, cholmod_factor *f, cholmod_dense *b, double *w)
{
    cholmod_dense *x = cholmod_solve(CHOLMOD_A, f, b, &s->cc);
    if (!x) return cm_error(ctx, CM_ERR_NOMEM, "cm_shapeup_apply: CHOLMOD solve failed");
    size_t k = s->v.k;
    const double *xx = x->x;
    for (size_t j = 0; j < k; ++j)
        for (int d = 0; d < 3; ++d)
            w[3 * j + d] = xx[d * k + j];
    cholmod_free_dense(&x, &s->cc);
    return CM_OK;
}

cm_status cm_shapeup_apply(cm_context *ctx, cm_shapeup *s, double *disp, double *residual0,
                           double *residual, cm_shapeup_report *rep)
{
    if (!s || !disp) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_shapeup_apply: NULL argument");
    const mls_view *v = &s->v;
    size_t k = v->k, nt = s->n_tot ? s->n_tot : 1;
    cm_status st = CM_OK;
    double t0 = cm_wtime();
    cholmod_dense *bfix = cholmod_zeros(k, 3, CHOLMOD_REAL, &s->cc);
    cholmod_dense *b = cholmod_zeros(k, 3, CHOLMOD_REAL, &s->cc);
    double *w = malloc(k * 3 * sizeof *w), *y = malloc(nt * 3 * sizeof *y);
    double *y2 = malloc(nt * 3 * sizeof *y2), *p = malloc(nt * 3 * sizeof *p);
    double *res = malloc((s->n_sets ? s->n_sets : 1) * sizeof *res);
    anderson *aa = s->opt.anderson > 0 ? anderson_create(3 * k, s->opt.anderson) : NULL;
    double *rc = NULL, *cb = NULL;
    if (!bfix || !b || !w || !y || !y2 || !p || !res || (s->opt.anderson > 0 && !aa)) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_shapeup_apply: out of memory");
        goto done;
    }
    /* the fix term of eq. 14, as cm_mls_apply builds it */
    double *bf = bfix->x;
    for (size_t i = 0; i < v->n_con; ++i) {
        int64_t node = v->con[i];
        for (int64_t q = v->row[node]; q < v->row[node + 1]; ++q)
            for (int d = 0; d < 3; ++d)
                bf[d * k + (size_t)v->col[q]] += v->wf[i] * v->val[q] * disp[3 * node + d];
    }
    /* start: the unconstrained deformation (its own factor) */
    st = solve(ctx, s, v->factor, bfix, w);
    if (st < 0) goto done;
    set_positions(s, w, y);
    int it = 0, converged = s->n_sets == 0;
    double move = 0;
    if (s->n_sets) {
        st = project_all(ctx, s, y, p);
        if (st < 0) goto done;
        if (residual0) set_residuals(s, y, p, residual0);
    }
    while (!converged && it < s->opt.max_iterations) {
        ++it;
        /* rhs = b_fix + sum_t gamma_t Phi^T C_t^T C_t (p - x) */
        double *bx = b->x;
        memcpy(bx, bf, 3 * k * sizeof *bx);
        for (size_t t = 0; t < s->n_sets; ++t) {
            size_t o = s->off[t], n = s->off[t + 1] - o;
            double z0[3] = {0, 0, 0};
            if (s->opt.sparse) {
                size_t q = o + s->pivot[t];
                for (int a = 0; a < 3; ++a)
                    z0[a] = p[3 * q + a] - s->ref[3 * q + a];
            } else {
                for (size_t i = o; i < o + n; ++i)
                    for (int a = 0; a < 3; ++a)
                        z0[a] += (p[3 * i + a] - s->ref[3 * i + a]) / (double)n;
            }
            double zs[3] = {0, 0, 0}; /* sum of the rows' values: what the pivot gets */
            for (size_t i = o; i < o + n; ++i) {
                if (s->opt.sparse && i == o + s->pivot[t]) continue;
                double z[3];
                for (int a = 0; a < 3; ++a)
                    z[a] = s->gamma[t] * (p[3 * i + a] - s->ref[3 * i + a] - z0[a]), zs[a] += z[a];
                int64_t node = s->nodes[i];
                for (int64_t q = v->row[node]; q < v->row[node + 1]; ++q)
                    for (int a = 0; a < 3; ++a)
                        bx[a * k + (size_t)v->col[q]] += v->val[q] * z[a];
            }
            if (s->opt.sparse) {
                /* C^T of the rows e_i - e_q puts -sum z on the pivot q; the mean-centred C is
                 * a projector, C^T C z = C z, whose entries already sum to zero */
                int64_t node = s->nodes[o + s->pivot[t]];
                for (int64_t q = v->row[node]; q < v->row[node + 1]; ++q)
                    for (int a = 0; a < 3; ++a)
                        bx[a * k + (size_t)v->col[q]] -= v->val[q] * zs[a];
            }
        }
        if (aa) memcpy(aa->wp, w, 3 * k * sizeof *w);
        st = solve(ctx, s, s->factor, b, w);
        if (st < 0) goto done;
        if (aa) anderson_step(aa, w);
        set_positions(s, w, y2);
        move = 0;
        for (size_t i = 0; i < s->n_tot; ++i) {
            double e = sqrt((y2[3 * i] - y[3 * i]) * (y2[3 * i] - y[3 * i]) +
                            (y2[3 * i + 1] - y[3 * i + 1]) * (y2[3 * i + 1] - y[3 * i + 1]) +
                            (y2[3 * i + 2] - y[3 * i + 2]) * (y2[3 * i + 2] - y[3 * i + 2]));
            if (e > move) move = e;
        }
        double *tmp = y;
        y = y2, y2 = tmp;
        if (!isfinite(move)) {
            st = cm_error(ctx, CM_ERR_NUMERIC, "cm_shapeup_apply: iteration %d: non-finite positions", it);
            goto done;
        }
        st = project_all(ctx, s, y, p);
        if (st < 0) goto done;
        if (move <= s->opt.tolerance * s->diag) converged = 1;
    }
    if (residual && s->n_sets) set_residuals(s, y, p, residual);
    /* the field at every node; with keep_constrained the constrained nodes keep their
     * prescribed values and the field's miss there is carried into the free nodes around
     * them, as cm_mls_apply does */
    double fres = 0;
    rc = v->blend ? malloc((v->n_con ? v->n_con : 1) * 3 * sizeof *rc) : NULL;
    if (v->blend && !rc) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_shapeup_apply: out of memory");
        goto done;
    }
    for (size_t i = 0, c = 0; i < v->n_nodes; ++i) {
        double d[3] = {0, 0, 0};
        for (int64_t q = v->row[i]; q < v->row[i + 1]; ++q)
            for (int a = 0; a < 3; ++a)
                d[a] += v->val[q] * w[3 * (size_t)v->col[q] + a];
        if (v->is_con[i]) {
            double e = sqrt((d[0] - disp[3 * i]) * (d[0] - disp[3 * i]) +
                            (d[1] - disp[3 * i + 1]) * (d[1] - disp[3 * i + 1]) +
                            (d[2] - disp[3 * i + 2]) * (d[2] - disp[3 * i + 2]));
            if (e > fres) fres = e;
            if (rc)
                for (int a = 0; a < 3; ++a)
                    rc[3 * c + a] = disp[3 * i + a] - d[a];
            ++c;
            if (v->keep_constrained) continue;
        }
        memcpy(disp + 3 * i, d, sizeof d);
    }
    if (rc) {
        /* the blend of the miss reaches set nodes near the constrained ones: at a node of a
         * plane set only its part along the plane of the alternation's positions, so that it
         * does not undo the flatness the constraint reached (a normal part would tilt the
         * plane's nodes beside a handle by the miss) */
        cb = calloc(v->n_nodes ? 3 * v->n_nodes : 1, sizeof *cb);
        if (!cb) {
            st = cm_error(ctx, CM_ERR_NOMEM, "cm_shapeup_apply: out of memory");
            goto done;
        }
        mls_blend_apply(v->blend, rc, cb, 1);
        for (size_t t = 0; t < s->n_sets; ++t) {
            size_t o = s->off[t], nn = s->off[t + 1] - o;
            double fit[6];
            if (s->type[t] != CM_SHAPE_PLANE) continue;
            st = cm_shape_project_plane(ctx, nn, y + 3 * o, y2 + 3 * o, fit);
            if (st < 0) goto done;
            for (size_t i = o; i < o + nn; ++i) {
                double *c = cb + 3 * (size_t)s->nodes[i];
                double dn = c[0] * fit[3] + c[1] * fit[4] + c[2] * fit[5];
                for (int a = 0; a < 3; ++a)
                    c[a] -= dn * fit[3 + a];
            }
        }
        for (size_t i = 0; i < 3 * v->n_nodes; ++i)
            disp[i] += cb[i];
    }
    double smove = 0;
    if (s->opt.snap && s->n_sets) {
        /* onto the shapes after everything else (shapeup_snap.c), and the residuals of the
         * result itself */
        set_final(s, disp, y);
        st = project_all(ctx, s, y, p);
        shapeup_snap_in in = {v, s->n_sets, s->type, s->off, s->nodes, s->ref, p, s->diag};
        if (st >= 0) st = shapeup_snap(ctx, &in, disp, &smove);
        if (st < 0) goto done;
        if (residual) {
            set_final(s, disp, y);
            st = project_all(ctx, s, y, p);
            if (st < 0) goto done;
            set_residuals(s, y, p, residual);
        }
    }
    if (rep) {
        rep->snap_move = smove;
        rep->iterations = it;
        rep->converged = converged;
        rep->last_move = move;
        rep->fix_residual = fres;
        rep->c_nonzeros = s->c_nnz;
        rep->update_nonzeros = s->u_nnz;
        rep->factor_nonzeros = s->l_nnz;
        rep->mls_factor_nonzeros = s->l0_nnz;
        rep->t_factor = s->t_factor;
        rep->t_iterate = cm_wtime() - t0;
    }
    if (!converged)
        st = cm_error(ctx, CM_WARNING,
                      "cm_shapeup_apply: %d iterations without meeting the tolerance (last move %g, "
                      "%g of the diagonal)",
                      it, move, s->diag > 0 ? move / s->diag : move);
done:
    if (bfix) cholmod_free_dense(&bfix, &s->cc);
    if (b) cholmod_free_dense(&b, &s->cc);
    free(w), free(y), free(y2), free(p), free(res), free(rc), free(cb);
    anderson_destroy(aa);
    return st;
}
