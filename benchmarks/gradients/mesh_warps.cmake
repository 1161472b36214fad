# The reverse product of the mesh-based warps (femwarp, lbwarp, and any other method by name)
# against their forward product on one warp: RESULTS.md, "Gradients".
add_executable(bench_warp_transpose_mesh ${CMAKE_CURRENT_LIST_DIR}/bench_warp_transpose_mesh.c)
target_link_libraries(bench_warp_transpose_mesh PRIVATE cm_volume cm_mesh cm_core cm_warnings
  cm_posix ${MATH_LIBRARY})
cm_bench_blas_setup(bench_warp_transpose_mesh)
