/* Outputs of several files (docs/DESIGN.md, "Command line contract"): a directory built as a
 * temporary sibling and made visible by one rename (an exchange onto an existing one), files
 * committed together, a writer's lock, and the same-file test by device and inode. */
#define _GNU_SOURCE
#include "cadmorph/core.h"
#include "live_paths.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <dirent.h>

/* Live temporary directories, removed by cm_output_signal (live_paths.h). */
static cm_live_table live_dir;

/* While a group of renames runs, a signal is only recorded (cm_output_signal returns 1) and
 * raised again when the group is done, so that SIGINT/SIGTERM/SIGHUP never stop it half-way. */
static atomic_int committing;
static atomic_int pending_signal;

static void commit_begin(void)
{
    atomic_fetch_add(&committing, 1);
}

static void commit_end(void)
{
    if (atomic_fetch_sub(&committing, 1) == 1) {
        int sig = atomic_exchange(&pending_signal, 0);
        if (sig) raise(sig);
    }
}

/* rm -rf of parent/name with async-signal-safe calls only (openat, getdents64, unlinkat), so
 * that a signal handler may call it. Depth-limited: the outputs are a few levels deep. */
#ifdef SYS_getdents64
struct cm_dirent64 {
    uint64_t d_ino;
    int64_t d_off;
    unsigned short d_reclen;
    unsigned char d_type;
    char d_name[];
};
#endif

static void remove_at(int parent, const char *name, int depth)
{
    if (unlinkat(parent, name, 0) == 0 || errno == ENOENT || depth > 24) return;
#ifdef SYS_getdents64
    int fd = openat(parent, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) return;
    /* entries removed while listing may shift the listing: list again until it is empty */
    for (int pass = 0; pass < 8; ++pass) {
        _Alignas(8) char buf[2048];
        int any = 0;
        lseek(fd, 0, SEEK_SET);
        long n;
        while ((n = syscall(SYS_getdents64, fd, buf, sizeof buf)) > 0) {
            for (long off = 0; off < n;) {
                struct cm_dirent64 *e = (struct cm_dirent64 *)(void *)(buf + off);
                off += e->d_reclen;
                if (e->d_name[0] == '.' && (!e->d_name[1] || (e->d_name[1] == '.' && !e->d_name[2])))
                    continue;
                any = 1;
                remove_at(fd, e->d_name, depth + 1);
            }
        }
        if (!any) break;
    }
    close(fd);
#endif
    unlinkat(parent, name, AT_REMOVEDIR);
}

int cm_output_signal(int sig)
{
    int saved = errno;
    if (atomic_load(&committing)) {
        atomic_store(&pending_signal, sig);
        errno = saved;
        return 1;
    }
    for (int i = 0; i < CM_LIVE_SLOTS; ++i) {
        char *t = atomic_load(&live_dir.slot[i]);
        if (t) remove_at(AT_FDCWD, t, 0);
    }
    errno = saved;
    return 0;
}

int cm_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0) return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* mkdir -p; 0 or -1 (errno set). */
static int make_dirs(const char *path)
{
    size_t l = strlen(path);
    char *t = malloc(l + 1);
    if (!t) return -1;
    memcpy(t, path, l + 1);
    for (size_t i = 1; i <= l; ++i)
        if (t[i] == '/' || t[i] == '\0') {
            char c = t[i];
            t[i] = '\0';
            if (mkdir(t, 0777) != 0 && errno != EEXIST) {
                free(t);
                return -1;
            }
            t[i] = c;
        }
    free(t);
    struct stat st;
    if (stat(path, &st) != 0) return -1;
    if (!S_ISDIR(st.st_mode)) {
        errno = ENOTDIR;
        return -1;
    }
    return 0;
}

/* "<parent of path>/<prefix>XXXXXX" (malloc'ed) and the path without trailing slashes. */
static char *sibling(const char *path, const char *prefix, char **clean)
{
    size_t l = strlen(path);
    while (l > 1 && path[l - 1] == '/') --l;
    *clean = malloc(l + 1);
    if (!*clean) return NULL;
    memcpy(*clean, path, l);
    (*clean)[l] = '\0';
    const char *slash = strrchr(*clean, '/');
    size_t dir = slash ? (size_t)(slash - *clean) + 1 : 0;
    size_t p = strlen(prefix);
    char *t = malloc(dir + p + 7);
    if (!t) {
        free(*clean);
        *clean = NULL;
        return NULL;
    }
    memcpy(t, *clean, dir);
    memcpy(t + dir, prefix, p);
    memcpy(t + dir + p, "XXXXXX", 7);
    return t;
}

