/* PyGeM's FFD parameter file (.prm, Python configparser syntax), read without Python:
 * [Box info] and [Parameters weights] as PyGeM's FFD.read_parameters reads them. Unlike PyGeM,
 * a missing file is an error (PyGeM writes a default file there and returns silently). */
#include "ffd_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Larger lengths, positions or displacements are no mesh: the lattice's map and the quality
 * of the moved cells multiply them (volumes are cubes, squared norms in the solvers), so
 * 1e308 overflows to inf there and writes inf/nan coordinates. The warp's displacement table
 * has the same bound. */
#define CM_PRM_MAX 1e150

typedef struct weight_entry {
    int axis, i, j, k, line;
    double v;
} weight_entry;

typedef struct prm_parse {
    cm_context *ctx;
    const char *path;
    int have[12]; /* the line of n x y z, length x y z, origin x y z, angle x y z; 0: none */
    cm_ffd_prm *prm;
    weight_entry *w;
    size_t nw, capw;
    int have_w[3];
} prm_parse;

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t')
        ++s;
    size_t n = strlen(s);
    while (n && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r'))
        s[--n] = 0;
    return s;
}

static int parse_double(const char *s, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(s, &end);
    if (end == s || errno == ERANGE || !isfinite(*v)) return 0;
    while (*end == ' ' || *end == '\t')
        ++end;
    return *end == 0;
}

/* "i j k value" */
static cm_status weight_line(prm_parse *p, int axis, char *text, int line)
{
    text = trim(text);
    if (!*text) return CM_OK;
    long ijk[3];
    char *s = text, *end;
    for (int a = 0; a < 3; ++a) {
        errno = 0;
        ijk[a] = strtol(s, &end, 10);
        if (end == s || errno || (*end != ' ' && *end != '\t'))
            return cm_error(p->ctx, CM_ERR_FORMAT,
                            "cm_ffd_prm_read: %s:%d: expected 'i j k value', got '%s'", p->path,
                            line, text);
        s = end;
    }
    double v;
    if (!parse_double(s, &v))
        return cm_error(p->ctx, CM_ERR_FORMAT,
                        "cm_ffd_prm_read: %s:%d: expected a finite number after the indices in "
                        "'%s'",
                        p->path, line, text);
    if (p->nw == p->capw) {
        size_t nc = p->capw ? 2 * p->capw : 64;
        weight_entry *nw = realloc(p->w, nc * sizeof *nw);
        if (!nw) return cm_error(p->ctx, CM_ERR_NOMEM, "cm_ffd_prm_read: out of memory");
        p->w = nw;
        p->capw = nc;
    }
    for (int a = 0; a < 3; ++a)
        if (ijk[a] < 0 || ijk[a] > 1000000)
            return cm_error(p->ctx, CM_ERR_FORMAT, "cm_ffd_prm_read: %s:%d: index %ld out of range",
                            p->path, line, ijk[a]);
    p->w[p->nw++] = (weight_entry){axis, (int)ijk[0], (int)ijk[1], (int)ijk[2], line, v};
    return CM_OK;
}

static const char *const box_keys[4] = {"n control points", "box length", "box origin",
                                        "rotation angle"};

static cm_status box_key(prm_parse *p, const char *key, char *value, int line)
{
    for (int q = 0; q < 4; ++q) {
        size_t kl = strlen(box_keys[q]);
        if (strncmp(key, box_keys[q], kl) || key[kl] != ' ') continue;
        const char *ax = key + kl + 1;
        if (strlen(ax) != 1 || ax[0] < 'x' || ax[0] > 'z') continue;
        int a = ax[0] - 'x';
        double v;
        if (!parse_double(trim(value), &v))
            return cm_error(p->ctx, CM_ERR_FORMAT,
                            "cm_ffd_prm_read: %s:%d: '%s' is not a number: '%s'", p->path, line,
                            key, trim(value));
        if (q == 0) {
            if (v != floor(v) || v < 1 || v > 100000)
                return cm_error(p->ctx, CM_ERR_FORMAT,
                                "cm_ffd_prm_read: %s:%d: '%s' must be a positive integer", p->path,
                                line, key);
            p->prm->n[a] = (int)v;
        } else if (q == 1) {
            p->prm->length[a] = v;
        } else if (q == 2) {
            p->prm->origin[a] = v;
        } else {
            p->prm->angle[a] = v;
        }
        p->have[3 * q + a] = line;
        return CM_OK;
    }
    return CM_OK; /* configparser keeps unknown keys; PyGeM ignores them */
}

