# Surface triangulation for TetGen meshing (issue 6): BRepMesh lives in TKMesh, which the
# rest of cad/ does not need.
target_sources(cm_cad PRIVATE ${CMAKE_CURRENT_LIST_DIR}/triangulate.cpp)
find_library(CM_OCC_TKMesh NAMES TKMesh HINTS ${OpenCASCADE_LIBRARY_DIR} REQUIRED NO_CACHE)
target_link_libraries(cm_cad PRIVATE ${CM_OCC_TKMesh})
