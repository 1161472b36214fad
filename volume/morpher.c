/* The morph engine (morph.h): M's boundary classified on G once; for each target G' the
 * surface morph (paper section 4) moves the boundary nodes onto G', and the interior follows
 * by a warp (section 3) whose factorisation depends only on M, kept per method. */
#include "cadmorph/morph.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct cm_morpher {
    cm_morph_options opt;
    const cm_cad_model *g; /* borrowed: the geometry the start mesh lies on */
    cm_mesh *mesh;         /* the start mesh (own copy) */
    cm_mesh_boundary *b;
    cm_cad_locator *loc; /* on g */
    cm_surface_nodes *nodes;
    cm_warp *warp[CM_WARP_N_METHODS]; /* on mesh, made when first used */
    const cm_cad_model *target;       /* the last target (borrowed) and its locator */
    cm_cad_locator *target_loc;
    cm_mesh *work; /* a copy of mesh whose coordinates are the result being measured */
    double *sj;    /* work's scaled_jacobian field */
    double *disp;  /* #nodes x 3 */
    double *bnew;  /* #boundary x 3: the surface morph's positions on the target */
    double *bxyz;  /* #boundary x 3: the positions of the current increment */
    cm_surface_morph_stats surface;
    cm_morpher_info info;
};

void cm_morph_method_init(cm_morph_method *m)
{
    m->surface = CM_SURFACE_RBF;
    cm_warp_options_init(&m->warp);
}

void cm_morph_options_init(cm_morph_options *opt)
{
    memset(opt, 0, sizeof *opt);
    cm_morph_method_init(&opt->method);
    opt->steps = 1;
    cm_classify_options_init(&opt->classify);
    cm_surface_morph_options_init(&opt->morph);
}

/* Warnings found before the mesh is known to lie on G are held back: a mesh in the wrong unit
 * makes the sampling warn about its cap, and the user should see only the real error. */
typedef struct held_warnings {
    int n;
    char msg[4][1024];
} held_warnings;

static void hold(cm_context *ctx, held_warnings *h, cm_status s)
{
    if (s == CM_WARNING && h->n < 4)
        snprintf(h->msg[h->n++], sizeof h->msg[0], "%s", cm_context_message(ctx));
}

static cm_status release(cm_context *ctx, const held_warnings *h)
{
    for (int i = 0; i < h->n; ++i)
        cm_log(ctx, CM_LOG_WARNING, "%s", h->msg[i]);
    return h->n ? cm_error(ctx, CM_WARNING, "%s", h->msg[0]) : CM_OK;
}

static cm_status make_locator(cm_context *ctx, const cm_morpher *mp, const cm_cad_model *g,
                              cm_cad_locator **loc)
{
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    so.h = mp->info.h;
    so.max_samples = mp->opt.max_samples ? mp->opt.max_samples : CM_MORPH_MAX_SAMPLES;
    return cm_cad_locator_create(ctx, g, &so, loc);
}

/* Samples g (once h is known) and classifies the boundary of mp->mesh on it. */
static cm_status classify(cm_context *ctx, cm_morpher *mp, held_warnings *held)
{
    double t0 = cm_wtime();
    cm_status s = CM_OK;
    if (!mp->loc) {
        s = make_locator(ctx, mp, mp->g, &mp->loc);
        if (s < 0) return s;
        hold(ctx, held, s);
        mp->info.h = cm_cad_locator_h(mp->loc);
    }
    double t1 = cm_wtime();
    cm_surface_nodes_destroy(&mp->nodes);
    s = cm_surface_classify(ctx, mp->g, mp->loc, mp->mesh, mp->b, &mp->opt.classify, &mp->nodes);
    if (s < 0) return s;
    for (int k = 0; k < 3; ++k)
        mp->info.counts[k] = mp->nodes->count[k];
    mp->info.class_dist = mp->nodes->max_dist;
    double bb[6];
    cm_cad_bbox(mp->g, bb);
    mp->info.diagonal = cm_bbox_diagonal(bb);
    mp->info.t_sample = t1 - t0;
    mp->info.t_classify = cm_wtime() - t1;
    cm_log(ctx, CM_LOG_DEBUG,
           "classify: %zu boundary nodes: %zu on vertices, %zu on edges, %zu on faces (largest "
           "distance to G %.3g); sampling h %.4g",
           mp->nodes->n, mp->info.counts[0], mp->info.counts[1], mp->info.counts[2],
           mp->info.class_dist, mp->info.h);
    return CM_OK;
}

