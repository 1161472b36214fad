/* Many right-hand sides in one iterative solve: each column solved with the others equals
 * its solve alone (weights, evaluation and iteration count), a slowly converging column
 * does not hold back the others, warm starts from the fit's history of solutions (its cap,
 * and in the refinement of fast sums), the columns solved in groups when the Krylov
 * storage exceeds its budget, and in warm groups (options warm_groups), the solve's progress
 * counted in columns. */
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "rbf_tuning.h"
#include "rbf_test_sets.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { NC = 10, ROUGH = 9 };

/* NC columns on the bore set's centres (m x NC row-major): the bore's motion (3), the same
 * motion about two shifted axes (3 + 3), and rough random data (ROUGH), which converges
 * more slowly. */
static double *columns(size_t m, const double *x, unsigned seed)
{
    double *v = malloc(m * NC * sizeof *v), *d = malloc(m * 3 * sizeof *d);
    if (!v || !d) {
        free(v), free(d);
        return NULL;
    }
    bore_motion(m, x, 2.0, 1.0, d);
    for (size_t i = 0; i < m; ++i)
        for (int e = 0; e < 3; ++e) v[i * NC + (size_t)e] = d[3 * i + (size_t)e];
    bore_motion(m, x, 2.1, 0.95, d);
    for (size_t i = 0; i < m; ++i)
        for (int e = 0; e < 3; ++e) v[i * NC + 3 + (size_t)e] = 0.8 * d[3 * i + (size_t)e];
    bore_motion(m, x, 1.9, 1.05, d);
    for (size_t i = 0; i < m; ++i)
        for (int e = 0; e < 3; ++e) v[i * NC + 6 + (size_t)e] = 1.2 * d[3 * i + (size_t)e];
    unsigned s = seed;
    for (size_t i = 0; i < m; ++i) {
        s = s * 1103515245u + 12345u;
        v[i * NC + ROUGH] = 0.05 * ((double)((s >> 8) & 0xffff) / 65535.0 - 0.5);
    }
    free(d);
    return v;
}

typedef struct solved {
    double *w, *q; /* nc x m, nc x k: as kept in the cm_rbf */
    int iters[NC];
    cm_rbf_stats st;
    cm_status status;
} solved;

/* Solves the nc columns cols[] of v (m x NC) together on r; copies what r keeps. */
static solved solve_cols(cm_context *ctx, cm_rbf *r, size_t m, const double *v, int nc,
                         const int *cols)
{
    solved o;
    memset(&o, 0, sizeof o);
    double *f = malloc(m * (size_t)nc * sizeof *f);
    for (size_t i = 0; i < m; ++i)
        for (int u = 0; u < nc; ++u) f[i * (size_t)nc + (size_t)u] = v[i * NC + (size_t)cols[u]];
    o.status = cm_rbf_solve(ctx, r, nc, f);
    free(f);
    cm_rbf_get_stats(r, &o.st);
    const size_t mm = cm_rbf_centre_count(r), k = (size_t)r->k;
    o.w = malloc(mm * (size_t)nc * sizeof *o.w);
    o.q = malloc(k * (size_t)nc * sizeof *o.q);
    memcpy(o.w, r->w, mm * (size_t)nc * sizeof *o.w);
    memcpy(o.q, r->q, k * (size_t)nc * sizeof *o.q);
    for (int u = 0; u < nc; ++u) o.iters[u] = cm_rbf_iterative_column_iterations(r, (size_t)u);
    return o;
}

static double rel_diff(size_t n, const double *a, const double *b)
{
    double d = 0.0, s = 0.0;
    for (size_t i = 0; i < n; ++i) d = fmax(d, fabs(a[i] - b[i])), s = fmax(s, fabs(b[i]));
    return s > 0.0 ? d / s : d;
}

/* The interpolant of column u of a against column 0 of b (one column) at p:
 * max difference / max |data of the column|. */
