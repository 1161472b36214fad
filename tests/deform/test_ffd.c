/* FFD lattice and deformation [SP86; SMB14 §2.1]: partition of unity, identity bit for
 * bit, translation, affine/rigid on a rotated lattice, local coordinates, locality, faces and
 * outside - PyGeM #272 - and C2 continuity at a zero border. */
#include "deform_test_util.h"
#include "test_util.h"

#include <math.h>
#include <string.h>

static cm_context *ctx;

/* 1: sum_p N_p(u) = 1 at random u and at the faces, for every basis. */
static void test_partition_of_unity(void)
{
    struct {
        cm_ffd_basis b;
        cm_ffd_knots k;
        int n;
    } cases[] = {{CM_FFD_BSPLINE, CM_FFD_KNOTS_UNIFORM, 8},
                 {CM_FFD_BSPLINE, CM_FFD_KNOTS_CLAMPED, 8},
                 {CM_FFD_BSPLINE, CM_FFD_KNOTS_UNIFORM, 4},
                 {CM_FFD_BERNSTEIN, CM_FFD_KNOTS_UNIFORM, 6}};
    for (size_t c = 0; c < sizeof cases / sizeof *cases; ++c) {
        cm_ffd_desc d;
        rotated_desc(&d, cases[c].n, cases[c].b, cases[c].k);
        cm_ffd *f = NULL;
        CHECK(cm_ffd_create(ctx, &d, &f) == CM_OK);
        if (!f) continue;
        size_t cap = cm_ffd_support_size(f);
        int64_t *idx = malloc(cap * sizeof *idx);
        double *w = malloc(cap * sizeof *w);
        double worst = 0;
        int negative = 0;
        for (int i = 0; i < 100000; ++i) {
            double u[3] = {urand(), urand(), urand()};
            if (i < 27) { /* the corners, edges and faces exactly: 0, 1 and 0.5 */
                u[0] = (i % 3) * 0.5;
                u[1] = (i / 3 % 3) * 0.5;
                u[2] = (i / 9) * 0.5;
            }
            size_t q = cm_ffd_basis_eval(f, u, idx, w);
            /* compensated (Neumaier) sum: measure the basis values, not this loop's rounding */
            double s = 0, comp = 0;
            for (size_t e = 0; e < q; ++e) {
                double t = s + w[e];
                comp += fabs(s) >= fabs(w[e]) ? (s - t) + w[e] : (w[e] - t) + s;
                s = t;
                negative += w[e] < 0;
            }
            worst = fmax(worst, fabs(s + comp - 1));
        }
        printf("partition of unity, case %zu: max |sum - 1| = %.3g\n", c, worst);
        CHECK_MSG(worst <= 1e-15, "case %zu: %g", c, worst);
        CHECK(negative == 0);
        free(idx);
        free(w);
        cm_ffd_destroy(&f);
    }
}

/* 2 and 3: zero displacements give d = 0 bit for bit (also on a moved lattice through
 * Newton); equal displacements t give t. */
