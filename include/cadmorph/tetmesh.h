/* cadmorph tet meshing: a tet mesh of a STEP solid, the OpenCASCADE surface triangulation
 * (cad.h) filled with tetrahedra by TetGen. Conventions: see core.h.
 */
#ifndef CADMORPH_TETMESH_H
#define CADMORPH_TETMESH_H

#include "cadmorph/cad.h"
#include "cadmorph/mesh.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cm_tetmesh_options {
    double size;       /* target edge length; <= 0: bbox diagonal / 20. The surface is
                          triangulated with chord deflection size / 10, the tets' volume is
                          bounded by that of a regular tet of edge `size`. */
    double quality;    /* bound on TetGen's radius-edge ratio (switch q); <= 0: 1.4 */
    double min_dihedral; /* lower bound on dihedral angles in degrees (switch q, after the
                            ratio); default 12, 0: TetGen's own. Higher values lift slivers
                            at the price of more tets (15: about +30 %) */
    /* 1: TetGen may not add nodes on the boundary (switch Y): the boundary nodes are
     * exactly OpenCASCADE's triangulation. 0 (default): TetGen refines the surface too,
     * and each node it adds there is projected onto its CAD face (or edge), so that every
     * boundary node lies on the CAD model either way. BRepMesh puts no interior nodes on
     * planes, and TetGen adds no interior node that would encroach on a boundary triangle:
     * with 1, a model with large planar faces gets a coarse mesh whatever the size. */
    int preserve_surface;
    /* 1 (default): the interior nodes are then optimised (optimize.h) to lift TetGen's
     * slivers; boundary nodes stay where they are. */
    int optimize;
    /* Refused (CM_ERR_NOMEM, with the estimate) when the tets expected from the model's volume
     * and `size` exceed this; <= 0: CM_TETMESH_MAX_TETS. INFINITY lifts the limit. */
    double max_tets;
} cm_tetmesh_options;

/* Default bound on the estimated tet count: ~3 GB in TetGen and the mesh, minutes of work. */
#define CM_TETMESH_MAX_TETS 1e7

CM_API void cm_tetmesh_options_init(cm_tetmesh_options *opt);

/* Tet mesh of the model's solids. The mesh holds the nodes, the tets (physical 1, entity 1,
 * group "solid") and the boundary triangles, outward, each with physical and entity tag
 * face + 1 of the CAD face it lies on (groups "face_<k>", k 0-based as in cad.h).
 * Errors: CM_ERR_UNSUPPORTED for a model without a solid, whose faces do not close
 * (message: number of open edges), whose solids touch or overlap (cm_cad_check_solids_apart)
 * or whose surface triangulation intersects itself (TetGen's -d check, run first because
 * TetGen's own error path crashes), CM_ERR_NOMEM beyond max_tets, CM_ERR_CAD for a surface triangulation failure,
 * CM_ERR_NUMERIC with TetGen's code and its meaning when TetGen gives up (self-intersecting
 * or too close facets, tiny features), CM_ERR_NOMEM. TetGen itself may print a line on
 * stdout before it fails (it does so unconditionally). Not thread-safe on one model. */
CM_API cm_status cm_tetmesh_create(cm_context *ctx, const cm_cad_model *model,
                            const cm_tetmesh_options *opt, cm_mesh **mesh);

#ifdef __cplusplus
}
#endif
#endif
