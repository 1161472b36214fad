/* The benchmark suite of [SMB14 §3] for FFD, DM-FFD and the RBF:
 * `bench_deform perf|precision|robust|smooth OUTDIR [threads]`. Each block prints a table and
 * writes CSV (and surface meshes with per-vertex mean curvature for ParaView) into OUTDIR;
 * plots.py turns the CSVs into SVG. Not a test: run by run_deform.sh. */
#include "surface.h"

#include "cadmorph/deform.h"
#include "cadmorph/mesh.h"
#include "cadmorph/rbf.h"

#include <cblas.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static const char *outdir;
static int max_threads = 2;

static uint64_t rng_state = 0x2545F4914F6CDD1Dull;
static double urand(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

static void die(cm_status s, const char *what)
{
    if (s >= 0) return;
    fprintf(stderr, "bench_deform: %s: %s\n", what, cm_context_message(ctx));
    exit(1);
}

static FILE *out_csv(const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", outdir, name);
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "bench_deform: cannot write %s\n", path);
        exit(1);
    }
    return f;
}

static void bbox_of(size_t n, const double *x, double bb[6])
{
    for (int a = 0; a < 3; ++a) {
        bb[a] = INFINITY;
        bb[a + 3] = -INFINITY;
    }
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            bb[a] = fmin(bb[a], x[3 * i + a]);
            bb[a + 3] = fmax(bb[a + 3], x[3 * i + a]);
        }
}

static cm_ffd *enclosing_lattice(size_t n, const double *x, int per_axis)
{
    double bb[6];
    bbox_of(n, x, bb);
    cm_ffd_desc d;
    cm_ffd_desc_enclosing(&d, bb, 1e-3, per_axis);
    cm_ffd *f = NULL;
    die(cm_ffd_create(ctx, &d, &f), "lattice");
    return f;
}

/* best of reps wall times */
#define TIME_BEST(reps, best, code)                                                                \
    do {                                                                                           \
        best = INFINITY;                                                                           \
        for (int r_ = 0; r_ < (reps); ++r_) {                                                      \
            double t0_ = cm_wtime();                                                               \
            code;                                                                                  \
            double dt_ = cm_wtime() - t0_;                                                         \
            if (dt_ < best) best = dt_;                                                            \
        }                                                                                          \
    } while (0)

/* ---- block 1: performance (Fig. 6) ---- */

