# CAD layer benchmark (issue 4): `bench_cad MODEL.step [samples] [points] [threads]`;
# results in benchmarks/results_cad.md.
if(NOT TARGET bench_cad)
  add_executable(bench_cad ${CMAKE_CURRENT_LIST_DIR}/bench_cad.c)
  target_link_libraries(bench_cad PRIVATE cm_cad cm_core cm_warnings cm_posix)
endif()
