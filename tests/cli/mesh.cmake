# `cadmorph mesh` on the gmsh-written bore of tests/data/models: the run, a cross-check of
# its output by VTK (scaled Jacobian) and gmsh (reads the .msh), and the error paths.
set(MD ${CM_TEST_DATA}/models)
set(MW ${CM_TEST_WORK}/mesh)
file(MAKE_DIRECTORY ${MW})

add_test(NAME cli_mesh_bore_vtu COMMAND ${CM_RUN_CLI} --exit 0 --stderr-lines 0 --last-line
  "min_scaled_jacobian=0\\.[0-9]+ mean_scaled_jacobian=0\\.[0-9]+ inverted=0 cells=[0-9]+" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/bore.vtu --size 0.3)
add_test(NAME cli_mesh_bore_msh COMMAND ${CM_RUN_CLI} --exit 0 --last-line ".* inverted=0 .*" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/bore.msh --size 0.3)
# the same with TetGen (--mesher tetgen)
add_test(NAME cli_mesh_bore_tetgen_vtu COMMAND ${CM_RUN_CLI} --exit 0 --stderr-lines 0 --last-line
  "min_scaled_jacobian=0\\.[0-9]+ mean_scaled_jacobian=0\\.[0-9]+ inverted=0 cells=[0-9]+" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/bore_tetgen.vtu --size 0.3 --mesher tetgen)
add_test(NAME cli_mesh_bore_tetgen_msh COMMAND ${CM_RUN_CLI} --exit 0 --last-line ".* inverted=0 .*" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/bore_tetgen.msh --size 0.3 --mesher tetgen)
# same options for both: both meshers are deterministic (gmsh on one thread), so gmsh's reader
# must find VTK's counts
set_tests_properties(cli_mesh_bore_vtu cli_mesh_bore_msh cli_mesh_bore_tetgen_vtu
  cli_mesh_bore_tetgen_msh PROPERTIES FIXTURES_SETUP cli_mesh_bore)
add_test(NAME cli_mesh_bore_medit COMMAND ${CM_RUN_CLI} --exit 0 --last-line ".* inverted=0 .*" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/bore.mesh --size 0.4 --quality 1.6 --threads 1)
add_test(NAME cli_mesh_bore_vtk_gmsh COMMAND ${CM_PYTHON}
  ${PROJECT_SOURCE_DIR}/tests/volume/test_tetmesh_vtk.py ${MW}/bore.vtu ${MW}/bore.msh 7)
add_test(NAME cli_mesh_bore_tetgen_vtk_gmsh COMMAND ${CM_PYTHON}
  ${PROJECT_SOURCE_DIR}/tests/volume/test_tetmesh_vtk.py ${MW}/bore_tetgen.vtu ${MW}/bore_tetgen.msh 7)
set_tests_properties(cli_mesh_bore_vtk_gmsh cli_mesh_bore_tetgen_vtk_gmsh PROPERTIES
  FIXTURES_REQUIRED cli_mesh_bore)
# TetGen's options select TetGen; with --mesher gmsh they are a usage error
add_test(NAME cli_mesh_gmsh_tetgen_option COMMAND ${CM_RUN_CLI} --exit 1
  --stderr "--quality, --min-dihedral and --preserve-surface are TetGen's: not with --mesher gmsh" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/x.vtu --mesher gmsh --quality 1.6)

add_test(NAME cli_mesh_help COMMAND ${CM_RUN_CLI} --exit 0 --last-line ".*internal error.*" --
  $<TARGET_FILE:cadmorph> mesh --help)
add_test(NAME cli_mesh_no_output COMMAND ${CM_RUN_CLI} --exit 1 --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step)
add_test(NAME cli_mesh_bad_size COMMAND ${CM_RUN_CLI} --exit 1 --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/x.vtu --size -1)
add_test(NAME cli_mesh_bad_quality COMMAND ${CM_RUN_CLI} --exit 1 --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/x.vtu --quality 0.5)
add_test(NAME cli_mesh_output_is_input COMMAND ${CM_RUN_CLI} --exit 1 --unchanged ${MD}/bore_0.step --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MD}/bore_0.step)
# the message must name the cause
add_test(NAME cli_mesh_no_solid COMMAND ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "cadmorph mesh: [^\n]*no solid" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/sheet.step -o ${MW}/sheet.vtu)
add_test(NAME cli_mesh_missing_file COMMAND ${CM_RUN_CLI} --exit 2 --stderr-lines 1 --
  $<TARGET_FILE:cadmorph> mesh ${MW}/does_not_exist.step -o ${MW}/x.vtu)