static void test_identity_translation(void)
{
    cm_ffd_desc d;
    rotated_desc(&d, 7, CM_FFD_BSPLINE, CM_FFD_KNOTS_UNIFORM);
    cm_ffd *f = NULL;
    CHECK(cm_ffd_create(ctx, &d, &f) == CM_OK);
    size_t nc = cm_ffd_control_count(f), n = 5000;
    double *dc = calloc(nc * 3, sizeof *dc), *x = malloc(n * 3 * sizeof *x);
    double *disp = malloc(n * 3 * sizeof *disp);
    for (size_t i = 0; i < n; ++i) {
        double s[3] = {urange(-0.2, 1.2), urange(-0.2, 1.2), urange(-0.2, 1.2)};
        desc_point(&d, s, x + 3 * i);
    }
    cm_ffd_stats st;
    CHECK(cm_ffd_deform(ctx, f, dc, n, x, disp, &st) == CM_OK);
    int nonzero = 0;
    for (size_t i = 0; i < 3 * n; ++i)
        nonzero += disp[i] != 0 || signbit(disp[i]);
    CHECK_MSG(nonzero == 0, "%d non-zero displacements from zero control displacements", nonzero);
    CHECK(st.inside > 0 && st.outside > 0 && st.inside + st.outside == n);

    /* a moved lattice (Newton) with zero displacements: still exactly 0 */
    double *ctrl = malloc(nc * 3 * sizeof *ctrl);
    cm_ffd_control_points(f, ctrl);
    for (size_t i = 0; i < 3 * nc; ++i)
        ctrl[i] += urange(-0.02, 0.02);
    CHECK(cm_ffd_set_control_points(ctx, f, ctrl) == CM_OK);
    CHECK(cm_ffd_deform(ctx, f, dc, n, x, disp, &st) >= 0);
    nonzero = 0;
    for (size_t i = 0; i < 3 * n; ++i)
        nonzero += disp[i] != 0 || signbit(disp[i]);
    CHECK(nonzero == 0);
    CHECK(cm_ffd_set_control_points(ctx, f, NULL) == CM_OK);

    const double t[3] = {0.37, -1.25, 2.5};
    for (size_t p = 0; p < nc; ++p)
        memcpy(dc + 3 * p, t, sizeof t);
    CHECK(cm_ffd_deform(ctx, f, dc, n, x, disp, &st) == CM_OK);
    double worst = 0, tn = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    size_t moved = 0;
    for (size_t i = 0; i < n; ++i) {
        if (disp[3 * i] == 0 && disp[3 * i + 1] == 0 && disp[3 * i + 2] == 0) continue;
        ++moved;
        for (int r = 0; r < 3; ++r)
            worst = fmax(worst, fabs(disp[3 * i + r] - t[r]));
    }
    printf("translation: %zu inside points, max |d - t| / |t| = %.3g\n", moved, worst / tn);
    CHECK(moved == st.inside);
    CHECK_MSG(worst <= 1e-15 * tn, "%g", worst / tn);
    free(dc);
    free(x);
    free(disp);
    free(ctrl);
    cm_ffd_destroy(&f);
}

/* 4: dc_p = (Q - I) c_p + t reproduces the rigid motion x -> Q x + t (Greville placement). */
static void test_affine(void)
{
    cm_ffd_basis bases[2] = {CM_FFD_BSPLINE, CM_FFD_BERNSTEIN};
    for (int b = 0; b < 2; ++b) {
        cm_ffd_desc d;
        rotated_desc(&d, b ? 5 : 9, bases[b], CM_FFD_KNOTS_UNIFORM);
        cm_ffd *f = NULL;
        CHECK(cm_ffd_create(ctx, &d, &f) == CM_OK);
        size_t nc = cm_ffd_control_count(f), n = 3000;
        double q[9], one[3] = {1, 1, 1}, ang[3] = {-40, 15, 70}, t[3] = {0.5, -0.1, 0.2};
        cm_ffd_box_axes(one, ang, q);
        double *ctrl = malloc(nc * 3 * sizeof *ctrl), *dc = malloc(nc * 3 * sizeof *dc);
        cm_ffd_control_points(f, ctrl);
        for (size_t p = 0; p < nc; ++p)
            for (int r = 0; r < 3; ++r)
                dc[3 * p + r] = q[3 * r] * ctrl[3 * p] + q[3 * r + 1] * ctrl[3 * p + 1] +
                                q[3 * r + 2] * ctrl[3 * p + 2] - ctrl[3 * p + r] + t[r];
        double *x = malloc(n * 3 * sizeof *x), *disp = malloc(n * 3 * sizeof *disp);
        for (size_t i = 0; i < n; ++i) {
            double s[3] = {urand(), urand(), urand()};
            desc_point(&d, s, x + 3 * i);
        }
        CHECK(cm_ffd_deform(ctx, f, dc, n, x, disp, NULL) == CM_OK);
        double worst = 0, rigid = 0;
        for (size_t i = 0; i < n; ++i)
            for (int r = 0; r < 3; ++r) {
                const double *p = x + 3 * i;
                double e = q[3 * r] * p[0] + q[3 * r + 1] * p[1] + q[3 * r + 2] * p[2] - p[r] + t[r];
                worst = fmax(worst, fabs(disp[3 * i + r] - e));
            }
        /* rigid: distances between moved points are kept */
        for (size_t i = 0; i + 1 < n; i += 2) {
            double a = 0, c = 0;
            for (int r = 0; r < 3; ++r) {
                double d0 = x[3 * i + r] - x[3 * i + 3 + r];
                double d1 = d0 + disp[3 * i + r] - disp[3 * i + 3 + r];
                a += d0 * d0;
                c += d1 * d1;
            }
            rigid = fmax(rigid, fabs(sqrt(a) - sqrt(c)));
        }
        printf("affine (%s): max |d - ((Q - I) x + t)| = %.3g, distance change %.3g\n",
               b ? "bernstein" : "bspline", worst, rigid);
        CHECK_MSG(worst <= 1e-14 * 2.0, "%g", worst);
        CHECK(rigid <= 1e-13);
        free(ctrl);
        free(dc);
        free(x);
        free(disp);
        cm_ffd_destroy(&f);
    }
}

