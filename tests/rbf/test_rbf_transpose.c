/* The reverse product of solve-then-evaluate (cm_rbf_evaluate_transpose): the dot-product
 * test <v, J d> = <J^T v, d> with random d and v, for the dense solver (r^3, r, 2D thin
 * plate), the iterative one (direct and treecode sums), merged duplicate centres; the
 * iterative reverse product against the dense one; the kept weights untouched. */
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "rbf_tuning.h"
#include "rbf_test_sets.h"
#include "test_rng.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

static double dot(size_t n, const double *a, const double *b)
{
    long double s = 0.0L;
    for (size_t i = 0; i < n; ++i) s += (long double)a[i] * b[i];
    return (double)s;
}

static double dot_abs(size_t n, const double *a, const double *b)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i) s += fabs(a[i] * b[i]);
    return s;
}

static void fill_random(uint64_t *rng, size_t n, double *x)
{
    for (size_t i = 0; i < n; ++i) x[i] = test_rng_range(rng, -1.0, 1.0);
}

/* The relative gap of the dot-product test for r (centres given to create: m_in), the np
 * points p, d (m_in x nc, copies of a merged centre's value where dup says: NULL none) and
 * v (np x nc); jtv receives J^T v. */
static double dot_gap(cm_context *ctx, cm_rbf *r, size_t m_in, int nc, const double *d,
                      size_t np, const double *p, const double *v, double *jtv)
{
    double *jd = malloc(np * (size_t)nc * sizeof *jd);
    cm_status s1 = cm_rbf_solve(ctx, r, nc, d);
    cm_status s2 = s1 >= 0 ? cm_rbf_evaluate(ctx, r, np, p, jd) : s1;
    cm_status s3 = cm_rbf_evaluate_transpose(ctx, r, np, p, nc, v, jtv);
    CHECK_MSG(s1 >= 0 && s2 >= 0 && s3 >= 0, "%d %d %d: %s", s1, s2, s3, cm_context_message(ctx));
    const double a = dot(np * (size_t)nc, v, jd), b = dot(m_in * (size_t)nc, jtv, d);
    /* relative to the sum of the products' sizes: what rounding in the sums is relative to */
    const double gap = fabs(a - b) / dot_abs(np * (size_t)nc, v, jd);
    printf("  <v, J d> = %.15g, <J^T v, d> = %.15g, gap %.3g (|<v,Jd>| / sum |v Jd| = %.3g)\n",
           a, b, gap, fabs(a) / dot_abs(np * (size_t)nc, v, jd));
    free(jd);
    return gap;
}

/* Points inside the 4 x 2 x 1 box (away from its faces), n of them. */
static double *inside_points(uint64_t *rng, size_t n)
{
    double *p = malloc(n * 3 * sizeof *p);
    for (size_t i = 0; i < n; ++i) {
        p[3 * i] = test_rng_range(rng, 0.05, 3.95);
        p[3 * i + 1] = test_rng_range(rng, 0.05, 1.95);
        p[3 * i + 2] = test_rng_range(rng, 0.05, 0.95);
    }
    return p;
}

