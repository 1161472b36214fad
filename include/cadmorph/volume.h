/* cadmorph volume: the RBF space warp that carries boundary motion into the interior of a
 * volume mesh, one interpolant per connected component (paper section 3).
 * Conventions: see core.h.
 */
#ifndef CADMORPH_VOLUME_H
#define CADMORPH_VOLUME_H

#include "cadmorph/cad.h"
#include "cadmorph/mesh.h"
#include "cadmorph/rbf.h"
#include "cadmorph/surface.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cm_warp_options {
    cm_rbf_kernel kernel; /* CM_RBF_TRIHARMONIC (default) or CM_RBF_BIHARMONIC */
} cm_warp_options;

void cm_warp_options_init(cm_warp_options *opt);

/* A factorised warp: the centres are the constrained nodes of each component, so one warp
 * serves every displacement of the same constrained nodes (absolute sweeps). */
typedef struct cm_warp cm_warp;

/* constrained: #nodes flags, non-zero where the displacement is prescribed (the boundary
 * nodes, and any interior node a caller wants to pin). NULL = the boundary nodes of b.
 * Every component with unconstrained nodes must have constrained nodes that are not all
 * coplanar: otherwise the RBF's CM_ERR_NUMERIC, its message prefixed "component <k>".
 * A constrained node shared by components (touching at an edge or vertex) is a centre of
 * each; an unconstrained one follows the lowest-numbered component. Unconstrained nodes of
 * no volume cell are left alone (a CM_LOG_WARNING gives their count). A mesh without
 * volume cells is CM_ERR_UNSUPPORTED. mesh and b are borrowed: the warp keeps copies. */
cm_status cm_warp_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                         const unsigned char *constrained, const cm_warp_options *opt,
                         cm_warp **warp);
void cm_warp_destroy(cm_warp **warp);

/* disp: #nodes x 3. On input, read at constrained nodes only; on output, constrained nodes
 * keep their value and every other node of a volume cell gets the warp's displacement (other
 * entries are not written). Reuses the factorisation: one warp, many calls (not concurrently
 * on the same warp). */
cm_status cm_warp_apply(cm_context *ctx, cm_warp *warp, double *disp);

/* Reads a displacement table (the D.csv of `cadmorph warp`): header `node,dx,dy,dz`, then one
 * row per listed node; node is the 0-based index in the mesh file's node order. Blank lines
 * and a CRLF ending are accepted.
 * disp: #nodes x 3 output, zeroed first, then the listed rows. listed: #nodes output flags,
 * 1 for listed nodes (may be NULL). n_nodes: the mesh's node count.
 * Errors name path:line: CM_ERR_FORMAT for a wrong header, column count, non-numeric or
 * non-finite value, CM_ERR_MISMATCH for a node index out of range or listed twice. */
cm_status cm_warp_read_displacements(cm_context *ctx, const char *path, size_t n_nodes,
                                     double *disp, unsigned char *listed);

/* ---- tet mesh of a STEP solid: the OpenCASCADE surface triangulation (cad) filled with
 * tetrahedra by TetGen ---- */

typedef struct cm_tetmesh_options {
    double size;       /* target edge length; <= 0: bbox diagonal / 20. The surface is
                          triangulated with chord deflection size / 10, the tets' volume is
                          bounded by that of a regular tet of edge `size`. */
    double quality;    /* bound on TetGen's radius-edge ratio (switch q); <= 0: 1.4 */
    /* 1: TetGen may not add nodes on the boundary (switch Y): the boundary nodes are
     * exactly OpenCASCADE's triangulation. 0 (default): TetGen refines the surface too,
     * and each node it adds there is projected onto its CAD face (or edge), so that every
     * boundary node lies on the CAD model either way. BRepMesh puts no interior nodes on
     * planes, and TetGen adds no interior node that would encroach on a boundary triangle:
     * with 1, a model with large planar faces gets a coarse mesh whatever the size. */
    int preserve_surface;
} cm_tetmesh_options;

void cm_tetmesh_options_init(cm_tetmesh_options *opt);

/* Tet mesh of the model's solids. The mesh holds the nodes, the tets (physical 1, entity 1,
 * group "solid") and the boundary triangles, outward, each with physical and entity tag
 * face + 1 of the CAD face it lies on (groups "face_<k>", k 0-based as in cad.h).
 * Errors: CM_ERR_UNSUPPORTED for a model without a solid or whose faces do not close
 * (message: number of open edges), CM_ERR_CAD for a surface triangulation failure,
 * CM_ERR_NUMERIC with TetGen's code and its meaning when TetGen gives up (self-intersecting
 * or too close facets, tiny features), CM_ERR_NOMEM. TetGen itself may print a line on
 * stdout before it fails (it does so unconditionally). Not thread-safe on one model. */
cm_status cm_tetmesh_create(cm_context *ctx, const cm_cad_model *model,
                            const cm_tetmesh_options *opt, cm_mesh **mesh);

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
