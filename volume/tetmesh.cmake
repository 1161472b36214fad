# TetGen bridge (issue 6): tet mesh of a STEP solid. C++ with TETLIBRARY (via cm_tetgen);
# the surface comes from cad/ (cad_triangulate.h, a draft header beside its source).
target_sources(cm_volume PRIVATE ${CMAKE_CURRENT_LIST_DIR}/tetmesh.cpp)
target_link_libraries(cm_volume PRIVATE cm_tetgen cm_cad)
