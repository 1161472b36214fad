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
 * \xHH, so that nothing a file holds can break the line or drive the terminal. Writes at most
 * cap - 1 characters and a NUL. */
static void escape_controls(char *out, size_t cap, const char *msg)
{
    size_t k = 0;
    for (const unsigned char *p = (const unsigned char *)msg; *p && k + 5 < cap; ++p) {
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
}

/* Long words of a message are paths (the readers quote file contents at most 60 characters
 * long): a word longer than CM_WORD_MAX is shortened in the middle, "/head/.../name.vtu",
 * keeping its last component whole up to CM_NAME_MAX characters, so that a message about a
 * path of any length still fits the message buffer and its reason, after the path, is never
 * cut off. Words end at blanks and quotes; "name.vtu:12:" stays one word, its line kept. */
#define CM_WORD_MAX 200
#define CM_NAME_MAX 100

static int word_end(char c)
{
    return c == '\0' || c == ' ' || c == '\t' || c == '\'' || c == '"' || c == '`' || c == '(' ||
           c == ')' || c == ',' || c == ';';
}

/* Appends w[0..n) to out at *k (out holds cap bytes, the last for the NUL). */
static void put(char *out, size_t cap, size_t *k, const char *w, size_t n)
{
    for (size_t i = 0; i < n && *k + 1 < cap; ++i)
        out[(*k)++] = w[i];
}

/* One word of n characters, at most CM_WORD_MAX once shortened. */
static void put_word(char *out, size_t cap, size_t *k, const char *w, size_t n)
{
    if (n <= CM_WORD_MAX) {
        put(out, cap, k, w, n);
        return;
    }
    /* the last component: after the last '/' that is not the word's last character */
    size_t slash = n - 1;
    while (slash > 0 && w[slash - 1] != '/')
        --slash;
    const size_t name = n - slash; /* slash == 0: no directory part */
    if (slash > 0 && name <= CM_NAME_MAX) {
        /* "<head>/.../<name>", the head cut at a '/' where it has one */
        size_t head = CM_WORD_MAX - 5 - name, cut = head;
        while (cut > 1 && w[cut] != '/')
            --cut;
        if (w[cut] == '/') {
            put(out, cap, k, w, cut);
            put(out, cap, k, "/.../", 5);
        } else {
            put(out, cap, k, w, head);
            put(out, cap, k, ".../", 4);
        }
        put(out, cap, k, w + slash, name);
        return;
    }
    /* no directory part, or a name too long itself: its start and its end (the extension) */
    const size_t tail = (CM_WORD_MAX - 3) / 3, head = CM_WORD_MAX - 3 - tail;
    put(out, cap, k, w, head);
    put(out, cap, k, "...", 3);
    put(out, cap, k, w + n - tail, tail);
}

/* msg, escaped and with its long words shortened, into out (cap bytes). */
static void compose(char *out, size_t cap, const char *msg)
{
    char small[4 * CM_MESSAGE_MAX + 1];
    const size_t n = strlen(msg);
    /* escaping makes a character at most four */
    char *esc = 4 * n + 1 <= sizeof small ? small : malloc(4 * n + 1);
    size_t esc_cap = esc == small ? sizeof small : 4 * n + 1;
    if (!esc) esc = small, esc_cap = sizeof small; /* out of memory: the message's start */
    escape_controls(esc, esc_cap, msg);
    size_t k = 0;
    for (const char *p = esc; *p && k + 1 < cap;) {
        const char *e = p;
        while (!word_end(*e))
            ++e;
        put_word(out, cap, &k, p, (size_t)(e - p));
        if (*e) put(out, cap, &k, e++, 1);
        p = e;
    }
    out[k] = '\0';
    if (esc != small) free(esc);
}

/* The whole text of a printf-style message: on the stack when it fits, else on the heap (the
 * caller frees *heap); NULL when it cannot be formatted at all. */
static const char *format_all(char *buf, size_t size, char **heap, const char *fmt, va_list ap)
{
    va_list aq;
    va_copy(aq, ap);
    const int len = vsnprintf(buf, size, fmt, aq);
    va_end(aq);
    *heap = NULL;
    if (len < 0) return NULL;
    if ((size_t)len < size) return buf;
    *heap = malloc((size_t)len + 1);
    if (!*heap) return buf; /* out of memory: the message's start */
    vsnprintf(*heap, (size_t)len + 1, fmt, ap);
    return *heap;
}

cm_status cm_error(cm_context *ctx, cm_status code, const char *fmt, ...)
{
    if (!ctx) return code;
    char buf[CM_MESSAGE_MAX], *heap;
    va_list ap;
    va_start(ap, fmt);
    const char *msg = format_all(buf, sizeof buf, &heap, fmt, ap);
    va_end(ap);
    compose(ctx->message, sizeof ctx->message, msg ? msg : "");
    free(heap);
    return code;
}

cm_status cm_error_prefix(cm_context *ctx, cm_status code, const char *fmt, ...)
{
    if (!ctx) return code;
    char buf[CM_MESSAGE_MAX], *heap;
    va_list ap;
    va_start(ap, fmt);
    const char *prefix = format_all(buf, sizeof buf, &heap, fmt, ap);
    va_end(ap);
    if (!prefix) prefix = "";
    /* the old message is composed already (escaped, its words short): composing it again
     * leaves it as it is */
    const size_t np = strlen(prefix), no = strlen(ctx->message);
    char both[2 * CM_MESSAGE_MAX];
    char *all = np + 2 + no + 1 <= sizeof both ? both : malloc(np + 2 + no + 1);
    if (all) {
        memcpy(all, prefix, np);
        memcpy(all + np, ": ", 2);
        memcpy(all + np + 2, ctx->message, no + 1);
        compose(ctx->message, sizeof ctx->message, all);
    } else {
        compose(ctx->message, sizeof ctx->message, prefix); /* out of memory: where, at least */
    }
    if (all != both) free(all);
    free(heap);
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
    char buf[CM_MESSAGE_MAX], line[CM_MESSAGE_MAX], *heap;
    va_list ap;
    va_start(ap, fmt);
    const char *msg = format_all(buf, sizeof buf, &heap, fmt, ap);
    va_end(ap);
    compose(line, sizeof line, msg ? msg : "");
    free(heap);
    ctx->log(ctx->log_user, level, line);
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

double cm_memory_available(void)
{
    double avail = 0;
    FILE *f = fopen("/proc/meminfo", "r");
    if (f) {
        char line[256];
        while (fgets(line, sizeof line, f)) {
            double kb = 0;
            if (sscanf(line, "MemAvailable: %lf kB", &kb) == 1) {
                avail = 1024 * kb;
                break;
            }
        }
        fclose(f);
    }
    return avail > 0 ? avail : cm_memory_budget();
}

double cm_wtime(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
