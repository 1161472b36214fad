/* Shape-Up projections (shapeup.h) against closed forms: points already on the primitive
 * stay put; symmetric noise whose least-squares primitive is known by symmetry goes onto
 * that primitive; rigid and similar matches keep distances and distance ratios. Every
 * configuration is placed in a random frame (rotation + translation) first. */
#include "cadmorph/shapeup.h"
#include "test_rng.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static double rnd(uint64_t *s)
{
    return test_rng_uniform(s);
}

/* a random rotation (normalised random quaternion) and translation */
static void random_frame(uint64_t *s, double r[9], double t[3])
{
    double q[4], l = 0;
    for (int i = 0; i < 4; ++i)
        q[i] = rnd(s) - 0.5, l += q[i] * q[i];
    l = sqrt(l);
    for (int i = 0; i < 4; ++i)
        q[i] /= l;
    double a = q[0], b = q[1], c = q[2], d = q[3];
    double m[9] = {a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c),
                   2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b),
                   2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d};
    memcpy(r, m, sizeof m);
    for (int i = 0; i < 3; ++i)
        t[i] = 4 * (rnd(s) - 0.5);
}

static void to_frame(const double r[9], const double t[3], size_t n, double *x)
{
    for (size_t i = 0; i < n; ++i) {
        double *p = x + 3 * i, y[3];
        for (int j = 0; j < 3; ++j)
            y[j] = r[3 * j] * p[0] + r[3 * j + 1] * p[1] + r[3 * j + 2] * p[2] + t[j];
        memcpy(p, y, sizeof y);
    }
}

static double max_diff(size_t n, const double *a, const double *b)
{
    double m = 0;
    for (size_t i = 0; i < 3 * n; ++i)
        if (fabs(a[i] - b[i]) > m) m = fabs(a[i] - b[i]);
    return m;
}

static void test_plane(cm_context *ctx, uint64_t *seed)
{
    /* 6 x 6 grid, heights eps * (-1)^(i+j): mean and correlations with (s, t) vanish, so the
     * least-squares plane is z = 0 and the projection removes the heights */
    enum { N = 36 };
    double x[3 * N], want[3 * N], p[3 * N], on[3 * N], r[9], t[3], fit[6];
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j) {
            int k = 6 * i + j;
            want[3 * k] = i - 2.5, want[3 * k + 1] = 0.7 * (j - 2.5), want[3 * k + 2] = 0;
            memcpy(x + 3 * k, want + 3 * k, 3 * sizeof *x);
            x[3 * k + 2] = 0.05 * (((i + j) & 1) ? -1 : 1);
        }
    random_frame(seed, r, t);
    to_frame(r, t, N, x);
    to_frame(r, t, N, want);
    CHECK(cm_shape_project_plane(ctx, N, want, on, fit) == CM_OK);
    CHECK_MSG(max_diff(N, on, want) < 1e-12, "plane: exact points moved %g", max_diff(N, on, want));
    CHECK(cm_shape_project_plane(ctx, N, x, p, fit) == CM_OK);
    CHECK_MSG(max_diff(N, p, want) < 1e-12, "plane: noisy points off by %g", max_diff(N, p, want));
    /* the normal is the frame's third axis (up to sign) */
    CHECK_NEAR(fabs(fit[3] * r[2] + fit[4] * r[5] + fit[5] * r[8]), 1, 1e-12);
    /* projecting in place (p aliases x) */
    CHECK(cm_shape_project_plane(ctx, N, x, x, NULL) == CM_OK);
    CHECK(max_diff(N, x, want) < 1e-12);
    CHECK(cm_shape_project_plane(ctx, 2, x, p, NULL) == CM_ERR_ARGUMENT);
}