static void block_perf(void)
{
    const size_t k = 100000, m = 427;
    const int lat = 8;
    double *x = malloc(k * 3 * sizeof *x), *u = malloc(k * 3 * sizeof *u);
    double *d = malloc(k * 3 * sizeof *d);
    /* the points of a sphere-like shell (a surface mesh stand-in) and 427 of them as handles */
    for (size_t i = 0; i < k; ++i) {
        double z = 2 * urand() - 1, ph = 2 * 3.141592653589793 * urand(), r = 0.9 + 0.1 * urand();
        double rho = sqrt(1 - z * z);
        x[3 * i] = r * rho * cos(ph);
        x[3 * i + 1] = 0.6 * r * rho * sin(ph);
        x[3 * i + 2] = 0.4 * r * z;
    }
    double *h = malloc(m * 3 * sizeof *h), *hd = malloc(m * 3 * sizeof *hd);
    for (size_t i = 0; i < m; ++i) {
        memcpy(h + 3 * i, x + 3 * (i * (k / m)), 3 * sizeof *h);
        for (int c = 0; c < 3; ++c)
            hd[3 * i + c] = 0.05 * sin(3 * h[3 * i + c] + c);
    }
    cm_ffd *f = enclosing_lattice(k, x, lat);
    size_t nc = cm_ffd_control_count(f);
    double *dc = malloc(nc * 3 * sizeof *dc), *ctrl = malloc(nc * 3 * sizeof *ctrl);
    for (size_t i = 0; i < 3 * nc; ++i)
        dc[i] = 0.02 * (urand() - 0.5);
    FILE *csv = out_csv("perf.csv");
    fprintf(csv, "stage,threads,seconds\n");
    printf("block 1 (performance): %zu points, %zu constraints, %d^3 lattice (%zu control "
           "points), best of 3\n",
           k, m, lat, nc);
    printf("%-52s %8s %10s\n", "stage", "threads", "seconds");
    for (int th = 1; th <= max_threads; th *= 2) {
        cm_context_set_threads(ctx, th);
        double t;
        cm_ffd_stats st;
        cm_ffd_set_local(f, CM_FFD_LOCAL_AFFINE);
        TIME_BEST(3, t, die(cm_ffd_local_coords(ctx, f, k, x, u, NULL, &st), "local"));
        printf("%-52s %8d %10.4f\n", "FFD local coordinates, affine", th, t);
        fprintf(csv, "ffd_local_affine,%d,%.6f\n", th, t);
        cm_ffd_set_local(f, CM_FFD_LOCAL_NEWTON);
        TIME_BEST(3, t, die(cm_ffd_local_coords(ctx, f, k, x, u, NULL, &st), "local"));
        printf("%-52s %8d %10.4f\n", "FFD local coordinates, Newton (reference lattice)", th, t);
        fprintf(csv, "ffd_local_newton_ref,%d,%.6f\n", th, t);
        /* a pre-deformed lattice: Newton does real work */
        cm_ffd_set_local(f, CM_FFD_LOCAL_AUTO);
        cm_ffd_set_control_points(ctx, f, NULL);
        cm_ffd_control_points(f, ctrl);
        uint64_t saved = rng_state;
        rng_state = 99;
        for (size_t i = 0; i < 3 * nc; ++i)
            ctrl[i] += 0.03 * (urand() - 0.5);
        rng_state = saved;
        die(cm_ffd_set_control_points(ctx, f, ctrl), "ctrl");
        TIME_BEST(3, t, die(cm_ffd_local_coords(ctx, f, k, x, u, NULL, &st), "local"));
        printf("%-52s %8d %10.4f   (max %d iterations, %zu failed)\n",
               "FFD local coordinates, Newton (moved lattice)", th, t, st.max_iterations,
               st.failed);
        fprintf(csv, "ffd_local_newton_moved,%d,%.6f\n", th, t);
        cm_ffd_set_control_points(ctx, f, NULL);
        TIME_BEST(3, t, die(cm_ffd_deform(ctx, f, dc, k, x, d, &st), "deform"));
        printf("%-52s %8d %10.4f\n", "FFD deformation (local coordinates + evaluation)", th, t);
        fprintf(csv, "ffd_deform,%d,%.6f\n", th, t);

        /* DM-FFD: Phi, SVD, B = M Phi^+ */
        cm_dmffd *dm = NULL;
        double *b = NULL, tc, tb;
        TIME_BEST(3, tc, cm_dmffd_destroy(&dm);
                  die(cm_dmffd_create(ctx, f, m, h, NULL, &dm), "dmffd"));
        TIME_BEST(3, tb, free(b); b = NULL; die(cm_dmffd_precompute(ctx, dm, k, x, &b), "B"));
        printf("%-52s %8d %10.4f\n", "DM-FFD Phi + SVD", th, tc);
        printf("%-52s %8d %10.4f\n", "DM-FFD B = M Phi^+", th, tb);
        printf("%-52s %8d %10.4f\n", "DM-FFD full precomputation (SVD + B)", th, tc + tb);
        fprintf(csv, "dmffd_svd,%d,%.6f\ndmffd_B,%d,%.6f\ndmffd_precompute,%d,%.6f\n", th, tc, th,
                tb, th, tc + tb);
        TIME_BEST(3, t,
                  cblas_dgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, (int)k, 3, (int)m, 1.0,
                              b, (int)m, hd, 3, 0.0, d, 3));
        printf("%-52s %8d %10.4f\n", "DM-FFD per step: B H", th, t);
        fprintf(csv, "dmffd_step_BH,%d,%.6f\n", th, t);
        TIME_BEST(3, t, die(cm_dmffd_solve(ctx, dm, hd, dc), "solve");
                  die(cm_ffd_deform(ctx, f, dc, k, x, d, NULL), "deform"));
        printf("%-52s %8d %10.4f\n", "DM-FFD per step without B: Phi^+ H, then FFD", th, t);
        fprintf(csv, "dmffd_step_direct,%d,%.6f\n", th, t);
        free(b);
        cm_dmffd_destroy(&dm);

        /* RBF: factorisation, B = M Phi^-1 (the identity as m right-hand sides) */
        cm_rbf *rbf = NULL;
        double *eye = calloc(m * m, sizeof *eye), *brbf = malloc(k * m * sizeof *brbf);
        for (size_t i = 0; i < m; ++i)
            eye[i * m + i] = 1;
        TIME_BEST(3, tc, cm_rbf_destroy(&rbf);
                  die(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, h, &rbf), "rbf"));
        TIME_BEST(1, tb, die(cm_rbf_solve(ctx, rbf, (int)m, eye), "rbf solve");
                  die(cm_rbf_evaluate(ctx, rbf, k, x, brbf), "rbf B"));
        printf("%-52s %8d %10.4f\n", "RBF factorisation (m + 4 system)", th, tc);
        printf("%-52s %8d %10.4f\n", "RBF B = M Phi^-1", th, tb);
        printf("%-52s %8d %10.4f\n", "RBF full precomputation", th, tc + tb);
        fprintf(csv, "rbf_factor,%d,%.6f\nrbf_B,%d,%.6f\nrbf_precompute,%d,%.6f\n", th, tc, th, tb,
                th, tc + tb);
        TIME_BEST(3, t, die(cm_rbf_solve(ctx, rbf, 3, hd), "solve");
                  die(cm_rbf_evaluate(ctx, rbf, k, x, d), "eval"));
        printf("%-52s %8d %10.4f\n", "RBF per step without B: solve, evaluate", th, t);
        fprintf(csv, "rbf_step_direct,%d,%.6f\n", th, t);
        free(eye);
        free(brbf);
        cm_rbf_destroy(&rbf);
    }
    fclose(csv);
    free(x);
    free(u);
    free(d);
    free(h);
    free(hd);
    free(dc);
    free(ctrl);
    cm_ffd_destroy(&f);
}

/* ---- block 5: precision (section 3.5) ---- */

/* The target motion: a localised bump, 0.1 high, pushing +z around (0.5, 0.5, 0.9). */
static void target(const double *p, double *g)
{
    double r2 = (p[0] - 0.5) * (p[0] - 0.5) + (p[1] - 0.5) * (p[1] - 0.5) +
                (p[2] - 0.9) * (p[2] - 0.9);
    g[0] = 0;
    g[1] = 0;
    g[2] = 0.1 * exp(-r2 / 0.05);
}

