/* The r^3 treecode (rbf/sum/rbf_treecode.c) against direct summation on real RBF weights and on
 * random ones, on the centres of a boundary set: error relative to sum_j |w_j| phi_ij (what
 * the bound controls) and to the result (what cancellation costs), CPU time of one fast and
 * one direct product.
 * usage: bench_rbf_treecode PREFIX WEIGHTS [--threads N] [--orders n:theta,n:theta,...]
 *        [--tol T,T,...] [--isa avx512,autovec,avx2,generic] [--points FILE [--comp 0,1,2]]
 * --isa: the products' code, each in turn on the same tree (side by side in one run; autovec
 * is the compiled loop the treecode had before the hand-written block); default the
 * library's choice. --points: with the weights cache, evaluate at FILE (n x 3 raw float64 in
 * the coordinates of PREFIX.centres, e.g. PREFIX.interior) and check 2,048 of them against
 * compensated sums, the error relative to max |PREFIX.values| (what fast_eval_tol bounds);
 * --comp: the rounding levels of cm_rbf_tree_set_compensated, each in turn.
 * PREFIX.centres / .values as for bench_rbf_iterative; WEIGHTS: a cache of the solved
 * weights (written by the first run, read afterwards). One key=value line per setting. */
#include "blas_reexec.h"
#include "cadmorph/rbf.h"
#include "rbf_internal.h"
#include "sum/rbf_treecode.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "bench_util.h"

static const struct { const char *name; cm_rbf_isa isa; } isa_names[] = {
    {"auto", CM_RBF_ISA_AUTO}, {"avx512", CM_RBF_ISA_AVX512},
    {"autovec", CM_RBF_ISA_AVX512_AUTOVEC}, {"avx2", CM_RBF_ISA_AVX2},
    {"generic", CM_RBF_ISA_GENERIC}};

/* "a,b,c" -> up to 8 ISAs; 0 on an unknown or unsupported name */
static int parse_isas(const char *list, cm_rbf_isa *isa, const char **name)
{
    char buf[256];
    int k = 0;
    snprintf(buf, sizeof buf, "%s", list ? list : "auto");
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok && k < 8;
         tok = strtok_r(NULL, ",", &save)) {
        int found = 0;
        for (size_t i = 0; i < sizeof isa_names / sizeof isa_names[0]; ++i)
            if (!strcmp(tok, isa_names[i].name) && cm_rbf_isa_supported(isa_names[i].isa)) {
                isa[k] = isa_names[i].isa;
                name[k++] = isa_names[i].name;
                found = 1;
            }
        if (!found) {
            fprintf(stderr, "isa %s unknown or not supported here\n", tok);
            return 0;
        }
    }
    return k;
}



/* err_i / S_i (max over i), max err / max S, max err / max |exact| */
static void compare(size_t m, const double *fast, const double *ex, const double *S,
                    double *rel_s, double *rel_smax, double *rel_res)
{
    double e_s = 0.0, emax = 0.0, smax = 0.0, rmax = 0.0;
    for (size_t i = 0; i < 3 * m; ++i) {
        double e = fabs(fast[i] - ex[i]);
        if (S[i] > 0.0) e_s = fmax(e_s, e / S[i]);
        emax = fmax(emax, e);
        smax = fmax(smax, S[i]);
        rmax = fmax(rmax, fabs(ex[i]));
    }
    *rel_s = e_s;
    *rel_smax = emax / smax;
    *rel_res = emax / rmax;
}

/* WEIGHTS "-": random weights on the centres of PREFIX, for sets too large to solve or to
 * sum directly in full: the direct products are timed on 20,000 of the targets and scaled
 * to m, the error is the sampled check (512 targets against compensated sums). */
