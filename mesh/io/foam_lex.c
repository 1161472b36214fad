/* OpenFOAM files: loading (plain or .gz), the FoamFile header, tokens, and the list forms
 * polyMesh files use ("N(...)", "N{v}", ASCII or a raw binary block after '('). */
#define _POSIX_C_SOURCE 200809L
#include "foam_internal.h"

#include "text.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

static char *join(const char *dir, const char *name)
{
    size_t a = strlen(dir), b = strlen(name);
    char *p = malloc(a + b + 2);
    if (!p) return NULL;
    memcpy(p, dir, a);
    p[a] = '/';
    memcpy(p + a + 1, name, b + 1);
    return p;
}

int cm_foam_join(char *out, size_t cap, const char *dir, const char *name, const char *suffix)
{
    size_t a = strlen(dir), b = strlen(name), c = suffix ? strlen(suffix) : 0;
    if (a + b + c + 2 > cap) {
        if (cap) out[0] = '\0';
        return -1;
    }
    memcpy(out, dir, a);
    out[a] = '/';
    memcpy(out + a + 1, name, b);
    if (c) memcpy(out + a + 1 + b, suffix, c);
    out[a + 1 + b + c] = '\0';
    return 0;
}

/* An inflated stream is bounded by what its content can hold, so that a small .gz cannot
 * become gigabytes in memory (1 MB of gzip'ed blanks inflates to 1 GB):
 * - the FoamFile header, banner and comments before the file's first count (the list size,
 *   or the number of patches or zones) may take GZ_PREFIX = 1 MiB (OpenFOAM writes ~1 KB);
 *   a stream of at most that much is read whatever it holds;
 * - after the count N, entry_bytes per entry (the caller's: 64 for a label, 256 for a point,
 *   1 KiB for a face, 16 KiB for a patch: an entry written by OpenFOAM in ASCII at full
 *   precision takes a quarter of that or less, in binary less still), N taken as at most the
 *   count the other files allow (max_count), plus GZ_PREFIX for what follows the list;
 * - nowhere more than GZ_PREFIX blank bytes in a row (OpenFOAM indents by a few bytes):
 *   blanks, in one gzip member or many concatenated, are the cheapest way to a huge stream.
 * Beyond the budget the file is refused with the inflated offset, and the buffer never grows
 * past the budget (+1 byte to see that there is more). What is left: a file whose N entries
 * are really there (repeated, so they compress 1000:1) is read, as any file of N entries. */
enum { GZ_PREFIX = 1 << 20, GZ_CHUNK = 1 << 16 };

static int is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

/* The first count after the FoamFile header in d[0, n): 1 with *count and *end set; 0 when it
 * is not there (the parser then reports what is). */
static int first_count(const char *d, size_t n, int64_t *count, size_t *end)
{
    cm_foam_file tmp;
    memset(&tmp, 0, sizeof tmp);
    tmp.data = (char *)d;
    tmp.size = n;
    cm_foam_lex lx;
    cm_foam_lex_init(&lx, &tmp, 0);
    cm_foam_tok t = cm_foam_next(&lx);
    if (t.kind != CM_FOAM_WORD || t.len != 8 || memcmp(t.s, "FoamFile", 8)) return 0;
    t = cm_foam_next(&lx);
    if (t.kind != CM_FOAM_PUNCT || t.s[0] != '{') return 0;
    for (int depth = 1; depth > 0;) {
        t = cm_foam_next(&lx);
        if (t.kind == CM_FOAM_EOF) return 0;
        if (t.kind == CM_FOAM_PUNCT && t.s[0] == '{') ++depth;
        if (t.kind == CM_FOAM_PUNCT && t.s[0] == '}') --depth;
    }
    t = cm_foam_next(&lx);
    if (t.kind == CM_FOAM_WORD && t.len > 5 && !memcmp(t.s, "List<", 5)) t = cm_foam_next(&lx);
    /* a count cut by the end of what was inflated is not a count yet */
    if (t.kind != CM_FOAM_WORD || lx.pos >= n || !cm_text_parse_int(t.s, t.s + t.len, count) || *count < 0)
        return 0;
    *end = lx.pos;
    return 1;
}