/* 5: Newton local coordinates: one step at most on the reference lattice; <= 8 steps and
 * round-off agreement on a lattice moved by 15 % of its spacing; a folded lattice is a
 * counted failure, not a silent "unmoved". */
static void test_local_coordinates(void)
{
    cm_ffd_desc d;
    rotated_desc(&d, 8, CM_FFD_BSPLINE, CM_FFD_KNOTS_UNIFORM);
    cm_ffd *f = NULL;
    CHECK(cm_ffd_create(ctx, &d, &f) == CM_OK);
    size_t n = 2000, nc = cm_ffd_control_count(f);
    double *x = malloc(n * 3 * sizeof *x), *ua = malloc(n * 3 * sizeof *ua);
    double *un = malloc(n * 3 * sizeof *un), *ut = malloc(n * 3 * sizeof *ut);
    unsigned char *in = malloc(n);
    for (size_t i = 0; i < n; ++i) {
        double s[3] = {urand(), urand(), urand()};
        desc_point(&d, s, x + 3 * i);
    }
    cm_ffd_stats st;
    CHECK(cm_ffd_local_coords(ctx, f, n, x, ua, in, &st) == CM_OK);
    CHECK(st.max_iterations == 0);
    cm_ffd_set_local(f, CM_FFD_LOCAL_NEWTON);
    CHECK(cm_ffd_local_coords(ctx, f, n, x, un, in, &st) == CM_OK);
    double worst = 0;
    for (size_t i = 0; i < 3 * n; ++i)
        worst = fmax(worst, fabs(un[i] - ua[i]));
    printf("newton on the reference lattice: %d iterations, |u - u_affine| = %.3g\n",
           st.max_iterations, worst);
    CHECK(st.max_iterations <= 1);
    CHECK(worst <= 1e-14);
    CHECK(st.inside == n);

    /* moved by up to 15 % of the spacing per coordinate (spacing: 1/5 of each axis) */
    double *ctrl = malloc(nc * 3 * sizeof *ctrl);
    cm_ffd_control_points(f, ctrl);
    const double len[3] = {2.0, 1.5, 1.0};
    double hmin = len[2] / 5;
    for (size_t i = 0; i < 3 * nc; ++i)
        ctrl[i] += urange(-0.15, 0.15) * hmin;
    cm_ffd_set_local(f, CM_FFD_LOCAL_AUTO);
    CHECK(cm_ffd_set_control_points(ctx, f, ctrl) == CM_OK);
    for (size_t i = 0; i < n; ++i) {
        double u[3] = {urand(), urand(), urand()};
        memcpy(ut + 3 * i, u, sizeof u);
        lattice_point(f, ctrl, u, x + 3 * i);
    }
    CHECK(cm_ffd_local_coords(ctx, f, n, x, un, in, &st) == CM_OK);
    double du = 0, dx = 0;
    for (size_t i = 0; i < n; ++i) {
        double xu[3];
        lattice_point(f, ctrl, un + 3 * i, xu);
        for (int r = 0; r < 3; ++r) {
            du = fmax(du, fabs(un[3 * i + r] - ut[3 * i + r]));
            dx = fmax(dx, fabs(xu[r] - x[3 * i + r]));
        }
    }
    double diag = sqrt(len[0] * len[0] + len[1] * len[1] + len[2] * len[2]);
    printf("newton on a moved lattice: %d iterations (max), |x(u) - x| = %.3g, |u - u_true| = "
           "%.3g, inside %zu of %zu\n",
           st.max_iterations, dx, du, st.inside, n);
    CHECK(st.max_iterations <= 8);
    CHECK(st.inside == n && st.failed == 0);
    CHECK(dx <= 1e-13 * diag);
    CHECK(du <= 1e-12);

    /* far outside the moved lattice: outside, not failed */
    double far[3] = {50, 50, 50}, uf[3];
    CHECK(cm_ffd_local_coords(ctx, f, 1, far, uf, in, &st) == CM_OK);
    CHECK(st.outside == 1 && in[0] == 0);

    /* folded: every control point on the plane z = 0.5 - the Jacobian is singular */
    for (size_t p = 0; p < nc; ++p)
        ctrl[3 * p + 2] = 0.5;
    CHECK(cm_ffd_set_control_points(ctx, f, ctrl) == CM_OK);
    double probe[3] = {1.0, 0.5, 0.5};
    cm_status s = cm_ffd_local_coords(ctx, f, 1, probe, uf, in, &st);
    printf("folded lattice: status %d, failed %zu, outside %zu: %s\n", (int)s, st.failed,
           st.outside, cm_context_message(ctx));
    CHECK(st.inside == 0);
    CHECK(st.failed == 1 && s == CM_WARNING);
    double dcz[3 * 512];
    for (int i = 0; i < 3 * 512; ++i)
        dcz[i] = 1;
    double dp[3] = {9, 9, 9};
    s = cm_ffd_deform(ctx, f, dcz, 1, probe, dp, &st);
    CHECK(dp[0] == 0 && dp[1] == 0 && dp[2] == 0);
    CHECK(st.failed == 0 || s == CM_WARNING);
    free(x);
    free(ua);
    free(un);
    free(ut);
    free(in);
    free(ctrl);
    cm_ffd_destroy(&f);
}