/* Dense r^3 and r on the bore set; 2D thin plate on a grid. */
static void test_dense(cm_context *ctx)
{
    uint64_t rng = 11;
    size_t m;
    double *x = bore_centres(0.2, &m);
    const size_t np = 3000;
    double *p = inside_points(&rng, np);
    double *d = malloc(m * 3 * sizeof *d), *v = malloc(np * 3 * sizeof *v);
    double *jtv = malloc(m * 3 * sizeof *jtv);
    const cm_rbf_kernel kernels[2] = {CM_RBF_TRIHARMONIC, CM_RBF_BIHARMONIC};
    for (int kk = 0; kk < 2; ++kk) {
        cm_rbf_options o;
        cm_rbf_options_init(&o);
        o.solver = CM_RBF_SOLVER_DENSE;
        cm_rbf *r = NULL;
        CHECK(cm_rbf_create_opt(ctx, kernels[kk], 3, m, x, &o, &r) == CM_OK);
        if (!r) continue;
        for (int trial = 0; trial < 2; ++trial) {
            fill_random(&rng, m * 3, d);
            fill_random(&rng, np * 3, v);
            /* smooth data too: the bore's motion */
            if (trial == 1) bore_motion(m, x, 2.0, 1.0, d);
            printf("dense %s, m = %zu, n = %zu, %s d:\n", kernels[kk] ? "r" : "r^3", m, np,
                   trial ? "smooth" : "random");
            double gap = dot_gap(ctx, r, m, 3, d, np, p, v, jtv);
            CHECK_MSG(gap <= 1e-10, "gap %.3g", gap);
        }
        /* one component and the kept weights: evaluate after the transpose gives what it
         * gave before */
        double *e1 = malloc(np * sizeof *e1), *e2 = malloc(np * sizeof *e2);
        CHECK(cm_rbf_solve(ctx, r, 1, d) == CM_OK);
        CHECK(cm_rbf_evaluate(ctx, r, np, p, e1) == CM_OK);
        CHECK(cm_rbf_evaluate_transpose(ctx, r, np, p, 1, v, jtv) == CM_OK);
        CHECK(cm_rbf_evaluate(ctx, r, np, p, e2) == CM_OK);
        CHECK(memcmp(e1, e2, np * sizeof *e1) == 0);
        const double a = dot(np, v, e1), b = dot(m, jtv, d);
        CHECK_MSG(fabs(a - b) <= 1e-10 * dot_abs(np, v, e1), "%.17g vs %.17g", a, b);
        free(e1), free(e2);
        cm_rbf_destroy(&r);
    }
    /* thin plate, 2D: a 12 x 9 grid of centres, values at 500 points */
    {
        const size_t m2 = 108, n2 = 500;
        double *c2 = malloc(m2 * 2 * sizeof *c2), *p2 = malloc(n2 * 2 * sizeof *p2);
        for (size_t i = 0; i < m2; ++i) {
            c2[2 * i] = 100.0 + 3.0 * (double)(i % 12) + 0.3 * test_rng_uniform(&rng);
            c2[2 * i + 1] = -50.0 + 3.0 * (double)(i / 12);
        }
        for (size_t i = 0; i < n2; ++i) {
            p2[2 * i] = test_rng_range(&rng, 100.0, 133.0);
            p2[2 * i + 1] = test_rng_range(&rng, -50.0, -26.0);
        }
        cm_rbf *r = NULL;
        CHECK(cm_rbf_create(ctx, CM_RBF_THIN_PLATE, 2, m2, c2, &r) == CM_OK);
        fill_random(&rng, m2 * 2, d);
        fill_random(&rng, n2 * 2, v);
        printf("thin plate 2D, m = %zu, n = %zu:\n", m2, n2);
        if (r) CHECK(dot_gap(ctx, r, m2, 2, d, n2, p2, v, jtv) <= 1e-10);
        cm_rbf_destroy(&r);
        free(c2), free(p2);
    }
    free(x), free(p), free(d), free(v), free(jtv);
}

/* Merged duplicates: the set with 40 centres repeated (to 1e-14 of the box), the values
 * repeated with them. The reverse product is that of the set without them, all of it at
 * the first of each pair, 0 at the repeats. */