static size_t budget_of(size_t end, int64_t count, int64_t max_count, uint64_t entry_bytes)
{
    uint64_t c = (uint64_t)count;
    if (max_count >= 0 && c > (uint64_t)max_count) c = (uint64_t)max_count;
    uint64_t b = entry_bytes && c > (UINT64_MAX - end - GZ_PREFIX) / entry_bytes
                     ? UINT64_MAX
                     : end + GZ_PREFIX + c * entry_bytes;
    return b > SIZE_MAX - 2 ? SIZE_MAX - 2 : (size_t)b;
}

/* gzread inflates gzip (members concatenated too) and passes plain files through, so one path
 * reads both; opened by the input rule of core/file.c (a FIFO would block in open()). */
static cm_status read_gz(cm_context *ctx, const char *path, uint64_t entry_bytes, int64_t max_count,
                         char **data, size_t *size)
{
    FILE *f = NULL;
    cm_status s = cm_file_open_read(ctx, path, &f);
    if (s != CM_OK) return cm_error_prefix(ctx, s, "cm_mesh_read");
    int fd = dup(fileno(f));
    fclose(f);
    gzFile g = fd >= 0 ? gzdopen(fd, "rb") : NULL;
    if (!g) {
        if (fd >= 0) close(fd);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", path);
    }
    size_t cap = GZ_CHUNK, n = 0, limit = GZ_PREFIX, blank = 0;
    int64_t count = -1;
    char *buf = malloc(cap + 1);
    while (s == CM_OK) {
        if (!buf) {
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", path);
            break;
        }
        /* read up to one byte past the budget, to see that there is more */
        size_t want = limit + 1 - n < GZ_CHUNK ? limit + 1 - n : GZ_CHUNK;
        if (n + want > cap) {
            size_t nc = cap < SIZE_MAX / 4 ? 2 * cap : SIZE_MAX / 2;
            if (nc < n + want) nc = n + want;
            if (nc > limit + 1) nc = limit + 1;
            char *nb = realloc(buf, nc + 1);
            if (!nb) free(buf);
            buf = nb;
            cap = nc;
            continue;
        }
        int got = gzread(g, buf + n, (unsigned)want);
        if (got < 0) {
            int e;
            const char *msg = gzerror(g, &e);
            s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: inflated offset %zu: corrupt gzip data: %s", path, n, msg);
            break;
        }
        if (got == 0) break;
        for (size_t i = n; i < n + (size_t)got; ++i) {
            blank = is_blank(buf[i]) ? blank + 1 : 0;
            if (blank > GZ_PREFIX) {
                s = cm_error(ctx, CM_ERR_FORMAT,
                             "cm_mesh_read: %s: inflated offset %zu: more than %d blank bytes in a row", path,
                             i, GZ_PREFIX);
                break;
            }
        }
        n += (size_t)got;
        if (s != CM_OK || n <= limit) continue;
        size_t end = 0;
        if (count < 0 && first_count(buf, n, &count, &end)) {
            limit = budget_of(end, count, max_count, entry_bytes);
            if (n <= limit) continue;
        }
        if (count < 0)
            s = cm_error(ctx, CM_ERR_FORMAT,
                         "cm_mesh_read: %s: inflated offset %zu: no FoamFile header and list size in the first %d bytes",
                         path, n - 1, GZ_PREFIX);
        else
            s = cm_error(ctx, CM_ERR_FORMAT,
                         "cm_mesh_read: %s: inflated offset %zu: more than the %zu bytes %lld entries can take "
                         "(%llu per entry)",
                         path, limit, limit, (long long)(max_count >= 0 && count > max_count ? max_count : count),
                         (unsigned long long)entry_bytes);
    }
    gzclose(g);
    if (s != CM_OK) {
        free(buf);
        return s;
    }
    buf[n] = '\0';
    *data = buf;
    *size = n;
    return CM_OK;
}