/* 6: one control point moves only the points in its 4x4x4-span support. */
static void test_locality(void)
{
    cm_ffd_desc d;
    cm_ffd_desc_init(&d);
    int n = 9;
    d.n[0] = d.n[1] = d.n[2] = n;
    cm_ffd *f = NULL;
    CHECK(cm_ffd_create(ctx, &d, &f) == CM_OK);
    size_t nc = cm_ffd_control_count(f), np = 20000;
    double *dc = calloc(nc * 3, sizeof *dc);
    int ip = 4, jp = 2, kp = 6;
    size_t p = ((size_t)ip * n + jp) * n + kp;
    dc[3 * p] = 0.1;
    dc[3 * p + 1] = -0.2;
    dc[3 * p + 2] = 0.05;
    double *x = malloc(np * 3 * sizeof *x), *disp = malloc(np * 3 * sizeof *disp);
    for (size_t i = 0; i < 3 * np; ++i)
        x[i] = urand();
    CHECK(cm_ffd_deform(ctx, f, dc, np, x, disp, NULL) == CM_OK);
    /* uniform knots t_j = (j - 3)/(n - 3): N_i lives on (t_i, t_{i+4}) */
    int ijk[3] = {ip, jp, kp}, wrong = 0, moved_in = 0, in = 0;
    for (size_t i = 0; i < np; ++i) {
        int inside = 1;
        for (int a = 0; a < 3; ++a) {
            double lo = (ijk[a] - 3.0) / (n - 3), hi = (ijk[a] + 1.0) / (n - 3);
            if (!(x[3 * i + a] > lo && x[3 * i + a] < hi)) inside = 0;
        }
        int zero = disp[3 * i] == 0 && disp[3 * i + 1] == 0 && disp[3 * i + 2] == 0;
        if (!inside && !zero) ++wrong;
        in += inside;
        moved_in += inside && !zero;
    }
    printf("locality: %d points in the support (%d moved), %d outside it moved\n", in, moved_in,
           wrong);
    CHECK(wrong == 0);
    CHECK(in > 100 && moved_in == in);
    free(dc);
    free(x);
    free(disp);
    cm_ffd_destroy(&f);
}

/* 7: box = the points' bounding box, every dc = t: every point moves by t, also those on the
 * faces (PyGeM #272 loses 1-3 in 1000); points outside get exactly 0. */
