/* Linear pre-scan of a STEP (ISO 10303-21) file before OpenCASCADE parses it: OpenCASCADE's
 * parser recurses once per parenthesis (100,000 nested ones overflow the stack), its transfer
 * loops forever on a NaN coordinate, and it reads an SI unit it does not know as metres.
 * One pass with O(1) memory refuses all three, naming the line. */
#include "step_scan.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ISO 10303-41 si_prefix and si_unit_name: every value a conforming SI_UNIT may hold. */
static const char *const si_prefixes[] = {"EXA",  "PETA",  "TERA",  "GIGA", "MEGA", "KILO",
                                          "HECTO", "DECA", "DECI",  "CENTI", "MILLI", "MICRO",
                                          "NANO", "PICO",  "FEMTO", "ATTO"};
static const char *const si_names[] = {
    "METRE",   "GRAM",   "SECOND",  "AMPERE", "KELVIN",         "MOLE",      "CANDELA",
    "RADIAN",  "STERADIAN", "HERTZ", "NEWTON", "PASCAL",        "JOULE",     "WATT",
    "COULOMB", "VOLT",   "FARAD",   "OHM",    "SIEMENS",        "WEBER",     "TESLA",
    "HENRY",   "DEGREE_CELSIUS", "LUMEN", "LUX", "BECQUEREL",   "GRAY",      "SIEVERT"};

/* Enumerations are upper case in ISO 10303-21, but some writers do not care. */
static int in_list(const char *s, size_t n, const char *const *list, size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        if (strlen(list[i]) != n) continue;
        size_t k = 0;
        while (k < n && (s[k] >= 'a' && s[k] <= 'z' ? s[k] - 'a' + 'A' : s[k]) == list[i][k]) ++k;
        if (k == n) return 1;
    }
    return 0;
}

