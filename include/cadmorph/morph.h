/* cadmorph morph engine: G, G' and a mesh M of G in, M' out (DESIGN.md's pipeline).
 * Conventions: see core.h.
 */
#ifndef CADMORPH_MORPH_H
#define CADMORPH_MORPH_H

#include "cadmorph/cad.h"
#include "cadmorph/mesh.h"
#include "cadmorph/rbf.h"
#include "cadmorph/surface.h"
#include "cadmorph/warp.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- the morph pipeline: read G, G' and M, check that G and G' correspond, sample and
 * classify, morph the surface (surface.h), warp the interior per component (cm_warp), in
 * `steps` increments. Library target cm_morph (volume/morph_pipeline.c), apart from cm_volume
 * so that the warp and the mesher do not pull in the surface module. ---- */

/* Samples on G beyond this are not worth their memory for the meshes cadmorph morphs; the
 * locator grows h instead and says so (a warning, never silent). Sweeps use it too. */
#define CM_MORPH_MAX_SAMPLES ((size_t)4000000)

typedef struct cm_morph_options {
    cm_surface_method surface; /* default CM_SURFACE_RBF */
    cm_rbf_kernel kernel;      /* volume warp: CM_RBF_TRIHARMONIC (default) or BIHARMONIC */
    int steps;                 /* >= 1 (default 1): equal increments of the boundary motion */
    const char *cad_unit;      /* target unit of both STEP files; NULL = "mm" */
    /* Samples of each model for the locators: h is a quarter of the shortest boundary edge,
     * raised (with a warning) if that needs more than max_samples; 0: 4,000,000. */
    size_t max_samples;
    cm_classify_options classify;
    cm_surface_morph_options morph;
} cm_morph_options;

void cm_morph_options_init(cm_morph_options *opt);

/* One row of the report per step. Stage times in seconds; read, sample, classify and surface
 * are spent once and counted in step 1; volume_solve = warp assembly and factorisation,
 * evaluation = solve for the step's displacements, evaluation at the interior nodes and the
 * scaled Jacobian; write is left for the caller (who writes the mesh). */
typedef struct cm_morph_step {
    int step;
    double min_sj, mean_sj;
    size_t inverted, cells;
    double max_dist; /* largest distance of the boundary nodes to G' after this step (by
                        projection through a locator on G'); before the last step the
                        boundary is a linear blend, so this is how far it still is */
    double t_read, t_sample, t_classify, t_surface, t_volume_solve, t_evaluation, t_write;
} cm_morph_step;

typedef struct cm_morph_result {
    cm_mesh *mesh; /* the morphed mesh, with per-node "displacement" (from M0) and
                      per-cell "scaled_jacobian" fields */
    double *sj;    /* #cells: the scaled_jacobian field's data (owned by mesh) */
    int n_steps;
    cm_morph_step *steps; /* n_steps rows */
    size_t counts[3];     /* boundary nodes on vertices, edges, faces */
    cm_surface_morph_stats surface;
    double max_dist; /* largest distance of the final boundary nodes to G' */
    double diagonal; /* bbox diagonal of G' (for relative tolerances) */
    double h;        /* sampling h actually used on G */
} cm_morph_result;

/* Runs the pipeline. Errors: CM_ERR_MISMATCH when G and G' do not correspond (up to 5
 * differences in the message) or M is not a mesh of G (see cm_surface_classify); file
 * errors from the readers. Returns CM_WARNING (the first warning's message) when a stage
 * warned (nodes left a trimmed domain, sample cap reached) but the result is complete.
 * Warnings also go to the context's log (CM_LOG_WARNING) as they happen; those of the
 * sampling of G only once the mesh is known to lie on G (a mesh in the wrong unit makes the
 * sampling warn, and the real error is the mismatch). */
cm_status cm_morph_run(cm_context *ctx, const char *g0_path, const char *g1_path,
                       const char *mesh_path, const cm_morph_options *opt,
                       cm_morph_result **result);
void cm_morph_result_destroy(cm_morph_result **result);

#ifdef __cplusplus
}
#endif
#endif
