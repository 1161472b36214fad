// Assemblies: a model whose solids touch (share a face or part of one) meshed as one conformal
// tet mesh with a group per solid (meshgen/tetmesh_assembly.cpp, docs/DESIGN.md,
// "Assemblies"). C++, private to meshgen/ (used by tetmesh.cpp).
#ifndef CADMORPH_MESHGEN_TETMESH_ASSEMBLY_H
#define CADMORPH_MESHGEN_TETMESH_ASSEMBLY_H

#include "cadmorph/cad.h"
#include "cadmorph/mesh.h"

#include <vector>

namespace cmvol {

// The mesh of a model whose solids touch (touching: the first touching pair, from
// cm_cad_check_solids_apart). gmsh (mesher CM_MESHER_GMSH) reads the file, fragments the
// solids (OpenCASCADE's BooleanFragments: a shared face becomes one surface, meshed once),
// meshes them together with maximum element size h; the tets of solid k get physical and
// entity tag k + 1 (group "solid_<k>"), each boundary triangle its CAD face f (tag f + 1,
// group "face_<f>"), oriented outward from its own solid. A triangle of an interface lies on
// one face of each of the two solids: it is written once per face, each copy outward from
// that face's solid (so that face_<f> is the whole face). TetGen takes no shared faces:
// CM_ERR_UNSUPPORTED naming the pair and --mesher gmsh. Other errors as cmvol::gmsh_mesh's.
cm_status assembly_mesh(cm_context *ctx, const cm_cad_model *model, int mesher, double h,
                        double time_limit, const int touching[2], cm_mesh **out);

// What the optimisation of a new mesh must not move: the nodes of its 2D cells (the surface
// triangles, interfaces between solids included) and its boundary. Empty when the mesh has
// one solid (its boundary is then the optimisation's default).
std::vector<unsigned char> assembly_fixed_nodes(const cm_mesh *mesh);

}  // namespace cmvol
#endif
