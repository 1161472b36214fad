# Boundary faces/nodes, components, duplicate and non-manifold checks on meshes built in code.
cm_add_unit_test(test_boundary test_boundary.c LIBS cm_mesh)
target_link_libraries(test_boundary PRIVATE m)
