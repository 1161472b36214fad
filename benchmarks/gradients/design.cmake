# Design velocities against one morph (bench_design_velocity): README.md names the command,
# benchmarks/RESULTS.md "Gradients" holds the figures.
add_executable(bench_design_velocity ${CMAKE_CURRENT_LIST_DIR}/bench_design_velocity.c)
target_link_libraries(bench_design_velocity PRIVATE cm_study cm_morph cm_cad cm_mesh cm_core
  cm_warnings cm_posix)
cm_bench_blas_setup(bench_design_velocity)