static void block_precision(void)
{
    FILE *csv = out_csv("precision.csv");
    fprintf(csv, "method,lattice,handles,residual_rel\n");
    printf("block 5 (precision): handles on a sphere (r 0.4 around (0.5, 0.5, 0.5)), target a "
           "0.1 bump; residual |d(h) - H|_inf / |H|_inf\n");
    printf("%-8s %8s %8s %14s\n", "method", "lattice", "handles", "residual");
    size_t ms[3] = {50, 427, 2000};
    for (int mi = 0; mi < 3; ++mi) {
        size_t m = ms[mi];
        double *h = malloc(m * 3 * sizeof *h), *hd = malloc(m * 3 * sizeof *hd);
        double *d = malloc(m * 3 * sizeof *d);
        for (size_t i = 0; i < m; ++i) {
            double z = 1 - (2 * i + 1.0) / m, rho = sqrt(1 - z * z), ph = 2.399963229728653 * i;
            h[3 * i] = 0.5 + 0.4 * rho * cos(ph);
            h[3 * i + 1] = 0.5 + 0.4 * rho * sin(ph);
            h[3 * i + 2] = 0.5 + 0.4 * z;
            target(h + 3 * i, hd + 3 * i);
        }
        double hmax = 0;
        for (size_t i = 0; i < 3 * m; ++i)
            hmax = fmax(hmax, fabs(hd[i]));
        int lats[4] = {5, 8, 10, 15};
        for (int li = 0; li < 4; ++li) {
            cm_ffd *f = enclosing_lattice(m, h, lats[li]);
            size_t nc = cm_ffd_control_count(f);
            double *dc = malloc(nc * 3 * sizeof *dc), *ctrl = malloc(nc * 3 * sizeof *ctrl);
            /* FFD: the designer moves the lattice by the target field at the control points */
            cm_ffd_control_points(f, ctrl);
            for (size_t p = 0; p < nc; ++p)
                target(ctrl + 3 * p, dc + 3 * p);
            die(cm_ffd_deform(ctx, f, dc, m, h, d, NULL), "ffd");
            double res = 0;
            for (size_t i = 0; i < 3 * m; ++i)
                res = fmax(res, fabs(d[i] - hd[i]));
            printf("%-8s %8d %8zu %14.3e\n", "FFD", lats[li], m, res / hmax);
            fprintf(csv, "ffd,%d,%zu,%.6e\n", lats[li], m, res / hmax);
            cm_dmffd *dm = NULL;
            die(cm_dmffd_create(ctx, f, m, h, NULL, &dm), "dmffd");
            die(cm_dmffd_solve(ctx, dm, hd, dc), "solve");
            die(cm_ffd_deform(ctx, f, dc, m, h, d, NULL), "ffd");
            res = 0;
            for (size_t i = 0; i < 3 * m; ++i)
                res = fmax(res, fabs(d[i] - hd[i]));
            cm_dmffd_info info;
            cm_dmffd_get_info(dm, &info);
            printf("%-8s %8d %8zu %14.3e   (Phi residual %.3e, rank %zu of %zu active)\n",
                   "DM-FFD", lats[li], m, res / hmax, info.residual, info.rank, info.active);
            fprintf(csv, "dmffd,%d,%zu,%.6e\n", lats[li], m, res / hmax);
            cm_dmffd_destroy(&dm);
            free(dc);
            free(ctrl);
            cm_ffd_destroy(&f);
        }
        cm_rbf *rbf = NULL;
        die(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, m, h, &rbf), "rbf");
        die(cm_rbf_solve(ctx, rbf, 3, hd), "rbf");
        die(cm_rbf_evaluate(ctx, rbf, m, h, d), "rbf");
        double res = 0;
        for (size_t i = 0; i < 3 * m; ++i)
            res = fmax(res, fabs(d[i] - hd[i]));
        printf("%-8s %8s %8zu %14.3e\n", "RBF", "-", m, res / hmax);
        fprintf(csv, "rbf,0,%zu,%.6e\n", m, res / hmax);
        cm_rbf_destroy(&rbf);
        free(h);
        free(hd);
        free(d);
    }
    fclose(csv);
}

/* ---- surfaces for blocks 2 and 3 ---- */

static void write_surface(const bench_surface *s, const double *xyz, const double *hc,
                          const unsigned char *region, const char *name)
{
    cm_mesh *m = NULL;
    die(cm_mesh_create(ctx, &m), "mesh");
    die(cm_mesh_resize_nodes(ctx, m, s->nv, 0), "mesh");
    memcpy(m->xyz, xyz, s->nv * 3 * sizeof *xyz);
    for (size_t t = 0; t < s->nt; ++t)
        die(cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, s->tri + 3 * t, 3, 0, 0, 0), "mesh");
    double *fh = NULL, *fr = NULL;
    die(cm_mesh_add_field(ctx, m, "mean_curvature", CM_FIELD_NODE, 1, &fh), "field");
    memcpy(fh, hc, s->nv * sizeof *fh);
    if (region) {
        die(cm_mesh_add_field(ctx, m, "region", CM_FIELD_NODE, 1, &fr), "field");
        for (size_t i = 0; i < s->nv; ++i)
            fr[i] = region[i];
    }
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", outdir, name);
    die(cm_mesh_write(ctx, m, path, NULL), path);
    cm_mesh_destroy(&m);
}

typedef struct hstats {
    double min, max, mean, std;
} hstats;

static hstats stats_of(size_t n, const double *v, const unsigned char *mask, int want)
{
    hstats s = {INFINITY, -INFINITY, 0, 0};
    size_t c = 0;
    for (size_t i = 0; i < n; ++i) {
        if (mask && mask[i] != want) continue;
        s.min = fmin(s.min, v[i]);
        s.max = fmax(s.max, v[i]);
        s.mean += v[i];
        ++c;
    }
    s.mean /= c ? c : 1;
    for (size_t i = 0; i < n; ++i)
        if (!mask || mask[i] == want) s.std += (v[i] - s.mean) * (v[i] - s.mean);
    s.std = sqrt(s.std / (c ? c : 1));
    return s;
}

