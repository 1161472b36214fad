/* The BLAS-core decision (blas.h): cpuid flags and OpenBLAS core names in, decision out; the
 * cpuid reader against the kernel's /proc/cpuinfo flags; cm_blas_info on this machine. */
#include "cadmorph/blas.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

static const cm_blas_cpu spr = {1, 1, 1, 1, 1, 1, 1, 1};   /* Sapphire Rapids, Zen 4/5 */
static const cm_blas_cpu hsw = {1, 1, 0, 0, 0, 0, 1, 0};   /* Haswell .. Zen 3 */
static const cm_blas_cpu old = {0, 0, 0, 0, 0, 0, 0, 0};   /* SSE only */

static void decisions(void)
{
    /* the issue: 0.3.21 on Sapphire Rapids (Prescott) and on Zen 5 (Haswell) */
    CHECK(cm_blas_decide(&spr, "Prescott", 0) == CM_BLAS_USE_SKYLAKEX);
    CHECK(cm_blas_decide(&spr, "Haswell", 0) == CM_BLAS_USE_SKYLAKEX);
    CHECK(cm_blas_decide(&spr, "Zen", 0) == CM_BLAS_USE_SKYLAKEX);
    CHECK(cm_blas_decide(&spr, "Sandybridge", 0) == CM_BLAS_USE_SKYLAKEX);
    /* already right: no re-exec, whatever the spelling */
    CHECK(cm_blas_decide(&spr, "SkylakeX", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&spr, "Cooperlake", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&spr, "sapphirerapids", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&spr, "SKYLAKEX", 0) == CM_BLAS_KEEP);
    /* the user's OPENBLAS_CORETYPE wins */
    CHECK(cm_blas_decide(&spr, "Prescott", 1) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&hsw, "Prescott", 1) == CM_BLAS_KEEP);
    /* AVX2 machines: Haswell, never SkylakeX */
    CHECK(cm_blas_decide(&hsw, "Prescott", 0) == CM_BLAS_USE_HASWELL);
    CHECK(cm_blas_decide(&hsw, "Sandybridge", 0) == CM_BLAS_USE_HASWELL);
    CHECK(cm_blas_decide(&hsw, "Unknown", 0) == CM_BLAS_USE_HASWELL);
    CHECK(cm_blas_decide(&hsw, "Haswell", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&hsw, "Zen", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&hsw, "SkylakeX", 0) == CM_BLAS_KEEP); /* not ours to downgrade */
    /* the OS must save the registers: AVX-512 silicon, no ZMM state in XCR0 */
    cm_blas_cpu no_os512 = spr;
    no_os512.os_avx512 = 0;
    CHECK(cm_blas_decide(&no_os512, "Haswell", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&no_os512, "Prescott", 0) == CM_BLAS_USE_HASWELL);
    cm_blas_cpu no_os = hsw;
    no_os.os_avx = 0;
    CHECK(cm_blas_decide(&no_os, "Prescott", 0) == CM_BLAS_KEEP);
    /* AVX-512F without BW/DQ/VL (Knights Landing): not SkylakeX */
    cm_blas_cpu knl = spr;
    knl.avx512bw = knl.avx512dq = knl.avx512vl = 0;
    CHECK(cm_blas_decide(&knl, "Haswell", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&knl, "Prescott", 0) == CM_BLAS_USE_HASWELL);
    /* AVX2 without FMA: no Haswell kernels */
    cm_blas_cpu nofma = hsw;
    nofma.fma = 0;
    CHECK(cm_blas_decide(&nofma, "Prescott", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&old, "Prescott", 0) == CM_BLAS_KEEP);
    /* names we do not know: another architecture, or newer than the table */
    CHECK(cm_blas_decide(&spr, "neoversen1", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&spr, "", 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(&spr, NULL, 0) == CM_BLAS_KEEP);
    CHECK(cm_blas_decide(NULL, "Prescott", 0) == CM_BLAS_KEEP);
    CHECK(!strcmp(cm_blas_action_core(CM_BLAS_USE_SKYLAKEX), "SkylakeX"));
    CHECK(!strcmp(cm_blas_action_core(CM_BLAS_USE_HASWELL), "Haswell"));
    CHECK(cm_blas_action_core(CM_BLAS_KEEP) == NULL);
}

