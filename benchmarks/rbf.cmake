# RBF core benchmark (run by benchmarks/bench_rbf.sh; not a test).
add_executable(bench_rbf ${CMAKE_CURRENT_LIST_DIR}/bench_rbf.c)
target_link_libraries(bench_rbf PRIVATE cm_rbf cm_core cm_lapack cm_warnings cm_posix)
