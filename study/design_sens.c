/* Sensitivity fields dJ/dX for cm_design_gradient (study.h): a CSV `node,gx,gy,gz` as adjoint
 * solvers' post-processing writes it, or a point field of a mesh file. */
#include "cadmorph/study.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* node,gx,gy,gz: four numbers; a longer line (a binary file, no newlines) is refused while
 * the file is read */
#define SENS_LINE_MAX 4096

static int ends_with_csv(const char *p)
{
    size_t n = strlen(p);
    return n >= 4 && !strcasecmp(p + n - 4, ".csv");
}

/* Splits line (NUL-terminated, modified) at commas into at most 5 trimmed fields. */
static int split(char *line, char *f[5])
{
    int n = 0;
    for (char *s = line;;) {
        char *c = strchr(s, ',');
        if (c) *c = 0;
        while (*s == ' ' || *s == '\t')
            ++s;
        char *e = s + strlen(s);
        while (e > s && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r' || e[-1] == '\n'))
            *--e = 0;
        if (n < 5) f[n] = s;
        ++n;
        if (!c) return n;
        s = c + 1;
    }
}

static cm_status read_csv(cm_context *ctx, const char *path, size_t nn, double *sens,
                          unsigned char *listed)
{
    char *text = NULL;
    size_t size = 0;
    cm_status s = cm_file_read_text(ctx, path, SENS_LINE_MAX, "a sensitivity CSV (node,gx,gy,gz)",
                                    &text, &size);
    if (s < 0) return s;
    unsigned char *seen = calloc(nn ? nn : 1, 1);
    if (!seen) {
        free(text);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_design_read_sensitivity: out of memory");
    }
    static const char *const names[4] = {"node", "gx", "gy", "gz"};
    long line = 0;
    int header = 0;
    for (char *p = text; s >= 0 && p && *p;) {
        char *nl = strchr(p, '\n');
        if (nl) *nl = 0;
        ++line;
        char *f[5];
        int n = split(p, f);
        p = nl ? nl + 1 : NULL;
        if (n == 1 && !f[0][0]) continue; /* blank */
        if (!header) {
            header = 1;
            const char *h0 = f[0];
            if ((unsigned char)h0[0] == 0xEF) h0 += 3; /* byte order mark */
            int ok = n == 4 && !strcasecmp(h0, names[0]);
            for (int c = 1; ok && c < 4; ++c)
                ok = !strcasecmp(f[c], names[c]);
            if (!ok)
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected the header node,gx,gy,gz", path,
                             line);
            continue;
        }
        if (n != 4) {
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected 4 columns (node,gx,gy,gz), got %d",
                         path, line, n);
            break;
        }
        char *end;
        errno = 0;
        long long id = strtoll(f[0], &end, 10);
        if (!f[0][0] || *end || errno) {
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: node: expected an integer, got '%.40s'", path,
                         line, f[0]);
            break;
        }
        if (id < 0 || (unsigned long long)id >= nn) {
            s = cm_error(ctx, CM_ERR_MISMATCH,
                         "%s:%ld: node %lld out of range: the mesh has %zu nodes (0-based)", path,
                         line, id, nn);
            break;
        }
        if (seen[id]) {
            s = cm_error(ctx, CM_ERR_MISMATCH, "%s:%ld: node %lld is listed twice", path, line, id);
            break;
        }
        seen[id] = 1;
        for (int c = 1; c < 4 && s >= 0; ++c) {
            double x = f[c][0] ? strtod(f[c], &end) : NAN;
            if (!f[c][0] || *end || !isfinite(x))
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: %s: expected a finite number, got '%.40s'",
                             path, line, names[c], f[c]);
            sens[3 * id + c - 1] = x;
        }
    }
    if (s >= 0 && !header)
        s = cm_error(ctx, CM_ERR_FORMAT, "%s: empty: expected the header node,gx,gy,gz", path);
    if (s >= 0 && listed) memcpy(listed, seen, nn);
    free(seen);
    free(text);
    return s;
}

static cm_status read_mesh_field(cm_context *ctx, const char *path, size_t nn, double *sens,
                                 unsigned char *listed)
{
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    if (s < 0) return s;
    const cm_field *f = cm_mesh_find_field(m, "dJdX", CM_FIELD_NODE);
    if (!f || f->components != 3) {
        f = NULL;
        for (size_t i = 0; i < m->n_fields; ++i) {
            const cm_field *g = &m->fields[i];
            if (g->location != CM_FIELD_NODE || g->components != 3) continue;
            if (f) {
                f = NULL;
                s = cm_error(ctx, CM_ERR_MISMATCH,
                             "%s: no 3-component point field 'dJdX', and several others ('%s', "
                             "'%s', ...): name the sensitivity 'dJdX'",
                             path, m->fields[i].name, g->name);
                break;
            }
            f = g;
        }
        if (s >= 0 && !f)
            s = cm_error(ctx, CM_ERR_MISMATCH, "%s: no 3-component point field (expected 'dJdX')",
                         path);
    }
    if (s >= 0 && m->n_nodes != nn)
        s = cm_error(ctx, CM_ERR_MISMATCH, "%s: %zu nodes, the mesh has %zu: not a field of its nodes",
                     path, m->n_nodes, nn);
    if (s >= 0) {
        for (size_t k = 0; k < 3 * nn && s >= 0; ++k)
            if (!isfinite(f->data[k]))
                s = cm_error(ctx, CM_ERR_FORMAT, "%s: field '%s' of node %zu is not finite", path,
                             f->name, k / 3);
        if (s >= 0) memcpy(sens, f->data, 3 * nn * sizeof *sens);
        if (s >= 0 && listed) memset(listed, 1, nn);
    }
    cm_mesh_destroy(&m);
    return s;
}

cm_status cm_design_read_sensitivity(cm_context *ctx, const char *path, size_t n_nodes,
                                     double *sens, unsigned char *listed)
{
    if (!path || (!sens && n_nodes))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_design_read_sensitivity: NULL input");
    if (n_nodes) memset(sens, 0, 3 * n_nodes * sizeof *sens);
    if (listed && n_nodes) memset(listed, 0, n_nodes);
    return ends_with_csv(path) ? read_csv(ctx, path, n_nodes, sens, listed)
                               : read_mesh_field(ctx, path, n_nodes, sens, listed);
}
