/* cadmorph BLAS check: which OpenBLAS kernels the dense RBF path runs on, and why a program
 * may have to restart itself to get the right ones. Conventions: see core.h.
 *
 * The dense path (cm_rbf_create) spends almost all its time in a Cholesky factorisation,
 * so its speed is OpenBLAS's. Two facts about Debian 12's OpenBLAS 0.3.21 that a program
 * using this library should know:
 *
 *  1. Kernel choice. OpenBLAS picks its kernels ("core") once, when the library loads, from
 *     the CPU model it recognises. 0.3.21 does not recognise Sapphire-Rapids-class Xeons and
 *     runs its Prescott (SSE3) kernels there: 4-5x slower factorisations than SkylakeX
 *     (m = 9,446: dpftrf 9.8 s Prescott, 4.1 s Haswell, 2.3 s SkylakeX). It runs its
 *     Haswell (AVX2) kernels on AMD Zen 5, which has AVX-512. Only the environment variable
 *     OPENBLAS_CORETYPE, read at load time, changes the choice, so a running process cannot
 *     fix it: it must execute itself again with the variable set. cm_blas_decide says
 *     whether to; the cadmorph program does it at start-up unless the user has set
 *     OPENBLAS_CORETYPE, and records the core OpenBLAS had picked in CM_BLAS_PICKED_ENV.
 *
 *  2. Threads and address space. OpenBLAS starts all its worker threads when it loads, and
 *     each thread (the caller's included, at its first BLAS call) takes a 128 MB buffer of
 *     address space. 0.3.21 retries a failed buffer allocation forever: under an
 *     address-space limit (ulimit -v of a few hundred MB) a worker spins at load and the
 *     process hangs at exit joining it. Set OPENBLAS_NUM_THREADS=1 before the library loads
 *     (cadmorph does so before OpenBLAS initialises, unless the user set it); cm_rbf_create
 *     then raises the thread count for the factorisation only as far as the address space
 *     allows, and fails with CM_ERR_NOMEM, not a hang, when not even one buffer fits.
 */
#ifndef CADMORPH_BLAS_H
#define CADMORPH_BLAS_H

#include "cadmorph/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Set by a program that re-executed itself with OPENBLAS_CORETYPE: the core OpenBLAS had
 * picked on its own (read back by cm_blas_info, and a guard against a second re-exec). */
#define CM_BLAS_PICKED_ENV "CADMORPH_OPENBLAS_PICKED"
/* Set (to "1") by a program that put OPENBLAS_NUM_THREADS=1 in its own environment before
 * OpenBLAS loaded, as point 2 above advises; read back by cm_blas_info. */
#define CM_BLAS_LAZY_THREADS_ENV "CADMORPH_OPENBLAS_LAZY_THREADS"

/* What the CPU and the operating system support (cpuid; xgetbv for the OS's saving of the
 * AVX and AVX-512 register state). All 0 on other architectures. */
typedef struct cm_blas_cpu {
    int avx2, fma;
    int avx512f, avx512bw, avx512dq, avx512vl;
    int os_avx;    /* XCR0 has the SSE and AVX state */
    int os_avx512; /* XCR0 also has the opmask and upper-ZMM state */
} cm_blas_cpu;

typedef enum cm_blas_action {
    CM_BLAS_KEEP = 0,         /* the core OpenBLAS chose is right, or not ours to change */
    CM_BLAS_USE_HASWELL = 1,  /* AVX2 + FMA available, OpenBLAS chose weaker kernels */
    CM_BLAS_USE_SKYLAKEX = 2  /* AVX-512 F/BW/DQ/VL available, OpenBLAS chose weaker kernels */
} cm_blas_action;

CM_API void cm_blas_cpu_detect(cm_blas_cpu *cpu);

/* The decision, a pure function: given the CPU, the name of the core OpenBLAS runs
 * (openblas_get_corename(), compared without case) and whether the user set
 * OPENBLAS_CORETYPE, which core to ask for. KEEP when the user set the variable, when the
 * name is not one of OpenBLAS's x86 cores (another architecture, or a core newer than this
 * table), and when the chosen core is already as strong as the CPU allows. */
CM_API cm_blas_action cm_blas_decide(const cm_blas_cpu *cpu, const char *core, int coretype_set);

/* OPENBLAS_CORETYPE value for an action ("SkylakeX", "Haswell"), NULL for KEEP. */
CM_API const char *cm_blas_action_core(cm_blas_action action);

typedef struct cm_blas_summary {
    char config[160];  /* openblas_get_config(), e.g. "OpenBLAS 0.3.21 DYNAMIC_ARCH ..." */
    char core[32];     /* the core OpenBLAS runs now */
    char picked[32];   /* the core OpenBLAS had picked itself, if this process was
                          re-executed with OPENBLAS_CORETYPE (CM_BLAS_PICKED_ENV); else "" */
    int coretype_set;  /* OPENBLAS_CORETYPE is in the environment */
    int lazy_threads;  /* OPENBLAS_NUM_THREADS=1 was set before load (CM_BLAS_LAZY_THREADS_ENV) */
    int threads_now;   /* openblas_get_num_threads() */
    int threads;       /* threads a factorisation asks for under ctx (0 in ctx: all cores) */
    cm_blas_action action; /* cm_blas_decide for this process as it runs now */
    cm_blas_cpu cpu;
} cm_blas_summary;

/* Fills out for this process. ctx (may be NULL) gives the thread count. */
CM_API void cm_blas_info(const cm_context *ctx, cm_blas_summary *out);

/* For code that calls BLAS or LAPACK itself (cm_rbf_create does this already): call first.
 * Checks that the address space can back OpenBLAS's buffers for its current thread count,
 * lowers the count if only fewer fit, and returns CM_ERR_NOMEM (message starting with who)
 * if not even the calling thread's buffer fits, where OpenBLAS would spin forever. */
CM_API cm_status cm_blas_reserve(cm_context *ctx, const char *who);

#ifdef __cplusplus
}
#endif
#endif