cm_status cm_outdir_open(cm_context *ctx, const char *path, cm_outdir *out)
{
    memset(out, 0, sizeof *out);
    out->tmp = sibling(path, ".cm-", &out->path);
    if (!out->tmp) {
        cm_outdir_abort(out);
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
    }
    struct stat st;
    if (stat(out->path, &st) == 0 && !S_ISDIR(st.st_mode)) {
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: exists and is not a directory", out->path);
        cm_outdir_abort(out);
        return s;
    }
    /* the parent, so that the temporary lies beside the target (one file system) */
    char *slash = strrchr(out->tmp, '/');
    if (slash && slash != out->tmp) {
        *slash = '\0';
        int bad = make_dirs(out->tmp);
        int err = errno;
        *slash = '/';
        if (bad) {
            cm_status s = cm_error(ctx, CM_ERR_IO, "%s: cannot create its directory: %s", out->path,
                                   strerror(err));
            cm_outdir_abort(out);
            return s;
        }
    }
    cm_live_add(&live_dir, out->tmp);
    if (!mkdtemp(out->tmp)) {
        int err = errno;
        cm_live_remove(&live_dir, out->tmp);
        free(out->tmp);
        out->tmp = NULL;
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: cannot create a temporary directory beside it: %s",
                               out->path, strerror(err));
        cm_outdir_abort(out);
        return s;
    }
    return CM_OK;
}

static int exchange(const char *a, const char *b)
{
#ifdef SYS_renameat2
    return (int)syscall(SYS_renameat2, AT_FDCWD, a, AT_FDCWD, b, 2 /* RENAME_EXCHANGE */);
#else
    (void)a;
    (void)b;
    errno = ENOSYS;
    return -1;
#endif
}

cm_status cm_outdir_commit(cm_context *ctx, cm_outdir *out)
{
    /* mkdtemp creates 0700; the output is an ordinary user directory */
    mode_t mask = umask(0);
    umask(mask);
    chmod(out->tmp, 0777 & ~mask);
    /* a new (or empty) target: one rename */
    if (rename(out->tmp, out->path) == 0) {
        cm_live_remove(&live_dir, out->tmp);
        cm_outdir_abort(out);
        return CM_OK;
    }
    if (errno != ENOTEMPTY && errno != EEXIST) {
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: cannot rename the temporary directory onto it: %s",
                               out->path, strerror(errno));
        cm_outdir_abort(out);
        return s;
    }
    /* an existing one: swapped in one step; the temporary name then holds the old directory */
    if (exchange(out->tmp, out->path) == 0) {
        cm_outdir_abort(out);
        return CM_OK;
    }
    if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP) {
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: cannot exchange the temporary directory with it: %s",
                               out->path, strerror(errno));
        cm_outdir_abort(out);
        return s;
    }
    /* A file system without the exchange: the old directory renamed aside onto an empty
     * ".cm-old-XXXXXX" sibling, then the new one into place. Between the two renames (a
     * power loss; signals wait) the target is missing and the old directory complete under
     * the ".cm-old-" name. */
    char *clean = NULL;
    char *old = sibling(out->path, ".cm-old-", &clean);
    free(clean);
    cm_status s = CM_OK;
    if (!old || !mkdtemp(old)) {
        s = cm_error(ctx, CM_ERR_IO, "%s: cannot create a temporary directory beside it", out->path);
    } else {
        commit_begin();
        if (rename(out->path, old) != 0) {
            s = cm_error(ctx, CM_ERR_IO, "%s: cannot move it aside: %s", out->path, strerror(errno));
            rmdir(old);
        } else if (rename(out->tmp, out->path) != 0) {
            s = cm_error(ctx, CM_ERR_IO, "%s: cannot rename the temporary directory onto it: %s",
                         out->path, strerror(errno));
            rename(old, out->path); /* the old one back */
        } else {
            cm_live_remove(&live_dir, out->tmp);
            remove_at(AT_FDCWD, old, 0);
        }
        commit_end();
    }
    free(old);
    cm_outdir_abort(out);
    return s;
}

void cm_outdir_abort(cm_outdir *out)
{
    if (out->tmp) {
        remove_at(AT_FDCWD, out->tmp, 0);
        cm_live_remove(&live_dir, out->tmp);
    }
    free(out->tmp);
    free(out->path);
    memset(out, 0, sizeof *out);
}

