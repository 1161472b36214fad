/* Nastran bulk data: lines, cards and fields, real numbers both ways, coordinate systems
 * (nastran_internal.h). */
#define _POSIX_C_SOURCE 200809L
#include "nastran_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void nas_card_free(nas_card *c)
{
    free(c->f);
    free(c->lines);
    memset(c, 0, sizeof *c);
}

void nas_line_at(const char *data, size_t size, size_t pos, nas_line *l)
{
    const char *nl = memchr(data + pos, '\n', size - pos);
    size_t e = nl ? (size_t)(nl - data) : size;
    l->b = pos;
    l->next = nl ? e + 1 : size;
    while (e > pos && data[e - 1] == '\r') --e;
    l->e = e;
    l->kind = NAS_SMALL;
    l->tabs = 0;
}

/* The end of a line's text before a '$' comment. */
static size_t text_end(const char *data, const nas_line *l)
{
    const char *d = memchr(data + l->b, '$', l->e - l->b);
    return d ? (size_t)(d - data) : l->e;
}

static int has_comma(const char *data, const nas_line *l)
{
    return memchr(data + l->b, ',', text_end(data, l) - l->b) != NULL;
}

int nas_line_is_comment(const char *data, const nas_line *l)
{
    for (size_t i = l->b; i < l->e; ++i) {
        if (data[i] == '$') return 1;
        if (!isspace((unsigned char)data[i])) return 0;
    }
    return 1;
}

int nas_line_is_continuation(const char *data, const nas_line *l)
{
    if (l->b == l->e) return 0;
    const char c0 = data[l->b];
    if (c0 == '+' || c0 == '*') return 1;
    if (has_comma(data, l)) {
        /* free field: an empty first field, or one that starts with + or * */
        size_t i = l->b;
        while (i < l->e && (data[i] == ' ' || data[i] == '\t')) ++i;
        return data[i] == ',' || data[i] == '+' || data[i] == '*';
    }
    /* fixed: the first 8 columns blank */
    for (size_t i = l->b, col = 0; i < l->e && col < 8; ++i) {
        if (data[i] == '\t') return 1;
        if (data[i] != ' ') return 0;
        ++col;
    }
    return 1;
}

static int grow(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap) return 0;
    size_t cap2 = *cap ? *cap : 16;
    while (cap2 < need) cap2 *= 2;
    void *q = realloc(*p, cap2 * size);
    if (!q) return -1;
    *p = q;
    *cap = cap2;
    return 0;
}

static int add_field(nas_card *c, size_t b, size_t e, int line, int width, int col)
{
    if (grow((void **)&c->f, &c->cap_fields, c->n_fields + 1, sizeof *c->f)) return -1;
    c->f[c->n_fields++] = (nas_field){b, e, line, width, col, 0};
    return 0;
}

/* The fixed field of column col: small 0..9 (8 wide), large 0, 1..4 (16 wide), 5. */
static int fixed_index(int large, size_t col)
{
    if (!large) return col < 80 ? (int)(col / 8) : -1;
    if (col < 8) return 0;
    if (col < 72) return 1 + (int)((col - 8) / 16);
    return col < 80 ? 5 : -1;
}

/* The data fields of line li of the card (its slots, padded with empty fields): free fields
 * split at commas, fixed ones by columns; field 1 (the name or the continuation mark) and the
 * last field (the continuation marker) are not data. */
