/* The morph engine (morph.h): M's boundary classified on G once; for each target G' the
 * surface morph [SMB12 §4] moves the boundary nodes onto G', and the interior follows
 * by a warp [SMB12 §3] whose factorisation depends only on M, kept per method. */
#include "cadmorph/morph.h"

#include "morpher_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cm_morph_method_init(cm_morph_method *m)
{
    m->surface = CM_SURFACE_RBF;
    cm_warp_options_init(&m->warp);
}

void cm_morph_options_init(cm_morph_options *opt)
{
    memset(opt, 0, sizeof *opt);
    cm_morph_method_init(&opt->method);
    opt->steps = CM_MORPH_STEPS_AUTO;
    opt->min_sj = 0;
    opt->allow_inverted = 0;
    opt->keep_fraction = 0;
    opt->min_fraction = 1.0 / 256;
    opt->optimize = 0;
    opt->escalate = 1;
    cm_optimize_options_init(&opt->optimize_options);
    cm_classify_options_init(&opt->classify);
    cm_surface_morph_options_init(&opt->morph);
    opt->off_cad = CM_OFF_CAD_REFUSE;
    cm_motion_options_init(&opt->motion);
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
                              double scale, cm_cad_locator **loc)
{
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    so.h = mp->info.h * (scale > 1 ? scale : 1);
    /* by default the samples scale with the boundary (cm_cad_sample_cap): a coarser h than the
     * shortest edge asks for is the rule on real parts, not news (the projections are Newton's
     * on the CAD faces); a cap the caller set is reported when it bites */
    so.max_samples = mp->opt.max_samples
                         ? mp->opt.max_samples
                         : cm_cad_sample_cap(mp->b->n_nodes, CM_MORPH_MAX_SAMPLES);
    cm_status s = cm_cad_locator_create(ctx, g, &so, loc);
    if (s == CM_WARNING && !mp->opt.max_samples) {
        cm_log(ctx, CM_LOG_DEBUG, "%s", cm_context_message(ctx));
        s = CM_OK;
    }
    return s;
}

/* keep_offset: the surface morph of g onto itself puts every node on its point of g (the same
 * parameters, evaluated): the offsets are the nodes minus those points. */
static cm_status node_offsets(cm_context *ctx, cm_morpher *mp)
{
    const cm_surface_nodes *nd = mp->nodes;
    free(mp->offset);
    mp->offset = malloc(3 * (nd->n ? nd->n : 1) * sizeof *mp->offset);
    if (!mp->offset) return cm_error(ctx, CM_ERR_NOMEM, "cm_morpher: out of memory for offsets");
    cm_surface_morph_options mo = mp->opt.morph;
    mo.method = mp->opt.method.surface;
    cm_surface_morph_stats st;
    memset(&st, 0, sizeof st);
    cm_status s = cm_surface_morph(ctx, mp->g, mp->g, nd, &mo, mp->offset, &st);
    if (s < 0) return cm_error_prefix(ctx, s, "the nodes' points on G (--keep-offset)");
    double worst = 0;
    for (size_t i = 0; i < 3 * nd->n; ++i) {
        mp->offset[i] = nd->xyz[i] - mp->offset[i];
        if (fabs(mp->offset[i]) > worst) worst = fabs(mp->offset[i]);
    }
    cm_log(ctx, CM_LOG_DEBUG, "keep-offset: largest offset component of a boundary node %.3g",
           worst);
    return CM_OK;
}

/* The boundary motion of the nodes off G (cm_morph_options.motion): the nodes on G
 * prescribed, the others by their patches' kinds. Kept only when some node off G slides. */
static cm_status make_motion(cm_context *ctx, cm_morpher *mp, held_warnings *held)
{
    cm_boundary_motion_destroy(&mp->motion);
    mp->info.off_cad_slide = 0;
    const cm_surface_nodes *nd = mp->nodes;
    if (!nd->n_off || mp->opt.motion.all_fixed) return CM_OK;
    size_t nn = mp->mesh->n_nodes;
    unsigned char *pre = calloc(nn ? nn : 1, 1);
    if (!pre) return cm_error(ctx, CM_ERR_NOMEM, "morph: out of memory for the boundary motion");
    for (size_t i = 0; i < nd->n; ++i)
        pre[nd->node[i]] = 1;
    cm_motion_options mo = mp->opt.motion;
    mo.no_reduction = 1;
    cm_status s = cm_boundary_motion_create(ctx, mp->mesh, mp->b, pre, &mo, &mp->motion);
    free(pre);
    if (s < 0) return cm_error_prefix(ctx, s, "the motion of the boundary off the CAD model");
    hold(ctx, held, s);
    for (size_t i = 0; i < nd->n_off; ++i)
        mp->info.off_cad_slide +=
            cm_boundary_motion_kind(mp->motion, (size_t)nd->off[i]) >= CM_MOTION_SLIDE_PLANE;
    if (!mp->info.off_cad_slide) cm_boundary_motion_destroy(&mp->motion);
    else
        cm_log(ctx, CM_LOG_DEBUG,
               "classify: %zu of the %zu boundary nodes off the CAD model slide on their "
               "patches, the rest stay",
               mp->info.off_cad_slide, nd->n_off);
    return CM_OK;
}

