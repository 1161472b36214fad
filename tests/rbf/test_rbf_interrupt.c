/* Stopping the RBF core on request (cm_context_interrupt, docs/DESIGN.md "progress"):
 *  - the sums cut into chunks with progress between them (kernel sums plain and compensated,
 *    the treecode, the assembly of the projected matrix) are the bits of one pass, on 1 and
 *    2 threads;
 *  - cm_rbf_create (dense: assembly and Cholesky; iterative: the local solves) stopped at a
 *    progress point gives no object; cm_rbf_solve (FGMRES) stopped keeps the last weights
 *    and solves again to the bits of a fresh fit; cm_rbf_evaluate stopped between chunks;
 *    a request made before a call stops it at the first point, cm_context_clear drops one. */
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "sum/rbf_treecode.h"
#include "test_rng.h"
#include "test_stopper.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

/* n points in [-1, 1]^3, n x 3 (AoS) */
static double *random_points(size_t n, uint64_t seed)
{
    double *p = malloc(3 * n * sizeof *p);
    for (size_t i = 0; i < 3 * n; ++i) p[i] = test_rng_range(&seed, -1.0, 1.0);
    return p;
}

/* the same as 3 x n SoA */
static double *soa(const double *p, size_t n)
{
    double *q = malloc(3 * n * sizeof *q);
    for (size_t i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) q[(size_t)d * n + i] = p[3 * i + (size_t)d];
    return q;
}

/* A tick that never reports (no context) but cuts the work into many chunks. */
static void small_chunks(cm_rbf_tick *t)
{
    cm_rbf_tick_init(t, NULL, "test", 1e300);
    t->chunk_pairs = 2e5;
    t->tree_chunks = 8;
}

static void test_chunks_same_bits(cm_context *ctx)
{
    const size_t m = 400, n = 20000;
    double *c = random_points(m, 1), *pa = random_points(n, 2);
    double *p = soa(pa, n), *vals = malloc(3 * m * sizeof *vals);
    uint64_t seed = 3;
    for (size_t i = 0; i < 3 * m; ++i) vals[i] = test_rng_range(&seed, -1, 1);
    cm_rbf *r = NULL;
    cm_rbf_options o;
    cm_rbf_options_init(&o);
    o.solver = CM_RBF_SOLVER_DENSE;
    cm_status s = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &o, &r);
    if (s >= 0) s = cm_rbf_solve(ctx, r, 3, vals);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    double *a = malloc(3 * n * sizeof *a), *b = malloc(3 * n * sizeof *b);
    for (int threads = 1; r && threads <= 2; ++threads) {
        cm_rbf_tick t;
        /* plain sums (dense evaluation) */
        cm_rbf_kernel_sum_all(r, r->w, 3, n, p, n, a, threads);
        small_chunks(&t);
        CHECK(cm_rbf_kernel_sum_all_tick(r, r->w, 3, n, p, n, b, threads, &t) == 0);
        CHECK_MSG(!memcmp(a, b, 3 * n * sizeof *a), "plain sums in chunks differ (%d threads)",
                  threads);
        CHECK(t.done == (double)n * (double)m); /* every chunk counted */
        /* compensated sums (iterative evaluation) */
        cm_rbf_kernel_sum_acc(m, r->c, r->w, 3, n, p, n, a, 3, threads);
        small_chunks(&t);
        CHECK(cm_rbf_kernel_sum_acc_tick(m, r->c, r->w, 3, n, p, n, b, 3, threads, &t) == 0);
        CHECK_MSG(!memcmp(a, b, 3 * n * sizeof *a),
                  "compensated sums in chunks differ (%d threads)", threads);
        /* the treecode */
        cm_rbf_tree *tree = cm_rbf_tree_create(m, r->c, 6, 0.5);
        cm_rbf_tree_targets *tg = cm_rbf_tree_targets_create(n, p, n);
        CHECK(tree && tg);
        if (tree && tg) {
            CHECK(cm_rbf_tree_sum_targets(tree, tg, 1, r->w, 3, a, 3, threads) == 0);
            small_chunks(&t);
            CHECK(cm_rbf_tree_sum_targets_tick(tree, tg, 1, r->w, 3, b, 3, threads, &t) == 0);
            CHECK_MSG(!memcmp(a, b, 3 * n * sizeof *a), "treecode in chunks differs (%d threads)",
                      threads);
            CHECK_NEAR(t.done, 1.0, 1e-12);
        }
        cm_rbf_tree_targets_destroy(&tg);
        cm_rbf_tree_destroy(&tree);
        /* the projected matrix, in packed storage */
        const int k = 4;
        const size_t n2 = m - (size_t)k, len = n2 * (n2 + 1) / 2;
        double *v = malloc(m * (size_t)k * sizeof *v), *z = malloc(m * (size_t)k * sizeof *z);
        double *ra = malloc(len * sizeof *ra), *rb = malloc(len * sizeof *rb);
        for (size_t i = 0; i < m * (size_t)k; ++i) {
            v[i] = test_rng_range(&seed, -1, 1);
            z[i] = test_rng_range(&seed, -1, 1);
        }
        cm_rbf_assemble_projected(CM_RBF_TRIHARMONIC, 3, m, r->c, k, v, z, 1.0, ra, threads);
        small_chunks(&t);
        t.chunk_pairs = 4000; /* a few columns a chunk */
        CHECK(cm_rbf_assemble_projected_tick(CM_RBF_TRIHARMONIC, 3, m, r->c, k, v, z, 1.0, rb,
                                             threads, &t) == 0);
        CHECK_MSG(!memcmp(ra, rb, len * sizeof *ra), "assembly in chunks differs (%d threads)",
                  threads);
        CHECK(t.done == (double)len);
        free(v), free(z), free(ra), free(rb);
    }
    cm_rbf_destroy(&r);
    free(c), free(pa), free(p), free(vals), free(a), free(b);
}

