/* The gmsh reader's messages and values (an ASCII token, or raw little-endian bytes in the
 * binary sections): the cursor both msh_read.c and msh_read_blocks.c read with, a leaf below
 * them. */
#include "msh_read_internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

/* ---- messages ---- */

cm_status cm_msh_err(cm_msh_reader *r, cm_status code, int bin, size_t at, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (bin) return cm_error(r->ctx, code, "%s: byte %zu: %s", r->t.path, at, msg);
    return cm_error(r->ctx, code, "%s:%ld: %s", r->t.path, r->t.line, msg);
}

/* "expected <what>, got '<token>'" at the current line / byte. */
cm_status cm_msh_expected(cm_msh_reader *r, int bin, const char *what, const char *tok, size_t len)
{
    if (bin) {
        return cm_msh_err(r, CM_ERR_FORMAT, 1, r->t.pos, "expected %s, got end of file (%zu bytes left)",
                          what, r->t.size - r->t.pos);
    }
    if (!tok) return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected %s, got end of file", what);
    return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected %s, got '%.*s'", what,
                      (int)(len > 40 ? 40 : len), tok);
}

/* ---- values: an ASCII token, or raw little-endian bytes when bin ---- */

static int parse_i64(const char *s, size_t len, int64_t *v)
{
    size_t i = 0;
    int neg = 0;
    if (len > 0 && (s[0] == '-' || s[0] == '+')) {
        neg = s[0] == '-';
        i = 1;
    }
    if (i == len) return 0;
    uint64_t x = 0;
    for (; i < len; ++i) {
        unsigned d = (unsigned)(unsigned char)s[i] - '0';
        if (d > 9 || x > (UINT64_MAX - d) / 10) return 0;
        x = x * 10 + d;
    }
    if (x > (uint64_t)INT64_MAX + (uint64_t)neg) return 0;
    *v = neg ? (x == 0 ? 0 : -(int64_t)(x - 1) - 1) : (int64_t)x;
    return 1;
}

const unsigned char *cm_msh_bytes(cm_msh_reader *r, size_t n, const char *what)
{
    if (r->t.size - r->t.pos < n) {
        cm_msh_expected(r, 1, what, NULL, 0);
        return NULL;
    }
    const unsigned char *p = (const unsigned char *)r->t.data + r->t.pos;
    r->t.pos += n;
    return p;
}

int64_t cm_msh_get_size(const unsigned char *p, int dsize)
{
    if (dsize == 4) {
        uint32_t v;
        memcpy(&v, p, 4);
        return (int64_t)v;
    }
    uint64_t v;
    memcpy(&v, p, 8);
    return v > (uint64_t)INT64_MAX ? -1 : (int64_t)v;
}

cm_status cm_msh_int(cm_msh_reader *r, int bin, const char *what, int64_t *v)
{
    if (bin) {
        const unsigned char *p = cm_msh_bytes(r, 4, what);
        if (!p) return CM_ERR_FORMAT;
        int32_t x;
        memcpy(&x, p, 4);
        *v = x;
        return CM_OK;
    }
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len) || !parse_i64(tok, len, v))
        return cm_msh_expected(r, 0, what, tok, len);
    return CM_OK;
}

/* A count or tag (size_t in binary 4.1): never negative. */
cm_status cm_msh_size(cm_msh_reader *r, int bin, const char *what, int64_t *v)
{
    size_t at = r->t.pos;
    if (bin) {
        const unsigned char *p = cm_msh_bytes(r, (size_t)r->dsize, what);
        if (!p) return CM_ERR_FORMAT;
        *v = cm_msh_get_size(p, r->dsize);
        if (*v < 0) return cm_msh_err(r, CM_ERR_FORMAT, 1, at, "expected %s, got a value above 2^63", what);
        return CM_OK;
    }
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len) || !parse_i64(tok, len, v) || *v < 0)
        return cm_msh_expected(r, 0, what, tok, len);
    return CM_OK;
}