static int split_line(const char *data, nas_card *c, int li)
{
    nas_line *l = &c->lines[li];
    const size_t end = text_end(data, l);
    const int slots = l->slots;
    const int width = l->kind == NAS_SMALL ? 8 : 16;
    if (l->kind == NAS_FREE) {
        size_t b = l->b;
        int k = 0;
        for (;;) {
            const char *comma = memchr(data + b, ',', end - b);
            const size_t e = comma ? (size_t)(comma - data) : end;
            if (k >= 1 && k <= slots && add_field(c, b, e, li, width, 0)) return -1;
            if (k > slots + 1 && (e > b || comma)) c->too_many = 1;
            ++k;
            if (!comma) break;
            b = e + 1;
        }
        for (; k <= slots; ++k) {
            if (add_field(c, end, end, li, width, 0)) return -1;
            c->f[c->n_fields - 1].pad = 1;
        }
        return 0;
    }
    const int large = l->kind == NAS_LARGE, n_idx = large ? 6 : 10;
    size_t fb[10], fe[10];
    for (int k = 0; k < n_idx; ++k) fb[k] = fe[k] = (size_t)-1;
    size_t col = 0;
    for (size_t i = l->b; i < end; ++i) {
        const int k = fixed_index(large, col);
        if (k < 0) break;
        if (fb[k] == (size_t)-1) fb[k] = i;
        fe[k] = i + 1;
        if (data[i] == '\t') {
            l->tabs = 1;
            col = (col / 8 + 1) * 8;
        } else {
            ++col;
        }
    }
    /* a field the line does not reach (or a tab jumped over) is empty where the next begins */
    size_t next = end;
    for (int k = n_idx - 1; k >= 0; --k) {
        if (fb[k] == (size_t)-1) fb[k] = fe[k] = next;
        next = fb[k];
    }
    for (int k = 1; k <= slots; ++k)
        if (add_field(c, fb[k], fe[k], li, width, large ? 8 + 16 * (k - 1) : 8 * k)) return -1;
    return 0;
}

size_t nas_card_split(const char *data, size_t size, size_t pos, long *line, nas_card *c)
{
    c->n_fields = c->n_lines = 0;
    c->too_many = 0;
    nas_line l;
    nas_line_at(data, size, pos, &l);
    l.number = *line;
    /* the name: the first field, upper case, without its '*' */
    const int free_ = has_comma(data, &l);
    const size_t tend = text_end(data, &l);
    size_t ne = l.b;
    if (free_) {
        while (ne < tend && data[ne] != ',') ++ne;
    } else {
        size_t col = 0;
        while (ne < tend && col < 8) {
            col = data[ne] == '\t' ? 8 : col + 1;
            ++ne;
        }
    }
    size_t nb = l.b;
    while (nb < ne && isspace((unsigned char)data[nb])) ++nb;
    while (ne > nb && isspace((unsigned char)data[ne - 1])) --ne;
    const int large = ne > nb && data[ne - 1] == '*';
    if (large) --ne;
    size_t k = 0;
    for (size_t i = nb; i < ne && k < 8; ++i) c->name[k++] = (char)toupper((unsigned char)data[i]);
    c->name[k] = '\0';
    l.kind = free_ ? NAS_FREE : large ? NAS_LARGE : NAS_SMALL;
    l.slots = large ? 4 : 8;
    for (;;) {
        if (grow((void **)&c->lines, &c->cap_lines, c->n_lines + 1, sizeof *c->lines)) return (size_t)-1;
        c->lines[c->n_lines++] = l;
        if (split_line(data, c, (int)c->n_lines - 1)) return (size_t)-1;
        /* the next line that is not a comment: a continuation of this card? */
        size_t p = l.next;
        long ln = l.number + 1;
        nas_line n;
        for (;;) {
            if (p >= size) break;
            nas_line_at(data, size, p, &n);
            if (!nas_line_is_comment(data, &n)) break;
            p = n.next;
            ++ln;
        }
        if (p >= size || !nas_line_is_continuation(data, &n)) {
            *line = l.number + 1;
            return l.next;
        }
        n.number = ln;
        n.kind = has_comma(data, &n) ? NAS_FREE : data[n.b] == '*' ? NAS_LARGE : NAS_SMALL;
        n.slots = data[n.b] == '*' ? 4 : 8;
        l = n;
    }
}

const char *nas_field_text(const char *data, const nas_card *c, size_t i, size_t *n)
{
    if (i >= c->n_fields) {
        *n = 0;
        return "";
    }
    size_t b = c->f[i].b, e = c->f[i].e;
    while (b < e && isspace((unsigned char)data[b])) ++b;
    while (e > b && isspace((unsigned char)data[e - 1])) --e;
    *n = e - b;
    return data + b;
}

