/* The displacement table D.csv (DESIGN.md, command line contract): `node,dx,dy,dz` rows with
 * 0-based node indices, read strictly so that a typo is reported at its line, not warped. */
#include "cadmorph/warp.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CSV_COLUMNS 4
/* Larger displacements are no mesh motion; their squares would overflow (1e150^2 = 1e300) */
#define CM_WARP_MAX_DISPLACEMENT 1e150

/* One line split at commas, each field trimmed of spaces (not copied: pointers into data). */
typedef struct csv_row {
    int n;
    const char *field[CSV_COLUMNS];
    size_t len[CSV_COLUMNS];
} csv_row;

static void split_line(const char *b, const char *e, csv_row *row)
{
    row->n = 0;
    for (;;) {
        const char *comma = memchr(b, ',', (size_t)(e - b));
        const char *fe = comma ? comma : e;
        const char *fb = b;
        while (fb < fe && isspace((unsigned char)*fb))
            ++fb;
        while (fe > fb && isspace((unsigned char)fe[-1]))
            --fe;
        if (row->n < CSV_COLUMNS) {
            row->field[row->n] = fb;
            row->len[row->n] = (size_t)(fe - fb);
        }
        ++row->n;
        if (!comma) return;
        b = comma + 1;
    }
}

static int field_is(const csv_row *row, int i, const char *name)
{
    size_t n = strlen(name);
    if (row->len[i] != n) return 0;
    for (size_t k = 0; k < n; ++k)
        if (tolower((unsigned char)row->field[i][k]) != name[k]) return 0;
    return 1;
}

static int blank(const char *b, const char *e)
{
    for (; b < e; ++b)
        if (!isspace((unsigned char)*b)) return 0;
    return 1;
}

/* Copies a field into buf (NUL-terminated) for strtoll/strtod; 0 if it does not fit. */
static int field_copy(const csv_row *row, int i, char *buf, size_t size)
{
    if (row->len[i] >= size) return 0;
    memcpy(buf, row->field[i], row->len[i]);
    buf[row->len[i]] = '\0';
    return 1;
}

static cm_status parse_row(cm_context *ctx, const char *path, long line, const csv_row *row,
                           size_t n_nodes, int64_t *node, double v[3])
{
    static const char *const names[CSV_COLUMNS] = {"node", "dx", "dy", "dz"};
    char buf[80], *end;
    if (row->n != CSV_COLUMNS)
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected 4 columns (node,dx,dy,dz), got %d",
                        path, line, row->n);
    int ok = field_copy(row, 0, buf, sizeof buf) && row->len[0] > 0;
    long long id = 0;
    if (ok) {
        errno = 0;
        id = strtoll(buf, &end, 10);
        ok = !*end && errno == 0;
    }
    if (!ok)
        return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: node: expected an integer, got '%.*s'", path,
                        line, (int)(row->len[0] > 40 ? 40 : row->len[0]), row->field[0]);
    if (id < 0 || (unsigned long long)id >= n_nodes)
        return cm_error(ctx, CM_ERR_MISMATCH,
                        "%s:%ld: node %lld out of range: the mesh has %zu nodes (0-based)", path,
                        line, id, n_nodes);
    *node = (int64_t)id;
    for (int c = 1; c < CSV_COLUMNS; ++c) {
        ok = field_copy(row, c, buf, sizeof buf) && row->len[c] > 0;
        if (ok) {
            v[c - 1] = strtod(buf, &end);
            ok = !*end;
        }
        if (!ok)
            return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s: expected a number, got '%.*s'", path,
                            line, names[c], (int)(row->len[c] > 40 ? 40 : row->len[c]),
                            row->field[c]);
        if (!isfinite(v[c - 1]))
            return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s of node %lld is not finite (%s)", path,
                            line, names[c], id, buf);
        /* the warp squares displacements (norms, the RBF solve): 1.7e308 overflows to inf
         * there and LAPACK reports a bad argument, so refuse it here, at its line */
        if (fabs(v[c - 1]) > CM_WARP_MAX_DISPLACEMENT)
            return cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s of node %lld is %s, beyond any mesh (|d| <= %g)",
                            path, line, names[c], id, buf, CM_WARP_MAX_DISPLACEMENT);
    }
    return CM_OK;
}

static void clear_outputs(size_t n_nodes, double *disp, unsigned char *listed)
{
    if (n_nodes == 0) return; /* disp may be NULL then */
    memset(disp, 0, n_nodes * 3 * sizeof *disp);
    if (listed) memset(listed, 0, n_nodes);
}

cm_status cm_warp_read_displacements(cm_context *ctx, const char *path, size_t n_nodes,
                                     double *disp, unsigned char *listed)
{
    if (!path || (!disp && n_nodes))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_read_displacements: path or disp is NULL");
    clear_outputs(n_nodes, disp, listed);
    /* line of each node's row, to name both lines of a duplicate */
    long *row_line = calloc(n_nodes ? n_nodes : 1, sizeof *row_line);
    if (!row_line) return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_read_displacements: out of memory");
    char *data = NULL;
    size_t size = 0;
    cm_status s = cm_file_read(ctx, path, &data, &size);
    if (s < 0) {
        free(row_line);
        return s;
    }
    const char *p = data, *end = data + size;
    if (size >= 3 && !memcmp(p, "\xEF\xBB\xBF", 3)) p += 3; /* spreadsheets write a BOM */
    long line = 0;
    int have_header = 0;
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const char *le = nl ? nl : end;
        ++line;
        if (memchr(p, '\0', (size_t)(le - p))) {
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: NUL byte: not a text file", path, line);
            goto done;
        }
        if (!blank(p, le)) {
            csv_row row;
            split_line(p, le, &row);
            if (!have_header) {
                if (row.n != CSV_COLUMNS || !field_is(&row, 0, "node") ||
                    !field_is(&row, 1, "dx") || !field_is(&row, 2, "dy") ||
                    !field_is(&row, 3, "dz")) {
                    s = cm_error(ctx, CM_ERR_FORMAT,
                                 "%s:%ld: expected the header 'node,dx,dy,dz', got '%.*s'", path,
                                 line, (int)(le - p > 60 ? 60 : le - p), p);
                    goto done;
                }
                have_header = 1;
            } else {
                int64_t node = 0;
                double v[3] = {0, 0, 0};
                s = parse_row(ctx, path, line, &row, n_nodes, &node, v);
                if (s < 0) goto done;
                if (row_line[node]) {
                    s = cm_error(ctx, CM_ERR_MISMATCH,
                                 "%s:%ld: node %lld listed twice (first on line %ld)", path, line,
                                 (long long)node, row_line[node]);
                    goto done;
                }
                row_line[node] = line;
                memcpy(disp + 3 * node, v, sizeof v);
                if (listed) listed[node] = 1;
            }
        }
        p = nl ? nl + 1 : end;
    }
    if (!have_header)
        s = cm_error(ctx, CM_ERR_FORMAT,
                     "%s:%ld: expected the header 'node,dx,dy,dz', got end of file", path,
                     line + 1);
done:
    free(data);
    free(row_line);
    if (s < 0) {
        clear_outputs(n_nodes, disp, listed);
    }
    return s;
}
