/* A morph onto a target (cm_morpher_apply) and its steps (cm_morph_options.steps): the mesh
 * at a fraction of the boundary motion (a trial), its judgement (no inverted cell, the
 * --min-sj floor), K equal increments or the adaptive steps with their escalation to
 * interior optimisation; one row per trial (cm_morpher_steps). morpher.c makes the morpher
 * and its warps; this file only calls it. docs/DESIGN.md, "The pipeline". */
#include "morpher_internal.h"

#include "cadmorph/optimize.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

cm_morph_step *cm_morph_new_row(cm_context *ctx, cm_morpher *mp)
{
    if (mp->n_rows == mp->cap_rows) {
        size_t cap = mp->cap_rows ? 2 * mp->cap_rows : 16;
        cm_morph_step *p = realloc(mp->rows, cap * sizeof *p);
        if (!p) {
            cm_error(ctx, CM_ERR_NOMEM, "cm_morpher_apply: out of memory for step rows");
            return NULL;
        }
        mp->rows = p;
        mp->cap_rows = cap;
    }
    cm_morph_step *r = &mp->rows[mp->n_rows++];
    memset(r, 0, sizeof *r);
    r->step = (int)mp->n_rows;
    return r;
}

/* Pass 1 of the two-pass warp (docs/DESIGN.md, "Boundary motion by patch kind"): mp->disp
 * (the move from `from`, set at the nodes on G, 0 elsewhere) warped with the slide nodes
 * free, then made admissible: the fixed nodes 0, the slide nodes projected onto their
 * constraints. The projection sees the motion from the start mesh (on which the motion was
 * made), so that a curved slide projects positions, not increments. */
static cm_status slide_pass(cm_context *ctx, cm_morpher *mp, cm_warp *w1, const double *from)
{
    size_t n3 = 3 * mp->mesh->n_nodes;
    const double *x0 = mp->mesh->xyz;
    cm_status s = cm_warp_apply(ctx, w1, mp->disp);
    if (s < 0) return s;
    for (size_t i = 0; i < n3; ++i) /* from is x0 in the shared first step: adds 0 */
        mp->disp[i] += from[i] - x0[i];
    s = cm_boundary_motion_project(ctx, mp->motion, mp->disp);
    if (s < 0) return s;
    for (size_t i = 0; i < n3; ++i)
        mp->disp[i] -= from[i] - x0[i];
    return CM_OK;
}

void cm_morph_boundary_move(cm_morpher *mp, const double *bnew, double f, const double *from,
                            double *disp)
{
    const cm_surface_nodes *nd = mp->nodes;
    memset(disp, 0, 3 * mp->mesh->n_nodes * sizeof *disp);
    for (size_t i = 0; i < nd->n; ++i)
        for (int c = 0; c < 3; ++c) {
            double want = nd->xyz[3 * i + c] + f * (bnew[3 * i + c] - nd->xyz[3 * i + c]);
            if (f == 1.0) want = bnew[3 * i + c];
            mp->bxyz[3 * i + c] = want;
            disp[3 * nd->node[i] + c] = want - from[3 * nd->node[i] + c];
        }
}

/* The mesh at fraction f of the boundary motion: the boundary blended linearly from M's
 * boundary to the surface morph's positions (exactly those at f = 1), the interior by the
 * warp of the move from `from` (the shared factorisation when from is the start mesh, else
 * one of its own on from), then optimised if `optimize`; measured into row. */