static void test_duplicates(cm_context *ctx)
{
    uint64_t rng = 23;
    size_t m;
    double *x = bore_centres(0.25, &m);
    const size_t extra = 40, md = m + extra, np = 1500;
    double *xd = malloc(md * 3 * sizeof *xd);
    size_t *src = malloc(md * sizeof *src);
    /* the repeats are interleaved: each copy right before the original's successor */
    for (size_t i = 0, j = 0; i < m; ++i) {
        memcpy(xd + 3 * j, x + 3 * i, 3 * sizeof *xd);
        src[j++] = i;
        if (i % 7 == 3 && j - i <= extra) {
            for (int e = 0; e < 3; ++e) xd[3 * j + (size_t)e] = x[3 * i + (size_t)e] * (1.0 + 1e-15);
            src[j++] = i;
        }
    }
    double *p = inside_points(&rng, np);
    double *d = malloc(m * 3 * sizeof *d), *dd = malloc(md * 3 * sizeof *dd);
    double *v = malloc(np * 3 * sizeof *v);
    double *jtv = malloc(m * 3 * sizeof *jtv), *jtvd = malloc(md * 3 * sizeof *jtvd);
    fill_random(&rng, m * 3, d);
    fill_random(&rng, np * 3, v);
    for (size_t j = 0; j < md; ++j) memcpy(dd + 3 * j, d + 3 * src[j], 3 * sizeof *dd);
    cm_rbf *r = NULL, *rd = NULL;
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &r) == CM_OK);
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, md, xd, &rd) == CM_OK);
    if (r && rd) {
        CHECK(cm_rbf_centre_count(rd) == m);
        printf("merged duplicates, %zu centres given, %zu after merging:\n", md, m);
        CHECK(dot_gap(ctx, rd, md, 3, dd, np, p, v, jtvd) <= 1e-10);
        CHECK(cm_rbf_evaluate_transpose(ctx, r, np, p, 3, v, jtv) == CM_OK);
        double worst = 0.0, scale = 0.0;
        int zero = 1;
        for (size_t j = 0; j < md; ++j) {
            const int first = j == 0 || src[j] != src[j - 1];
            for (int e = 0; e < 3; ++e) {
                double a = jtvd[3 * j + (size_t)e];
                if (first) {
                    worst = fmax(worst, fabs(a - jtv[3 * src[j] + (size_t)e]));
                    scale = fmax(scale, fabs(jtv[3 * src[j] + (size_t)e]));
                } else if (a != 0.0) {
                    zero = 0;
                }
            }
        }
        CHECK(zero);
        CHECK_MSG(worst <= 1e-9 * scale, "duplicates vs none: %.3g of %.3g", worst, scale);
    }
    cm_rbf_destroy(&r), cm_rbf_destroy(&rd);
    free(x), free(xd), free(src), free(p), free(d), free(dd), free(v), free(jtv), free(jtvd);
}

/* The iterative solver at a tight tolerance: the dot-product test, and J^T v against the
 * dense solver's; then with the treecode forced for the evaluation and its transpose. */
