/* OpenBLAS reads OPENBLAS_CORETYPE and OPENBLAS_NUM_THREADS once, when it loads, before main
 * runs (include/cadmorph/blas.h says why both matter). So cadmorph executes itself once
 * more, through /proc/self/exe, with them set:
 *  - OPENBLAS_CORETYPE=SkylakeX or Haswell when OpenBLAS picked weaker kernels than the CPU
 *    runs (cm_blas_decide) and the user did not set the variable;
 *  - OPENBLAS_NUM_THREADS=1 when OpenBLAS started more, so that it starts no worker threads
 *    at load (each takes 128 MB of address space, and under ulimit -v one that cannot get it
 *    spins forever); cm_rbf_create raises the count for the factorisation to --threads.
 * A marker variable keeps it to one re-exec. The cost is one more program start (~70 ms). */
#define _GNU_SOURCE /* setenv, unsetenv */
#include "blas_reexec.h"

#include "cadmorph/blas.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Set in the re-executed process: it must not re-execute again. */
#define CLI_REEXEC_ENV "CADMORPH_BLAS_REEXEC"

static int want_verbose(int argc, char **argv)
{
    for (int i = 1; i < argc; ++i)
        if (!strcmp(argv[i], "--verbose") || !strcmp(argv[i], "-v")) return 1;
    return 0;
}

static int env_set(const char *name)
{
    const char *v = getenv(name);
    return v && *v;
}

/* What the re-executed process says under --verbose. */
static void explain(const cm_blas_summary *s)
{
    if (s->picked[0])
        fprintf(stderr,
                "cadmorph: OpenBLAS picked its %s kernels, the CPU runs %s: re-executed with "
                "OPENBLAS_CORETYPE=%s (set OPENBLAS_CORETYPE to choose yourself)\n",
                s->picked, s->core, s->core);
    if (s->lazy_threads)
        fprintf(stderr,
                "cadmorph: OpenBLAS started on 1 thread (OPENBLAS_NUM_THREADS=1); a "
                "factorisation raises it to --threads (default %d)\n",
                s->threads);
}

void cli_blas_setup(int argc, char **argv)
{
    const int verbose = want_verbose(argc, argv);
    cm_blas_summary s;
    cm_blas_info(NULL, &s);
    if (env_set(CLI_REEXEC_ENV)) {
        if (verbose) explain(&s);
        return;
    }
    if (verbose && s.coretype_set) {
        /* the user's choice stands, but say when it is the weaker one */
        cm_blas_action a = cm_blas_decide(&s.cpu, s.core, 0);
        if (a != CM_BLAS_KEEP)
            fprintf(stderr,
                    "cadmorph: OPENBLAS_CORETYPE=%s is set; this CPU would run OpenBLAS's %s "
                    "kernels, faster for the dense factorisation\n",
                    getenv("OPENBLAS_CORETYPE"), cm_blas_action_core(a));
    }
    /* for the CLI test of the re-exec on machines where OpenBLAS chooses well: pretend it
     * picked this core (it is what CM_BLAS_PICKED_ENV then reports) */
    const char *pretend = getenv("CADMORPH_TEST_BLAS_PICKED");
    if (pretend && *pretend && !s.coretype_set) {
        snprintf(s.core, sizeof s.core, "%s", pretend);
        s.action = cm_blas_decide(&s.cpu, s.core, 0);
    }
    const char *core = cm_blas_action_core(s.action);
    /* even a count the user set: cm_rbf_create sets its own from --threads, so the count at
     * load only decides how many workers (and 128 MB buffers) exist before they are needed */
    const int threads = s.threads_now > 1;
    if (!core && !threads) return;
    int ok = setenv(CLI_REEXEC_ENV, "1", 1) == 0;
    if (ok && core)
        ok = setenv("OPENBLAS_CORETYPE", core, 1) == 0 && setenv(CM_BLAS_PICKED_ENV, s.core, 1) == 0;
    if (ok && threads)
        ok = setenv("OPENBLAS_NUM_THREADS", "1", 1) == 0 &&
             setenv(CM_BLAS_LAZY_THREADS_ENV, "1", 1) == 0;
    if (ok) execv("/proc/self/exe", argv);
    /* still here: run on as we are, with the environment the user gave */
    int err = errno;
    unsetenv(CLI_REEXEC_ENV);
    if (core) unsetenv("OPENBLAS_CORETYPE"), unsetenv(CM_BLAS_PICKED_ENV);
    if (threads) unsetenv("OPENBLAS_NUM_THREADS"), unsetenv(CM_BLAS_LAZY_THREADS_ENV);
    if (verbose)
        fprintf(stderr, "cadmorph: could not re-execute with %s%s%s: %s; OpenBLAS stays on %s\n",
                core ? "OPENBLAS_CORETYPE=" : "", core ? core : "",
                threads ? " OPENBLAS_NUM_THREADS=1" : "", strerror(err), s.core);
}

void cli_blas_print_version(FILE *out)
{
    cm_blas_summary s;
    cm_blas_info(NULL, &s);
    fprintf(out, "BLAS: %s\n", s.config);
    if (s.picked[0])
        fprintf(out, "BLAS core: %s (OpenBLAS picked %s; cadmorph set OPENBLAS_CORETYPE=%s)\n",
                s.core, s.picked, s.core);
    else if (s.coretype_set)
        fprintf(out, "BLAS core: %s (OPENBLAS_CORETYPE=%s, set by the user)\n", s.core,
                getenv("OPENBLAS_CORETYPE"));
    else
        fprintf(out, "BLAS core: %s (chosen by OpenBLAS)\n", s.core);
    if (s.lazy_threads)
        fprintf(out, "BLAS threads: %d for factorisations (1 at start: OPENBLAS_NUM_THREADS=1 "
                     "set by cadmorph)\n", s.threads);
    else
        fprintf(out, "BLAS threads: %d for factorisations (%d at start)\n", s.threads,
                s.threads_now);
}
