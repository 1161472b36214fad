/* Tests of the RBF core: linear precision, interpolation, several right-hand sides, thread
 * independence, duplicate merging, and the refusals (coplanar/collinear, too few centres). */
#include "cadmorph/rbf.h"
#include "test_rng.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

static uint64_t rng_state = 88172645463325252ULL;

static double urand(void) { return test_rng_uniform(&rng_state); }

/* Centres in an off-centre, anisotropic box, so that the unit-box map matters. */
static void random_points(int dim, size_t n, double *x)
{
    static const double lo[3] = {-2.0, 10.0, 1e3}, len[3] = {7.0, 0.5, 3.0};
    for (size_t i = 0; i < n; ++i)
        for (int d = 0; d < dim; ++d) x[i * (size_t)dim + (size_t)d] = lo[d] + len[d] * urand();
}

static double max_abs(size_t n, const double *x)
{
    double v = 0.0;
    for (size_t i = 0; i < n; ++i) v = fmax(v, fabs(x[i]));
    return v;
}

static double max_diff(size_t n, const double *a, const double *b)
{
    double v = 0.0;
    for (size_t i = 0; i < n; ++i) v = fmax(v, fabs(a[i] - b[i]));
    return v;
}

/* A smooth field with O(1) derivatives on the test boxes. */
static double smooth(int dim, const double *x, int r)
{
    return sin(0.7 * x[0] + r) * cos(3.0 * x[1]) + (0.2 + r) * 0.1 * x[dim - 1];
}

static const char *kname(cm_rbf_kernel k)
{
    return k == CM_RBF_TRIHARMONIC ? "r^3" : k == CM_RBF_BIHARMONIC ? "r" : "r^2 log r";
}

/* Affine data A x + b is reproduced exactly (linear precision) at random points. */
static void test_linear_precision(cm_context *ctx, cm_rbf_kernel kern)
{
    const int dim = kern == CM_RBF_THIN_PLATE ? 2 : 3, nc = dim;
    const size_t m = 401, n = 700; /* m - dim - 1 odd in 3D, even in 2D: both RFP layouts */
    double *c = malloc(m * dim * sizeof *c), *v = malloc(m * nc * sizeof *v);
    double *p = malloc(n * dim * sizeof *p), *out = malloc(n * nc * sizeof *out);
    double *ref = malloc(n * nc * sizeof *ref);
    double a[3][3], b[3];
    for (int i = 0; i < nc; ++i) {
        b[i] = 10.0 * (urand() - 0.5);
        for (int j = 0; j < dim; ++j) a[i][j] = 4.0 * (urand() - 0.5);
    }
    random_points(dim, m, c);
    random_points(dim, n, p);
    for (size_t i = 0; i < n; ++i) /* also a little outside the box */
        p[i * dim] += 0.5 * (urand() - 0.5);
    for (size_t i = 0; i < m + n; ++i) {
        const double *x = i < m ? c + i * dim : p + (i - m) * dim;
        double *y = i < m ? v + i * nc : ref + (i - m) * nc;
        for (int r = 0; r < nc; ++r) {
            y[r] = b[r];
            for (int d = 0; d < dim; ++d) y[r] += a[r][d] * x[d];
        }
    }
    cm_rbf *rbf = NULL;
    cm_status st = cm_rbf_create(ctx, kern, dim, m, c, &rbf);
    CHECK_MSG(st == CM_OK, "%s: %s", kname(kern), cm_context_message(ctx));
    if (st == CM_OK) {
        CHECK(cm_rbf_centre_count(rbf) == m);
        CHECK(cm_rbf_solve(ctx, rbf, nc, v) == CM_OK);
        CHECK(cm_rbf_evaluate(ctx, rbf, n, p, out) == CM_OK);
        double err = max_diff(n * nc, out, ref) / max_abs(n * nc, ref);
        printf("%s: linear precision error %.3g\n", kname(kern), err);
        CHECK_MSG(err <= 1e-10, "%s: linear precision error %.3g", kname(kern), err);
    }
    cm_rbf_destroy(&rbf);
    CHECK(rbf == NULL);
    free(c), free(v), free(p), free(out), free(ref);
}