/* Deforms the surface by DM-FFD through handles sel (m indices) with displacements hd. */
static void dmffd_surface(const bench_surface *s, int lat, double eps, size_t m,
                          const int64_t *sel, const double *hd, double *moved,
                          cm_dmffd_info *info)
{
    double *h = malloc(m * 3 * sizeof *h), *d = malloc(s->nv * 3 * sizeof *d);
    for (size_t i = 0; i < m; ++i)
        memcpy(h + 3 * i, s->xyz + 3 * sel[i], 3 * sizeof *h);
    cm_ffd *f = enclosing_lattice(s->nv, s->xyz, lat);
    size_t nc = cm_ffd_control_count(f);
    double *dc = malloc(nc * 3 * sizeof *dc);
    cm_dmffd_options opt;
    cm_dmffd_options_init(&opt);
    opt.eps = eps;
    cm_dmffd *dm = NULL;
    die(cm_dmffd_create(ctx, f, m, h, &opt, &dm), "dmffd");
    die(cm_dmffd_solve(ctx, dm, hd, dc), "solve");
    cm_dmffd_get_info(dm, info);
    die(cm_ffd_deform(ctx, f, dc, s->nv, s->xyz, d, NULL), "deform");
    for (size_t i = 0; i < 3 * s->nv; ++i)
        moved[i] = s->xyz[i] + d[i];
    cm_dmffd_destroy(&dm);
    cm_ffd_destroy(&f);
    free(h);
    free(d);
    free(dc);
}

/* ---- block 2: robustness (Fig. 8) ---- */

static void block_robust(void)
{
    bench_surface s;
    double c[3] = {0, 0, 0};
    bench_icosphere(4, c, 1.0, &s);
    /* handles: the top cap (z > 0.75) lifted by 0.2, the bottom cap (z < -0.75) held */
    size_t m = 0;
    int64_t *sel = malloc(s.nv * sizeof *sel);
    double *hd = malloc(s.nv * 3 * sizeof *hd);
    unsigned char *region = calloc(s.nv, 1);
    for (size_t i = 0; i < s.nv; ++i) {
        double z = s.xyz[3 * i + 2];
        if (fabs(z) <= 0.75) continue;
        region[i] = z > 0 ? 2 : 1;
        sel[m] = (int64_t)i;
        hd[3 * m] = hd[3 * m + 1] = 0;
        hd[3 * m + 2] = z > 0 ? 0.2 : 0;
        ++m;
    }
    double *moved = malloc(s.nv * 3 * sizeof *moved), *hc = malloc(s.nv * sizeof *hc);
    bench_mean_curvature(&s, s.xyz, hc);
    hstats h0 = stats_of(s.nv, hc, NULL, 0);
    write_surface(&s, s.xyz, hc, region, "robust_sphere.vtu");
    FILE *csv = out_csv("robust.csv");
    fprintf(csv, "eps,handles,active,rank,clamped,residual_rel,max_dc,H_min,H_max,H_std\n");
    printf("block 2 (robustness): unit icosphere (%zu vertices), %zu handles (caps |z| > 0.75: "
           "top +0.2 z, bottom held), 5^3 lattice\n",
           s.nv, m);
    printf("undeformed: mean curvature %.4f .. %.4f\n", h0.min, h0.max);
    printf("%-8s %8s %8s %12s %12s %10s %10s %10s\n", "eps", "rank", "clamped", "residual",
           "max|dc|", "H min", "H max", "H std");
    double eps[2] = {1e-10, 1e-2};
    for (int e = 0; e < 2; ++e) {
        cm_dmffd_info info;
        dmffd_surface(&s, 5, eps[e], m, sel, hd, moved, &info);
        bench_mean_curvature(&s, moved, hc);
        hstats hs = stats_of(s.nv, hc, NULL, 0);
        printf("%-8.0e %8zu %8zu %12.4e %12.4g %10.4f %10.4f %10.4f\n", eps[e], info.rank,
               info.clamped, info.residual, info.max_control, hs.min, hs.max, hs.std);
        fprintf(csv, "%g,%zu,%zu,%zu,%zu,%.6e,%.6g,%.6g,%.6g,%.6g\n", eps[e], m, info.active,
                info.rank, info.clamped, info.residual, info.max_control, hs.min, hs.max, hs.std);
        char name[64];
        snprintf(name, sizeof name, "robust_eps%g.vtu", eps[e]);
        write_surface(&s, moved, hc, region, name);
    }
    fclose(csv);
    free(sel);
    free(hd);
    free(region);
    free(moved);
    free(hc);
    bench_surface_free(&s);
}

/* ---- block 3: smoothness (Fig. 9) ---- */