static cm_status parse(prm_parse *p, char *text)
{
    enum { SEC_OTHER, SEC_BOX, SEC_WEIGHTS } sec = SEC_OTHER;
    int cont_axis = -1; /* a "parameter x|y|z" value continues on indented lines */
    int line = 0;
    for (char *ln = text; ln;) {
        char *next = strchr(ln, '\n');
        if (next) *next++ = 0;
        ++line;
        int indented = *ln == ' ' || *ln == '\t';
        char *s = trim(ln);
        ln = next;
        if (!*s || *s == '#' || *s == ';') continue;
        if (indented && cont_axis >= 0) {
            cm_status st = weight_line(p, cont_axis, s, line);
            if (st < 0) return st;
            continue;
        }
        cont_axis = -1;
        if (*s == '[') {
            char *e = strchr(s, ']');
            if (!e)
                return cm_error(p->ctx, CM_ERR_FORMAT, "cm_ffd_prm_read: %s:%d: unclosed section",
                                p->path, line);
            *e = 0;
            sec = !strcmp(s + 1, "Box info")             ? SEC_BOX
                  : !strcmp(s + 1, "Parameters weights") ? SEC_WEIGHTS
                                                         : SEC_OTHER;
            continue;
        }
        char *sep = strpbrk(s, ":=");
        if (!sep)
            return cm_error(p->ctx, CM_ERR_FORMAT,
                            "cm_ffd_prm_read: %s:%d: expected 'key: value', got '%s'", p->path,
                            line, s);
        *sep = 0;
        char *key = trim(s), *value = sep + 1;
        for (char *c = key; *c; ++c)
            *c = (char)tolower((unsigned char)*c); /* configparser keys are case-insensitive */
        if (sec == SEC_BOX) {
            cm_status st = box_key(p, key, value, line);
            if (st < 0) return st;
        } else if (sec == SEC_WEIGHTS && !strncmp(key, "parameter ", 10) && strlen(key) == 11 &&
                   key[10] >= 'x' && key[10] <= 'z') {
            cont_axis = key[10] - 'x';
            p->have_w[cont_axis] = 1;
            cm_status st = weight_line(p, cont_axis, value, line);
            if (st < 0) return st;
        }
    }
    return CM_OK;
}