static void test_iterative(cm_context *ctx)
{
    uint64_t rng = 37;
    size_t m;
    double *x = bore_centres(0.1, &m);
    const size_t np = 20000;
    double *p = inside_points(&rng, np);
    double *d = malloc(m * 3 * sizeof *d), *v = malloc(np * 3 * sizeof *v);
    double *jtv = malloc(m * 3 * sizeof *jtv), *jtv_dense = malloc(m * 3 * sizeof *jtv_dense);
    bore_motion(m, x, 2.0, 1.0, d);
    fill_random(&rng, np * 3, v);
    cm_rbf_options o;
    cm_rbf_options_init(&o);
    cm_rbf_tuning tun;
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_DENSE;
    cm_rbf *rdense = NULL, *r = NULL;
    CHECK(cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &rdense) == CM_OK);
    if (rdense) {
        CHECK(cm_rbf_evaluate_transpose(ctx, rdense, np, p, 3, v, jtv_dense) == CM_OK);
        cm_rbf_stats sd;
        cm_rbf_get_stats(rdense, &sd);
        printf("dense reverse solve: residual %.3g after %d refinement steps\n", sd.residual,
               sd.iterations);
    }
    cm_rbf_destroy(&rdense);
    const double tols[2] = {1e-6, 1e-13};
    for (int fast = 0; fast < 2; ++fast) {
        for (int t = 0; t < 2; ++t) {
            if (fast && t == 0) continue;
            o.solver = CM_RBF_SOLVER_ITERATIVE;
            o.tolerance = tols[t];
            o.max_iterations = 600;
            o.fast_sum = fast;
            /* the forward evaluation's treecode to near rounding, so that the dot-product
             * test measures the transpose, not the 1e-9 the evaluation is allowed */
            tun.fast_eval_tol = fast ? 1e-14 : 1e-9;
            CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_OK);
            if (!r) continue;
            printf("iterative, m = %zu, n = %zu, tolerance %g, fast sums %d:\n", m, np, tols[t],
                   fast);
            double gap = dot_gap(ctx, r, m, 3, d, np, p, v, jtv);
            cm_rbf_stats st;
            cm_rbf_get_stats(r, &st);
            if (fast) {
                CHECK_MSG(st.eval_fast == 1, "forward evaluation not by the treecode");
                CHECK_MSG(cm_rbf_iterative_transpose_was_fast(r) == 1,
                          "transposed evaluation not by the treecode");
            }
            double diff = max_diff(m * 3, jtv, jtv_dense), scale = 0.0;
            for (size_t i = 0; i < m * 3; ++i) scale = fmax(scale, fabs(jtv_dense[i]));
            printf("  |J^T v - dense| / max |dense| = %.3g (residual of the reverse solve %.3g, "
                   "%d iterations)\n",
                   diff / scale, st.residual, st.iterations);
            if (t == 1) CHECK_MSG(gap <= 1e-10, "gap %.3g", gap);
            /* against the dense reverse product: as a functional of the smooth d (what a
             * gradient is) to the tolerance; entry by entry only to the tolerance times the
             * growth of weights (A^-1 of the residual is the error; 6e4 on this set, seen:
             * 1e-6 -> 6e-2, 1e-13 -> 1e-8 of max |J^T v|) */
            double *dj = malloc(m * 3 * sizeof *dj);
            for (size_t i = 0; i < m * 3; ++i) dj[i] = jtv[i] - jtv_dense[i];
            const double dual = fabs(dot(m * 3, dj, d)) / dot_abs(m * 3, jtv_dense, d);
            free(dj);
            printf("  |<J^T v - dense, d>| / sum |dense d| = %.3g\n", dual);
            CHECK_MSG(dual <= 10.0 * tols[t] || dual <= 1e-12, "%.3g", dual);
            CHECK_MSG(diff <= 1e6 * tols[t] * scale, "%.3g", diff / scale);
            cm_rbf_destroy(&r);
        }
    }
    free(x), free(p), free(d), free(v), free(jtv), free(jtv_dense);
}

static void test_arguments(cm_context *ctx)
{
    size_t m;
    double *x = bore_centres(0.5, &m);
    cm_rbf *r = NULL;
    double p[3] = {1, 1, 0.5}, v[3] = {1, 2, 3}, *out = malloc(m * 3 * sizeof *out);
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &r) == CM_OK);
    CHECK(cm_rbf_evaluate_transpose(ctx, NULL, 1, p, 3, v, out) == CM_ERR_ARGUMENT);
    CHECK(cm_rbf_evaluate_transpose(ctx, r, 1, p, 0, v, out) == CM_ERR_ARGUMENT);
    CHECK(cm_rbf_evaluate_transpose(ctx, r, 1, NULL, 3, v, out) == CM_ERR_ARGUMENT);
    v[1] = NAN;
    CHECK(cm_rbf_evaluate_transpose(ctx, r, 1, p, 3, v, out) == CM_ERR_NUMERIC);
    /* no points: nothing flows back */
    out[0] = 7.0;
    CHECK(cm_rbf_evaluate_transpose(ctx, r, 0, NULL, 3, NULL, out) == CM_OK && out[0] == 0.0);
    cm_rbf_destroy(&r);
    free(x), free(out);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    test_dense(ctx);
    test_duplicates(ctx);
    test_iterative(ctx);
    test_arguments(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
