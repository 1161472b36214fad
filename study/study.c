/* The study driver (study.h): M0 morphed onto every variant of a family by each method,
 * absolutely through one shared cm_morpher (classification of M0 once, one factorisation per
 * warp method for the whole family: the point of the design, DESIGN.md) and relatively
 * through one morpher per method re-based on each result. */
#include "cadmorph/study.h"
#include "cadmorph/parallel.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

void cm_study_options_init(cm_study_options *opt)
{
    memset(opt, 0, sizeof *opt);
    opt->modes = CM_STUDY_BOTH;
    opt->ranks = 1;
    cm_morph_options_init(&opt->morph);
}

void cm_study_result_destroy(cm_study_result **r)
{
    if (!r || !*r) return;
    free((*r)->rows);
    free((*r)->methods);
    free((*r)->value_names);
    free((*r)->values);
    free(*r);
    *r = NULL;
}

/* One method in one mode. */
typedef struct series {
    int mode;
    size_t method;
    int reported;      /* the one-time costs are in a row already */
    cm_morpher *mp;    /* relative: this series' own morpher (NULL once stopped) */
    double t_rebase;   /* relative: the last re-base, reported in the next row */
    cm_status stopped; /* relative: the error that stopped the series */
    char why[400];
} series;

typedef struct study {
    const cm_study_options *o;
    const cm_study_family *fam;
    cm_study_result *r;
    const cm_cad_model *g0;
    const cm_mesh *mesh0;
    cm_morpher *abs;
    /* Variant geometries the morphers still point at: the absolute morpher's last target, the
     * relative morphers' base (NULL: G0 or none). A morpher recognises its last target by its
     * address, so a model it may remember is freed only once it has moved on (keep). */
    cm_cad_model *last, *base;
    cm_mesh *work; /* M0 with the output fields, coordinates of the row being written */
    double *sj, *dfield, *xyz;
    series *s;
    size_t n_series;
} study;

static cm_status add_row(cm_context *ctx, cm_study_result *r, const cm_study_row *row)
{
    if (r->n_rows == r->cap_rows) {
        size_t cap = r->cap_rows ? 2 * r->cap_rows : 64;
        cm_study_row *p = realloc(r->rows, cap * sizeof *p);
        if (!p) return cm_error(ctx, CM_ERR_NOMEM, "study: out of memory for rows");
        r->rows = p;
        r->cap_rows = cap;
    }
    r->rows[r->n_rows++] = *row;
    if (row->status < 0) ++r->n_failed;
    return CM_OK;
}

static void row_error(cm_study_row *row, cm_status s, const char *msg)
{
    row->status = s;
    snprintf(row->message, sizeof row->message, "%s", msg);
}

static int wants_mesh(const study *w, const cm_study_row *row)
{
    if (row->status < 0 || !w->o->out_dir) return 0;
    switch (w->o->write_meshes) {
    case CM_STUDY_WRITE_ALL: return 1;
    case CM_STUDY_WRITE_FAILED: return row->inverted > 0;
    case CM_STUDY_WRITE_LISTED: return w->o->write_listed && w->o->write_listed[row->variant];
    default: return 0;
    }
}

/* The result in w->xyz as <out_dir>/<method>_<mode>_<label>.vtu, with the morpher's scaled
 * Jacobian and the displacement from M0. */
static cm_status write_mesh(cm_context *ctx, study *w, const cm_morpher *mp, const char *label,
                            cm_study_row *row)
{
    double t0 = cm_wtime();
    cm_mesh *m = w->work;
    size_t nn = m->n_nodes;
    memcpy(m->xyz, w->xyz, 3 * nn * sizeof *m->xyz);
    for (size_t i = 0; i < 3 * nn; ++i)
        w->dfield[i] = w->xyz[i] - w->mesh0->xyz[i];
    memcpy(w->sj, cm_morpher_quality(mp), w->work->n_cells * sizeof *w->sj);
    char path[4096];
    snprintf(path, sizeof path, "%s/%s_%s_%s.vtu", w->o->out_dir, w->r->methods[row->method].name,
             cm_study_mode_name(row->mode), label);
    cm_status s = cm_mesh_write(ctx, m, path, NULL);
    row->t_write = cm_wtime() - t0;
    return s;
}

