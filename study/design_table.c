/* Design tables (study.h): the CSV a CAD program exports for a family of designs - a header
 * `step,<p1>,<p2>,...` and one row per STEP file with its parameter values - read strictly
 * (errors name path:line), and the choice, for each parameter, of the rows that perturb only
 * it relative to a base row: the finite differences behind the design velocities
 * (docs/DESIGN.md, "Gradients"). */
#include "cadmorph/study.h"
#include "study_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

/* A row is a path and its parameter values: a line longer than this (a binary file, a file
 * without newlines) is refused while the file is read, before it is all in memory. */
#define TABLE_LINE_MAX ((size_t)1 << 20)

struct cm_design_table {
    size_t n_par, n_rows;
    char **names; /* n_par */
    char **paths; /* n_rows, resolved against the table's directory */
    double *values; /* n_rows x n_par */
    long *lines;    /* n_rows: the line of each row in the file */
    char *file;     /* the table's path, for messages */
};

void cm_design_table_destroy(cm_design_table **table)
{
    if (!table || !*table) return;
    cm_design_table *t = *table;
    for (size_t j = 0; t->names && j < t->n_par; ++j)
        free(t->names[j]);
    for (size_t i = 0; t->paths && i < t->n_rows; ++i)
        free(t->paths[i]);
    free(t->names);
    free(t->paths);
    free(t->values);
    free(t->lines);
    free(t->file);
    free(t);
    *table = NULL;
}

/* ---- one CSV record (RFC 4180: quoted fields with "" for a quote, CRLF or LF) ---- */

typedef struct record {
    size_t n, cap;
    char **field; /* owned copies, trimmed of blanks outside quotes */
} record;

static void record_clear(record *r)
{
    for (size_t i = 0; i < r->n; ++i)
        free(r->field[i]);
    r->n = 0;
}

static int record_push(record *r, const char *b, size_t len)
{
    if (r->n == r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 16;
        char **f = realloc(r->field, cap * sizeof *f);
        if (!f) return -1;
        r->field = f;
        r->cap = cap;
    }
    char *s = malloc(len + 1);
    if (!s) return -1;
    memcpy(s, b, len);
    s[len] = 0;
    r->field[r->n++] = s;
    return 0;
}

/* Parses the record starting at *p (a line, or several when a quoted field holds a line
 * break); *p moves past it, *line counts the lines it spans. 1 when a record was read, 0 at
 * the end, -1 out of memory, -2 an unterminated quote. */
static int next_record(const char **p, long *line, record *r)
{
    record_clear(r);
    const char *s = *p;
    if (!*s) return 0;
    char *buf = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        while (*s == ' ' || *s == '\t')
            ++s;
        len = 0;
        int quoted = 0;
        if (*s == '"') {
            quoted = 1;
            ++s;
            for (;;) {
                if (!*s) {
                    free(buf);
                    return -2;
                }
                if (*s == '"' && s[1] == '"') s += 1;
                else if (*s == '"') break;
                if (*s == '\n') ++*line;
                if (len + 1 >= cap) {
                    cap = cap ? 2 * cap : 64;
                    char *nb = realloc(buf, cap);
                    if (!nb) return free(buf), -1;
                    buf = nb;
                }
                buf[len++] = *s++;
            }
            ++s; /* the closing quote */
            while (*s == ' ' || *s == '\t')
                ++s;
        }
        const char *b = s;
        while (*s && *s != ',' && *s != '\n' && *s != '\r')
            ++s;
        const char *e = s;
        while (e > b && (e[-1] == ' ' || e[-1] == '\t'))
            --e;
        if (!quoted) {
            if (record_push(r, b, (size_t)(e - b)) < 0) return free(buf), -1;
        } else {
            /* text after a closing quote is kept, as spreadsheet programs do */
            size_t extra = (size_t)(e - b);
            if (len + extra + 1 > cap) {
                cap = len + extra + 1;
                char *nb = realloc(buf, cap);
                if (!nb) return free(buf), -1;
                buf = nb;
            }
            memcpy(buf + len, b, extra);
            len += extra;
            if (record_push(r, buf ? buf : "", len) < 0) return free(buf), -1;
        }
        if (*s == ',') {
            ++s;
            continue;
        }
        break;
    }
    free(buf);
    if (*s == '\r') ++s;
    if (*s == '\n') ++s;
    ++*line;
    *p = s;
    return 1;
}

static int blank_record(const record *r)
{
    for (size_t i = 0; i < r->n; ++i)
        if (r->field[i][0]) return 0;
    return 1;
}

