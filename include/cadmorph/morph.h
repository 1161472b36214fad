/* cadmorph morph engine: a mesh M of G follows G onto G' of the same topology (DESIGN.md's
 * pipeline). The engine works on objects in memory:
 *
 *   cm_morpher_create  - classifies M's boundary nodes on G (vertex | edge | face) once;
 *   cm_morpher_apply   - morphs onto any target G' of G's topology: the boundary by the
 *                        surface morph (surface.h), the interior by a warp (warp.h) whose
 *                        factorisation depends only on M, so it is made once per method and
 *                        shared by every target (absolute morphs, studies);
 *   cm_morpher_rebase  - a relative step: the morpher now starts from a morphed mesh on its
 *                        geometry (classified again, warps refactorised on first use).
 *
 * cm_morph_run is the file-level wrapper behind `cadmorph morph`.
 * Conventions: see core.h. Lifetimes: every cm_cad_model handed to the morpher (G at create
 * or rebase, targets at apply) is borrowed and must outlive the morpher or the next rebase;
 * meshes and coordinate arrays are copied. A morpher is used by one thread at a time.
 */
#ifndef CADMORPH_MORPH_H
#define CADMORPH_MORPH_H

#include "cadmorph/cad.h"
#include "cadmorph/mesh.h"
#include "cadmorph/optimize.h"
#include "cadmorph/surface.h"
#include "cadmorph/warp.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Samples on G beyond this are not worth their memory for the meshes cadmorph morphs; the
 * locator grows h instead. */
#define CM_MORPH_MAX_SAMPLES ((size_t)4000000)

/* A morph method: how the boundary reaches G' and how the interior follows. */
typedef struct cm_morph_method {
    cm_surface_method surface; /* default CM_SURFACE_RBF (RBF-S) */
    cm_warp_options warp;      /* default CM_WARP_RBF (triharmonic) */
} cm_morph_method;

CM_API void cm_morph_method_init(cm_morph_method *m);

/* Boundary nodes that are not on G (cm_morph_options.off_cad). */
typedef enum cm_off_cad {
    CM_OFF_CAD_REFUSE = 0, /* default: a mesh with such nodes is not a mesh of G (MISMATCH) */
    /* such nodes stay where they are (e.g. the wind tunnel around a body in a CFD mesh), when
     * they form whole boundary components of their own (connected through boundary faces);
     * a component partly on G and partly off it, or no node on G at all, is still refused */
    CM_OFF_CAD_FIXED = 1
} cm_off_cad;

/* steps = CM_MORPH_STEPS_AUTO: adaptive steps (see cm_morph_options). */
#define CM_MORPH_STEPS_AUTO 0

