# gmsh .msh reader/writer: C tests on gmsh-written fixtures, then a Python cross-check of what
# they read and wrote against meshio and the gmsh API, and a 1M-tet timing (label slow).
cm_add_unit_test(test_msh test_msh.c LIBS cm_mesh)
set_tests_properties(test_msh PROPERTIES FIXTURES_SETUP msh_outputs)
add_test(NAME test_msh_crosscheck
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_msh_crosscheck.py
          ${CM_TEST_DATA} ${CM_TEST_WORK} ${PROJECT_SOURCE_DIR}/mesh/io/msh_common.c)
set_tests_properties(test_msh_crosscheck PROPERTIES FIXTURES_REQUIRED msh_outputs LABELS "unit")