static int same_name(const char *a, const char *b)
{
    for (; *a && *b; ++a, ++b)
        if (tolower((unsigned char)*a) != tolower((unsigned char)*b)) return 0;
    return *a == *b;
}


/* The header's first field is "step" (any case), after an optional UTF-8 byte order mark. */
static const char *skip_bom(const char *s)
{
    return (unsigned char)s[0] == 0xEF && (unsigned char)s[1] == 0xBB && (unsigned char)s[2] == 0xBF
               ? s + 3
               : s;
}

int cm_design_table_detect(const char *path)
{
    if (!path) return 0;
    /* the input rule (core.h: no FIFO, no device) and a bounded look: the header is within
     * the first blank lines, not after gigabytes of them */
    FILE *f = cm_file_open_quiet(path, NULL);
    if (!f) return 0;
    static const size_t head_max = 65536;
    char *buf = malloc(head_max + 1);
    size_t n = buf ? fread(buf, 1, head_max, f) : 0;
    fclose(f);
    if (!buf) return 0;
    buf[n] = '\0';
    const char *s = skip_bom(buf);
    while (*s == ' ' || *s == '\t' || *s == '\n' || *s == '\r')
        ++s;
    const char *q = s + (*s == '"');
    const int found = (size_t)(s - buf) < n && !strncasecmp(q, "step", 4) &&
                      (q[4] == ',' || (q[4] == '"' && s != q && q[5] == ',') || q[4] == ' ');
    free(buf);
    return found;
}

static cm_status parse(cm_context *ctx, const char *path, const char *text, cm_design_table *t)
{
    const char *slash = strrchr(path, '/');
    size_t dir_len = slash ? (size_t)(slash - path) + 1 : 0;
    record r = {0};
    const char *p = skip_bom(text);
    long line = 0, at;
    size_t cap = 0;
    cm_status s = CM_OK;
    int header = 0, rc;
    while (s >= 0 && (at = line + 1, rc = next_record(&p, &line, &r)) != 0) {
        if (rc == -1) {
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_design_table_read: out of memory");
            break;
        }
        if (rc == -2) {
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: a quoted field is not closed", path, at);
            break;
        }
        if (blank_record(&r)) continue;
        if (!header) {
            header = 1;
            if (!same_name(r.field[0], "step")) {
                s = cm_error(ctx, CM_ERR_FORMAT,
                             "%s:%ld: expected the header step,<parameter>,... (a design table), "
                             "got '%.60s' as the first column",
                             path, at, r.field[0]);
                break;
            }
            if (r.n < 2) {
                s = cm_error(ctx, CM_ERR_FORMAT,
                             "%s:%ld: the header names no parameter: expected step,<parameter>,...",
                             path, at);
                break;
            }
            t->n_par = r.n - 1;
            t->names = calloc(t->n_par, sizeof *t->names);
            if (!t->names) {
                s = cm_error(ctx, CM_ERR_NOMEM, "cm_design_table_read: out of memory");
                break;
            }
            for (size_t j = 0; j < t->n_par && s >= 0; ++j) {
                const char *name = r.field[j + 1];
                if (!name[0])
                    s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: column %zu of the header has no "
                                 "parameter name", path, at, j + 2);
                for (size_t k = 0; k < j && s >= 0; ++k)
                    if (!strcmp(t->names[k], name))
                        s = cm_error(ctx, CM_ERR_FORMAT,
                                     "%s:%ld: parameter '%s' is named twice (columns %zu and %zu)",
                                     path, at, name, k + 2, j + 2);
                if (s >= 0 && !(t->names[j] = strdup(name)))
                    s = cm_error(ctx, CM_ERR_NOMEM, "cm_design_table_read: out of memory");
            }
            continue;
        }
        if (r.n != t->n_par + 1) {
            s = cm_error(ctx, CM_ERR_FORMAT,
                         "%s:%ld: expected %zu columns (step and %zu parameters), got %zu", path,
                         at, t->n_par + 1, t->n_par, r.n);
            break;
        }
        if (t->n_rows == cap) {
            cap = cap ? 2 * cap : 16;
            if (cap > SIZE_MAX / sizeof(double) / t->n_par) {
                s = cm_error(ctx, CM_ERR_NOMEM, "cm_design_table_read: out of memory");
                break;
            }
            char **np = realloc(t->paths, cap * sizeof *np);
            if (np) t->paths = np;
            double *nv = np ? realloc(t->values, cap * t->n_par * sizeof *nv) : NULL;
            if (nv) t->values = nv;
            long *nl = nv ? realloc(t->lines, cap * sizeof *nl) : NULL;
            if (nl) t->lines = nl;
            if (!nl) {
                s = cm_error(ctx, CM_ERR_NOMEM, "cm_design_table_read: out of memory");
                break;
            }
        }
        const char *step = r.field[0];
        if (!step[0]) {
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: step: expected the path of a STEP file, "
                         "got an empty field", path, at);
            break;
        }
        size_t k = step[0] != '/' ? dir_len : 0, len = strlen(step);
        char *full = malloc(k + len + 1);
        if (!full) {
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_design_table_read: out of memory");
            break;
        }
        memcpy(full, path, k);
        memcpy(full + k, step, len + 1);
        size_t i = t->n_rows;
        t->paths[i] = full;
        t->lines[i] = at;
        t->n_rows = i + 1;
        for (size_t j = 0; j < t->n_par && s >= 0; ++j) {
            const char *v = r.field[j + 1];
            char *end = NULL;
            errno = 0;
            double x = v[0] ? strtod(v, &end) : NAN;
            if (!v[0] || *end || errno == ERANGE || !isfinite(x))
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s: expected a finite number, got '%.40s'",
                             path, at, t->names[j], v);
            t->values[i * t->n_par + j] = x;
        }
        if (s < 0) break;
        const char *why = cm_study_unreadable(full);
        if (why) s = cm_error(ctx, CM_ERR_IO, "%s:%ld: %s: %s", path, at, full, why);
    }
    record_clear(&r);
    free(r.field);
    if (s >= 0 && !header) s = cm_error(ctx, CM_ERR_FORMAT, "%s: empty: expected the header "
                                        "step,<parameter>,...", path);
    if (s >= 0 && t->n_rows == 0)
        s = cm_error(ctx, CM_ERR_FORMAT, "%s: no rows after the header", path);
    return s;
}