/* Samples g (once h is known) and classifies the boundary of mp->mesh on it. */
static cm_status classify(cm_context *ctx, cm_morpher *mp, held_warnings *held)
{
    double t0 = cm_wtime();
    cm_status s = CM_OK;
    cm_surface_morph_cache_clear(mp->scache); /* its fits are on the old nodes and g */
    if (!mp->loc) {
        s = make_locator(ctx, mp, mp->g, 1, &mp->loc);
        if (s < 0) return s;
        hold(ctx, held, s);
        mp->info.h = cm_cad_locator_h(mp->loc);
    }
    double t1 = cm_wtime();
    cm_surface_nodes_destroy(&mp->nodes);
    mp->opt.classify.keep_off = mp->opt.off_cad == CM_OFF_CAD_FIXED;
    s = cm_surface_classify(ctx, mp->g, mp->loc, mp->mesh, mp->b, &mp->opt.classify, &mp->nodes);
    if (s == CM_ERR_MISMATCH && mp->opt.off_cad == CM_OFF_CAD_REFUSE) {
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", cm_context_message(ctx));
        return cm_error(ctx, s,
                        "%s; if the rest of the boundary is not part of the model (a wind "
                        "tunnel around the body), --off-cad fixed keeps it in place",
                        msg);
    }
    if (s < 0) return s;
    cm_off_cad_contact_free(&mp->contact);
    size_t partial = 0;
    s = cm_morph_off_cad_check(ctx, mp->mesh, mp->b, mp->nodes, &mp->info.off_cad_components,
                               &partial, &mp->contact);
    if (s < 0) return s;
    if (partial)
        cm_log(ctx, CM_LOG_DEBUG,
               "classify: %zu boundary components partly on the CAD model: %zu nodes on it touch "
               "the fixed surface (they may slide along it where it is flat)",
               partial, mp->contact.n);
    mp->info.off_cad_nodes = mp->nodes->n_off;
    s = make_motion(ctx, mp, held);
    if (s < 0) return s;
    if (mp->nodes->n_off)
        cm_log(ctx, CM_LOG_DEBUG,
               "classify: %zu of %zu boundary nodes are off the CAD model, in %zu boundary "
               "components of their own (--off-cad fixed)",
               mp->nodes->n_off, mp->b->n_nodes, mp->info.off_cad_components);
    for (int k = 0; k < 3; ++k)
        mp->info.counts[k] = mp->nodes->count[k];
    mp->info.class_dist = mp->nodes->max_dist;
    if (mp->opt.keep_offset) {
        s = node_offsets(ctx, mp);
        if (s < 0) return s;
    }
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
    for (int i = 0; i < mp->n_warps; ++i) {
        cm_warp_destroy(&mp->warps[i].warp);
        cm_warp_destroy(&mp->warps[i].warp1);
    }
    mp->n_warps = 0;
}