static int random_only(const char *prefix, const char *orders, const char *tols, int threads,
                       const char *isas)
{
    cm_rbf_isa isa[8];
    const char *iname[8];
    const int nisa = parse_isas(isas, isa, iname);
    if (!nisa) return 1;
    char path[4096];
    size_t bytes = 0;
    snprintf(path, sizeof path, "%s.centres", prefix);
    double *x = bench_read_raw(path, &bytes);
    if (!x) return 1;
    const size_t m = bytes / 24;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, ext = 0.0;
    for (size_t i = 0; i < m; ++i)
        for (int d = 0; d < 3; ++d) lo[d] = fmin(lo[d], x[3 * i + d]);
    for (size_t i = 0; i < m; ++i)
        for (int d = 0; d < 3; ++d) ext = fmax(ext, x[3 * i + d] - lo[d]);
    double *c = malloc(3 * m * sizeof *c), *w = malloc(3 * m * sizeof *w);
    double *out = malloc(3 * m * sizeof *out);
    for (size_t i = 0; i < m; ++i)
        for (int d = 0; d < 3; ++d) c[(size_t)d * m + i] = (x[3 * i + d] - lo[d]) / ext;
    unsigned long long s = 12345;
    for (size_t i = 0; i < 3 * m; ++i) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        w[i] = (double)(s >> 11) / 9007199254740992.0 * 2.0 - 1.0;
    }
    const size_t ns = m < 20000 ? m : 20000;
    double *sp = malloc(3 * ns * sizeof *sp), *so = malloc(3 * ns * sizeof *so);
    for (size_t k = 0; k < ns; ++k)
        for (int d = 0; d < 3; ++d) sp[(size_t)d * ns + k] = c[(size_t)d * m + k * (m / ns)];
    double c0 = bench_cpu_seconds();
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, w, 3, ns, sp, ns, so, 3, threads);
    const double direct = (bench_cpu_seconds() - c0) * (double)m / (double)ns;
    c0 = bench_cpu_seconds();
    cm_rbf_kernel_sum_acc(m, c, w, 3, ns, sp, ns, so, 3, threads);
    const double acc = (bench_cpu_seconds() - c0) * (double)m / (double)ns;
    printf("set=%s m=%zu threads=%d random weights: direct_cpu_s=%.1f compensated_cpu_s=%.1f "
           "(scaled from %zu targets; %.3g pairs per CPU-s plain, 3 components)\n", prefix, m,
           threads, direct, acc, ns, (double)m * (double)m / direct);
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", tols ? tols : orders);
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        int n;
        double th, tol = 0.0;
        if (tols) {
            tol = atof(tok);
            cm_rbf_tree_params(tol, &n, &th);
        } else if (sscanf(tok, "%d:%lf", &n, &th) != 2) continue;
        c0 = bench_cpu_seconds();
        cm_rbf_tree *t = cm_rbf_tree_create(m, c, n, th);
        double build = bench_cpu_seconds() - c0;
        if (!t) return 1;
        for (int k = 0; k < nisa; ++k) {
            cm_rbf_tree_set_isa(t, isa[k]);
            c0 = bench_cpu_seconds();
            double w0 = cm_wtime();
            cm_rbf_tree_sum_self(t, w, 3, out, 3, threads);
            double fast = bench_cpu_seconds() - c0, fast_wall = cm_wtime() - w0;
            double e, sabs;
            cm_rbf_tree_check(t, w, 3, m, c, m, out, 3, 512, NULL, &e, &sabs, threads);
            printf("tol=%.0e order=%d theta=%.2f isa=%s build_cpu_s=%.2f fast_cpu_s=%.2f "
                   "fast_wall_s=%.2f speedup=%.1f speedup_vs_compensated=%.1f "
                   "sampled_err_Smax=%.3g tree_mb=%.1f\n",
                   tol, n, th, iname[k], build, fast, fast_wall, direct / fast, acc / fast,
                   e / sabs, (double)cm_rbf_tree_bytes(t) / 1e6);
            fflush(stdout);
        }
        cm_rbf_tree_destroy(&t);
    }
    free(x), free(c), free(w), free(out), free(sp), free(so);
    return 0;
}

