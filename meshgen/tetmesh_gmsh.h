// gmsh as cadmorph's second mesher (meshgen/tetmesh_gmsh.cpp): the same STEP file read by gmsh's
// OpenCASCADE kernel and meshed in 3D in a child process, its surfaces mapped to our face
// indices. C++, private to meshgen/ (used by tetmesh.cpp).
#ifndef CADMORPH_MESHGEN_TETMESH_GMSH_H
#define CADMORPH_MESHGEN_TETMESH_GMSH_H

#include "cadmorph/cad.h"

#include <array>
#include <cstdint>
#include <vector>

// The estimate's constants (tets per volume bound vmax, tets per layer level of
// surface_layers), fitted on the parts of benchmarks/RESULTS.md, Meshers: TetGen's fill of
// OpenCASCADE's triangulation, gmsh's fill of its own surface mesh
#define CM_EST_TETGEN_VOLUME 2.5
#define CM_EST_TETGEN_LAYER 12.0
#define CM_EST_GMSH_VOLUME 0.6
#define CM_EST_GMSH_LAYER 0.6

namespace cmvol {

// a tet mesh before orientation: nodes, tets, boundary triangles with their CAD face (0-based)
struct raw_mesh {
    std::vector<double> xyz;
    std::vector<std::array<int64_t, 4>> tets;
    std::vector<int64_t> tri;
    std::vector<int> tri_face;
};

// gmsh's mesh of the model's file with maximum element size h (and 12 elements per 2 pi of
// curvature, close to the TetGen path's chord deflection h / 10 on the fixtures' radii).
// Every boundary triangle gets the CAD face its gmsh surface is (checked: sampled nodes on
// that face within 4 x the model's tolerance there, cm_cad_face_tolerances, at least 1e-7 x
// diagonal); the nodes are gmsh's, not yet projected. Errors: CM_ERR_UNSUPPORTED without gmsh or at the time
// limit, CM_ERR_NUMERIC when gmsh fails or crashes, CM_ERR_MISMATCH when gmsh's geometry is
// not ours.
// Before the volume mesh, the tets expected from gmsh's surface mesh (as estimate_tets in
// tetmesh.cpp: CM_EST_GMSH_*, the model's volume given) are checked against max_tets:
// CM_ERR_NOMEM beyond it.
cm_status gmsh_mesh(cm_context *ctx, const cm_cad_model *model, double h, double time_limit,
                    double volume, double max_tets, raw_mesh *out);

// The graded layer of tets expected over a surface mesh with target size h: per triangle,
// 1 + log2(h / l) for its equilateral edge l < h, else 1.
double surface_layers(const double *xyz, const int64_t *tri, size_t n_tri, double h);

}  // namespace cmvol
#endif