/* Interpolation at the centres for smooth nonlinear data; one factorisation, several
 * right-hand sides of different widths. */
static void test_interpolation(cm_context *ctx, cm_rbf_kernel kern)
{
    const int dim = kern == CM_RBF_THIN_PLATE ? 2 : 3;
    const size_t m = 600;
    double *c = malloc(m * dim * sizeof *c), *v = malloc(m * 6 * sizeof *v);
    double *out = malloc(m * 6 * sizeof *out);
    random_points(dim, m, c);
    cm_rbf *rbf = NULL;
    cm_status st = cm_rbf_create(ctx, kern, dim, m, c, &rbf);
    CHECK_MSG(st == CM_OK, "%s: %s", kname(kern), cm_context_message(ctx));
    if (st != CM_OK) goto done;
    static const int widths[] = {1, 3, 6, 2};
    for (size_t t = 0; t < sizeof widths / sizeof widths[0]; ++t) {
        int nc = widths[t];
        for (size_t i = 0; i < m; ++i)
            for (int r = 0; r < nc; ++r) {
                const double *x = c + i * dim;
                v[i * nc + r] = sin(0.7 * x[0] + r) * cos(3.0 * x[1]) + (r + t) * 0.1 * x[dim - 1] +
                                0.05 * urand();
            }
        CHECK(cm_rbf_solve(ctx, rbf, nc, v) == CM_OK);
        CHECK(cm_rbf_evaluate(ctx, rbf, m, c, out) == CM_OK);
        double err = max_diff(m * nc, out, v) / max_abs(m * nc, v);
        printf("%s: residual at centres %.3g (nc %d)\n", kname(kern), err, nc);
        CHECK_MSG(err <= 1e-10, "%s: residual at centres %.3g (nc %d)", kname(kern), err, nc);
    }
done:
    cm_rbf_destroy(&rbf);
    free(c), free(v), free(out);
}

/* The same fit and evaluation on 1 and 2 threads (sizes above the parallel thresholds). */
static void test_threads(cm_rbf_kernel kern)
{
    const int dim = kern == CM_RBF_THIN_PLATE ? 2 : 3, nc = 3;
    const size_t m = 1500, n = 5000;
    double *c = malloc(m * dim * sizeof *c), *v = malloc(m * nc * sizeof *v);
    double *p = malloc(n * dim * sizeof *p);
    double *out[2] = {malloc(n * nc * sizeof(double)), malloc(n * nc * sizeof(double))};
    random_points(dim, m, c);
    random_points(dim, n, p);
    for (size_t i = 0; i < m; ++i)
        for (int r = 0; r < nc; ++r) v[i * nc + r] = smooth(dim, c + i * dim, r);
    for (int t = 0; t < 2; ++t) {
        cm_context *ctx = NULL;
        cm_context_create(&ctx);
        cm_context_set_threads(ctx, t + 1);
        cm_rbf *rbf = NULL;
        CHECK(cm_rbf_create(ctx, kern, dim, m, c, &rbf) == CM_OK);
        CHECK(rbf && cm_rbf_solve(ctx, rbf, nc, v) == CM_OK);
        CHECK(rbf && cm_rbf_evaluate(ctx, rbf, n, p, out[t]) == CM_OK);
        cm_rbf_destroy(&rbf);
        cm_context_destroy(&ctx);
    }
    double err = max_diff(n * nc, out[0], out[1]) / max_abs(n * nc, out[0]);
    printf("%s: 1 vs 2 threads differ by %.3g\n", kname(kern), err);
    CHECK_MSG(err <= 1e-12, "%s: 1 vs 2 threads differ by %.3g", kname(kern), err);
    free(c), free(v), free(p), free(out[0]), free(out[1]);
}

/* Duplicates (exact and within 1e-12 of the diagonal) merge when their values agree and are
 * refused, naming both indices, when they do not. */
