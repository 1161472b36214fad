# SU2 native .su2: the reader, the write back and new files on files written in the test
# (hostile ones too); against the .su2 that gmsh and meshio write (su2_crosscheck.py: the
# cadmorph Python package of the build tree); the CLI's commands on the gmsh-meshed bore
# written to .su2 by gmsh (su2_cli.py).
cm_add_unit_test(test_su2 test_su2.c LIBS cm_mesh)
set_tests_properties(test_su2 PROPERTIES LABELS "unit;hostile")
add_test(NAME test_su2_crosscheck
  COMMAND ${CM_PYTHON_LIB} ${CMAKE_CURRENT_SOURCE_DIR}/su2_crosscheck.py ${CM_TEST_WORK})
set_tests_properties(test_su2_crosscheck PROPERTIES LABELS "unit;python" TIMEOUT 120
  ENVIRONMENT "PYTHONPATH=${PROJECT_BINARY_DIR}/python;PYTHONDONTWRITEBYTECODE=1")
add_test(NAME test_su2_cli
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/su2_cli.py $<TARGET_FILE:cadmorph> ${CM_TEST_DATA}
          ${CM_TEST_WORK})
set_tests_properties(test_su2_cli PROPERTIES LABELS "cli" TIMEOUT 300)
# an SU2 user's CFD case (body in a box, gmsh's markers and the FFD block SU2_DEF appends):
# the wall moved and the volume warped into mesh_out.su2 as SU2_DEF does, twice; the case's
# .msh with volume and boundary groups written to a new .su2
add_test(NAME test_su2_cfd
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/su2_cfd.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK})
set_tests_properties(test_su2_cfd PROPERTIES LABELS "cli" TIMEOUT 300)
