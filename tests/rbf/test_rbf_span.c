/* A family's fields solved in warm groups: the order the groups take them in
 * (cm_rbf_history_order: on synthetic data whose answer is known, with and without a
 * history), and the evaluation of the warm columns through the span of the cold ones
 * (rbf_evaluate_span.c) against direct compensated sums of the same weights and against each
 * field solved alone: at the default tolerance the warm columns take steps (their rests
 * summed plainly), at 1e-6 their starts meet it (combined alone). */
#include "cadmorph/rbf.h"
#include "iterative/rbf_iter.h"
#include "rbf_internal.h"
#include "rbf_test_sets.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { NF = 6, NCOL = 3 * NF };

/* 5 fields of one column in R^8 (e_i the unit vectors): e0, e0 + 1e-3 e1, e1, e0 + e1 + e2,
 * e2. Each pick is the field the span of the picks before it fits worst, relative to its
 * norm: e0 first (all fit none: the first of the ties), then e1 and e2 (each wholly outside),
 * while e0 + 1e-3 e1 and e0 + e1 + e2 are left in the span; with e0 in a history, e1 first. */
static void order_known(void)
{
    enum { M = 8, F = 5 };
    double pf[F * M], scale[F];
    size_t order[F];
    for (int hist = 0; hist < 2; ++hist) {
        memset(pf, 0, sizeof pf);
        pf[0 * M + 0] = 1.0;
        pf[1 * M + 0] = 1.0, pf[1 * M + 1] = 1e-3;
        pf[2 * M + 1] = 1.0;
        pf[3 * M + 0] = pf[3 * M + 1] = pf[3 * M + 2] = 1.0;
        pf[4 * M + 2] = 1.0;
        for (int f = 0; f < F; ++f) {
            double s = 0.0;
            for (int i = 0; i < M; ++i) s += pf[f * M + i] * pf[f * M + i];
            scale[f] = sqrt(s);
        }
        cm_rbf_history *h = NULL;
        if (hist) {
            h = cm_rbf_history_create(M, 4);
            double w[M] = {0.0}, b[M] = {1.0};
            CHECK(h && cm_rbf_history_add(h, w, b) == 1);
        }
        cm_rbf_history_order(h, M, F, 1, 3, pf, scale, order);
        printf("order %s a history: %zu %zu %zu | %zu %zu\n", hist ? "with" : "without",
               order[0], order[1], order[2], order[3], order[4]);
        if (!hist) CHECK(order[0] == 0 && order[1] == 2 && order[2] == 4);
        else CHECK(order[0] == 2 && order[1] == 4); /* e0 known: then the ties at 0 */
        int seen[F] = {0};
        for (int f = 0; f < F; ++f) seen[order[f]]++;
        for (int f = 0; f < F; ++f) CHECK(seen[f] == 1);
        cm_rbf_history_destroy(&h);
    }
}

/* The fields (m x NCOL row-major, field k in columns 3k..3k+2): the bore's motion scaled by
 * 1 + 0.1 k, plus eps of the motion about an axis moved by (0.05, 0.03) k: near the span of
 * the first fields, not in it. eps above the tolerance: the warm columns take steps and leave
 * their evaluation a rest that matters; below it, their starts meet the tolerance. */
static double *family(size_t m, const double *x, double eps)
{
    double *v = malloc(m * NCOL * sizeof *v), *d = malloc(m * 3 * sizeof *d);
    double *e = malloc(m * 3 * sizeof *e);
    if (v && d && e) bore_motion(m, x, 2.0, 1.0, d);
    for (int k = 0; v && d && e && k < NF; ++k) {
        bore_motion(m, x, 2.0 + 0.05 * k, 1.0 + 0.03 * k, e);
        for (size_t i = 0; i < m * 3; ++i)
            v[i / 3 * NCOL + (size_t)(3 * k) + i % 3] = (1.0 + 0.1 * k) * d[i] + eps * e[i];
    }
    free(d), free(e);
    return v;
}

/* The fit's interpolant at the np points p (np x 3) by compensated direct sums of all its
 * weights plus the polynomial part, into out (np x nc). */
static void direct(const cm_rbf *r, size_t np, const double *p, double *out)
{
    const size_t m = r->m, nc = (size_t)r->ncomp, k = (size_t)r->k;
    double *s = calloc(3 * np, sizeof *s);
    if (!s) {
        memset(out, 0, np * nc * sizeof *out);
        return;
    }
    for (size_t i = 0; i < np; ++i)
        for (int d = 0; d < 3; ++d)
            s[(size_t)d * np + i] = (p[3 * i + (size_t)d] - r->shift[d]) * r->scale;
    cm_rbf_kernel_sum_acc(m, r->c, r->w, (int)nc, np, s, np, out, nc, 2);
    for (size_t i = 0; i < np; ++i)
        for (size_t c = 0; c < nc; ++c) {
            const double *q = r->q + c * k;
            out[i * nc + c] += q[0] + q[1] * s[i] + q[2] * s[np + i] + q[3] * s[2 * np + i];
        }
    free(s);
}

