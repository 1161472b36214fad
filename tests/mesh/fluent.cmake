# Fluent .msh/.cas: a C test on the fixtures of tests/data/fluent (foamMeshToFluent's files and
# their binary variants: reading, the write back, hostile files), and the cross-check against
# OpenFOAM's own Fluent readers and the CLI (label foam; skipped with exit 77 only when the
# openfoam package is absent - scripts/setup.sh installs it).
cm_add_unit_test(test_fluent test_fluent.c LIBS cm_mesh_internal LABELS hostile)
add_test(NAME test_fluent_crosscheck
  COMMAND ${CM_PYTHON_LIB} ${CMAKE_CURRENT_SOURCE_DIR}/test_fluent_crosscheck.py $<TARGET_FILE:cadmorph>
          ${CM_TEST_DATA} ${CM_TEST_WORK})
set_tests_properties(test_fluent_crosscheck PROPERTIES LABELS "foam;cli" SKIP_RETURN_CODE 77 TIMEOUT 300
  ENVIRONMENT "PYTHONPATH=${PROJECT_BINARY_DIR}/python;PYTHONDONTWRITEBYTECODE=1")
