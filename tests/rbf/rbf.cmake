# RBF core tests: invariants in C, and a cross-check against scipy's RBFInterpolator.
cm_add_unit_test(test_rbf ${CMAKE_CURRENT_LIST_DIR}/test_rbf.c LIBS cm_rbf LABELS rbf)

# scipy cross-check: the C side writes problems and results into the work dir, then the
# Python side solves the same problems with scipy and compares.
cm_add_unit_test(test_rbf_scipy ${CMAKE_CURRENT_LIST_DIR}/test_rbf_scipy.c LIBS cm_rbf LABELS rbf)
set_tests_properties(test_rbf_scipy PROPERTIES FIXTURES_SETUP rbf_scipy_data)
add_test(NAME rbf_scipy_check
         COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/rbf_scipy_check.py ${CM_TEST_WORK})
set_tests_properties(rbf_scipy_check PROPERTIES LABELS "unit;rbf" FIXTURES_REQUIRED rbf_scipy_data)
