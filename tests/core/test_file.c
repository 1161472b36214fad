/* The input rule (core/file.c, docs/DESIGN.md "Reading input"): regular files only, refused
 * without blocking (a FIFO, a directory, a device); bounded lines; NUL bytes refused; what is
 * read is the file's bytes. */
#include "cadmorph/core.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static cm_context *ctx;
static char work[2048];

static const char *at(const char *name)
{
    static char p[4][2300];
    static int k;
    k = (k + 1) % 4;
    snprintf(p[k], sizeof p[k], "%s/file_%s", work, name);
    return p[k];
}

static const char *put(const char *name, const char *data, size_t n)
{
    const char *p = at(name);
    FILE *f = fopen(p, "wb");
    if (f) {
        fwrite(data, 1, n, f);
        fclose(f);
    }
    return p;
}

static int says(const char *what)
{
    const char *m = cm_context_message(ctx);
    const int ok = m && strstr(m, what);
    if (!ok) fprintf(stderr, "message '%s' lacks '%s'\n", m ? m : "(none)", what);
    return ok;
}

/* Every entry point refuses p with "<p>: not a regular file (<kind>)" and does not block. */
static void refuses(const char *p, const char *kind)
{
    char want[2400];
    snprintf(want, sizeof want, "%s: not a regular file (%s)", p, kind);
    char *data = NULL;
    size_t n = 1;
    FILE *f = NULL;
    CHECK(cm_file_read(ctx, p, &data, &n) == CM_ERR_IO && !data && n == 0);
    CHECK(says(want));
    CHECK(cm_file_read_text(ctx, p, 100, NULL, &data, &n) == CM_ERR_IO && !data);
    CHECK(says(want));
    CHECK(cm_file_open_read(ctx, p, &f) == CM_ERR_IO && !f);
    CHECK(says(want));
    const char *why = NULL;
    CHECK(cm_file_open_quiet(p, &why) == NULL && why && strstr(why, kind));
}

int main(int argc, char **argv)
{
    snprintf(work, sizeof work, "%s", argc > 2 ? argv[2] : ".");
    cm_context_create(&ctx);
    /* a FIFO with no writer: a blocking open would never return (the test would time out) */
    const char *fifo = at("fifo");
    unlink(fifo);
    CHECK(mkfifo(fifo, 0600) == 0);
    refuses(fifo, "a FIFO");
    refuses(work, "a directory");
    refuses("/dev/null", "a character device");

    /* a missing file: the reason from the system */
    FILE *f = NULL;
    CHECK(cm_file_open_read(ctx, at("missing"), &f) == CM_ERR_IO && says("cannot open: No such file"));

    /* lines: each one back without its newline, the line count, a last line without newline */
    const char *p = put("lines", "ab\n\ncd\r\nlast", 12);
    CHECK(cm_file_open_read(ctx, p, &f) == CM_OK && f);
    char buf[8];
    size_t len = 99;
    long line = 0;
    CHECK(cm_file_read_line(ctx, f, p, NULL, &line, buf, sizeof buf, &len) == 1 && !strcmp(buf, "ab") && len == 2 && line == 1);
    CHECK(cm_file_read_line(ctx, f, p, NULL, &line, buf, sizeof buf, &len) == 1 && !strcmp(buf, "") && len == 0 && line == 2);
    CHECK(cm_file_read_line(ctx, f, p, NULL, &line, buf, sizeof buf, &len) == 1 && !strcmp(buf, "cd\r") && line == 3);
    CHECK(cm_file_read_line(ctx, f, p, NULL, &line, buf, sizeof buf, &len) == 1 && !strcmp(buf, "last") && line == 4);
    CHECK(cm_file_read_line(ctx, f, p, NULL, &line, buf, sizeof buf, &len) == 0 && line == 4);
    fclose(f);

    /* a line of exactly cap - 1 bytes fits; one byte more is refused, naming the line */
    p = put("long", "1234567\n12345678\n", 17);
    CHECK(cm_file_open_read(ctx, p, &f) == CM_OK);
    line = 0;
    CHECK(cm_file_read_line(ctx, f, p, "a list", &line, buf, sizeof buf, &len) == 1 && len == 7);
    CHECK(cm_file_read_line(ctx, f, p, "a list", &line, buf, sizeof buf, &len) == CM_ERR_FORMAT);
    char want[2400];
    snprintf(want, sizeof want, "%s:2: longer than 7 bytes: not a list", p);
    CHECK(says(want));
    fclose(f);

    /* a NUL byte: a binary file */
    p = put("nul", "ab\nc\0d\n", 7);
    CHECK(cm_file_open_read(ctx, p, &f) == CM_OK);
    line = 0;
    CHECK(cm_file_read_line(ctx, f, p, NULL, &line, buf, sizeof buf, &len) == 1);
    CHECK(cm_file_read_line(ctx, f, p, NULL, &line, buf, sizeof buf, &len) == CM_ERR_FORMAT);
    snprintf(want, sizeof want, "%s:2: a NUL byte (a binary file): not a text file", p);
    CHECK(says(want));
    fclose(f);

    /* whole text files: the bytes as written (across the reader's 64 KiB chunks), and the
     * same refusals */
    const size_t big = 200000;
    char *text = malloc(big);
    for (size_t i = 0; i < big; ++i)
        text[i] = i % 100 == 99 ? '\n' : (char)('a' + i % 26);
    p = put("text", text, big);
    char *data = NULL;
    size_t n = 0;
    CHECK(cm_file_read_text(ctx, p, 99, NULL, &data, &n) == CM_OK && n == big && data &&
          !memcmp(data, text, big) && data[big] == '\0');
    free(data);
    CHECK(cm_file_read_text(ctx, p, 98, "a table", &data, &n) == CM_ERR_FORMAT && !data);
    snprintf(want, sizeof want, "%s:1: longer than 98 bytes: not a table", p);
    CHECK(says(want));
    text[150123] = '\0';
    p = put("text_nul", text, big);
    CHECK(cm_file_read_text(ctx, p, 99, NULL, &data, &n) == CM_ERR_FORMAT && !data);
    snprintf(want, sizeof want, "%s:1502: a NUL byte", p);
    CHECK(says(want));
    /* cm_file_read keeps NUL bytes (binary formats) */
    CHECK(cm_file_read(ctx, p, &data, &n) == CM_OK && n == big && data[150123] == '\0');
    free(data);
    free(text);
    p = put("empty", "", 0);
    CHECK(cm_file_read_text(ctx, p, 10, NULL, &data, &n) == CM_OK && n == 0 && data && !data[0]);
    free(data);

    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
