# `cadmorph warp` end to end on the gmsh sphere-in-box mesh (fixture warp_sphere from
# tests/volume/warp.cmake, which also writes it as .vtu and .mesh with meshio), its error
# paths (exit 2 with file:line, one stderr line) and the refusal to overwrite an input.
set(W ${CM_TEST_WORK}/warp)
set(WD ${CM_TEST_DATA}/warp)
set(SUMMARY "^min_scaled_jacobian=[-+0-9.e]+ mean_scaled_jacobian=[-+0-9.e]+ inverted=0 cells=[1-9][0-9]*\n?\\Z")

function(cm_warp_cli_test name)
  add_test(NAME ${name} COMMAND ${ARGN})
  set_tests_properties(${name} PROPERTIES LABELS "cli" FIXTURES_REQUIRED warp_sphere)
endfunction()

# the three input formats, different output formats; the summary line ends stdout
cm_warp_cli_test(cli_warp_msh ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
  $<TARGET_FILE:cadmorph> warp --mesh ${W}/sphere.msh --displacements ${W}/sphere_disp.csv
  -o ${W}/cli_from_msh.vtu)
cm_warp_cli_test(cli_warp_vtu ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
  $<TARGET_FILE:cadmorph> warp --mesh ${W}/sphere.vtu --displacements ${W}/sphere_disp.csv
  -o ${W}/cli_from_vtu.msh --threads 1)
cm_warp_cli_test(cli_warp_medit ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
  $<TARGET_FILE:cadmorph> warp --mesh ${W}/sphere.mesh --displacements ${W}/sphere_disp.csv
  -o ${W}/cli_from_medit.vtk --kernel biharmonic)
# the written mesh: nodes moved by its displacement field, sphere nodes exactly as listed
add_test(NAME cli_warp_output
  COMMAND ${CM_PYTHON} ${PROJECT_SOURCE_DIR}/tests/volume/warp_sphere.py check ${CM_TEST_WORK}
          cli_from_msh.vtu cli_from_vtu.msh cli_from_medit.vtk)
set_tests_properties(cli_warp_output PROPERTIES LABELS "cli" FIXTURES_REQUIRED warp_sphere)
cm_test_reads(cli_warp_output cli_warp_msh cli_warp_vtu cli_warp_medit)

# bad tables: exit 2, one stderr line naming file:line, no output written
foreach(case header:1 columns:3 number:2 node:4 range:3 duplicate:4 nan:2 inf:3)
  string(REPLACE ":" ";" parts ${case})
  list(GET parts 0 what)
  list(GET parts 1 line)
  cm_warp_cli_test(cli_warp_bad_${what} ${CM_RUN_CLI} --exit 2 --stderr-lines 1
    --stderr "^cadmorph warp: .*bad_${what}\\.csv:${line}: " --absent ${W}/cli_bad_${what}.vtu --
    $<TARGET_FILE:cadmorph> warp --mesh ${W}/sphere.msh --displacements ${WD}/bad_${what}.csv
    -o ${W}/cli_bad_${what}.vtu)
endforeach()
# a component whose boundary is flat: exit 2, the component named
cm_warp_cli_test(cli_warp_flat ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "^cadmorph warp: .*flat\\.vtk: .*component 0" --
  $<TARGET_FILE:cadmorph> warp --mesh ${WD}/flat.vtk --displacements ${WD}/none.csv
  -o ${W}/cli_flat.vtu)
# inverted cells: exit 0 (the mesh is written) with one warning line naming the count and the
# worst cell: corner 0 of the unit cube pushed past the centre inverts the 6 tets around it,
# the worst (cell 5, SJ -0.192587) is the summary's minimum; none on the unmoved cube
cm_warp_cli_test(cli_warp_inverted_warns ${CM_RUN_CLI} --exit 0 --stderr-lines 1
  --stderr "^cadmorph warp: warning: 6 inverted cells \\(scaled Jacobian <= 0\\). the worst is cell 5 \\(0-based, tet4, scaled Jacobian -0\\.192587\\) at \\(0\\.825, 0\\.575, 1\\.075\\)"
  --last-line "min_scaled_jacobian=-0\\.192587 .* inverted=6 cells=12" --
  $<TARGET_FILE:cadmorph> warp --mesh ${WD}/cube.vtk --displacements ${WD}/invert.csv
  -o ${W}/cli_inverted.vtu)
cm_warp_cli_test(cli_warp_no_inverted_no_warning ${CM_RUN_CLI} --exit 0 --stderr-lines 0
  --last-line "min_scaled_jacobian=0\\.57735 .* inverted=0 cells=12" --
  $<TARGET_FILE:cadmorph> warp --mesh ${WD}/cube.vtk --displacements ${WD}/none.csv
  -o ${W}/cli_not_inverted.vtu)
# output equal to the input: usage error, the input untouched
cm_warp_cli_test(cli_warp_same_file ${CM_RUN_CLI} --exit 1 --stderr "is an input"
  --unchanged ${W}/sphere.vtu --
  $<TARGET_FILE:cadmorph> warp --mesh ${W}/sphere.vtu --displacements ${W}/sphere_disp.csv
  -o ${W}/../warp/sphere.vtu)
cm_warp_cli_test(cli_warp_help ${CM_RUN_CLI} --exit 0
  --stdout "listed interior nodes are pinned to their displacement" --
  $<TARGET_FILE:cadmorph> warp --help)
cm_warp_cli_test(cli_warp_usage ${CM_RUN_CLI} --exit 1 --stderr "--displacements is required" --
  $<TARGET_FILE:cadmorph> warp --mesh ${W}/sphere.msh -o ${W}/cli_usage.vtu)
cm_warp_cli_test(cli_warp_kernel ${CM_RUN_CLI} --exit 1 --stderr "unknown kernel" --
  $<TARGET_FILE:cadmorph> warp --mesh ${W}/sphere.msh --displacements ${W}/sphere_disp.csv
  -o ${W}/cli_kernel.vtu --kernel gaussian)
