/* The study driver (study.h): M0 morphed onto every variant of a family by each method,
 * absolutely through one shared cm_morpher (classification of M0 once, one factorisation per
 * warp method for the whole family: the point of the design, DESIGN.md) and relatively
 * through one morpher per method re-based on each result. */
#include "cadmorph/study.h"
#include "cadmorph/parallel.h"

#include <math.h>
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
    /* The variant geometry the relative morphers are based on (NULL: G0 or none): a morpher
     * recognises its last target by its address, so that model is freed only once they have
     * moved on. The absolute morpher keeps none (cm_morpher_apply_batch). */
    cm_cad_model *base;
    cm_mesh *work; /* M0 with the output fields, coordinates of the row being written */
    double *sj, *dfield, *xyz;
    series *s;
    size_t n_series;
    size_t batch;    /* variants per batch of the absolute morphs */
    double **bxyz;   /* batch results (#nodes x 3 each) */
    cm_morph_batch_item *items;
    int rel_ranked;  /* relative series over the ranks: series of method m on rank m % ranks */
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

/* The result xyz as <out_dir>/<method>_<mode>_<label>.vtu, with its scaled Jacobian sj
 * and the displacement from M0. */
static cm_status write_mesh(cm_context *ctx, study *w, const double *xyz, const double *sj,
                            const char *label, cm_study_row *row)
{
    double t0 = cm_wtime();
    cm_mesh *m = w->work;
    size_t nn = m->n_nodes;
    memcpy(m->xyz, xyz, 3 * nn * sizeof *m->xyz);
    for (size_t i = 0; i < 3 * nn; ++i)
        w->dfield[i] = xyz[i] - w->mesh0->xyz[i];
    if (sj)
        memcpy(w->sj, sj, w->work->n_cells * sizeof *w->sj);
    else { /* what the morph measured on these nodes */
        cm_status e = cm_mesh_quality(ctx, m, w->sj);
        if (e < 0) return e;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/%s_%s_%s.vtu", w->o->out_dir, w->r->methods[row->method].name,
             cm_study_mode_name(row->mode), label);
    cm_status s = cm_mesh_write(ctx, m, path, NULL);
    row->t_write = cm_wtime() - t0;
    return s;
}

/* A row's figures from a morph's status, message and row (its steps added up, the quality
 * of the last). */
static cm_status fill_row(cm_study_row *row, cm_status s, const char *msg, const cm_morph_step *st)
{
    row->t_sample += st->t_sample;
    row->t_surface += st->t_surface;
    row->t_volume_solve += st->t_volume_solve;
    row->t_evaluation += st->t_evaluation;
    row->t_distance += st->t_distance;
    row->residual = st->residual;
    if (s < 0) {
        row_error(row, s, msg);
        return s;
    }
    row->status = s;
    if (s == CM_WARNING) row_error(row, s, msg);
    row->min_sj = st->min_sj;
    row->mean_sj = st->mean_sj;
    row->inverted = st->inverted;
    row->cells = st->cells;
    row->max_dist = st->max_dist;
    row->outside = st->outside;
    return s;
}

/* One morph of series se onto g (relative: its own morpher). */
static cm_status morph(cm_context *ctx, study *w, series *se, cm_morpher *mp,
                       const cm_cad_model *g, const char *label, cm_study_row *row)
{
    const cm_study_method *m = &w->r->methods[se->method];
    cm_morph_step st;
    memset(&st, 0, sizeof st);
    cm_status s = cm_morpher_apply_method(ctx, mp, g, &m->method, w->xyz, &st);
    s = fill_row(row, s, cm_context_message(ctx), &st);
    if (s >= 0 && wants_mesh(w, row)) {
        cm_status e = write_mesh(ctx, w, w->xyz, cm_morpher_quality(mp), label, row);
        if (e < 0) return e;
    }
    return s;
}

typedef struct row_key {
    size_t variant, mode, method, at;
} row_key;

static int cmp_key(const void *a, const void *b)
{
    const row_key *x = a, *y = b;
    if (x->variant != y->variant) return x->variant < y->variant ? -1 : 1;
    if (x->mode != y->mode) return x->mode < y->mode ? -1 : 1;
    if (x->method != y->method) return x->method < y->method ? -1 : 1;
    return x->at < y->at ? -1 : x->at > y->at;
}

/* How one rank's part of a distributed study ended. */
typedef struct rank_outcome {
    cm_status status;
    char message[512];
} rank_outcome;

