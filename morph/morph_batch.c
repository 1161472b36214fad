/* Several targets with one warp apply (cm_morpher_apply_batch, morph.h): each target's surface
 * morph, then one cm_warp_apply_many for all whole-motion fields (the RBF warps solve and
 * evaluate their columns together: docs/DESIGN.md, "Studies in batches"), then each result
 * judged as cm_morpher_apply judges its first trial. What the batch cannot serve, or a result
 * that one step does not finish, goes through cm_morpher_apply_method, so every target's
 * result and row are those of one apply (to the solver's tolerance). */
#include "morpher_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Errors that end the batch rather than one target's morph. */
static int stops(cm_status s) { return s == CM_ERR_NOMEM || s == CM_ERR_INTERRUPTED; }

static void set_item(cm_context *ctx, cm_morph_batch_item *it, cm_status s, int batched)
{
    it->status = s;
    it->batched = batched;
    if (s == CM_OK)
        it->message[0] = 0;
    else
        snprintf(it->message, sizeof it->message, "%s", cm_context_message(ctx));
}

/* One target the way cm_morpher_apply_method morphs it alone. */
static cm_status one(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target,
                     const cm_morph_method *method, double *xyz, cm_morph_batch_item *it)
{
    memset(&it->row, 0, sizeof it->row);
    cm_status s = cm_morpher_apply_method(ctx, mp, target, method, xyz, &it->row);
    set_item(ctx, it, s, 0);
    return stops(s) ? s : CM_OK;
}

/* Whether the shared multi-column apply can give what apply gives: an RBF warp (the methods
 * whose apply_many shares the kernel passes; the others apply block by block, nothing to
 * share), one pass (no slides), no contact check against a fixed surface, and a morph whose
 * first trial is the whole motion with the shared warp (steps auto or 1). */
static int can_batch(const cm_morpher *mp, const cm_morph_method *method)
{
    cm_warp_method wm = method->warp.method;
    return (wm == CM_WARP_RBF || wm == CM_WARP_RBF_BIHARMONIC) && cm_warp_method_is_linear(wm) &&
           !mp->motion && !mp->contact.n &&
           (mp->opt.steps == CM_MORPH_STEPS_AUTO || mp->opt.steps == 1);
}

