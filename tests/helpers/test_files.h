/* Files for the tests: write a buffer or a string to a file, read a whole file back, and the
 * test's work directory with `test_at(name)` paths in it. Needs POSIX (cm_posix) for
 * mkdir/mkdtemp. */
#ifndef CADMORPH_TEST_FILES_H
#define CADMORPH_TEST_FILES_H

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* Writes the n bytes at data to path (created or truncated). 0 on success; -1 (with a line on
 * stderr) when the file cannot be opened or written, so the checks that read it fail. */
static inline int test_write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(data, 1, n, f) == n;
    if (f && fclose(f) != 0) ok = 0;
    if (!ok) fprintf(stderr, "test_write_file: cannot write %s\n", path);
    return ok ? 0 : -1;
}

/* Writes the NUL-terminated text to path (without the NUL). */
static inline int test_write_text(const char *path, const char *text)
{
    return test_write_file(path, text, strlen(text));
}

/* The whole file at path in a malloc'd buffer with a NUL after its last byte (so a text file
 * is a C string); its byte count in *size when size is not NULL. NULL (and *size = 0) when the
 * file cannot be opened or read completely. The caller frees. */
static inline char *test_read_file(const char *path, size_t *size)
{
    if (size) *size = 0;
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *d = NULL;
    long n = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    if (n >= 0 && fseek(f, 0, SEEK_SET) == 0 && (d = malloc((size_t)n + 1)) != NULL) {
        if (fread(d, 1, (size_t)n, f) == (size_t)n) {
            d[n] = '\0';
            if (size) *size = (size_t)n;
        } else {
            free(d);
            d = NULL;
        }
    }
    fclose(f);
    return d;
}

/* ---- the work directory: set once in main, then test_at(name) is a path in it */

static inline char *test_work_buffer_(void)
{
    static char dir[512];
    return dir;
}

/* The work directory ("" before it is set). */
static inline const char *test_work_dir(void)
{
    return test_work_buffer_();
}

/* parent/sub as the work directory, made with its missing parents (like mkdir -p). 0 when it
 * exists afterwards; -1 (with a line on stderr) otherwise. */
static inline int test_work_in(const char *parent, const char *sub)
{
    char *dir = test_work_buffer_();
    if (snprintf(dir, 512, "%s/%s", parent, sub) >= 512) {
        fprintf(stderr, "test_work_in: path too long: %s/%s\n", parent, sub);
        return -1;
    }
    for (char *p = dir + 1; *p; ++p)
        if (*p == '/') {
            *p = '\0';
            mkdir(dir, 0777);
            *p = '/';
        }
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "test_work_in: cannot make %s\n", dir);
        return -1;
    }
    return 0;
}

/* A fresh directory /tmp/cm-test-<name>-XXXXXX (mkdtemp) as the work directory; remove it
 * with test_work_remove. 0 on success, -1 otherwise. */
static inline int test_work_temp(const char *name)
{
    char *dir = test_work_buffer_();
    if (snprintf(dir, 512, "/tmp/cm-test-%s-XXXXXX", name) >= 512 || !mkdtemp(dir)) {
        fprintf(stderr, "test_work_temp: cannot make a directory for %s\n", name);
        dir[0] = '\0';
        return -1;
    }
    return 0;
}

/* Removes the work directory and all in it (rm -rf). 0 on success, -1 otherwise. */
static inline int test_work_remove(void)
{
    const char *dir = test_work_dir();
    if (!*dir) return -1;
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    return system(cmd) == 0 ? 0 : -1;
}

/* <work directory>/name, in one of 8 static buffers used in turn: valid until 8 more calls
 * (a call taking a few paths at once gets distinct ones). Aborts on a path too long rather
 * than write to a truncated name. */
static inline const char *test_at(const char *name)
{
    static char buf[8][1024];
    static int k;
    k = (k + 1) % 8;
    if (snprintf(buf[k], sizeof buf[k], "%s/%s", test_work_dir(), name) >= (int)sizeof buf[k]) {
        fprintf(stderr, "test_at: path too long: %s/%s\n", test_work_dir(), name);
        abort();
    }
    return buf[k];
}

#endif