typedef struct cm_morph_options {
    cm_morph_method method;
    /* A result is valid when no volume cell is inverted (cm_mesh_invalid_cells: docs/DESIGN.md,
     * "What counts as an inverted cell") and, for min_sj > 0, every cell's scaled Jacobian is
     * above min_sj. Unless allow_inverted, a morph returns only valid meshes (CM_ERR_REJECTED
     * otherwise, naming the worst cells).
     * CM_MORPH_STEPS_AUTO (the default): adaptive steps, the largest that keep the mesh valid
     * (and, while steps can still shrink, its minimum scaled Jacobian above keep_fraction x
     * M's): first the whole motion at once with the shared factorisation, so that a morph
     * whose one step is valid costs what steps = 1 costs and gives the same mesh bit for bit;
     * on failure half the step, refit on the last accepted mesh; after two easy steps in a row
     * the step doubles. When no step down to min_fraction of the motion is valid: escalate
     * (below), else CM_ERR_REJECTED (out_xyz: the last accepted mesh, valid).
     * >= 1: equal increments of the boundary motion (1: the plain one-step morph of the
     * papers); increment 1 uses the shared factorisation, later ones refit the warp on the
     * intermediate mesh. Unless allow_inverted, the first increment that is not valid ends the
     * morph with CM_ERR_REJECTED (out_xyz: the increment before it, M itself for the first). */
    int steps;
    double min_sj;        /* floor of a valid mesh (default 0: no inverted cell; <= 0 means
                             that, which also accepts an OpenFOAM mesh's valid cells whose
                             scaled Jacobian is <= 0) */
    double keep_fraction; /* auto: 0 (default) = floor only */
    double min_fraction;  /* auto: smallest step (default 1/256) */
    /* 1: the result is returned whatever its cells (the morph never fails for inverted cells;
     * rows and cm_morpher_quality say how many): fixed steps run to the end, and adaptive
     * steps that find no valid step (after the escalation) morph the rest of the motion in one
     * step from the last accepted mesh, with a warning. 0 (default): see steps. */
    int allow_inverted;
    int optimize;         /* 1: optimise the interior (optimize.h) after every increment,
                             before it is judged; boundary nodes never move */
    /* auto without optimize: 1 (default) = when no step down to min_fraction is valid, the
     * rest of the motion is retried with interior optimisation (a warning says from where;
     * the rows' optimized_moves show it); 0 = CM_ERR_REJECTED there */
    int escalate;
    cm_optimize_options optimize_options;
    const char *cad_unit; /* target unit of STEP files read by cm_morph_run; NULL = "mm" */
    /* Samples of G for its locator: h is a quarter of the shortest boundary edge, raised if
     * that needs more than max_samples (with a warning when max_samples was set); 0:
     * cm_cad_sample_cap(boundary nodes, CM_MORPH_MAX_SAMPLES), 64 per boundary node. */
    size_t max_samples;
    /* Kept for compatibility, no longer used: targets are not sampled (max_dist projects each
     * node onto its own entity of G'), a rebase samples its new G at the classification h. */
    double target_h_scale;
    cm_classify_options classify; /* its keep_off is set from off_cad */
    cm_surface_morph_options morph; /* its method field is replaced by method.surface */
    cm_off_cad off_cad;             /* default CM_OFF_CAD_REFUSE */
    /* 1: each boundary node keeps its offset from G (its position minus its point on G, as
     * classified): it moves by how its point on G moves, so a mesh snapped near G (e.g. by
     * snappyHexMesh onto an STL of G, classified with a loose classify.rel_tol) keeps its
     * cells, and G' = G changes nothing. 0 (default): the boundary lands on G'. */
    int keep_offset;
    /* CM_OFF_CAD_FIXED: how the boundary nodes off G move, from the kinds of their patches
     * (motion.h; docs/DESIGN.md, "Boundary motion by patch kind"): those on a sliding patch (a
     * symmetry plane, empty or wedge planes, a patch named in motion.slide) slide on it, the
     * others stay; motion.all_fixed = 1 keeps every one of them where it is. The nodes on G are
     * prescribed (they beat a patch's kind). No 2-D or wedge reduction (no_reduction is
     * implied). The patch names are borrowed for the morpher's life (a rebase reads them
     * again). Default (cm_motion_options_init): the patch kinds. Where no node off G slides,
     * the morph is the one without slides, bit for bit. */
    cm_motion_options motion;
} cm_morph_options;

CM_API void cm_morph_options_init(cm_morph_options *opt);

/* One row per step. Stage times in seconds; read, sample and classify are spent by the caller
 * or by create and are filled in by cm_morph_run only; volume_solve = warp assembly and
 * factorisation (0 when a shared factorisation was reused), evaluation = the warp's apply,
 * the node update and the scaled Jacobian; write is left for the caller. */
typedef struct cm_morph_step {
    int step;
    double min_sj, mean_sj;
    size_t inverted, cells;
    double max_dist; /* largest distance of the boundary nodes to G' after this step: each
                        node projected onto its own vertex, edge or face of G' (the CAD
                        entity, not samples of it; an upper bound of the distance to G', exact
                        for a node on its entity); before the last step the boundary is a
                        linear blend, so this is how far it still is */
    size_t outside;  /* face nodes whose (u',v') left the trimmed face (cm_surface_morph_stats) */
    double residual; /* the warp's miss at the constrained nodes (cm_warp_residual) */
    double fraction; /* of the boundary motion this row reaches (1 for the last) */
    int accepted;    /* 0 for a rejected adaptive step (the next row retries a smaller one) */
    size_t optimized_moves; /* node moves kept by the optimisation of this step */
    char note[160];  /* why a step was rejected: worst cells with their scaled Jacobians */
    double t_read, t_sample, t_classify, t_surface, t_volume_solve, t_evaluation, t_distance,
        t_write;
} cm_morph_step;

typedef struct cm_morpher cm_morpher;

