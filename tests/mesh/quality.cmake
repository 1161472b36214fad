# Scaled Jacobian: analytic cases, and a cross-check against VTK's vtkMeshQuality (Verdict):
# a C program writes cells and our values, a python script recomputes them with VTK.
cm_add_unit_test(test_quality test_quality.c LIBS cm_mesh)
target_link_libraries(test_quality PRIVATE m)

cm_add_unit_test(test_quality_vtk_cases test_quality_vtk_cases.c LIBS cm_mesh)
set_tests_properties(test_quality_vtk_cases PROPERTIES FIXTURES_SETUP quality_vtk_cases)
add_test(NAME quality_vtk_crosscheck
         COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/check_quality_vtk.py ${CM_TEST_WORK})
set_tests_properties(quality_vtk_crosscheck PROPERTIES LABELS unit FIXTURES_REQUIRED quality_vtk_cases)