static double eval_diff(cm_rbf *r, size_t m, size_t np, const double *p, const solved *a,
                        int u, const solved *b, double scale)
{
    const size_t k = (size_t)r->k;
    double worst = 0.0;
    for (size_t i = 0; i < np; ++i) {
        double s[3], ea = 0.0, eb = 0.0;
        for (int e = 0; e < 3; ++e) s[e] = (p[3 * i + (size_t)e] - r->shift[e]) * r->scale;
        (void)s;
        ea = a->q[(size_t)u * k];
        eb = b->q[0];
        for (int e = 0; e < 3; ++e) {
            ea += a->q[(size_t)u * k + 1 + (size_t)e] * s[e];
            eb += b->q[1 + (size_t)e] * s[e];
        }
        for (size_t j = 0; j < m; ++j) {
            double dx = s[0] - r->c[j], dy = s[1] - r->c[m + j], dz = s[2] - r->c[2 * m + j];
            double rr = sqrt(dx * dx + dy * dy + dz * dz), phi = rr * rr * rr;
            ea += a->w[(size_t)u * m + j] * phi;
            eb += b->w[j] * phi;
        }
        worst = fmax(worst, fabs(ea - eb));
    }
    return worst / scale;
}

static void release(solved *s) { free(s->w), free(s->q); }

/* The largest eval_diff, relative to its data, of the first nc columns of s (solved from
 * v's columns 0..nc-1) against each solved alone from zero. */
static double against_cold(cm_context *ctx, cm_rbf *r, size_t m, size_t m_in, size_t np,
                           const double *p, const double *v, const solved *s, int nc)
{
    double worst = 0.0;
    const int warm = r->opt.warm_start;
    for (int u = 0; u < nc; ++u) {
        double fmx = 0.0;
        for (size_t i = 0; i < m_in; ++i) fmx = fmax(fmx, fabs(v[i * NC + (size_t)u]));
        r->opt.warm_start = 0;
        solved a = solve_cols(ctx, r, m, v, 1, &u);
        r->opt.warm_start = warm;
        worst = fmax(worst, eval_diff(r, m, np, p, s, u, &a, fmx));
        release(&a);
    }
    return worst;
}

/* How far the fit's interpolant of its last solve (its nc columns, v's columns cols[])
 * misses its data at the m_in centres x: max |s_u(x_i) - v_iu| relative to max |v| over
 * them, by an evaluation, which knows nothing of how the solve checked itself. -1 if the
 * evaluation fails. */
static double data_miss(cm_context *ctx, const cm_rbf *r, size_t m_in, const double *x,
                        const double *v, int nc, const int *cols)
{
    double *at = malloc(m_in * (size_t)nc * sizeof *at), miss = 0.0, fall = 0.0;
    if (!at || cm_rbf_evaluate(ctx, r, m_in, x, at) != CM_OK) {
        free(at);
        return -1.0;
    }
    for (size_t i = 0; i < m_in; ++i)
        for (int u = 0; u < nc; ++u) {
            const double d = v[i * NC + (size_t)cols[u]];
            miss = fmax(miss, fabs(at[i * (size_t)nc + (size_t)u] - d));
            fall = fmax(fall, fabs(d));
        }
    free(at);
    return fall > 0.0 ? miss / fall : miss;
}

/* The starts a solve's groups took from the first group's products unchecked (its log). */
static void count_exact(void *user, cm_log_level level, const char *msg)
{
    (void)level;
    int g, c, p, n;
    double t;
    if (sscanf(msg, "cm_rbf_solve: group %d: %d columns, %d products, %lf s; %d", &g, &c, &p,
               &t, &n) == 5)
        *(int *)user += n;
}

/* What a solve's debug log says of its checks (rbf_fgmres.c): the warm starts whose plain
 * check summed S(w) (the last logged; -1: none), and the checks after a cycle that came from
 * the Arnoldi relation (summed over the cycles). */
typedef struct {
    int s_summed, at_once, arnoldi;
} check_log;

/* The reports of stage "rbf solve": how many, the last done, whether done ever fell,
 * whether any came inside the first group (0 < done < first) and inside the last (last_from
 * < done < columns), and a total other than the solve's columns. */
typedef struct progress_seen {
    int n, fell, inside, late, other_total;
    double first_group, last_from, columns, last;
} progress_seen;

