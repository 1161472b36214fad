/* The text cursor every text reader shares (text.h). */
#define _POSIX_C_SOURCE 200809L
#include "text.h"

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>

void cm_text_init(cm_text *t, const char *path, const char *data, size_t size)
{
    t->path = path;
    t->data = data;
    t->size = size;
    t->pos = 0;
    t->line = 1;
}

int cm_text_skip_space(cm_text *t)
{
    while (t->pos < t->size) {
        char c = t->data[t->pos];
        if (c == '\n') ++t->line;
        else if (c != ' ' && c != '\t' && c != '\r' && c != '\f' && c != '\v') return 1;
        ++t->pos;
    }
    return 0;
}

int cm_text_token(cm_text *t, const char **tok, size_t *len)
{
    if (!cm_text_skip_space(t)) return 0;
    size_t b = t->pos;
    while (t->pos < t->size && !isspace((unsigned char)t->data[t->pos])) ++t->pos;
    *tok = t->data + b;
    *len = t->pos - b;
    return 1;
}

static cm_status token_error(cm_context *ctx, cm_text *t, const char *what, const char *tok,
                             size_t len)
{
    if (!tok) return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected %s, got end of file", t->path, t->line, what);
    return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected %s, got '%.*s'", t->path, t->line, what,
                    (int)(len > 40 ? 40 : len), tok);
}

cm_status cm_text_int(cm_context *ctx, cm_text *t, const char *what, int64_t *v)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(t, &tok, &len)) return token_error(ctx, t, what, NULL, 0);
    char buf[32], *end;
    if (len >= sizeof buf) return token_error(ctx, t, what, tok, len);
    memcpy(buf, tok, len);
    buf[len] = '\0';
    errno = 0;
    long long x = strtoll(buf, &end, 10);
    if (*end || errno) return token_error(ctx, t, what, tok, len);
    *v = (int64_t)x;
    return CM_OK;
}

cm_status cm_text_double(cm_context *ctx, cm_text *t, const char *what, double *v)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(t, &tok, &len)) return token_error(ctx, t, what, NULL, 0);
    char buf[64], *end;
    if (len >= sizeof buf) return token_error(ctx, t, what, tok, len);
    memcpy(buf, tok, len);
    buf[len] = '\0';
    *v = strtod(buf, &end);
    if (*end) return token_error(ctx, t, what, tok, len);
    return CM_OK;
}

void cm_text_next_line(cm_text *t)
{
    while (t->pos < t->size && t->data[t->pos] != '\n') ++t->pos;
    if (t->pos < t->size) {
        ++t->pos;
        ++t->line;
    }
}