static int is_alpha(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
static int is_digit(char c) { return c >= '0' && c <= '9'; }
static int is_word(char c) { return is_alpha(c) || is_digit(c) || c == '-'; }

static int ieq(const char *s, size_t n, const char *w)
{
    if (strlen(w) != n) return 0;
    for (size_t i = 0; i < n; ++i) {
        char c = s[i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != w[i]) return 0;
    }
    return 1;
}

/* What is echoed from the file goes into a one-line message: printable ASCII only, cut. */
static void excerpt(const char *s, size_t n, char *out, size_t size)
{
    size_t k = 0;
    for (size_t i = 0; i < n && k + 1 < size; ++i) out[k++] = s[i] >= 0x20 && s[i] < 0x7f ? s[i] : '?';
    out[k] = '\0';
}

cm_status cm_step_scan(cm_context *ctx, const char *path, const char *d, size_t size)
{
    /* OpenCASCADE's parser accepts some garbage silently; a STEP file starts with ISO-10303-21. */
    if (size < 12 || memcmp(d, "ISO-10303-21", 12) != 0)
        return cm_error(ctx, CM_ERR_FORMAT, "%s: not a STEP file (no ISO-10303-21 header)", path);
    long line = 1;
    int depth = 0;
    /* inside SI_UNIT(...): the depth of its list and the enumerations seen in it */
    int si_depth = -1, si_n = 0;
    long si_line = 0;
    const char *si_enum[2] = {NULL, NULL};
    size_t si_len[2] = {0, 0};
    char tok[48];
    for (size_t p = 0; p < size;) {
        const char c = d[p];
        if (c == '\n') {
            ++line, ++p;
        } else if (c == '\'' || c == '"') {
            /* strings ('' is a quote inside) and binaries: skipped, lines counted */
            const long start = line;
            size_t q = p + 1;
            for (;; ++q) {
                if (q >= size)
                    return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: string never closed", path, start);
                if (d[q] == '\n') ++line;
                if (d[q] == c) {
                    if (c == '\'' && q + 1 < size && d[q + 1] == '\'') {
                        ++q;
                        continue;
                    }
                    break;
                }
            }
            p = q + 1;
        } else if (c == '/' && p + 1 < size && d[p + 1] == '*') {
            const long start = line;
            size_t q = p + 2;
            while (q + 1 < size && !(d[q] == '*' && d[q + 1] == '/')) line += d[q++] == '\n';
            if (q + 1 >= size)
                return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: comment never closed", path, start);
            p = q + 2;
        } else if (c == '(') {
            if (++depth > CM_STEP_MAX_DEPTH)
                return cm_error(ctx, CM_ERR_FORMAT,
                                "%s:%ld: parentheses nested deeper than %d (not a STEP entity)",
                                path, line, CM_STEP_MAX_DEPTH);
            ++p;
        } else if (c == ')') {
            if (depth == 0)
                return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: ')' without '('", path, line);
            if (depth == si_depth) {
                /* SI_UNIT(prefix, name): prefix is $ or an si_prefix; name an si_unit_name */
                const int named = si_n >= 1;
                const char *nm = named ? si_enum[si_n - 1] : NULL;
                const size_t nl = named ? si_len[si_n - 1] : 0;
                if (!named || !in_list(nm, nl, si_names, sizeof si_names / sizeof *si_names) ||
                    (si_n == 2 && !in_list(si_enum[0], si_len[0], si_prefixes,
                                           sizeof si_prefixes / sizeof *si_prefixes))) {
                    char a[40] = "", b[40] = "";
                    if (si_n == 2) excerpt(si_enum[0], si_len[0], a, sizeof a);
                    if (named) excerpt(nm, nl, b, sizeof b);
                    return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                    "%s:%ld: unknown SI unit '%s%s%s' (ISO 10303-41 names only)",
                                    path, si_line, a, si_n == 2 ? "." : "", b);
                }
                si_depth = -1;
            }
            --depth, ++p;
        } else if (c == '#') {
            size_t q = p + 1;
            while (q < size && is_digit(d[q])) ++q;
            p = q > p + 1 ? q : p + 1;
        } else if (c == '.' && p + 1 < size && is_alpha(d[p + 1])) {
            /* enumeration .NAME. */
            size_t q = p + 1;
            while (q < size && is_word(d[q])) ++q;
            if (depth == si_depth && si_n < 2) {
                si_enum[si_n] = d + p + 1;
                si_len[si_n++] = q - p - 1;
            }
            p = q < size && d[q] == '.' ? q + 1 : q;
        } else if (is_digit(c) || ((c == '-' || c == '+' || c == '.') && p + 1 < size &&
                                   (is_digit(d[p + 1]) || d[p + 1] == '.'))) {
            size_t q = p + 1;
            while (q < size && (is_digit(d[q]) || d[q] == '.' || d[q] == 'E' || d[q] == 'e' ||
                                ((d[q] == '-' || d[q] == '+') && (d[q - 1] == 'E' || d[q - 1] == 'e'))))
                ++q;
            /* a number whose value is not finite (1.E999) or that runs on into letters
             * (1.#INF, 1.0nan) is what OpenCASCADE turns into inf/NaN coordinates */
            const size_t n = q - p;
            int bad = n >= sizeof tok || (q < size && is_alpha(d[q])) || (q < size && d[q] == '#');
            if (!bad) {
                memcpy(tok, d + p, n);
                tok[n] = '\0';
                char *end = NULL;
                const double v = strtod(tok, &end);
                bad = !isfinite(v);
            }
            if (bad) {
                size_t e = q;
                while (e < size && e - p < 40 && (is_word(d[e]) || d[e] == '#' || d[e] == '.')) ++e;
                excerpt(d + p, e - p, tok, sizeof tok);
                return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: number '%s' is not finite", path,
                                line, tok);
            }
            p = q;
        } else if (is_alpha(c)) {
            size_t q = p + 1;
            while (q < size && is_word(d[q])) ++q;
            size_t r = q;
            while (r < size && (d[r] == ' ' || d[r] == '\t' || d[r] == '\r' || d[r] == '\n')) ++r;
            const size_t n = q - p;
            if (r < size && d[r] == '(') {
                if (n == 7 && !memcmp(d + p, "SI_UNIT", 7) && si_depth < 0) {
                    si_depth = depth + 1;
                    si_n = 0;
                    si_line = line;
                }
            } else if (depth > 0 && (ieq(d + p, n, "nan") || ieq(d + p, n, "inf") ||
                                     ieq(d + p, n, "infinity"))) {
                /* a bare word is no STEP parameter, but OpenCASCADE reads these as numbers */
                excerpt(d + p, n, tok, sizeof tok);
                return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: number '%s' is not finite", path,
                                line, tok);
            }
            p = q;
        } else {
            ++p;
        }
    }
    return CM_OK;
}