void cm_morpher_destroy(cm_morpher **morpher)
{
    if (!morpher || !*morpher) return;
    cm_morpher *mp = *morpher;
    drop_warps(mp);
    cm_surface_morph_cache_destroy(&mp->scache);
    cm_cad_locator_destroy(&mp->loc);
    cm_surface_nodes_destroy(&mp->nodes);
    cm_mesh_boundary_destroy(&mp->b);
    cm_mesh_destroy(&mp->mesh);
    cm_mesh_destroy(&mp->work);
    free(mp->disp);
    free(mp->bnew);
    free(mp->bxyz);
    free(mp->next);
    free(mp->offset);
    free(mp->fixed);
    cm_off_cad_contact_free(&mp->contact);
    cm_boundary_motion_destroy(&mp->motion);
    free(mp->rows);
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
    cm_status s = mp->opt.steps >= 1 || mp->opt.steps == CM_MORPH_STEPS_AUTO
                      ? cm_mesh_copy(ctx, mesh, &mp->mesh)
                      : cm_error(ctx, CM_ERR_ARGUMENT,
                                 "cm_morpher_create: steps must be >= 1 or auto");
    if (s >= 0) s = cm_surface_morph_cache_create(ctx, &mp->scache);
    if (s >= 0) s = cm_mesh_boundary_create(ctx, mp->mesh, &mp->b);
    hold(ctx, &held, s);
    size_t n_interface = 0; /* an assembly's interfaces move onto G' as the boundary does */
    if (s >= 0) s = cm_morph_add_interfaces(ctx, mp->mesh, mp->b, &n_interface);
    if (n_interface)
        cm_log(ctx, CM_LOG_DEBUG, "classify: %zu interface triangles between solids join the "
               "boundary", n_interface);
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
        mp->next = malloc(3 * (nn ? nn : 1) * sizeof *mp->next);
        mp->fixed = calloc(nn ? nn : 1, 1);
        if (!mp->disp || !mp->bnew || !mp->bxyz || !mp->next || !mp->fixed)
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_morpher_create: out of memory for %zu nodes", nn);
    }
    if (s < 0) {
        cm_morpher_destroy(&mp);
        return s;
    }
    for (size_t i = 0; i < mp->b->n_nodes; ++i)
        mp->fixed[mp->b->nodes[i]] = 1;
    cm_quality_stats q0;
    if (cm_mesh_quality(ctx, mp->work, mp->sj) >= 0 &&
        cm_quality_summarize(ctx, mp->work, mp->sj, NULL, &q0) >= 0) {
        mp->min_sj0 = q0.min;
        mp->inverted0 = q0.inverted;
    }
    mp->info.nodes = nn;
    mp->info.cells = cm_mesh_count_dim(mp->mesh, 3);
    mp->info.boundary_nodes = mp->b->n_nodes; /* on G (nb) and off it */
    mp->info.components = mp->b->n_components;
    *morpher = mp;
    return release(ctx, &held);
}

/* Whether target is the last target (same address and the same bounding box: a model read
 * again at a freed one's address is another model). */
static int is_last_target(const cm_morpher *mp, const cm_cad_model *target)
{
    if (target != mp->target) return 0;
    double bb[6];
    cm_cad_bbox(target, bb);
    return !memcmp(bb, mp->target_bb, sizeof bb);
}

/* The target, checked once to correspond to G (kept while the same target comes back). The
 * distances to it are projections onto its entities (node_distance.c): no samples of it. */
cm_status cm_morpher_use_target(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target)
{
    if (is_last_target(mp, target)) return CM_OK;
    cm_status s = target == mp->g ? CM_OK : cm_cad_compare(ctx, mp->g, target, 5);
    if (s < 0) return cm_error_prefix(ctx, s, "the target does not correspond to G");
    mp->target = target;
    cm_cad_bbox(target, mp->target_bb);
    return CM_OK;
}

/* The warp with options wo on the start mesh, made on first use (options compared bytewise:
 * cm_warp_options_init zeroes them first); *t: its factorisation time. */
/* The two masks of the two-pass warp: pass 1 holds the fixed and prescribed nodes, pass 2
 * every node that is not free (docs/DESIGN.md, "Boundary motion by patch kind"). */
static cm_status slide_masks(cm_context *ctx, const cm_morpher *mp, unsigned char **m1,
                             unsigned char **m2)
{
    size_t nn = mp->mesh->n_nodes;
    *m1 = malloc(nn ? nn : 1), *m2 = malloc(nn ? nn : 1);
    if (!*m1 || !*m2) {
        free(*m1), free(*m2);
        *m1 = *m2 = NULL;
        return cm_error(ctx, CM_ERR_NOMEM, "morph: out of memory for the slide masks");
    }
    for (size_t i = 0; i < nn; ++i) {
        cm_motion_kind k = cm_boundary_motion_kind(mp->motion, i);
        (*m1)[i] = k == CM_MOTION_FIXED || k == CM_MOTION_PRESCRIBED;
        (*m2)[i] = k != CM_MOTION_FREE;
    }
    return CM_OK;
}