int nas_field_blank(const char *data, const nas_card *c, size_t i)
{
    size_t n;
    nas_field_text(data, c, i, &n);
    return n == 0;
}

int nas_parse_int(const char *s, size_t n, int64_t *v)
{
    size_t i = 0;
    int neg = 0;
    if (i < n && (s[i] == '+' || s[i] == '-')) neg = s[i++] == '-';
    if (i == n || n - i > 18) return -1;
    int64_t x = 0;
    for (; i < n; ++i) {
        if (s[i] < '0' || s[i] > '9') return -1;
        x = 10 * x + (s[i] - '0');
    }
    *v = neg ? -x : x;
    return 0;
}

int nas_parse_real(const char *s, size_t n, double *v)
{
    char buf[80];
    size_t k = 0, i = 0;
    int digits = 0;
    if (n == 0 || n > 40) return -1;
    if (s[i] == '+' || s[i] == '-') buf[k++] = s[i++];
    while (i < n && isdigit((unsigned char)s[i])) buf[k++] = s[i++], ++digits;
    if (i < n && s[i] == '.') {
        buf[k++] = s[i++];
        while (i < n && isdigit((unsigned char)s[i])) buf[k++] = s[i++], ++digits;
    }
    if (!digits) return -1;
    if (i < n) {
        /* exponent: E, D (either case) with an optional sign, or a bare sign */
        buf[k++] = 'e';
        if (s[i] == 'e' || s[i] == 'E' || s[i] == 'd' || s[i] == 'D') ++i;
        if (i < n && (s[i] == '+' || s[i] == '-')) buf[k++] = s[i++];
        if (i == n) return -1;
        while (i < n && isdigit((unsigned char)s[i])) buf[k++] = s[i++];
        if (i < n || buf[k - 1] == 'e' || buf[k - 1] == '+' || buf[k - 1] == '-') return -1;
    }
    buf[k] = '\0';
    char *end;
    const double x = strtod(buf, &end);
    if (*end || !isfinite(x)) return -1;
    *v = x;
    return 0;
}

int nas_text_digits(const char *s, size_t n)
{
    int d = 0, z = 0, lead = 1;
    for (size_t i = 0; i < n; ++i) {
        const char ch = s[i];
        if (ch == '.' || ch == '+' || ch == '-') {
            if (i > 0 && ch != '.') break; /* the exponent's sign */
            continue;
        }
        if (!isdigit((unsigned char)ch)) break;
        if (ch == '0' && lead) {
            ++z;
            continue;
        }
        lead = 0;
        ++d;
    }
    if (!d) d = z; /* a zero: its digits */
    return d < 1 ? 1 : d > 17 ? 17 : d;
}

int nas_format_digits(char *out, size_t cap, double v, int digits)
{
    if (digits < 1) digits = 1;
    if (digits > 17) digits = 17;
    if (v == 0) return snprintf(out, cap, signbit(v) ? "-0." : "0.");
    char e[48];
    snprintf(e, sizeof e, "%.*e", digits - 1, v);
    /* e: [-]d.ddde[+-]xx */
    const char *p = e;
    const int neg = *p == '-';
    if (neg) ++p;
    char mant[24];
    int k = 0;
    for (; *p && *p != 'e'; ++p)
        if (isdigit((unsigned char)*p)) mant[k++] = *p;
    while (k > 1 && mant[k - 1] == '0') --k;
    mant[k] = '\0';
    const int ex = atoi(p + 1);
    /* fixed: the digits around a decimal point */
    char fixed[64], expo[48];
    int f = 0;
    if (neg) fixed[f++] = '-';
    if (ex >= 0) {
        if (ex > 20) {
            fixed[0] = '\0';
            f = 999;
        } else {
            for (int i = 0; i <= ex; ++i) fixed[f++] = i < k ? mant[i] : '0';
            fixed[f++] = '.';
            for (int i = ex + 1; i < k; ++i) fixed[f++] = mant[i];
        }
    } else if (-ex > 20) {
        f = 999;
    } else {
        fixed[f++] = '.';
        for (int i = 0; i < -ex - 1; ++i) fixed[f++] = '0';
        for (int i = 0; i < k; ++i) fixed[f++] = mant[i];
    }
    if (f < 999) fixed[f] = '\0';
    /* exponent: d.ddd followed by the signed exponent ("1.5-3", "2.+12") */
    const int x = snprintf(expo, sizeof expo, "%s%c.%s%c%d", neg ? "-" : "", mant[0], mant + 1, ex < 0 ? '-' : '+',
                           ex < 0 ? -ex : ex);
    if (f <= x) return snprintf(out, cap, "%s", fixed);
    return snprintf(out, cap, "%s", expo);
}

