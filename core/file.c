/* Whole-file reading and atomic output (a temporary file beside the target, renamed only
 * on success), shared by every module that reads or writes files, and the CLI. */
#include "cadmorph/core.h"

#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

cm_status cm_file_read(cm_context *ctx, const char *path, char **data, size_t *size)
{
    *data = NULL;
    *size = 0;
    /* A FIFO or a device blocks in open() itself: look before opening, then open without
     * blocking and check again what was opened (the path may have changed in between). */
    struct stat st;
    if (stat(path, &st) != 0) return cm_error(ctx, CM_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    if (!S_ISREG(st.st_mode)) return cm_error(ctx, CM_ERR_IO, "%s: not a regular file", path);
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return cm_error(ctx, CM_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return cm_error(ctx, CM_ERR_IO, "%s: not a regular file", path);
    }
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    FILE *f = fdopen(fd, "rb");
    if (!f) {
        close(fd);
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
    }
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

/* Live temporaries, so that a program's signal handler can remove them
 * (cm_outfile_unlink_all). Slots are claimed and released with atomic exchanges; the handler
 * only reads them and calls unlink(), which is async-signal-safe. A full table only means
 * that the extra temporaries are not removed on a signal. */
#define CM_LIVE_TMP 64
static _Atomic(char *) live_tmp[CM_LIVE_TMP];

static void live_add(char *tmp)
{
    for (int i = 0; i < CM_LIVE_TMP; ++i) {
        char *expected = NULL;
        if (atomic_compare_exchange_strong(&live_tmp[i], &expected, tmp)) return;
    }
}

static void live_remove(const char *tmp)
{
    for (int i = 0; i < CM_LIVE_TMP; ++i) {
        char *expected = (char *)tmp;
        if (atomic_compare_exchange_strong(&live_tmp[i], &expected, NULL)) return;
    }
}

void cm_outfile_unlink_all(void)
{
    for (int i = 0; i < CM_LIVE_TMP; ++i) {
        char *t = atomic_load(&live_tmp[i]);
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
    live_add(out->tmp);
    int fd = mkstemp(out->tmp);
    int err = errno;
    if (fd < 0) {
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: cannot create a temporary file beside it: %s",
                               path, strerror(err));
        live_remove(out->tmp);
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
    live_remove(out->tmp);
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
        live_remove(out->tmp);
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
