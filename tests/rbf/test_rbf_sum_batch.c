/* Kernel sums of many columns in one pass (rbf/sum): every entry point takes any number of
 * columns, and a column's sum is the same bits whether it is summed alone or with others
 * (rbf_internal.h, CM_RBF_SUM_MAX_NC). Checked for the plain sums (r^3 3D at targets and at
 * the centres, where AVX-512 runs the self product; biharmonic 3D; thin-plate 2D), the
 * compensated sums (general and self), and the treecode (self sums and evaluation sums,
 * plain and compensated), on every instruction set this CPU runs, for nc = 1, 3, 4, 5, 12,
 * 60 (and 70, more than one pass, for the plain sums) against nc = 1 per column; and the
 * batched sums against a plain scalar reference to a tolerance. */
#include "rbf_internal.h"
#include "sum/rbf_sum_isa.h"
#include "sum/rbf_treecode.h"
#include "test_rng.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

#define M 1030 /* centres: >= CM_RBF_SELF_MIN_M (the self product), tails in every block */
#define N 300  /* separate targets */
#define NCMAX 70

static const int ncs[] = {1, 3, 4, 5, 12, 60, NCMAX};

static double phi(cm_rbf_kernel k, double r2)
{
    switch (k) {
    case CM_RBF_TRIHARMONIC: return r2 * sqrt(r2);
    case CM_RBF_BIHARMONIC: return sqrt(r2);
    default: return r2 > 0.0 ? 0.5 * r2 * log(r2) : 0.0;
    }
}

/* the sums of nc columns (a batch starting at column 0) against nc = 1 per column: 1 if
 * every column has the same bits. which: 0 plain, 1 compensated, 2 tree self, 3 tree at
 * targets. */
typedef struct job {
    int which;
    cm_rbf_isa isa;
    cm_rbf_kernel kern;
    int dim;
    const double *c, *w, *p;
    size_t n;
    const cm_rbf_tree *tree;
    const cm_rbf_tree_targets *tg;
} job;

static void run(const job *j, int nc, double *out, size_t ldo, const double *w)
{
    /* 2 threads where a row's sum comes in parts (the AVX-512 self product, the treecode's
     * batches), 1 elsewhere (a busy machine makes many small parallel regions slow) */
    const int th = j->p == j->c || j->which >= 2 ? 2 : 1;
    switch (j->which) {
    case 0:
        cm_rbf_kernel_sum_isa(j->isa, j->kern, j->dim, M, j->c, w, nc, j->n, j->p,
                              j->p == j->c ? M : j->n, out, ldo, th);
        break;
    case 1:
        cm_rbf_kernel_sum_acc_isa(j->isa, M, j->c, w, nc, j->n, j->p, j->p == j->c ? M : j->n,
                                  out, ldo, th);
        break;
    case 2: CHECK(cm_rbf_tree_sum_self(j->tree, w, nc, out, ldo, th) == 0); break;
    default: CHECK(cm_rbf_tree_sum_targets(j->tree, j->tg, 1, w, nc, out, ldo, th) == 0); break;
    }
}

/* 1 if every batch gives each column's nc = 1 bits; worst relative error against ref
 * (n x NCMAX, scale S n x NCMAX) into *err */
static int same_bits(const job *j, const double *ref, const double *S, double *err)
{
    const size_t n = j->n;
    double *one = malloc(n * NCMAX * sizeof *one), *bat = malloc(n * NCMAX * sizeof *bat);
    /* more than one pass (NCMAX > CM_RBF_SUM_MAX_NC) for the plain sums only: time */
    const int ncol = j->which == 0 ? NCMAX : 60;
    for (int q = 0; q < ncol; ++q) run(j, 1, one + q, NCMAX, j->w + (size_t)q * M);
    int same = 1;
    *err = 0.0;
    for (size_t k = 0; k < sizeof ncs / sizeof ncs[0]; ++k) {
        const int nc = ncs[k];
        if (nc > ncol) continue;
        memset(bat, 0xff, n * NCMAX * sizeof *bat);
        run(j, nc, bat, NCMAX, j->w);
        for (size_t i = 0; i < n; ++i)
            for (int q = 0; q < nc; ++q) {
                const size_t e = i * NCMAX + (size_t)q;
                /* the plain AVX-512 self product only up to CM_RBF_SELF_MAX_NC columns
                 * (rbf_sum_isa.h): beyond, the general blocks, whose rounding differs */
                if (j->which == 0 && j->p == j->c && j->isa == CM_RBF_ISA_AVX512 &&
                    nc > CM_RBF_SELF_MAX_NC) {
                    CHECK_MSG(fabs(bat[e] - one[e]) <= 1e-14 * S[e], "self nc %d: %.3g", nc,
                              fabs(bat[e] - one[e]) / S[e]);
                    continue;
                }
                if (memcmp(&bat[e], &one[e], sizeof(double)) != 0) {
                    if (same)
                        printf("  which %d isa %d kern %d nc %d: column %d row %zu %.17g vs "
                               "%.17g\n",
                               j->which, (int)j->isa, (int)j->kern, nc, q, i, bat[e], one[e]);
                    same = 0;
                }
                *err = fmax(*err, fabs(bat[e] - ref[e]) / S[e]);
            }
    }
    free(one), free(bat);
    return same;
}