/* A distributed study ends as a serial one would: a rank's error (out of memory, a mesh that
 * could not be written, an interrupt) ends every rank's study, or rank 0 would write the rows
 * it has as the study's, the failed rank's missing. s: this rank's status; the result, the
 * first error over the ranks (this rank's own when it has one: its message is in ctx). */
static cm_status agree_status(cm_context *ctx, cm_status s)
{
    rank_outcome mine = {s, ""};
    if (s < 0) snprintf(mine.message, sizeof mine.message, "%s", cm_context_message(ctx));
    void *all = NULL;
    size_t n = 0;
    cm_status g = cm_parallel_allgather(ctx, &mine, 1, sizeof mine, &all, &n);
    if (s < 0) {
        free(all);
        return s;
    }
    if (g < 0) return g;
    const rank_outcome *got = all;
    for (size_t q = 0; q < n && s >= 0; ++q)
        if (got[q].status < 0)
            s = cm_error(ctx, got[q].status, "rank %zu of %zu: %s", q, n, got[q].message);
    free(all);
    return s;
}

/* A distributed study: every rank's rows into r, variant-major as a serial study has them
 * (per variant in series order: mode, then method). */
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
    for (size_t i = 0; i < n; ++i)
        key[i] = (row_key){got[i].variant, (size_t)got[i].mode, got[i].method, i};
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

/* A variant loaded for a batch: its model (NULL when it could not be used: its rows are
 * made already) and what every row of it starts with. */
typedef struct variant {
    cm_cad_model *g;
    char label[256];
    cm_study_row base;
    int abs; /* this rank runs its absolute rows */
} variant;

/* Whether this rank runs series se's row of variant i: absolute rows by variant (i mod
 * ranks), relative series by method (a chain cannot be split: method m's on rank m mod
 * ranks). */
static int owns(const study *w, const series *se, size_t i)
{
    const int ranks = w->o->ranks > 1 ? w->o->ranks : 1;
    if (ranks == 1) return 1;
    if (se->mode == CM_STUDY_ABSOLUTE) return (int)(i % (size_t)ranks) == w->o->rank;
    return (int)(se->method % (size_t)ranks) == w->o->rank;
}

/* Whether this rank says what is wrong with variant i itself: of the ranks that load it, one
 * (a serial study says it once): the rank of its absolute rows, or without those rank 0 (the
 * first method's relative series: every variant). */
static int says_variant(const study *w, size_t i)
{
    const int ranks = w->o->ranks > 1 ? w->o->ranks : 1;
    if (ranks == 1) return 1;
    if (w->o->modes & CM_STUDY_ABSOLUTE) return (int)(i % (size_t)ranks) == w->o->rank;
    return w->o->rank == 0;
}

/* Reads variant i and checks it against G0; one that cannot be used is a row with its error
 * for each series this rank runs. */
static cm_status load_variant(cm_context *ctx, study *w, size_t i, variant *v)
{
    const cm_study_family *f = w->fam;
    memset(v, 0, sizeof *v);
    f->label(f->user, i, v->label, sizeof v->label);
    v->base.variant = i;
    snprintf(v->base.label, sizeof v->base.label, "%.63s", v->label);
    v->base.t = f->param ? f->param(f->user, i) : (double)(i + 1) / (double)f->n;
    double t0 = cm_wtime();
    cm_cad_model *g = NULL;
    cm_status s = f->load(ctx, f->user, i, &g);
    if (s == CM_WARNING && says_variant(w, i))
        cm_log(ctx, CM_LOG_WARNING, "study: %s: %s", v->label, cm_context_message(ctx));
    /* checked here, before any morpher sees g: a variant of another topology touches none */
    if (s >= 0) {
        s = cm_cad_match(ctx, w->g0, g, 5, NULL); /* renumbers the variant like G0 */
        if (s < 0) s = cm_error_prefix(ctx, s, "not a variant of G0");
    }
    v->base.t_sample = cm_wtime() - t0;
    if (s >= 0) {
        v->g = g;
        return CM_OK;
    }
    cm_cad_destroy(&g);
    if (s == CM_ERR_NOMEM || s == CM_ERR_INTERRUPTED) return s;
    if (says_variant(w, i))
        cm_log(ctx, CM_LOG_WARNING, "study: variant %s: %s", v->label, cm_context_message(ctx));
    row_error(&v->base, s, cm_context_message(ctx)); /* every row of it */
    return CM_OK;
}

