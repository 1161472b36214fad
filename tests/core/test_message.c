/* The context's messages: one line whatever the text holds, and a message about a path of any
 * length keeps its reason: long words (paths) are shortened in the middle, the file name kept
 * whole where it is short enough, so that the line stays below the message buffer
 * (core/context.c). */
#include "cadmorph/core.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

#define MESSAGE_MAX 2048 /* core/context.c */

static cm_context *ctx;

/* A path of n characters: "/work/" then directories of 30 characters, then name. */
static char *long_path(size_t n, const char *name)
{
    char *p = malloc(n + 1);
    size_t k = (size_t)snprintf(p, n + 1, "/work/");
    for (; k + strlen(name) < n; ++k)
        p[k] = k % 31 == 30 ? '/' : 'd';
    if (p[k - 1] != '/') p[k - 1] = '/';
    snprintf(p + k, n + 1 - k, "%s", name);
    return p;
}

static void test_short_messages_unchanged(void)
{
    const char *text = "cm_mesh_read: /tmp/a/b/c.msh:12: expected 4 nodes, got 3 ('x y')";
    cm_error(ctx, CM_ERR_FORMAT, "%s", text);
    CHECK(!strcmp(cm_context_message(ctx), text));
    /* a word of exactly 200 characters (the path and its colon) stays */
    char *p = long_path(199, "name.vtu");
    CHECK(strlen(p) == 199);
    cm_error(ctx, CM_ERR_IO, "%s: cannot open", p);
    CHECK_MSG(!strncmp(cm_context_message(ctx), p, 199) && !strcmp(cm_context_message(ctx) + 199, ": cannot open"),
              "%s", cm_context_message(ctx));
    free(p);
    /* one more: shortened */
    p = long_path(200, "name.vtu");
    cm_error(ctx, CM_ERR_IO, "%s: cannot open", p);
    CHECK_MSG(strstr(cm_context_message(ctx), "/.../name.vtu: cannot open"), "%s", cm_context_message(ctx));
    free(p);
}

static void test_long_path(void)
{
    /* 4,204 characters, the reason after it: all of the reason, the head and the file name */
    char *p = long_path(4204, "tail.vtu");
    CHECK(strlen(p) == 4204);
    cm_error(ctx, CM_ERR_IO, "%s: cannot create a temporary file beside it: %s", p, "File name too long");
    const char *msg = cm_context_message(ctx);
    CHECK_MSG(strlen(msg) <= 200 + 70, "%zu characters", strlen(msg));
    CHECK_MSG(!strncmp(msg, "/work/dddd", 10), "%s", msg);
    CHECK_MSG(strstr(msg, "/.../tail.vtu: cannot create a temporary file beside it: File name too long"),
              "%s", msg);
    /* the prefix of a caller goes through the same rule, the old message stays as it was */
    char before[MESSAGE_MAX];
    snprintf(before, sizeof before, "%s", msg);
    cm_error_prefix(ctx, CM_ERR_IO, "%s", p);
    msg = cm_context_message(ctx);
    const char *second = strstr(msg, ": ");
    CHECK_MSG(second && !strcmp(second + 2, before), "%s", msg);
    CHECK_MSG(strstr(msg, "/.../tail.vtu: /work/"), "%s", msg);
    CHECK(strlen(msg) < 520);
    /* a line number after the name stays with it */
    cm_error(ctx, CM_ERR_FORMAT, "%s:%d: expected a number", p, 12);
    CHECK_MSG(strstr(cm_context_message(ctx), "/.../tail.vtu:12: expected a number"), "%s", cm_context_message(ctx));
    /* several long paths in one message: each shortened, all of the text kept */
    cm_error(ctx, CM_ERR_MISMATCH, "%s and %s are the same file (%s)", p, p, "device 1, inode 2");
    msg = cm_context_message(ctx);
    CHECK_MSG(strstr(msg, "/.../tail.vtu and /work/") && strstr(msg, "/.../tail.vtu are the same file (device 1, inode 2)"),
              "%s", msg);
    free(p);
}

static void test_long_name(void)
{
    /* a file name longer than 100 characters: the word's start and its end (the extension) */
    char name[400];
    memset(name, 'n', 300);
    strcpy(name + 300, "_end.msh");
    char *p = long_path(1000, name);
    cm_error(ctx, CM_ERR_IO, "%s: cannot open: %s", p, "No such file or directory");
    const char *msg = cm_context_message(ctx);
    CHECK_MSG(strlen(msg) <= 200 + 40, "%s", msg);
    CHECK_MSG(!strncmp(msg, "/work/ddd", 9) && strstr(msg, "...nnn"), "%s", msg);
    CHECK_MSG(strstr(msg, "nnn_end.msh: cannot open: No such file or directory"), "%s", msg);
    free(p);
    /* no directory at all: the same */
    char word[3000];
    memset(word, 'w', 2990);
    strcpy(word + 2990, ".csv");
    cm_error(ctx, CM_ERR_FORMAT, "%s:1: no header", word);
    msg = cm_context_message(ctx);
    CHECK_MSG(strlen(msg) <= 220 && strstr(msg, "www...www") && strstr(msg, "www.csv:1: no header"), "%s", msg);
}

static void test_one_line(void)
{
    /* control characters in a long path: escaped, then shortened, never a second line */
    char *p = long_path(3000, "new\nline.vtu");
    cm_error(ctx, CM_ERR_IO, "%s: cannot open\r\n", p);
    const char *msg = cm_context_message(ctx);
    CHECK(strchr(msg, '\n') == NULL && strchr(msg, '\r') == NULL);
    CHECK_MSG(strstr(msg, "/.../new\\nline.vtu: cannot open\\r\\n"), "%s", msg);
    free(p);
    /* whatever the length, the message fits its buffer */
    char *huge = malloc(100001);
    memset(huge, 'x', 100000);
    huge[100000] = 0;
    for (size_t i = 100; i < 100000; i += 101) huge[i] = ' ';
    cm_error(ctx, CM_ERR_IO, "%s", huge);
    CHECK(strlen(cm_context_message(ctx)) == MESSAGE_MAX - 1);
    free(huge);
}

int main(void)
{
    cm_context_create(&ctx);
    test_short_messages_unchanged();
    test_long_path();
    test_long_name();
    test_one_line();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
