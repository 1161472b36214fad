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

int cm_text_parse_int(const char *b, const char *e, int64_t *v)
{
    int neg = 0;
    if (b < e && (*b == '+' || *b == '-')) neg = *b++ == '-';
    if (b == e) return 0;
    uint64_t x = 0;
    for (; b < e; ++b) {
        const unsigned d = (unsigned)(*b - '0');
        if (d > 9 || x > (UINT64_C(9223372036854775807) - d) / 10) return 0;
        x = 10 * x + d;
    }
    *v = neg ? -(int64_t)x : (int64_t)x;
    return 1;
}

cm_status cm_text_int(cm_context *ctx, cm_text *t, const char *what, int64_t *v)
{
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(t, &tok, &len)) return token_error(ctx, t, what, NULL, 0);
    if (!cm_text_parse_int(tok, tok + len, v)) return token_error(ctx, t, what, tok, len);
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

