# RBF core tests: invariants in C, and a cross-check against scipy's RBFInterpolator.
cm_add_unit_test(test_rbf ${CMAKE_CURRENT_LIST_DIR}/test_rbf.c LIBS cm_rbf LABELS rbf)

# scipy cross-check: the C side writes problems and results into the work dir, then the
# Python side solves the same problems with scipy and compares.
cm_add_unit_test(test_rbf_scipy ${CMAKE_CURRENT_LIST_DIR}/test_rbf_scipy.c LIBS cm_rbf LABELS rbf)
set_tests_properties(test_rbf_scipy PROPERTIES FIXTURES_SETUP rbf_scipy_data)
add_test(NAME rbf_scipy_check
         COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/rbf_scipy_check.py ${CM_TEST_WORK})
set_tests_properties(rbf_scipy_check PROPERTIES LABELS "unit;rbf" FIXTURES_REQUIRED rbf_scipy_data)

# the panel-by-panel RFP Cholesky against dpftrf (round-off), pivots, progress
cm_add_unit_test(test_cholesky_blocked ${CMAKE_CURRENT_LIST_DIR}/test_cholesky_blocked.c
  LIBS cm_rbf_internal cm_lapack LABELS rbf)
# the look-ahead RFP Cholesky on 1-3 threads against dpftrf (round-off, A - LL'), pivots,
# progress, the path cm_rbf_cholesky_rfp takes
cm_add_unit_test(test_cholesky_lookahead ${CMAKE_CURRENT_LIST_DIR}/test_cholesky_lookahead.c
  LIBS cm_rbf_internal cm_lapack LABELS rbf)
# the BLAS-core decision table (cpuid flags and core names in, decision out), cm_blas_info
cm_add_unit_test(test_blas_core ${CMAKE_CURRENT_LIST_DIR}/test_blas_core.c
  LIBS cm_platform LABELS rbf)
# iterative solver vs dense on a box-with-bore boundary set, affine data, two bodies, threads
cm_add_unit_test(test_rbf_iterative ${CMAKE_CURRENT_LIST_DIR}/test_rbf_iterative.c LIBS cm_rbf_internal LABELS rbf)
# the Schwarz coarse problem by an inner Krylov solve (multilevel) against dense
cm_add_unit_test(test_rbf_schwarz_inner ${CMAKE_CURRENT_LIST_DIR}/test_rbf_schwarz_inner.c LIBS cm_rbf_internal LABELS rbf)
# the kD-tree leaves on sets with tied coordinates (planar faces): a partition, boxes apart
cm_add_unit_test(test_rbf_schwarz ${CMAKE_CURRENT_LIST_DIR}/test_rbf_schwarz.c LIBS cm_rbf_internal LABELS rbf)
# thinned overlap: a thinned subdomain keeps its leaf, its cap and its reach; against dense
cm_add_unit_test(test_rbf_thin ${CMAKE_CURRENT_LIST_DIR}/test_rbf_thin.c LIBS cm_rbf_internal LABELS rbf)

# the distributed solver (CADMORPH_WITH_PETSC only): against the serial iterative solver
# under `mpirun -n 2` (--oversubscribe: the CI machine may have fewer slots; as root too), and
# on one rank without mpirun
if(CADMORPH_WITH_PETSC)
  add_executable(test_rbf_petsc ${CMAKE_CURRENT_LIST_DIR}/test_rbf_petsc.c)
  target_include_directories(test_rbf_petsc PRIVATE ${PROJECT_SOURCE_DIR}/tests/helpers)
  target_link_libraries(test_rbf_petsc PRIVATE cm_rbf cm_platform cm_core cm_warnings cm_posix)
  set(CM_MPI_ENV "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1")
  add_test(NAME test_rbf_petsc_2ranks
    COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 --oversubscribe
            $<TARGET_FILE:test_rbf_petsc> ${CM_TEST_DATA} ${CM_TEST_WORK} 2)
  add_test(NAME test_rbf_petsc_1rank
    COMMAND test_rbf_petsc ${CM_TEST_DATA} ${CM_TEST_WORK} 1)
  set_tests_properties(test_rbf_petsc_2ranks test_rbf_petsc_1rank PROPERTIES
    LABELS "unit;rbf;petsc" ENVIRONMENT "${CM_MPI_ENV}")
endif()
# the r^3 treecode: its error bound on random and real weights; fits with fast matvecs
# against direct ones and dense; affine data; the choice of the fast evaluation
cm_add_unit_test(test_rbf_treecode ${CMAKE_CURRENT_LIST_DIR}/test_rbf_treecode.c LIBS cm_rbf_internal LABELS rbf)
# the kernel sums per instruction set (generic, AVX2, AVX-512 compiled and by hand) against
# each other and a long-double reference: plain and compensated, tails, threads
cm_add_unit_test(test_rbf_sum ${CMAKE_CURRENT_LIST_DIR}/test_rbf_sum.c LIBS cm_rbf_internal LABELS rbf)
# many columns in one pass: each column's sum the same bits alone or in a batch (plain,
# compensated, self product, treecode; every ISA this CPU runs), and against a reference
cm_add_unit_test(test_rbf_sum_batch ${CMAKE_CURRENT_LIST_DIR}/test_rbf_sum_batch.c
  LIBS cm_rbf_internal LABELS rbf)
# AUTO's cost model: probe rates, growth of the costs, one crossover
cm_add_unit_test(test_rbf_auto ${CMAKE_CURRENT_LIST_DIR}/test_rbf_auto.c LIBS cm_rbf_internal LABELS rbf)
# stopping on request (cm_context_interrupt): sums in chunks are the bits of one pass;
# create, solve and evaluate stopped at progress points
cm_add_unit_test(test_rbf_interrupt ${CMAKE_CURRENT_LIST_DIR}/test_rbf_interrupt.c LIBS cm_rbf_internal LABELS rbf)
# the reverse product of solve-then-evaluate: the dot-product test (dense r^3, r, thin plate;
# iterative with direct and treecode sums; merged duplicates), iterative against dense
cm_add_unit_test(test_rbf_transpose ${CMAKE_CURRENT_LIST_DIR}/test_rbf_transpose.c LIBS cm_rbf_internal LABELS rbf)
# many right-hand sides in one iterative solve against each alone (direct and treecode
# sums), a slow column beside smooth ones, warm starts, columns in groups of a memory budget,
# the solve's progress in columns
cm_add_unit_test(test_rbf_batch ${CMAKE_CURRENT_LIST_DIR}/test_rbf_batch.c LIBS cm_rbf_internal LABELS rbf)
# the Schwarz preconditioner's dense arithmetic for a batch of columns (local rows, coarse
# solves) against plain references, each column the same bits whatever its batch
cm_add_unit_test(test_schwarz_rows ${CMAKE_CURRENT_LIST_DIR}/test_schwarz_rows.c LIBS cm_rbf_internal LABELS rbf)
# a family's fields in warm groups: the order they are solved in, and the warm columns
# evaluated through the span of the cold ones, against direct sums and each field alone
cm_add_unit_test(test_rbf_span ${CMAKE_CURRENT_LIST_DIR}/test_rbf_span.c LIBS cm_rbf_internal LABELS rbf)