static void block_smooth(void)
{
    bench_surface s;
    double c[3] = {0, 0, 0};
    bench_icosphere(5, c, 1.0, &s);
    /* regions: handle z > 0.85 (lifted 0.3 in z), fixed z < 0.2, deformable in between; 792
     * constraints taken evenly from the handle and fixed vertices (the paper's kernel count) */
    unsigned char *region = calloc(s.nv, 1); /* 0 deformable, 1 fixed, 2 handle */
    size_t n_con = 0;
    for (size_t i = 0; i < s.nv; ++i) {
        double z = s.xyz[3 * i + 2];
        region[i] = z > 0.85 ? 2 : z < 0.2 ? 1 : 0;
        n_con += region[i] != 0;
    }
    const size_t m = 792;
    int64_t *sel = malloc(m * sizeof *sel);
    double *hd = calloc(m * 3, sizeof *hd);
    size_t q = 0, seen = 0;
    for (size_t i = 0; i < s.nv && q < m; ++i) {
        if (!region[i]) continue;
        if (seen++ * m / n_con >= q) { /* every (n_con / m)-th constrained vertex */
            sel[q] = (int64_t)i;
            hd[3 * q + 2] = region[i] == 2 ? 0.3 : 0;
            ++q;
        }
    }
    double *moved = malloc(s.nv * 3 * sizeof *moved), *hc = malloc(s.nv * sizeof *hc);
    FILE *csv = out_csv("smooth.csv");
    fprintf(csv, "method,dof,constraints,residual_rel,H_min,H_max,H_mean,H_std\n");
    FILE *hist = out_csv("smooth_H.csv");
    fprintf(hist, "method,vertex,z,H\n");
    printf("block 3 (smoothness): unit icosphere (%zu vertices), %zu constraints (handle z > "
           "0.85 +0.3 z, fixed z < 0.2), H over the deformable band 0.2 <= z <= 0.85\n",
           s.nv, q);
    printf("%-8s %6s %12s %10s %10s %10s %10s\n", "method", "DoF", "residual", "H min", "H max",
           "H mean", "H std");
    for (int meth = 0; meth < 2; ++meth) {
        double res;
        size_t dof;
        if (meth == 0) {
            cm_dmffd_info info;
            dmffd_surface(&s, 9, 1e-10, q, sel, hd, moved, &info);
            res = info.residual;
            dof = 729;
        } else {
            double *h = malloc(q * 3 * sizeof *h), *d = malloc(s.nv * 3 * sizeof *d);
            for (size_t i = 0; i < q; ++i)
                memcpy(h + 3 * i, s.xyz + 3 * sel[i], 3 * sizeof *h);
            cm_rbf *rbf = NULL;
            die(cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, q, h, &rbf), "rbf");
            die(cm_rbf_solve(ctx, rbf, 3, hd), "rbf");
            die(cm_rbf_evaluate(ctx, rbf, s.nv, s.xyz, d), "rbf");
            for (size_t i = 0; i < 3 * s.nv; ++i)
                moved[i] = s.xyz[i] + d[i];
            res = 0;
            for (size_t i = 0; i < q; ++i)
                for (int k = 0; k < 3; ++k)
                    res = fmax(res, fabs(d[3 * sel[i] + k] - hd[3 * i + k]));
            res /= 0.3;
            dof = q;
            cm_rbf_destroy(&rbf);
            free(h);
            free(d);
        }
        bench_mean_curvature(&s, moved, hc);
        hstats hs = stats_of(s.nv, hc, region, 0);
        const char *name = meth ? "RBF" : "DM-FFD";
        printf("%-8s %6zu %12.4e %10.4f %10.4f %10.4f %10.4f\n", name, dof, res, hs.min, hs.max,
               hs.mean, hs.std);
        fprintf(csv, "%s,%zu,%zu,%.6e,%.6g,%.6g,%.6g,%.6g\n", meth ? "rbf" : "dmffd", dof, q, res,
                hs.min, hs.max, hs.mean, hs.std);
        for (size_t i = 0; i < s.nv; ++i)
            if (!region[i]) fprintf(hist, "%s,%zu,%.6g,%.6g\n", meth ? "rbf" : "dmffd", i, s.xyz[3 * i + 2], hc[i]);
        write_surface(&s, moved, hc, region, meth ? "smooth_rbf.vtu" : "smooth_dmffd.vtu");
    }
    fclose(csv);
    fclose(hist);
    free(region);
    free(sel);
    free(hd);
    free(moved);
    free(hc);
    bench_surface_free(&s);
}

/* ---- block 4: adaptivity (Fig. 12) ---- */

/* The target: a plane z = 0 on [0,1]^2 pushed into a steep bump 0.2 high (sigma ~0.055). */
static double bump(double x, double y)
{
    return 0.2 * exp(-((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5)) / 0.006);
}

/* Knot vector of n + 4 entries from the m + 1 domain knots g (0 = g_0 < ... < g_m = 1,
 * m = n - 3 spans), extended by the end spans' widths. */
static void full_knots(const double *g, int spans, double *t)
{
    double h0 = g[1] - g[0], h1 = g[spans] - g[spans - 1];
    for (int j = 0; j < 3; ++j) {
        t[j] = -(3 - j) * h0;
        t[spans + 4 + j] = 1 + (j + 1) * h1;
    }
    for (int j = 0; j <= spans; ++j)
        t[3 + j] = g[j];
}

