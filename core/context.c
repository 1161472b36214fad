/* The context: last message, thread count and the callbacks through which the library
 * talks to its caller (it never prints itself). */
#include "cadmorph/core.h"

#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#define CM_MESSAGE_MAX 2048

struct cm_context {
    char message[CM_MESSAGE_MAX];
    int threads;
    cm_log_fn log;
    void *log_user;
    cm_progress_fn progress;
    void *progress_user;
    /* set by cm_context_interrupt from any thread or a signal handler, consumed by
     * cm_progress: a lock-free atomic is async-signal-safe */
    atomic_int interrupt;
};

const char *cm_status_name(cm_status s)
{
    switch (s) {
    case CM_OK: return "ok";
    case CM_WARNING: return "warning";
    case CM_ERR_NOMEM: return "out of memory";
    case CM_ERR_ARGUMENT: return "invalid argument";
    case CM_ERR_IO: return "i/o error";
    case CM_ERR_FORMAT: return "format error";
    case CM_ERR_UNSUPPORTED: return "unsupported";
    case CM_ERR_MISMATCH: return "mismatch";
    case CM_ERR_NUMERIC: return "numerical error";
    case CM_ERR_CAD: return "CAD error";
    case CM_ERR_INTERNAL: return "internal error";
    case CM_ERR_REJECTED: return "result rejected";
    case CM_ERR_INTERRUPTED: return "interrupted";
    case CM_ERR_BUSY: return "busy";
    }
    return "unknown status";
}

int cm_status_is_input_error(cm_status s)
{
    return s == CM_ERR_IO || s == CM_ERR_FORMAT || s == CM_ERR_UNSUPPORTED ||
           s == CM_ERR_MISMATCH || s == CM_ERR_CAD || s == CM_ERR_NUMERIC;
}

cm_status cm_context_create(cm_context **ctx)
{
    if (!ctx) return CM_ERR_ARGUMENT;
    *ctx = calloc(1, sizeof **ctx);
    if (!*ctx) return CM_ERR_NOMEM;
    atomic_init(&(*ctx)->interrupt, 0);
    return CM_OK;
}

void cm_context_destroy(cm_context **ctx)
{
    if (!ctx || !*ctx) return;
    free(*ctx);
    *ctx = NULL;
}

const char *cm_context_message(const cm_context *ctx) { return ctx ? ctx->message : ""; }

void cm_context_clear(cm_context *ctx)
{
    if (!ctx) return;
    ctx->message[0] = '\0';
    atomic_store(&ctx->interrupt, 0);
}

void cm_context_set_threads(cm_context *ctx, int threads)
{
    if (ctx) ctx->threads = threads > 0 ? threads : 0;
}

/* Under an address-space limit (ulimit -v) libgomp aborts the process when it cannot create
 * a thread, so the count is capped to what the free address space backs with room to spare:
 * per thread its stack (RLIMIT_STACK) and a malloc arena (64 MB), for half of what is free. */
static int address_space_cap(int threads)
{
    struct rlimit as, st;
    if (getrlimit(RLIMIT_AS, &as) != 0 || as.rlim_cur == RLIM_INFINITY) return threads;
    unsigned long pages = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%lu", &pages) != 1) pages = 0;
        fclose(f);
    }
    double used = (double)pages * 4096.0, limit = (double)as.rlim_cur;
    double stack = 8.0 * 1048576.0;
    if (getrlimit(RLIMIT_STACK, &st) == 0 && st.rlim_cur != RLIM_INFINITY) stack = (double)st.rlim_cur;
    double spare = limit > used ? 0.5 * (limit - used) : 0.0;
    double fit = 1.0 + spare / (stack + 64.0 * 1048576.0);
    if (threads <= 0) threads = omp_get_max_threads();
    return fit < (double)threads ? (int)fit : threads;
}

int cm_context_threads(const cm_context *ctx)
{
    return address_space_cap(ctx ? ctx->threads : 0);
}

void cm_context_set_log(cm_context *ctx, cm_log_fn fn, void *user)
{
    if (!ctx) return;
    ctx->log = fn;
    ctx->log_user = user;
}