int nas_format_fit(char *out, size_t cap, double v, int width, int min_digits)
{
    char t[64];
    double back;
    /* The shortest exact text, when it fits. Bisections, not walks over the 17 digit counts
     * (a write back formats every moved coordinate): a text exact with d digits is exact
     * with more, and more digits never make a shorter text. */
    int lo = 1, hi = 17;
    while (lo < hi) {
        const int mid = (lo + hi) / 2;
        const int n = nas_format_digits(t, sizeof t, v, mid);
        if (nas_parse_real(t, (size_t)n, &back) == 0 && back == v) hi = mid;
        else lo = mid + 1;
    }
    if (nas_format_digits(t, sizeof t, v, lo) <= width) return snprintf(out, cap, "%s", t);
    /* else the most digits that fit, if at least min_digits */
    lo = min_digits < 1 ? 1 : min_digits;
    hi = 17;
    if (lo > hi || nas_format_digits(t, sizeof t, v, lo) > width) return 0;
    while (lo < hi) {
        const int mid = (lo + hi + 1) / 2;
        if (nas_format_digits(t, sizeof t, v, mid) <= width) lo = mid;
        else hi = mid - 1;
    }
    nas_format_digits(t, sizeof t, v, lo);
    return snprintf(out, cap, "%s", t);
}

/* ---- coordinate systems ---- */

static void to_rect(char type, const double l[3], double p[3])
{
    const double deg = acos(-1.0) / 180.0;
    if (type == 'C') {
        p[0] = l[0] * cos(l[1] * deg);
        p[1] = l[0] * sin(l[1] * deg);
        p[2] = l[2];
    } else if (type == 'S') {
        p[0] = l[0] * sin(l[1] * deg) * cos(l[2] * deg);
        p[1] = l[0] * sin(l[1] * deg) * sin(l[2] * deg);
        p[2] = l[0] * cos(l[1] * deg);
    } else {
        p[0] = l[0], p[1] = l[1], p[2] = l[2];
    }
}

void nas_coord_to_basic(const nas_coord *c, const double local[3], double basic[3])
{
    double p[3];
    to_rect(c->type, local, p);
    for (int i = 0; i < 3; ++i) basic[i] = c->o[i] + p[0] * c->e[0][i] + p[1] * c->e[1][i] + p[2] * c->e[2][i];
}

void nas_coord_from_basic(const nas_coord *c, const double basic[3], double local[3])
{
    const double d[3] = {basic[0] - c->o[0], basic[1] - c->o[1], basic[2] - c->o[2]};
    double p[3];
    for (int i = 0; i < 3; ++i) p[i] = d[0] * c->e[i][0] + d[1] * c->e[i][1] + d[2] * c->e[i][2];
    const double deg = 180.0 / acos(-1.0);
    if (c->type == 'C') {
        local[0] = hypot(p[0], p[1]);
        local[1] = atan2(p[1], p[0]) * deg;
        local[2] = p[2];
    } else if (c->type == 'S') {
        const double r = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        local[0] = r;
        local[1] = r > 0 ? acos(fmax(-1.0, fmin(1.0, p[2] / r))) * deg : 0.0;
        local[2] = atan2(p[1], p[0]) * deg;
    } else {
        local[0] = p[0], local[1] = p[1], local[2] = p[2];
    }
}

void nas_record_free(void *record)
{
    nas_record *r = record;
    if (!r) return;
    free(r->coords);
    free(r->xyz);
    free(r);
}
