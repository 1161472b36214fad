/* DM-FFD [HHK92; SMB14 §2.2]: exact at full row rank, least norm / least squares against
 * LAPACK's dgelsd, the precomputed B = M Phi^+, clamping (Fig. 8 setting), and the documented
 * non-reproduction of translations (the RBF with its linear polynomial does reproduce them). */
#include "deform_test_util.h"
#include "test_util.h"

#include "cadmorph/rbf.h"

#include <lapacke.h>
#include <math.h>
#include <string.h>

static cm_context *ctx;

static cm_ffd *unit_lattice(int n)
{
    cm_ffd_desc d;
    cm_ffd_desc_init(&d);
    d.n[0] = d.n[1] = d.n[2] = n;
    cm_ffd *f = NULL;
    CHECK(cm_ffd_create(ctx, &d, &f) == CM_OK);
    return f;
}

/* Dense Phi (m x #ctrl) from the public basis, independent of dmffd.c. */
static double *dense_phi(const cm_ffd *f, size_t m, const double *h)
{
    size_t nc = cm_ffd_control_count(f), cap = cm_ffd_support_size(f);
    double *phi = calloc(m * nc, sizeof *phi), u[3];
    int64_t *idx = malloc(cap * sizeof *idx);
    double *w = malloc(cap * sizeof *w);
    unsigned char in;
    for (size_t i = 0; i < m; ++i) {
        cm_ffd_local_coords(ctx, f, 1, h + 3 * i, u, &in, NULL);
        size_t q = cm_ffd_basis_eval(f, u, idx, w);
        for (size_t e = 0; e < q; ++e)
            phi[i * nc + idx[e]] += w[e];
    }
    free(idx);
    free(w);
    return phi;
}

/* Minimum-norm least-squares solution by dgelsd (x: nc x 3). */
static void lapack_lstsq(const double *phi, size_t m, size_t nc, const double *h, double *x)
{
    size_t ld = m > nc ? m : nc;
    double *a = malloc(m * nc * sizeof *a), *b = calloc(ld * 3, sizeof *b);
    double *s = malloc((m < nc ? m : nc) * sizeof *s);
    memcpy(a, phi, m * nc * sizeof *a);
    memcpy(b, h, m * 3 * sizeof *b);
    lapack_int rank;
    lapack_int info = LAPACKE_dgelsd(LAPACK_ROW_MAJOR, (lapack_int)m, (lapack_int)nc, 3, a,
                                     (lapack_int)nc, b, 3, s, -1.0, &rank);
    CHECK(info == 0);
    memcpy(x, b, nc * 3 * sizeof *x);
    free(a);
    free(b);
    free(s);
}

/* 9: m = 20 < n = 64, full row rank: Phi C = H to round-off, and the FFD moves the handles
 * onto their targets. */
static void test_exact(void)
{
    cm_ffd *f = unit_lattice(4);
    size_t m = 20, nc = cm_ffd_control_count(f);
    double h[60], hd[60], dc[3 * 64], moved[60];
    for (int i = 0; i < 60; ++i) {
        h[i] = urange(0.05, 0.95);
        hd[i] = urange(-0.1, 0.1);
    }
    cm_dmffd *dm = NULL;
    CHECK(cm_dmffd_create(ctx, f, m, h, NULL, &dm) == CM_OK);
    CHECK(cm_dmffd_solve(ctx, dm, hd, dc) == CM_OK);
    cm_dmffd_info info;
    cm_dmffd_get_info(dm, &info);
    CHECK(cm_ffd_deform(ctx, f, dc, m, h, moved, NULL) == CM_OK);
    double worst = 0, hmax = 0;
    for (int i = 0; i < 60; ++i) {
        worst = fmax(worst, fabs(moved[i] - hd[i]));
        hmax = fmax(hmax, fabs(hd[i]));
    }
    printf("exact: m %zu, active %zu, rank %zu, sigma %.3g .. %.3g, residual %.3g, handles "
           "miss by %.3g\n",
           m, info.active, info.rank, info.sigma_max, info.sigma_min, info.residual, worst);
    CHECK(info.active == nc && info.rank == m && info.clamped == 0);
    CHECK(info.residual <= 1e-12);
    CHECK(worst <= 1e-12 * hmax);
    cm_dmffd_destroy(&dm);
    CHECK(dm == NULL);
    cm_ffd_destroy(&f);
}