/* ref and S = sum_j |w_qj phi_ij| at the n points p (stride ldp), NCMAX columns */
static void reference(cm_rbf_kernel kern, int dim, const double *c, const double *w, size_t n,
                      const double *p, size_t ldp, double *ref, double *S)
{
    for (size_t i = 0; i < n; ++i)
        for (int q = 0; q < NCMAX; ++q) {
            double s = 0.0;
            double a = 0.0;
            for (size_t jj = 0; jj < M; ++jj) {
                double r2 = 0.0;
                for (int d = 0; d < dim; ++d) {
                    const double dd = p[(size_t)d * ldp + i] - c[(size_t)d * M + jj];
                    r2 += dd * dd;
                }
                const double t = w[(size_t)q * M + jj] * phi(kern, r2);
                s += t;
                a += fabs(t);
            }
            ref[i * NCMAX + (size_t)q] = s;
            S[i * NCMAX + (size_t)q] = a > 0.0 ? a : 1.0;
        }
}

int main(void)
{
    uint64_t seed = 45;
    double *c = malloc(3 * M * sizeof *c), *p = malloc(3 * N * sizeof *p);
    double *w = malloc((size_t)NCMAX * M * sizeof *w);
    for (size_t i = 0; i < 3 * M; ++i) c[i] = test_rng_uniform(&seed);
    for (size_t i = 0; i < 3 * N; ++i) p[i] = 1.2 * test_rng_uniform(&seed) - 0.1;
    for (size_t i = 0; i < (size_t)NCMAX * M; ++i) w[i] = test_rng_range(&seed, -1.0, 1.0);
    /* column 7: all zero (its own binade); column 9: tiny, the compensated sums' TwoSum
     * fallback for that column alone */
    memset(w + 7 * M, 0, M * sizeof *w);
    for (size_t j = 0; j < M; ++j) w[9 * M + j] *= 1e-300;
    double *ref = malloc((size_t)M * NCMAX * sizeof *ref);
    double *S = malloc((size_t)M * NCMAX * sizeof *S);
    double *ref_c = malloc((size_t)M * NCMAX * sizeof *ref_c);
    double *S_c = malloc((size_t)M * NCMAX * sizeof *S_c);
    static const cm_rbf_isa isas[] = {CM_RBF_ISA_GENERIC, CM_RBF_ISA_AVX2,
                                      CM_RBF_ISA_AVX512_AUTOVEC, CM_RBF_ISA_AVX512};
    /* plain and compensated direct sums, r^3 3D, at targets and at the centres */
    reference(CM_RBF_TRIHARMONIC, 3, c, w, N, p, N, ref, S);
    reference(CM_RBF_TRIHARMONIC, 3, c, w, M, c, M, ref_c, S_c);
    for (size_t k = 0; k < sizeof isas / sizeof isas[0]; ++k) {
        if (!cm_rbf_isa_supported(isas[k])) continue;
        for (int which = 0; which < 2; ++which)
            for (int self = 0; self < 2; ++self) {
                /* at the centres only AVX-512 has other code (the self product); elsewhere
                 * it would be the general blocks again (time) */
                if (self && isas[k] != CM_RBF_ISA_AVX512) continue;
                const job j = {which, isas[k], CM_RBF_TRIHARMONIC, 3, c, w, self ? c : p,
                               self ? M : N, NULL, NULL};
                double err;
                const int same = same_bits(&j, self ? ref_c : ref, self ? S_c : S, &err);
                CHECK_MSG(same, "%s isa %d self %d: a batch changed a column's bits",
                          which ? "compensated" : "plain", (int)isas[k], self);
                CHECK_MSG(err <= 1e-13, "%s isa %d self %d: error %.3g",
                          which ? "compensated" : "plain", (int)isas[k], self, err);
                printf("%s isa %d self %d: %s, error %.2g\n", which ? "compensated" : "plain",
                       (int)isas[k], self, same ? "same bits" : "DIFFERENT", err);
            }
    }
    /* the AVX-512 self product itself for any nc (the sums take it up to
     * CM_RBF_SELF_MAX_NC columns), plain and compensated, against nc = 1 per column */
    if (cm_rbf_isa_supported(CM_RBF_ISA_AVX512)) {
        double *one = malloc((size_t)M * 60 * sizeof *one);
        double *bat = malloc((size_t)M * 60 * sizeof *bat);
        double bigs[60];
        for (int q = 0; q < 60; ++q) bigs[q] = 0x1.8p50; /* >= 4 sum |w| dmax^3 (3^1.5 1030) */
        for (int comp = 0; comp < 2; ++comp) {
            int same = 1;
            for (int q = 0; q < 60; ++q)
                CHECK(cm_rbf_r3_self_avx512(1, M, c, w + (size_t)q * M, comp ? bigs : NULL,
                                            one + q, 60, 2) == 0);
            for (size_t k = 0; k < sizeof ncs / sizeof ncs[0]; ++k) {
                if (ncs[k] > 60) continue;
                CHECK(cm_rbf_r3_self_avx512(ncs[k], M, c, w, comp ? bigs : NULL, bat, 60, 2) == 0);
                for (size_t i = 0; i < M; ++i)
                    for (int q = 0; q < ncs[k]; ++q)
                        same &= memcmp(&bat[i * 60 + (size_t)q], &one[i * 60 + (size_t)q],
                                       sizeof(double)) == 0;
            }
            CHECK_MSG(same, "self product comp %d: a batch changed a column's bits", comp);
            printf("self product comp %d, any nc: %s\n", comp, same ? "same bits" : "DIFFERENT");
        }
        free(one), free(bat);
    }
    /* the other kernels through the compiled blocks */
    for (int kk = 0; kk < 2; ++kk) {
        const cm_rbf_kernel kern = kk ? CM_RBF_THIN_PLATE : CM_RBF_BIHARMONIC;
        const int dim = kk ? 2 : 3;
        reference(kern, dim, c, w, N, p, N, ref, S);
        for (size_t k = 0; k < sizeof isas / sizeof isas[0]; ++k) {
            if (!cm_rbf_isa_supported(isas[k])) continue;
            const job j = {0, isas[k], kern, dim, c, w, p, N, NULL, NULL};
            double err;
            const int same = same_bits(&j, ref, S, &err);
            CHECK_MSG(same, "kernel %d isa %d: a batch changed a column's bits", (int)kern,
                      (int)isas[k]);
            CHECK_MSG(err <= 1e-12, "kernel %d isa %d: error %.3g", (int)kern, (int)isas[k], err);
            printf("kernel %d isa %d: %s, error %.2g\n", (int)kern, (int)isas[k],
                   same ? "same bits" : "DIFFERENT", err);
        }
    }
    /* the treecode: self sums and sums at targets, plain and compensated products; the
     * far field is exercised (order 3: clusters of more than 64 centres carry proxies) */
    reference(CM_RBF_TRIHARMONIC, 3, c, w, N, p, N, ref, S);
    cm_rbf_tree *t = cm_rbf_tree_create(M, c, 3, 0.5);
    cm_rbf_tree_targets *tg = cm_rbf_tree_targets_create(N, p, N);
    CHECK(t && tg);
    for (size_t k = 0; t && tg && k < sizeof isas / sizeof isas[0]; ++k) {
        if (!cm_rbf_isa_supported(isas[k])) continue;
        cm_rbf_tree_set_isa(t, isas[k]);
        /* compensated products only where the AVX-512 block runs (elsewhere plain) */
        for (int comp = 0; comp <= (isas[k] == CM_RBF_ISA_AVX512 ? 2 : 0); ++comp) {
            cm_rbf_tree_set_compensated(t, comp);
            for (int self = 0; self < 2; ++self) {
                const job j = {self ? 2 : 3, isas[k], CM_RBF_TRIHARMONIC, 3, c, w, self ? c : p,
                               self ? M : N, t, tg};
                double err;
                const int same = same_bits(&j, self ? ref_c : ref, self ? S_c : S, &err);
                CHECK_MSG(same, "tree isa %d comp %d self %d: a batch changed a column's bits",
                          (int)isas[k], comp, self);
                /* order 3, theta 0.5: the table's 1e-3 row */
                CHECK_MSG(err <= 1e-3, "tree isa %d comp %d self %d: error %.3g", (int)isas[k],
                          comp, self, err);
                printf("tree isa %d comp %d self %d: %s, error %.2g\n", (int)isas[k], comp, self,
                       same ? "same bits" : "DIFFERENT", err);
            }
        }
    }
    cm_rbf_tree_targets_destroy(&tg);
    cm_rbf_tree_destroy(&t);
    free(c), free(p), free(w), free(ref), free(S), free(ref_c), free(S_c);
    return TEST_REPORT();
}
