/* The morph engine's state, shared by the files of the morph module (morpher.c: create,
 * apply, rebase; velocity.c: the boundary positions and warp products behind the design
 * velocities, docs/DESIGN.md "Gradients"; morph_steps.c: an apply and its steps). Private to
 * the morph module. */
#ifndef CM_MORPH_MORPHER_INTERNAL_H
#define CM_MORPH_MORPHER_INTERNAL_H

#include "cadmorph/morph.h"

#include "off_cad.h"

#define CM_MORPHER_MAX_WARPS 16

struct cm_morpher {
    cm_morph_options opt;
    const cm_cad_model *g; /* borrowed: the geometry the start mesh lies on */
    cm_mesh *mesh;         /* the start mesh (own copy) */
    cm_mesh_boundary *b;
    cm_cad_locator *loc; /* on g */
    cm_surface_nodes *nodes;
    /* the surface morph's per-face fits on g and nodes, factorised once for every target;
     * emptied whenever g or nodes change (classify) */
    cm_surface_morph_cache *scache;
    /* warps on mesh, made when first used, one per set of warp options (a study may compare
     * one method with several settings, e.g. lattice sizes) */
    struct {
        cm_warp_options opt;
        cm_warp *warp;  /* every boundary node held (the only warp when nothing slides) */
        cm_warp *warp1; /* with motion: pass 1, the slide nodes free; else NULL */
    } warps[CM_MORPHER_MAX_WARPS];
    int n_warps;
    const cm_cad_model *target; /* the last target (borrowed, checked to correspond to g) and its
                                   bounding box (so that another model read at the same
                                   address is not taken for it) */
    double target_bb[6];
    cm_mesh *work; /* a copy of mesh whose coordinates are the result being measured */
    double *sj;    /* work's scaled_jacobian field */
    double *disp;  /* #nodes x 3 */
    double *bnew;  /* #boundary x 3: the surface morph's positions on the target */
    double *bxyz;  /* #boundary x 3: the positions of the current increment */
    double *next;  /* #nodes x 3: the step being tried */
    double *offset; /* keep_offset: #boundary x 3, each node minus its point on g */
    unsigned char *fixed; /* #nodes: the boundary nodes, which optimisation never moves */
    cm_off_cad_contact contact; /* off_cad fixed: nodes on G touching the fixed surface */
    /* off_cad fixed with nodes off G that slide (motion.h): the nodes on G prescribed, those
     * off it fixed or sliding by their patches; NULL when none slides (the warp is then the
     * one-pass warp with every boundary node held, as without patch kinds) */
    cm_boundary_motion *motion;
    double min_sj0;       /* M's minimum scaled Jacobian (keep_fraction) */
    size_t inverted0;     /* M's inverted cells (named when no valid mesh is reached) */
    cm_morph_step *rows;  /* the last apply's steps */
    size_t n_rows, cap_rows;
    cm_surface_morph_stats surface;
    cm_morpher_info info;
};

/* The warp with options wo on the start mesh, made on first use and kept (up to
 * CM_MORPHER_MAX_WARPS, the oldest dropped beyond); *t: its factorisation time (untouched
 * when the warp was already made). With slides (mp->motion) the pair of the two-pass warp
 * is made at once: *warp holds every node that is not free (pass 2), *warp1 (may be NULL
 * when not wanted) only the fixed and prescribed ones (pass 1); without slides *warp1 is
 * NULL. */
cm_status cm_morpher_shared_warps(cm_context *ctx, cm_morpher *mp, const cm_warp_options *wo,
                                  cm_warp **warp, cm_warp **warp1, double *t);
#define cm_morpher_shared_warp(ctx, mp, wo, warp, t) cm_morpher_shared_warps(ctx, mp, wo, warp, NULL, t)

/* The surface morph onto target as apply makes it (its classification, keep_offset, the
 * contact check of boundaries partly off G): bnew (nodes->n x 3) the positions of the
 * boundary nodes on G; mp->surface its statistics. CM_WARNING when face nodes left their
 * trimmed face. target must correspond to G (checked by the caller). */
cm_status cm_morpher_surface_positions(cm_context *ctx, cm_morpher *mp,
                                       const cm_cad_model *target, cm_surface_method surface,
                                       double *bnew);

/* The warp (and with slides the pass-1 warp too) on mesh, created with the morpher's
 * boundary; *w1 NULL without slides (morpher.c). */
cm_status cm_morpher_make_warps(cm_context *ctx, const cm_morpher *mp, const cm_mesh *mesh,
                                const cm_warp_options *wo, cm_warp **w, cm_warp **w1);

/* The target, checked once to correspond to G (kept while the same target comes back;
 * morpher.c). */
cm_status cm_morpher_use_target(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target);

/* A new row of the last apply (zeroed); NULL when out of memory. Rows move when the array
 * grows: fill one before asking for the next (morph_steps.c). */
cm_morph_step *cm_morph_new_row(cm_context *ctx, cm_morpher *mp);

/* The move of the boundary nodes on G to fraction f of the way from M's boundary to bnew
 * (nodes->n x 3; exactly bnew at f = 1): their positions into mp->bxyz, disp (#nodes x 3) the
 * move from `from` there, 0 elsewhere (morph_steps.c). */
void cm_morph_boundary_move(cm_morpher *mp, const double *bnew, double f, const double *from,
                            double *disp);

/* The rest of a trial once the warp has filled disp (the move from `from`): xyz = from + disp
 * with the boundary nodes exactly at mp->bxyz (those off G where they were unless they
 * slide), optimised if `optimize`, its quality (mp->work, mp->sj) and distance to target
 * measured into row (t_evaluation: this part only; outside and residual are the caller's). */
cm_status cm_morph_trial_finish(cm_context *ctx, cm_morpher *mp, const cm_cad_model *target,
                                double f, int optimize, const double *from, const double *disp,
                                double *xyz, cm_morph_step *row);

/* Whether row, the whole-motion trial with the shared warp (the first trial of steps auto or
 * steps 1), is the whole morph as cm_morpher_apply judges it: valid (auto: under its floor;
 * 1: or allow_inverted). 0 for fixed steps > 1. */
int cm_morph_whole_motion_final(const cm_morpher *mp, const cm_morph_step *row);

/* Appends to b the faces of an assembly's interfaces (a triangle of the mesh between two
 * tets of different physical groups) and their nodes (interfaces.c); *n_added: how many. */
cm_status cm_morph_add_interfaces(cm_context *ctx, const cm_mesh *mesh, cm_mesh_boundary *b,
                                  size_t *n_added);

/* The largest distance of the boundary nodes at xyz (nd->n x 3, in nd's order) to G': each
 * node to the vertex, edge or face of g2 that its entity of G corresponds to, projected onto
 * the CAD entity itself (node_distance.c); *worst: its node (index into nd). thorough: the
 * final positions, where a face node that Newton from its (u,v) on G leaves off the face is
 * projected again from a grid start. */
cm_status cm_morph_node_distances(cm_context *ctx, const cm_cad_model *g2,
                                  const cm_surface_nodes *nd, const double *xyz, int thorough,
                                  double *max_dist, size_t *worst);

#endif
