/* Opening inputs (regular files only, never a blocking open, bounded lines), whole-file
 * reading and atomic output (a temporary file beside the target, renamed only on success),
 * shared by every module that reads or writes files, and the CLI. */
#include "cadmorph/core.h"
#include "live_paths.h"

#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* "a FIFO", "a directory", ...: what a path that is not a regular file is instead. */
static const char *file_kind(mode_t m)
{
    if (S_ISFIFO(m)) return "a FIFO";
    if (S_ISDIR(m)) return "a directory";
    if (S_ISCHR(m)) return "a character device";
    if (S_ISBLK(m)) return "a block device";
    if (S_ISSOCK(m)) return "a socket";
    return "neither file nor directory";
}

/* The one rule for opening an input (docs/DESIGN.md, "Reading input"): a regular file only,
 * and never a blocking open. A FIFO or a device blocks in open() itself, so the type is
 * looked at before opening, the open does not block, and the type of what was opened is
 * checked again (the path may have changed in between). 0 and the descriptor (blocking
 * again), or -1 with why[] saying why. */
static int open_regular(const char *path, struct stat *st, char *why, size_t why_size)
{
    if (stat(path, st) != 0) {
        snprintf(why, why_size, "cannot open: %s", strerror(errno));
        return -1;
    }
    if (!S_ISREG(st->st_mode)) {
        snprintf(why, why_size, "not a regular file (%s)", file_kind(st->st_mode));
        return -1;
    }
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        snprintf(why, why_size, "cannot open: %s", strerror(errno));
        return -1;
    }
    if (fstat(fd, st) != 0 || !S_ISREG(st->st_mode)) {
        snprintf(why, why_size, "not a regular file (%s)", file_kind(st->st_mode));
        close(fd);
        return -1;
    }
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    return fd;
}

static FILE *open_stream(const char *path, struct stat *st, char *why, size_t why_size)
{
    int fd = open_regular(path, st, why, why_size);
    if (fd < 0) return NULL;
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        snprintf(why, why_size, "cannot open: %s", strerror(errno));
        close(fd);
    }
    return f;
}

cm_status cm_file_open_read(cm_context *ctx, const char *path, FILE **f)
{
    if (f) *f = NULL;
    if (!path || !f) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_file_open_read: NULL argument");
    struct stat st;
    char why[160];
    *f = open_stream(path, &st, why, sizeof why);
    return *f ? CM_OK : cm_error(ctx, CM_ERR_IO, "%s: %s", path, why);
}

FILE *cm_file_open_quiet(const char *path, const char **why)
{
    /* thread-local: the sniffers run on any thread */
    static _Thread_local char reason[160];
    struct stat st;
    FILE *f = path ? open_stream(path, &st, reason, sizeof reason) : NULL;
    if (!path) snprintf(reason, sizeof reason, "no path");
    if (why) *why = f ? NULL : reason;
    return f;
}

static cm_status line_error(cm_context *ctx, const char *path, long line, const char *what,
                            const char *reason)
{
    return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s: not %s", path, line, reason,
                    what ? what : "a text file");
}

int cm_file_read_line(cm_context *ctx, FILE *f, const char *path, const char *what, long *line,
                      char *buf, size_t cap, size_t *len)
{
    if (len) *len = 0;
    if (!f || !buf || cap < 2 || !line || !len)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_file_read_line: bad argument");
    size_t n = 0;
    int c;
    /* byte by byte: a NUL is seen where fgets would hide it, and nothing past the bound is
     * kept (an endless line costs cap bytes, not the line) */
    while ((c = getc(f)) != EOF && c != '\n') {
        if (c == 0) {
            buf[n] = '\0';
            return line_error(ctx, path, *line + 1, what, "a NUL byte (a binary file)");
        }
        if (n + 1 >= cap) {
            char reason[64];
            snprintf(reason, sizeof reason, "longer than %zu bytes", cap - 1);
            buf[n] = '\0';
            return line_error(ctx, path, *line + 1, what, reason);
        }
        buf[n++] = (char)c;
    }
    buf[n] = '\0';
    if (ferror(f)) return cm_error(ctx, CM_ERR_IO, "%s:%ld: read error: %s", path, *line + 1, strerror(errno));
    if (c == EOF && n == 0) return 0;
    ++*line;
    *len = n;
    return 1;
}

cm_status cm_file_read_text(cm_context *ctx, const char *path, size_t max_line, const char *what,
                            char **data, size_t *size)
{
    if (data) *data = NULL;
    if (size) *size = 0;
    if (!path || !data || !size || max_line == 0)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_file_read_text: bad argument");
    FILE *f = NULL;
    cm_status s = cm_file_open_read(ctx, path, &f);
    if (s != CM_OK) return s;
    /* grown while read rather than sized by stat: a refused line stops the read early, so a
     * large file without newlines costs about max_line bytes */
    size_t cap = 0, n = 0, in_line = 0;
    long line = 0;
    char *buf = NULL;
    for (;;) {
        if (cap - n < 65536 + 1) {
            size_t ncap = cap ? 2 * cap : 65536 * 2;
            if (ncap < cap) {
                s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
                break;
            }
            char *nb = realloc(buf, ncap);
            if (!nb) {
                s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory for %zu bytes", path, ncap);
                break;
            }
            buf = nb;
            cap = ncap;
        }
        size_t got = fread(buf + n, 1, 65536, f);
        for (size_t i = n; i < n + got && s == CM_OK; ++i) {
            if (buf[i] == '\n') {
                ++line;
                in_line = 0;
            } else if (buf[i] == '\0') {
                s = line_error(ctx, path, line + 1, what, "a NUL byte (a binary file)");
            } else if (++in_line > max_line) {
                char reason[64];
                snprintf(reason, sizeof reason, "longer than %zu bytes", max_line);
                s = line_error(ctx, path, line + 1, what, reason);
            }
        }
        n += got;
        if (s != CM_OK) break;
        if (got < 65536) {
            if (ferror(f)) s = cm_error(ctx, CM_ERR_IO, "%s: read error after %zu bytes: %s", path, n, strerror(errno));
            break;
        }
    }
    fclose(f);
    if (s != CM_OK) {
        free(buf);
        return s;
    }
    buf[n] = '\0';
    *data = buf;
    *size = n;
    return CM_OK;
}

