/* Families of STEP files (study.h): the variant list of `cadmorph study` (a list file or a
 * glob pattern) and the family that reads its files one at a time. */
#include "cadmorph/study.h"
#include "study_internal.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <glob.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

void cm_study_paths_free(char ***paths, size_t n)
{
    if (!paths || !*paths) return;
    for (size_t i = 0; i < n; ++i)
        free((*paths)[i]);
    free(*paths);
    *paths = NULL;
}

typedef struct path_list {
    char **v;
    size_t n, cap;
} path_list;

static cm_status push(cm_context *ctx, path_list *l, const char *dir, size_t dir_len,
                      const char *path, size_t len)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 16;
        char **v = realloc(l->v, cap * sizeof *v);
        if (!v) return cm_error(ctx, CM_ERR_NOMEM, "cm_study_read_list: out of memory");
        l->v = v;
        l->cap = cap;
    }
    /* dir: the list file's directory with its trailing '/' (dir_len 0: none) */
    size_t k = path[0] != '/' ? dir_len : 0;
    char *p = malloc(k + len + 1);
    if (!p) return cm_error(ctx, CM_ERR_NOMEM, "cm_study_read_list: out of memory");
    if (k) memcpy(p, dir, k);
    memcpy(p + k, path, len);
    p[k + len] = 0;
    l->v[l->n++] = p;
    return CM_OK;
}


/* A list line holds one path and perhaps a comment: a line longer than this is not a list
 * (a binary file, /dev/zero's endless line). */
#define LIST_LINE_MAX (PATH_MAX + 256)

static const char list_what[] = "a list of STEP paths";

