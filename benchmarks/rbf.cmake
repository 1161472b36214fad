# RBF core benchmark (run by benchmarks/bench_rbf.sh; not a test).
add_executable(bench_rbf ${CMAKE_CURRENT_LIST_DIR}/bench_rbf.c)
target_link_libraries(bench_rbf PRIVATE cm_rbf cm_core cm_lapack cm_warnings cm_posix)
# dpftrf vs the panel-by-panel RFP Cholesky, side by side (benchmarks/RESULTS.md)
add_executable(bench_cholesky ${CMAKE_CURRENT_LIST_DIR}/bench_cholesky.c)
target_include_directories(bench_cholesky PRIVATE ${PROJECT_SOURCE_DIR})
# OpenMP: MODEL=1 compiles rbf/cholesky_lookahead.c into it once more, with its tasks timed
target_link_libraries(bench_cholesky PRIVATE cm_rbf cm_core cm_lapack cm_warnings cm_posix OpenMP::OpenMP_C)
# Iterative vs dense solver on real boundary node sets (see RESULTS.md; not a test).
add_executable(bench_rbf_iterative ${CMAKE_CURRENT_LIST_DIR}/bench_rbf_iterative.c)
target_link_libraries(bench_rbf_iterative PRIVATE cm_rbf cm_core cm_warnings cm_posix)
target_include_directories(bench_rbf_iterative PRIVATE ${PROJECT_SOURCE_DIR})
# The r^3 treecode against direct sums on real and random weights (RESULTS.md, fast summation)
add_executable(bench_rbf_treecode ${CMAKE_CURRENT_LIST_DIR}/bench_rbf_treecode.c)
target_include_directories(bench_rbf_treecode PRIVATE ${PROJECT_SOURCE_DIR})
target_link_libraries(bench_rbf_treecode PRIVATE cm_rbf cm_core cm_warnings cm_posix)
# Pairs per CPU-second of the r^3 kernel sums, plain and compensated, per instruction set
# (before/after the hand-written AVX-512 blocks side by side; see RESULTS.md, issue 10)
add_executable(bench_kernel ${CMAKE_CURRENT_LIST_DIR}/bench_kernel.c)
target_include_directories(bench_kernel PRIVATE ${PROJECT_SOURCE_DIR})
target_link_libraries(bench_kernel PRIVATE cm_rbf cm_core cm_warnings cm_posix)