static void drop_warps(cm_morpher *mp)
{
    for (int m = 0; m < CM_WARP_N_METHODS; ++m)
        cm_warp_destroy(&mp->warp[m]);
}

void cm_morpher_destroy(cm_morpher **morpher)
{
    if (!morpher || !*morpher) return;
    cm_morpher *mp = *morpher;
    drop_warps(mp);
    cm_cad_locator_destroy(&mp->loc);
    cm_cad_locator_destroy(&mp->target_loc);
    cm_surface_nodes_destroy(&mp->nodes);
    cm_mesh_boundary_destroy(&mp->b);
    cm_mesh_destroy(&mp->mesh);
    cm_mesh_destroy(&mp->work);
    free(mp->disp);
    free(mp->bnew);
    free(mp->bxyz);
    free(mp);
    *morpher = NULL;
}

cm_status cm_morpher_create(cm_context *ctx, const cm_cad_model *g, const cm_mesh *mesh,
                            const cm_morph_options *opt, cm_morpher **morpher)
{
    if (morpher) *morpher = NULL;
    if (!g || !mesh || !morpher)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_create: NULL input");
    cm_morpher *mp = calloc(1, sizeof *mp);
    if (!mp) return cm_error(ctx, CM_ERR_NOMEM, "cm_morpher_create: out of memory");
    if (opt)
        mp->opt = *opt;
    else
        cm_morph_options_init(&mp->opt);
    mp->g = g;
    held_warnings held = {0};
    cm_status s = mp->opt.steps >= 1
                      ? cm_mesh_copy(ctx, mesh, &mp->mesh)
                      : cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_create: steps must be >= 1");
    if (s >= 0) s = cm_mesh_boundary_create(ctx, mp->mesh, &mp->b);
    hold(ctx, &held, s);
    if (s >= 0 && mp->b->n_nodes == 0)
        s = cm_error(ctx, CM_ERR_UNSUPPORTED, "no volume cells, nothing to morph");
    double hmin = 0;
    if (s >= 0) s = cm_surface_edge_lengths(ctx, mp->mesh, mp->b, NULL, &hmin);
    if (s >= 0 && !(hmin > 0))
        s = cm_error(ctx, CM_ERR_FORMAT, "all boundary edges have zero length");
    mp->info.h = hmin / 4;
    if (s >= 0) s = classify(ctx, mp, &held);
    size_t nn = mp->mesh ? mp->mesh->n_nodes : 0, nb = mp->nodes ? mp->nodes->n : 0;
    if (s >= 0) s = cm_mesh_copy(ctx, mp->mesh, &mp->work);
    if (s >= 0) s = cm_mesh_add_field(ctx, mp->work, "scaled_jacobian", CM_FIELD_CELL, 1, &mp->sj);
    if (s >= 0) {
        mp->disp = malloc(3 * (nn ? nn : 1) * sizeof *mp->disp);
        mp->bnew = malloc(3 * (nb ? nb : 1) * sizeof *mp->bnew);
        mp->bxyz = malloc(3 * (nb ? nb : 1) * sizeof *mp->bxyz);
        if (!mp->disp || !mp->bnew || !mp->bxyz)
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_morpher_create: out of memory for %zu nodes", nn);
    }
    if (s < 0) {
        cm_morpher_destroy(&mp);
        return s;
    }
    mp->info.nodes = nn;
    mp->info.cells = cm_mesh_count_dim(mp->mesh, 3);
    mp->info.boundary_nodes = nb;
    mp->info.components = mp->b->n_components;
    *morpher = mp;
    return release(ctx, &held);
}

