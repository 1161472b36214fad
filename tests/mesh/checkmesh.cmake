# checkMesh's whole verdict: `cadmorph quality --foam` against the real checkMesh on blockMesh
# cases of every kind and broken copies of them (label foam; skipped with exit 77 only when
# the openfoam package is absent), and the inverted-cell count on a snappyHexMesh case.
add_test(NAME test_checkmesh_verdict
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_checkmesh_verdict.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK} blockmesh)
add_test(NAME test_checkmesh_inverted_snappy
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_checkmesh_verdict.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK}/snappy_inverted snappy)
set_tests_properties(test_checkmesh_verdict test_checkmesh_inverted_snappy PROPERTIES
  LABELS "foam;cli;cfd" SKIP_RETURN_CODE 77 TIMEOUT 300)
