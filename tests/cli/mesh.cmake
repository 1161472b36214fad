# `cadmorph mesh` on the gmsh-written bore of tests/data/models: the run, a cross-check of
# its output by VTK (scaled Jacobian) and gmsh (reads the .msh), and the error paths.
set(MD ${CM_TEST_DATA}/models)
set(MW ${CM_TEST_WORK}/mesh)
file(MAKE_DIRECTORY ${MW})
set(MRUN ${CM_PYTHON} ${PROJECT_SOURCE_DIR}/tests/mesh/run_quality_cli.py)

add_test(NAME cli_mesh_bore_vtu COMMAND ${MRUN} --exit 0 --stderr-lines 0 --last-line
  "min_scaled_jacobian=0\\.[0-9]+ mean_scaled_jacobian=0\\.[0-9]+ inverted=0 cells=[0-9]+" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/bore.vtu --size 0.3)
add_test(NAME cli_mesh_bore_msh COMMAND ${MRUN} --exit 0 --last-line ".* inverted=0 .*" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/bore.msh --size 0.3)
# same options for both: TetGen is deterministic, so gmsh must find VTK's counts
set_tests_properties(cli_mesh_bore_vtu cli_mesh_bore_msh PROPERTIES FIXTURES_SETUP cli_mesh_bore)
add_test(NAME cli_mesh_bore_medit COMMAND ${MRUN} --exit 0 --last-line ".* inverted=0 .*" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/bore.mesh --size 0.4 --quality 1.6 --threads 1)
add_test(NAME cli_mesh_bore_vtk_gmsh COMMAND ${CM_PYTHON}
  ${PROJECT_SOURCE_DIR}/tests/volume/test_tetmesh_vtk.py ${MW}/bore.vtu ${MW}/bore.msh 7)
set_tests_properties(cli_mesh_bore_vtk_gmsh PROPERTIES FIXTURES_REQUIRED cli_mesh_bore)

add_test(NAME cli_mesh_help COMMAND ${MRUN} --exit 0 --last-line ".*internal error.*" --
  $<TARGET_FILE:cadmorph> mesh --help)
add_test(NAME cli_mesh_no_output COMMAND ${MRUN} --exit 1 --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step)
add_test(NAME cli_mesh_bad_size COMMAND ${MRUN} --exit 1 --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/x.vtu --size -1)
add_test(NAME cli_mesh_bad_quality COMMAND ${MRUN} --exit 1 --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/x.vtu --quality 0.5)
add_test(NAME cli_mesh_output_is_input COMMAND ${MRUN} --exit 1 --unchanged ${MD}/bore_0.step --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MD}/bore_0.step)
add_test(NAME cli_mesh_no_solid COMMAND ${MRUN} --exit 2 --stderr-lines 1 --
  $<TARGET_FILE:cadmorph> mesh ${MD}/sheet.step -o ${MW}/sheet.vtu)
# the wrapper checks the exit code and prints FAIL: otherwise; the message must name the cause
set_tests_properties(cli_mesh_no_solid PROPERTIES PASS_REGULAR_EXPRESSION
  "cadmorph mesh: [^\n]*no solid" FAIL_REGULAR_EXPRESSION "FAIL:")
add_test(NAME cli_mesh_missing_file COMMAND ${MRUN} --exit 2 --stderr-lines 1 --
  $<TARGET_FILE:cadmorph> mesh ${MW}/does_not_exist.step -o ${MW}/x.vtu)
add_test(NAME cli_mesh_not_step COMMAND ${MRUN} --exit 2 --stderr-lines 1 --
  $<TARGET_FILE:cadmorph> mesh ${MD}/make_fixtures.py -o ${MW}/x.vtu)
set_tests_properties(cli_mesh_bore_vtu cli_mesh_bore_msh cli_mesh_bore_vtk_gmsh cli_mesh_bore_medit cli_mesh_help
  cli_mesh_no_output cli_mesh_bad_size cli_mesh_bad_quality cli_mesh_output_is_input
  cli_mesh_no_solid cli_mesh_missing_file cli_mesh_not_step PROPERTIES LABELS "unit;cli;cad")