/* 10: least norm (under-determined) and least squares (over-determined) agree with dgelsd;
 * control points outside every handle's support get exactly 0. */
static void test_least_norm_squares(void)
{
    for (int over = 0; over < 2; ++over) {
        /* under: 60 handles in the corner [0, 0.45]^3 of a 7^3 lattice (untouched control
         * points exist); over: 900 handles everywhere on a 5^3 lattice (well conditioned) */
        cm_ffd *f = unit_lattice(over ? 5 : 7);
        size_t nc = cm_ffd_control_count(f);
        size_t m = over ? 900 : 60;
        double *h = malloc(m * 3 * sizeof *h), *hd = malloc(m * 3 * sizeof *hd);
        for (size_t i = 0; i < 3 * m; ++i) {
            h[i] = over ? urand() : urange(0, 0.45);
            hd[i] = urange(-0.2, 0.2);
        }
        /* over-determined: a smooth target plus noise, so that C stays moderate */
        for (size_t i = 0; over && i < m; ++i) {
            const double *p = h + 3 * i;
            hd[3 * i] = 0.1 * sin(3 * p[0]) + 0.01 * urange(-1, 1);
            hd[3 * i + 1] = 0.1 * cos(2 * p[1]) * p[2] + 0.01 * urange(-1, 1);
            hd[3 * i + 2] = 0.1 * p[0] * p[1] * p[2] + 0.01 * urange(-1, 1);
        }
        double *dc = malloc(nc * 3 * sizeof *dc), *ref = malloc(nc * 3 * sizeof *ref);
        cm_dmffd *dm = NULL;
        CHECK(cm_dmffd_create(ctx, f, m, h, NULL, &dm) == CM_OK);
        CHECK(cm_dmffd_solve(ctx, dm, hd, dc) == CM_OK);
        cm_dmffd_info info;
        cm_dmffd_get_info(dm, &info);
        double *phi = dense_phi(f, m, h);
        lapack_lstsq(phi, m, nc, hd, ref);
        double diff = 0, cmax = 0;
        for (size_t i = 0; i < 3 * nc; ++i) {
            diff = fmax(diff, fabs(dc[i] - ref[i]));
            cmax = fmax(cmax, fabs(ref[i]));
        }
        /* untouched columns: exactly zero */
        int untouched = 0, nonzero = 0;
        for (size_t p = 0; p < nc; ++p) {
            int used = 0;
            for (size_t i = 0; i < m && !used; ++i)
                used = phi[i * nc + p] != 0;
            if (!used) {
                ++untouched;
                nonzero += dc[3 * p] != 0 || dc[3 * p + 1] != 0 || dc[3 * p + 2] != 0;
            }
        }
        /* normal equations: Phi^T (Phi C - H) = 0 */
        double ne = 0;
        if (over) {
            double *r = malloc(m * 3 * sizeof *r);
            for (size_t i = 0; i < m; ++i)
                for (int k = 0; k < 3; ++k) {
                    double s = -hd[3 * i + k];
                    for (size_t p = 0; p < nc; ++p)
                        s += phi[i * nc + p] * dc[3 * p + k];
                    r[3 * i + k] = s;
                }
            for (size_t p = 0; p < nc; ++p)
                for (int k = 0; k < 3; ++k) {
                    double s = 0;
                    for (size_t i = 0; i < m; ++i)
                        s += phi[i * nc + p] * r[3 * i + k];
                    ne = fmax(ne, fabs(s));
                }
            free(r);
        }
        printf("%s: m %zu, active %zu of %zu, |C - dgelsd| = %.3g (max |C| %.3g), untouched %d "
               "(non-zero %d), residual %.3g, |Phi^T r| = %.3g\n",
               over ? "least squares" : "least norm", m, info.active, nc, diff, cmax, untouched,
               nonzero, info.residual, ne);
        CHECK(diff <= 1e-12 * fmax(1, cmax));
        CHECK(nonzero == 0);
        if (!over) {
            CHECK(untouched > 0 && info.active == nc - (size_t)untouched);
            CHECK(info.residual <= 1e-12);
        } else {
            CHECK(ne <= 1e-12);
            CHECK(info.residual > 1e-3); /* 900 random targets on 125 controls: not met */
        }
        cm_ffd_destroy(&f);
        free(phi);
        free(h);
        free(hd);
        free(dc);
        free(ref);
        cm_dmffd_destroy(&dm);
    }
}