cm_status cm_design_table_read(cm_context *ctx, const char *path, cm_design_table **table)
{
    if (table) *table = NULL;
    if (!path || !table) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_design_table_read: NULL input");
    char *text = NULL;
    size_t size = 0;
    cm_status s = cm_file_read_text(ctx, path, TABLE_LINE_MAX, "a design table", &text, &size);
    if (s < 0) return s;
    cm_design_table *t = calloc(1, sizeof *t);
    if (!t || !(t->file = strdup(path))) {
        free(t);
        free(text);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_design_table_read: out of memory");
    }
    s = parse(ctx, path, text, t);
    free(text);
    if (s < 0) {
        cm_design_table_destroy(&t);
        return s;
    }
    *table = t;
    return CM_OK;
}

size_t cm_design_table_n_parameters(const cm_design_table *t) { return t ? t->n_par : 0; }
size_t cm_design_table_n_rows(const cm_design_table *t) { return t ? t->n_rows : 0; }

const char *cm_design_table_parameter(const cm_design_table *t, size_t j)
{
    return t && j < t->n_par ? t->names[j] : NULL;
}

const char *cm_design_table_path(const cm_design_table *t, size_t i)
{
    return t && i < t->n_rows ? t->paths[i] : NULL;
}

const double *cm_design_table_values(const cm_design_table *t, size_t i)
{
    return t && i < t->n_rows ? t->values + i * t->n_par : NULL;
}

long cm_design_table_line(const cm_design_table *t, size_t i)
{
    return t && i < t->n_rows ? t->lines[i] : 0;
}

static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0) return strcmp(a, b) == 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

cm_status cm_design_table_find(cm_context *ctx, const cm_design_table *t, const char *path,
                               size_t *row)
{
    if (!t || !path || !row) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_design_table_find: NULL input");
    for (size_t i = 0; i < t->n_rows; ++i)
        if (same_file(t->paths[i], path)) {
            *row = i;
            return CM_OK;
        }
    return cm_error(ctx, CM_ERR_MISMATCH,
                    "%s: no row names %s: the base geometry must be a row of the design table",
                    t->file, path);
}

const char *cm_design_scheme_name(cm_design_scheme s)
{
    switch (s) {
    case CM_DESIGN_CENTRAL: return "central";
    case CM_DESIGN_FORWARD: return "forward";
    case CM_DESIGN_BACKWARD: return "backward";
    default: return "none";
    }
}

/* Values that a CAD export prints alike are equal: relative 1e-12. */
static int same_value(double a, double b)
{
    return fabs(a - b) <= 1e-12 * fmax(1.0, fmax(fabs(a), fabs(b)));
}

