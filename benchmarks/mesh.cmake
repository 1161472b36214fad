# Mesh I/O and quality benchmarks (issue 2); commands and figures in RESULTS.md.
add_executable(bench_mesh_io bench_mesh_io.c)
target_link_libraries(bench_mesh_io PRIVATE cm_mesh cm_core cm_warnings cm_posix)
add_executable(bench_quality bench_quality.c)
target_link_libraries(bench_quality PRIVATE cm_mesh cm_core cm_warnings cm_posix)