/* max over the columns of max |a - b| / max |f_c| (a, b: np x NCOL; v: the data) */
static double worst_rel(size_t np, const double *a, const double *b, size_t m_in, const double *v)
{
    double worst = 0.0;
    for (size_t c = 0; c < NCOL; ++c) {
        double fm = 0.0, dm = 0.0;
        for (size_t i = 0; i < m_in; ++i) fm = fmax(fm, fabs(v[i * NCOL + c]));
        for (size_t i = 0; i < np; ++i) dm = fmax(dm, fabs(a[i * NCOL + c] - b[i * NCOL + c]));
        worst = fmax(worst, dm / fm);
    }
    return worst;
}

/* The first group's fields from the solve's log line "... the fields in the order a b ..." */
typedef struct {
    int first[2];
} order_log;

static void read_order(void *user, cm_log_level level, const char *msg)
{
    (void)level;
    order_log *ol = user;
    const char *t = strstr(msg, "the fields in the order");
    if (t) sscanf(t, "the fields in the order %d %d", &ol->first[0], &ol->first[1]);
}

/* A combination that would amplify the basis' rounding is summed instead: three columns
 * solved from zero, then their weights made w0 = u, w1 = u + 1e-10 v, w2 = v (v, u two of
 * the solutions) with w2 marked as a warm start that took no step: w2 = 1e10 (w1 - w0)
 * exactly, but 1e10 times the sums' rounding is above the tolerance, so it is not combined,
 * and the evaluation matches direct sums. */
static void ill_conditioned(cm_context *ctx, size_t m_in, const double *x, size_t np,
                            const double *p)
{
    cm_rbf_options o;
    cm_rbf_options_init(&o);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    o.tolerance = 1e-6;
    cm_rbf *r = NULL;
    double *f = malloc(m_in * 3 * sizeof *f), *ev = malloc(np * 3 * sizeof *ev);
    double *ed = malloc(np * 3 * sizeof *ed);
    bore_motion(m_in, x, 2.0, 1.0, f);
    CHECK(f && ev && ed && cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m_in, x, &o, &r) == CM_OK);
    if (r && cm_rbf_solve(ctx, r, 3, f) == CM_OK) {
        const size_t m = r->m;
        double *w = r->w;
        for (size_t i = 0; i < m; ++i) {
            const double u = w[i], v = w[m + i];
            w[i] = u, w[m + i] = u + 1e-10 * v, w[2 * m + i] = v;
        }
        r->iter->scales.start[0] = r->iter->scales.start[1] = -1.0;
        r->iter->scales.start[2] = 0.0;
        CHECK(cm_rbf_evaluate(ctx, r, np, p, ev) == CM_OK);
        cm_rbf_stats st;
        cm_rbf_get_stats(r, &st);
        direct(r, np, p, ed);
        double e = 0.0, fm = 0.0;
        for (size_t i = 0; i < np * 3; ++i) e = fmax(e, fabs(ev[i] - ed[i]));
        for (size_t i = 0; i < np * 3; ++i) fm = fmax(fm, fabs(ed[i]));
        printf("ill-conditioned: %d combined, against direct sums %.3g of the values\n",
               st.eval_combined, e / fm);
        CHECK_MSG(st.eval_combined == 0, "%d", st.eval_combined);
        CHECK_MSG(e <= 1e-7 * fm, "%.3g", e / fm);
    } else
        CHECK_MSG(0, "%s", cm_context_message(ctx));
    cm_rbf_destroy(&r);
    free(f), free(ev), free(ed);
}