static cm_status trial(cm_context *ctx, cm_morpher *mp, const cm_warp_options *wo, double f,
                       int shared, int optimize, const double *from, double *xyz,
                       cm_morph_step *row)
{
    size_t nn = mp->mesh->n_nodes;
    cm_morph_boundary_move(mp, mp->bnew, f, from, mp->disp);
    cm_warp *w = NULL, *w1 = NULL, *own = NULL, *own1 = NULL;
    double t0 = cm_wtime();
    cm_status s;
    if (shared) {
        s = cm_morpher_shared_warps(ctx, mp, wo, &w, &w1, &row->t_volume_solve);
    } else {
        /* a warp of its own serves this one apply: the caller's count of solves
         * (cm_warp_options.solves) is the shared warp's */
        cm_warp_options once = *wo;
        once.solves = 0;
        memcpy(mp->work->xyz, from, 3 * nn * sizeof *from);
        s = cm_morpher_make_warps(ctx, mp, mp->work, &once, &own, &own1);
        w = own, w1 = own1;
        row->t_volume_solve = cm_wtime() - t0;
    }
    double t1 = cm_wtime(), residual1 = 0;
    if (s >= 0 && w1) {
        s = slide_pass(ctx, mp, w1, from);
        residual1 = cm_warp_residual(w1);
    }
    if (s >= 0) s = cm_warp_apply(ctx, w, mp->disp);
    double t_apply = cm_wtime() - t1;
    row->residual = fmax(cm_warp_residual(w), residual1);
    cm_warp_destroy(&own);
    cm_warp_destroy(&own1);
    if (s < 0) return s;
    row->outside = mp->surface.outside;
    s = cm_morph_trial_finish(ctx, mp, mp->target, f, optimize, from, mp->disp, xyz, row);
    row->t_evaluation += t_apply;
    return s;
}

cm_status cm_morph_trial_finish(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target,
                                double f, int optimize, const double *from, const double *disp,
                                double *xyz, cm_morph_step *row)
{
    const cm_surface_nodes *nd = mp->nodes;
    size_t nn = mp->mesh->n_nodes;
    double t1 = cm_wtime();
    for (size_t i = 0; i < 3 * nn; ++i)
        xyz[i] = from[i] + disp[i];
    /* boundary nodes exactly where they were sent (no round-off from the increments), those
     * off G exactly where they were (the warp's residual there is not zero) unless they slide
     * (their normal motion is exactly 0 already) */
    for (size_t i = 0; i < nd->n; ++i)
        memcpy(xyz + 3 * nd->node[i], mp->bxyz + 3 * i, 3 * sizeof(double));
    for (size_t i = 0; i < nd->n_off; ++i)
        if (!mp->motion || cm_boundary_motion_kind(mp->motion, (size_t)nd->off[i]) <
                               CM_MOTION_SLIDE_PLANE)
            memcpy(xyz + 3 * nd->off[i], mp->mesh->xyz + 3 * nd->off[i], 3 * sizeof(double));
    memcpy(mp->work->xyz, xyz, 3 * nn * sizeof *xyz);
    cm_status s;
    if (optimize) {
        cm_optimize_stats st;
        s = cm_mesh_optimize(ctx, mp->work, mp->fixed, &mp->opt.optimize_options, &st);
        if (s < 0) return s;
        memcpy(xyz, mp->work->xyz, 3 * nn * sizeof *xyz);
        row->optimized_moves = st.moves;
    }
    cm_quality_stats all;
    s = cm_mesh_quality(ctx, mp->work, mp->sj);
    if (s >= 0) s = cm_quality_summarize(ctx, mp->work, mp->sj, NULL, &all);
    row->t_evaluation = cm_wtime() - t1;
    /* t_evaluation holds the warp's apply (for an iterative RBF its Krylov solve too), added
     * by the caller */
    cm_log(ctx, CM_LOG_DEBUG, "morph: optimisation and quality %.3f s", row->t_evaluation);
    double t2 = cm_wtime();
    if (s >= 0)
        s = cm_morph_node_distances(ctx, target, nd, mp->bxyz, f == 1.0, &row->max_dist, NULL);
    row->t_distance = cm_wtime() - t2;
    if (s < 0) return s;
    row->min_sj = all.min;
    row->mean_sj = all.mean;
    row->inverted = all.inverted;
    row->cells = all.count;
    row->fraction = f;
    row->accepted = 1;
    return CM_OK;
}