static void test_duplicates(cm_context *ctx)
{
    const size_t base = 200, m = base + 3;
    double *c = malloc(m * 3 * sizeof *c), *v = malloc(m * 3 * sizeof *v);
    double *out = malloc(m * 3 * sizeof *out);
    random_points(3, base, c);
    /* 200 = copy of 17, 201 = copy of 3 moved by ~1e-14 x diagonal, 202 = copy of 17 */
    memcpy(c + 200 * 3, c + 17 * 3, 3 * sizeof *c);
    memcpy(c + 201 * 3, c + 3 * 3, 3 * sizeof *c);
    c[201 * 3 + 0] += 1e-13;
    memcpy(c + 202 * 3, c + 17 * 3, 3 * sizeof *c);
    for (size_t i = 0; i < base; ++i)
        for (int r = 0; r < 3; ++r) v[i * 3 + r] = smooth(3, c + i * 3, r);
    memcpy(v + 200 * 3, v + 17 * 3, 3 * sizeof *v);
    memcpy(v + 201 * 3, v + 3 * 3, 3 * sizeof *v);
    memcpy(v + 202 * 3, v + 17 * 3, 3 * sizeof *v);
    cm_rbf *rbf = NULL;
    cm_status st = cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &rbf);
    CHECK_MSG(st == CM_OK, "%s", cm_context_message(ctx));
    if (st == CM_OK) {
        CHECK_MSG(cm_rbf_centre_count(rbf) == base, "%zu centres", cm_rbf_centre_count(rbf));
        CHECK(cm_rbf_solve(ctx, rbf, 3, v) == CM_OK);
        CHECK(cm_rbf_evaluate(ctx, rbf, m, c, out) == CM_OK);
        CHECK_MSG(max_diff(m * 3, out, v) <= 1e-10 * max_abs(m * 3, v), "dup residual %.3g", max_diff(m * 3, out, v));
        /* round-off between the copies is accepted (the first one's value is used) */
        v[201 * 3 + 1] += 1e-12 * max_abs(m * 3, v);
        CHECK_MSG(cm_rbf_solve(ctx, rbf, 3, v) == CM_OK, "%s", cm_context_message(ctx));
        v[201 * 3 + 1] = v[3 * 3 + 1];
        /* now the copy of 3 carries another value */
        v[201 * 3 + 1] += 1e-3 * max_abs(m * 3, v);
        CHECK(cm_rbf_solve(ctx, rbf, 3, v) == CM_ERR_NUMERIC);
        const char *msg = cm_context_message(ctx);
        CHECK_MSG(strstr(msg, " 3 ") && strstr(msg, " 201 "), "message: %s", msg);
        /* the old weights survive a refused solve */
        CHECK(cm_rbf_evaluate(ctx, rbf, m, c, out) == CM_OK);
        v[201 * 3 + 1] = v[3 * 3 + 1];
        CHECK_MSG(max_diff(m * 3, out, v) <= 1e-10 * max_abs(m * 3, v), "dup residual %.3g", max_diff(m * 3, out, v));
    }
    cm_rbf_destroy(&rbf);
    free(c), free(v), free(out);
}