/* cpuid agrees with the flags the kernel reports (it also masks what the OS does not save). */
static void detection(void)
{
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f) return;
    char line[8192], *flags = NULL;
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, "flags", 5)) {
            flags = line;
            break;
        }
    fclose(f);
    if (!flags) return;
    cm_blas_cpu cpu;
    cm_blas_cpu_detect(&cpu);
    const char *names[] = {" avx2", " fma", " avx512f", " avx512bw", " avx512dq", " avx512vl"};
    const int got[] = {cpu.avx2 && cpu.os_avx, cpu.fma, cpu.avx512f && cpu.os_avx512,
                       cpu.avx512bw && cpu.os_avx512, cpu.avx512dq && cpu.os_avx512,
                       cpu.avx512vl && cpu.os_avx512};
    for (int i = 0; i < 6; ++i) {
        char word[32];
        snprintf(word, sizeof word, "%s ", names[i]);
        int listed = strstr(flags, word) != NULL;
        if (!listed) { /* the last word ends with the newline */
            snprintf(word, sizeof word, "%s\n", names[i]);
            listed = strstr(flags, word) != NULL;
        }
        CHECK_MSG(listed == got[i], "%s: cpuinfo %d, cpuid %d", names[i] + 1, listed, got[i]);
    }
}

static void info(void)
{
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_context_set_threads(ctx, 3);
    cm_blas_summary s;
    cm_blas_info(ctx, &s);
    printf("config '%s' core '%s' picked '%s' coretype_set %d threads %d/%d action %d\n",
           s.config, s.core, s.picked, s.coretype_set, s.threads_now, s.threads, (int)s.action);
    CHECK(!strncmp(s.config, "OpenBLAS", 8));
    CHECK(s.core[0] != '\0');
    CHECK(s.threads == 3);
    CHECK(s.threads_now >= 1);
    CHECK(s.action == cm_blas_decide(&s.cpu, s.core, s.coretype_set));
    CHECK(s.coretype_set == (getenv("OPENBLAS_CORETYPE") && *getenv("OPENBLAS_CORETYPE")));
    cm_context_destroy(&ctx);
}

/* Under an address-space limit that leaves no room for OpenBLAS's 128 MB buffer,
 * cm_blas_reserve fails with CM_ERR_NOMEM (OpenBLAS itself would spin); with room it passes.
 * In a child process: the limit must not reach the rest of the tests. */
static int reserve_under(size_t extra_mb)
{
    fflush(NULL);
    pid_t pid = fork();
    if (pid == 0) {
        FILE *f = fopen("/proc/self/statm", "r");
        unsigned long pages = 0;
        if (!f || fscanf(f, "%lu", &pages) != 1) _exit(3);
        fclose(f);
        struct rlimit rl;
        rl.rlim_cur = rl.rlim_max = (rlim_t)pages * 4096u + (rlim_t)extra_mb * 1048576u;
        if (setrlimit(RLIMIT_AS, &rl) != 0) _exit(3);
        cm_context *ctx = NULL;
        if (cm_context_create(&ctx) != CM_OK) _exit(3);
        cm_status st = cm_blas_reserve(ctx, "test");
        if (st == CM_ERR_NOMEM && strstr(cm_context_message(ctx), "test: out of memory")) _exit(1);
        _exit(st == CM_OK ? 0 : 2);
    }
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
    return WEXITSTATUS(status);
}

int main(void)
{
    CHECK(reserve_under(40) == 1);  /* no room: a clean CM_ERR_NOMEM */
    CHECK(reserve_under(600) == 0); /* room for the buffers of a few threads */
    decisions();
    detection();
    info();
    return TEST_REPORT();
}
