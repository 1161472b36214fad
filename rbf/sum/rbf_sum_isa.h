/* The instruction-set variants of the kernel sums (rbf_sum.c, rbf_sum_acc.c, and the
 * treecode's products in rbf_treecode.c) and the hand-written AVX-512 r^3 blocks
 * (rbf_sum_avx512.c) they dispatch to. Not a public header. */
#ifndef CADMORPH_RBF_SUM_ISA_H
#define CADMORPH_RBF_SUM_ISA_H

#include <stddef.h>

/* Points per work item of the plain and of the compensated sums: the drivers pack that many
 * points (3 x PB SoA) and the blocks add all centres' contributions to them. */
#define CM_RBF_SUM_PB 128
#define CM_RBF_ACC_PB 64

/* acc[q * CM_RBF_SUM_PB + l] += sum_j |pt_l - c_j|^3 w[q * m + j], q < nc (any nc >= 1: up
 * to 4 in registers, more on the entries of the first 4 kept in L1; the same bits per
 * column whatever nc), in the
 * order j = 0, 1, ..., m - 1 for every point. c: 3 x m SoA (stride m), pt: 3 x PB SoA. */
void cm_rbf_r3_block_avx512(int nc, size_t m, const double *c, const double *w,
                            const double *pt, double *acc);

/* The same block with strides, for the treecode (rbf_treecode.c: a batch of targets against
 * proxies or centres): acc[q * ldp + l] += sum_j |pt_l - c_j|^3 w[q * ldw + j], q < nc,
 * l < npt rounded up to a multiple of 8 (pt and acc must hold that many; pad with a copy
 * of a real point), c_j = (c[j], c[ldc + j], c[2 ldc + j]), pt: 3 x ldp SoA. Same
 * arithmetic (and results) as cm_rbf_r3_block_avx512, which is this with npt = ldp =
 * CM_RBF_SUM_PB, ldc = ldw = m. */
void cm_rbf_r3_strided_avx512(int nc, size_t m, const double *c, size_t ldc, const double *w,
                              size_t ldw, size_t npt, const double *pt, size_t ldp, double *acc);

/* The same with compensated accumulation: (hi, lo)[q * CM_RBF_ACC_PB + l] is a double-double
 * running sum, each product split exactly (FMA) and added by TwoSum. */
void cm_rbf_r3_acc_block_avx512(int nc, size_t m, const double *c, const double *w,
                                const double *pt, double *hi, double *lo);

/* The compensated (TwoSum) block with strides, for the treecode's compensated products:
 * (hi, lo)[q * ldp + l] as cm_rbf_r3_acc_block_avx512, targets and strides as
 * cm_rbf_r3_strided_avx512 (npt rounded up to a multiple of 8). */
void cm_rbf_r3_acc_strided_avx512(int nc, size_t m, const double *c, size_t ldc,
                                  const double *w, size_t ldw, size_t npt, const double *pt,
                                  size_t ldp, double *hi, double *lo);

/* The same with a fixed-binade running sum (rbf_sum_avx512.c says why it is exact enough):
 * hi[q * CM_RBF_ACC_PB + l] must start at big_q = 1.5 * 2^k with 2^k >= 4 * (a bound of
 * every partial sum |sum_{j<=J} w_qj phi_lj|), and the result is (hi - big_q) + lo. */
void cm_rbf_r3_accf_block_avx512(int nc, size_t m, const double *c, const double *w,
                                 const double *pt, double *hi, double *lo);

/* The r^3 sums for the self product (targets = the m centres): out[i * ldo + q] =
 * sum_j |c_i - c_j|^3 w[q * m + j], q < nc (any), each entry computed once for rows i and j
 * (rbf_sum_self_avx512.c). big: the offsets of cm_rbf_r3_accf_block_avx512 for the
 * fixed-binade compensated sums, or NULL for plain sums. OpenMP over threads. Returns 0, or
 * 1 if its work space (about 2 (threads + 1) nc m doubles) could not be allocated or this
 * build has no AVX-512 blocks: then nothing is written. */
#define CM_RBF_SELF_MIN_M 1024 /* the self product from this many centres (fewer: few tiles) */
/* ... and up to this many columns: beyond, the general blocks run (each further column costs
 * them one FMA per entry, while the self product's per-tile column sums outgrow the caches:
 * at 2e4 centres and 12 columns it took 1.3x, at 60 columns 2.5x the general blocks' CPU
 * time; benchmarks/RESULTS.md, Study, "Kernel cost per column"). So a column's plain self
 * product has other bits alone than in a batch of more than this (rounding: a few eps
 * sum_j |w_j phi_ij|); compensated, the same bits up to the order of the remainders. */
#define CM_RBF_SELF_MAX_NC 4
int cm_rbf_r3_self_avx512(int nc, size_t m, const double *c, const double *w,
                          const double *big, double *out, size_t ldo, int threads);

/* The vsqrtpd share of the AVX-512 r^3 blocks on this CPU (rbf_sum_avx512.c says why it
 * varies): vectors of the plain block's 4, and of the fixed-binade block's 2, whose sqrt
 * takes vsqrtpd; chosen by timing once per process, the results do not depend on it. */
void cm_rbf_sqrt_split(int *plain_sqrt, int *acc_sqrt);
/* For benchmarks and tests: use this split from now on (one of the two candidates of each
 * block: plain 3 or 2, compensated 2 or 1), or (0, 0) the probed one again. -1: not a
 * candidate (or no AVX-512 blocks in this build). */
int cm_rbf_sqrt_split_force(int plain_sqrt, int acc_sqrt);

/* 1 if this CPU and OS run AVX-512 F/DQ/VL code (cpuid, as GCC's __builtin_cpu_supports). */
int cm_rbf_cpu_avx512(void);
/* 1 if they run AVX2 + FMA code. */
int cm_rbf_cpu_avx2(void);

#endif
