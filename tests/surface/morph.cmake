# The morph pipeline: the library end to end (test_morph) and `cadmorph morph` on the gmsh
# meshes of fixture surface_meshes (surface.cmake): outputs checked by gmsh's own closest
# point on G1 and meshio (check_morph.py), the report, and the error paths (exit codes, one
# stderr line each, nothing written).
cm_add_unit_test(test_morph test_morph.c LIBS cm_morph LABELS cad)
set_tests_properties(test_morph PROPERTIES FIXTURES_REQUIRED surface_meshes)

set(SD ${CM_TEST_DATA}/surface)
set(SW ${CM_TEST_WORK}/surface)
set(CHECK ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/check_morph.py)
set(SUMMARY "^min_scaled_jacobian=[-+0-9.e]+ mean_scaled_jacobian=[-+0-9.e]+ inverted=0 cells=[1-9][0-9]*\n?\\Z")

function(cm_morph_cli name)
  add_test(NAME ${name} COMMAND ${ARGN})
  set_tests_properties(${name} PROPERTIES LABELS "cli;cad" FIXTURES_REQUIRED surface_meshes)
endfunction()

# each edit, one output format each; then gmsh measures the distance of the boundary to G1
foreach(case hole:vtu holes2:msh cyl:vtk sphere:vtu cone:mesh torus:msh)
  string(REPLACE ":" ";" parts ${case})
  list(GET parts 0 m)
  list(GET parts 1 ext)
  cm_morph_cli(cli_morph_${m} ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
    $<TARGET_FILE:cadmorph> morph --from ${SD}/${m}_a.step --to ${SD}/${m}_b.step
    --mesh ${SW}/${m}_a.msh -o ${SW}/cli_${m}.${ext} --fail-on-inverted)
  cm_morph_cli(cli_morph_${m}_on_g1 ${CHECK} ongeom ${SW}/${m}_a.msh ${SW}/cli_${m}.${ext}
    ${SD}/${m}_b.step 1e-9)
  cm_test_reads(cli_morph_${m}_on_g1 cli_morph_${m})
endforeach()

# second order: mid-edge nodes are boundary nodes too
cm_morph_cli(cli_morph_cyl_o2 ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/cyl_a.step --to ${SD}/cyl_b.step
  --mesh ${SW}/cyl_a_o2.msh -o ${SW}/cli_cyl_o2.vtu)
cm_morph_cli(cli_morph_cyl_o2_on_g1 ${CHECK} ongeom ${SW}/cyl_a_o2.msh ${SW}/cli_cyl_o2.vtu
  ${SD}/cyl_b.step 1e-9)
cm_test_reads(cli_morph_cyl_o2_on_g1 cli_morph_cyl_o2)

# increments, the other kernel, a report with one row per step
cm_morph_cli(cli_morph_steps ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/cli_steps.msh --steps 3 --kernel biharmonic --threads 1
  --report ${SW}/cli_steps.csv)
cm_morph_cli(cli_morph_steps_report ${CHECK} report ${SW}/cli_steps.csv 3)
cm_test_reads(cli_morph_steps_report cli_morph_steps)

# the baseline inverts cells on the bore edit in one step: exit 3, nothing written
cm_morph_cli(cli_morph_fail_on_inverted ${CM_RUN_CLI} --exit 3 --stderr-lines 1
  --stderr "^cadmorph morph: .*step 1 of 1: the one-step morph leaves [0-9]+ inverted cells"
  --absent ${SW}/cli_rejected.vtu --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/cli_rejected.vtu --surface project --steps 1)

# bad input: exit 2, one line saying what
cm_morph_cli(cli_morph_topology ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "^cadmorph morph: .*hole_a.step and .*holes2_a.step do not correspond: .*faces: 7 in G, 8 in G'"
  --absent ${SW}/cli_bad1.vtu --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/holes2_a.step
  --mesh ${SW}/hole_a.msh -o ${SW}/cli_bad1.vtu)