/* What create (or the last rebase) found. */
typedef struct cm_morpher_info {
    size_t nodes, cells, boundary_nodes, components;
    size_t counts[3];  /* boundary nodes on vertices, edges, faces */
    double h;          /* sampling h used on G */
    double class_dist; /* largest distance of a boundary node to its entity of G */
    double diagonal;   /* bbox diagonal of G */
    double t_sample, t_classify;
    size_t off_cad_nodes;      /* boundary nodes off G (CM_OFF_CAD_FIXED): fixed or sliding */
    size_t off_cad_components; /* the boundary components they form */
    size_t off_cad_slide;      /* of off_cad_nodes, those that slide (cm_morph_options.motion) */
} cm_morpher_info;

/* g: the geometry M lies on; mesh: M (copied). Errors: CM_ERR_UNSUPPORTED for a mesh without
 * volume cells, CM_ERR_MISMATCH when M is not a mesh of G (cm_surface_classify's message,
 * prefixed; with CM_OFF_CAD_FIXED: no node on G, or a boundary component partly on it), CM_ERR_FORMAT when every boundary edge has zero length. Returns CM_WARNING
 * (after logging it) when the sampling hit its cap. opt may be NULL. */
CM_API cm_status cm_morpher_create(cm_context *ctx, const cm_cad_model *g, const cm_mesh *mesh,
                            const cm_morph_options *opt, cm_morpher **morpher);
CM_API void cm_morpher_destroy(cm_morpher **morpher);

/* Morphs onto target with the options' method: out_xyz (#nodes x 3) receives the new
 * coordinates (boundary nodes exactly where the surface morph sent them), out_row (may be
 * NULL) the last step's row with the times of all steps added up; every row (with rejected
 * adaptive steps) is in cm_morpher_steps. Errors: CM_ERR_MISMATCH when target does not
 * correspond to G (up to 5 differences in the message); the warp's errors; CM_ERR_REJECTED
 * when no valid mesh was reached (cm_morph_options.steps: out_xyz then holds the last
 * accepted mesh, valid unless M itself is not, out_row its row; the rejected row, accepted
 * = 0, has the worst cells in its note). Returns CM_WARNING when face nodes left their
 * trimmed face, or when allow_inverted finished an adaptive morph with inverted cells (the
 * result is complete). */
CM_API cm_status cm_morpher_apply(cm_context *ctx, cm_morpher *morpher, const cm_cad_model *target,
                           double *out_xyz, cm_morph_step *out_row);

/* The same with another method; factorisations are kept per set of warp options (up to 16,
 * the oldest dropped beyond), so a study that compares methods factorises each once. */
CM_API cm_status cm_morpher_apply_method(cm_context *ctx, cm_morpher *morpher,
                                  const cm_cad_model *target, const cm_morph_method *method,
                                  double *out_xyz, cm_morph_step *out_row);

/* ---- batches: several targets, one warp apply ----
 * An absolute study morphs many targets from one morpher: their whole-motion fields can share
 * one multi-column warp apply (cm_warp_apply_many: for the RBF warps one solve and one
 * evaluation of all columns). Per target: */
typedef struct cm_morph_batch_item {
    cm_status status;  /* what cm_morpher_apply_method returns for this target alone */
    char message[512]; /* the message of that status ("" for CM_OK) */
    cm_morph_step row; /* its out_row (zeroed when the morph stopped before a step) */
    int batched;       /* 1: the result of the shared apply; 0: morphed alone */
} cm_morph_batch_item;

/* Morphs onto the k targets with method: out_xyz[j] (#nodes x 3 each) and items[j] receive
 * what cm_morpher_apply_method(targets[j]) gives (result, row, status and message), equal to
 * rounding (dense RBF) or to the iterative solver's tolerance. Batched: the targets' surface
 * morphs, then one apply of the shared warp for all whole-motion fields, then each result
 * judged as apply judges its first trial (steps auto: valid under the floor; steps 1: valid
 * or allow_inverted); a result that one step does not finish is morphed again alone (its
 * steps, its rejection). Alone throughout: k < 2, a warp other than rbf and rbf-biharmonic
 * (their apply_many shares the kernel passes; the others' applies one field at a time, so
 * there is nothing to share), slides of nodes off G (two-pass warp), nodes on G touching a
 * fixed surface off G (checked per step), steps > 1. Times: a batched row has its own surface
 * morph, optimisation, quality and distance times; the shared apply's time (for an iterative
 * RBF its Krylov solve) is divided equally over the batched rows' t_evaluation, and a
 * factorisation made by the call is in the first row that used it, as the first apply's
 * would be. Warnings of batched targets are logged as apply logs them. cm_morpher_steps,
 * cm_morpher_quality and cm_morpher_surface_stats afterwards: those of the last target morphed
 * (its step rows when morphed alone). The morpher keeps no target: the caller may free them
 * after the call. Returns CM_ERR_NOMEM or CM_ERR_INTERRUPTED when one stopped the batch
 * (items from there on unset), CM_ERR_ARGUMENT for NULL inputs, else CM_OK (each target's
 * status in its item). */
