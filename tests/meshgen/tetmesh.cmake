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
# real files and what goes wrong with them: gmsh judged by the model's own tolerances (the
# OpenCASCADE repository's screw, gen_shapes' loose box), the fallback to the other mesher,
# the quality judgement, the estimate within 3x (docs/DESIGN.md, "Meshers")
cm_add_unit_test(test_tetmesh_real test_tetmesh_real.c LIBS cm_meshgen cm_cad cm_mesh LABELS cad)
set_tests_properties(test_tetmesh_real PROPERTIES FIXTURES_REQUIRED cad_shapes)
# `cadmorph mesh` with its defaults on the screw: gmsh meshes it, nothing on stderr
set(CM_MESHGEN_WORK ${CM_TEST_WORK}/meshgen)
file(MAKE_DIRECTORY ${CM_MESHGEN_WORK})
add_test(NAME cli_mesh_screw_defaults COMMAND ${CM_RUN_CLI} --exit 0 --stderr-lines 0 --last-line
  "min_scaled_jacobian=0\\.[0-9]+ mean_scaled_jacobian=0\\.[0-9]+ inverted=0 cells=[0-9]+" --
  $<TARGET_FILE:cadmorph> mesh ${CM_TEST_DATA}/occt/screw.step -o ${CM_MESHGEN_WORK}/screw.vtu)
add_test(NAME cli_mesh_loose_box_gmsh COMMAND ${CM_RUN_CLI} --exit 0 --stderr-lines 0 --last-line
  ".* inverted=0 cells=[0-9]+" --
  $<TARGET_FILE:cadmorph> mesh ${CM_TEST_WORK}/cad/loose_box.step -o ${CM_MESHGEN_WORK}/loose_box.vtu
  --mesher gmsh)
set_tests_properties(cli_mesh_loose_box_gmsh PROPERTIES FIXTURES_REQUIRED cad_shapes)
# a mesh below --min-sj is not written: exit 3, one line naming the worst tet
add_test(NAME cli_mesh_min_sj_rejected COMMAND ${CM_RUN_CLI} --exit 3 --stderr-lines 1
  --stderr "cadmorph mesh: [^\n]*bore_0.step: TetGen.s mesh has [0-9]+ tets? at or below the scaled-Jacobian floor 0.99[^\n]*the worst, tet [0-9]+"
  --absent ${CM_MESHGEN_WORK}/rejected.vtu --
  $<TARGET_FILE:cadmorph> mesh ${CM_TEST_DATA}/models/bore_0.step -o ${CM_MESHGEN_WORK}/rejected.vtu
  --size 0.8 --mesher tetgen --min-sj 0.99)
set_tests_properties(cli_mesh_screw_defaults cli_mesh_loose_box_gmsh cli_mesh_min_sj_rejected
  PROPERTIES LABELS "unit;cli;cad")