/* --points: the real weights evaluated at the points of a file, as the iterative solver's
 * evaluation does (cm_rbf_tree_sum, then a sampled check), per setting and ISA: CPU s, the
 * sampled error relative to max |data| and to the sampled sum |w| phi, against the CPU s of
 * compensated direct sums (timed on 20,000 of the points, scaled). */
static int at_points(const char *prefix, const char *file, size_t m, const double *c,
                     const double *w, const char *orders, const char *tols, int threads,
                     const char *isas, const char *comps)
{
    int comp[3], ncomp = 0;
    char cb[64];
    snprintf(cb, sizeof cb, "%s", comps ? comps : "0");
    for (char *save = NULL, *tok = strtok_r(cb, ",", &save); tok && ncomp < 3;
         tok = strtok_r(NULL, ",", &save))
        comp[ncomp++] = atoi(tok);
    cm_rbf_isa isa[8];
    const char *iname[8];
    const int nisa = parse_isas(isas, isa, iname);
    if (!nisa) return 1;
    char path[4096];
    size_t bytes = 0;
    snprintf(path, sizeof path, "%s.centres", prefix);
    double *x = bench_read_raw(path, &bytes);
    const size_t mx = bytes / 24;
    snprintf(path, sizeof path, "%s.values", prefix);
    double *v = bench_read_raw(path, &bytes);
    double *pr = bench_read_raw(file, &bytes);
    const size_t n = bytes / 24;
    if (!x || !v || !pr || n == 0) {
        fprintf(stderr, "cannot read %s.centres / .values or %s\n", prefix, file);
        return 1;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double ext = 0.0, dmax = 0.0;
    for (size_t i = 0; i < mx; ++i)
        for (int d = 0; d < 3; ++d) {
            lo[d] = fmin(lo[d], x[3 * i + d]);
            hi[d] = fmax(hi[d], x[3 * i + d]);
            dmax = fmax(dmax, fabs(v[3 * i + d]));
        }
    for (int d = 0; d < 3; ++d) ext = fmax(ext, hi[d] - lo[d]);
    double *p = malloc(3 * n * sizeof *p), *out = malloc(3 * n * sizeof *out);
    for (size_t i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) p[(size_t)d * n + i] = (pr[3 * i + d] - lo[d]) / ext;
    const size_t ns = n < 20000 ? n : 20000;
    double *sp = malloc(3 * ns * sizeof *sp), *so = malloc(3 * ns * sizeof *so);
    for (size_t k = 0; k < ns; ++k)
        for (int d = 0; d < 3; ++d) sp[(size_t)d * ns + k] = p[(size_t)d * n + k * (n / ns)];
    double c0 = bench_cpu_seconds();
    cm_rbf_kernel_sum_acc(m, c, w, 3, ns, sp, ns, so, 3, threads);
    const double acc = (bench_cpu_seconds() - c0) * (double)n / (double)ns;
    c0 = bench_cpu_seconds();
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, w, 3, ns, sp, ns, so, 3, threads);
    const double direct = (bench_cpu_seconds() - c0) * (double)n / (double)ns;
    /* a third reference at the check's samples: every entry in long double (64-bit
     * mantissa), summed by TwoSum in long double, to see how far the compensated double sums (whose entries phi_ij
     * are rounded doubles) are from the exact sum of these weights */
    const size_t nsr = 2048 < n ? 2048 : n;
    long double *ld = malloc(3 * nsr * sizeof *ld);
    double *sx = malloc(3 * nsr * sizeof *sx), *sa = malloc(3 * nsr * sizeof *sa);
    for (size_t k = 0; k < nsr; ++k) {
        const size_t i = (size_t)((double)k * (double)n / (double)nsr);
        long double a[3] = {0, 0, 0}, ae[3] = {0, 0, 0};
        for (size_t j = 0; j < m; ++j) {
            long double dx = (long double)p[i] - c[j], dy = (long double)p[n + i] - c[m + j];
            long double dz = (long double)p[2 * n + i] - c[2 * m + j];
            long double r2 = dx * dx + dy * dy + dz * dz, f = r2 * sqrtl(r2);
            for (int q = 0; q < 3; ++q) { /* TwoSum in long double: the sum's rounding out too */
                long double t = f * w[(size_t)q * m + j], s1 = a[q] + t, bv = s1 - a[q];
                ae[q] += (a[q] - (s1 - bv)) + (t - bv);
                a[q] = s1;
            }
        }
        for (int q = 0; q < 3; ++q) ld[3 * k + (size_t)q] = a[q] + ae[q];
        for (int d = 0; d < 3; ++d) sx[(size_t)d * nsr + k] = p[(size_t)d * n + i];
    }
    cm_rbf_kernel_sum_acc(m, c, w, 3, nsr, sx, nsr, sa, 3, threads);
    double acc_ld = 0.0;
    for (size_t k = 0; k < 3 * nsr; ++k) acc_ld = fmax(acc_ld, fabs((double)(sa[k] - ld[k])));
    printf("reference check at %zu points: max |compensated - long double| / max|data| = %.3g\n",
           nsr, acc_ld / dmax);
    printf("set=%s m=%zu points=%s n=%zu threads=%d max_data=%.6g: direct_cpu_s=%.1f "
           "compensated_cpu_s=%.1f (scaled from %zu points)\n", prefix, m, file, n, threads,
           dmax, direct, acc, ns);
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", tols ? tols : orders);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int order;
        double th, tol = 0.0;
        if (tols) {
            tol = atof(tok);
            cm_rbf_tree_params(tol, &order, &th);
        } else if (sscanf(tok, "%d:%lf", &order, &th) != 2) continue;
        cm_rbf_tree *t = cm_rbf_tree_create(m, c, order, th);
        if (!t) return 1;
        for (int k = 0; k < nisa * ncomp; ++k) {
            cm_rbf_tree_set_isa(t, isa[k / ncomp]);
            cm_rbf_tree_set_compensated(t, comp[k % ncomp]);
            c0 = bench_cpu_seconds();
            if (cm_rbf_tree_sum(t, w, 3, n, p, n, out, 3, threads)) return 1;
            const double fast = bench_cpu_seconds() - c0;
            double e, sabs;
            cm_rbf_tree_check(t, w, 3, n, p, n, out, 3, 2048, NULL, &e, &sabs, threads);
            double eld = 0.0;
            for (size_t kk = 0; kk < nsr; ++kk) {
                const size_t i = (size_t)((double)kk * (double)n / (double)nsr);
                for (int q = 0; q < 3; ++q)
                    eld = fmax(eld, fabs((double)(out[3 * i + (size_t)q] - ld[3 * kk + (size_t)q])));
            }
            printf("order=%d theta=%.2f isa=%s comp=%d fast_cpu_s=%.2f x_plain=%.2f "
                   "x_compensated=%.2f sampled_err_data=%.3g sampled_err_Smax=%.3g "
                   "Smax_data=%.3g err_vs_long_double_data=%.3g\n", order, th, iname[k / ncomp],
                   comp[k % ncomp], fast, direct / fast, acc / fast, e / dmax, e / sabs,
                   sabs / dmax, eld / dmax);
            fflush(stdout);
        }
        cm_rbf_tree_destroy(&t);
    }
    free(x), free(v), free(pr), free(p), free(out), free(sp), free(so), free(ld), free(sx);
    free(sa);
    return 0;
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv); /* the right OpenBLAS core, as cadmorph */
    if (argc < 3) {
        fprintf(stderr, "usage: bench_rbf_treecode PREFIX WEIGHTS [options], see the source\n");
        return 1;
    }
    const char *prefix = argv[1], *wpath = argv[2];
    int threads = 2;
    const char *orders = "4:0.5,6:0.5,8:0.5,10:0.5,12:0.5,8:0.4,10:0.4,12:0.4,14:0.4";
    const char *tols = NULL, *isas = NULL, *points = NULL, *comps = NULL;
    for (int i = 3; i < argc; ++i) {
        const char *a = argv[i], *b = i + 1 < argc ? argv[i + 1] : "";
        if (!strcmp(a, "--threads")) threads = atoi(b), ++i;
        else if (!strcmp(a, "--orders")) orders = b, ++i;
        else if (!strcmp(a, "--tol")) tols = b, ++i;
        else if (!strcmp(a, "--isa")) isas = b, ++i;
        else if (!strcmp(a, "--points")) points = b, ++i;
        else if (!strcmp(a, "--comp")) comps = b, ++i;
        else {
            fprintf(stderr, "unknown option %s\n", a);
            return 1;
        }
    }
    size_t bytes = 0, m = 0;
    if (!strcmp(wpath, "-")) return random_only(prefix, orders, tols, threads, isas);
    double *cw = bench_read_raw(wpath, &bytes); /* 3 x m unit-box centres, then 3 x m weights */
    if (cw) {
        m = bytes / (6 * sizeof(double));
    } else {
        char path[4096];
        snprintf(path, sizeof path, "%s.centres", prefix);
        double *x = bench_read_raw(path, &bytes);
        size_t mx = bytes / 24;
        snprintf(path, sizeof path, "%s.values", prefix);
        double *v = bench_read_raw(path, &bytes);
        if (!x || !v || bytes / 24 != mx) {
            fprintf(stderr, "cannot read %s.centres / .values\n", prefix);
            return 1;
        }
        cm_context *ctx = NULL;
        cm_context_create(&ctx);
        cm_context_set_threads(ctx, threads);
        cm_rbf_options o;
        cm_rbf_options_init(&o);
        o.solver = CM_RBF_SOLVER_ITERATIVE;
        cm_rbf *r = NULL;
        cm_status st = cm_rbf_create_opt(ctx, CM_RBF_TRIHARMONIC, 3, mx, x, &o, &r);
        if (st >= 0) st = cm_rbf_solve(ctx, r, 3, v);
        if (st < 0) {
            fprintf(stderr, "fit: %s\n", cm_context_message(ctx));
            return 1;
        }
        m = r->m;
        cw = malloc(6 * m * sizeof *cw);
        memcpy(cw, r->c, 3 * m * sizeof *cw);
        memcpy(cw + 3 * m, r->w, 3 * m * sizeof *cw);
        FILE *f = fopen(wpath, "wb");
        if (f) fwrite(cw, sizeof *cw, 6 * m, f), fclose(f);
        cm_rbf_destroy(&r);
        cm_context_destroy(&ctx);
        free(x), free(v);
    }
    const double *c = cw, *wreal = cw + 3 * m;
    if (points) return at_points(prefix, points, m, c, wreal, orders, tols, threads, isas, comps);
    double *wrand = malloc(3 * m * sizeof *wrand), *aw = malloc(3 * m * sizeof *aw);
    unsigned long long s = 12345;
    for (size_t i = 0; i < 3 * m; ++i) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        wrand[i] = (double)(s >> 11) / 9007199254740992.0 * 2.0 - 1.0;
    }
    /* exact products (compensated) and the scales sum |w| phi, for both weight sets */
    double *ex[2], *S[2], *fast = malloc(3 * m * sizeof *fast);
    const double *ws[2] = {wreal, wrand};
    double direct_cpu = 0.0, acc_cpu = 0.0;
    for (int k = 0; k < 2; ++k) {
        ex[k] = malloc(3 * m * sizeof(double));
        S[k] = malloc(3 * m * sizeof(double));
        double c0 = bench_cpu_seconds();
        cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, ws[k], 3, m, c, m, fast, 3, threads);
        if (k == 0) direct_cpu = bench_cpu_seconds() - c0;
        c0 = bench_cpu_seconds();
        cm_rbf_kernel_sum_acc(m, c, ws[k], 3, m, c, m, ex[k], 3, threads);
        if (k == 0) acc_cpu = bench_cpu_seconds() - c0;
        for (size_t i = 0; i < 3 * m; ++i) aw[i] = fabs(ws[k][i]);
        cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, aw, 3, m, c, m, S[k], 3, threads);
    }
    double kappa = 0.0, smax = 0.0, rmax = 0.0;
    for (size_t i = 0; i < 3 * m; ++i) smax = fmax(smax, S[0][i]), rmax = fmax(rmax, fabs(ex[0][i]));
    kappa = smax / rmax;
    /* plain direct sums against compensated ones: the rounding floor, of the symmetric self
     * product (targets = the centres) and of the general block (the same targets as a copy,
     * which the kernel sums cannot tell are the centres) */
    double rel_s, pr_smax, pr_res, pg_smax, pg_res; /* rel_s (per target): not printed */
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, wreal, 3, m, c, m, fast, 3, threads);
    compare(m, fast, ex[0], S[0], &rel_s, &pr_smax, &pr_res);
    double *ccopy = malloc(3 * m * sizeof *ccopy);
    if (!ccopy) {
        fprintf(stderr, "out of memory for a copy of the %zu centres\n", m);
        return 1;
    }
    memcpy(ccopy, c, 3 * m * sizeof *ccopy);
    cm_rbf_kernel_sum(CM_RBF_TRIHARMONIC, 3, m, c, wreal, 3, m, ccopy, m, fast, 3, threads);
    compare(m, fast, ex[0], S[0], &rel_s, &pg_smax, &pg_res);
    free(ccopy);
    printf("set=%s m=%zu threads=%d direct_cpu_s=%.3f compensated_cpu_s=%.3f cancellation=%.3g "
           "plain_err_rel_S=%.3g plain_err_rel_result=%.3g plain_general_err_rel_S=%.3g "
           "plain_general_err_rel_result=%.3g\n", prefix, m, threads, direct_cpu, acc_cpu,
           kappa, pr_smax, pr_res, pg_smax, pg_res);
    /* settings: explicit n:theta pairs, or tolerances through cm_rbf_tree_params */
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", tols ? tols : orders);
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        int n;
        double th, tol = 0.0;
        if (tols) {
            tol = atof(tok);
            cm_rbf_tree_params(tol, &n, &th);
        } else if (sscanf(tok, "%d:%lf", &n, &th) != 2) continue;
        double c0 = bench_cpu_seconds();
        cm_rbf_tree *t = cm_rbf_tree_create(m, c, n, th);
        double build = bench_cpu_seconds() - c0;
        if (!t) return 1;
        double res[2][3], tcpu[2];
        for (int k = 0; k < 2; ++k) {
            c0 = bench_cpu_seconds();
            cm_rbf_tree_sum_self(t, ws[k], 3, fast, 3, threads);
            tcpu[k] = bench_cpu_seconds() - c0;
            compare(m, fast, ex[k], S[k], &res[k][0], &res[k][1], &res[k][2]);
        }
        double est_err, est_s;
        double true_max = 0.0;
        cm_rbf_tree_sum_self(t, wreal, 3, fast, 3, threads);
        cm_rbf_tree_check(t, wreal, 3, m, c, m, fast, 3, 256, NULL, &est_err, &est_s, threads);
        (void)est_s;
        for (size_t i = 0; i < 3 * m; ++i) true_max = fmax(true_max, fabs(fast[i] - ex[0][i]));
        printf("tol=%.0e order=%d theta=%.2f build_cpu_s=%.3f fast_cpu_s=%.3f speedup=%.2f "
               "speedup_vs_compensated=%.2f rand_err_S=%.3g rand_errmax_Smax=%.3g rand_err_result=%.3g "
               "real_err_S=%.3g real_errmax_Smax=%.3g real_err_result=%.3g digits_lost=%.2f "
               "sample_est/true=%.3g tree_mb=%.1f\n",
               tol, n, th, build, tcpu[0], direct_cpu / tcpu[0], acc_cpu / tcpu[0], res[1][0], res[1][1],
               res[1][2], res[0][0], res[0][1], res[0][2],
               log10(res[0][2] / res[1][2]), est_err / true_max,
               (double)cm_rbf_tree_bytes(t) / 1e6);
        fflush(stdout);
        cm_rbf_tree_destroy(&t);
    }
    return 0;
}