static void block_adapt(void)
{
    const int side = 41;
    const size_t nv = (size_t)side * side;
    double *x = malloc(nv * 3 * sizeof *x), *hd = malloc(nv * 3 * sizeof *hd);
    double *d = malloc(nv * 3 * sizeof *d);
    for (int j = 0; j < side; ++j)
        for (int i = 0; i < side; ++i) {
            size_t v = (size_t)j * side + i;
            x[3 * v] = (double)i / (side - 1);
            x[3 * v + 1] = (double)j / (side - 1);
            x[3 * v + 2] = 0;
            hd[3 * v] = hd[3 * v + 1] = 0;
            hd[3 * v + 2] = bump(x[3 * v], x[3 * v + 1]);
        }
    FILE *csv = out_csv("adapt.csv");
    fprintf(csv, "method,dof,error_rel\n");
    printf("block 4 (adaptivity): plane %dx%d vertices, all constraints, bump 0.2 high; "
           "error = max |d - target| / 0.2 over the vertices\n",
           side, side);
    /* DM-FFD: domain knots in x and y, 4 control points in z; insert a knot in x and y at the
     * middle of the spans holding the worst vertex, until DoF >= #constraints */
    double gx[256] = {0, 1}, gy[256] = {0, 1};
    int sx = 1, sy = 1;
    const double eps = 1e-6;
    for (int it = 0; it < 200; ++it) {
        double tx[260], ty[260];
        static const double tz[8] = {-3, -2, -1, 0, 1, 2, 3, 4};
        full_knots(gx, sx, tx);
        full_knots(gy, sy, ty);
        cm_ffd_desc desc;
        cm_ffd_desc_init(&desc);
        desc.knots = CM_FFD_KNOTS_CUSTOM;
        desc.n[0] = sx + 3;
        desc.n[1] = sy + 3;
        desc.n[2] = 4;
        desc.knot[0] = tx;
        desc.knot[1] = ty;
        desc.knot[2] = tz;
        desc.origin[0] = desc.origin[1] = -eps;
        desc.origin[2] = -0.5;
        desc.axes[0] = desc.axes[4] = 1 + 2 * eps;
        desc.axes[8] = 1;
        cm_ffd *f = NULL;
        die(cm_ffd_create(ctx, &desc, &f), "lattice");
        size_t nc = cm_ffd_control_count(f);
        double *dc = malloc(nc * 3 * sizeof *dc);
        cm_dmffd *dm = NULL;
        die(cm_dmffd_create(ctx, f, nv, x, NULL, &dm), "dmffd");
        die(cm_dmffd_solve(ctx, dm, hd, dc), "solve");
        die(cm_ffd_deform(ctx, f, dc, nv, x, d, NULL), "deform");
        cm_dmffd_info info;
        cm_dmffd_get_info(dm, &info);
        double err = 0;
        size_t worst = 0;
        for (size_t v = 0; v < nv; ++v) {
            double e = fabs(d[3 * v + 2] - hd[3 * v + 2]);
            if (e > err) {
                err = e;
                worst = v;
            }
        }
        /* the plane sees the 4 z-layers only through one fixed combination: DoF = one layer */
        size_t dof = (size_t)(sx + 3) * (sy + 3);
        printf("DM-FFD  DoF %5zu (%d x %d x 4 control points, rank %zu)  error %.4e\n", dof,
               sx + 3, sy + 3, info.rank, err / 0.2);
        fprintf(csv, "dmffd,%zu,%.6e\n", dof, err / 0.2);
        cm_dmffd_destroy(&dm);
        free(dc);
        cm_ffd_destroy(&f);
        if (dof >= nv || sx >= 250 || sy >= 250) break;
        /* refine: the spans (in x and in y) that hold the worst vertex */
        double wx = (x[3 * worst] + eps) / (1 + 2 * eps), wy = (x[3 * worst + 1] + eps) / (1 + 2 * eps);
        int kx = 0, ky = 0;
        while (kx + 1 < sx && gx[kx + 1] <= wx)
            ++kx;
        while (ky + 1 < sy && gy[ky + 1] <= wy)
            ++ky;
        memmove(gx + kx + 2, gx + kx + 1, (size_t)(sx - kx) * sizeof *gx);
        gx[kx + 1] = (gx[kx] + gx[kx + 2]) / 2;
        ++sx;
        memmove(gy + ky + 2, gy + ky + 1, (size_t)(sy - ky) * sizeof *gy);
        gy[ky + 1] = (gy[ky] + gy[ky + 2]) / 2;
        ++sy;
    }
    /* RBF, greedy (Schaback-Wendland): start from 3 corners, add the worst vertices (one at a
     * time up to 100 centres, then 10 % more per round), refit from scratch. The vertices are
     * coplanar, so the RBF is the 2D thin-plate spline (r^2 log r + linear) in (x, y): the 3D
     * triharmonic one has no unisolvent polynomial block on a plane. */
    unsigned char *is_c = calloc(nv, 1);
    size_t *cent = malloc(nv * sizeof *cent), mc = 0;
    size_t corners[3] = {0, (size_t)side - 1, nv - 1};
    for (int i = 0; i < 3; ++i) {
        cent[mc++] = corners[i];
        is_c[corners[i]] = 1;
    }
    double *c2 = malloc(nv * 2 * sizeof *c2), *val = malloc(nv * sizeof *val);
    double *p2 = malloc(nv * 2 * sizeof *p2), *out = malloc(nv * sizeof *out);
    double *e = malloc(nv * sizeof *e);
    for (size_t v = 0; v < nv; ++v) {
        p2[2 * v] = x[3 * v];
        p2[2 * v + 1] = x[3 * v + 1];
    }
    for (;;) {
        for (size_t i = 0; i < mc; ++i) {
            c2[2 * i] = p2[2 * cent[i]];
            c2[2 * i + 1] = p2[2 * cent[i] + 1];
            val[i] = hd[3 * cent[i] + 2];
        }
        cm_rbf *rbf = NULL;
        die(cm_rbf_create(ctx, CM_RBF_THIN_PLATE, 2, mc, c2, &rbf), "rbf");
        die(cm_rbf_solve(ctx, rbf, 1, val), "rbf");
        die(cm_rbf_evaluate(ctx, rbf, nv, p2, out), "rbf");
        cm_rbf_destroy(&rbf);
        double err = 0;
        for (size_t v = 0; v < nv; ++v) {
            e[v] = is_c[v] ? -1 : fabs(out[v] - hd[3 * v + 2]);
            err = fmax(err, fabs(out[v] - hd[3 * v + 2]));
        }
        printf("RBF     DoF %5zu  error %.4e\n", mc, err / 0.2);
        fprintf(csv, "rbf,%zu,%.6e\n", mc, err / 0.2);
        if (mc >= nv || err / 0.2 < 1e-9) break;
        size_t add = mc < 100 ? 1 : mc / 10;
        for (size_t a = 0; a < add && mc < nv; ++a) {
            size_t best = 0;
            for (size_t v = 1; v < nv; ++v)
                if (e[v] > e[best]) best = v;
            if (e[best] < 0) break;
            cent[mc++] = best;
            is_c[best] = 1;
            e[best] = -1;
        }
    }
    fclose(csv);
    free(x);
    free(hd);
    free(d);
    free(is_c);
    free(cent);
    free(c2);
    free(val);
    free(p2);
    free(out);
    free(e);
}