add_test(NAME cli_mesh_not_step COMMAND ${CM_RUN_CLI} --exit 2 --stderr-lines 1 --
  $<TARGET_FILE:cadmorph> mesh ${MD}/make_fixtures.py -o ${MW}/x.vtu)
# TetGen runs in a child process under a time limit: far below the work it is killed, the
# command says so in one line and writes nothing
add_test(NAME cli_mesh_time_limit COMMAND ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "cadmorph mesh: [^\n]*bore_0.step: TetGen[^\n]* did not finish in 0.05 s[^\n]*--time-limit"
  --absent ${MW}/time_limit.vtu --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/time_limit.vtu --size 0.1 --time-limit 0.05 --mesher tetgen)
add_test(NAME cli_mesh_bad_time_limit COMMAND ${CM_RUN_CLI} --exit 1 --stderr "--time-limit needs seconds > 0" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/x.vtu --time-limit 0)
add_test(NAME cli_mesh_bad_mesher COMMAND ${CM_RUN_CLI} --exit 1 --stderr "unknown mesher 'netgen'" --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/x.vtu --mesher netgen)
# gmsh as the mesher: quiet (nothing on stderr), no inverted tet, and the mesh is one that
# `cadmorph morph` classifies (every boundary node on a CAD face of G) and morphs; its time
# limit as TetGen's
set(CD ${CM_TEST_DATA}/cad)
add_test(NAME cli_mesh_gmsh COMMAND ${CM_RUN_CLI} --exit 0 --stderr-lines 0 --last-line
  "min_scaled_jacobian=0\\.[0-9]+ mean_scaled_jacobian=0\\.[0-9]+ inverted=0 cells=[0-9]+" --
  $<TARGET_FILE:cadmorph> mesh ${CD}/bore_a.step -o ${MW}/gmsh_bore_a.msh --size 0.6 --mesher gmsh)
set_tests_properties(cli_mesh_gmsh PROPERTIES FIXTURES_SETUP cli_mesh_gmsh)
add_test(NAME cli_mesh_gmsh_morph COMMAND ${CM_RUN_CLI} --exit 0 --stderr-lines 0 --last-line
  ".* inverted=0 cells=[0-9]+" --
  $<TARGET_FILE:cadmorph> morph --from ${CD}/bore_a.step --to ${CD}/bore_b.step
  --mesh ${MW}/gmsh_bore_a.msh -o ${MW}/gmsh_bore_b.vtu)
set_tests_properties(cli_mesh_gmsh_morph PROPERTIES FIXTURES_REQUIRED cli_mesh_gmsh)
add_test(NAME cli_mesh_gmsh_time_limit COMMAND ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "cadmorph mesh: [^\n]*bore_0.step: gmsh did not finish in 0.05 s"
  --absent ${MW}/gmsh_time_limit.vtu --
  $<TARGET_FILE:cadmorph> mesh ${MD}/bore_0.step -o ${MW}/gmsh_time_limit.vtu --size 0.05
  --mesher gmsh --time-limit 0.05)
set_tests_properties(cli_mesh_time_limit cli_mesh_bad_time_limit cli_mesh_bad_mesher
  cli_mesh_gmsh cli_mesh_gmsh_morph cli_mesh_gmsh_time_limit cli_mesh_gmsh_tetgen_option
  cli_mesh_bore_tetgen_vtu cli_mesh_bore_tetgen_msh cli_mesh_bore_tetgen_vtk_gmsh PROPERTIES LABELS "unit;cli;cad")
set_tests_properties(cli_mesh_bore_vtu cli_mesh_bore_msh cli_mesh_bore_vtk_gmsh cli_mesh_bore_medit cli_mesh_help
  cli_mesh_no_output cli_mesh_bad_size cli_mesh_bad_quality cli_mesh_output_is_input
  cli_mesh_no_solid cli_mesh_missing_file cli_mesh_not_step PROPERTIES LABELS "unit;cli;cad")