/* The groups the warp solves a batch in (cm_warp_options.warm_groups): the first from zero
 * (or warm from the batches before), each later one warm from the solutions before it, which
 * saves more than a larger group's passes share (bracket, 10^5 boundary nodes, 20 variants:
 * batches of 5 the fastest, 20 the slowest, before batches were grouped; benchmarks/
 * RESULTS.md, "Study"), while the evaluation at the interior nodes sums the whole batch in one
 * pass, where each column costs less the more ride along ("Kernel cost per column"). */
#define CM_STUDY_WARM_GROUPS 4

/* The solves the shared warp of method q will serve (cm_warp_options.solves, for AUTO's
 * choice of the RBF solver): one per variant this rank runs, for each method with the same
 * warp options (the morpher keeps one warp per set of options: rbf and rbf-s share one).
 * Variants that fail to load are counted too: the count is known before the first. */
static int abs_solves(const study *w, size_t q)
{
    const cm_study_method *ms = w->r->methods;
    const int ranks = w->o->ranks > 1 ? w->o->ranks : 1;
    size_t variants = w->fam->n / (size_t)ranks +
                      ((size_t)w->o->rank < w->fam->n % (size_t)ranks ? 1 : 0);
    size_t sharing = 0;
    for (size_t j = 0; j < w->r->n_methods; ++j)
        sharing += !memcmp(&ms[j].method.warp, &ms[q].method.warp, sizeof ms[q].method.warp);
    const double solves = (double)variants * (double)sharing;
    return solves < 1e9 ? (int)solves : 1000000000;
}

/* The absolute rows of series se (mode absolute) for the batch's variants that this rank
 * runs, into rows[j] (one per variant; the meshes written): one cm_morpher_apply_batch per
 * w->batch variants. */
static cm_status absolute_rows(cm_context *ctx, study *w, series *se, variant *v, size_t n,
                               cm_study_row *rows)
{
    const cm_study_method *m = &w->r->methods[se->method];
    cm_morph_method method = m->method;
    method.warp.solves = abs_solves(w, se->method);
    method.warp.warm_groups = CM_STUDY_WARM_GROUPS;
    const cm_cad_model **targets = malloc((n ? n : 1) * sizeof *targets);
    size_t *of = malloc((n ? n : 1) * sizeof *of), k = 0;
    cm_status s = targets && of ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "study: out of memory");
    for (size_t j = 0; j < n && s >= 0; ++j)
        if (v[j].abs && v[j].g) {
            targets[k] = v[j].g;
            of[k++] = j;
        }
    if (s >= 0) s = cm_morpher_apply_batch(ctx, w->abs, k, targets, &method, w->bxyz, w->items);
    for (size_t q = 0; q < k && s >= 0; ++q) {
        cm_study_row *row = &rows[of[q]];
        const cm_morph_batch_item *it = &w->items[q];
        if (!se->reported) {
            const cm_morpher_info *info = cm_morpher_get_info(w->abs);
            row->t_classify = info->t_sample + info->t_classify;
            se->reported = 1;
        }
        if (fill_row(row, it->status, it->message, &it->row) >= 0 && wants_mesh(w, row))
            s = write_mesh(ctx, w, w->bxyz[q], NULL, v[of[q]].label, row);
        if (fatal(it->status)) s = it->status;
    }
    free(targets);
    free(of);
    return s;
}

/* Series se's (relative) row of variant v: the morph from its last result, then the re-base
 * onto it; a failure stops the series (its later rows say why). *used: the morpher is now
 * based on v's model. */
static cm_status relative_row(cm_context *ctx, study *w, series *se, const variant *v,
                              cm_study_row *row, int *used)
{
    if (!se->mp) {
        row_error(row, se->stopped, se->why);
        return CM_OK;
    }
    if (!se->reported) {
        const cm_morpher_info *info = cm_morpher_get_info(se->mp);
        row->t_classify = info->t_sample + info->t_classify;
        se->reported = 1;
    }
    row->t_classify += se->t_rebase;
    cm_status s = morph(ctx, w, se, se->mp, v->g, v->label, row);
    if (s >= 0) {
        double t1 = cm_wtime();
        s = cm_morpher_rebase(ctx, se->mp, v->g, w->xyz);
        se->t_rebase = cm_wtime() - t1;
        if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
        if (s < 0)
            snprintf(se->why, sizeof se->why, "not run: re-basing on variant %s failed: %s",
                     v->label, cm_context_message(ctx));
    } else if (!fatal(s)) {
        snprintf(se->why, sizeof se->why, "not run: the relative series stopped at "
                 "variant %s: %s", v->label, cm_context_message(ctx));
    }
    if (s < 0) {
        se->stopped = s;
        cm_morpher_destroy(&se->mp);
    } else {
        *used = 1;
    }
    return s;
}

