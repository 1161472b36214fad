/* The instruction-set variants of the kernel sums (rbf/sum/rbf_sum.c, rbf_sum_acc.c, the hand-written
 * AVX-512 blocks of rbf_sum_avx512.c) against the generic code and a long-double reference:
 * plain sums within 64 eps sum_j |w_j phi_ij| of the generic ones; compensated sums within
 * 4 eps |ref| (+ 1e-18 sum |w phi|) of the reference on a cancelling set (dipoles of large
 * opposite weights), where a plain sum is off by far more; sizes off every block and vector
 * width (tails); points on centres (phi = 0, the rsqrt seed); 1 and 2 threads identical.
 * Coordinates are multiples of 2^-10, so r^2 is exact and phi_ij is the same double in every
 * variant: the comparison measures the summation alone. Both vsqrtpd splits of the AVX-512
 * blocks give the same bits (off the grid too). */
#include "rbf_internal.h"
#include "sum/rbf_sum_isa.h"
#include "test_rng.h"
#include "test_util.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

static double grid(uint64_t *s) { return floor(test_rng_uniform(s) * 1024.0) / 1024.0; }

/* phi rounded as every variant rounds it (r2 exact here) */
static double phi_r3(double r2) { return r2 * sqrt(r2); }

typedef struct set {
    size_t m, n;
    double *c, *w, *p;          /* 3 x m, 4 x m, 3 x n SoA */
    long double *ref;           /* n x 4 */
    double *sum_abs, *max_abs;  /* n x 4 */
} set;

static void fill_ref(set *s);

static void make_set(set *s, size_t m, size_t n, int dipoles, uint64_t seed)
{
    s->m = m, s->n = n;
    s->c = malloc(3 * m * sizeof *s->c), s->w = malloc(4 * m * sizeof *s->w);
    s->p = malloc(3 * n * sizeof *s->p), s->ref = malloc(4 * n * sizeof *s->ref);
    s->sum_abs = malloc(4 * n * sizeof *s->sum_abs), s->max_abs = malloc(4 * n * sizeof *s->max_abs);
    uint64_t st = seed;
    for (size_t j = 0; j < m; ++j) {
        const int partner = dipoles && j % 2 == 1;
        for (int d = 0; d < 3; ++d)
            s->c[d * m + j] = partner ? s->c[d * m + j - 1] + (d == 0 ? 1.0 / 1024.0 : 0.0)
                                      : grid(&st);
        for (int q = 0; q < 4; ++q)
            s->w[q * m + j] = partner ? -s->w[q * m + j - 1] + test_rng_range(&st, -0.01, 0.01)
                                      : (dipoles ? 1e8 : 1.0) * test_rng_range(&st, -1.0, 1.0);
    }
    for (size_t i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) /* every third point on a centre: phi = 0 there */
            s->p[d * n + i] = i % 3 == 0 ? s->c[d * m + (i * 7) % m] : grid(&st);
    fill_ref(s);
}

/* the long-double sums at the points and the scales of the tolerances */
static void fill_ref(set *s)
{
    const size_t m = s->m, n = s->n;
    for (size_t i = 0; i < n; ++i)
        for (int q = 0; q < 4; ++q) {
            long double acc = 0.0L;
            double sa = 0.0, mx = 0.0;
            for (size_t j = 0; j < m; ++j) {
                double r2 = 0.0;
                for (int d = 0; d < 3; ++d) {
                    double dd = s->p[d * n + i] - s->c[d * m + j];
                    r2 += dd * dd;
                }
                const double f = phi_r3(r2), t = fabs(f * s->w[q * m + j]);
                acc += (long double)f * s->w[q * m + j];
                sa += t, mx = fmax(mx, t);
            }
            s->ref[i * 4 + q] = acc, s->sum_abs[i * 4 + q] = sa, s->max_abs[i * 4 + q] = mx;
        }
}

static void free_set(set *s)
{
    free(s->c), free(s->w), free(s->p), free(s->ref), free(s->sum_abs), free(s->max_abs);
}