/* One morph of series se onto g: the row's figures from the morph engine's (its steps added
 * up, the quality of the last). */
static cm_status morph(cm_context *ctx, study *w, series *se, cm_morpher *mp,
                       const cm_cad_model *g, const char *label, cm_study_row *row)
{
    const cm_study_method *m = &w->r->methods[se->method];
    cm_morph_step st;
    memset(&st, 0, sizeof st);
    cm_status s = cm_morpher_apply_method(ctx, mp, g, &m->method, w->xyz, &st);
    row->t_sample += st.t_sample;
    row->t_surface += st.t_surface;
    row->t_volume_solve += st.t_volume_solve;
    row->t_evaluation += st.t_evaluation;
    row->t_distance += st.t_distance;
    row->residual = st.residual;
    if (s < 0) {
        row_error(row, s, cm_context_message(ctx));
        return s;
    }
    row->status = s;
    if (s == CM_WARNING) row_error(row, s, cm_context_message(ctx));
    row->min_sj = st.min_sj;
    row->mean_sj = st.mean_sj;
    row->inverted = st.inverted;
    row->cells = st.cells;
    row->max_dist = st.max_dist;
    row->outside = st.outside;
    if (wants_mesh(w, row)) {
        cm_status e = write_mesh(ctx, w, mp, label, row);
        if (e < 0) return e;
    }
    return s;
}

typedef struct row_key {
    size_t variant, at;
} row_key;

static int cmp_key(const void *a, const void *b)
{
    const row_key *x = a, *y = b;
    if (x->variant != y->variant) return x->variant < y->variant ? -1 : 1;
    return x->at < y->at ? -1 : x->at > y->at;
}

/* A distributed study: every rank's rows into r, variant-major as a serial study has them
 * (the rows of one variant come from one rank, in their order). */
static cm_status gather_rows(cm_context *ctx, cm_study_result *r)
{
    void *all = NULL;
    size_t n = 0;
    cm_status s = cm_parallel_allgather(ctx, r->rows, r->n_rows, sizeof *r->rows, &all, &n);
    if (s < 0) return s;
    const cm_study_row *got = all;
    row_key *key = malloc((n ? n : 1) * sizeof *key);
    cm_study_row *rows = malloc((n ? n : 1) * sizeof *rows);
    if (!key || !rows) {
        free(all), free(key), free(rows);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_study_run: out of memory");
    }
    for (size_t i = 0; i < n; ++i) key[i] = (row_key){got[i].variant, i};
    qsort(key, n, sizeof *key, cmp_key);
    r->n_failed = 0;
    for (size_t i = 0; i < n; ++i) {
        rows[i] = got[key[i].at];
        r->n_failed += rows[i].status < 0;
    }
    free(all);
    free(key);
    free(r->rows);
    r->rows = rows;
    r->n_rows = r->cap_rows = n;
    return CM_OK;
}

/* Errors of a row that are not the method's or the variant's fault end the study (and so
 * does the caller's request to stop). */
static int fatal(cm_status s)
{
    return s == CM_ERR_NOMEM || s == CM_ERR_IO || s == CM_ERR_INTERRUPTED;
}

static void log_row(cm_context *ctx, const study *w, const cm_study_row *row, const char *label)
{
    cm_log(ctx, CM_LOG_WARNING, "study: %s %s, variant %s: %s", w->r->methods[row->method].name,
           cm_study_mode_name(row->mode), label, row->message);
}

/* Every method and mode of variant i. *g: the variant's geometry (NULL if it could not be
 * used); *abs_used, *rel_used: whether the absolute morpher and live relative morphers now
 * point at it. */
