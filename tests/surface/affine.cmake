# Affine edits reproduced exactly (benchmarks/RESULTS.md, Affine edits): gen_affine writes the STEP pairs
# G0, G1 = A G0 + b with OpenCASCADE (fixture affine_steps); test_affine checks the surface
# morph of every pair and the whole morph (tets and hexes) against A M0 + b.
add_executable(gen_affine gen_affine.cpp)
target_link_libraries(gen_affine PRIVATE cm_warnings cm_occ cm_cad)
add_test(NAME surface_affine_steps COMMAND gen_affine ${CM_TEST_DATA} ${CM_TEST_WORK})
set_tests_properties(surface_affine_steps PROPERTIES FIXTURES_SETUP affine_steps
  LABELS "unit;cad")

add_executable(test_affine test_affine.c)
target_include_directories(test_affine PRIVATE ${PROJECT_SOURCE_DIR}/tests/helpers)
target_link_libraries(test_affine PRIVATE cm_study cm_morph cm_meshgen cm_volume cm_core cm_warnings cm_posix)
foreach(mode surface morph general)
  add_test(NAME test_affine_${mode} COMMAND test_affine ${CM_TEST_DATA} ${CM_TEST_WORK} ${mode})
  set_tests_properties(test_affine_${mode} PROPERTIES LABELS "unit;cad"
    FIXTURES_REQUIRED "affine_steps;surface_meshes")
endforeach()
