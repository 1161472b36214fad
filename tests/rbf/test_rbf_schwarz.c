/* The Schwarz preconditioner's kD-tree on sets with many tied coordinates, as CAD boundary
 * sets have (thousands of centres on one axis-aligned planar face): the leaves partition the
 * centres and no two leaf boxes touch, so no leaf holds a scattered subset of a plane. A
 * median split inside such a group made slab leaves whose nearly coplanar local solves
 * stalled the two-body bracket (RESULTS.md, RBF solvers). And the bodies
 * the subdomains see (rbf_bodies.c): one for one part, two for two parts far apart, and the
 * projection leaves no linear moment on either. */
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "rbf_tuning.h"
#include "rbf_test_sets.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Leaves of the preconditioner of x (m centres, 3 x m in r->c after scaling): each centre in
 * exactly one leaf, and the count of leaf pairs whose boxes touch or overlap. */
static void check_leaves(cm_context *ctx, const char *name, size_t m, const double *x)
{
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    tun.leaf_size = 64; /* many splits on a small set */
    tun.local_size = 200;
    cm_rbf *r = NULL;
    cm_status s = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r);
    CHECK_MSG(s == CM_OK, "%s: %s", name, cm_context_message(ctx));
    if (s != CM_OK) return;
    const cm_rbf_schwarz *pc = cm_rbf_iterative_pc(r);
    const int nl = cm_rbf_schwarz_subdomains(pc);
    const double *c = r->c;
    double *box = malloc((size_t)nl * 6 * sizeof *box);
    int *own = calloc(m, sizeof *own);
    for (int l = 0; l < nl; ++l) {
        size_t n, nin;
        const size_t *idx = cm_rbf_schwarz_subdomain(pc, l, &n, &nin);
        double *lo = box + 6 * l, *hi = lo + 3;
        for (int d = 0; d < 3; ++d) lo[d] = INFINITY, hi[d] = -INFINITY;
        for (size_t u = 0; u < nin; ++u) {
            ++own[idx[u]];
            for (int d = 0; d < 3; ++d) {
                lo[d] = fmin(lo[d], c[(size_t)d * m + idx[u]]);
                hi[d] = fmax(hi[d], c[(size_t)d * m + idx[u]]);
            }
        }
    }
    size_t unowned = 0;
    for (size_t i = 0; i < m; ++i) unowned += own[i] != 1;
    int touching = 0;
    for (int a = 0; a < nl; ++a)
        for (int b = a + 1; b < nl; ++b) {
            const double *la = box + 6 * a, *lb = box + 6 * b;
            int apart = 0;
            for (int d = 0; d < 3; ++d) apart |= la[d + 3] < lb[d] || lb[d + 3] < la[d];
            touching += !apart;
        }
    printf("%s: m = %zu, %d leaves, %d pairs of touching leaf boxes, %zu centres not in "
           "exactly one leaf\n", name, m, nl, touching, unowned);
    CHECK_MSG(nl > 16, "%s: %d leaves", name, nl);
    CHECK_MSG(unowned == 0, "%s: %zu", name, unowned);
    CHECK_MSG(touching == 0, "%s: %d pairs", name, touching);
    free(box);
    free(own);
    cm_rbf_destroy(&r);
}

/* Linear moments (sum w, sum w x, y, z) of w on the centres [i0, i1) of r->c, largest
 * relative to sum |w| |(1, x)|. */
static double moments(const cm_rbf *r, const double *w, size_t i0, size_t i1)
{
    const size_t m = r->m;
    double worst = 0.0;
    for (int a = 0; a < 4; ++a) {
        double s = 0.0, t = 0.0;
        for (size_t i = i0; i < i1; ++i) {
            double p = a == 0 ? 1.0 : r->c[(size_t)(a - 1) * m + i];
            s += w[i] * p;
            t += fabs(w[i] * p);
        }
        worst = fmax(worst, t > 0.0 ? fabs(s) / t : 0.0);
    }
    return worst;
}

static void test_bodies(cm_context *ctx)
{
    const double off0[3] = {0.0, 0.0, 0.0}, off1[3] = {40.0, 15.0, -8.0};
    size_t m0 = box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.1, off0, NULL);
    size_t m1 = box_with_bore(3.0, 1.5, 1.0, 1.5, 0.75, 0.3, 0.1, off1, NULL);
    const size_t m = m0 + m1;
    double *x = malloc(m * 3 * sizeof *x);
    box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.1, off0, x);
    box_with_bore(3.0, 1.5, 1.0, 1.5, 0.75, 0.3, 0.1, off1, x + 3 * m0);
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    for (int two = 0; two < 2; ++two) {
        const size_t n = two ? m : m0;
        cm_rbf *r = NULL;
        cm_status s = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, n, x, &o, &tun, &r);
        CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
        if (s != CM_OK) break;
        const cm_rbf_bodies *b = cm_rbf_schwarz_bodies(cm_rbf_iterative_pc(r));
        printf("bodies of %s: %d\n", two ? "two parts 40 apart" : "one part", cm_rbf_bodies_count(b));
        CHECK(cm_rbf_bodies_count(b) == (two ? 2 : 1));
        if (two) {
            /* random weights lose their moments on each body and nothing else */
            double *w = malloc(2 * m * sizeof *w), *w2 = w + m;
            srand(3);
            for (size_t i = 0; i < m; ++i) w[i] = rand() / (double)RAND_MAX - 0.5 + 0.1;
            double before = moments(r, w, 0, m0);
            cm_rbf_bodies_project(b, 1, m, w);
            double a0 = moments(r, w, 0, m0), a1 = moments(r, w, m0, m);
            memcpy(w2, w, m * sizeof *w);
            cm_rbf_bodies_project(b, 1, m, w2);
            double again = 0.0;
            for (size_t i = 0; i < m; ++i) again = fmax(again, fabs(w2[i] - w[i]));
            printf("moments on body 1 before %.3g, after %.3g / %.3g; projected twice %.3g\n",
                   before, a0, a1, again);
            CHECK(before > 1e-3);
            CHECK_MSG(a0 <= 1e-13 && a1 <= 1e-13, "%.3g %.3g", a0, a1);
            CHECK_MSG(again <= 1e-15, "%.3g", again);
            free(w);
        }
        cm_rbf_destroy(&r);
    }
    free(x);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;

    /* the bore's boundary grid: planar faces, rows of equal coordinates everywhere */
    const double off[3] = {0.0, 0.0, 0.0};
    size_t m = box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.1, off, NULL);
    double *x = malloc(m * 3 * sizeof *x);
    box_with_bore(4.0, 2.0, 1.0, 2.0, 1.0, 0.4, 0.1, off, x);
    check_leaves(ctx, "box with bore", m, x);
    free(x);

    /* an unstructured planar face (3/4 of the centres on z = 0, at random) under a layer of
     * centres just above it: once the cells are narrow, z is the widest axis and its median
     * lies inside the face */
    m = 4000;
    x = malloc(m * 3 * sizeof *x);
    srand(7);
    for (size_t i = 0; i < m; ++i) {
        x[3 * i] = 4.0 * rand() / (double)RAND_MAX;
        x[3 * i + 1] = 4.0 * rand() / (double)RAND_MAX;
        x[3 * i + 2] = i % 4 ? 0.0 : 1.0 * rand() / (double)RAND_MAX + 1e-3;
    }
    check_leaves(ctx, "planar face", m, x);
    free(x);

    test_bodies(ctx);

    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
