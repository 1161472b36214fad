/* Which OpenBLAS kernels this process runs, and which it should (see blas.h for why):
 * cpuid/xgetbv detection, the pure decision table, and cm_blas_info. */
#include "cadmorph/blas.h"

#include <cblas.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>

/* XCR0 through xgetbv; only valid when cpuid says the OS enabled XSAVE (OSXSAVE). */
static unsigned long long read_xcr0(void)
{
    unsigned int lo, hi;
    __asm__ volatile("xgetbv" : "=a"(lo), "=d"(hi) : "c"(0));
    return ((unsigned long long)hi << 32) | lo;
}
#endif

void cm_blas_cpu_detect(cm_blas_cpu *cpu)
{
    if (!cpu) return;
    memset(cpu, 0, sizeof *cpu);
#if defined(__x86_64__) || defined(__i386__)
    unsigned int a, b, c, d;
    if (!__get_cpuid(1, &a, &b, &c, &d)) return;
    const int fma = (c >> 12) & 1, osxsave = (c >> 27) & 1, avx = (c >> 28) & 1;
    if (osxsave && avx) {
        unsigned long long xcr0 = read_xcr0();
        cpu->os_avx = (xcr0 & 0x6) == 0x6;             /* XMM and YMM state */
        cpu->os_avx512 = cpu->os_avx && (xcr0 & 0xe0) == 0xe0; /* opmask, ZMM_Hi256, Hi16_ZMM */
    }
    cpu->fma = fma;
    if (__get_cpuid_max(0, NULL) < 7) return;
    __cpuid_count(7, 0, a, b, c, d);
    cpu->avx2 = (b >> 5) & 1;
    cpu->avx512f = (b >> 16) & 1;
    cpu->avx512dq = (b >> 17) & 1;
    cpu->avx512bw = (b >> 30) & 1;
    cpu->avx512vl = (b >> 31) & 1;
#endif
}

/* Strength of OpenBLAS's x86 cores for double precision BLAS-3: 3 = AVX-512 kernels,
 * 2 = AVX2/FMA kernels, 1 = older; -1 for a name not in the table (another architecture,
 * or a core newer than this table: not ours to second-guess). Names as 0.3.21's
 * dynamic.c spells them, plus SapphireRapids from 0.3.22. */
static int core_tier(const char *core)
{
    static const char *const avx512[] = {"SkylakeX", "Cooperlake", "SapphireRapids"};
    static const char *const avx2[] = {"Haswell", "Zen"};
    static const char *const older[] = {
        "Unknown",   "Katmai",  "Coppermine", "Northwood",  "Prescott",     "Banias",
        "Atom",      "Core2",   "Penryn",     "Dunnington", "Nehalem",      "Athlon",
        "Opteron",   "Opteron_SSE3", "Barcelona", "Nano",   "Sandybridge",  "Bobcat",
        "Bulldozer", "Piledriver", "Steamroller", "Excavator"};
    if (!core) return -1;
    for (size_t i = 0; i < sizeof avx512 / sizeof *avx512; ++i)
        if (!strcasecmp(core, avx512[i])) return 3;
    for (size_t i = 0; i < sizeof avx2 / sizeof *avx2; ++i)
        if (!strcasecmp(core, avx2[i])) return 2;
    for (size_t i = 0; i < sizeof older / sizeof *older; ++i)
        if (!strcasecmp(core, older[i])) return 1;
    return -1;
}

cm_blas_action cm_blas_decide(const cm_blas_cpu *cpu, const char *core, int coretype_set)
{
    if (!cpu || coretype_set) return CM_BLAS_KEEP;
    const int tier = core_tier(core);
    if (tier < 0) return CM_BLAS_KEEP;
    /* SkylakeX's kernels use AVX512F/BW/DQ/VL; OpenBLAS itself asks for all four */
    const int has512 = cpu->os_avx512 && cpu->avx512f && cpu->avx512bw && cpu->avx512dq &&
                       cpu->avx512vl && cpu->avx2 && cpu->fma;
    const int has2 = cpu->os_avx && cpu->avx2 && cpu->fma;
    if (has512 && tier < 3) return CM_BLAS_USE_SKYLAKEX;
    if (has2 && tier < 2) return CM_BLAS_USE_HASWELL;
    return CM_BLAS_KEEP;
}

const char *cm_blas_action_core(cm_blas_action action)
{
    switch (action) {
    case CM_BLAS_USE_SKYLAKEX: return "SkylakeX";
    case CM_BLAS_USE_HASWELL: return "Haswell";
    case CM_BLAS_KEEP: break;
    }
    return NULL;
}

static void copy(char *dst, size_t size, const char *src)
{
    if (!src) src = "";
    size_t n = strlen(src);
    if (n >= size) n = size - 1;
    memcpy(dst, src, n);
    dst[n] = '\0';
    /* openblas_get_config() ends with a space */
    while (n > 0 && dst[n - 1] == ' ') dst[--n] = '\0';
}

void cm_blas_info(const cm_context *ctx, cm_blas_summary *out)
{
    if (!out) return;
    memset(out, 0, sizeof *out);
    copy(out->config, sizeof out->config, openblas_get_config());
    copy(out->core, sizeof out->core, openblas_get_corename());
    copy(out->picked, sizeof out->picked, getenv(CM_BLAS_PICKED_ENV));
    const char *ct = getenv("OPENBLAS_CORETYPE");
    out->coretype_set = ct && *ct;
    const char *lazy = getenv(CM_BLAS_LAZY_THREADS_ENV);
    out->lazy_threads = lazy && !strcmp(lazy, "1");
    out->threads_now = openblas_get_num_threads();
    /* as the dense factorisation sizes its BLAS threads: every thread the context allows */
    out->threads = cm_context_threads_for(ctx, SIZE_MAX, 1);
    cm_blas_cpu_detect(&out->cpu);
    out->action = cm_blas_decide(&out->cpu, out->core, out->coretype_set);
}