/* The locator of target (for distances), kept while the same target comes back. */
static cm_status use_target(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target,
                            cm_morph_step *first)
{
    if (target == mp->target && mp->target_loc) return CM_OK;
    cm_status s = target == mp->g ? CM_OK : cm_cad_compare(ctx, mp->g, target, 5);
    if (s < 0) return cm_error_prefix(ctx, s, "the target does not correspond to G");
    double t0 = cm_wtime();
    cm_cad_locator_destroy(&mp->target_loc);
    mp->target = NULL;
    s = make_locator(ctx, mp, target, &mp->target_loc);
    if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
    if (s < 0) return s;
    mp->target = target;
    if (first) first->t_sample += cm_wtime() - t0;
    return CM_OK;
}

/* The warp of method on the start mesh, made on first use; *t: its factorisation time. */
static cm_status shared_warp(cm_context *ctx, cm_morpher *mp, const cm_warp_options *wo,
                             cm_warp **warp, double *t)
{
    cm_warp **slot = &mp->warp[wo->method];
    if (!*slot) {
        double t0 = cm_wtime();
        cm_status s = cm_warp_create(ctx, mp->mesh, mp->b, NULL, wo, slot);
        if (s < 0) return s;
        *t = cm_wtime() - t0;
    }
    *warp = *slot;
    return CM_OK;
}

/* Increment k of n: the boundary at fraction k/n of its motion, the interior by the warp
 * made on the coordinates xyz (in: after increment k - 1, out: after k). */
static cm_status increment(cm_context *ctx, cm_morpher *mp, const cm_warp_options *wo, int k,
                           int n, double *xyz, cm_morph_step *row)
{
    const cm_surface_nodes *nd = mp->nodes;
    size_t nn = mp->mesh->n_nodes;
    double frac = (double)k / n;
    memset(mp->disp, 0, 3 * nn * sizeof *mp->disp);
    for (size_t i = 0; i < nd->n; ++i)
        for (int c = 0; c < 3; ++c) {
            double want = nd->xyz[3 * i + c] + frac * (mp->bnew[3 * i + c] - nd->xyz[3 * i + c]);
            if (k == n) want = mp->bnew[3 * i + c];
            mp->bxyz[3 * i + c] = want;
            mp->disp[3 * nd->node[i] + c] = want - xyz[3 * nd->node[i] + c];
        }
    cm_warp *w = NULL, *own = NULL;
    double t0 = cm_wtime();
    cm_status s;
    if (k == 1) {
        s = shared_warp(ctx, mp, wo, &w, &row->t_volume_solve);
    } else {
        /* later increments start from the moved mesh: a warp of its own */
        memcpy(mp->work->xyz, xyz, 3 * nn * sizeof *xyz);
        s = cm_warp_create(ctx, mp->work, mp->b, NULL, wo, &own);
        w = own;
        row->t_volume_solve = cm_wtime() - t0;
    }
    double t1 = cm_wtime();
    if (s >= 0) s = cm_warp_apply(ctx, w, mp->disp);
    row->residual = cm_warp_residual(w);
    cm_warp_destroy(&own);
    if (s < 0) return s;
    for (size_t i = 0; i < 3 * nn; ++i)
        xyz[i] += mp->disp[i];
    /* boundary nodes exactly where they were sent (no round-off from the increments) */
    for (size_t i = 0; i < nd->n; ++i)
        memcpy(xyz + 3 * nd->node[i], mp->bxyz + 3 * i, 3 * sizeof(double));
    memcpy(mp->work->xyz, xyz, 3 * nn * sizeof *xyz);
    cm_quality_stats all;
    s = cm_mesh_quality(ctx, mp->work, mp->sj);
    if (s >= 0) s = cm_quality_summarize(ctx, mp->work, mp->sj, NULL, &all);
    row->t_evaluation = cm_wtime() - t1;
    double t2 = cm_wtime();
    if (s >= 0)
        s = cm_surface_max_distance(ctx, mp->target_loc, mp->bxyz, nd->n, &row->max_dist, NULL);
    row->t_distance = cm_wtime() - t2;
    if (s < 0) return s;
    row->step = k;
    row->min_sj = all.min;
    row->mean_sj = all.mean;
    row->inverted = all.inverted;
    row->cells = all.count;
    row->outside = mp->surface.outside;
    return CM_OK;
}

