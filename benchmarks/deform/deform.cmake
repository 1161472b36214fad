# The FFD / DM-FFD / RBF benchmark suite of the second paper (run by benchmarks/deform/
# run_deform.sh; not a test).
add_executable(bench_deform
  ${CMAKE_CURRENT_LIST_DIR}/bench_deform.c
  ${CMAKE_CURRENT_LIST_DIR}/surface.c
)
target_link_libraries(bench_deform PRIVATE cm_deform cm_rbf cm_mesh cm_core cm_lapack cm_warnings
  cm_posix)