cm_status cm_outdir_merge(cm_context *ctx, cm_outdir *out, const char *dir, const char *const *inputs,
                          size_t n)
{
    /* a new (or empty) dir beside the temporary: one rename */
    if (rename(out->tmp, dir) == 0) {
        cm_live_remove(&live_dir, out->tmp);
        cm_outdir_abort(out);
        return CM_OK;
    }
    DIR *d = opendir(out->tmp);
    if (!d) {
        cm_status s = cm_error(ctx, CM_ERR_IO, "%s: cannot list the temporary directory: %s", dir,
                               strerror(errno));
        cm_outdir_abort(out);
        return s;
    }
    /* the names first: every one checked against the inputs before the first rename */
    char **names = NULL;
    size_t k = 0, cap = 0;
    cm_status s = CM_OK;
    struct dirent *e;
    while (s == CM_OK && (e = readdir(d))) {
        if (e->d_name[0] == '.' && (!e->d_name[1] || !strcmp(e->d_name, ".."))) continue;
        if (k == cap) {
            cap = cap ? 2 * cap : 16;
            char **grown = realloc(names, cap * sizeof *names);
            if (!grown) {
                s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", dir);
                break;
            }
            names = grown;
        }
        size_t l = strlen(dir) + strlen(e->d_name) + 2;
        if (!(names[k] = malloc(l))) {
            s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", dir);
            break;
        }
        snprintf(names[k++], l, "%s/%s", dir, e->d_name);
    }
    closedir(d);
    for (size_t i = 0; s == CM_OK && i < k; ++i)
        for (size_t j = 0; j < n; ++j)
            if (inputs[j] && cm_same_file(names[i], inputs[j])) {
                s = cm_error(ctx, CM_ERR_ARGUMENT, "output %s is the input %s: refusing to overwrite it",
                             names[i], inputs[j]);
                break;
            }
    if (s == CM_OK) {
        commit_begin();
        size_t t = strlen(out->tmp);
        for (size_t i = 0; s == CM_OK && i < k; ++i) {
            const char *base = strrchr(names[i], '/') + 1;
            char *from = malloc(t + strlen(base) + 2);
            if (!from) {
                s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", dir);
                break;
            }
            sprintf(from, "%s/%s", out->tmp, base);
            if (rename(from, names[i]) != 0)
                s = cm_error(ctx, CM_ERR_IO, "%s: cannot rename the temporary file onto it: %s", names[i],
                             strerror(errno));
            free(from);
        }
        commit_end();
    }
    for (size_t i = 0; i < k; ++i)
        free(names[i]);
    free(names);
    cm_outdir_abort(out);
    return s;
}

cm_status cm_outfile_commit_all(cm_context *ctx, cm_outfile *outs, size_t n, const char *from,
                                const char *to)
{
    /* everything written out before the first rename: a full disk shows here */
    cm_status s = CM_OK;
    for (size_t i = 0; s == CM_OK && i < n; ++i)
        if (outs[i].f && (fflush(outs[i].f) != 0 || ferror(outs[i].f)))
            s = cm_error(ctx, CM_ERR_IO, "%s: write failed: %s", outs[i].path, strerror(errno));
    commit_begin();
    if (s == CM_OK && from && rename(from, to) != 0)
        s = cm_error(ctx, CM_ERR_IO, "%s: cannot rename the temporary file onto it: %s", to, strerror(errno));
    for (size_t i = 0; i < n; ++i) {
        if (!outs[i].f) continue;
        if (s != CM_OK) {
            cm_outfile_abort(&outs[i]);
            continue;
        }
        s = cm_outfile_commit(ctx, &outs[i]);
    }
    commit_end();
    return s;
}

cm_status cm_output_lock(cm_context *ctx, const char *dir, int *fd)
{
    *fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (*fd < 0) return cm_error(ctx, CM_ERR_IO, "%s: cannot open the directory: %s", dir, strerror(errno));
    if (flock(*fd, LOCK_EX | LOCK_NB) != 0) {
        int err = errno;
        close(*fd);
        *fd = -1;
        if (err == EWOULDBLOCK) return cm_error(ctx, CM_ERR_BUSY, "%s: another process is writing it", dir);
        return cm_error(ctx, CM_ERR_IO, "%s: cannot lock it: %s", dir, strerror(err));
    }
    return CM_OK;
}

void cm_output_unlock(int *fd)
{
    if (*fd >= 0) close(*fd);
    *fd = -1;
}
