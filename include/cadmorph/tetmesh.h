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
    /* Refused (CM_ERR_NOMEM, with the estimate) when the tets expected exceed this; <= 0:
     * CM_TETMESH_MAX_TETS. INFINITY lifts the limit. The estimate comes from OpenCASCADE's
     * surface triangulation at `size` for TetGen, from gmsh's own surface mesh for gmsh:
     * the enclosed volume over the volume bound plus a layer of tets per boundary
     * triangle. */
    double max_tets;
    /* Seconds of wall time the meshing may take (each mesher runs in a child process, killed
     * at its limit: CM_ERR_UNSUPPORTED "... did not finish in N s"); <= 0:
     * CM_TETMESH_TIME_LIMIT, INFINITY: none. With a fallback, the first mesher gets
     * CM_TETMESH_FIRST_SHARE of it and the second what is left. */
    double time_limit;
    /* CM_MESHER_TETGEN (the library's default, which keeps the study sweeps' meshes as
     * recorded) or CM_MESHER_GMSH (`cadmorph mesh`'s default: gmsh's library, opened at run
     * time, meshes the same STEP file with its OpenCASCADE kernel, `size` its largest element
     * size; quality, min_dihedral and preserve_surface are TetGen's and ignored). gmsh's
     * surfaces are mapped to the CAD faces by projection, so the boundary triangles carry
     * the same face tags either way. */
    int mesher;
    /* 1 (default): when `mesher` fails (refuses, crashes, runs out of its time, or its mesh
     * stays below min_sj after the optimisation), the other mesher is tried, and its success
     * logs one warning naming why the first one failed; the error, when both fail, names
     * both reasons. 0: `mesher` only. */
    int fallback;
    /* The quality judgement of the result (after the optimisation), as a morph's (morph.h):
     * the mesh is accepted when every tet's scaled Jacobian is above min_sj and, for
     * min_sj >= 0, none is flat (below CM_TETMESH_FLAT_SJ); else CM_ERR_REJECTED naming the
     * worst tet and its scaled Jacobian (after the fallback, if any). Default 0: no inverted
     * or flat tet. < -1 (e.g. -INFINITY): no judgement. */
    double min_sj;
} cm_tetmesh_options;

enum { CM_MESHER_TETGEN = 0, CM_MESHER_GMSH = 1 };

/* Default time limit of one mesher run, seconds: a 1e7-tet mesh takes TetGen a few minutes. */
#define CM_TETMESH_TIME_LIMIT 600.0

/* Share of the time limit the first mesher gets when the other may follow: the rest is
 * the fallback's. */
#define CM_TETMESH_FIRST_SHARE 0.5

/* Scaled Jacobian below which a tet counts as flat (a millionth as high as it is wide):
 * what TetGen's -Y leaves on surfaces it cannot refine, which no solver takes. */
#define CM_TETMESH_FLAT_SJ 1e-6

/* Default bound on the estimated tet count: ~3 GB in TetGen and the mesh, minutes of work. */
#define CM_TETMESH_MAX_TETS 1e7

CM_API void cm_tetmesh_options_init(cm_tetmesh_options *opt);

/* Tet mesh of the model's solids. The mesh holds the nodes, the tets (physical 1, entity 1,
 * group "solid") and the boundary triangles, outward, each with physical and entity tag
 * face + 1 of the CAD face it lies on (groups "face_<k>", k 0-based as in cad.h).
 * The mesher runs in a child process: its crash, abort (TetGen 1.5.0 on some valid
 * surfaces) or hang is a status, never a signal. gmsh's mesh is accepted when every boundary
 * node lies on its CAD face within the model's own tolerance (cm_cad_face_tolerances: 4 x
 * the face's, at least 1e-7 x diagonal); its boundary nodes are then projected onto the
 * faces and edges, as TetGen's added nodes are, so the mesh lies on this model. When TetGen fails, cadmorph tries again with
 * the surface kept (-Y), a looser quality bound (q 2, no dihedral bound) and a surface
 * perturbed by 1e-6 x size (its nodes put back after); success after a retry logs a warning
 * naming what worked, failure names everything tried. A timeout is not retried.
 * Errors: CM_ERR_UNSUPPORTED for a model without a solid, whose faces do not close
 * (message: number of open edges), whose solids overlap (cm_cad_check_solids_apart), whose
 * solids touch with TetGen (gmsh meshes them: one conformal mesh, the tets of solid k tagged
 * k + 1, group "solid_<k>", an interface triangle once per CAD face, docs/DESIGN.md
 * "Assemblies")
 * or whose surface triangulation intersects itself (TetGen's -d check, run first because
 * TetGen's own error path crashes), CM_ERR_NOMEM beyond max_tets, CM_ERR_CAD for a surface triangulation failure,
 * CM_ERR_NUMERIC with TetGen's code and its meaning, or its crash, when every retry failed,
 * CM_ERR_UNSUPPORTED at the time limit, CM_ERR_NOMEM, CM_ERR_REJECTED below min_sj; with
 * the fallback, the status of the first mesher's failure and a message naming both. What the mesher prints goes into the
 * message's tail, never to stdout. Not thread-safe on one model. */
CM_API cm_status cm_tetmesh_create(cm_context *ctx, const cm_cad_model *model,
                            const cm_tetmesh_options *opt, cm_mesh **mesh);

#ifdef __cplusplus
}
#endif
#endif
