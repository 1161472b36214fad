/* Thinned overlap (thin_reach, rbf_thin.c): a thinned subdomain keeps its leaf and its near
 * set, stays within its cap, reaches the geometric distance (every centre within the reach
 * lies within a voxel diagonal of a pick) with fewer centres than the full overlap there,
 * and the solver with thinning agrees with the dense one on a box-with-bore set at ~5k. */
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "rbf_tuning.h"
#include "rbf_test_sets.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double box_d2(const double *c, size_t m, size_t i, const double *lo, const double *hi)
{
    double s = 0.0;
    for (int d = 0; d < 3; ++d) {
        double x = c[(size_t)d * m + i];
        double e = x < lo[d] ? lo[d] - x : x > hi[d] ? x - hi[d] : 0.0;
        s += e * e;
    }
    return s;
}

/* The subdomains of a thinned preconditioner on x (m centres): leaves partition the centres,
 * counts within the cap, every centre within the reach covered by a pick. */
static void check_subdomains(cm_context *ctx, const cm_rbf_options *o, const cm_rbf_tuning *tun, size_t m, const double *x,
                             int expect_cap_hit)
{
    cm_rbf *r = NULL;
    cm_status s = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, o, tun, &r);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (s != CM_OK) return;
    const cm_rbf_schwarz *pc = cm_rbf_iterative_pc(r);
    const double H = cm_rbf_schwarz_fill(pc), R = tun->thin_reach * H;
    const size_t mm = r->m;
    const double *c = r->c;
    CHECK(H > 0.0 && mm == m);
    int *own = calloc(mm, sizeof *own);
    unsigned char *in = calloc(mm, 1);
    const int nsub = cm_rbf_schwarz_subdomains(pc);
    int uncovered = 0, over_cap = 0, beyond = 0, capped = 0;
    double ratio = 0.0, reach = 0.0;
    for (int l = 0; l < nsub; ++l) {
        size_t n, nin;
        const size_t *idx = cm_rbf_schwarz_subdomain(pc, l, &n, &nin);
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t u = 0; u < nin; ++u) {
            ++own[idx[u]];
            for (int d = 0; d < 3; ++d) {
                lo[d] = fmin(lo[d], c[(size_t)d * mm + idx[u]]);
                hi[d] = fmax(hi[d], c[(size_t)d * mm + idx[u]]);
            }
        }
        if (n > (size_t)tun->thin_max) ++over_cap;
        if (n == (size_t)tun->thin_max) ++capped;
        double far = 0.0;
        for (size_t u = 0; u < n; ++u) {
            in[idx[u]] = 1;
            double d2 = box_d2(c, mm, idx[u], lo, hi);
            far = fmax(far, d2);
            if (d2 > R * R * (1.0 + 1e-12)) ++beyond;
        }
        reach += sqrt(far) / R;
        /* coverage: a centre within the reach is at most a voxel diagonal (sqrt 3 x cell x
         * its distance, or the fill distance where the band starts) from a pick */
        size_t within = 0;
        for (size_t i = 0; i < mm; ++i) {
            double d2 = box_d2(c, mm, i, lo, hi);
            if (d2 > R * R) continue;
            ++within;
            if (in[i] || n >= (size_t)tun->thin_max) continue;
            const double tol = sqrt(3.0) * tun->thin_cell * fmax(sqrt(d2), H) * (1.0 + 1e-9);
            int ok = 0;
            for (size_t u = 0; u < n && !ok; ++u) {
                double e = 0.0;
                for (int d = 0; d < 3; ++d) {
                    double t = c[(size_t)d * mm + i] - c[(size_t)d * mm + idx[u]];
                    e += t * t;
                }
                ok = e <= tol * tol;
            }
            uncovered += !ok;
        }
        ratio += (double)n / (double)within;
        for (size_t u = 0; u < n; ++u) in[idx[u]] = 0;
    }
    int part = 1;
    for (size_t i = 0; i < mm; ++i) part &= own[i] == 1;
    printf("thin_reach %g H (H %.3g), cell %g, cap %d: %d subdomains, mean count / full overlap "
           "%.2f, mean reach %.2f of R, %d at the cap, %d uncovered\n", tun->thin_reach, H,
           tun->thin_cell, tun->thin_max, nsub, ratio / nsub, reach / nsub, capped, uncovered);
    CHECK_MSG(part, "the leaves (first n_in of each subdomain) do not partition the centres");
    CHECK_MSG(over_cap == 0 && beyond == 0, "%d over the cap, %d centres beyond the reach",
              over_cap, beyond);
    if (expect_cap_hit) {
        CHECK_MSG(capped > nsub / 2, "%d of %d at the cap", capped, nsub);
    } else {
        CHECK_MSG(uncovered == 0, "%d centres within the reach not covered", uncovered);
        CHECK_MSG(ratio / nsub < 0.75, "thinning kept %.2f of the full overlap", ratio / nsub);
        CHECK_MSG(reach / nsub > 0.9, "mean reach %.2f of R", reach / nsub);
    }
    free(own);
    free(in);
    cm_rbf_destroy(&r);
}