/* ---- block 6: volume morphing (Fig. 13-14) ---- */

static size_t volume_cells(const cm_mesh *m)
{
    size_t n = 0;
    for (size_t c = 0; c < m->n_cells; ++c)
        n += cm_cell_type_info(m->type[c])->dim == 3;
    return n;
}

static cm_quality_stats quality_of(cm_mesh *m, const double *xyz)
{
    double *saved = m->xyz, *sj = malloc(m->n_cells * sizeof *sj);
    m->xyz = (double *)xyz;
    die(cm_mesh_quality(ctx, m, sj), "quality");
    cm_quality_stats all;
    die(cm_quality_summarize(ctx, m, sj, NULL, &all), "quality");
    m->xyz = saved;
    free(sj);
    return all;
}

/* bench_deform volume OUTDIR TAG M0 T1:M1 T2:M2 ...: the targets M(t) are RBF-S results of
 * `cadmorph morph` (their boundary nodes are on G(t)); DM-FFD-5/10/15/25 on M0's boundary
 * nodes, factorised once (absolute), applied for every t. Two readings: "exact boundary" (the
 * warp interface: boundary nodes at their targets, interior by DM-FFD - what `--method dmffd`
 * does) and "pure" (every node by the DM-FFD map, as the paper: boundary nodes miss G(t)). */
