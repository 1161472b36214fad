/* Running a dependency that may crash, abort or never end (TetGen 1.5.0, gmsh) in a forked
 * child: its result comes back through a pipe, its crash or hang becomes a status. Private
 * to meshgen/. */
#ifndef CADMORPH_MESHGEN_CHILD_PROCESS_H
#define CADMORPH_MESHGEN_CHILD_PROCESS_H

#include "cadmorph/core.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* What the child does: writes its result to fd (cm_child_write) and returns its exit code
 * (0 on success). It runs in a copy of the process with only the calling thread: it may use
 * malloc and stdio (its stdout and stderr go to a log the parent reads), but no OpenMP, no
 * BLAS and no OpenCASCADE call made before the fork must be relied upon, and no cm_context. */
typedef int (*cm_child_work)(void *arg, int fd);

typedef struct cm_child_outcome {
    int exit_code;    /* the child's exit code when it exited, else -1 */
    int signal;       /* the signal that ended it (SIGSEGV, SIGABRT, ...), else 0 */
    int timed_out;    /* 1: killed after the time limit */
    double seconds;   /* wall time of the child */
    double time_limit; /* the limit it ran under (<= 0: none) */
    char log[512];    /* the last lines the child printed on stdout/stderr, '\0'-terminated */
} cm_child_outcome;

/* Forks, runs work(arg, fd) in the child, collects what it writes to fd into *data (malloc'd,
 * *size bytes; NULL when empty) and how it ended into *outcome. time_limit: seconds of wall
 * time (<= 0 or INFINITY: none); the child is then killed with SIGKILL. CM_OK whenever the
 * child ran (however it ended: look at *outcome); CM_ERR_NOMEM / CM_ERR_INTERNAL when no child
 * could be started or its output not read. `what` names the work in messages. While the
 * child runs, cm_progress(ctx, stage, 0, 1) every 0.1 s: when it returns CM_ERR_INTERRUPTED
 * the child is killed and that is returned (the dependency itself cannot stop, its process
 * can). */
cm_status cm_child_run(cm_context *ctx, const char *what, const char *stage, cm_child_work work,
                       void *arg, double time_limit, char **data, size_t *size,
                       cm_child_outcome *outcome);

/* In the child: writes all n bytes to fd; 0 on success. */
int cm_child_write(int fd, const void *p, size_t n);

/* "crashed (signal 11, segmentation fault)", "aborted (signal 6): <log>", "did not finish in
 * 5 s", "exited with code 3": how the child ended, for a message. */
void cm_child_describe(const cm_child_outcome *o, char *buf, size_t n);

#ifdef __cplusplus
}
#endif
#endif
