# Boundary motion by patch kind on the shared OpenFOAM cases (tests/helpers/foam_cases.py:
# 2-D, wedge, symmetry plane, cyclic): warp and deform of the body through the CLI, checked
# by the real checkMesh and 5 solver steps (label foam; skipped with exit 77 only when the
# openfoam package is absent).
add_test(NAME test_foam_slide
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_foam_slide.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK})
set_tests_properties(test_foam_slide PROPERTIES LABELS "foam;cfd" SKIP_RETURN_CODE 77 TIMEOUT 300)