CM_API cm_status cm_morpher_apply_batch(cm_context *ctx, cm_morpher *morpher, size_t k,
                                        const cm_cad_model *const *targets,
                                        const cm_morph_method *method, double *const *out_xyz,
                                        cm_morph_batch_item *items);

/* The rows of the last apply, in order (accepted and rejected steps); *n their count. Valid
 * until the next apply. */
CM_API const cm_morph_step *cm_morpher_steps(const cm_morpher *morpher, size_t *n);

/* Relative morphing: the morpher's mesh becomes xyz (#nodes x 3, e.g. the last apply's
 * result), lying on g (e.g. that apply's target); the boundary is classified on g again and
 * the warps are refactorised when next used. After a failed rebase (CM_ERR_INTERRUPTED too)
 * apply refuses (CM_ERR_ARGUMENT) until a rebase succeeds. */
CM_API cm_status cm_morpher_rebase(cm_context *ctx, cm_morpher *morpher, const cm_cad_model *g,
                            const double *xyz);

CM_API const cm_morpher_info *cm_morpher_get_info(const cm_morpher *morpher);
/* The mesh the morpher starts from (its coordinates change only by rebase). */
CM_API const cm_mesh *cm_morpher_mesh(const cm_morpher *morpher);
/* Per-cell scaled Jacobian (#cells) of the last apply's result; valid until the next call. */
CM_API const double *cm_morpher_quality(const cm_morpher *morpher);
/* Surface-morph statistics of the last apply. */
CM_API const cm_surface_morph_stats *cm_morpher_surface_stats(const cm_morpher *morpher);

/* ---- derivatives: design velocities (docs/DESIGN.md, "Gradients") ----
 * The absolute morph of one increment (steps = 1, no optimisation) is
 * X(G') = X_M + J (B(G') - B_M): B(G') the boundary positions of the surface morph onto G',
 * J the warp, linear in the boundary motion (cm_warp_method_is_linear). The design velocity dX/dp of a CAD parameter p is then J applied to dB/dp, and
 * dB/dp a difference quotient of surface morphs onto geometries at perturbed p: no volume
 * morph is differenced, and the warp's products use the factorisation apply shares (made
 * once per set of warp options: velocities after a morph cost no factorisation). The
 * options' steps and optimize do not enter: the velocity is that of the one-increment morph.
 * The surface and warp methods are the options' (opt.method). */

/* The boundary positions of the surface morph onto target, as apply places them (same
 * classification, keep_offset, contact check of boundaries partly off G), without a volume
 * morph: out_xyz (#nodes x 3) = the morpher's mesh with every boundary node on G moved there;
 * interior nodes and boundary nodes off G keep their coordinates. Errors: CM_ERR_MISMATCH
 * when target does not correspond to G. Returns CM_WARNING when face nodes left their trimmed
 * face (cm_morpher_surface_stats). */
CM_API cm_status cm_morpher_boundary(cm_context *ctx, cm_morpher *morpher,
                                     const cm_cad_model *target, double *out_xyz);

/* The design velocity of every node: out (#nodes x 3) = dX/dp, the boundary part by the
 * difference quotient (plus - minus) / (dp_plus - dp_minus) of two cm_morpher_boundary
 * results (read at boundary nodes on G: 0 at those off G), the rest by the warp's forward
 * product of it (cm_morpher_warp_forward) when interior is non-zero, else 0.
 * dp_plus, dp_minus: the parameter values of plus and minus minus the base value (central
 * differences: dp_plus > 0 > dp_minus; second order when dp_minus = -dp_plus).
 * minus NULL: the morpher's mesh itself (the base geometry G, dp_minus = 0 then): one-sided
 * differences, forward for dp_plus > 0, backward for dp_plus < 0. Unit: mesh unit per
 * parameter unit. Errors: CM_ERR_ARGUMENT when dp_plus = dp_minus; CM_ERR_UNSUPPORTED
 * (interior) for a warp method that is not linear (cm_warp_method_is_linear). */