cm_status cm_morpher_apply_method(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target,
                                  const cm_morph_method *method, double *out_xyz,
                                  cm_morph_step *rows)
{
    if (!mp || !target || !method || !out_xyz)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_apply: NULL input");
    if ((int)method->warp.method < 0 || method->warp.method >= CM_WARP_N_METHODS)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_apply: unknown warp method %d",
                        (int)method->warp.method);
    int n = mp->opt.steps;
    cm_morph_step scratch;
    if (rows)
        memset(rows, 0, (size_t)n * sizeof *rows);
    cm_status s = use_target(ctx, mp, target, rows);
    if (s < 0) return s;
    cm_surface_morph_options mo = mp->opt.morph;
    mo.method = method->surface;
    double t0 = cm_wtime();
    memset(&mp->surface, 0, sizeof mp->surface);
    s = cm_surface_morph(ctx, mp->g, target, mp->nodes, &mo, mp->bnew, &mp->surface);
    if (s < 0) return s;
    cm_status warned = s;
    if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
    char warning[1024];
    snprintf(warning, sizeof warning, "%s", s == CM_WARNING ? cm_context_message(ctx) : "");
    if (rows) rows[0].t_surface = cm_wtime() - t0;
    memcpy(out_xyz, mp->mesh->xyz, 3 * mp->mesh->n_nodes * sizeof *out_xyz);
    for (int k = 1; k <= n; ++k) {
        cm_progress(ctx, "morph", k - 1, n);
        cm_morph_step *row = rows ? &rows[k - 1] : memset(&scratch, 0, sizeof scratch);
        s = increment(ctx, mp, &method->warp, k, n, out_xyz, row);
        if (s < 0) return cm_error_prefix(ctx, s, "step %d of %d", k, n);
    }
    cm_progress(ctx, "morph", n, n);
    return warned == CM_WARNING ? cm_error(ctx, CM_WARNING, "%s", warning) : CM_OK;
}

cm_status cm_morpher_apply(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target,
                           double *out_xyz, cm_morph_step *rows)
{
    if (!mp) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_apply: NULL input");
    return cm_morpher_apply_method(ctx, mp, target, &mp->opt.method, out_xyz, rows);
}

cm_status cm_morpher_rebase(cm_context *ctx, cm_morpher *mp, const cm_cad_model *g,
                            const double *xyz)
{
    if (!mp || !g || !xyz) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_rebase: NULL input");
    if (g != mp->g) {
        cm_status s = cm_cad_compare(ctx, mp->g, g, 5);
        if (s < 0) return cm_error_prefix(ctx, s, "the new base does not correspond to G");
        cm_cad_locator_destroy(&mp->loc);
        if (g == mp->target) { /* the usual case: rebase onto the last target */
            mp->loc = mp->target_loc;
            mp->target_loc = NULL;
            mp->target = NULL;
        }
        mp->g = g;
    }
    memcpy(mp->mesh->xyz, xyz, 3 * mp->mesh->n_nodes * sizeof *xyz);
    drop_warps(mp);
    held_warnings held = {0};
    cm_status s = classify(ctx, mp, &held);
    if (s < 0) return s;
    return release(ctx, &held);
}

const cm_morpher_info *cm_morpher_get_info(const cm_morpher *mp) { return &mp->info; }

const cm_mesh *cm_morpher_mesh(const cm_morpher *mp) { return mp->mesh; }

const double *cm_morpher_quality(const cm_morpher *mp) { return mp->sj; }

const cm_surface_morph_stats *cm_morpher_surface_stats(const cm_morpher *mp)
{
    return &mp->surface;
}
