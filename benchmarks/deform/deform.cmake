# The FFD / DM-FFD / RBF benchmark suite of the second paper (run by benchmarks/deform/
# run_deform.sh; not a test).
add_executable(bench_deform
  ${CMAKE_CURRENT_LIST_DIR}/bench_deform.c
  ${CMAKE_CURRENT_LIST_DIR}/surface.c
)
target_link_libraries(bench_deform PRIVATE cm_deform cm_rbf cm_mesh cm_core cm_lapack cm_warnings
  cm_posix)
# The MLS deformation at scale (issue 15): set-up once, repeated deformations, peak memory.
add_executable(bench_mls ${CMAKE_CURRENT_LIST_DIR}/../deform_mls/bench_mls.c)
target_link_libraries(bench_mls PRIVATE cm_mls cm_volume cm_mesh cm_core cm_warnings cm_posix)
# CSV -> SVG through cadmorph's plot writer (the MLS figures of RESULTS.md)
add_executable(mls_plot ${CMAKE_CURRENT_LIST_DIR}/../deform_mls/mls_plot.c)
target_link_libraries(mls_plot PRIVATE cm_study cm_core cm_warnings cm_posix)
