# Nastran bulk data: a C test on decks written in code (numbers, layouts, systems, quadratic
# node order, INCLUDE, hostile decks, writing back), and the cross-check against decks that gmsh
# and meshio write and read.
cm_add_unit_test(test_nastran test_nastran.c LIBS cm_mesh_internal LABELS hostile)
add_test(NAME test_nastran_crosscheck
  COMMAND ${CM_PYTHON_LIB} ${CMAKE_CURRENT_SOURCE_DIR}/test_nastran_crosscheck.py ${CM_TEST_WORK})
set_tests_properties(test_nastran_crosscheck PROPERTIES LABELS "unit" TIMEOUT 300
  ENVIRONMENT "PYTHONPATH=${PROJECT_BINARY_DIR}/python")
