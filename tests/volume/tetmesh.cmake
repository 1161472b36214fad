# Tests of the TetGen bridge (volume/tetmesh.cpp, cad/triangulate.cpp) on the STEP fixtures of
# tests/data/models (written by gmsh: make_fixtures.py).
cm_add_unit_test(test_tetmesh test_tetmesh.c LIBS cm_volume cm_cad cm_mesh LABELS cad)
