# CAD layer benchmark (issue 4): `bench_cad MODEL.step [samples] [points] [threads]`;
# results in benchmarks/RESULTS.md.
add_executable(bench_cad bench_cad.c)
target_link_libraries(bench_cad PRIVATE cm_cad cm_core cm_warnings cm_posix)