static cm_status run_variant(cm_context *ctx, study *w, size_t i, cm_cad_model **gout,
                             int *abs_used, int *rel_used)
{
    const cm_study_family *f = w->fam;
    char label[256];
    f->label(f->user, i, label, sizeof label);
    double t = f->param ? f->param(f->user, i) : (double)(i + 1) / (double)f->n;
    cm_study_row base_row;
    memset(&base_row, 0, sizeof base_row);
    base_row.variant = i;
    snprintf(base_row.label, sizeof base_row.label, "%.63s", label);
    base_row.t = t;

    double t0 = cm_wtime();
    cm_cad_model *g = NULL;
    cm_status s = f->load(ctx, f->user, i, &g);
    if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "study: %s: %s", label, cm_context_message(ctx));
    /* checked here, before any morpher sees g: a variant of another topology touches none */
    if (s >= 0) {
        s = cm_cad_match(ctx, w->g0, g, 5, NULL); /* renumbers the variant like G0 */
        if (s < 0) s = cm_error_prefix(ctx, s, "not a variant of G0");
    }
    double t_load = cm_wtime() - t0;
    if (s < 0) {
        cm_cad_destroy(&g);
        if (s == CM_ERR_NOMEM || s == CM_ERR_INTERRUPTED) return s;
        cm_log(ctx, CM_LOG_WARNING, "study: variant %s: %s", label, cm_context_message(ctx));
        for (size_t k = 0; k < w->n_series; ++k) {
            cm_study_row row = base_row;
            row.mode = w->s[k].mode;
            row.method = w->s[k].method;
            row.t_sample = t_load;
            row_error(&row, s, cm_context_message(ctx));
            cm_status e = add_row(ctx, w->r, &row);
            if (e < 0) return e;
        }
        return CM_OK;
    }

    *gout = g;
    for (size_t k = 0; k < w->n_series; ++k) {
        series *se = &w->s[k];
        cm_study_row row = base_row;
        row.mode = se->mode;
        row.method = se->method;
        row.t_sample = t_load;
        if (se->mode == CM_STUDY_ABSOLUTE) {
            const cm_morpher_info *info = cm_morpher_get_info(w->abs);
            if (!se->reported) {
                row.t_classify = info->t_sample + info->t_classify;
                se->reported = 1;
            }
            s = morph(ctx, w, se, w->abs, g, label, &row);
            *abs_used = 1;
        } else if (!se->mp) {
            row_error(&row, se->stopped, se->why);
            s = CM_OK;
        } else {
            if (!se->reported) {
                const cm_morpher_info *info = cm_morpher_get_info(se->mp);
                row.t_classify = info->t_sample + info->t_classify;
                se->reported = 1;
            }
            row.t_classify += se->t_rebase;
            s = morph(ctx, w, se, se->mp, g, label, &row);
            if (s >= 0) {
                double t1 = cm_wtime();
                s = cm_morpher_rebase(ctx, se->mp, g, w->xyz);
                se->t_rebase = cm_wtime() - t1;
                if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
                if (s < 0)
                    snprintf(se->why, sizeof se->why, "not run: re-basing on variant %s failed: %s",
                             label, cm_context_message(ctx));
            } else if (!fatal(s)) {
                snprintf(se->why, sizeof se->why, "not run: the relative series stopped at "
                         "variant %s: %s", label, cm_context_message(ctx));
            }
            if (s < 0) {
                se->stopped = s;
                cm_morpher_destroy(&se->mp);
            } else {
                *rel_used = 1;
            }
        }
        if (fatal(s)) return s;
        if (row.status < 0) log_row(ctx, w, &row, label);
        if ((s = add_row(ctx, w->r, &row)) < 0) return s;
    }
    return CM_OK;
}

/* After a variant: g becomes what the morphers point at, and what they no longer point at
 * is freed. */
static void keep(study *w, cm_cad_model *g, int abs_used, int rel_used)
{
    cm_cad_model *old_last = w->last, *old_base = w->base;
    if (abs_used) w->last = g;
    if (rel_used) w->base = g;
    if (old_base == old_last) old_base = NULL; /* one model, freed once */
    if (old_last && old_last != w->last && old_last != w->base) cm_cad_destroy(&old_last);
    if (old_base && old_base != w->last && old_base != w->base) cm_cad_destroy(&old_base);
    if (g && g != w->last && g != w->base) cm_cad_destroy(&g);
}

static void study_free(study *w)
{
    cm_morpher_destroy(&w->abs);
    for (size_t k = 0; k < w->n_series; ++k)
        cm_morpher_destroy(&w->s[k].mp);
    free(w->s);
    cm_mesh_destroy(&w->work);
    free(w->xyz);
    cm_cad_model *last = w->last, *base = w->base;
    w->last = w->base = NULL;
    if (last != base) cm_cad_destroy(&base);
    cm_cad_destroy(&last);
}