static int is_file(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

static cm_status parse_header(cm_context *ctx, cm_foam_file *f);

cm_status cm_foam_file_load(cm_context *ctx, const char *dir, const char *name, int optional,
                            cm_foam_file *f)
{
    return cm_foam_file_load_bounded(ctx, dir, name, optional, 1024, -1, f);
}

cm_status cm_foam_file_load_bounded(cm_context *ctx, const char *dir, const char *name, int optional,
                                    uint64_t entry_bytes, int64_t max_count, cm_foam_file *f)
{
    memset(f, 0, sizeof *f);
    f->label_bytes = 4;
    f->scalar_bytes = 8;
    char *plain = join(dir, name), *gz = NULL;
    if (!plain) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    if (is_file(plain)) {
        f->path = plain;
    } else {
        size_t l = strlen(plain);
        gz = malloc(l + 4);
        if (!gz) {
            free(plain);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        }
        memcpy(gz, plain, l);
        memcpy(gz + l, ".gz", 4);
        if (!is_file(gz)) {
            cm_status s = optional ? CM_OK
                                   : cm_error(ctx, CM_ERR_IO,
                                              "cm_mesh_read: %s: no such file (nor %s.gz) in the polyMesh",
                                              plain, name);
            free(plain);
            free(gz);
            return s;
        }
        free(plain);
        f->path = gz;
        f->gz = 1;
    }
    cm_status s;
    if (f->gz) {
        s = read_gz(ctx, f->path, entry_bytes, max_count, &f->data, &f->size);
    } else {
        s = cm_file_read(ctx, f->path, &f->data, &f->size);
        /* A gzip file under the plain name: read it through zlib too. */
        if (s == CM_OK && f->size >= 2 && (unsigned char)f->data[0] == 0x1f &&
            (unsigned char)f->data[1] == 0x8b) {
            free(f->data);
            f->data = NULL;
            f->gz = 1;
            s = read_gz(ctx, f->path, entry_bytes, max_count, &f->data, &f->size);
        }
    }
    if (s == CM_OK) s = parse_header(ctx, f);
    if (s != CM_OK) cm_foam_file_free(f);
    return s;
}

void cm_foam_file_free(cm_foam_file *f)
{
    if (!f) return;
    free(f->path);
    free(f->data);
    memset(f, 0, sizeof *f);
}

/* ---- tokens ---- */

void cm_foam_lex_init(cm_foam_lex *lx, const cm_foam_file *f, size_t pos)
{
    lx->f = f;
    lx->pos = 0;
    lx->line = 1;
    for (size_t i = 0; i < pos && i < f->size; ++i)
        if (f->data[i] == '\n') ++lx->line;
    lx->pos = pos;
}

static void skip_space(cm_foam_lex *lx)
{
    const char *d = lx->f->data;
    size_t n = lx->f->size;
    while (lx->pos < n) {
        char c = d[lx->pos];
        if (c == '\n') {
            ++lx->line;
            ++lx->pos;
        } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
            ++lx->pos;
        } else if (c == '/' && lx->pos + 1 < n && d[lx->pos + 1] == '/') {
            while (lx->pos < n && d[lx->pos] != '\n') ++lx->pos;
        } else if (c == '/' && lx->pos + 1 < n && d[lx->pos + 1] == '*') {
            lx->pos += 2;
            while (lx->pos < n && !(d[lx->pos] == '*' && lx->pos + 1 < n && d[lx->pos + 1] == '/')) {
                if (d[lx->pos] == '\n') ++lx->line;
                ++lx->pos;
            }
            lx->pos = lx->pos + 2 < n ? lx->pos + 2 : n;
        } else {
            return;
        }
    }
}

static int is_punct(char c)
{
    return c == '(' || c == ')' || c == '{' || c == '}' || c == '[' || c == ']' || c == ';';
}

cm_foam_tok cm_foam_next(cm_foam_lex *lx)
{
    skip_space(lx);
    cm_foam_tok t = {CM_FOAM_EOF, NULL, 0, lx->pos};
    const char *d = lx->f->data;
    size_t n = lx->f->size;
    if (lx->pos >= n) return t;
    char c = d[lx->pos];
    if (is_punct(c)) {
        t.kind = CM_FOAM_PUNCT;
        t.s = d + lx->pos++;
        t.len = 1;
    } else if (c == '"') {
        size_t b = ++lx->pos;
        while (lx->pos < n && d[lx->pos] != '"') {
            if (d[lx->pos] == '\\' && lx->pos + 1 < n) ++lx->pos;
            if (d[lx->pos] == '\n') ++lx->line;
            ++lx->pos;
        }
        t.kind = CM_FOAM_STRING;
        t.s = d + b;
        t.len = lx->pos - b;
        if (lx->pos < n) ++lx->pos;
    } else {
        size_t b = lx->pos;
        while (lx->pos < n) {
            char e = d[lx->pos];
            if (e == ' ' || e == '\t' || e == '\n' || e == '\r' || e == '"' || is_punct(e)) break;
            if (e == '/' && lx->pos + 1 < n && (d[lx->pos + 1] == '/' || d[lx->pos + 1] == '*')) break;
            ++lx->pos;
        }
        t.kind = CM_FOAM_WORD;
        t.s = d + b;
        t.len = lx->pos - b;
    }
    return t;
}

