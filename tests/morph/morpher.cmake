# The morph engine (morph/morpher.c, morph/morph_pipeline.c) on the gmsh meshes of the
# surface fixtures (fixture surface_meshes of tests/surface).
cm_add_unit_test(test_morpher test_morpher.c LIBS cm_morph LABELS cad)
set_tests_properties(test_morpher PROPERTIES FIXTURES_REQUIRED surface_meshes)

# --off-cad fixed: a body in a box (gmsh's Python API), the box not on the body's STEP.
add_test(NAME test_off_cad
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_off_cad.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK})
set_tests_properties(test_off_cad PROPERTIES LABELS "cad;cli" TIMEOUT 120)

# Stopping on request (cm_context_interrupt): the morpher on the built-in bore (its STEP and
# hex O-grid: study/), stopped at progress points, then applied again
cm_add_unit_test(test_morph_interrupt test_morph_interrupt.c LIBS cm_morph cm_study LABELS cad)

# --off-cad fixed with sliding patches: a block in a half tunnel whose symmetry plane cuts it,
# morphed and studied with --slide symmetry (gmsh's Python API makes the mesh and the STEPs).
add_test(NAME test_off_cad_slide
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_off_cad_slide.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK})
set_tests_properties(test_off_cad_slide PROPERTIES LABELS "cad;cli" TIMEOUT 120)

# cm_morpher_apply_batch against cm_morpher_apply_method per target on the built-in bore (dense
# and iterative RBF solves): statuses, rows and coordinates, with a mismatched target and
# results morphed again alone
cm_add_unit_test(test_morph_batch test_morph_batch.c LIBS cm_morph cm_study LABELS cad)