/* Variants first .. first + n - 1 that this rank needs: loaded, the absolute rows in
 * batches, then per variant in order its rows (series order), the relative ones morphed
 * there. Frees the batch's models but the relative morphers' base. */
static cm_status run_batch(cm_context *ctx, study *w, const size_t *idx, size_t n)
{
    const int ranks = w->o->ranks > 1 ? w->o->ranks : 1;
    variant *v = calloc(n ? n : 1, sizeof *v);
    cm_study_row *rows = calloc((n ? n : 1) * w->n_series, sizeof *rows);
    cm_status s = v && rows ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "study: out of memory");
    size_t loaded = 0;
    for (size_t j = 0; j < n && s >= 0; ++j, ++loaded) {
        s = load_variant(ctx, w, idx[j], &v[j]);
        v[j].abs = ranks == 1 || (int)(idx[j] % (size_t)ranks) == w->o->rank;
        for (size_t q = 0; q < w->n_series; ++q) {
            cm_study_row *row = &rows[j * w->n_series + q];
            *row = v[j].base;
            row->mode = w->s[q].mode;
            row->method = w->s[q].method;
        }
    }
    /* the absolute series, in batches over the variants (their rows kept for the order) */
    cm_study_row *col = malloc((n ? n : 1) * sizeof *col);
    if (s >= 0 && !col) s = cm_error(ctx, CM_ERR_NOMEM, "study: out of memory");
    for (size_t q = 0; q < w->n_series && s >= 0; ++q) {
        if (w->s[q].mode != CM_STUDY_ABSOLUTE) continue;
        for (size_t j = 0; j < n; ++j)
            col[j] = rows[j * w->n_series + q];
        s = absolute_rows(ctx, w, &w->s[q], v, n, col);
        for (size_t j = 0; j < n; ++j)
            rows[j * w->n_series + q] = col[j];
    }
    free(col);
    /* per variant: the relative series from their last results, then every row in order */
    for (size_t j = 0; j < n && s >= 0; ++j) {
        int used = 0;
        for (size_t q = 0; q < w->n_series && s >= 0; ++q) {
            series *se = &w->s[q];
            cm_study_row *row = &rows[j * w->n_series + q];
            if (!owns(w, se, idx[j])) continue;
            if (se->mode == CM_STUDY_RELATIVE && v[j].g) {
                cm_status e = relative_row(ctx, w, se, &v[j], row, &used);
                if (fatal(e)) s = e;
            }
            if (s < 0) break;
            if (row->status < 0) log_row(ctx, w, row, v[j].label);
            s = add_row(ctx, w->r, row);
        }
        if (used && v[j].g != w->base) { /* the relative morphers moved on to this variant */
            int in_batch = 0;
            for (size_t k = 0; k < n; ++k)
                in_batch |= v[k].g == w->base;
            if (!in_batch) cm_cad_destroy(&w->base);
            w->base = v[j].g;
        }
    }
    for (size_t j = 0; j < loaded; ++j)
        if (v[j].g != w->base) cm_cad_destroy(&v[j].g);
    free(v);
    free(rows);
    return s;
}

static void study_free(study *w)
{
    cm_morpher_destroy(&w->abs);
    for (size_t k = 0; k < w->n_series; ++k)
        cm_morpher_destroy(&w->s[k].mp);
    free(w->s);
    cm_mesh_destroy(&w->work);
    free(w->xyz);
    if (w->bxyz)
        for (size_t j = 0; j < w->batch; ++j)
            free(w->bxyz[j]);
    free(w->bxyz);
    free(w->items);
    cm_cad_destroy(&w->base);
}