/* The one parameter row i changes relative to row base, or SIZE_MAX (none, several, i = base). */
static size_t single_change(const cm_design_table *t, size_t base, size_t i)
{
    if (i == base) return SIZE_MAX;
    const double *v = t->values + i * t->n_par, *b = t->values + base * t->n_par;
    size_t changed = 0, which = SIZE_MAX;
    for (size_t j = 0; j < t->n_par; ++j)
        if (!same_value(v[j], b[j])) ++changed, which = j;
    return changed == 1 ? which : SIZE_MAX;
}

cm_status cm_design_plan(cm_context *ctx, const cm_design_table *t, size_t base,
                         cm_design_difference *out)
{
    if (!t || !out) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_design_plan: NULL input");
    if (base >= t->n_rows)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_design_plan: base row %zu of %zu", base,
                        t->n_rows);
    const size_t np = t->n_par;
    const double *b = t->values + base * np;
    for (size_t j = 0; j < np; ++j)
        out[j] = (cm_design_difference){CM_DESIGN_NONE, 0, 0, 0, 0};
    for (size_t i = 0; i < t->n_rows; ++i) {
        if (i == base) continue;
        const double *v = t->values + i * np;
        size_t changed = 0, which = 0;
        for (size_t j = 0; j < np; ++j)
            if (!same_value(v[j], b[j])) ++changed, which = j;
        if (changed != 1) {
            cm_log(ctx, CM_LOG_INFO,
                   "%s:%ld: row ignored: it changes %zu parameters of the base row (line %ld); "
                   "a velocity needs rows that change one",
                   t->file, t->lines[i], changed, t->lines[base]);
            continue;
        }
        /* the nearest row on each side: the smallest step, the most accurate difference */
        cm_design_difference *d = &out[which];
        double dp = v[which] - b[which];
        if (dp > 0 && (!(d->dp_plus > 0) || dp < d->dp_plus)) d->plus = i, d->dp_plus = dp;
        if (dp < 0 && (!(d->dp_minus < 0) || dp > d->dp_minus)) d->minus = i, d->dp_minus = dp;
    }
    /* both sides: a symmetric pair, where there is one, makes the difference second order
     * (the smallest such pair, even when a nearer row on one side has no partner) */
    for (size_t j = 0; j < np; ++j) {
        cm_design_difference *d = &out[j];
        if (!(d->dp_plus > 0 && d->dp_minus < 0)) continue;
        double best = INFINITY;
        for (size_t i = 0; i < t->n_rows; ++i) {
            size_t k = single_change(t, base, i);
            double dp = t->values[i * np + j] - b[j];
            if (k != j || !(dp > 0) || dp >= best) continue;
            for (size_t m = 0; m < t->n_rows; ++m)
                if (single_change(t, base, m) == j &&
                    same_value(t->values[m * np + j] - b[j], -dp)) {
                    best = dp;
                    d->plus = i, d->dp_plus = dp;
                    d->minus = m, d->dp_minus = t->values[m * np + j] - b[j];
                    break;
                }
        }
    }
    size_t used = 0;
    char skipped[512] = "";
    size_t len = 0;
    for (size_t j = 0; j < np; ++j) {
        cm_design_difference *d = &out[j];
        if (d->dp_plus > 0 && d->dp_minus < 0) {
            d->scheme = CM_DESIGN_CENTRAL;
        } else if (d->dp_plus > 0) {
            d->scheme = CM_DESIGN_FORWARD;
            d->minus = 0, d->dp_minus = 0;
        } else if (d->dp_minus < 0) {
            /* one side below: the difference from the base, (X(minus) - X(base)) / dp */
            d->scheme = CM_DESIGN_BACKWARD;
            d->plus = d->minus, d->dp_plus = d->dp_minus;
            d->minus = 0, d->dp_minus = 0;
        } else {
            int w = snprintf(skipped + len, sizeof skipped - len, "%s%s", len ? ", " : "",
                             t->names[j]);
            if (w > 0 && (size_t)w < sizeof skipped - len) len += (size_t)w;
            continue;
        }
        ++used;
    }
    if (!used)
        return cm_error(ctx, CM_ERR_FORMAT,
                        "%s: no row changes exactly one parameter of the base row (line %ld, %s): "
                        "nothing to differentiate",
                        t->file, t->lines[base], t->paths[base]);
    if (len)
        return cm_error(ctx, CM_WARNING,
                        "%s: no row changes only %s relative to the base row (line %ld): skipped",
                        t->file, skipped, t->lines[base]);
    return CM_OK;
}
