# Shape-Up benchmarks (issue 16): the two constraint formulations of section 6.1 on a
# whole-plate planarity constraint. Run by hand, results in RESULTS.md.
add_executable(bench_shapeup_sparse ${CMAKE_CURRENT_LIST_DIR}/bench_shapeup_sparse.c)
target_link_libraries(bench_shapeup_sparse PRIVATE cm_mls cm_mesh cm_core cm_warnings cm_posix)
