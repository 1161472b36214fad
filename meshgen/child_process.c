/* A forked child for meshers that crash, abort or hang (TetGen 1.5.0 frees its pools twice on
 * its error path and asserts in fillcavity; a hard part can run for an hour): the parent reads
 * the child's result from a pipe under a deadline and turns how it ended into an outcome.
 *
 * Why fork without exec is safe here: the child holds only the forking thread, so OpenMP's
 * and OpenBLAS's thread pools are not there; the child's work (TetGen, gmsh) calls neither
 * (TetGen is serial; gmsh is told to use one thread), and glibc resets malloc's and stdio's
 * locks across fork. The child leaves with _exit: no atexit handler, no flush of stdio buffers
 * copied from the parent, and its SIGINT/SIGTERM/SIGHUP handlers are reset so that it never
 * removes the parent's registered temporaries (core/file.c). */
#define _GNU_SOURCE
#include "child_process.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdio_ext.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

int cm_child_write(int fd, const void *p, size_t n)
{
    const char *c = p;
    while (n > 0) {
        ssize_t w = write(fd, c, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return -1;
        c += w;
        n -= (size_t)w;
    }
    return 0;
}

static void child_main(cm_child_work work, void *arg, int fd, int log_fd, pid_t parent)
{
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};
    for (size_t i = 0; i < sizeof sigs / sizeof *sigs; ++i) signal(sigs[i], SIG_DFL);
    /* dies with the parent (killed, or interrupted) instead of meshing on as an orphan */
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(126);
    /* what the parent had buffered is the parent's to print */
    __fpurge(stdout);
    __fpurge(stderr);
    dup2(log_fd, STDOUT_FILENO);
    dup2(log_fd, STDERR_FILENO);
    close(log_fd);
    const int rc = work(arg, fd);
    fflush(stdout);
    fflush(stderr);
    close(fd);
    _exit(rc);
}

/* the last lines (up to sizeof o->log - 1 bytes) of the child's log, on one line */
static void read_log_tail(int log_fd, cm_child_outcome *o)
{
    o->log[0] = '\0';
    off_t end = lseek(log_fd, 0, SEEK_END);
    if (end <= 0) return;
    const size_t cap = sizeof o->log - 1;
    off_t start = end > (off_t)cap ? end - (off_t)cap : 0;
    ssize_t got = pread(log_fd, o->log, (size_t)(end - start), start);
    if (got <= 0) return;
    o->log[got] = '\0';
    /* trim trailing blank space, join lines */
    while (got > 0 && (o->log[got - 1] == '\n' || o->log[got - 1] == ' ' || o->log[got - 1] == '\r'))
        o->log[--got] = '\0';
    for (ssize_t i = 0; i < got; ++i)
        if (o->log[i] == '\n' || o->log[i] == '\r' || o->log[i] == '\t') o->log[i] = ' ';
}

/* Seconds between two progress points while the child runs. */
#define CM_CHILD_BEAT 0.1