CM_API cm_status cm_morpher_velocity(cm_context *ctx, cm_morpher *morpher, const double *plus,
                                     double dp_plus, const double *minus, double dp_minus,
                                     int interior, double *out);

/* The warp's forward product with the shared factorisation of the options' warp method:
 * disp (#nodes x 3) read at the boundary nodes (cm_morpher_boundary_flags), written at every
 * other node of a volume cell: J disp (cm_warp_apply). CM_ERR_UNSUPPORTED for a method that
 * is not linear in the boundary motion. */
CM_API cm_status cm_morpher_warp_forward(cm_context *ctx, cm_morpher *morpher, double *disp);

/* The same for k fields at once: disp holds k blocks of #nodes x 3, each as disp above
 * (cm_warp_apply_many: the RBF warps solve and evaluate all 3k columns together, equal to k
 * calls of cm_morpher_warp_forward to rounding or the iterative solver's tolerance). */
CM_API cm_status cm_morpher_warp_forward_many(cm_context *ctx, cm_morpher *morpher, size_t k,
                                              double *disp);

/* The reverse product with the same factorisation: out (#nodes x 3) = J^T v (v #nodes x 3,
 * e.g. dJ/dX of an objective at every node), non-zero at boundary nodes only
 * (cm_warp_apply_transpose). Then dJ/dp = <out, dX_b/dp> for every parameter: one reverse
 * product serves them all. CM_ERR_UNSUPPORTED for a method that is not linear. */
CM_API cm_status cm_morpher_warp_transpose(cm_context *ctx, cm_morpher *morpher, const double *v,
                                           double *out);

/* #nodes flags, 1 at the boundary nodes (the warp's constrained nodes: on G and off it). Valid
 * while the morpher lives. */
CM_API const unsigned char *cm_morpher_boundary_flags(const cm_morpher *morpher);

/* ---- the file-level wrapper ---- */

typedef struct cm_morph_result {
    cm_mesh *mesh; /* the morphed mesh, with per-node "displacement" (from M0) and
                      per-cell "scaled_jacobian" fields */
    double *sj;    /* #cells: the scaled_jacobian field's data (owned by mesh) */
    int n_steps;
    cm_morph_step *steps; /* n_steps rows: each leg's rows (of a --via chain) in order */
    size_t counts[3];     /* boundary nodes on vertices, edges, faces */
    cm_surface_morph_stats surface;
    double max_dist; /* largest distance of the final boundary nodes to G' (as the steps') */
    double diagonal; /* bbox diagonal of G' (for relative tolerances) */
    double h;        /* sampling h actually used on G */
    size_t off_cad_nodes, off_cad_components; /* off G (CM_OFF_CAD_FIXED) */
    size_t off_cad_slide; /* of off_cad_nodes, those that slide (the rest kept fixed) */
} cm_morph_result;

/* Reads G (g0_path), G' (g1_path) and M, checks that they correspond, and morphs M onto G'.
 * via: n_via intermediate geometries (may be 0): a relative morph G -> via[0] -> ... -> G',
 * each step a rebase onto the previous result (opt.steps increments each). When no valid mesh
 * is reached (cm_morph_options.steps), the return is CM_ERR_REJECTED and, unlike every other
 * error, *result is set: the last valid mesh (M itself when even the first step failed) and
 * every row, rejected ones included (the caller decides whether to keep it). Errors:
 * CM_ERR_MISMATCH when two geometries do not correspond or M is not a mesh of G; file errors
 * from the readers. Returns CM_WARNING (the first warning's message) when a stage warned
 * (nodes left a trimmed domain, sample cap reached) but the result is complete. Warnings
 * also go to the context's log (CM_LOG_WARNING) as they happen; those of the sampling of G
 * only once the mesh is known to lie on G (a mesh in the wrong unit makes the sampling warn,
 * and the real error is the mismatch). */
CM_API cm_status cm_morph_run(cm_context *ctx, const char *g0_path, const char *g1_path,
                       const char *mesh_path, const char *const *via, size_t n_via,
                       const cm_morph_options *opt, cm_morph_result **result);
CM_API void cm_morph_result_destroy(cm_morph_result **result);

#ifdef __cplusplus
}
#endif
#endif
