/* The control-displacement table of `cadmorph ffd`: `i,j,k,dx,dy,dz` rows, physical
 * displacements in the world frame (not PyGeM's box-normalised mu), read strictly: a typo is
 * reported at its line. */
#include "ffd_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Splits line at commas into at most 7 trimmed fields (NUL-terminated in place). */
static int split(char *line, char **f)
{
    int n = 0;
    for (char *p = line;;) {
        char *c = strchr(p, ',');
        if (c) *c = 0;
        while (isspace((unsigned char)*p))
            ++p;
        char *e = p + strlen(p);
        while (e > p && isspace((unsigned char)e[-1]))
            *--e = 0;
        if (n < 7) f[n] = p;
        ++n;
        if (!c) return n;
        p = c + 1;
    }
}

cm_status cm_ffd_read_displacements(cm_context *ctx, const char *path, const int n[3],
                                    double *dc, unsigned char *listed)
{
    if (!path || !n || !dc)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_read_displacements: NULL input");
    size_t nc = (size_t)n[0] * n[1] * n[2];
    memset(dc, 0, nc * 3 * sizeof *dc);
    unsigned char *seen = calloc(nc ? nc : 1, 1);
    char *text = NULL;
    size_t size = 0;
    if (!seen) return cm_error(ctx, CM_ERR_NOMEM, "cm_ffd_read_displacements: out of memory");
    cm_status s = cm_file_read(ctx, path, &text, &size);
    if (s < 0) {
        free(seen);
        return s;
    }
    static const char *const names[6] = {"i", "j", "k", "dx", "dy", "dz"};
    int line = 0, header = 0;
    for (char *ln = text; ln && s >= 0;) {
        char *next = strchr(ln, '\n');
        if (next) *next++ = 0;
        ++line;
        char *f[7];
        char *p = ln;
        ln = next;
        while (isspace((unsigned char)*p))
            ++p;
        if (!*p) continue;
        int nf = split(p, f);
        if (nf != 6) {
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%d: expected 6 columns (i,j,k,dx,dy,dz), got %d",
                         path, line, nf);
            break;
        }
        if (!header) {
            for (int c = 0; c < 6 && s >= 0; ++c) {
                for (char *q = f[c]; *q; ++q)
                    *q = (char)tolower((unsigned char)*q);
                if (strcmp(f[c], names[c]))
                    s = cm_error(ctx, CM_ERR_FORMAT,
                                 "%s:%d: expected the header i,j,k,dx,dy,dz, column %d is '%s'",
                                 path, line, c + 1, f[c]);
            }
            header = 1;
            continue;
        }
        long ijk[3];
        double v[3];
        for (int c = 0; c < 3 && s >= 0; ++c) {
            char *end;
            errno = 0;
            ijk[c] = strtol(f[c], &end, 10);
            if (end == f[c] || *end || errno)
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%d: %s '%s' is not an integer", path, line,
                             names[c], f[c]);
            else if (ijk[c] < 0 || ijk[c] >= n[c])
                s = cm_error(ctx, CM_ERR_MISMATCH,
                             "%s:%d: %s = %ld outside the lattice (0..%d)", path, line, names[c],
                             ijk[c], n[c] - 1);
        }
        for (int c = 0; c < 3 && s >= 0; ++c) {
            char *end;
            errno = 0;
            v[c] = strtod(f[c + 3], &end);
            if (end == f[c + 3] || *end || errno == ERANGE || !isfinite(v[c]))
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%d: %s '%s' is not a finite number", path,
                             line, names[c + 3], f[c + 3]);
            /* the bound of the .prm's displacements (prm.c): beyond it the moved nodes' cubes
             * overflow */
            else if (fabs(v[c]) > 1e150)
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%d: %s %s is beyond any mesh (|d| <= 1e150)",
                             path, line, names[c + 3], f[c + 3]);
        }
        if (s < 0) break;
        size_t idx = ((size_t)ijk[0] * n[1] + ijk[1]) * n[2] + ijk[2];
        if (seen[idx]) {
            s = cm_error(ctx, CM_ERR_MISMATCH, "%s:%d: control point (%ld, %ld, %ld) listed twice",
                         path, line, ijk[0], ijk[1], ijk[2]);
            break;
        }
        seen[idx] = 1;
        memcpy(dc + 3 * idx, v, sizeof v);
    }
    if (s >= 0 && !header) s = cm_error(ctx, CM_ERR_FORMAT, "%s: empty (no header)", path);
    if (s >= 0 && listed) memcpy(listed, seen, nc);
    if (s < 0) memset(dc, 0, nc * 3 * sizeof *dc);
    free(seen);
    free(text);
    return s;
}