/* M0's quality, the morphers, the series and the scratch arrays. */
static cm_status setup(cm_context *ctx, study *w)
{
    const cm_study_options *o = w->o;
    cm_study_result *r = w->r;
    size_t nn = w->mesh0->n_nodes;
    cm_status s = cm_mesh_copy(ctx, w->mesh0, &w->work);
    if (s >= 0) s = cm_mesh_add_field(ctx, w->work, "scaled_jacobian", CM_FIELD_CELL, 1, &w->sj);
    if (s >= 0) s = cm_mesh_add_field(ctx, w->work, "displacement", CM_FIELD_NODE, 3, &w->dfield);
    if (s < 0) return s;
    /* adding the second field may have moved the first */
    w->sj = cm_mesh_find_field(w->work, "scaled_jacobian", CM_FIELD_CELL)->data;
    cm_quality_stats q0;
    if ((s = cm_mesh_quality(ctx, w->work, w->sj)) < 0 ||
        (s = cm_quality_summarize(ctx, w->work, w->sj, NULL, &q0)) < 0)
        return s;
    r->min_sj0 = q0.min;
    r->mean_sj0 = q0.mean;
    r->inverted0 = q0.inverted;
    w->xyz = malloc(3 * (nn ? nn : 1) * sizeof *w->xyz);
    w->s = calloc(2 * r->n_methods, sizeof *w->s);
    if (!w->xyz || !w->s) return cm_error(ctx, CM_ERR_NOMEM, "study: out of memory");
    for (int mode = CM_STUDY_ABSOLUTE; mode <= CM_STUDY_RELATIVE; ++mode) {
        if (!(o->modes & mode)) continue;
        for (size_t m = 0; m < r->n_methods; ++m) {
            series *se = &w->s[w->n_series++];
            se->mode = mode;
            se->method = m;
            if (mode == CM_STUDY_ABSOLUTE && w->abs) continue;
            cm_morpher **mp = mode == CM_STUDY_ABSOLUTE ? &w->abs : &se->mp;
            cm_morph_options mo = o->morph;
            /* absolute: the targets are sampled only to measure the distance of the boundary
             * to them, at 16 times fewer samples than the classification needs (the cost that
             * would otherwise dominate a variant); relative: the fine sampling of a target is
             * reused by the rebase onto it */
            if (mode == CM_STUDY_ABSOLUTE && !(mo.target_h_scale > 0))
                mo.target_h_scale = CM_STUDY_TARGET_H_SCALE;
            s = cm_morpher_create(ctx, w->g0, w->mesh0, &mo, mp);
            if (s < 0) return cm_error_prefix(ctx, s, "M0 on G0");
            if (s == CM_WARNING && mode == CM_STUDY_ABSOLUTE)
                cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
            const cm_morpher_info *info = cm_morpher_get_info(*mp);
            r->boundary_nodes = info->boundary_nodes;
        }
    }
    return CM_OK;
}