static void see_progress(void *user, const char *stage, double done, double total)
{
    progress_seen *ps = user;
    if (strcmp(stage, "rbf solve") != 0) return;
    ps->fell |= ps->n > 0 && done < ps->last;
    ps->inside |= done > 0.0 && done < ps->first_group;
    ps->late |= done > ps->last_from && done < ps->columns;
    ps->other_total |= total != ps->columns;
    ps->last = done;
    ++ps->n;
}

static void count_checks(void *user, cm_log_level level, const char *msg)
{
    (void)level;
    check_log *cl = user;
    int a, b, c, d;
    if (sscanf(msg, "cm_rbf_solve: the check of %d starts summed S(w) for %d, bounded it by the "
               "fit's last weights for %d, and was compensated at once for %d", &a, &b, &c,
               &d) == 4)
        cl->s_summed = b, cl->at_once = d;
    if (sscanf(msg, "cm_rbf_solve: cycle %d: %d checks by the Arnoldi relation", &a, &b) == 2)
        cl->arnoldi += b;
}

/* solve_cols with the solve's log counted into cl */
static solved solve_logged(cm_rbf *r, size_t m, const double *v, int nc, const int *cols,
                           check_log *cl)
{
    cm_context *lc = NULL;
    solved o;
    memset(&o, 0, sizeof o);
    o.status = CM_ERR_NOMEM;
    cl->s_summed = cl->at_once = -1;
    cl->arnoldi = 0;
    if (cm_context_create(&lc) != CM_OK) return o;
    cm_context_set_threads(lc, 2);
    cm_context_set_log(lc, count_checks, cl);
    o = solve_cols(lc, r, m, v, nc, cols);
    cm_context_destroy(&lc);
    return o;
}

#ifndef CM_RBF_SUM_MAX_NC
#define CM_RBF_SUM_MAX_NC 4
#endif

/* 1 if the kernel sums (plain and compensated) give each column the same bits whatever the
 * number of columns of the call: then a batch must equal its columns' solos bit for bit. */