/* max over points and components of |a - b| / scale_i, scale from the set */
static double worst(const set *s, int nc, const double *a, const double *b, int use_ref)
{
    double e = 0.0;
    for (size_t i = 0; i < s->n; ++i)
        for (int q = 0; q < nc; ++q) {
            const double x = a[i * (size_t)nc + (size_t)q];
            if (use_ref) {
                const long double r = s->ref[i * 4 + q];
                const double tol = 4.0 * DBL_EPSILON * (double)fabsl(r) +
                                   1e-18 * s->sum_abs[i * 4 + q] + 1e-300;
                e = fmax(e, (double)fabsl((long double)x - r) / tol);
            } else {
                const double tol = 64.0 * DBL_EPSILON * s->sum_abs[i * 4 + q] + 1e-300;
                e = fmax(e, fabs(x - b[i * (size_t)nc + (size_t)q]) / tol);
            }
        }
    return e; /* <= 1 passes */
}

int main(void)
{
    static const size_t ms[] = {1, 7, 9, 33, 517, 1500}, ns[] = {1, 5, 63, 65, 130, 301};
    static const cm_rbf_isa isas[] = {CM_RBF_ISA_AVX2, CM_RBF_ISA_AVX512_AUTOVEC, CM_RBF_ISA_AVX512};
    int tried_avx512 = 0;
    double plain_cancel_err = 0.0; /* the plain sum on the dipoles, in the compensated tolerance */
    for (int dip = 0; dip < 2; ++dip)
        for (size_t a = 0; a < sizeof ms / sizeof ms[0]; ++a) {
            const size_t m = ms[a] < 2 && dip ? 2 : ms[a], n = ns[a];
            set s;
            make_set(&s, m, n, dip, 1000 + 10 * a + (size_t)dip);
            double *g = malloc(4 * n * sizeof *g), *o = malloc(4 * n * sizeof *o);
            double *o2 = malloc(4 * n * sizeof *o2);
            for (int nc = 1; nc <= 4; ++nc) {
                cm_rbf_kernel_sum_isa(CM_RBF_ISA_GENERIC, CM_RBF_TRIHARMONIC, 3, m, s.c, s.w, nc,
                                      n, s.p, n, g, (size_t)nc, 1);
                if (dip) plain_cancel_err = fmax(plain_cancel_err, worst(&s, nc, g, NULL, 1));
                cm_rbf_kernel_sum_acc_isa(CM_RBF_ISA_GENERIC, m, s.c, s.w, nc, n, s.p, n, o,
                                          (size_t)nc, 1);
                double e = worst(&s, nc, o, NULL, 1);
                CHECK_MSG(e <= 1.0, "generic compensated m=%zu n=%zu nc=%d dip=%d: %.3g", m, n,
                          nc, dip, e);
                for (size_t k = 0; k < sizeof isas / sizeof isas[0]; ++k) {
                    if (!cm_rbf_isa_supported(isas[k])) continue;
                    tried_avx512 |= isas[k] == CM_RBF_ISA_AVX512;
                    cm_rbf_kernel_sum_isa(isas[k], CM_RBF_TRIHARMONIC, 3, m, s.c, s.w, nc, n, s.p,
                                          n, o, (size_t)nc, 1);
                    e = worst(&s, nc, o, g, 0);
                    CHECK_MSG(e <= 1.0, "plain isa=%d m=%zu n=%zu nc=%d dip=%d: %.3g", (int)isas[k],
                              m, n, nc, dip, e);
                    /* thread count: the same order of summation per point, so bit for bit */
                    cm_rbf_kernel_sum_isa(isas[k], CM_RBF_TRIHARMONIC, 3, m, s.c, s.w, nc, n, s.p,
                                          n, o2, (size_t)nc, 2);
                    CHECK(memcmp(o, o2, (size_t)nc * n * sizeof *o) == 0);
                    cm_rbf_kernel_sum_acc_isa(isas[k], m, s.c, s.w, nc, n, s.p, n, o, (size_t)nc,
                                              1);
                    e = worst(&s, nc, o, NULL, 1);
                    CHECK_MSG(e <= 1.0, "compensated isa=%d m=%zu n=%zu nc=%d dip=%d: %.3g",
                              (int)isas[k], m, n, nc, dip, e);
                    cm_rbf_kernel_sum_acc_isa(isas[k], m, s.c, s.w, nc, n, s.p, n, o2, (size_t)nc,
                                              2);
                    CHECK(memcmp(o, o2, (size_t)nc * n * sizeof *o) == 0);
                }
            }
            free(g), free(o), free(o2);
            free_set(&s);
        }
    /* the compensated tolerance must be one a plain sum misses on the dipoles, or the checks
     * above would not tell compensation from none */
    printf("plain sum on the dipole sets: %.3g x the compensated tolerance\n", plain_cancel_err);
    CHECK(plain_cancel_err > 10.0);

    /* the other kernels through the AVX-512 entry (compiled loops there) match generic */
    if (cm_rbf_isa_supported(CM_RBF_ISA_AVX512)) {
        set s;
        make_set(&s, 300, 70, 0, 77);
        double g[4 * 70], o[4 * 70];
        for (int kern = CM_RBF_BIHARMONIC; kern <= CM_RBF_THIN_PLATE; ++kern) {
            const int dim = kern == CM_RBF_THIN_PLATE ? 2 : 3;
            cm_rbf_kernel_sum_isa(CM_RBF_ISA_GENERIC, (cm_rbf_kernel)kern, dim, 300, s.c, s.w, 3,
                                  70, s.p, 70, g, 3, 1);
            cm_rbf_kernel_sum_isa(CM_RBF_ISA_AVX512, (cm_rbf_kernel)kern, dim, 300, s.c, s.w, 3,
                                  70, s.p, 70, o, 3, 1);
            double e = 0.0, scale = 0.0;
            for (int i = 0; i < 3 * 70; ++i) e = fmax(e, fabs(o[i] - g[i])), scale = fmax(scale, fabs(g[i]));
            CHECK_MSG(e <= 1e-12 * scale, "kernel %d: %.3g of %.3g", kern, e, scale);
        }
        free_set(&s);
    }
    /* The vsqrtpd split of the AVX-512 blocks (chosen by timing, rbf_sum_isa.h) changes which
     * unit computes each sqrt, never the result: the FMA sequence is correctly rounded. So
     * both splits give the same bits, here on coordinates off the grid (r^2 not exact). */
    if (cm_rbf_isa_supported(CM_RBF_ISA_AVX512)) {
        enum { M = 1500, N = 301, NC = 3 };
        double *c = malloc(3 * M * sizeof *c), *w = malloc(NC * M * sizeof *w);
        double *p = malloc(3 * N * sizeof *p), *o[2][2];
        uint64_t st = 4242;
        for (int i = 0; i < 3 * M; ++i) c[i] = test_rng_uniform(&st);
        for (int i = 0; i < NC * M; ++i) w[i] = 2.0 * test_rng_uniform(&st) - 1.0;
        for (int i = 0; i < 3 * N; ++i) p[i] = test_rng_uniform(&st);
        static const int split[2][2] = {{3, 2}, {2, 1}};
        for (int k = 0; k < 2; ++k) {
            CHECK(cm_rbf_sqrt_split_force(split[k][0], split[k][1]) == 0);
            o[k][0] = malloc(NC * N * sizeof(double)), o[k][1] = malloc(NC * N * sizeof(double));
            cm_rbf_kernel_sum_isa(CM_RBF_ISA_AVX512, CM_RBF_TRIHARMONIC, 3, M, c, w, NC, N, p, N,
                                  o[k][0], NC, 2);
            cm_rbf_kernel_sum_acc_isa(CM_RBF_ISA_AVX512, M, c, w, NC, N, p, N, o[k][1], NC, 2);
        }
        CHECK(cm_rbf_sqrt_split_force(4, 2) == -1); /* not a candidate */
        CHECK(cm_rbf_sqrt_split_force(0, 0) == 0);
        int pl = 0, ac = 0;
        cm_rbf_sqrt_split(&pl, &ac);
        printf("probed sqrt split here: plain %d of 4, compensated %d of 2 through vsqrtpd\n", pl,
               ac);
        CHECK((pl == 3 || pl == 2) && (ac == 2 || ac == 1));
        CHECK(memcmp(o[0][0], o[1][0], NC * N * sizeof(double)) == 0);
        CHECK(memcmp(o[0][1], o[1][1], NC * N * sizeof(double)) == 0);
        for (int k = 0; k < 2; ++k) free(o[k][0]), free(o[k][1]);
        free(c), free(w), free(p);
    }
    /* The self product (targets = the centres: the Krylov products) computes each entry once
     * for both rows (rbf_sum_self_avx512.c), from CM_RBF_SELF_MIN_M centres on. Sizes off its
     * tile (256) and group (8), dipoles and plain weights, 1 and 2 threads: compensated
     * within the compensated tolerance of the reference (and reported: the same bits as the
     * general block on a copy of the centres, which takes the other path); plain within the
     * plain tolerance of the generic sums. */
    if (cm_rbf_isa_supported(CM_RBF_ISA_AVX512)) {
        static const size_t sm[] = {CM_RBF_SELF_MIN_M, 1283, 2600};
        int same_bits = 1;
        for (int dip = 0; dip < 2; ++dip)
            for (size_t a = 0; a < sizeof sm / sizeof sm[0]; ++a) {
                const size_t m = sm[a];
                set s;
                make_set(&s, m, m, dip, 2000 + 10 * a + (size_t)dip);
                memcpy(s.p, s.c, 3 * m * sizeof *s.c);
                fill_ref(&s);
                double *o = malloc(4 * m * sizeof *o), *gc = malloc(4 * m * sizeof *gc);
                double *gp = malloc(4 * m * sizeof *gp);
                for (int nc = 1; nc <= 4; nc += 1 + (a == 0)) {
                    /* the general compensated block (s.p: a copy), the generic plain sums */
                    cm_rbf_kernel_sum_acc_isa(CM_RBF_ISA_AVX512, m, s.c, s.w, nc, m, s.p, m, gc,
                                              (size_t)nc, 1);
                    cm_rbf_kernel_sum_isa(CM_RBF_ISA_GENERIC, CM_RBF_TRIHARMONIC, 3, m, s.c, s.w,
                                          nc, m, s.p, m, gp, (size_t)nc, 1);
                    for (int th = 1; th <= 2; ++th) {
                        cm_rbf_kernel_sum_acc_isa(CM_RBF_ISA_AVX512, m, s.c, s.w, nc, m, s.c, m,
                                                  o, (size_t)nc, th);
                        const double e = worst(&s, nc, o, NULL, 1);
                        CHECK_MSG(e <= 1.0, "self product m=%zu nc=%d dip=%d threads %d: %.3g",
                                  m, nc, dip, th, e);
                        same_bits &= memcmp(o, gc, (size_t)nc * m * sizeof *o) == 0;
                        cm_rbf_kernel_sum_isa(CM_RBF_ISA_AVX512, CM_RBF_TRIHARMONIC, 3, m, s.c,
                                              s.w, nc, m, s.c, m, o, (size_t)nc, th);
                        const double ep = worst(&s, nc, o, gp, 0);
                        CHECK_MSG(ep <= 1.0, "plain self product m=%zu nc=%d dip=%d threads %d: "
                                  "%.3g", m, nc, dip, th, ep);
                    }
                }
                free(o), free(gc), free(gp);
                free_set(&s);
            }
        printf("self product %s the general block's bits\n", same_bits ? "equal to" : "off");
    }
    printf("AVX-512 blocks %s\n", tried_avx512 ? "tested" : "not supported here: not tested");
    return TEST_REPORT();
}