cm_status cm_study_run(cm_context *ctx, const cm_cad_model *g0, const cm_mesh *mesh,
                       const cm_study_family *family, const cm_study_options *opt,
                       cm_study_result **result)
{
    if (result) *result = NULL;
    if (!g0 || !mesh || !family || !family->load || !family->label || !opt || !result)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_run: NULL input");
    if (!(opt->modes & CM_STUDY_BOTH) || opt->morph.steps < 0 || (opt->methods && !opt->n_methods))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_run: modes %d, steps %d, %zu methods",
                        opt->modes, opt->morph.steps, opt->n_methods);
    const int ranks = opt->ranks > 1 ? opt->ranks : 1;
    if (ranks > 1 && ((opt->modes & CM_STUDY_RELATIVE) || opt->rank < 0 || opt->rank >= ranks))
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_study_run: over %d ranks only absolute studies (relative steps "
                        "chain the variants); rank %d",
                        ranks, opt->rank);
    if (opt->write_meshes == CM_STUDY_WRITE_LISTED && !opt->write_listed)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_run: listed meshes without a list");
    double t_start = cm_wtime();
    study w;
    memset(&w, 0, sizeof w);
    w.o = opt;
    w.fam = family;
    w.g0 = g0;
    w.mesh0 = mesh;
    cm_study_result *r = w.r = calloc(1, sizeof *w.r);
    size_t nm = opt->methods ? opt->n_methods : 3;
    if (r) r->methods = calloc(nm, sizeof *r->methods);
    if (!r || !r->methods) {
        cm_study_result_destroy(&w.r);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_study_run: out of memory");
    }
    r->n_methods = opt->methods ? nm : cm_study_default_methods(r->methods, nm);
    if (opt->methods) memcpy(r->methods, opt->methods, nm * sizeof *r->methods);
    snprintf(r->model, sizeof r->model, "%s", opt->model ? opt->model : "G0");
    snprintf(r->mesh, sizeof r->mesh, "%s", opt->mesh ? opt->mesh : "file");
    r->nodes = mesh->n_nodes;
    r->cells = cm_mesh_count_dim(mesh, 3);
    r->n_variants = family->n;
    snprintf(r->x_label, sizeof r->x_label, "%s", family->x_label ? family->x_label : "variant");
    r->x_max = family->x_max > 0 || family->x_min < family->x_max ? family->x_max
                                                                  : (double)family->n;
    r->x_tick = family->x_tick;
    r->x_min = family->x_min < r->x_max ? family->x_min : 0;
    r->x0 = family->x0;
    if (family->n_values && family->value_names && family->values) {
        r->value_names = calloc(family->n_values, sizeof *r->value_names);
        r->values = calloc(family->n_values * (family->n ? family->n : 1), sizeof *r->values);
        if (!r->value_names || !r->values) {
            cm_study_result_destroy(&w.r);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_study_run: out of memory");
        }
        r->n_values = family->n_values;
        for (size_t k = 0; k < r->n_values; ++k)
            snprintf(r->value_names[k], sizeof r->value_names[k], "%s", family->value_names[k]);
        for (size_t i = 0; i < family->n; ++i)
            memcpy(r->values + i * r->n_values, family->values(family->user, i),
                   r->n_values * sizeof *r->values);
    }
    double bb[6];
    cm_cad_bbox(g0, bb);
    r->diagonal = cm_bbox_diagonal(bb);
    r->threads = cm_context_threads(ctx);
    if (r->threads <= 0) r->threads = (int)sysconf(_SC_NPROCESSORS_ONLN);

    cm_status s = setup(ctx, &w);
    for (size_t i = 0; i < family->n && s >= 0; ++i) {
        if (ranks > 1 && (int)(i % (size_t)ranks) != opt->rank) continue; /* another rank's */
        if ((s = cm_progress(ctx, "study", (double)i, (double)family->n)) < 0) break;
        cm_cad_model *g = NULL;
        int abs_used = 0, rel_used = 0;
        s = run_variant(ctx, &w, i, &g, &abs_used, &rel_used);
        if (s < 0) { /* study_free: the morphers first, then last and base */
            if (g != w.last && g != w.base) cm_cad_destroy(&g);
            break;
        }
        keep(&w, g, abs_used, rel_used);
    }
    if (s >= 0) s = cm_progress(ctx, "study", (double)family->n, (double)family->n);
    study_free(&w);
    /* every rank gathers, also one that failed: the others would wait for it */
    if (ranks > 1) {
        cm_status g = gather_rows(ctx, w.r);
        if (s >= 0 && g < 0) s = g;
    }
    if (s < 0) {
        cm_study_result_destroy(&w.r);
        return s;
    }
    r->t_total = cm_wtime() - t_start;
    *result = r;
    for (size_t i = 0; i < r->n_rows; ++i)
        if (r->rows[i].status < 0)
            return cm_error(ctx, CM_WARNING, "%zu of %zu rows failed; first: %s, %s, variant %s: %s",
                            r->n_failed, r->n_rows, r->methods[r->rows[i].method].name,
                            cm_study_mode_name(r->rows[i].mode), r->rows[i].label,
                            r->rows[i].message);
    return CM_OK;
}