/* Values of a smooth field at the centres (n x 3). */
static double *field(const double *c, size_t m)
{
    double *f = malloc(3 * m * sizeof *f);
    for (size_t i = 0; i < m; ++i) {
        const double *x = c + 3 * i;
        f[3 * i] = sin(x[0]) * x[1];
        f[3 * i + 1] = x[2] * x[2] - x[0];
        f[3 * i + 2] = cos(x[1] + x[2]);
    }
    return f;
}

static void test_create(cm_context *ctx, stopper *st, cm_rbf_solver solver, size_t m,
                        const char *name)
{
    double *c = random_points(m, 11);
    cm_rbf_options o;
    cm_rbf_options_init(&o);
    o.solver = solver;
    o.tolerance = 1e-9;
    cm_rbf *r = NULL;
    arm(st, 0);
    cm_status s = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &o, &r);
    CHECK_MSG(s >= 0 && r, "%s: %s", name, cm_context_message(ctx));
    const int calls = st->calls;
    printf("%s create (%zu centres): %d progress points\n", name, m, calls);
    CHECK(calls >= 3);
    cm_rbf_destroy(&r);
    const int at[3] = {1, (calls + 1) / 2, calls};
    for (int k = 0; k < 3; ++k) {
        arm(st, at[k]);
        r = (cm_rbf *)1;
        s = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &o, &r);
        CHECK_MSG(interrupted(ctx, s) && !r && st->calls == at[k],
                  "%s: create stopped at %d (%s): status %d, %d calls, %s", name, at[k],
                  st->stage, (int)s, st->calls, cm_context_message(ctx));
    }
    /* asked before: the first point; cleared: runs */
    arm(st, 0);
    cm_context_interrupt(ctx);
    s = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &o, &r);
    CHECK_MSG(interrupted(ctx, s) && !r && st->calls == 1, "%s: early request", name);
    cm_context_interrupt(ctx);
    cm_context_clear(ctx);
    s = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &o, &r);
    CHECK_MSG(s >= 0 && r, "%s: after cm_context_clear: %s", name, cm_context_message(ctx));
    cm_rbf_destroy(&r);
    free(c);
}