/* The worst volume cells of the last trial (up to 3): "cell <id> at (x, y, z) SJ <v>". */
static void worst_cells(const cm_morpher *mp, char *out, size_t size)
{
    const cm_mesh *m = mp->work;
    size_t best[3] = {0};
    int n = 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        double q = mp->sj[c];
        if (isnan(q) && cm_cell_type_info((cm_cell_type)m->type[c])->dim != 3) continue;
        if (fabs(q) >= 1e29) q = -INFINITY; /* collapsed */
        int pos = n;
        while (pos > 0) {
            double qb = mp->sj[best[pos - 1]];
            if (fabs(qb) >= 1e29) qb = -INFINITY;
            if (!(q < qb)) break;
            --pos;
        }
        if (pos >= 3) continue;
        for (int k = (n < 3 ? n : 2); k > pos; --k)
            best[k] = best[k - 1];
        best[pos] = c;
        if (n < 3) ++n;
    }
    size_t len = 0;
    out[0] = 0;
    for (int k = 0; k < n && len < size; ++k) {
        size_t c = best[k];
        double x[3] = {0, 0, 0};
        int64_t b = m->offset[c], e = m->offset[c + 1];
        for (int64_t j = b; j < e; ++j)
            for (int d = 0; d < 3; ++d)
                x[d] += m->xyz[3 * m->conn[j] + d] / (double)(e - b);
        int on_boundary = 1;
        for (int64_t j = b; j < e; ++j)
            on_boundary &= mp->fixed[m->conn[j]] != 0;
        int w = snprintf(out + len, size - len, "%scell %zu at (%.4g, %.4g, %.4g) SJ %.3g%s",
                         k ? "; " : "", c, x[0], x[1], x[2], mp->sj[c],
                         on_boundary ? " (all its nodes on the boundary)" : "");
        if (w < 0) break;
        len += (size_t)w;
    }
}

/* Whether a trial's mesh is valid (cm_morph_options): no inverted cell (the one definition,
 * cm_mesh_invalid_cells, which an OpenFOAM mesh's valid cells of scaled Jacobian <= 0 pass)
 * and, above a positive floor, every cell's scaled Jacobian. */
static int valid(const cm_morph_step *row, double floor)
{
    return row->inverted == 0 && (floor <= 0 || row->min_sj > floor);
}

/* A rejected trial: its row says why (the worst cells). */
static void reject(cm_morpher *mp, cm_morph_step *row, double floor)
{
    row->accepted = 0;
    int w = row->inverted
                ? snprintf(row->note, sizeof row->note, "%zu inverted: ", row->inverted)
                : snprintf(row->note, sizeof row->note, "min SJ %.3g <= %.3g: ", row->min_sj,
                           floor);
    if (w > 0 && (size_t)w < sizeof row->note)
        worst_cells(mp, row->note + w, sizeof row->note - (size_t)w);
}

/* "; M itself has N inverted cells ..." when it has: no morph of it can be valid. */
static void start_note(const cm_morpher *mp, char *out, size_t size)
{
    out[0] = 0;
    if (mp->inverted0)
        snprintf(out, size, "; the mesh to morph has %zu inverted cells itself (allowing "
                 "inverted cells, --allow-inverted, morphs it as it is)", mp->inverted0);
}

/* K equal increments (opt.steps >= 1); unless allow_inverted, the first increment that is
 * not valid ends the morph (xyz: the increment before it). */
static cm_status fixed_steps(cm_context *ctx, cm_morpher *mp, const cm_warp_options *wo,
                             double *xyz)
{
    int n = mp->opt.steps;
    for (int k = 1; k <= n; ++k) {
        cm_status p = cm_progress(ctx, "morph", k - 1, n);
        if (p < 0) return p;
        cm_morph_step *row = cm_morph_new_row(ctx, mp);
        if (!row) return CM_ERR_NOMEM;
        cm_status s =
            trial(ctx, mp, wo, (double)k / n, k == 1, mp->opt.optimize, xyz, mp->next, row);
        if (s < 0) return cm_error_prefix(ctx, s, "step %d of %d", k, n);
        if (!mp->opt.allow_inverted && !valid(row, mp->opt.min_sj)) {
            reject(mp, row, mp->opt.min_sj);
            char many[1024], start[200];
            worst_cells(mp, many, sizeof many);
            start_note(mp, start, sizeof start);
            const char *what = n == 1 ? "the one-step morph" : "this increment";
            if (row->inverted)
                return cm_error(ctx, CM_ERR_REJECTED,
                                "step %d of %d: %s leaves %zu inverted cells (worst: %s); "
                                "adaptive steps (--steps auto) may avoid them, --allow-inverted "
                                "keeps them%s",
                                k, n, what, row->inverted, many, start);
            return cm_error(ctx, CM_ERR_REJECTED,
                            "step %d of %d: %s leaves cells at or below scaled Jacobian %.3g "
                            "(worst: %s); adaptive steps (--steps auto) may avoid them%s",
                            k, n, what, mp->opt.min_sj, many, start);
        }
        memcpy(xyz, mp->next, 3 * mp->mesh->n_nodes * sizeof *xyz);
    }
    return cm_progress(ctx, "morph", n, n);
}

