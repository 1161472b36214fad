# Parametric benchmark models and their structured hex meshes (issue 6): benchmarks/models/.
add_subdirectory(${CMAKE_CURRENT_LIST_DIR}/models ${CMAKE_CURRENT_BINARY_DIR}/models)