cm_foam_tok cm_foam_peek(cm_foam_lex *lx)
{
    cm_foam_lex save = *lx;
    cm_foam_tok t = cm_foam_next(lx);
    *lx = save;
    return t;
}

const char *cm_foam_where(const cm_foam_lex *lx, char *buf, size_t cap)
{
    snprintf(buf, cap, "%s:%ld", lx->f->path, lx->line);
    return buf;
}

static cm_status tok_error(cm_context *ctx, const cm_foam_lex *lx, const char *what, cm_foam_tok t)
{
    char w[600];
    cm_foam_where(lx, w, sizeof w);
    if (t.kind == CM_FOAM_EOF)
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: expected %s, got end of file", w, what);
    return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: expected %s, got '%.*s'", w, what,
                    (int)(t.len > 40 ? 40 : t.len), t.s);
}

cm_status cm_foam_expect(cm_context *ctx, cm_foam_lex *lx, char c, const char *what)
{
    cm_foam_tok t = cm_foam_next(lx);
    if (t.kind == CM_FOAM_PUNCT && t.s[0] == c) return CM_OK;
    return tok_error(ctx, lx, what, t);
}

static int parse_i64(const char *s, size_t len, int64_t *v)
{
    return cm_text_parse_int(s, s + len, v);
}

static int parse_f64(const char *s, size_t len, double *v)
{
    char buf[64], *end;
    if (len == 0 || len >= sizeof buf) return 0;
    memcpy(buf, s, len);
    buf[len] = '\0';
    errno = 0;
    double x = strtod(buf, &end);
    if (*end || errno == ERANGE) return 0;
    *v = x;
    return 1;
}

cm_status cm_foam_label(cm_context *ctx, cm_foam_lex *lx, const char *what, int64_t *v)
{
    cm_foam_tok t = cm_foam_next(lx);
    if (t.kind == CM_FOAM_WORD && parse_i64(t.s, t.len, v)) return CM_OK;
    return tok_error(ctx, lx, what, t);
}

static cm_status scalar(cm_context *ctx, cm_foam_lex *lx, const char *what, double *v)
{
    cm_foam_tok t = cm_foam_next(lx);
    if (t.kind == CM_FOAM_WORD && parse_f64(t.s, t.len, v)) return CM_OK;
    return tok_error(ctx, lx, what, t);
}

/* ---- the header ---- */