cm_status cm_ffd_prm_read(cm_context *ctx, const char *path, cm_ffd_prm *prm)
{
    if (!path || !prm) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_ffd_prm_read: NULL input");
    memset(prm, 0, sizeof *prm);
    char *text = NULL;
    size_t size = 0;
    cm_status s = cm_file_read(ctx, path, &text, &size);
    if (s < 0) return s;
    prm_parse p = {ctx, path, {0}, prm, NULL, 0, 0, {0}};
    s = parse(&p, text);
    free(text);
    static const char *const names[12] = {
        "n control points x", "n control points y", "n control points z", "box length x",
        "box length y",       "box length z",       "box origin x",       "box origin y",
        "box origin z",       "rotation angle x",   "rotation angle y",   "rotation angle z"};
    for (int q = 0; s >= 0 && q < 12; ++q)
        if (!p.have[q])
            s = cm_error(ctx, CM_ERR_FORMAT, "cm_ffd_prm_read: %s: [Box info] has no '%s'", path,
                         names[q]);
    for (int a = 0; s >= 0 && a < 3; ++a)
        if (!p.have_w[a])
            s = cm_error(ctx, CM_ERR_FORMAT,
                         "cm_ffd_prm_read: %s: [Parameters weights] has no 'parameter %c'", path,
                         'x' + a);
    for (int q = 3; s >= 0 && q < 9; ++q) {
        const double v = q < 6 ? prm->length[q - 3] : prm->origin[q - 6];
        if (q < 6 && v == 0)
            s = cm_error(ctx, CM_ERR_FORMAT,
                         "cm_ffd_prm_read: %s:%d: '%s' is 0: the box is flat (no lattice)", path,
                         p.have[q], names[q]);
        else if (fabs(v) > CM_PRM_MAX)
            s = cm_error(ctx, CM_ERR_FORMAT,
                         "cm_ffd_prm_read: %s:%d: '%s' is %g, beyond any mesh (|v| <= %g)", path,
                         p.have[q], names[q], v, CM_PRM_MAX);
    }
    size_t nc = 0;
    if (s >= 0) {
        double count = (double)prm->n[0] * prm->n[1] * prm->n[2];
        if (count > 1e8)
            s = cm_error(ctx, CM_ERR_FORMAT, "cm_ffd_prm_read: %s: %.0f control points", path,
                         count);
        nc = (size_t)count;
    }
    if (s >= 0 && !(prm->mu = calloc(nc * 3, sizeof *prm->mu)))
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_ffd_prm_read: out of memory");
    for (size_t e = 0; s >= 0 && e < p.nw; ++e) {
        weight_entry *w = &p.w[e];
        if (w->i >= prm->n[0] || w->j >= prm->n[1] || w->k >= prm->n[2]) {
            s = cm_error(ctx, CM_ERR_FORMAT,
                         "cm_ffd_prm_read: %s:%d: control point (%d, %d, %d) outside the %d x %d "
                         "x %d lattice",
                         path, w->line, w->i, w->j, w->k, prm->n[0], prm->n[1], prm->n[2]);
            break;
        }
        /* the physical displacement is R diag(length) mu: |mu| length along the box axis */
        const double d = fabs(w->v) * fabs(prm->length[w->axis]);
        if (d > CM_PRM_MAX) {
            s = cm_error(ctx, CM_ERR_FORMAT,
                         "cm_ffd_prm_read: %s:%d: weight %g of control point (%d, %d, %d) along %c "
                         "times the box length %g is a displacement of %g, beyond any mesh (|d| <= %g)",
                         path, w->line, w->v, w->i, w->j, w->k, 'x' + w->axis,
                         prm->length[w->axis], d, CM_PRM_MAX);
            break;
        }
        size_t idx = ((size_t)w->i * prm->n[1] + w->j) * prm->n[2] + w->k;
        prm->mu[3 * idx + w->axis] = w->v; /* a repeated line overwrites, as in PyGeM */
    }
    free(p.w);
    if (s < 0) cm_ffd_prm_free(prm);
    return s;
}

void cm_ffd_prm_free(cm_ffd_prm *prm)
{
    if (!prm) return;
    free(prm->mu);
    prm->mu = NULL;
}

void cm_ffd_prm_desc(const cm_ffd_prm *prm, cm_ffd_basis basis, cm_ffd_desc *desc, double *dc)
{
    cm_ffd_desc_init(desc);
    desc->basis = basis;
    memcpy(desc->n, prm->n, sizeof desc->n);
    memcpy(desc->origin, prm->origin, sizeof desc->origin);
    cm_ffd_box_axes(prm->length, prm->angle, desc->axes);
    if (!dc) return;
    size_t nc = (size_t)prm->n[0] * prm->n[1] * prm->n[2];
    /* dc = R diag(L) mu = A mu */
    for (size_t p = 0; p < nc; ++p) {
        const double *m = prm->mu + 3 * p;
        for (int r = 0; r < 3; ++r)
            dc[3 * p + r] =
                desc->axes[3 * r] * m[0] + desc->axes[3 * r + 1] * m[1] + desc->axes[3 * r + 2] * m[2];
    }
}