static void test_faces_and_outside(void)
{
    for (int rot = 0; rot < 2; ++rot) {
        cm_ffd_basis basis = rot ? CM_FFD_BSPLINE : CM_FFD_BERNSTEIN;
        size_t n = 1000;
        double *x = malloc(n * 3 * sizeof *x), *disp = malloc(n * 3 * sizeof *disp);
        cm_ffd_desc d;
        if (rot) {
            rotated_desc(&d, 6, basis, CM_FFD_KNOTS_UNIFORM);
            for (size_t i = 0; i < n; ++i) {
                double s[3] = {urand(), urand(), urand()};
                s[i % 3] = (i / 3) % 2 ? 1.0 : 0.0; /* every point on a face */
                desc_point(&d, s, x + 3 * i);
            }
        } else {
            double bb[6] = {1e300, 1e300, 1e300, -1e300, -1e300, -1e300};
            for (size_t i = 0; i < 3 * n; ++i)
                x[i] = urange(-3.1, 7.3) * (1 + (double)(i % 3));
            for (size_t i = 0; i < n; ++i)
                for (int a = 0; a < 3; ++a) {
                    bb[a] = fmin(bb[a], x[3 * i + a]);
                    bb[a + 3] = fmax(bb[a + 3], x[3 * i + a]);
                }
            cm_ffd_desc_init(&d);
            d.basis = basis;
            d.n[0] = 3, d.n[1] = 4, d.n[2] = 2;
            for (int a = 0; a < 3; ++a) {
                d.origin[a] = bb[a];
                d.axes[4 * a] = bb[a + 3] - bb[a];
            }
        }
        cm_ffd *f = NULL;
        CHECK(cm_ffd_create(ctx, &d, &f) == CM_OK);
        size_t nc = cm_ffd_control_count(f);
        double *dc = malloc(nc * 3 * sizeof *dc), t[3] = {0.25, 0.5, -1};
        for (size_t p = 0; p < nc; ++p)
            memcpy(dc + 3 * p, t, sizeof t);
        cm_ffd_stats st;
        CHECK(cm_ffd_deform(ctx, f, dc, n, x, disp, &st) == CM_OK);
        double worst = 0;
        for (size_t i = 0; i < n; ++i)
            for (int r = 0; r < 3; ++r)
                worst = fmax(worst, fabs(disp[3 * i + r] - t[r]));
        printf("faces (%s): %zu of %zu points inside, max |d - t| = %.3g\n",
               rot ? "rotated, on the faces" : "bounding box", st.inside, n, worst);
        CHECK_MSG(st.inside == n, "%zu of %zu moved", st.inside, n);
        CHECK(worst <= 1e-14);
        /* outside: beyond the faces by more than the tolerance */
        for (size_t i = 0; i < n; ++i) {
            double s[3] = {urange(-1, 2), urange(-1, 2), urange(-1, 2)};
            s[i % 3] = (i / 3) % 2 ? urange(1 + 1e-9, 3) : urange(-2, -1e-9);
            if (rot)
                desc_point(&d, s, x + 3 * i);
            else
                for (int a = 0; a < 3; ++a)
                    x[3 * i + a] = d.origin[a] + d.axes[4 * a] * s[a];
        }
        CHECK(cm_ffd_deform(ctx, f, dc, n, x, disp, &st) == CM_OK);
        int nonzero = 0;
        for (size_t i = 0; i < 3 * n; ++i)
            nonzero += disp[i] != 0;
        CHECK(nonzero == 0 && st.outside == n);
        free(x);
        free(disp);
        free(dc);
        cm_ffd_destroy(&f);
    }
}

/* 8: with the outer 3 control layers at zero, |d| = O(eps^3) at distance eps inside the
 * domain (uniform knots): the deformation meets the undeformed outside C2-continuously. */
static void test_continuity(void)
{
    cm_ffd_desc d;
    cm_ffd_desc_init(&d);
    int n = 10;
    d.n[0] = d.n[1] = d.n[2] = n;
    cm_ffd *f = NULL;
    CHECK(cm_ffd_create(ctx, &d, &f) == CM_OK);
    size_t nc = cm_ffd_control_count(f);
    double *dc = calloc(nc * 3, sizeof *dc);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k) {
                int border = i < 3 || j < 3 || k < 3 || i >= n - 3 || j >= n - 3 || k >= n - 3;
                if (border) continue;
                for (int r = 0; r < 3; ++r)
                    dc[3 * (((size_t)i * n + j) * n + k) + r] = urange(-0.1, 0.1);
            }
    double eps[4] = {1e-1 / 7, 1e-2 / 7, 1e-3 / 7, 1e-4 / 7}, mag[4];
    for (int face = 0; face < 2; ++face) {
        for (int e = 0; e < 4; ++e) {
            double x[3] = {0.43, 0.56, face ? 1 - eps[e] : eps[e]}, dd[3];
            CHECK(cm_ffd_deform(ctx, f, dc, 1, x, dd, NULL) == CM_OK);
            mag[e] = sqrt(dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
        }
        double slope_lo = log(mag[0] / mag[1]) / log(eps[0] / eps[1]);
        double slope_hi = log(mag[2] / mag[3]) / log(eps[2] / eps[3]);
        printf("continuity (face z = %d): |d| = %.3g .. %.3g, log-log slopes %.4f %.4f\n", face,
               mag[0], mag[3], slope_lo, slope_hi);
        CHECK(mag[0] > 0);
        CHECK(fabs(slope_lo - 3) < 0.01 && fabs(slope_hi - 3) < 0.01);
    }
    double on[3] = {0.5, 0.5, 0}, dd[3];
    CHECK(cm_ffd_deform(ctx, f, dc, 1, on, dd, NULL) == CM_OK);
    CHECK(dd[0] == 0 && dd[1] == 0 && dd[2] == 0);
    free(dc);
    cm_ffd_destroy(&f);
}