static cm_status parse_header(cm_context *ctx, cm_foam_file *f)
{
    cm_foam_lex lx;
    cm_foam_lex_init(&lx, f, 0);
    cm_foam_tok t = cm_foam_next(&lx);
    if (t.kind != CM_FOAM_WORD || t.len != 8 || memcmp(t.s, "FoamFile", 8))
        return tok_error(ctx, &lx, "the FoamFile header", t);
    cm_status s = cm_foam_expect(ctx, &lx, '{', "'{' after FoamFile");
    if (s != CM_OK) return s;
    for (;;) {
        cm_foam_tok key = cm_foam_next(&lx);
        if (key.kind == CM_FOAM_PUNCT && key.s[0] == '}') break;
        if (key.kind != CM_FOAM_WORD) return tok_error(ctx, &lx, "a header entry or '}'", key);
        cm_foam_tok val = cm_foam_next(&lx);
        if (val.kind != CM_FOAM_WORD && val.kind != CM_FOAM_STRING)
            return tok_error(ctx, &lx, "a header value", val);
        if (key.len == 6 && !memcmp(key.s, "format", 6)) {
            if (val.len == 6 && !memcmp(val.s, "binary", 6)) f->binary = 1;
            else if (val.len == 5 && !memcmp(val.s, "ascii", 5)) f->binary = 0;
            else return tok_error(ctx, &lx, "format ascii or binary", val);
        } else if (key.len == 5 && !memcmp(key.s, "class", 5)) {
            size_t l = val.len < sizeof f->cls - 1 ? val.len : sizeof f->cls - 1;
            memcpy(f->cls, val.s, l);
            f->cls[l] = '\0';
        } else if (key.len == 4 && !memcmp(key.s, "arch", 4)) {
            /* "LSB;label=32;scalar=64" */
            char a[128];
            size_t l = val.len < sizeof a - 1 ? val.len : sizeof a - 1;
            memcpy(a, val.s, l);
            a[l] = '\0';
            if (strstr(a, "MSB"))
                return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_read: %s:%ld: big-endian (MSB) binary files are not supported",
                                f->path, lx.line);
            const char *lb = strstr(a, "label="), *sb = strstr(a, "scalar=");
            if (lb) f->label_bytes = atoi(lb + 6) / 8;
            if (sb) f->scalar_bytes = atoi(sb + 7) / 8;
            if ((f->label_bytes != 4 && f->label_bytes != 8) || (f->scalar_bytes != 4 && f->scalar_bytes != 8))
                return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_read: %s:%ld: arch \"%s\": expected label=32|64 and scalar=32|64",
                                f->path, lx.line, a);
        }
        /* values may run over several tokens up to ';' */
        for (;;) {
            cm_foam_tok e = cm_foam_next(&lx);
            if (e.kind == CM_FOAM_PUNCT && e.s[0] == ';') break;
            if (e.kind == CM_FOAM_EOF) return tok_error(ctx, &lx, "';' ending the header entry", e);
        }
    }
    f->body = lx.pos;
    return CM_OK;
}

/* ---- lists ---- */

/* A uniform list "N{v}" with no limit given: more is refused (OpenFOAM writes one only when
 * all N values are equal, which no polyMesh list of that size has). */
enum { UNIFORM_DEFAULT = 1 << 20 };

/* Reads the count (skipping a "List<...>" word before it) and the opening bracket, and checks
 * the count before anything is allocated: against lim, and against the bytes left in the file
 * (an ASCII entry takes at least ascii_min bytes with its separator, a binary one exactly
 * bin_bytes). */
static cm_status list_open(cm_context *ctx, cm_foam_lex *lx, const char *what, const cm_foam_limit *lim,
                           size_t ascii_min, size_t bin_bytes, int64_t *n, char *open)
{
    cm_foam_tok t = cm_foam_next(lx);
    if (t.kind == CM_FOAM_WORD && t.len > 5 && !memcmp(t.s, "List<", 5)) t = cm_foam_next(lx);
    char buf[200];
    snprintf(buf, sizeof buf, "the size of %s", what);
    if (t.kind != CM_FOAM_WORD || !parse_i64(t.s, t.len, n) || *n < 0) return tok_error(ctx, lx, buf, t);
    if (lim && (*n < lim->lo || *n > lim->hi))
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s:%ld: %s has %lld entries, expected %s", lx->f->path,
                        lx->line, what, (long long)*n, lim->expect);
    cm_foam_tok b = cm_foam_peek(lx);
    /* OpenFOAM writes an empty list in binary as its size alone ("cellLabels 0;"), in ASCII
     * as "0()"; "0{v}" is read below like any uniform list */
    if (*n == 0 && !(b.kind == CM_FOAM_PUNCT && (b.s[0] == '(' || b.s[0] == '{'))) {
        *open = 0;
        return CM_OK;
    }
    b = cm_foam_next(lx);
    if (b.kind != CM_FOAM_PUNCT || (b.s[0] != '(' && b.s[0] != '{')) {
        snprintf(buf, sizeof buf, "'(' or '{' opening %s", what);
        return tok_error(ctx, lx, buf, b);
    }
    *open = b.s[0];
    const size_t left = lx->f->size - lx->pos;
    if (*open == '(') {
        const int bin = lx->f->binary && bin_bytes;
        const size_t per = bin ? bin_bytes : ascii_min;
        if (bin && (uint64_t)*n > (left ? left - 1 : 0) / per)
            return cm_error(ctx, CM_ERR_FORMAT,
                            "cm_mesh_read: %s: byte %zu: truncated binary block of %s: %lld entries of %zu bytes and "
                            "')' expected, the file has %zu bytes left",
                            lx->f->path, lx->pos, what, (long long)*n, per, left);
        if (!bin && (uint64_t)*n > left / per)
            return cm_error(ctx, CM_ERR_FORMAT,
                            "cm_mesh_read: %s:%ld: %s has size %lld, more than the %zu bytes left in the file can "
                            "hold (%zu per entry at least)",
                            lx->f->path, lx->line, what, (long long)*n, left, per);
    } else {
        const int64_t most = lim ? lim->uniform_hi : UNIFORM_DEFAULT;
        if (*n > most)
            return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s:%ld: %s: uniform list of %lld entries, expected at most %lld%s%s%s",
                            lx->f->path, lx->line, what, (long long)*n, (long long)most, lim ? " (" : "",
                            lim ? lim->expect : "", lim ? ")" : "");
    }
    return CM_OK;
}

