# `cadmorph quality` on the fixtures of tests/data/quality (made by make_fixture.py with gmsh
# and meshio; the expected numbers are VTK's vtkMeshQuality values that the script prints),
# its CSV output and its error paths.
set(QD ${CM_TEST_DATA}/quality)
set(QW ${CM_TEST_WORK}/quality)
file(MAKE_DIRECTORY ${QW})
# a truncated gmsh file: bad input, exit 2
file(WRITE ${QW}/truncated.msh "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n")

add_test(NAME cli_quality_box COMMAND ${CM_RUN_CLI} --exit 0 --stdout
  "\ntet4 +968 [^\n]*\nmin_scaled_jacobian=-0\\.662871 mean_scaled_jacobian=0\\.594018 inverted=1 cells=968\n\\Z" --
  $<TARGET_FILE:cadmorph> quality ${QD}/box_tets.vtu)
set_tests_properties(cli_quality_box PROPERTIES LABELS "unit;cli")
# hex, wedge and pyramid through the reader (meshio wrote the wedge in VTK's order);
# hex 1, pyramid of height 1/2 on a unit square sqrt(2/3), wedge 0.755929 (Verdict)
add_test(NAME cli_quality_mixed COMMAND ${CM_RUN_CLI} --exit 0 --last-line
  "min_scaled_jacobian=0\\.755929 mean_scaled_jacobian=0\\.857475 inverted=0 cells=3" --
  $<TARGET_FILE:cadmorph> quality ${QD}/mixed.vtu --threads 1)
add_test(NAME cli_quality_csv COMMAND ${CM_RUN_CLI} --exit 0 --csv ${QW}/box.csv 968
  --last-line "min_scaled_jacobian=-0\\.662871 mean_scaled_jacobian=0\\.594018 inverted=1 cells=968" --
  $<TARGET_FILE:cadmorph> quality ${QD}/box_tets.vtu --csv ${QW}/box.csv --threads 2)
add_test(NAME cli_quality_help COMMAND ${CM_RUN_CLI} --exit 0 --last-line ".*help.*" --
  $<TARGET_FILE:cadmorph> quality --help)
add_test(NAME cli_quality_missing_arg COMMAND ${CM_RUN_CLI} --exit 1 --
  $<TARGET_FILE:cadmorph> quality)
add_test(NAME cli_quality_bad_option COMMAND ${CM_RUN_CLI} --exit 1 --
  $<TARGET_FILE:cadmorph> quality ${QD}/box_tets.vtu --threads zero)
add_test(NAME cli_quality_no_file COMMAND ${CM_RUN_CLI} --exit 2 --stderr-lines 1 --
  $<TARGET_FILE:cadmorph> quality ${QW}/does_not_exist.vtu)
add_test(NAME cli_quality_truncated COMMAND ${CM_RUN_CLI} --exit 2 --stderr-lines 1 --
  $<TARGET_FILE:cadmorph> quality ${QW}/truncated.msh)
add_test(NAME cli_quality_csv_is_input COMMAND ${CM_RUN_CLI} --exit 1 --unchanged ${QD}/mixed.vtu --
  $<TARGET_FILE:cadmorph> quality ${QD}/mixed.vtu --csv ${QD}/mixed.vtu)
set_tests_properties(cli_quality_mixed cli_quality_csv cli_quality_help cli_quality_missing_arg
  cli_quality_bad_option cli_quality_no_file cli_quality_truncated cli_quality_csv_is_input
  PROPERTIES LABELS "unit;cli")
# gmsh's own hybrid mesh (hexes, prisms, pyramids, tets, second order) is valid: a reader
# that keeps gmsh's prism winding reports every prism inverted.
add_test(NAME cli_quality_gmsh_hybrid COMMAND ${CM_RUN_CLI} --exit 0 --last-line
  "min_scaled_jacobian=0\\.[0-9]+ mean_scaled_jacobian=0\\.[0-9]+ inverted=0 cells=146" --
  $<TARGET_FILE:cadmorph> quality ${CM_TEST_DATA}/msh/hybrid_o2_41.msh)
set_tests_properties(cli_quality_gmsh_hybrid PROPERTIES LABELS "unit;cli")