static int sums_column_exact(const cm_rbf *r, size_t m)
{
    const int nc = NC < CM_RBF_SUM_MAX_NC ? NC : CM_RBF_SUM_MAX_NC;
    double *w = malloc(m * (size_t)nc * sizeof *w), *o1 = malloc(m * sizeof *o1);
    double *on = malloc(m * (size_t)nc * sizeof *on);
    unsigned s = 3u;
    for (size_t i = 0; i < m * (size_t)nc; ++i) {
        s = s * 1103515245u + 12345u;
        w[i] = (double)((s >> 8) & 0xffff) / 65535.0 - 0.5;
    }
    int same = nc > 1;
    for (int acc = 0; acc < 2 && same; ++acc) {
        if (acc) cm_rbf_kernel_sum_acc(m, r->c, w, nc, m, r->c, m, on, (size_t)nc, 2);
        else cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, r->c, w, nc, m, r->c, m, on, (size_t)nc, 2);
        for (int u = 0; u < nc && same; ++u) {
            if (acc) cm_rbf_kernel_sum_acc(m, r->c, w + (size_t)u * m, 1, m, r->c, m, o1, 1, 2);
            else cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, r->c, w + (size_t)u * m, 1, m, r->c,
                                   m, o1, 1, 2);
            for (size_t i = 0; i < m && same; ++i) same = o1[i] == on[i * (size_t)nc + (size_t)u];
        }
    }
    free(w), free(o1), free(on);
    return same;
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    double *x = NULL, *d = NULL;
    const size_t m_in = bore_set(0.09, &x, &d);
    double *v = columns(m_in, x, 7u);
    cm_rbf_options o;
    cm_rbf_options_init(&o);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    o.warm_start = 0;
    cm_rbf *r = NULL;
    cm_status s = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m_in, x, &o, &r);
    CHECK_MSG(s == CM_OK && v, "%s", cm_context_message(ctx));
    if (s != CM_OK || !v) return TEST_REPORT();
    const size_t m = cm_rbf_centre_count(r);
    int all[NC];
    for (int u = 0; u < NC; ++u) all[u] = u;

    /* all columns at once against each alone */
    solved b = solve_cols(ctx, r, m, v, NC, all);
    CHECK_MSG(b.status == CM_OK, "batch: %s", cm_context_message(ctx));
    CHECK(b.st.column_groups == 1 && b.st.warm_columns == 0);
    int same_bits = 0;
    size_t np;
    double *p = eval_points(0, x, 300, 1.8, &np);
    for (int u = 0; u < NC; ++u) {
        solved a = solve_cols(ctx, r, m, v, 1, &u);
        CHECK_MSG(a.status == CM_OK, "column %d alone: %s", u, cm_context_message(ctx));
        double fmx = 0.0;
        for (size_t i = 0; i < m_in; ++i) fmx = fmax(fmx, fabs(v[i * NC + (size_t)u]));
        const int bits = !memcmp(a.w, b.w + (size_t)u * m, m * sizeof *a.w) &&
                         !memcmp(a.q, b.q + (size_t)u * (size_t)r->k, (size_t)r->k * sizeof *a.q);
        same_bits += bits;
        const double ed = eval_diff(r, m, np, p, &b, u, &a, fmx);
        printf("column %d: %d iterations alone, %d in the batch; weights %s (%.3g), "
               "interpolants differ by %.3g of max |f|\n", u, a.iters[0], b.iters[u],
               bits ? "the same bits" : "differ", rel_diff(m, b.w + (size_t)u * m, a.w), ed);
        /* the solve's tolerance, 1e-10, at the centres; inside, the interpolants of two
         * solutions within it: a few times that */
        CHECK_MSG(ed <= 1e-8, "column %d: %.3g", u, ed);
        /* a slowly converging batch-mate does not change a column's iterations */
        CHECK_MSG(a.iters[0] == b.iters[u], "column %d: %d alone, %d in the batch", u,
                  a.iters[0], b.iters[u]);
        release(&a);
    }
    const int exact_sums = sums_column_exact(r, m);
    printf("%d of %d columns the same bits in the batch as alone (the kernel sums %s the "
           "same bits per column whatever the columns of a call)\n", same_bits, NC,
           exact_sums ? "give" : "do not give");
    /* the solve adds nothing of its own: each column's arithmetic is its solo solve's */
    if (exact_sums) CHECK(same_bits == NC);
    CHECK_MSG(b.iters[ROUGH] > b.iters[0], "the rough column took %d iterations, the smooth "
              "%d", b.iters[ROUGH], b.iters[0]);
    CHECK(b.st.iterations == b.iters[ROUGH]);

    /* a tiny budget for the Krylov storage: one column per group, the same result */
    {
        r->tun.krylov_budget = 1.0;
        {
            solved g = solve_cols(ctx, r, m, v, NC, all);
            r->tun.krylov_budget = 0.0;
            CHECK_MSG(g.status == CM_OK && g.st.column_groups == NC, "%d groups",
                      g.st.column_groups);
            const double wd = rel_diff(m * NC, g.w, b.w);
            const int bits = !memcmp(g.w, b.w, m * NC * sizeof *g.w);
            printf("in %d groups: weights %s (%.3g)\n", g.st.column_groups,
                   bits ? "the same bits" : "differ", wd);
            if (exact_sums) CHECK(bits);
            for (int u = 0; u < NC; ++u) {
                double fmx = 0.0;
                for (size_t i = 0; i < m_in; ++i) fmx = fmax(fmx, fabs(v[i * NC + (size_t)u]));
                solved one = {.w = g.w + (size_t)u * m, .q = g.q + (size_t)u * (size_t)r->k};
                const double ed = eval_diff(r, m, np, p, &b, u, &one, fmx);
                CHECK_MSG(ed <= 1e-8, "column %d in groups: %.3g", u, ed);
                CHECK(g.iters[u] == b.iters[u]);
            }
            release(&g);
        }
    }

    /* warm start: nearby data (the shifted axis moved a little) after a solve */
    {
        r->opt.warm_start = 1;
        {
            const int smooth[6] = {0, 1, 2, 3, 4, 5};
            solved w0 = solve_cols(ctx, r, m, v, 6, smooth); /* 6 columns after 10: cold */
            CHECK(w0.st.warm_columns == 0);
            double *v2 = malloc(m_in * NC * sizeof *v2), *d2 = malloc(m_in * 3 * sizeof *d2);
            memcpy(v2, v, m_in * NC * sizeof *v2);
            bore_motion(m_in, x, 2.11, 0.955, d2);
            for (size_t i = 0; i < m_in; ++i)
                for (int e = 0; e < 3; ++e) v2[i * NC + 3 + (size_t)e] = 0.8 * d2[3 * i + (size_t)e];
            solved w1 = solve_cols(ctx, r, m, v2, 6, smooth); /* warm */
            r->opt.warm_start = 0;
            solved c1 = solve_cols(ctx, r, m, v2, 6, smooth); /* cold */
            r->opt.warm_start = 1;
            CHECK_MSG(w1.status == CM_OK && c1.status == CM_OK, "%s", cm_context_message(ctx));
            printf("warm start: %d columns warm from a residual of %.3g at most; iterations "
                   "warm / cold:", w1.st.warm_columns, w1.st.warm_residual);
            for (int u = 0; u < 6; ++u) printf(" %d/%d", w1.iters[u], c1.iters[u]);
            printf("\n");
            CHECK(w1.st.warm_columns == 6 && w1.st.warm_residual > 0.0 &&
                  w1.st.warm_residual < 1.0);
            CHECK(c1.st.warm_columns == 0);
            /* unchanged columns start at their solution; the moved ones near it */
            for (int u = 0; u < 6; ++u) {
                CHECK_MSG(w1.iters[u] < c1.iters[u], "column %d: warm %d, cold %d", u,
                          w1.iters[u], c1.iters[u]);
                double fmx = 0.0;
                for (size_t i = 0; i < m_in; ++i) fmx = fmax(fmx, fabs(v2[i * NC + (size_t)u]));
                solved one = {.w = c1.w + (size_t)u * m, .q = c1.q + (size_t)u * (size_t)r->k};
                const double ed = eval_diff(r, m, np, p, &w1, u, &one, fmx);
                CHECK_MSG(ed <= 1e-8, "column %d warm against cold: %.3g", u, ed);
            }
            CHECK(w1.st.iterations < c1.st.iterations);
            /* another number of columns, data in the span of earlier ones (two solves
             * back and one back): the history's combination starts at their solution */
            double *v3 = malloc(m_in * NC * sizeof *v3);
            for (size_t i = 0; i < m_in; ++i)
                for (size_t u = 0; u < NC; ++u)
                    v3[i * NC + u] = 0.5 * v[i * NC + u % 6] - 2.0 * v2[i * NC + (u + 3) % 6];
            solved w2 = solve_cols(ctx, r, m, v3, 3, smooth);
            r->opt.warm_start = 0;
            solved c2 = solve_cols(ctx, r, m, v3, 3, smooth);
            r->opt.warm_start = 1;
            printf("data in the span of the history: %d columns warm from %.3g, %d earlier "
                   "solutions; iterations %d (from zero %d)\n", w2.st.warm_columns,
                   w2.st.warm_residual, w2.st.warm_basis, w2.st.iterations, c2.st.iterations);
            CHECK(w2.status == CM_OK && w2.st.warm_columns == 3);
            CHECK_MSG(w2.st.warm_residual < 1e-6, "%.3g", w2.st.warm_residual);
            /* of the 12 solutions, the first 6 are independent; of the second 6 the
             * unchanged ones lie in their span and are not kept */
            CHECK_MSG(w2.st.warm_basis > 6 && w2.st.warm_basis < 12, "%d", w2.st.warm_basis);
            CHECK(w2.st.iterations <= 2 && w2.st.iterations < c2.st.iterations);
            for (int u = 0; u < 3; ++u) {
                double fmx = 0.0;
                for (size_t i = 0; i < m_in; ++i) fmx = fmax(fmx, fabs(v3[i * NC + (size_t)u]));
                solved one = {.w = c2.w + (size_t)u * m, .q = c2.q + (size_t)u * (size_t)r->k};
                const double ed = eval_diff(r, m, np, p, &w2, u, &one, fmx);
                CHECK_MSG(ed <= 1e-8, "column %d from the history against cold: %.3g", u, ed);
            }
            /* data near the span (a further motion 1e-4 its size added): the starts'
             * check is the one compensated product, as the last check takes the step's
             * product from the cycle's own (the Arnoldi relation, within a tenth of the
             * tolerance); the data met at the centres by an evaluation, which knows none of
             * that */
            double *v5 = malloc(m_in * NC * sizeof *v5);
            bore_motion(m_in, x, 2.12, 0.96, d2);
            for (size_t i = 0; i < m_in; ++i)
                for (size_t u = 0; u < NC; ++u)
                    v5[i * NC + u] = v3[i * NC + u] + (u < 3 ? 1e-4 * d2[3 * i + u] : 0.0);
            check_log cl;
            solved n1 = solve_logged(r, m, v5, 3, smooth, &cl);
            const double miss = data_miss(ctx, r, m_in, x, v5, 3, smooth);
            printf("near the span: warm from %.3g, %d iterations, products %d compensated + %d "
                   "plain, %d checks by the Arnoldi relation, residual %.3g, the data missed by "
                   "%.3g\n", n1.st.warm_residual, n1.st.iterations, n1.st.matvecs_compensated,
                   n1.st.matvecs_plain, cl.arnoldi, n1.st.residual, miss);
            CHECK(n1.status == CM_OK && n1.st.iterations >= 1 && n1.st.residual <= 1e-10);
            CHECK_MSG(n1.st.matvecs_compensated == 1, "%d", n1.st.matvecs_compensated);
            CHECK_MSG(cl.arnoldi >= 1, "%d", cl.arnoldi);
            CHECK_MSG(miss >= 0.0 && miss <= 2e-10, "%.3g", miss);
            const double en = against_cold(ctx, r, m, m_in, np, p, v5, &n1, 3);
            CHECK_MSG(en <= 1e-8, "near the span against cold: %.3g", en);
            /* a loose tolerance: a start's plain check bounds S(w0) by the last solve's
             * weights (S subadditive, phi <= diam^3) instead of summing |w0|, certainly once
             * that solve was at 1e-6 too (its own check summed S); the solutions as the
             * cold ones' */
            r->opt.tolerance = 1e-6;
            double *v6 = malloc(m_in * NC * sizeof *v6);
            for (size_t i = 0; i < m_in * NC; ++i) v6[i] = v5[i];
            int summed[2] = {-1, -1};
            for (int pass = 0; pass < 2; ++pass) {
                for (size_t i = 0; i < m_in; ++i)
                    for (size_t u = 0; u < 3; ++u) v6[i * NC + u] += 1e-3 * d2[3 * i + u];
                solved l1 = solve_logged(r, m, v6, 3, smooth, &cl);
                summed[pass] = cl.s_summed;
                CHECK(l1.status == CM_OK && l1.st.warm_columns == 3 && l1.st.residual <= 1e-6);
                const double eb = pass ? against_cold(ctx, r, m, m_in, np, p, v6, &l1, 3) : 0.0;
                CHECK_MSG(eb <= 2e-6, "bounded S, against cold: %.3g", eb);
                release(&l1);
            }
            printf("loose warm starts: S(w) summed at the check of 3 starts for %d, then %d\n",
                   summed[0], summed[1]);
            CHECK_MSG(summed[1] == 0, "%d, %d", summed[0], summed[1]);
            /* where S(w) of the last weights is far above what plain sums allow (1e4 |f| at
             * 1e-8), the starts' check goes compensated at once */
            for (double tl = 1e-7; tl >= 1e-8; tl *= 0.1) {
                r->opt.tolerance = tl;
                for (size_t i = 0; i < m_in; ++i)
                    for (size_t u = 0; u < 3; ++u) v6[i * NC + u] += 1e-3 * d2[3 * i + u];
                solved l2 = solve_logged(r, m, v6, 3, smooth, &cl);
                printf("tolerance %.0e: the check of 3 starts summed S(w) for %d, compensated at "
                       "once %d; residual %.3g\n", tl, cl.s_summed, cl.at_once, l2.st.residual);
                CHECK(l2.status == CM_OK && l2.st.residual <= tl);
                if (tl < 5e-8) CHECK_MSG(cl.at_once >= 1, "%d", cl.at_once);
                release(&l2);
            }
            r->opt.tolerance = o.tolerance;
            free(v6);
            release(&n1);
            free(v5);
            release(&w0), release(&w1), release(&c1), release(&w2), release(&c2);
            free(v2), free(d2), free(v3);
        }
        r->opt.warm_start = 0;
    }

    /* warm groups: 3 fields of a study-like family (the bore's axis moved and the motion
     * scaled a little per field) in one solve, in 3 groups, the second and third warm from
     * the solutions before them: each column as its cold solve alone, and each later group
     * in fewer iterations than the first. At 1e-6 a cold column's last check comes from the
     * Arnoldi relation (its zero start's product is exact), and the data are met at the
     * centres by an evaluation, which knows none of that. */
    {
        cm_rbf_options og = o;
        og.warm_start = 1;
        og.warm_groups = 3;
        cm_rbf *rg = NULL;
        CHECK(cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m_in, x, &og, &rg) == CM_OK);
        double *vf = calloc(m_in * NC, sizeof *vf), *df = malloc(m_in * 3 * sizeof *df);
        for (int k = 0; k < 3; ++k) {
            bore_motion(m_in, x, 2.0 + 0.02 * k, 1.0, df);
            for (size_t i = 0; i < m_in; ++i)
                for (int e = 0; e < 3; ++e)
                    vf[i * NC + (size_t)(3 * k + e)] = (1.0 + 0.1 * k) * df[3 * i + (size_t)e];
        }
        const int smooth[9] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
        /* its progress: in columns, never back, within the cold group too, to the end */
        progress_seen ps = {.first_group = 3.0, .last_from = 6.0, .columns = 9.0};
        int unchecked = 0;
        cm_context_set_progress(ctx, see_progress, &ps);
        cm_context_set_log(ctx, count_exact, &unchecked);
        solved g = solve_cols(ctx, rg, m, vf, 9, smooth);
        cm_context_set_progress(ctx, NULL, NULL);
        cm_context_set_log(ctx, NULL, NULL);
        /* the later groups start from the first's products, their starts unchecked (at this
         * tolerance a check would be compensated): the data are still met at the centres to
         * the tolerance, by an evaluation that knows none of that */
        const double miss9 = data_miss(ctx, rg, m_in, x, vf, 9, smooth);
        printf("warm groups: %d starts unchecked, the data missed by %.3g (tolerance %.3g)\n",
               unchecked, miss9, og.tolerance);
        CHECK_MSG(unchecked >= 3, "%d", unchecked);
        CHECK_MSG(miss9 >= 0.0 && miss9 <= 2.0 * og.tolerance, "%.3g", miss9);
        printf("warm groups' progress: %d reports, last %g of 9, inside the first group %s, "
               "the last %s, %s\n", ps.n, ps.last, ps.inside ? "yes" : "no",
               ps.late ? "yes" : "no", ps.fell ? "fell" : "never fell");
        CHECK(ps.n >= 3 && !ps.fell && ps.inside && ps.late && !ps.other_total &&
              ps.last == 9.0);
        int its[3] = {0, 0, 0};
        printf("warm groups: %d groups, %d columns warm, iterations", g.st.column_groups,
               g.st.warm_columns);
        for (int u = 0; u < 9; ++u) printf(" %d", g.iters[u]), its[u / 3] += g.iters[u];
        printf("\n");
        CHECK_MSG(g.status == CM_OK && g.st.column_groups == 3 && g.st.warm_columns == 6,
                  "%d groups, %d warm", g.st.column_groups, g.st.warm_columns);
        CHECK_MSG(its[1] < its[0] && its[2] < its[0], "iterations by group %d %d %d", its[0],
                  its[1], its[2]);
        const double eg = against_cold(ctx, rg, m, m_in, np, p, vf, &g, 9);
        CHECK_MSG(eg <= 1e-8, "warm groups against cold: %.3g", eg);
        release(&g);
        rg->opt.tolerance = 1e-6;
        rg->opt.warm_start = 0;
        check_log cl;
        solved c6 = solve_logged(rg, m, vf, 3, smooth, &cl);
        const double miss = data_miss(ctx, rg, m_in, x, vf, 3, smooth);
        printf("cold at 1e-6: %d checks by the Arnoldi relation, residual %.3g, the data "
               "missed by %.3g\n", cl.arnoldi, c6.st.residual, miss);
        CHECK(c6.status == CM_OK && c6.st.residual <= 1e-6);
        CHECK_MSG(cl.arnoldi >= 1, "%d", cl.arnoldi);
        CHECK_MSG(miss >= 0.0 && miss <= 2e-6, "%.3g", miss);
        free(vf), free(df);
        release(&c6);
        cm_rbf_destroy(&rg);
    }

    /* a history of 2 solutions: the oldest gives way, the starts use the 2 kept */
    {
        cm_rbf_tuning tu;
        cm_rbf_tuning_init(&tu);
        tu.warm_history = 2;
        cm_rbf_options o2 = o;
        o2.warm_start = 1;
        cm_rbf *r2 = NULL;
        CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m_in, x, &o2, &tu, &r2) == CM_OK);
        for (int u = 0; r2 && u < 4; ++u) {
            solved a = solve_cols(ctx, r2, m, v, 1, &u);
            CHECK_MSG(a.status == CM_OK && a.st.warm_basis == (u < 2 ? u : 2),
                      "solve %d: %d earlier solutions", u, a.st.warm_basis);
            release(&a);
        }
        cm_rbf_destroy(&r2);
    }

    /* fast (treecode) matvecs with refinement: the batch against each column alone */
    {
        r->opt.fast_sum = 1;
        cm_rbf *rf = r;
        {
            const int cols[4] = {0, 3, 4, ROUGH};
            solved fb = solve_cols(ctx, rf, m, v, 4, cols);
            CHECK_MSG(fb.status == CM_OK && fb.st.fast_sum == 1, "%s", cm_context_message(ctx));
            for (int u = 0; u < 4; ++u) {
                solved a = solve_cols(ctx, rf, m, v, 1, cols + u);
                double fmx = 0.0;
                for (size_t i = 0; i < m_in; ++i) fmx = fmax(fmx, fabs(v[i * NC + (size_t)cols[u]]));
                const double ed = eval_diff(r, m, np, p, &fb, u, &a, fmx);
                printf("fast sums, column %d: %d iterations alone, %d in the batch, "
                       "interpolants differ by %.3g\n", cols[u], a.iters[0], fb.iters[u], ed);
                CHECK_MSG(ed <= 1e-8, "fast, column %d: %.3g", cols[u], ed);
                CHECK(a.iters[0] == fb.iters[u]);
                release(&a);
            }
            /* a warm start in the refinement: the same data again start at their solution */
            r->opt.warm_start = 1;
            solved f1 = solve_cols(ctx, rf, m, v, 4, cols);
            solved f2 = solve_cols(ctx, rf, m, v, 4, cols);
            r->opt.warm_start = 0;
            printf("fast sums, the same data again: %d columns warm from %.3g, %d iterations "
                   "(from zero %d)\n", f2.st.warm_columns, f2.st.warm_residual,
                   f2.st.iterations, fb.st.iterations);
            CHECK(f2.status == CM_OK && f2.st.warm_columns == 4 && f2.st.warm_residual < 1e-6);
            CHECK(f2.st.iterations < fb.st.iterations);
            for (int u = 0; u < 4; ++u) {
                double fmx = 0.0;
                for (size_t i = 0; i < m_in; ++i) fmx = fmax(fmx, fabs(v[i * NC + (size_t)cols[u]]));
                solved one = {.w = f2.w + (size_t)u * m, .q = f2.q + (size_t)u * (size_t)r->k};
                CHECK(eval_diff(r, m, np, p, &f1, u, &one, fmx) <= 1e-8);
            }
            release(&f1), release(&f2);
            release(&fb);
        }
    }
    release(&b);
    free(p), free(v), free(x), free(d);
    cm_rbf_destroy(&r);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