/* 11: B = M Phi^+ once, then B H = M (Phi^+ H) for three different H. */
static void test_precompute(void)
{
    cm_ffd *f = unit_lattice(6);
    size_t m = 50, k = 300, nc = cm_ffd_control_count(f);
    double *h = malloc(m * 3 * sizeof *h), *x = malloc(k * 3 * sizeof *x);
    for (size_t i = 0; i < 3 * m; ++i)
        h[i] = urange(0.1, 0.9);
    for (size_t i = 0; i < 3 * k; ++i)
        x[i] = urange(-0.1, 1.1); /* some outside: zero rows */
    cm_dmffd *dm = NULL;
    CHECK(cm_dmffd_create(ctx, f, m, h, NULL, &dm) == CM_OK);
    double *b = NULL;
    CHECK(cm_dmffd_precompute(ctx, dm, k, x, &b) == CM_OK);
    double *hd = malloc(m * 3 * sizeof *hd), *dc = malloc(nc * 3 * sizeof *dc);
    double *d1 = malloc(k * 3 * sizeof *d1);
    double worst = 0;
    for (int trial = 0; trial < 3; ++trial) {
        for (size_t i = 0; i < 3 * m; ++i)
            hd[i] = urange(-1, 1);
        CHECK(cm_dmffd_solve(ctx, dm, hd, dc) == CM_OK);
        CHECK(cm_ffd_deform(ctx, f, dc, k, x, d1, NULL) == CM_OK);
        for (size_t i = 0; i < k; ++i)
            for (int c = 0; c < 3; ++c) {
                double s = 0;
                for (size_t j = 0; j < m; ++j)
                    s += b[i * m + j] * hd[3 * j + c];
                worst = fmax(worst, fabs(s - d1[3 * i + c]));
            }
    }
    printf("precompute: k %zu, m %zu: max |B H - M Phi^+ H| = %.3g over 3 H\n", k, m, worst);
    CHECK(worst <= 1e-13);
    free(b);
    free(h);
    free(x);
    free(hd);
    free(dc);
    free(d1);
    cm_dmffd_destroy(&dm);
    cm_ffd_destroy(&f);
}

/* Handles on a sphere of radius r around the centre of the unit cube. */
static void sphere_points(size_t m, double r, double *h)
{
    for (size_t i = 0; i < m; ++i) {
        /* Fibonacci sphere: evenly spread, deterministic */
        double z = 1 - (2 * i + 1.0) / m, rho = sqrt(1 - z * z), phi = 2.399963229728653 * i;
        h[3 * i] = 0.5 + r * rho * cos(phi);
        h[3 * i + 1] = 0.5 + r * rho * sin(phi);
        h[3 * i + 2] = 0.5 + r * z;
    }
}

/* 12: Fig. 8 setting - a 5^3 lattice, handles on a sphere, eps 1e-10 vs 1e-2: the larger
 * eps gives smaller control displacements and a larger handle residual. */
static void test_clamping(void)
{
    cm_ffd *f = unit_lattice(5);
    size_t m = 400, nc = cm_ffd_control_count(f);
    double *h = malloc(m * 3 * sizeof *h), *hd = malloc(m * 3 * sizeof *hd);
    double *dc = malloc(nc * 3 * sizeof *dc);
    sphere_points(m, 0.4, h);
    for (size_t i = 0; i < m; ++i) /* a localised bump pushed outwards */
        for (int c = 0; c < 3; ++c) {
            double n = (h[3 * i + c] - 0.5) / 0.4, z = (h[3 * i + 2] - 0.5) / 0.4;
            hd[3 * i + c] = z > 0.7 ? 0.1 * n * (z - 0.7) / 0.3 : 0;
        }
    cm_dmffd_info info[2];
    double eps[2] = {1e-10, 1e-2};
    for (int e = 0; e < 2; ++e) {
        cm_dmffd_options opt;
        cm_dmffd_options_init(&opt);
        opt.eps = eps[e];
        cm_dmffd *dm = NULL;
        CHECK(cm_dmffd_create(ctx, f, m, h, &opt, &dm) == CM_OK);
        CHECK(cm_dmffd_solve(ctx, dm, hd, dc) == CM_OK);
        cm_dmffd_get_info(dm, &info[e]);
        printf("clamping eps %g: active %zu, rank %zu, clamped %zu, sigma %.3g .. %.3g, max |dc| "
               "%.4g, residual %.4g\n",
               eps[e], info[e].active, info[e].rank, info[e].clamped, info[e].sigma_max,
               info[e].sigma_min, info[e].max_control, info[e].residual);
        cm_dmffd_destroy(&dm);
    }
    CHECK(info[1].clamped > info[0].clamped);
    CHECK(info[1].max_control < info[0].max_control);
    CHECK(info[1].residual > info[0].residual);
    free(h);
    free(hd);
    free(dc);
    cm_ffd_destroy(&f);
}