/* The smallest adaptive step: min_fraction, or the default's 1/256 when unset. */
static double min_step_of(const cm_morph_options *o)
{
    return o->min_fraction > 0 ? o->min_fraction : 1.0 / 256;
}

/* The floor of a valid adaptive step of length step: min_sj, raised to keep_fraction x M's
 * while steps can still shrink. */
static double auto_floor(const cm_morpher *mp, double step, double min_step)
{
    const cm_morph_options *o = &mp->opt;
    double floor = o->min_sj;
    if (o->keep_fraction > 0 && step > min_step && o->keep_fraction * mp->min_sj0 > floor)
        floor = o->keep_fraction * mp->min_sj0;
    return floor;
}

int cm_morph_whole_motion_final(const cm_morpher *mp, const cm_morph_step *row)
{
    const cm_morph_options *o = &mp->opt;
    if (o->steps == 1) return o->allow_inverted || valid(row, o->min_sj);
    if (o->steps != CM_MORPH_STEPS_AUTO) return 0;
    return valid(row, auto_floor(mp, 1, min_step_of(o)));
}

/* Adaptive steps (CM_MORPH_STEPS_AUTO), see cm_morph_options. */
static cm_status auto_steps(cm_context *ctx, cm_morpher *mp, const cm_warp_options *wo,
                            double *xyz)
{
    const cm_morph_options *o = &mp->opt;
    double done = 0, step = 1, min_step = min_step_of(o);
    int easy = 0, optimize = o->optimize;
    while (done < 1) {
        double f = done + step;
        if (f > 1 - 1e-12) f = 1;
        cm_status p = cm_progress(ctx, "morph", done, 1);
        if (p < 0) return p;
        cm_morph_step *row = cm_morph_new_row(ctx, mp);
        if (!row) return CM_ERR_NOMEM;
        cm_status s = trial(ctx, mp, wo, f, done == 0, optimize, xyz, mp->next, row);
        if (s < 0) return cm_error_prefix(ctx, s, "step to %.4g %%", 100 * f);
        double floor = auto_floor(mp, step, min_step);
        if (valid(row, floor)) {
            memcpy(xyz, mp->next, 3 * mp->mesh->n_nodes * sizeof *xyz);
            done = f;
            if (++easy >= 2) { /* two easy steps in a row: try a longer one */
                step *= 2;
                easy = 0;
            }
            continue;
        }
        reject(mp, row, floor);
        easy = 0;
        step /= 2;
        if (step < min_step && !optimize && o->escalate) {
            /* a cell that inverts at every step length is not one smaller steps can save (an
             * interior cell squeezed by the whole motion): the optimiser may, from here on */
            cm_log(ctx, CM_LOG_WARNING,
                   "morph: from %.4g %% of the motion no step down to %.3g %% is valid without "
                   "interior optimisation (worst: %s); the rest is morphed with it",
                   100 * done, 100 * 2 * step, row->note);
            optimize = 1;
            step = 1;
            continue;
        }
        if (step < min_step && o->allow_inverted) {
            /* asked for: the rest of the motion in one step, whatever its cells */
            double from = done;
            row = cm_morph_new_row(ctx, mp);
            if (!row) return CM_ERR_NOMEM;
            s = trial(ctx, mp, wo, 1, done == 0, optimize, xyz, mp->next, row);
            if (s < 0) return cm_error_prefix(ctx, s, "step to 100 %%");
            memcpy(xyz, mp->next, 3 * mp->mesh->n_nodes * sizeof *xyz);
            snprintf(row->note, sizeof row->note, "inverted cells allowed");
            p = cm_progress(ctx, "morph", 1, 1);
            if (p < 0) return p;
            cm_log(ctx, CM_LOG_WARNING,
                   "morph: from %.4g %% of the motion no step is valid; inverted cells are "
                   "allowed, so the rest was morphed in one step (%zu inverted cells, min "
                   "scaled Jacobian %.3g)",
                   100 * from, row->inverted, row->min_sj);
            return cm_error(ctx, CM_WARNING,
                            "morph: from %.4g %% of the motion no step is valid; inverted cells "
                            "are allowed, so the rest was morphed in one step (%zu inverted "
                            "cells, min scaled Jacobian %.3g)",
                            100 * from, row->inverted, row->min_sj);
        }
        if (step < min_step) {
            char many[1024], start[200];
            worst_cells(mp, many, sizeof many);
            start_note(mp, start, sizeof start);
            char what[64];
            if (row->inverted)
                snprintf(what, sizeof what, "%zu inverted cells", row->inverted);
            else
                snprintf(what, sizeof what, "cells at or below scaled Jacobian %.3g", floor);
            return cm_error(ctx, CM_ERR_REJECTED,
                            "no valid step: from %.4g %% of the motion even a step of %.3g %% "
                            "leaves %s (worst: %s)%s%s",
                            100 * done, 100 * 2 * step, what, many,
                            optimize ? (o->optimize ? "" : ", also with interior optimisation")
                                     : "; interior optimisation (--optimize) may lift them",
                            start);
        }
    }
    return cm_progress(ctx, "morph", 1, 1);
}