cm_status cm_morpher_make_warps(cm_context *ctx, const cm_morpher *mp, const cm_mesh *mesh,
                                const cm_warp_options *wo, cm_warp **w, cm_warp **w1)
{
    *w = *w1 = NULL;
    if (!mp->motion) return cm_warp_create(ctx, mesh, mp->b, NULL, wo, w);
    unsigned char *m1 = NULL, *m2 = NULL;
    cm_status s = slide_masks(ctx, mp, &m1, &m2);
    if (s >= 0) s = cm_warp_create(ctx, mesh, mp->b, m2, wo, w);
    if (s >= 0) s = cm_warp_create(ctx, mesh, mp->b, m1, wo, w1);
    free(m1), free(m2);
    if (s < 0) cm_warp_destroy(w), cm_warp_destroy(w1);
    return s;
}

cm_status cm_morpher_shared_warps(cm_context *ctx, cm_morpher *mp, const cm_warp_options *wo,
                                  cm_warp **warp, cm_warp **warp1, double *t)
{
    for (int i = 0; i < mp->n_warps; ++i)
        if (!memcmp(&mp->warps[i].opt, wo, sizeof *wo)) {
            *warp = mp->warps[i].warp;
            if (warp1) *warp1 = mp->warps[i].warp1;
            return CM_OK;
        }
    if (mp->n_warps == CM_MORPHER_MAX_WARPS) { /* keep the newest: drop the oldest */
        cm_warp_destroy(&mp->warps[0].warp);
        cm_warp_destroy(&mp->warps[0].warp1);
        memmove(mp->warps, mp->warps + 1, (CM_MORPHER_MAX_WARPS - 1) * sizeof mp->warps[0]);
        --mp->n_warps;
    }
    double t0 = cm_wtime();
    cm_warp *w = NULL, *w1 = NULL;
    cm_status s = cm_morpher_make_warps(ctx, mp, mp->mesh, wo, &w, &w1);
    if (s < 0) return s;
    *t = cm_wtime() - t0;
    mp->warps[mp->n_warps].opt = *wo;
    mp->warps[mp->n_warps].warp1 = w1;
    mp->warps[mp->n_warps++].warp = w;
    *warp = w;
    if (warp1) *warp1 = w1;
    return CM_OK;
}

cm_status cm_morpher_surface_positions(cm_context *ctx, cm_morpher *mp,
                                       const cm_cad_model *target, cm_surface_method surface,
                                       double *bnew)
{
    cm_surface_morph_options mo = mp->opt.morph;
    mo.method = surface;
    memset(&mp->surface, 0, sizeof mp->surface);
    cm_status s =
        cm_surface_morph_cached(ctx, mp->scache, mp->g, target, mp->nodes, &mo, bnew, &mp->surface);
    if (s < 0) return s;
    if (mp->opt.keep_offset)
        for (size_t i = 0; i < 3 * mp->nodes->n; ++i)
            bnew[i] += mp->offset[i];
    if (mp->contact.n) {
        cm_status c = cm_morph_off_cad_contact_check(ctx, mp->mesh, mp->nodes, &mp->contact, bnew);
        if (c < 0) return c;
    }
    return s;
}


cm_status cm_morpher_rebase(cm_context *ctx, cm_morpher *mp, const cm_cad_model *g,
                            const double *xyz)
{
    if (!mp || !g || !xyz) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morpher_rebase: NULL input");
    if (g != mp->g) {
        cm_status s = cm_cad_compare(ctx, mp->g, g, 5);
        if (s < 0) return cm_error_prefix(ctx, s, "the new base does not correspond to G");
        cm_cad_locator_destroy(&mp->loc); /* classify samples g */
        mp->g = g;
    }
    memcpy(mp->mesh->xyz, xyz, 3 * mp->mesh->n_nodes * sizeof *xyz);
    drop_warps(mp);
    held_warnings held = {0};
    cm_status s = classify(ctx, mp, &held);
    if (s < 0) {
        /* half re-based (stopped by the caller, or g not under the mesh): no apply until a
         * rebase succeeds */
        cm_surface_nodes_destroy(&mp->nodes);
        return s;
    }
    return release(ctx, &held);
}

const cm_morpher_info *cm_morpher_get_info(const cm_morpher *mp) { return &mp->info; }

const cm_mesh *cm_morpher_mesh(const cm_morpher *mp) { return mp->mesh; }

const double *cm_morpher_quality(const cm_morpher *mp) { return mp->sj; }

const cm_surface_morph_stats *cm_morpher_surface_stats(const cm_morpher *mp)
{
    return &mp->surface;
}
