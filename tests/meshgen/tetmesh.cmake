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
# Assemblies (docs/DESIGN.md, "Assemblies"): solids that touch meshed as one conformal mesh with
# a group per solid (two boxes sharing a face, a cylinder on part of a box's face, three
# stacked boxes), the interfaces moved onto an edited assembly by the morph; overlapping and
# nested solids refused with the way out; TetGen refuses touching solids naming gmsh
foreach(_case two_boxes box_cylinder stack overlap nested tetgen_touching morph_edit)
  add_test(NAME meshgen_assembly_${_case} COMMAND ${CM_PYTHON}
    ${CMAKE_CURRENT_SOURCE_DIR}/test_assembly.py $<TARGET_FILE:cadmorph>
    ${CM_TEST_WORK}/assembly_${_case} ${_case})
  set_tests_properties(meshgen_assembly_${_case} PROPERTIES LABELS "unit;cli;cad" TIMEOUT 120)
endforeach()