cm_status cm_file_read(cm_context *ctx, const char *path, char **data, size_t *size)
{
    *data = NULL;
    *size = 0;
    struct stat st;
    char why[160];
    FILE *f = open_stream(path, &st, why, sizeof why);
    if (!f) return cm_error(ctx, CM_ERR_IO, "%s: %s", path, why);
    /* One allocation of the file's size: a 1M-cell mesh is ~50 MB, and growing a buffer by
     * doubling costs as much as parsing it. */
    size_t len = (size_t)st.st_size;
    char *buf = malloc(len + 1);
    if (!buf) {
        fclose(f);
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory for %zu bytes", path, len);
    }
    size_t got = fread(buf, 1, len, f);
    int err = ferror(f);
    fclose(f);
    if (err || got != len) {
        free(buf);
        return cm_error(ctx, CM_ERR_IO, "%s: read error after %zu of %zu bytes", path, got, len);
    }
    buf[len] = '\0';
    *data = buf;
    *size = len;
    return CM_OK;
}

/* Live temporaries, so that a program's signal handler can remove them (cm_outfile_unlink_all
 * calls only unlink(), which is async-signal-safe; live_paths.h). */
static cm_live_table live_tmp;

void cm_outfile_unlink_all(void)
{
    for (int i = 0; i < CM_LIVE_SLOTS; ++i) {
        char *t = atomic_load(&live_tmp.slot[i]);
        if (t) unlink(t);
    }
}

cm_status cm_outfile_open(cm_context *ctx, const char *path, cm_outfile *out)
{
    memset(out, 0, sizeof *out);
    size_t n = strlen(path);
    /* The temporary is "<dir>/.cm-XXXXXX" rather than "<path>.tmp.XXXXXX": beside the target
     * (rename stays on one file system) but with a short name, so that outputs whose names
     * are near NAME_MAX (255) still work. */
    const char *slash = strrchr(path, '/');
    size_t dir = slash ? (size_t)(slash - path) + 1 : 0;
    static const char pattern[] = ".cm-XXXXXX";
    out->path = malloc(n + 1);
    out->tmp = malloc(dir + sizeof pattern);
    if (!out->path || !out->tmp) {
        cm_outfile_abort(out);
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
    }
    memcpy(out->path, path, n + 1);
    memcpy(out->tmp, path, dir);
    memcpy(out->tmp + dir, pattern, sizeof pattern);
    /* Registered before it exists: a signal may reach any thread (OpenMP workers too) while
     * mkstemp runs, and a handler that unlinks the template or a name mkstemp is still
     * filling in does no harm. */
    cm_live_add(&live_tmp, out->tmp);
    int fd = mkstemp(out->tmp);
    int err = errno;
    if (fd < 0) {
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: cannot create a temporary file beside it: %s",
                               path, strerror(err));
        cm_live_remove(&live_tmp, out->tmp);
        free(out->tmp);
        out->tmp = NULL;
        cm_outfile_abort(out);
        return s;
    }
    out->f = fdopen(fd, "wb");
    if (!out->f) {
        close(fd);
        cm_outfile_abort(out);
        return cm_error(ctx, CM_ERR_IO, "%s: cannot open for writing", path);
    }
    setvbuf(out->f, NULL, _IOFBF, 1 << 20);
    return CM_OK;
}

cm_status cm_outfile_commit(cm_context *ctx, cm_outfile *out)
{
    int bad = ferror(out->f);
    bad |= fclose(out->f) != 0;
    out->f = NULL;
    if (bad) {
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: write failed: %s", out->path, strerror(errno));
        cm_outfile_abort(out);
        return s;
    }
    /* mkstemp creates 0600; a mesh is an ordinary user file. */
    mode_t mask = umask(0);
    umask(mask);
    chmod(out->tmp, 0666 & ~mask);
    if (rename(out->tmp, out->path) != 0) {
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: cannot rename the temporary file: %s",
                               out->path, strerror(errno));
        cm_outfile_abort(out);
        return s;
    }
    cm_live_remove(&live_tmp, out->tmp);
    free(out->tmp);
    free(out->path);
    out->tmp = out->path = NULL;
    return CM_OK;
}

void cm_outfile_abort(cm_outfile *out)
{
    if (out->f) fclose(out->f);
    if (out->tmp) {
        remove(out->tmp);
        cm_live_remove(&live_tmp, out->tmp);
    }
    free(out->tmp);
    free(out->path);
    memset(out, 0, sizeof *out);
}

int cm_host_little_endian(void)
{
    const uint16_t one = 1;
    return *(const uint8_t *)&one == 1;
}