void cm_context_set_progress(cm_context *ctx, cm_progress_fn fn, void *user)
{
    if (!ctx) return;
    ctx->progress = fn;
    ctx->progress_user = user;
}

/* A message is one line (the CLI prints it as "cadmorph <cmd>: <message>"), and parts of it
 * come from files: control characters (newlines, escape sequences) become \n, \r, \t or
 * \xHH, so that nothing a file holds can break the line or drive the terminal. */
static void escape_controls(char *msg, size_t size)
{
    char out[CM_MESSAGE_MAX];
    size_t k = 0;
    for (const unsigned char *p = (const unsigned char *)msg; *p && k + 5 < sizeof out && k + 5 < size; ++p) {
        if (*p >= 0x20 && *p != 0x7f) {
            out[k++] = (char)*p;
        } else if (*p == '\n' || *p == '\r' || *p == '\t') {
            out[k++] = '\\';
            out[k++] = *p == '\n' ? 'n' : *p == '\r' ? 'r' : 't';
        } else {
            k += (size_t)snprintf(out + k, 5, "\\x%02x", *p);
        }
    }
    out[k] = '\0';
    memcpy(msg, out, k + 1);
}

cm_status cm_error(cm_context *ctx, cm_status code, const char *fmt, ...)
{
    if (ctx) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(ctx->message, sizeof ctx->message, fmt, ap);
        va_end(ap);
        escape_controls(ctx->message, sizeof ctx->message);
    }
    return code;
}

cm_status cm_error_prefix(cm_context *ctx, cm_status code, const char *fmt, ...)
{
    if (!ctx) return code;
    char prefix[CM_MESSAGE_MAX], old[CM_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    /* copy first: the message is rewritten from itself */
    snprintf(old, sizeof old, "%s", ctx->message);
    size_t n = strlen(prefix), size = sizeof ctx->message;
    if (n > size - 3) n = size - 3;
    memcpy(ctx->message, prefix, n);
    memcpy(ctx->message + n, ": ", 2);
    n += 2;
    size_t k = strlen(old);
    if (k > size - 1 - n) k = size - 1 - n; /* a long message loses its end, not its start */
    memcpy(ctx->message + n, old, k);
    ctx->message[n + k] = 0;
    escape_controls(ctx->message, sizeof ctx->message);
    return code;
}

int cm_context_threads_for(const cm_context *ctx, size_t n, size_t min_per_thread)
{
    int t = ctx ? cm_context_threads(ctx) : 0;
    if (t <= 0) t = omp_get_max_threads();
    size_t useful = min_per_thread ? n / min_per_thread : n;
    if (useful < (size_t)t) t = useful > 1 ? (int)useful : 1;
    return t;
}

double cm_bbox_diagonal(const double bb[6])
{
    double dx = bb[3] - bb[0], dy = bb[4] - bb[1], dz = bb[5] - bb[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

void cm_log(cm_context *ctx, cm_log_level level, const char *fmt, ...)
{
    if (!ctx || !ctx->log) return;
    char buf[CM_MESSAGE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    escape_controls(buf, sizeof buf);
    ctx->log(ctx->log_user, level, buf);
}

void cm_context_interrupt(cm_context *ctx)
{
    if (ctx) atomic_store(&ctx->interrupt, 1);
}

cm_status cm_progress(cm_context *ctx, const char *stage, double done, double total)
{
    if (!ctx) return CM_OK;
    if (ctx->progress) ctx->progress(ctx->progress_user, stage, done, total);
    if (!atomic_exchange(&ctx->interrupt, 0)) return CM_OK;
    return cm_error(ctx, CM_ERR_INTERRUPTED, "%s: interrupted", stage ? stage : "cadmorph");
}

double cm_memory_budget(void)
{
    const long pages = sysconf(_SC_PHYS_PAGES), psize = sysconf(_SC_PAGESIZE);
    return pages > 0 && psize > 0 ? 0.5 * (double)pages * (double)psize : 0.0;
}

double cm_wtime(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