cm_morph_cli(cli_morph_other_model ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "^cadmorph morph: .*cyl_a.msh is not a mesh of .*hole_a.step: .*boundary nodes are off the CAD model \\(worst: node [0-9]+ at distance"
  --absent ${SW}/cli_bad2.vtu --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/cyl_a.msh -o ${SW}/cli_bad2.vtu)
cm_morph_cli(cli_morph_unit ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "^cadmorph morph: .*hole_a_metres.msh is not a mesh of .*1000x smaller than the model: a unit mismatch"
  --absent ${SW}/cli_bad3.vtu --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a_metres.msh -o ${SW}/cli_bad3.vtu)
# the mesh in metres against the model in millimetres with --off-cad fixed: the run ends on the
# contact error, and stderr has that one line (the sampling warned about its cap twice before,
# once for G and once for G')
cm_morph_cli(cli_morph_unit_once ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "^cadmorph morph: .*touches the fixed surface off it" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a_metres.msh -o ${SW}/cli_unit_once.vtu --off-cad fixed)
cm_morph_cli(cli_morph_unit_fixed ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a_metres.msh -o ${SW}/cli_metres.vtu --cad-unit m)
cm_morph_cli(cli_morph_missing ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "^cadmorph morph: .*no_such.step" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/no_such.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/cli_bad4.vtu)
# usage: output equal to an input (left untouched), missing option, bad value
cm_morph_cli(cli_morph_same_output ${CM_RUN_CLI} --exit 1 --stderr "is an input: refusing"
  --unchanged ${SW}/hole_a.msh --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/hole_a.msh)
cm_morph_cli(cli_morph_usage ${CM_RUN_CLI} --exit 1 --stderr "--to is required" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --mesh ${SW}/hole_a.msh -o ${SW}/x.vtu)
cm_morph_cli(cli_morph_bad_surface ${CM_RUN_CLI} --exit 1 --stderr "unknown surface method" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/x.vtu --surface nearest)

# the warp method by name, and a relative morph through an intermediate geometry
cm_morph_cli(cli_morph_method ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/cli_method.vtu --method rbf-biharmonic)
cm_morph_cli(cli_morph_bad_method ${CM_RUN_CLI} --exit 1 --stderr "unknown method 'nearest' \\(rbf" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/x.vtu --method nearest)
cm_morph_cli(cli_morph_via ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_a.step
  --mesh ${SW}/hole_a.msh -o ${SW}/cli_via.vtu --relative --via ${SD}/hole_b.step
  --steps 2 --report ${SW}/cli_via.csv)
cm_morph_cli(cli_morph_via_report ${CHECK} report ${SW}/cli_via.csv 4)
cm_test_reads(cli_morph_via_report cli_morph_via)
cm_morph_cli(cli_morph_via_topology ${CM_RUN_CLI} --exit 2 --stderr-lines 1
  --stderr "^cadmorph morph: .*hole_b.step and .*holes2_a.step do not correspond"
  --absent ${SW}/cli_bad5.vtu --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/cli_bad5.vtu --relative --via ${SD}/hole_b.step,${SD}/holes2_a.step)
cm_morph_cli(cli_morph_via_alone ${CM_RUN_CLI} --exit 1 --stderr "--via needs --relative" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/x.vtu --via ${SD}/hole_b.step)

# the RBF solver by name: the iterative solver's morph passes the same checks as the dense one
cm_morph_cli(cli_morph_solver_iterative ${CM_RUN_CLI} --exit 0 --stdout "${SUMMARY}" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/cli_solver.vtu --solver iterative)
cm_morph_cli(cli_morph_solver_on_g1 ${CHECK} ongeom ${SW}/hole_a.msh ${SW}/cli_solver.vtu
  ${SD}/hole_b.step 1e-9)
cm_test_reads(cli_morph_solver_on_g1 cli_morph_solver_iterative)
cm_morph_cli(cli_morph_bad_solver ${CM_RUN_CLI} --exit 1 --stderr "unknown solver 'fast'" --
  $<TARGET_FILE:cadmorph> morph --from ${SD}/hole_a.step --to ${SD}/hole_b.step
  --mesh ${SW}/hole_a.msh -o ${SW}/x.vtu --solver fast)