static void block_volume(int argc, char **argv)
{
    const char *tag = argv[0];
    cm_mesh *m0 = NULL;
    die(cm_mesh_read(ctx, argv[1], &m0), argv[1]);
    cm_mesh_boundary *b = NULL;
    die(cm_mesh_boundary_create(ctx, m0, &b), "boundary");
    size_t nn = m0->n_nodes, nt = (size_t)(argc - 2), m = b->n_nodes;
    double *t = malloc(nt * sizeof *t), **target = malloc(nt * sizeof *target);
    for (size_t i = 0; i < nt; ++i) {
        const char *arg = argv[2 + i], *colon = strchr(arg, ':');
        t[i] = atof(arg);
        cm_mesh *mt = NULL;
        die(cm_mesh_read(ctx, colon + 1, &mt), colon + 1);
        if (mt->n_nodes != nn) die(cm_error(ctx, CM_ERR_MISMATCH, "node counts"), colon + 1);
        target[i] = malloc(nn * 3 * sizeof **target);
        memcpy(target[i], mt->xyz, nn * 3 * sizeof **target);
        cm_mesh_destroy(&mt);
    }
    double bb[6];
    bbox_of(nn, m0->xyz, bb);
    double diag = cm_bbox_diagonal(bb);
    char name[256];
    snprintf(name, sizeof name, "volume_%s%s%s.csv", tag, getenv("BENCH_EPS") ? "_eps" : "",
             getenv("BENCH_EPS") ? getenv("BENCH_EPS") : "");
    FILE *csv = out_csv(name);
    fprintf(csv, "mesh,method,lattice,t,min_sj,inverted,min_sj_pure,inverted_pure,"
                 "boundary_err_rel,residual_rel,t_create,t_apply,max_dc\n");
    setvbuf(stdout, NULL, _IOLBF, 0);
    printf("block 6 (volume): %s, %zu nodes, %zu boundary nodes, %zu volume cells; boundary error = "
           "max |DM-FFD(b) - G(t) target| / the diagonal %.4g\n",
           tag, nn, m, volume_cells(m0), diag);
    printf("%-9s %4s %12s %8s %12s %8s %12s %10s %9s\n", "method", "t", "min SJ", "inverted",
           "min SJ pure", "inv pure", "bnd err/diag", "residual", "create s");
    for (size_t i = 0; i < nt; ++i) {
        cm_quality_stats q = quality_of(m0, target[i]);
        printf("%-9s %4.2f %12.5f %8zu %12s %8s %12s %10s %9s\n", "rbf-s", t[i], q.min,
               q.inverted, "-", "-", "0", "0", "-");
        fprintf(csv, "%s,rbf-s,0,%g,%.6g,%zu,%.6g,%zu,0,0,0,0,0\n", tag, t[i], q.min, q.inverted,
                q.min, q.inverted);
    }
    double *h = malloc(m * 3 * sizeof *h), *hd = malloc(m * 3 * sizeof *hd);
    double *d = malloc(nn * 3 * sizeof *d), *xyz = malloc(nn * 3 * sizeof *xyz);
    for (size_t i = 0; i < m; ++i)
        memcpy(h + 3 * i, m0->xyz + 3 * b->nodes[i], 3 * sizeof *h);
    /* BENCH_LATTICES (e.g. "5,10") and BENCH_EPS (the clamping value) vary the defaults */
    int lats[8] = {5, 10, 15, 25}, nl = 4;
    const char *env = getenv("BENCH_LATTICES");
    if (env) {
        nl = 0;
        for (const char *p = env; *p && nl < 8; p = strchr(p, ',') ? strchr(p, ',') + 1 : "")
            lats[nl++] = atoi(p);
    }
    cm_dmffd_options dopt;
    cm_dmffd_options_init(&dopt);
    if (getenv("BENCH_EPS")) dopt.eps = atof(getenv("BENCH_EPS"));
    printf("clamping eps %g\n", dopt.eps);
    for (int li = 0; li < nl; ++li) {
        cm_ffd_desc desc;
        cm_ffd_desc_enclosing(&desc, bb, 1e-3, lats[li]); /* as volume/warp_dmffd.c */
        cm_ffd *f = NULL;
        die(cm_ffd_create(ctx, &desc, &f), "lattice");
        double *dc = malloc(cm_ffd_control_count(f) * 3 * sizeof *dc);
        cm_dmffd *dm = NULL;
        double t0 = cm_wtime();
        cm_status st = cm_dmffd_create(ctx, f, m, h, &dopt, &dm);
        double tc = cm_wtime() - t0;
        if (st < 0) {
            printf("dmffd-%-3d: %s\n", lats[li], cm_context_message(ctx));
            fprintf(csv, "%s,dmffd,%d,,,,,,,,%.3f,\n", tag, lats[li], tc);
            free(dc);
            cm_ffd_destroy(&f);
            continue;
        }
        for (size_t i = 0; i < nt; ++i) {
            for (size_t j = 0; j < m; ++j)
                for (int c = 0; c < 3; ++c)
                    hd[3 * j + c] = target[i][3 * b->nodes[j] + c] - h[3 * j + c];
            double t1 = cm_wtime();
            die(cm_dmffd_solve(ctx, dm, hd, dc), "solve");
            die(cm_ffd_deform(ctx, f, dc, nn, m0->xyz, d, NULL), "deform");
            double ta = cm_wtime() - t1;
            cm_dmffd_info info;
            cm_dmffd_get_info(dm, &info);
            for (size_t v = 0; v < 3 * nn; ++v)
                xyz[v] = m0->xyz[v] + d[v];
            cm_quality_stats qp = quality_of(m0, xyz);
            double berr = 0;
            for (size_t j = 0; j < m; ++j) {
                double e = 0;
                for (int c = 0; c < 3; ++c) {
                    double r = d[3 * b->nodes[j] + c] - hd[3 * j + c];
                    e += r * r;
                }
                berr = fmax(berr, sqrt(e));
            }
            for (size_t j = 0; j < m; ++j)
                memcpy(xyz + 3 * b->nodes[j], target[i] + 3 * b->nodes[j], 3 * sizeof *xyz);
            cm_quality_stats qe = quality_of(m0, xyz);
            char meth[32];
            snprintf(meth, sizeof meth, "dmffd-%d", lats[li]);
            printf("%-9s %4.2f %12.5f %8zu %12.5f %8zu %12.4e %10.3e %9.2f  max|dc| %.3g\n", meth,
                   t[i], qe.min, qe.inverted, qp.min, qp.inverted, berr / diag, info.residual, tc,
                   info.max_control);
            fprintf(csv, "%s,dmffd,%d,%g,%.6g,%zu,%.6g,%zu,%.6e,%.6e,%.3f,%.3f,%.6g\n", tag,
                    lats[li], t[i], qe.min, qe.inverted, qp.min, qp.inverted, berr / diag,
                    info.residual, tc, ta, info.max_control);
        }
        cm_dmffd_info info;
        cm_dmffd_get_info(dm, &info);
        printf("  dmffd-%d: %zu of %zu control points active, rank %zu, sigma %.3g .. %.3g\n",
               lats[li], info.active, cm_ffd_control_count(f), info.rank, info.sigma_max,
               info.sigma_min);
        cm_dmffd_destroy(&dm);
        free(dc);
        cm_ffd_destroy(&f);
    }
    fclose(csv);
    for (size_t i = 0; i < nt; ++i)
        free(target[i]);
    free(target);
    free(t);
    free(h);
    free(hd);
    free(d);
    free(xyz);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m0);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: bench_deform perf|precision|robust|smooth|adapt|all OUTDIR [threads]\n"
                        "       bench_deform volume OUTDIR TAG M0 T:MT ...\n");
        return 1;
    }
    outdir = argv[2];
    if (argc > 3 && strcmp(argv[1], "volume")) max_threads = atoi(argv[3]);
    cm_context_create(&ctx);
    int all = !strcmp(argv[1], "all");
    if (all || !strcmp(argv[1], "perf")) block_perf();
    if (all || !strcmp(argv[1], "precision")) block_precision();
    if (all || !strcmp(argv[1], "robust")) block_robust();
    if (all || !strcmp(argv[1], "smooth")) block_smooth();
    if (all || !strcmp(argv[1], "adapt")) block_adapt();
    if (!strcmp(argv[1], "volume")) {
        if (argc < 6) {
            fprintf(stderr, "usage: bench_deform volume OUTDIR TAG M0 T:MT...\n");
            return 1;
        }
        block_volume(argc - 3, argv + 3);
    }
    cm_context_destroy(&ctx);
    return 0;
}