static void test_thin(cm_context *ctx)
{
    double *x = NULL, *d = NULL;
    size_t m = bore_set(0.076, &x, &d);
    cm_rbf_options o;
    cm_rbf_tuning tun;
    cm_rbf_options_init(&o);
    cm_rbf_tuning_init(&tun);
    o.solver = CM_RBF_SOLVER_ITERATIVE;
    tun.leaf_size = 128;
    tun.local_size = 300;
    tun.overlap = 0.0; /* the near set by count alone */
    tun.coarse_size = 500;
    tun.thin_reach = 8.0;
    tun.thin_cell = 0.3;
    tun.thin_max = 5000; /* no cap: the reach and the coverage */
    check_subdomains(ctx, &o, &tun, m, x, 0);
    tun.thin_max = 450; /* the cap */
    check_subdomains(ctx, &o, &tun, m, x, 1);

    /* the solver with thinning against dense, at the centres and inside */
    size_t np = 0;
    double *p = eval_points(m, x, 1500, 1.8, &np);
    double *sd = malloc(np * 3 * sizeof *sd), *st = malloc(np * 3 * sizeof *st);
    cm_rbf_stats sdn, sth;
    cm_rbf *r = NULL;
    cm_rbf_options od;
    cm_rbf_tuning tun_d;
    cm_rbf_options_init(&od);
    cm_rbf_tuning_init(&tun_d);
    od.solver = CM_RBF_SOLVER_DENSE;
    cm_status a = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &od, &tun_d, &r);
    if (a == CM_OK) a = cm_rbf_solve(ctx, r, 3, d);
    if (a == CM_OK) a = cm_rbf_evaluate(ctx, r, np, p, sd);
    cm_rbf_get_stats(r, &sdn);
    cm_rbf_destroy(&r);
    tun.thin_max = 700;
    {
        cm_status b = cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r);
        if (b == CM_OK) b = cm_rbf_solve(ctx, r, 3, d);
        if (b == CM_OK) b = cm_rbf_evaluate(ctx, r, np, p, st);
        cm_rbf_get_stats(r, &sth);
        cm_rbf_destroy(&r);
        CHECK_MSG(a == CM_OK && b == CM_OK, "dense %d thinned %d: %s", a, b,
                  cm_context_message(ctx));
        const double range = range_of(m * 3, d), diff = max_diff(np * 3, sd, st) / range;
        printf("thinned vs dense: m = %zu, %d iterations, residual %.3g, |thinned - dense| = "
               "%.3g of the range\n", m, sth.iterations, sth.residual, diff);
        CHECK_MSG(diff <= 1e-9, "%.3g", diff);
        CHECK_MSG(sth.residual <= fmax(1e-10, sth.floor), "%.3g", sth.residual);
        CHECK_MSG(sth.iterations >= 1 && sth.iterations <= 40, "%d iterations", sth.iterations);
    }

    /* bad options are refused */
    tun.thin_reach = -1.0;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT);
    tun.thin_reach = 4.0;
    tun.thin_cell = 0.0;
    CHECK(cm_rbf_create_tuned(ctx, CM_RBF_TRIHARMONIC, 3, m, x, &o, &tun, &r) == CM_ERR_ARGUMENT);
    CHECK(r == NULL);
    free(x), free(d), free(p), free(sd), free(st);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    test_thin(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
