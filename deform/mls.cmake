# The constrained MLS space deformation (mls.h): own grid search, LAPACKE for the 4x4 SVD,
# CHOLMOD (cm_suitesparse, the root list) for the sparse normal equations.
add_library(cm_mls STATIC
  ${CMAKE_CURRENT_LIST_DIR}/mls.c         # samples, eq. 14 with CHOLMOD, apply
  ${CMAKE_CURRENT_LIST_DIR}/mls_basis.c   # shape functions, gradients, Laplacians
  ${CMAKE_CURRENT_LIST_DIR}/mls_grid.c    # uniform-grid nearest samples
  ${CMAKE_CURRENT_LIST_DIR}/mls_sample.c  # dense sampling, farthest points, Lloyd
  ${CMAKE_CURRENT_LIST_DIR}/mls_blend.c   # the residual carried into the free nodes
  ${CMAKE_CURRENT_LIST_DIR}/mls_curvature.c  # cotangent mean curvature of surfaces
  ${CMAKE_CURRENT_LIST_DIR}/mls_shell.c      # the mesh-based shell of section 3 (ground truth)
)
target_link_libraries(cm_mls
  PUBLIC cm_mesh cm_core
  PRIVATE cm_warnings cm_posix OpenMP::OpenMP_C cm_lapack cm_suitesparse ${MATH_LIBRARY})
# white-box access for tests (mls_internal.h): the module's folder on the include path
add_library(cm_mls_internal INTERFACE)
target_include_directories(cm_mls_internal INTERFACE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(cm_mls_internal INTERFACE cm_mls)
