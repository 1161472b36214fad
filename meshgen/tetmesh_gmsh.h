// gmsh as cadmorph's second mesher (meshgen/tetmesh_gmsh.cpp): the same STEP file read by gmsh's
// OpenCASCADE kernel and meshed in 3D in a child process, its surfaces mapped to our face
// indices. C++, private to meshgen/ (used by tetmesh.cpp).
#ifndef CADMORPH_MESHGEN_TETMESH_GMSH_H
#define CADMORPH_MESHGEN_TETMESH_GMSH_H

#include "cadmorph/cad.h"

#include <array>
#include <cstdint>
#include <vector>

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
cm_status gmsh_mesh(cm_context *ctx, const cm_cad_model *model, double h, double time_limit,
                    raw_mesh *out);

}  // namespace cmvol
#endif