/* 13: every handle translated by t: the handles are met (full row rank) but the least-norm
 * control net does not translate the rest - DM-FFD is not "fixed" into an interpolant that
 * reproduces translations. The RBF with its linear polynomial reproduces t exactly. */
static void test_translation_not_reproduced(void)
{
    cm_ffd *f = unit_lattice(8);
    size_t m = 60, k = 500, nc = cm_ffd_control_count(f);
    double *h = malloc(m * 3 * sizeof *h), *hd = malloc(m * 3 * sizeof *hd);
    double *x = malloc(k * 3 * sizeof *x), *d = malloc(k * 3 * sizeof *d);
    double *dc = malloc(nc * 3 * sizeof *dc);
    sphere_points(m, 0.3, h);
    const double t[3] = {0.05, -0.02, 0.03};
    double tn = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (size_t i = 0; i < m; ++i)
        memcpy(hd + 3 * i, t, sizeof t);
    for (size_t i = 0; i < 3 * k; ++i)
        x[i] = urange(0.25, 0.75);
    cm_dmffd *dm = NULL;
    CHECK(cm_dmffd_create(ctx, f, m, h, NULL, &dm) == CM_OK);
    CHECK(cm_dmffd_solve(ctx, dm, hd, dc) == CM_OK);
    cm_dmffd_info info;
    cm_dmffd_get_info(dm, &info);
    CHECK(cm_ffd_deform(ctx, f, dc, k, x, d, NULL) == CM_OK);
    double lo = INFINITY, hi = 0;
    for (size_t i = 0; i < k; ++i) {
        double s = (d[3 * i] * t[0] + d[3 * i + 1] * t[1] + d[3 * i + 2] * t[2]) / (tn * tn);
        lo = fmin(lo, s);
        hi = fmax(hi, s);
    }
    printf("translation by DM-FFD: handle residual %.3g, interior moves %.3g t .. %.3g t\n",
           info.residual, lo, hi);
    CHECK(info.residual <= 1e-12);
    CHECK(lo < 0.95 || hi > 1.05);

    cm_rbf *rbf = NULL;
    CHECK(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, h, &rbf) == CM_OK);
    CHECK(cm_rbf_solve(ctx, rbf, 3, hd) == CM_OK);
    CHECK(cm_rbf_evaluate(ctx, rbf, k, x, d) == CM_OK);
    double worst = 0;
    for (size_t i = 0; i < k; ++i)
        for (int c = 0; c < 3; ++c)
            worst = fmax(worst, fabs(d[3 * i + c] - t[c]));
    printf("translation by the RBF: max |d - t| / |t| = %.3g\n", worst / tn);
    CHECK(worst <= 1e-9 * tn);
    cm_rbf_destroy(&rbf);
    cm_dmffd_destroy(&dm);
    free(h);
    free(hd);
    free(x);
    free(d);
    free(dc);
    cm_ffd_destroy(&f);
}

static void test_errors(void)
{
    cm_ffd *f = unit_lattice(4);
    double h[6] = {0.5, 0.5, 0.5, 1.5, 0.5, 0.5};
    cm_dmffd *dm = NULL;
    CHECK(cm_dmffd_create(ctx, f, 2, h, NULL, &dm) == CM_ERR_ARGUMENT && dm == NULL);
    CHECK(strstr(cm_context_message(ctx), "handle 1") != NULL);
    CHECK(cm_dmffd_create(ctx, f, 0, h, NULL, &dm) == CM_ERR_ARGUMENT);
    cm_ffd_destroy(&f);
}

int main(void)
{
    cm_context_create(&ctx);
    test_exact();
    test_least_norm_squares();
    test_precompute();
    test_clamping();
    test_translation_not_reproduced();
    test_errors();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