/* Custom (refined, non-uniform) knots: partition of unity and linear precision still hold,
 * so the reference map stays affine and local coordinates exact. */
static void test_custom_knots(void)
{
    /* n = 7: interior knots 0, 0.1, 0.15, 0.5, 1 plus end extensions */
    static const double kx[11] = {-0.3, -0.2, -0.1, 0, 0.1, 0.15, 0.5, 1, 1.5, 2, 2.5};
    static const double ky[8] = {-3, -2, -1, 0, 1, 2, 3, 4}; /* n = 4: one span */
    static const double kz[9] = {-0.6, -0.4, -0.2, 0, 0.2, 1, 1.8, 2.6, 3.4};
    cm_ffd_desc d;
    rotated_desc(&d, 4, CM_FFD_BSPLINE, CM_FFD_KNOTS_CUSTOM);
    d.n[0] = 7;
    d.n[2] = 5;
    d.knot[0] = kx;
    d.knot[1] = ky;
    d.knot[2] = kz;
    cm_ffd *f = NULL;
    CHECK(cm_ffd_create(ctx, &d, &f) == CM_OK);
    if (!f) return;
    int64_t idx[64];
    double w[64], worst = 0, lin = 0;
    size_t nc = cm_ffd_control_count(f);
    double *ctrl = malloc(nc * 3 * sizeof *ctrl);
    cm_ffd_control_points(f, ctrl);
    for (int i = 0; i < 20000; ++i) {
        double u[3] = {urand(), urand(), urand()}, x[3], xr[3];
        if (i < 3) u[i] = 1.0;
        size_t q = cm_ffd_basis_eval(f, u, idx, w);
        double s = 0;
        for (size_t e = 0; e < q; ++e)
            s += w[e];
        worst = fmax(worst, fabs(s - 1));
        lattice_point(f, ctrl, u, x);
        desc_point(&d, u, xr);
        for (int r = 0; r < 3; ++r)
            lin = fmax(lin, fabs(x[r] - xr[r]));
    }
    printf("custom knots: max |sum - 1| = %.3g, |x(u) - (o + A u)| = %.3g\n", worst, lin);
    CHECK(worst <= 4e-15);
    CHECK(lin <= 1e-14);
    free(ctrl);
    cm_ffd_destroy(&f);
    /* a repeated knot inside the domain is refused */
    static const double bad[10] = {-3, -2, -1, 0, 0.5, 0.5, 1, 2, 3, 4};
    d.n[0] = d.n[1] = d.n[2] = 6;
    d.knot[0] = d.knot[1] = d.knot[2] = bad;
    CHECK(cm_ffd_create(ctx, &d, &f) == CM_ERR_ARGUMENT);
}

static void test_errors(void)
{
    cm_ffd_desc d;
    cm_ffd_desc_init(&d);
    cm_ffd *f = (cm_ffd *)&d;
    d.n[1] = 3;
    CHECK(cm_ffd_create(ctx, &d, &f) == CM_ERR_ARGUMENT && f == NULL);
    CHECK(strstr(cm_context_message(ctx), "axis 1") != NULL);
    cm_ffd_desc_init(&d);
    d.axes[8] = 0; /* flat */
    CHECK(cm_ffd_create(ctx, &d, &f) == CM_ERR_ARGUMENT && f == NULL);
    cm_ffd_destroy(&f);
}

int main(void)
{
    cm_context_create(&ctx);
    test_partition_of_unity();
    test_identity_translation();
    test_affine();
    test_local_coordinates();
    test_locality();
    test_faces_and_outside();
    test_continuity();
    test_custom_knots();
    test_errors();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