/* FGMRES stopped at its k-th iteration keeps the weights of the last solve; solving again
 * gives the bits of a fresh fit's solve. */
static void test_solve(cm_context *ctx, stopper *st)
{
    const size_t m = 3000;
    double *c = random_points(m, 21), *f = field(c, m), *g = malloc(3 * m * sizeof *g);
    for (size_t i = 0; i < 3 * m; ++i) g[i] = 0.5 * f[i] + 0.1;
    cm_rbf_options o;
    cm_rbf_options_init(&o);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    o.tolerance = 1e-9;
    /* from zero: a warm start would begin from the weights of g, kept by the interrupted
     * solves, where a fresh fit has none */
    o.warm_start = 0;
    cm_rbf *r = NULL, *fresh = NULL;
    arm(st, 0);
    cm_status s = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &o, &r);
    if (s >= 0) s = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &o, &fresh);
    if (s >= 0) s = cm_rbf_solve(ctx, fresh, 3, f);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    if (s < 0) goto done;
    arm(st, 0);
    s = cm_rbf_solve(ctx, r, 3, g);
    const int calls = st->calls;
    CHECK_MSG(s >= 0 && calls >= 2, "solve: %d progress points, %s", calls, cm_context_message(ctx));
    printf("iterative solve (%zu centres): %d progress points\n", m, calls);
    double *w_g = malloc(3 * m * sizeof *w_g);
    memcpy(w_g, r->w, 3 * m * sizeof *w_g);
    const int at[2] = {1, calls};
    for (int k = 0; k < 2; ++k) {
        arm(st, at[k]);
        s = cm_rbf_solve(ctx, r, 3, f);
        CHECK_MSG(interrupted(ctx, s) && st->calls == at[k], "solve stopped at %d: status %d",
                  at[k], (int)s);
        CHECK_MSG(!memcmp(r->w, w_g, 3 * m * sizeof *w_g), "an interrupted solve changed the weights");
    }
    arm(st, 0);
    s = cm_rbf_solve(ctx, r, 3, f);
    CHECK_MSG(s >= 0 && !memcmp(r->w, fresh->w, 3 * m * sizeof *w_g) &&
                  !memcmp(r->q, fresh->q, 3 * (size_t)r->k * sizeof *r->q),
              "solve after interrupted ones differs from a fresh fit's");
    free(w_g);

    /* evaluation at many points: stopped between chunks (by time: asked before the call, it
     * stops at the first report), then the same values as without */
    const size_t n = 100000;
    double *p = random_points(n, 31), *a = malloc(3 * n * sizeof *a), *b = malloc(3 * n * sizeof *b);
    arm(st, 0);
    s = cm_rbf_evaluate(ctx, r, n, p, a);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    printf("evaluation at %zu points: %d progress points\n", n, st->calls);
    if (st->calls > 0) {
        arm(st, 0);
        cm_context_interrupt(ctx);
        s = cm_rbf_evaluate(ctx, r, n, p, b);
        CHECK_MSG(interrupted(ctx, s) && st->calls == 1, "evaluate: status %d, %d calls", (int)s,
                  st->calls);
        arm(st, 0);
        s = cm_rbf_evaluate(ctx, r, n, p, b);
        CHECK(s >= 0 && !memcmp(a, b, 3 * n * sizeof *a));
    }
    free(p), free(a), free(b);
done:
    cm_rbf_destroy(&r);
    cm_rbf_destroy(&fresh);
    free(c), free(f), free(g);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    test_chunks_same_bits(ctx);
    stopper st = {ctx, 0, 0, ""};
    cm_context_set_progress(ctx, on_progress, &st);
    test_create(ctx, &st, CM_RBF_SOLVER_DENSE, 1500, "dense");
    /* one thread: the local solves report from the caller's thread, every subdomain */
    cm_context_set_threads(ctx, 1);
    test_create(ctx, &st, CM_RBF_SOLVER_ITERATIVE, 3000, "iterative");
    cm_context_set_threads(ctx, 2);
    test_solve(ctx, &st);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
