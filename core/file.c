/* Whole-file reading and atomic output (a temporary file beside the target, renamed only
 * on success), shared by every module that reads or writes files, and the CLI. */
#include "cadmorph/core.h"

#include <errno.h>
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
    FILE *f = fopen(path, "rb");
    if (!f) return cm_error(ctx, CM_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        fclose(f);
        return cm_error(ctx, CM_ERR_IO, "%s: not a regular file", path);
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

cm_status cm_outfile_open(cm_context *ctx, const char *path, cm_outfile *out)
{
    memset(out, 0, sizeof *out);
    size_t n = strlen(path);
    out->path = malloc(n + 1);
    out->tmp = malloc(n + 16);
    if (!out->path || !out->tmp) {
        cm_outfile_abort(out);
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
    }
    memcpy(out->path, path, n + 1);
    snprintf(out->tmp, n + 16, "%s.tmp.XXXXXX", path);
    int fd = mkstemp(out->tmp);
    if (fd < 0) {
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: cannot create: %s", path, strerror(errno));
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
    free(out->tmp);
    free(out->path);
    out->tmp = out->path = NULL;
    return CM_OK;
}

void cm_outfile_abort(cm_outfile *out)
{
    if (out->f) fclose(out->f);
    if (out->tmp) remove(out->tmp);
    free(out->tmp);
    free(out->path);
    memset(out, 0, sizeof *out);
}

int cm_host_little_endian(void)
{
    const uint16_t one = 1;
    return *(const uint8_t *)&one == 1;
}