cm_status cm_msh_double(cm_msh_reader *r, int bin, const char *what, double *v)
{
    if (bin) {
        const unsigned char *p = cm_msh_bytes(r, 8, what);
        if (!p) return CM_ERR_FORMAT;
        memcpy(v, p, 8);
        return CM_OK;
    }
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_token(&r->t, &tok, &len)) return cm_msh_expected(r, 0, what, NULL, 0);
    /* The data is NUL-terminated and tokens end at white space, so strtod stays inside. */
    char *end = NULL;
    *v = strtod(tok, &end);
    if (end != tok + len) return cm_msh_expected(r, 0, what, tok, len);
    return CM_OK;
}

/* A coordinate: like cm_msh_double but NaN and infinities are errors. */
cm_status cm_msh_coord(cm_msh_reader *r, int bin, const char *what, double *v)
{
    size_t at = r->t.pos;
    long line = r->t.line;
    cm_status s = cm_msh_double(r, bin, what, v);
    if (s != CM_OK) return s;
    if (!isfinite(*v)) {
        if (bin) return cm_msh_err(r, CM_ERR_FORMAT, 1, at, "expected a finite %s, got %g", what, *v);
        r->t.line = line;
        return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected a finite %s, got %g", what, *v);
    }
    return CM_OK;
}

/* Count read from the file, checked against the bytes left before anything is allocated:
 * each item takes at least min_bytes, so a larger count cannot be honest. */
cm_status cm_msh_count(cm_msh_reader *r, int bin, const char *what, size_t min_bytes, int64_t *v)
{
    size_t at = r->t.pos;
    long line = r->t.line;
    cm_status s = cm_msh_size(r, bin, what, v);
    if (s != CM_OK) return s;
    size_t left = r->t.size - r->t.pos;
    if (min_bytes > 0 && (uint64_t)*v > left / min_bytes) {
        if (bin)
            return cm_msh_err(r, CM_ERR_FORMAT, 1, at,
                              "expected %s that fits the %zu bytes left, got %lld", what, left,
                              (long long)*v);
        r->t.line = line;
        return cm_msh_err(r, CM_ERR_FORMAT, 0, 0, "expected %s that fits the %zu bytes left, got %lld",
                          what, left, (long long)*v);
    }
    return CM_OK;
}

cm_status cm_msh_expect(cm_msh_reader *r, int bin, const char *word)
{
    const char *tok = NULL;
    size_t len = 0;
    size_t at = r->t.pos;
    if (!cm_text_token(&r->t, &tok, &len)) {
        if (bin) return cm_msh_err(r, CM_ERR_FORMAT, 1, at, "expected %s, got end of file", word);
        return cm_msh_expected(r, 0, word, NULL, 0);
    }
    if (len == strlen(word) && memcmp(tok, word, len) == 0) return CM_OK;
    if (bin)
        return cm_msh_err(r, CM_ERR_FORMAT, 1, (size_t)(tok - r->t.data),
                          "expected %s (are the counts right?), got '%.*s'", word,
                          (int)(len > 40 ? 40 : len), tok);
    return cm_msh_expected(r, 0, word, tok, len);
}

/* Binary data starts right after the newline that ends the header line. */
void cm_msh_to_binary(cm_msh_reader *r)
{
    cm_text_next_line(&r->t);
}

/* A name in double quotes (may hold spaces), or a bare token. Caller frees. */
cm_status cm_msh_string(cm_msh_reader *r, const char *what, char **out)
{
    *out = NULL;
    const char *tok = NULL;
    size_t len = 0;
    if (!cm_text_skip_space(&r->t)) return cm_msh_expected(r, 0, what, NULL, 0);
    const char *s = r->t.data + r->t.pos;
    if (*s == '"') {
        const char *e = s + 1;
        const char *end = r->t.data + r->t.size;
        while (e < end && *e != '"' && *e != '\n') ++e;
        if (e >= end || *e != '"') return cm_msh_expected(r, 0, what, s, (size_t)(e - s));
        tok = s + 1;
        len = (size_t)(e - s - 1);
        r->t.pos = (size_t)(e + 1 - r->t.data);
    } else if (!cm_text_token(&r->t, &tok, &len)) {
        return cm_msh_expected(r, 0, what, NULL, 0);
    }
    *out = malloc(len + 1);
    if (!*out) return cm_error(r->ctx, CM_ERR_NOMEM, "%s: out of memory", r->t.path);
    memcpy(*out, tok, len);
    (*out)[len] = '\0';
    return CM_OK;
}