cm_status cm_morpher_apply_method(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target,
                                  const cm_morph_method *method, double *out_xyz,
                                  cm_morph_step *out_row)
{
    if (!mp || !target || !method || !out_xyz)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_apply: NULL input");
    if ((int)method->warp.method < 0 || method->warp.method >= CM_WARP_N_METHODS)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_apply: unknown warp method %d",
                        (int)method->warp.method);
    if (!mp->nodes)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_morpher_apply: the last cm_morpher_rebase failed; rebase again first");
    mp->n_rows = 0;
    cm_status s = cm_morpher_use_target(ctx, mp, target);
    if (s < 0) return s;
    double t0 = cm_wtime();
    s = cm_morpher_surface_positions(ctx, mp, target, method->surface, mp->bnew);
    if (s < 0) return s;
    double t_surface = cm_wtime() - t0;
    char warning[1024] = "";
    if (s == CM_WARNING) {
        cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
        snprintf(warning, sizeof warning, "%s", cm_context_message(ctx));
    }
    memcpy(out_xyz, mp->mesh->xyz, 3 * mp->mesh->n_nodes * sizeof *out_xyz);
    s = mp->opt.steps == CM_MORPH_STEPS_AUTO ? auto_steps(ctx, mp, &method->warp, out_xyz)
                                             : fixed_steps(ctx, mp, &method->warp, out_xyz);
    /* allow_inverted finished an adaptive morph with inverted cells (logged already) */
    if (s == CM_WARNING && !warning[0])
        snprintf(warning, sizeof warning, "%s", cm_context_message(ctx));
    if (mp->n_rows) {
        mp->rows[0].t_surface += t_surface;
    }
    if (out_row && mp->n_rows) {
        /* the last accepted row, with every row's stage times */
        size_t last = mp->n_rows - 1;
        while (last > 0 && !mp->rows[last].accepted)
            --last;
        *out_row = mp->rows[last];
        out_row->t_sample = out_row->t_surface = out_row->t_volume_solve = 0;
        out_row->t_evaluation = out_row->t_distance = 0;
        for (size_t i = 0; i < mp->n_rows; ++i) {
            out_row->t_sample += mp->rows[i].t_sample;
            out_row->t_surface += mp->rows[i].t_surface;
            out_row->t_volume_solve += mp->rows[i].t_volume_solve;
            out_row->t_evaluation += mp->rows[i].t_evaluation;
            out_row->t_distance += mp->rows[i].t_distance;
        }
    }
    if (s < 0) return s;
    return warning[0] ? cm_error(ctx, CM_WARNING, "%s", warning) : CM_OK;
}

cm_status cm_morpher_apply(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target,
                           double *out_xyz, cm_morph_step *out_row)
{
    if (!mp) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_apply: NULL input");
    return cm_morpher_apply_method(ctx, mp, target, &mp->opt.method, out_xyz, out_row);
}

const cm_morph_step *cm_morpher_steps(const cm_morpher *mp, size_t *n)
{
    if (n) *n = mp ? mp->n_rows : 0;
    return mp ? mp->rows : NULL;
}
