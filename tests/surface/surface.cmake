# Tests of surface/ (classification, surface morph): gmsh meshes of the STEP pairs in
# tests/data/surface, made at test time into the work dir (fixture surface_meshes).
set(CM_SURFACE_WORK ${CM_TEST_WORK}/surface)
file(MAKE_DIRECTORY ${CM_SURFACE_WORK})
add_test(NAME surface_meshes_setup
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/make_meshes.py ${CM_TEST_DATA} ${CM_TEST_WORK})
set_tests_properties(surface_meshes_setup PROPERTIES FIXTURES_SETUP surface_meshes
  LABELS "unit;cad")

cm_add_unit_test(test_surface test_surface.c LIBS cm_surface LABELS cad)
set_tests_properties(test_surface PROPERTIES FIXTURES_REQUIRED surface_meshes)

cm_add_unit_test(test_cad_sets test_cad_sets.c LIBS cm_surface LABELS cad)
set_tests_properties(test_cad_sets PROPERTIES FIXTURES_REQUIRED surface_meshes)

cm_add_unit_test(test_surface_cache test_surface_cache.c LIBS cm_morph cm_surface LABELS cad)
set_tests_properties(test_surface_cache PROPERTIES FIXTURES_REQUIRED surface_meshes)