/* Centres that leave the polynomial block singular, and too few centres. */
static void test_refusals(cm_context *ctx)
{
    const size_t m = 300;
    double *c = malloc(m * 3 * sizeof *c);
    cm_rbf *rbf = NULL;
    /* 3D: all on the tilted plane x + 2y - z = 4 */
    random_points(3, m, c);
    for (size_t i = 0; i < m; ++i) c[i * 3 + 2] = c[i * 3] + 2.0 * c[i * 3 + 1] - 4.0;
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &rbf) == CM_ERR_NUMERIC);
    CHECK(rbf == NULL);
    CHECK_MSG(strstr(cm_context_message(ctx), "coplanar"), "%s", cm_context_message(ctx));
    CHECK(cm_rbf_create(ctx, CM_RBF_BIHARMONIC, 3, m, c, &rbf) == CM_ERR_NUMERIC);
    /* 2D: all on the line v = 3u - 1 */
    random_points(2, m, c);
    for (size_t i = 0; i < m; ++i) c[i * 2 + 1] = 3.0 * c[i * 2] - 1.0;
    CHECK(cm_rbf_create(ctx, CM_RBF_THIN_PLATE, 2, m, c, &rbf) == CM_ERR_NUMERIC);
    CHECK_MSG(strstr(cm_context_message(ctx), "collinear"), "%s", cm_context_message(ctx));
    /* too few centres, before and after merging */
    random_points(3, m, c);
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, 3, c, &rbf) == CM_ERR_NUMERIC);
    CHECK(cm_rbf_create(ctx, CM_RBF_THIN_PLATE, 2, 2, c, &rbf) == CM_ERR_NUMERIC);
    for (int i = 0; i < 3; ++i) memcpy(c + 3 * (3 + i), c, 3 * sizeof *c);
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, 6, c, &rbf) == CM_ERR_NUMERIC);
    CHECK(rbf == NULL);
    /* exactly dim + 1 centres in general position: the interpolant is affine */
    random_points(3, 4, c);
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, 4, c, &rbf) == CM_OK);
    if (rbf) {
        double v[4] = {1, 2, 3, 4}, out[4];
        CHECK(cm_rbf_solve(ctx, rbf, 1, v) == CM_OK);
        CHECK(cm_rbf_evaluate(ctx, rbf, 4, c, out) == CM_OK);
        CHECK(max_diff(4, out, v) <= 1e-12 * 4);
    }
    cm_rbf_destroy(&rbf);
    /* near-duplicates just above the merge tolerance (40 pairs, so that rounding cannot let
     * every pivot through): r^3 cannot resolve them; the message has the pivot and names
     * two centres that really are that close */
    for (size_t i = 0; i < 3 * m; ++i) c[i] = urand();
    for (size_t i = 0; i < 40; ++i) {
        memcpy(c + 3 * (m - 1 - i), c + 3 * (2 * i + 1), 3 * sizeof *c);
        c[3 * (m - 1 - i)] += 1e-10;
    }
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &rbf) == CM_ERR_NUMERIC);
    {
        const char *msg = cm_context_message(ctx), *at = strstr(msg, "centres ");
        size_t a = 0, b = 0;
        CHECK_MSG(strstr(msg, "pivot") && at && sscanf(at, "centres %zu and %zu", &a, &b) == 2 &&
                      a < m && b < m && a != b,
                  "%s", msg);
        double d2 = 0.0;
        for (int d = 0; d < 3 && a < m && b < m; ++d)
            d2 += (c[3 * a + d] - c[3 * b + d]) * (c[3 * a + d] - c[3 * b + d]);
        CHECK_MSG(a != b && sqrt(d2) < 1e-9, "named centres %zu and %zu are %.3g apart", a, b,
                  sqrt(d2));
    }
    /* wrong dimension, NaN, evaluate before solve */
    CHECK(cm_rbf_create(ctx, CM_RBF_THIN_PLATE, 3, m, c, &rbf) == CM_ERR_ARGUMENT);
    random_points(3, m, c);
    c[5] = NAN;
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &rbf) == CM_ERR_NUMERIC);
    c[5] = 1.0;
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, c, &rbf) == CM_OK);
    double out[3];
    CHECK(cm_rbf_evaluate(ctx, rbf, 1, c, out) == CM_ERR_ARGUMENT);
    cm_rbf_destroy(&rbf);
    cm_rbf_destroy(&rbf);
    cm_rbf_destroy(NULL);
    free(c);
}

int main(void)
{
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    const cm_rbf_kernel kernels[] = {CM_RBF_TRIHARMONIC, CM_RBF_BIHARMONIC, CM_RBF_THIN_PLATE};
    for (int i = 0; i < 3; ++i) {
        test_linear_precision(ctx, kernels[i]);
        test_interpolation(ctx, kernels[i]);
        test_threads(kernels[i]);
    }
    test_duplicates(ctx);
    test_refusals(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