/* Variants per batch: o->batch, or (0) all the variants this rank runs, as many as half the
 * available memory holds, up to CM_STUDY_BATCH_MAX (the kernel sums' cost per column has
 * flattened by 60 columns, the same section). Memory per variant: for each of its 3 columns
 * of an iterative RBF solve the Krylov storage, (2 restart + 9) doubles per boundary node
 * (rbf.h, cm_rbf_solve; the default restart, 40), while its group solves (one in
 * CM_STUDY_WARM_GROUPS at a time: counted for all, a margin that also holds the first group's
 * weights and products kept for the later groups' starts, 4 doubles per boundary node and
 * column of that group), and its columns' data and
 * weights once more in the order the groups take them; the apply's fields, the evaluation's
 * values, the result and, where the evaluation goes through the span of others, the summed
 * and the combined columns' values (3 doubles per node each); its loaded model (a few MB:
 * 8 MB counted). */
static size_t batch_size(const cm_study_options *o, size_t variants, size_t nodes,
                         size_t boundary)
{
    if (!(o->modes & CM_STUDY_ABSOLUTE)) return 1;
    if (o->batch > 0) return (size_t)o->batch;
    const double restart = 40;
    const double per = 8.0 * (3 * (2 * restart + 9) * (double)boundary + 15.0 * (double)nodes +
                              9.0 * (double)boundary) + 8e6;
    double k = fmin(0.5 * cm_memory_available() / per, (double)variants);
    if (!(k >= 1)) return 1;
    return k < CM_STUDY_BATCH_MAX ? (size_t)k : CM_STUDY_BATCH_MAX;
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
            if (mode == CM_STUDY_RELATIVE && !owns(w, se, 0)) continue; /* another rank's */
            cm_morpher **mp = mode == CM_STUDY_ABSOLUTE ? &w->abs : &se->mp;
            s = cm_morpher_create(ctx, w->g0, w->mesh0, &o->morph, mp);
            if (s < 0) return cm_error_prefix(ctx, s, "M0 on G0");
            /* a CM_WARNING is logged by cm_morpher_create already */
            const cm_morpher_info *info = cm_morpher_get_info(*mp);
            r->boundary_nodes = info->boundary_nodes;
        }
    }
    const int ranks = o->ranks > 1 ? o->ranks : 1;
    w->batch = batch_size(o, (w->fam->n + (size_t)ranks - 1) / (size_t)ranks, nn,
                          r->boundary_nodes);
    cm_log(ctx, CM_LOG_DEBUG, "study: absolute morphs in batches of up to %zu variants%s, "
           "solved in %d groups", w->batch, o->batch > 0 ? " (asked for)"
           : " (the variants, memory, CM_STUDY_BATCH_MAX)", CM_STUDY_WARM_GROUPS);
    w->bxyz = calloc(w->batch, sizeof *w->bxyz);
    w->items = malloc(w->batch * sizeof *w->items);
    if (!w->bxyz || !w->items) return cm_error(ctx, CM_ERR_NOMEM, "study: out of memory");
    for (size_t j = 0; j < w->batch; ++j)
        if (!(w->bxyz[j] = malloc(3 * (nn ? nn : 1) * sizeof *w->bxyz[j])))
            return cm_error(ctx, CM_ERR_NOMEM, "study: out of memory for %zu batch results",
                            w->batch);
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
    if (ranks > 1 && (opt->rank < 0 || opt->rank >= ranks))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_run: rank %d of %d", opt->rank, ranks);
    if (opt->batch < 0)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_run: batch %d (0: auto, K >= 1)",
                        opt->batch);
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
    /* the variants this rank needs (its absolute ones; all for a relative series it runs), in
     * batches of w.batch */
    size_t *idx = s >= 0 ? malloc((w.batch ? w.batch : 1) * sizeof *idx) : NULL;
    if (s >= 0 && !idx) s = cm_error(ctx, CM_ERR_NOMEM, "cm_study_run: out of memory");
    for (size_t i = 0, n = 0; i < family->n && s >= 0; ++i) {
        int need = 0;
        for (size_t q = 0; q < w.n_series; ++q)
            need |= owns(&w, &w.s[q], i);
        if (need) idx[n++] = i;
        if (n < w.batch && i + 1 < family->n) continue;
        if (n && (s = cm_progress(ctx, "study", (double)idx[0], (double)family->n)) >= 0)
            s = run_batch(ctx, &w, idx, n);
        n = 0;
    }
    free(idx);
    if (s >= 0) s = cm_progress(ctx, "study", (double)family->n, (double)family->n);
    study_free(&w);
    /* every rank gathers, also one that failed: the others would wait for it */
    if (ranks > 1) {
        cm_status g = gather_rows(ctx, w.r);
        if (s >= 0 && g < 0) s = g;
        s = agree_status(ctx, s);
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