cm_status cm_child_run(cm_context *ctx, const char *what, const char *stage, cm_child_work work,
                       void *arg, double time_limit, char **data, size_t *size,
                       cm_child_outcome *o)
{
    const char *fn = "cm_child_run";
    *data = NULL;
    *size = 0;
    memset(o, 0, sizeof *o);
    o->exit_code = -1;
    o->time_limit = time_limit;
    int pfd[2];
    if (pipe2(pfd, O_CLOEXEC) != 0)
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: %s: no pipe: %s", fn, what, strerror(errno));
    /* an anonymous file for the child's stdout and stderr: nothing to remove, whatever
     * happens to either process */
    int log_fd = memfd_create("cadmorph-child-log", MFD_CLOEXEC);
    if (log_fd < 0) log_fd = open("/dev/null", O_RDWR | O_CLOEXEC);

    const pid_t parent = getpid();
    const double t0 = cm_wtime();
    const pid_t pid = fork();
    if (pid < 0) {
        const int err = errno;
        close(pfd[0]);
        close(pfd[1]);
        if (log_fd >= 0) close(log_fd);
        return cm_error(ctx, err == ENOMEM || err == EAGAIN ? CM_ERR_NOMEM : CM_ERR_INTERNAL,
                        "%s: %s: cannot start a child process: %s", fn, what, strerror(err));
    }
    if (pid == 0) {
        close(pfd[0]);
        child_main(work, arg, pfd[1], log_fd, parent);
    }
    close(pfd[1]);

    const int limited = time_limit > 0 && isfinite(time_limit);
    const double deadline = t0 + time_limit;
    size_t cap = 0, len = 0;
    char *buf = NULL;
    cm_status st = CM_OK;
    double beat = t0;
    for (;;) {
        /* a progress point every CM_CHILD_BEAT s while the child works: the caller may stop
         * it there (the child is killed, as after the time limit) */
        const double now = cm_wtime();
        if (now - beat >= CM_CHILD_BEAT) {
            beat = now;
            if ((st = cm_progress(ctx, stage, 0, 1)) < 0) break;
        }
        int wait_ms = (int)(CM_CHILD_BEAT * 1000);
        if (limited) {
            const double left = deadline - now;
            if (left <= 0) {
                o->timed_out = 1;
                break;
            }
            if (left < CM_CHILD_BEAT) wait_ms = (int)ceil(left * 1000);
        }
        struct pollfd p = {.fd = pfd[0], .events = POLLIN};
        const int r = poll(&p, 1, wait_ms);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            st = cm_error(ctx, CM_ERR_INTERNAL, "%s: %s: poll: %s", fn, what, strerror(errno));
            break;
        }
        if (r == 0) continue; /* the deadline and the progress point are checked above */
        if (len == cap) {
            const size_t ncap = cap ? 2 * cap : 1 << 16;
            char *nb = realloc(buf, ncap);
            if (!nb) {
                st = cm_error(ctx, CM_ERR_NOMEM, "%s: %s: out of memory for its result", fn, what);
                break;
            }
            buf = nb;
            cap = ncap;
        }
        const ssize_t got = read(pfd[0], buf + len, cap - len);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) {
            st = cm_error(ctx, CM_ERR_INTERNAL, "%s: %s: read: %s", fn, what, strerror(errno));
            break;
        }
        if (got == 0) break; /* the child closed the pipe: it is ending */
        len += (size_t)got;
    }
    close(pfd[0]);
    if (o->timed_out || st < 0) kill(pid, SIGKILL);
    int wst = 0;
    while (waitpid(pid, &wst, 0) < 0 && errno == EINTR) {
    }
    o->seconds = cm_wtime() - t0;
    if (WIFEXITED(wst)) o->exit_code = WEXITSTATUS(wst);
    if (WIFSIGNALED(wst) && !o->timed_out) o->signal = WTERMSIG(wst);
    if (log_fd >= 0) {
        read_log_tail(log_fd, o);
        close(log_fd);
    }
    if (st < 0 || o->timed_out || o->signal || o->exit_code != 0) {
        free(buf);
        buf = NULL;
        len = 0;
    }
    *data = buf;
    *size = len;
    return st;
}

void cm_child_describe(const cm_child_outcome *o, char *buf, size_t n)
{
    int w;
    if (o->timed_out)
        w = snprintf(buf, n, "did not finish in %.3g s (killed)", o->time_limit);
    else if (o->signal)
        w = snprintf(buf, n, "%s (signal %d, %s)", o->signal == SIGABRT ? "aborted" : "crashed",
                     o->signal, strsignal(o->signal));
    else
        w = snprintf(buf, n, "exited with code %d", o->exit_code);
    if (o->log[0] && w >= 0 && (size_t)w < n) {
        /* TetGen's and gmsh's own last words: the assertion or error they printed */
        const char *tail = o->log;
        const size_t room = n - (size_t)w;
        const size_t len = strlen(tail);
        if (len + 16 > room && room > 16) tail += len - (room - 16);
        snprintf(buf + w, room, "; it printed: %s%s", tail == o->log ? "" : "...", tail);
    }
}
