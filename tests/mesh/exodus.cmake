# Exodus II (mesh/io/exodus.c): a C test on files written with SEACAS's own library (node order
# of the quadratic types against VTK's, sets as groups, number maps, the write back in the
# file's word size, refusals, hostile files), and the cross-check with meshio and netCDF4:
# a meshio-written file and the library-written fixture read, moved by an affine map, written
# back with every other netCDF variable and attribute unchanged, and read again by meshio.
# (the test writes its fixtures with the library itself: linked here, opened by cm_mesh)
cm_add_unit_test(test_exodus test_exodus.c LIBS cm_mesh cm_exodus ${EXODUS_LIBRARY} LABELS hostile)
add_test(NAME test_exodus_crosscheck
  COMMAND ${CM_PYTHON_LIB} ${CMAKE_CURRENT_SOURCE_DIR}/test_exodus_crosscheck.py
          $<TARGET_FILE:test_exodus> $<TARGET_FILE:cadmorph> ${CM_TEST_WORK}/exodus)
set_tests_properties(test_exodus_crosscheck PROPERTIES LABELS "unit;cli"
  ENVIRONMENT "PYTHONPATH=${PROJECT_BINARY_DIR}/python")