static cm_status binary_block(cm_context *ctx, cm_foam_lex *lx, const char *what, size_t bytes,
                              const char **at)
{
    if (bytes > lx->f->size - lx->pos || lx->f->size - lx->pos - bytes < 1)
        return cm_error(ctx, CM_ERR_FORMAT,
                        "cm_mesh_read: %s: byte %zu: truncated binary block of %s: expected %zu bytes and ')', "
                        "the file has %zu left",
                        lx->f->path, lx->pos, what, bytes, lx->f->size - lx->pos);
    *at = lx->f->data + lx->pos;
    lx->pos += bytes;
    if (lx->f->data[lx->pos] != ')')
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: byte %zu: expected ')' closing the binary block of %s",
                        lx->f->path, lx->pos, what);
    ++lx->pos;
    return CM_OK;
}

static void *alloc_n(int64_t n, size_t size)
{
    if (n <= 0) return NULL;
    if ((uint64_t)n > SIZE_MAX / size) return NULL;
    return malloc((size_t)n * size);
}

cm_status cm_foam_label_list(cm_context *ctx, cm_foam_lex *lx, const char *what, int64_t **out,
                             int64_t *n)
{
    return cm_foam_label_list_in(ctx, lx, what, NULL, out, n);
}

cm_status cm_foam_label_list_in(cm_context *ctx, cm_foam_lex *lx, const char *what,
                                const cm_foam_limit *lim, int64_t **out, int64_t *n)
{
    *out = NULL;
    *n = 0;
    char open;
    int64_t cnt;
    cm_status s = list_open(ctx, lx, what, lim, 2, (size_t)lx->f->label_bytes, &cnt, &open);
    if (s != CM_OK) return s;
    if (!open) return CM_OK; /* an empty list written as its size alone */
    int64_t *v = alloc_n(cnt, sizeof *v);
    if (cnt > 0 && !v) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for %lld labels", lx->f->path, (long long)cnt);
    if (open == '{') {
        int64_t x;
        s = cm_foam_label(ctx, lx, what, &x);
        for (int64_t i = 0; s == CM_OK && i < cnt; ++i) v[i] = x;
        if (s == CM_OK) s = cm_foam_expect(ctx, lx, '}', "'}' closing a uniform list");
    } else if (lx->f->binary && cnt > 0) {
        const int lb = lx->f->label_bytes;
        const char *at;
        s = binary_block(ctx, lx, what, (size_t)cnt * (size_t)lb, &at);
        for (int64_t i = 0; s == CM_OK && i < cnt; ++i) {
            if (lb == 4) {
                int32_t x;
                memcpy(&x, at + 4 * i, 4);
                v[i] = x;
            } else {
                memcpy(&v[i], at + 8 * i, 8);
            }
        }
    } else {
        char entry[160];
        snprintf(entry, sizeof entry, "one of the %lld entries of %s", (long long)cnt, what);
        for (int64_t i = 0; s == CM_OK && i < cnt; ++i) s = cm_foam_label(ctx, lx, entry, &v[i]);
        if (s == CM_OK) s = cm_foam_expect(ctx, lx, ')', "')' closing the list (more entries than its size?)");
    }
    if (s != CM_OK) {
        free(v);
        return s < 0 ? s : CM_ERR_FORMAT;
    }
    *out = v;
    *n = cnt;
    return CM_OK;
}