int main(void)
{
    order_known();
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    double *x = NULL, *d = NULL;
    const size_t m_in = bore_set(0.09, &x, &d);
    size_t np = 0;
    double *p = eval_points(m_in, x, 400, 1.8, &np);
    double *f = malloc(m_in * NCOL * sizeof *f), *one = malloc(m_in * 3 * sizeof *one);
    double *ev = malloc(np * NCOL * sizeof *ev), *ed = malloc(np * NCOL * sizeof *ed);
    double *ec = malloc(np * NCOL * sizeof *ec), *e1 = malloc(np * 3 * sizeof *e1);
    CHECK(p && f && one && ev && ed && ec && e1);
    ill_conditioned(ctx, m_in, x, np, p);
    const double tols[2] = {1e-10, 1e-6}, eps[2] = {1e-5, 1e-8};
    for (int t = 0; t < 2; ++t) {
        double *v = family(m_in, x, eps[t]);
        CHECK(v != NULL);
        if (!v) break;
        memcpy(f, v, m_in * NCOL * sizeof *f);
        /* each field alone, from zero: the reference for the solutions */
        cm_rbf_options o;
        cm_rbf_options_init(&o);
        o.solver = CM_RBF_SOLVER_ITERATIVE;
        o.tolerance = tols[t];
        o.warm_start = 0;
        cm_rbf *rc = NULL;
        CHECK(cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m_in, x, &o, &rc) == CM_OK);
        for (int k = 0; rc && k < NF; ++k) {
            for (size_t i = 0; i < m_in; ++i)
                for (size_t e = 0; e < 3; ++e) one[3 * i + e] = v[i * NCOL + (size_t)(3 * k) + e];
            CHECK(cm_rbf_solve(ctx, rc, 3, one) == CM_OK);
            CHECK(cm_rbf_evaluate(ctx, rc, np, p, e1) == CM_OK);
            for (size_t i = 0; i < np; ++i)
                for (size_t e = 0; e < 3; ++e) ec[i * NCOL + (size_t)(3 * k) + e] = e1[3 * i + e];
        }
        cm_rbf_destroy(&rc);
        /* all fields in one solve, in 3 warm groups */
        o.warm_start = 1;
        o.warm_groups = 3;
        cm_rbf *r = NULL;
        CHECK(cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m_in, x, &o, &r) == CM_OK);
        if (!r) {
            free(v);
            break;
        }
        cm_context *lc = NULL;
        order_log ol = {{-1, -1}};
        CHECK(cm_context_create(&lc) == CM_OK);
        cm_context_set_threads(lc, 2);
        cm_context_set_log(lc, read_order, &ol);
        CHECK(cm_rbf_solve(lc, r, NCOL, f) == CM_OK);
        cm_context_destroy(&lc);
        CHECK(cm_rbf_evaluate(ctx, r, np, p, ev) == CM_OK);
        cm_rbf_stats st;
        cm_rbf_get_stats(r, &st);
        direct(r, np, p, ed);
        const double vs_direct = worst_rel(np, ev, ed, m_in, v);
        const double vs_alone = worst_rel(np, ev, ec, m_in, v);
        printf("tolerance %.0e: the first group's fields %d %d; %d warm columns, %d combined "
               "(%s sums); against direct sums of the same weights %.3g, against each field "
               "alone %.3g\n", tols[t], ol.first[0], ol.first[1], st.warm_columns,
               st.eval_combined, st.eval_plain ? "plain" : "compensated", vs_direct, vs_alone);
        /* the family's ends first: the later groups lie between them */
        CHECK_MSG((ol.first[0] == 0 && ol.first[1] == NF - 1) ||
                  (ol.first[0] == NF - 1 && ol.first[1] == 0), "%d %d", ol.first[0], ol.first[1]);
        CHECK(st.warm_columns == 2 * NCOL / 3);
        /* every warm column: with its rest summed, or (1e-6) its start's combination alone */
        CHECK_MSG(st.eval_combined == st.warm_columns, "%d", st.eval_combined);
        CHECK(st.eval_plain == (t == 1));
        /* the combination adds no more than the sums' own rounding, a tenth of the tolerance */
        CHECK_MSG(vs_direct <= 0.1 * tols[t], "%.3g", vs_direct);
        /* two solutions within the tolerance at the centres: a few times it inside */
        CHECK_MSG(vs_alone <= (t ? 2e-6 : 1e-8), "%.3g", vs_alone);
        /* the treecode's evaluation (forced: at this size it would sum directly): the basis is
         * then every column that took a step, so the warm columns whose starts met the
         * tolerance are combined (at 1e-6 all; at the default those wholly in the span) */
        int no_step = 0;
        for (size_t c = 0; c < NCOL; ++c) no_step += cm_rbf_iterative_column_iterations(r, c) == 0;
        r->opt.fast_sum = 1;
        CHECK(cm_rbf_evaluate(ctx, r, np, p, ev) == CM_OK);
        cm_rbf_get_stats(r, &st);
        const double fast_vs_direct = worst_rel(np, ev, ed, m_in, v);
        printf("  by the treecode: %d combined, its estimated error %.3g of the data scale; "
               "against direct sums %.3g\n", st.eval_combined, st.eval_error, fast_vs_direct);
        CHECK(st.eval_fast == 1 && st.eval_plain == 0);
        CHECK_MSG(st.eval_combined == no_step && (t == 0 || no_step == st.warm_columns),
                  "%d combined, %d without a step", st.eval_combined, no_step);
        CHECK_MSG(fast_vs_direct <= 1e-8, "%.3g", fast_vs_direct);
        cm_rbf_destroy(&r);
        free(v);
    }
    free(f), free(one), free(ev), free(ed), free(ec), free(e1);
    free(p), free(x), free(d);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