cm_status cm_morpher_apply_batch(cm_context *ctx, cm_morpher *mp, size_t k,
                                 const cm_cad_model *const *targets,
                                 const cm_morph_method *method, double *const *out_xyz,
                                 cm_morph_batch_item *items)
{
    if (!mp || !method || (k && (!targets || !out_xyz || !items)))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_apply_batch: NULL input");
    for (size_t j = 0; j < k; ++j)
        if (!targets[j] || !out_xyz[j])
            return cm_error(ctx, CM_ERR_ARGUMENT,
                            "cm_morpher_apply_batch: target or output %zu is NULL", j);
    if ((int)method->warp.method < 0 || method->warp.method >= CM_WARP_N_METHODS)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_apply_batch: unknown warp method %d",
                        (int)method->warp.method);
    if (!mp->nodes)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_apply_batch: the last "
                        "cm_morpher_rebase failed; rebase again first");
    cm_status s = CM_OK;
    if (k < 2 || !can_batch(mp, method)) {
        for (size_t j = 0; j < k && s >= 0; ++j)
            s = one(ctx, mp, targets[j], method, out_xyz[j], &items[j]);
        mp->target = NULL;
        return s;
    }
    const size_t nn = mp->mesh->n_nodes, nb = mp->nodes->n;
    double *bnew = malloc(k * 3 * (nb ? nb : 1) * sizeof *bnew);
    double *disp = malloc(k * 3 * (nn ? nn : 1) * sizeof *disp);
    size_t *at = malloc(k * sizeof *at); /* target j's block in disp, or k: not in the batch */
    cm_surface_morph_stats *surf = malloc(k * sizeof *surf);
    if (!bnew || !disp || !at || !surf) {
        free(bnew), free(disp), free(at), free(surf);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_morpher_apply_batch: out of memory for %zu "
                        "targets of %zu nodes", k, nn);
    }
    /* each target's surface morph and its whole motion from M (block m of disp) */
    size_t m = 0;
    for (size_t j = 0; j < k && s >= 0; ++j) {
        at[j] = k;
        memset(&items[j], 0, sizeof items[j]);
        if ((s = cm_progress(ctx, "morph", (double)j, (double)k)) < 0) break;
        double t0 = cm_wtime();
        cm_status e = cm_morpher_use_target(ctx, mp, targets[j]);
        double *b = bnew + 3 * nb * j;
        if (e >= 0) e = cm_morpher_surface_positions(ctx, mp, targets[j], method->surface, b);
        if (e < 0) { /* apply stops there too: its status, no row */
            set_item(ctx, &items[j], e, 0);
            if (stops(e)) s = e;
            continue;
        }
        set_item(ctx, &items[j], e, 1); /* CM_WARNING: face nodes left their trimmed face */
        items[j].row.t_surface = cm_wtime() - t0;
        surf[j] = mp->surface;
        at[j] = m;
        cm_morph_boundary_move(mp, b, 1, mp->mesh->xyz, disp + 3 * nn * m++);
    }
    /* one apply for all (the factorisation, when made now, is the first batched row's, as
     * the first apply's) */
    cm_warp *w = NULL;
    double t_solve = 0, t_apply = 0, residual = 0;
    cm_status wa = CM_OK;
    if (s >= 0 && m) {
        wa = cm_morpher_shared_warp(ctx, mp, &method->warp, &w, &t_solve);
        double t1 = cm_wtime();
        if (wa >= 0) wa = cm_warp_apply_many(ctx, w, m, disp);
        t_apply = cm_wtime() - t1;
        if (stops(wa)) s = wa;
        if (wa >= 0) residual = cm_warp_residual(w);
        /* another error: each target alone meets it and has it in its row */
    }
    int first = 1;
    for (size_t j = 0; j < k && s >= 0; ++j) {
        cm_morph_batch_item *it = &items[j];
        if (at[j] == k && it->status < 0) continue; /* its surface morph failed */
        if (at[j] < k && wa >= 0) {
            cm_morph_step row = it->row;
            memcpy(mp->bxyz, bnew + 3 * nb * j, 3 * nb * sizeof *mp->bxyz);
            cm_status e = cm_morph_trial_finish(ctx, mp, targets[j], 1, mp->opt.optimize,
                                                mp->mesh->xyz, disp + 3 * nn * at[j],
                                                out_xyz[j], &row);
            if (stops(e)) {
                s = e;
                break;
            }
            row.step = 1;
            row.outside = surf[j].outside;
            row.residual = residual;
            /* the shared apply's time (an iterative RBF's Krylov solve in it) in equal parts */
            row.t_evaluation += t_apply / (double)m;
            row.t_volume_solve = first ? t_solve : 0;
            if (e >= 0 && cm_morph_whole_motion_final(mp, &row)) {
                first = 0;
                if (it->status == CM_WARNING)
                    cm_log(ctx, CM_LOG_WARNING, "%s", it->message);
                it->row = row;
                it->batched = 1;
                mp->n_rows = 0;
                cm_morph_step *r = cm_morph_new_row(ctx, mp);
                if (!r) {
                    s = CM_ERR_NOMEM;
                    break;
                }
                *r = row;
                mp->surface = surf[j];
                continue;
            }
        }
        s = one(ctx, mp, targets[j], method, out_xyz[j], it); /* the steps apply would take */
        if (first && it->row.step) { /* it used the factorisation made above */
            it->row.t_volume_solve += t_solve;
            first = 0;
        }
    }
    if (s >= 0) s = cm_progress(ctx, "morph", (double)k, (double)k);
    free(bnew), free(disp), free(at), free(surf);
    mp->target = NULL; /* the caller may free the targets now */
    return s;
}