cm_status cm_foam_scalar_list(cm_context *ctx, cm_foam_lex *lx, const char *what, int width,
                              const cm_foam_limit *lim, double **out, int64_t *n)
{
    *out = NULL;
    *n = 0;
    char open;
    int64_t cnt;
    /* ASCII: "(a b c)" takes 7 bytes, a scalar and its separator 2 */
    cm_status s = list_open(ctx, lx, what, lim, width > 1 ? 2 * (size_t)width + 1 : 2,
                            (size_t)width * (size_t)lx->f->scalar_bytes, &cnt, &open);
    if (s != CM_OK) return s;
    if (!open) return CM_OK; /* an empty list written as its size alone */
    double *v = alloc_n(cnt * width, sizeof *v);
    if (cnt > 0 && !v) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for %lld values", lx->f->path, (long long)cnt);
    if (open == '{' || !lx->f->binary || cnt == 0) {
        int uniform = open == '{';
        int64_t items = uniform ? 1 : cnt;
        for (int64_t i = 0; s == CM_OK && i < items; ++i) {
            if (width > 1) s = cm_foam_expect(ctx, lx, '(', "'(' opening a vector");
            for (int k = 0; s == CM_OK && k < width; ++k) s = scalar(ctx, lx, what, &v[i * width + k]);
            if (s == CM_OK && width > 1) s = cm_foam_expect(ctx, lx, ')', "')' closing a vector");
        }
        if (uniform)
            for (int64_t i = 1; s == CM_OK && i < cnt; ++i) memcpy(v + i * width, v, (size_t)width * sizeof *v);
        if (s == CM_OK) s = cm_foam_expect(ctx, lx, uniform ? '}' : ')', "the end of the list (more entries than its size?)");
    } else {
        const int sb = lx->f->scalar_bytes;
        const char *at;
        s = binary_block(ctx, lx, what, (size_t)cnt * (size_t)width * (size_t)sb, &at);
        for (int64_t i = 0; s == CM_OK && i < cnt * width; ++i) {
            if (sb == 8) {
                memcpy(&v[i], at + 8 * i, 8);
            } else {
                float x;
                memcpy(&x, at + 4 * i, 4);
                v[i] = x;
            }
        }
    }
    if (s != CM_OK) {
        free(v);
        return s;
    }
    *out = v;
    *n = cnt;
    return CM_OK;
}

cm_status cm_foam_face_list(cm_context *ctx, cm_foam_lex *lx, int compact, const char *what,
                            int64_t **off, int64_t **nodes, int64_t *n)
{
    *off = *nodes = NULL;
    *n = 0;
    char w[600];
    if (compact) {
        int64_t no = 0, nn = 0;
        /* offsets rise from 0 and a face's vertices are distinct: neither is uniform */
        static const cm_foam_limit offsets = {0, INT64_MAX, 1, "the offsets of faces rise"};
        static const cm_foam_limit vertices = {0, INT64_MAX, 1, "a face's vertices are distinct points"};
        cm_status s = cm_foam_label_list_in(ctx, lx, "face offsets", &offsets, off, &no);
        if (s == CM_OK) s = cm_foam_label_list_in(ctx, lx, "face nodes", &vertices, nodes, &nn);
        if (s == CM_OK && no < 1) {
            s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: faceCompactList: empty offsets list", cm_foam_where(lx, w, sizeof w));
        }
        for (int64_t i = 0; s == CM_OK && i < no; ++i)
            if ((*off)[i] < (i ? (*off)[i - 1] : 0) || (*off)[i] > nn || (i == 0 && (*off)[0] != 0) ||
                (i == no - 1 && (*off)[i] != nn))
                s = cm_error(ctx, CM_ERR_FORMAT,
                             "cm_mesh_read: %s: faceCompactList: offset %lld of face %lld is not in order "
                             "within [0, %lld]",
                             lx->f->path, (long long)(*off)[i], (long long)i, (long long)nn);
        if (s != CM_OK) {
            free(*off);
            free(*nodes);
            *off = *nodes = NULL;
            return s;
        }
        *n = no - 1;
        return CM_OK;
    }
    char open;
    int64_t cnt;
    /* "3(a b c)" takes 8 bytes */
    cm_status s = list_open(ctx, lx, what, NULL, 8, 0, &cnt, &open);
    if (s != CM_OK) return s;
    if (open != '(' && !(open == 0 && cnt == 0)) return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: expected '(' opening the face list", cm_foam_where(lx, w, sizeof w));
    int64_t *o = alloc_n(cnt + 1, sizeof *o);
    size_t cap = (size_t)(cnt > 0 ? cnt : 1) * 4, used = 0;
    int64_t *nd = malloc(cap * sizeof *nd);
    if (!o || !nd) {
        free(o);
        free(nd);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for %lld faces", lx->f->path, (long long)cnt);
    }
    o[0] = 0;
    /* a face's vertices are distinct: "n{v}" is no face */
    static const cm_foam_limit one_face = {0, INT64_MAX, 0, "a face's vertices are distinct points"};
    for (int64_t i = 0; s == CM_OK && i < cnt; ++i) {
        int64_t *f = NULL, fn = 0;
        s = cm_foam_label_list_in(ctx, lx, "a face", &one_face, &f, &fn);
        if (s != CM_OK) break;
        if (used + (size_t)fn > cap) {
            size_t nc = 2 * cap + (size_t)fn;
            int64_t *g = realloc(nd, nc * sizeof *g);
            if (!g) {
                free(f);
                s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", lx->f->path);
                break;
            }
            nd = g;
            cap = nc;
        }
        if (fn) memcpy(nd + used, f, (size_t)fn * sizeof *f);
        free(f);
        used += (size_t)fn;
        o[i + 1] = (int64_t)used;
    }
    if (s == CM_OK && open) s = cm_foam_expect(ctx, lx, ')', "')' closing the face list (more faces than its size?)");
    if (s != CM_OK) {
        free(o);
        free(nd);
        return s;
    }
    *off = o;
    *nodes = nd;
    *n = cnt;
    return CM_OK;
}

