# Tests of the volume warp (volume/warp.c, volume/displacement_csv.c).
cm_add_unit_test(test_warp_csv test_warp_csv.c LIBS cm_volume)
cm_add_unit_test(test_warp test_warp.c LIBS cm_volume)
# the reverse product of the RBF warps: the dot-product test on tets, hexes, several
# components, dense and iterative, and a gmsh mesh; iterative against dense
cm_add_unit_test(test_warp_transpose_rbf test_warp_transpose_rbf.c LIBS cm_volume)
# the forward product of k fields in one call against k applies: the RBF's many-column solve
# (dense, iterative), FEMWARP's loop over apply, stopping on request
cm_add_unit_test(test_warp_apply_many test_warp_apply_many.c LIBS cm_volume)
# the tolerance from the mesh: the rule on tets, hexes and polyhedra, and the wall step it
# promises (iterative against dense on a block with a thin wall layer)
cm_add_unit_test(test_warp_tolerance test_warp_tolerance.c LIBS cm_volume)
# ... and on a boundary-layer mesh gmsh writes (prisms, a 1e-4 wall layer): `cadmorph warp -v`
# names the rule's tolerance, and its mesh stays within the strain it allows
add_test(NAME warp_layer_gmsh
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/warp_layer.py $<TARGET_FILE:cadmorph>
          ${CM_TEST_WORK}/warp_layer)
set_tests_properties(warp_layer_gmsh PROPERTIES LABELS "unit;cli")

# Cross-check on a real mesh: gmsh meshes a sphere cut out of a box (setup, also used by the
# CLI tests), cadmorph warps it (test_warp_sphere), scipy's RBFInterpolator redoes it (scipy).
add_test(NAME warp_sphere_setup
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/warp_sphere.py setup ${CM_TEST_WORK}
          ${CM_TEST_DATA}/warp/sphere_in_box.geo)
set_tests_properties(warp_sphere_setup PROPERTIES FIXTURES_SETUP warp_sphere LABELS "unit")
cm_add_unit_test(test_warp_sphere test_warp_sphere.c LIBS cm_volume)
set_tests_properties(test_warp_sphere PROPERTIES
  FIXTURES_REQUIRED warp_sphere FIXTURES_SETUP warp_sphere_result)
add_test(NAME warp_sphere_scipy
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/warp_sphere.py compare ${CM_TEST_WORK})
set_tests_properties(warp_sphere_scipy PROPERTIES
  FIXTURES_REQUIRED "warp_sphere;warp_sphere_result" LABELS "unit")

# Staten's comparators (FEMWARP, LBWARP, linear-simplex): gmsh writes a mixed mesh (tets,
# hexes, wedges, pyramids) and the meshes of the scipy and CLI checks (tests/cli/
# warp_methods.cmake); the C test checks affine reproduction, zero motion, the LBWARP weights
# and the simplex location.
add_test(NAME warp_staten_setup
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/warp_staten.py setup ${CM_TEST_WORK})
set_tests_properties(warp_staten_setup PROPERTIES FIXTURES_SETUP warp_staten LABELS "unit;volume")
cm_add_unit_test(test_warp_staten test_warp_staten.c LIBS cm_volume_internal LABELS volume)
set_tests_properties(test_warp_staten PROPERTIES FIXTURES_REQUIRED warp_staten)

# Stopping on request (cm_context_interrupt): every warp method and the optimiser on the
# bore's O-grid, stopped at each progress point, then run again (cm_hexmesh_bore: study/)
cm_add_unit_test(test_warp_interrupt test_warp_interrupt.c LIBS cm_volume cm_study)

# The reverse product of the mesh-based warps and of dmffd and mls (cm_warp_apply_transpose):
# the dot-product test and the linearity it rests on, on blocks, two components, polyhedra,
# the bore's O-grid (cm_hexmesh_bore: study/) and the mixed mesh of warp_staten.py setup
cm_add_unit_test(test_warp_transpose test_warp_transpose.c LIBS cm_volume cm_study LABELS volume)
set_tests_properties(test_warp_transpose PROPERTIES FIXTURES_REQUIRED warp_staten)
# Boundary motion by patch kind (motion.h): kinds, lines, 2-D and wedge recognition, the
# projection, cm_warp_mesh under a motion, and the same bits as before without slides.
cm_add_unit_test(test_motion test_motion.c LIBS cm_volume)
