# Tests of the TetGen bridge (meshgen/tetmesh.cpp, cad/triangulate.cpp) on the STEP fixtures of
# tests/data/models (written by gmsh: make_fixtures.py).
cm_add_unit_test(test_tetmesh test_tetmesh.c LIBS cm_meshgen cm_cad cm_mesh LABELS cad)
# TetGen in a child process: its crash on a self-intersecting surface (no -d), its time limit
cm_add_unit_test(test_tetgen_child test_tetgen_child.c LIBS cm_meshgen_internal OpenMP::OpenMP_C LABELS cad)
# TetGen's own crash must reach the parent as a signal, which is what the test checks; under
# `make check-asan` AddressSanitizer's SEGV handler would turn it into exit code 1
set_tests_properties(test_tetgen_child PROPERTIES ENVIRONMENT "ASAN_OPTIONS=handle_segv=0")
# the retries on a real TetGen failure: out of memory under an address-space limit, -Y fits
cm_add_unit_test(test_tetmesh_fallback test_tetmesh_fallback.c LIBS cm_meshgen cm_cad cm_mesh LABELS cad)