cm_status cm_foam_skip_value(cm_context *ctx, cm_foam_lex *lx, const char *what)
{
    int depth = 0;
    for (;;) {
        cm_foam_lex before = *lx;
        cm_foam_tok t = cm_foam_next(lx);
        if (t.kind == CM_FOAM_EOF) return tok_error(ctx, lx, what, t);
        if (t.kind != CM_FOAM_PUNCT) continue;
        char c = t.s[0];
        if (c == '(' || c == '{' || c == '[') {
            ++depth;
        } else if (c == ')' || c == '}' || c == ']') {
            if (--depth < 0) return tok_error(ctx, lx, what, t);
        } else if (c == ';' && depth == 0) {
            *lx = before; /* leave the ';' to the caller */
            return CM_OK;
        }
    }
}

cm_status cm_foam_bool_list(cm_context *ctx, cm_foam_lex *lx, const char *what,
                            const cm_foam_limit *lim, uint8_t **out, int64_t *n)
{
    *out = NULL;
    *n = 0;
    char open;
    int64_t cnt;
    cm_status s = list_open(ctx, lx, what, lim, 2, 1, &cnt, &open);
    if (s != CM_OK) return s;
    if (!open) return CM_OK; /* an empty list written as its size alone */
    uint8_t *v = alloc_n(cnt, 1);
    if (cnt > 0 && !v) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", lx->f->path);
    int64_t x = 0;
    if (open == '{') {
        s = cm_foam_label(ctx, lx, what, &x);
        if (s == CM_OK && cnt) memset(v, x != 0, (size_t)cnt);
        if (s == CM_OK) s = cm_foam_expect(ctx, lx, '}', "'}' closing a uniform list");
    } else if (lx->f->binary && cnt > 0) {
        const char *at;
        s = binary_block(ctx, lx, what, (size_t)cnt, &at);
        for (int64_t i = 0; s == CM_OK && i < cnt; ++i) v[i] = at[i] != 0;
    } else {
        for (int64_t i = 0; s == CM_OK && i < cnt; ++i) {
            s = cm_foam_label(ctx, lx, what, &x);
            v[i] = x != 0;
        }
        if (s == CM_OK) s = cm_foam_expect(ctx, lx, ')', "')' closing the list");
    }
    if (s != CM_OK) {
        free(v);
        return s;
    }
    *out = v;
    *n = cnt;
    return CM_OK;
}