static void test_circle(cm_context *ctx, uint64_t *seed)
{
    enum { N = 16 };
    double x[3 * N], want[3 * N], p[3 * N], r[9], t[3], fit[7], R = 1.7;
    /* an arc of 7 exact points stays put */
    for (int i = 0; i < 7; ++i) {
        double a = 0.3 + 0.25 * i;
        want[3 * i] = R * cos(a), want[3 * i + 1] = R * sin(a), want[3 * i + 2] = 0;
    }
    random_frame(seed, r, t);
    to_frame(r, t, 7, want);
    CHECK(cm_shape_project_circle(ctx, 7, want, p, fit) == CM_OK);
    CHECK_MSG(max_diff(7, p, want) < 1e-12, "circle: arc moved %g", max_diff(7, p, want));
    CHECK_NEAR(fit[6], R, 1e-12);
    CHECK_NEAR(fabs(fit[0] - t[0]) + fabs(fit[1] - t[1]) + fabs(fit[2] - t[2]), 0, 1e-12);
    /* 16 equally spaced angles, radius R +- eps alternately, heights +-h with the pattern
     * + + - - (no mean, no correlation with cos and sin): the geometric least-squares circle
     * is the symmetric one, radius R = the mean radius; the projection keeps the angles */
    for (int i = 0; i < N; ++i) {
        double a = 2 * PI * i / N, ri = R + 0.08 * ((i & 1) ? -1 : 1);
        double h = 0.03 * ((i & 2) ? -1 : 1);
        x[3 * i] = ri * cos(a), x[3 * i + 1] = ri * sin(a), x[3 * i + 2] = h;
        want[3 * i] = R * cos(a), want[3 * i + 1] = R * sin(a), want[3 * i + 2] = 0;
    }
    random_frame(seed, r, t);
    to_frame(r, t, N, x);
    to_frame(r, t, N, want);
    CHECK(cm_shape_project_circle(ctx, N, x, p, fit) == CM_OK);
    CHECK_MSG(max_diff(N, p, want) < 1e-12, "circle: noisy points off by %g", max_diff(N, p, want));
    CHECK_NEAR(fit[6], R, 1e-12);
    /* collinear points define no circle */
    double line[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
    CHECK(cm_shape_project_circle(ctx, 3, line, p, NULL) == CM_ERR_NUMERIC);
}

static void test_cylinder(cm_context *ctx, uint64_t *seed)
{
    enum { NA = 12, NH = 5, N = NA * NH };
    double x[3 * N], want[3 * N], p[3 * N], r[9], t[3], fit[7], R = 0.8;
    /* a half cylinder (angles over pi) of exact points stays put */
    for (int i = 0; i < NA; ++i)
        for (int j = 0; j < NH; ++j) {
            int k = NH * i + j;
            double a = PI * i / (NA - 1);
            want[3 * k] = R * cos(a), want[3 * k + 1] = R * sin(a), want[3 * k + 2] = 0.6 * j;
        }
    random_frame(seed, r, t);
    to_frame(r, t, N, want);
    CHECK(cm_shape_project_cylinder(ctx, N, want, NULL, p, fit) == CM_OK);
    CHECK_MSG(max_diff(N, p, want) < 1e-12, "cylinder: exact points moved %g", max_diff(N, p, want));
    CHECK_NEAR(fit[6], R, 1e-12);
    CHECK_NEAR(fabs(fit[3] * r[2] + fit[4] * r[5] + fit[5] * r[8]), 1, 1e-12);
    /* full circle of 12 angles, radii R +- eps alternately, symmetric heights: by symmetry
     * the least-squares cylinder has the true axis and radius R */
    for (int i = 0; i < NA; ++i)
        for (int j = 0; j < NH; ++j) {
            int k = NH * i + j;
            double a = 2 * PI * i / NA, ri = R + 0.05 * ((i & 1) ? -1 : 1);
            x[3 * k] = ri * cos(a), x[3 * k + 1] = ri * sin(a), x[3 * k + 2] = 0.5 * (j - 2);
            want[3 * k] = R * cos(a), want[3 * k + 1] = R * sin(a), want[3 * k + 2] = 0.5 * (j - 2);
        }
    random_frame(seed, r, t);
    to_frame(r, t, N, x);
    to_frame(r, t, N, want);
    CHECK(cm_shape_project_cylinder(ctx, N, x, NULL, p, fit) == CM_OK);
    CHECK_MSG(max_diff(N, p, want) < 1e-12, "cylinder: noisy points off by %g", max_diff(N, p, want));
    CHECK_NEAR(fit[6], R, 1e-12);
    /* from a rough guess (the warm start of Shape-Up) the same cylinder */
    double guess[7];
    memcpy(guess, fit, sizeof guess);
    guess[0] += 0.05, guess[3] += 0.05, guess[6] *= 1.1;
    double p2[3 * N];
    CHECK(cm_shape_project_cylinder(ctx, N, x, guess, p2, NULL) == CM_OK);
    CHECK_MSG(max_diff(N, p2, want) < 1e-12, "cylinder from a guess: off by %g", max_diff(N, p2, want));
}

/* Points of a cone with apex 0, axis z, half-angle A in the local frame: angle a, distance
 * t from the apex along the generator, offset e along the outward normal. */
static void cone_point(double A, double a, double t, double e, double *x)
{
    double r = t * sin(A) + e * cos(A), h = t * cos(A) - e * sin(A);
    x[0] = r * cos(a), x[1] = r * sin(a), x[2] = h;
}

static void test_cone(cm_context *ctx, uint64_t *seed)
{
    enum { NA = 12, NT = 5, N = NA * NT };
    const double A = 0.45;
    double x[3 * N], want[3 * N], p[3 * N], r[9], t[3], fit[7];
    /* exact points on part of a cone (angles over 1.5 pi, uneven) stay put; the fit is the
     * cone: apex t, axis r e_z, half-angle A */
    for (int i = 0; i < NA; ++i)
        for (int j = 0; j < NT; ++j)
            cone_point(A, 1.5 * PI * i / (NA - 1) + 0.01 * i * i, 0.8 + 0.4 * j + 0.03 * i, 0,
                       want + 3 * (NT * i + j));
    random_frame(seed, r, t);
    to_frame(r, t, N, want);
    CHECK(cm_shape_project_cone(ctx, N, want, NULL, p, fit) == CM_OK);
    CHECK_MSG(max_diff(N, p, want) < 1e-12, "cone: exact points moved %g", max_diff(N, p, want));
    CHECK_NEAR(fit[6], A, 1e-12);
    for (int k = 0; k < 3; ++k)
        CHECK_NEAR(fit[k], t[k], 1e-11);
    /* the axis into the nappe: r e_z (to_frame applies x -> r x + t) */
    CHECK_NEAR(fit[3] * r[2] + fit[4] * r[5] + fit[5] * r[8], 1, 1e-12);
    /* 12 full-circle angles, offsets +-eps along the normal alternately: by symmetry the
     * least-squares cone is the true one and each point goes to its foot on the generator */
    for (int i = 0; i < NA; ++i)
        for (int j = 0; j < NT; ++j) {
            int k = NT * i + j;
            double a = 2 * PI * i / NA, tt = 0.8 + 0.4 * j, e = 0.04 * ((i & 1) ? -1 : 1);
            cone_point(A, a, tt, e, x + 3 * k);
            cone_point(A, a, tt, 0, want + 3 * k);
        }
    random_frame(seed, r, t);
    to_frame(r, t, N, x);
    to_frame(r, t, N, want);
    CHECK(cm_shape_project_cone(ctx, N, x, NULL, p, fit) == CM_OK);
    CHECK_MSG(max_diff(N, p, want) < 1e-12, "cone: noisy points off by %g", max_diff(N, p, want));
    CHECK_NEAR(fit[6], A, 1e-12);
    /* from a rough guess (the warm start of Shape-Up) the same cone */
    double guess[7], p2[3 * N];
    memcpy(guess, fit, sizeof guess);
    guess[0] += 0.05, guess[4] += 0.05, guess[6] *= 1.1;
    CHECK(cm_shape_project_cone(ctx, N, x, guess, p2, NULL) == CM_OK);
    CHECK_MSG(max_diff(N, p2, want) < 1e-12, "cone from a guess: off by %g", max_diff(N, p2, want));
    /* a point behind the fitted apex goes to the apex */
    double y[3 * (N + 1)], q[3 * (N + 1)];
    memcpy(y, want, sizeof want);
    cone_point(A, 0.3, -0.1, 0, y + 3 * N); /* on the other nappe, near the apex */
    to_frame(r, t, 1, y + 3 * N);
    CHECK(cm_shape_project_cone(ctx, N + 1, y, NULL, q, fit) == CM_OK);
    double yy[3] = {y[3 * N] - fit[0], y[3 * N + 1] - fit[1], y[3 * N + 2] - fit[2]};
    double hh = yy[0] * fit[3] + yy[1] * fit[4] + yy[2] * fit[5];
    double rr = sqrt(fmax(yy[0] * yy[0] + yy[1] * yy[1] + yy[2] * yy[2] - hh * hh, 0));
    CHECK_MSG(hh * cos(fit[6]) + rr * sin(fit[6]) < 0, "the extra point is not behind the apex");
    double da = 0;
    for (int k = 0; k < 3; ++k)
        da = fmax(da, fabs(q[3 * N + k] - fit[k]));
    CHECK_MSG(da < 1e-12, "behind the apex: %g from it", da);
    /* too few points */
    CHECK(cm_shape_project_cone(ctx, 5, want, NULL, p, NULL) < 0);
}

static void test_similar(cm_context *ctx, uint64_t *seed)
{
    enum { N = 20 };
    double ref[3 * N], x[3 * N], p[3 * N], r[9], t[3];
    for (int i = 0; i < 3 * N; ++i)
        ref[i] = rnd(seed);
    for (int scale = 0; scale <= 1; ++scale) {
        /* an exact rigid / similar copy is matched exactly */
        double s = scale ? 1.7 : 1;
        for (int i = 0; i < 3 * N; ++i)
            x[i] = s * ref[i];
        random_frame(seed, r, t);
        to_frame(r, t, N, x);
        CHECK(cm_shape_project_similar(ctx, N, ref, x, scale, p) == CM_OK);
        CHECK_MSG(max_diff(N, p, x) < 1e-12, "similar %d: exact copy off by %g", scale,
                  max_diff(N, p, x));
        /* noisy copy: the match keeps every distance ratio (rigid: every distance) */
        for (int i = 0; i < 3 * N; ++i)
            x[i] += 0.05 * (rnd(seed) - 0.5);
        CHECK(cm_shape_project_similar(ctx, N, ref, x, scale, p) == CM_OK);
        double worst = 0, s0 = -1;
        for (int i = 0; i < N; ++i)
            for (int j = i + 1; j < N; ++j) {
                double dp = 0, dr = 0;
                for (int a = 0; a < 3; ++a) {
                    dp += (p[3 * i + a] - p[3 * j + a]) * (p[3 * i + a] - p[3 * j + a]);
                    dr += (ref[3 * i + a] - ref[3 * j + a]) * (ref[3 * i + a] - ref[3 * j + a]);
                }
                double ratio = sqrt(dp / dr);
                if (s0 < 0) s0 = ratio;
                if (fabs(ratio - (scale ? s0 : 1)) > worst) worst = fabs(ratio - (scale ? s0 : 1));
            }
        CHECK_MSG(worst < 1e-12, "similar %d: distance ratio varies by %g", scale, worst);
        if (scale) CHECK_NEAR(s0, 1.7, 0.05);
        /* no reflection: a mirrored copy gets a proper rotation (det +1), so it is not met */
        double m[3 * N];
        for (int i = 0; i < N; ++i)
            m[3 * i] = -ref[3 * i], m[3 * i + 1] = ref[3 * i + 1], m[3 * i + 2] = ref[3 * i + 2];
        CHECK(cm_shape_project_similar(ctx, N, ref, m, scale, p) == CM_OK);
        CHECK(max_diff(N, p, m) > 1e-3);
    }
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    uint64_t seed = 12345;
    for (int rep = 0; rep < 5; ++rep) {
        test_plane(ctx, &seed);
        test_circle(ctx, &seed);
        test_cylinder(ctx, &seed);
        test_cone(ctx, &seed);
        test_similar(ctx, &seed);
    }
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
