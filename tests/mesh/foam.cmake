# OpenFOAM polyMesh I/O and checkMesh's metrics: a C test on meshes built in code (no
# OpenFOAM needed), and the cross-check against the real blockMesh / snappyHexMesh /
# checkMesh and VTK's vtkOpenFOAMReader (label foam; skipped with exit 77 only when the
# openfoam package is absent - scripts/setup.sh installs it).
cm_add_unit_test(test_foam_io test_foam_io.c LIBS cm_mesh_internal ZLIB::ZLIB LABELS foam)
add_test(NAME test_foam_crosscheck
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_foam_crosscheck.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK})
set_tests_properties(test_foam_crosscheck PROPERTIES LABELS "foam;cli" SKIP_RETURN_CODE 77 TIMEOUT 300)
# The polyhedral morph test at ~52k cells (benchmarks/foam/make_case.py; RBF roof warp and the
# CAD-driven morph, checkMesh against quality --foam).
add_test(NAME test_foam_car
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_foam_car.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK})
set_tests_properties(test_foam_car PROPERTIES LABELS "foam;cli;slow" SKIP_RETURN_CODE 77 TIMEOUT 600)
# Decomposed cases (decomposePar pieces read as one mesh, written back piece by piece,
# against reconstructPar and checkMesh) and whole-case output (-o newcase/ runs simpleFoam;
# ASCII points at the case's writePrecision).
add_test(NAME test_foam_decomposed
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_foam_decomposed.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK})
set_tests_properties(test_foam_decomposed PROPERTIES LABELS "foam;cli;cfd" SKIP_RETURN_CODE 77 TIMEOUT 300)