static cm_status read_file(cm_context *ctx, const char *list, path_list *l)
{
    FILE *f = NULL;
    cm_status s = cm_file_open_read(ctx, list, &f);
    if (s < 0) return s;
    const char *slash = strrchr(list, '/');
    size_t dir_len = slash ? (size_t)(slash - list) + 1 : 0;
    char *line = malloc(LIST_LINE_MAX + 1);
    if (!line) {
        fclose(f);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_study_read_list: out of memory");
    }
    long lineno = 0;
    size_t len = 0;
    int rc;
    while ((rc = cm_file_read_line(ctx, f, list, list_what, &lineno, line, LIST_LINE_MAX + 1, &len)) > 0) {
        /* a STEP file given where its list was meant: say so instead of "no such file" for
         * its first line */
        if (lineno == 1 && !strncmp(line, "ISO-10303-21;", 13)) {
            rc = cm_error(ctx, CM_ERR_FORMAT, "%s: a STEP file, not a list of variants (expected a "
                          "list of STEP paths, a quoted glob pattern or a design table)", list);
            break;
        }
        char *hash = strchr(line, '#');
        if (hash) *hash = 0;
        char *b = line, *e = line + strlen(line);
        while (*b == ' ' || *b == '\t') ++b;
        while (e > b && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\n' || e[-1] == '\r')) --e;
        if (e == b) continue;
        *e = 0;
        rc = push(ctx, l, list, dir_len, b, (size_t)(e - b));
        if (rc < 0) break;
        const char *why = cm_study_unreadable(l->v[l->n - 1]);
        if (why) {
            rc = cm_error(ctx, CM_ERR_IO, "%s:%ld: %s: %s", list, lineno, l->v[l->n - 1], why);
            break;
        }
    }
    free(line);
    fclose(f);
    s = rc < 0 ? (cm_status)rc : CM_OK;
    if (s >= 0 && l->n == 0) s = cm_error(ctx, CM_ERR_FORMAT, "%s: no STEP paths", list);
    return s;
}

static cm_status read_glob(cm_context *ctx, const char *pattern, path_list *l)
{
    glob_t g;
    int rc = glob(pattern, 0, NULL, &g);
    if (rc == GLOB_NOMATCH) return cm_error(ctx, CM_ERR_IO, "%s: no file matches", pattern);
    if (rc == GLOB_NOSPACE) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", pattern);
    if (rc != 0) return cm_error(ctx, CM_ERR_IO, "%s: cannot expand the pattern", pattern);
    cm_status s = CM_OK;
    for (size_t i = 0; i < g.gl_pathc && s >= 0; ++i) {
        s = push(ctx, l, NULL, 0, g.gl_pathv[i], strlen(g.gl_pathv[i]));
        const char *why = s >= 0 ? cm_study_unreadable(g.gl_pathv[i]) : NULL;
        if (why) s = cm_error(ctx, CM_ERR_IO, "%s: %s: %s", pattern, g.gl_pathv[i], why);
    }
    globfree(&g);
    return s;
}

cm_status cm_study_read_list(cm_context *ctx, const char *list, char ***paths, size_t *n)
{
    if (paths) *paths = NULL;
    if (n) *n = 0;
    if (!list || !paths || !n) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_read_list: NULL input");
    path_list l = {0};
    struct stat st;
    int is_file = stat(list, &st) == 0;
    cm_status s = !is_file && strpbrk(list, "*?[") ? read_glob(ctx, list, &l)
                                                     : read_file(ctx, list, &l);
    if (s < 0) {
        cm_study_paths_free(&l.v, l.n);
        return s;
    }
    *paths = l.v;
    *n = l.n;
    return CM_OK;
}

/* ---- the family over the files ---- */

typedef struct files {
    char **paths;
    size_t n;
    cm_cad_read_options opt;
    int has_opt;
} files;

static cm_status files_load(cm_context *ctx, void *user, size_t i, cm_cad_model **g)
{
    files *f = user;
    cm_status s = cm_cad_read(ctx, f->paths[i], f->has_opt ? &f->opt : NULL, g);
    return s < 0 ? cm_error_prefix(ctx, s, "%s", f->paths[i]) : s;
}

static void files_label(void *user, size_t i, char *buf, size_t size)
{
    const files *f = user;
    const char *base = strrchr(f->paths[i], '/');
    base = base ? base + 1 : f->paths[i];
    const char *dot = strrchr(base, '.');
    int len = dot && dot != base ? (int)(dot - base) : (int)strlen(base);
    snprintf(buf, size, "%.*s", len, base);
}

static void files_destroy(void *user)
{
    files *f = user;
    cm_study_paths_free(&f->paths, f->n);
    free(f);
}

cm_status cm_study_family_files(cm_context *ctx, const char *const *paths, size_t n,
                                const cm_cad_read_options *opt, cm_study_family *family)
{
    if (family) memset(family, 0, sizeof *family);
    if (!paths || !family) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_family_files: NULL input");
    files *f = calloc(1, sizeof *f);
    if (f) f->paths = calloc(n ? n : 1, sizeof *f->paths);
    if (!f || !f->paths) {
        free(f);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_study_family_files: out of memory");
    }
    for (size_t i = 0; i < n; ++i) {
        f->paths[i] = paths[i] ? strdup(paths[i]) : NULL;
        f->n = i + 1;
        if (!f->paths[i]) {
            files_destroy(f);
            return paths[i] ? cm_error(ctx, CM_ERR_NOMEM, "cm_study_family_files: out of memory")
                            : cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_family_files: path %zu is NULL", i);
        }
    }
    if (opt) f->opt = *opt, f->has_opt = 1;
    family->n = n;
    family->load = files_load;
    family->label = files_label;
    family->destroy = files_destroy;
    family->user = f;
    return CM_OK;
}

void cm_study_family_release(cm_study_family *family)
{
    if (!family) return;
    if (family->destroy) family->destroy(family->user);
    memset(family, 0, sizeof *family);
}

/* ---- the family over a design table's rows ---- */

typedef struct design_rows {
    files f;           /* the rows' paths (every row but the base) */
    const cm_design_table *t;
    size_t *row;       /* variant -> table row */
    const char **names;
    double lo, hi;     /* the varying parameter's range (one-parameter sweeps) */
    size_t varying;    /* its index, or SIZE_MAX */
} design_rows;

static const double *design_values(void *user, size_t i)
{
    const design_rows *d = user;
    return cm_design_table_values(d->t, d->row[i]);
}

static double design_param(void *user, size_t i)
{
    const design_rows *d = user;
    if (d->varying == SIZE_MAX) return (double)(i + 1) / (double)d->f.n;
    return (cm_design_table_values(d->t, d->row[i])[d->varying] - d->lo) / (d->hi - d->lo);
}

static void design_destroy(void *user)
{
    design_rows *d = user;
    cm_study_paths_free(&d->f.paths, d->f.n);
    free(d->row);
    free(d->names);
    free(d);
}

cm_status cm_study_family_design(cm_context *ctx, const cm_design_table *t, size_t base,
                                 const cm_cad_read_options *opt, cm_study_family *family)
{
    if (family) memset(family, 0, sizeof *family);
    if (!t || !family) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_family_design: NULL input");
    const size_t nr = cm_design_table_n_rows(t), np = cm_design_table_n_parameters(t);
    if (base >= nr || nr < 2)
        return cm_error(ctx, nr < 2 ? CM_ERR_FORMAT : CM_ERR_ARGUMENT,
                        "cm_study_family_design: base row %zu of %zu rows (a study needs a row "
                        "besides G0's)", base, nr);
    design_rows *d = calloc(1, sizeof *d);
    if (d) {
        d->f.paths = calloc(nr, sizeof *d->f.paths);
        d->row = calloc(nr, sizeof *d->row);
        d->names = calloc(np ? np : 1, sizeof *d->names);
    }
    if (!d || !d->f.paths || !d->row || !d->names) {
        if (d) free(d->f.paths), free(d->row), free(d->names);
        free(d);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_study_family_design: out of memory");
    }
    d->t = t;
    for (size_t i = 0; i < nr; ++i) {
        if (i == base) continue;
        d->row[d->f.n] = i;
        if (!(d->f.paths[d->f.n] = strdup(cm_design_table_path(t, i)))) {
            design_destroy(d);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_study_family_design: out of memory");
        }
        ++d->f.n;
    }
    if (opt) d->f.opt = *opt, d->f.has_opt = 1;
    for (size_t j = 0; j < np; ++j)
        d->names[j] = cm_design_table_parameter(t, j);
    /* a one-parameter sweep: the only parameter whose value is not the same in every row */
    d->varying = SIZE_MAX;
    size_t n_varying = 0;
    for (size_t j = 0; j < np; ++j) {
        double lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < nr; ++i) {
            const double v = cm_design_table_values(t, i)[j];
            lo = fmin(lo, v), hi = fmax(hi, v);
        }
        if (hi > lo) ++n_varying, d->varying = j, d->lo = lo, d->hi = hi;
    }
    if (n_varying != 1) d->varying = SIZE_MAX;
    family->n = d->f.n;
    family->load = files_load;
    family->label = files_label;
    family->destroy = design_destroy;
    family->user = d;
    family->param = design_param;
    family->n_values = np;
    family->value_names = d->names;
    family->values = design_values;
    if (d->varying != SIZE_MAX) {
        family->x_label = d->names[d->varying];
        family->x_min = d->lo;
        family->x_max = d->hi;
        family->x0 = cm_design_table_values(t, base)[d->varying];
    }
    return CM_OK;
}
