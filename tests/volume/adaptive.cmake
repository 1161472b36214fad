# Adaptive steps and interior optimisation through `cadmorph morph` on gmsh meshes of blocks
# with a bore (make_adaptive.py): a motion that inverts cells in one step reaches 100 % with
# --steps auto in more than one step; an easy one takes one step; a cell that the boundary
# motion itself flattens ends in exit 3 naming it, with or without the last valid mesh.
set(AW ${CM_TEST_WORK}/adaptive)
set(CHECK ${CM_PYTHON} ${PROJECT_SOURCE_DIR}/tests/surface/check_morph.py)
set(CLEAN "inverted=0 cells=[1-9][0-9]*\n?\\Z")
add_test(NAME adaptive_setup
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/make_adaptive.py ${CM_TEST_WORK})
set_tests_properties(adaptive_setup PROPERTIES FIXTURES_SETUP adaptive LABELS "unit;volume")

function(cm_adaptive_cli name)
  add_test(NAME ${name} COMMAND ${ARGN})
  set_tests_properties(${name} PROPERTIES LABELS "cli;volume" FIXTURES_REQUIRED adaptive)
endfunction()

set(MORPH_MOVED $<TARGET_FILE:cadmorph> morph --from ${AW}/hole_0.step --to ${AW}/hole_moved.step
  --mesh ${AW}/hole_0.msh)
cm_adaptive_cli(cli_morph_one_step_inverts ${CM_RUN_CLI} --exit 3 --stderr "inverted cells" --
  ${MORPH_MOVED} -o ${AW}/one_step.vtu --fail-on-inverted)
# the same without --fail-on-inverted: written, exit 0, and one warning line naming the count
# and the worst cell (the summary line alone is easy to miss)
cm_adaptive_cli(cli_morph_one_step_warns ${CM_RUN_CLI} --exit 0 --stderr-lines 1
  --stderr "^cadmorph morph: warning: [1-9][0-9]* inverted cells? \\(scaled Jacobian <= 0\\). the worst is cell [0-9]+ \\(0-based, tet4, scaled Jacobian -?[0-9.e+-]+\\) at \\("
  --stdout "inverted=[1-9][0-9]* cells=" -- ${MORPH_MOVED} -o ${AW}/one_step_warned.vtu)
cm_adaptive_cli(cli_morph_auto ${CM_RUN_CLI} --exit 0 --stdout "${CLEAN}" --
  ${MORPH_MOVED} -o ${AW}/auto.vtu --steps auto --report ${AW}/auto.csv)
cm_adaptive_cli(cli_morph_auto_report ${CHECK} report ${AW}/auto.csv auto+2)
set_tests_properties(cli_morph_auto_report PROPERTIES DEPENDS cli_morph_auto)
cm_adaptive_cli(cli_morph_auto_optimize ${CM_RUN_CLI} --exit 0 --stdout "${CLEAN}" --
  ${MORPH_MOVED} -o ${AW}/auto_opt.vtu --steps auto --optimize)

# easy: the surface fixture's bore edit goes in one step
add_test(NAME cli_morph_auto_easy COMMAND ${CM_RUN_CLI} --exit 0 --stdout "${CLEAN}" --
  $<TARGET_FILE:cadmorph> morph --from ${CM_TEST_DATA}/surface/hole_a.step
  --to ${CM_TEST_DATA}/surface/hole_b.step --mesh ${CM_TEST_WORK}/surface/hole_a.msh
  -o ${AW}/easy.vtu --steps auto --report ${AW}/easy.csv)
set_tests_properties(cli_morph_auto_easy PROPERTIES LABELS "cli;volume"
  FIXTURES_REQUIRED "adaptive;surface_meshes")
cm_adaptive_cli(cli_morph_auto_easy_report ${CHECK} report ${AW}/easy.csv 1)
set_tests_properties(cli_morph_auto_easy_report PROPERTIES DEPENDS cli_morph_auto_easy)

# forced by the boundary: exit 3, the worst cell named, nothing written; --keep-partial writes
# the last valid mesh (no inverted cell) and the report has the rejected steps
set(MORPH_TILT $<TARGET_FILE:cadmorph> morph --from ${AW}/tilt_0.step --to ${AW}/tilt_15.step
  --mesh ${AW}/tilt_0.msh --steps auto --optimize --min-step 0.03)
cm_adaptive_cli(cli_morph_auto_rejected ${CM_RUN_CLI} --exit 3 --stderr-lines 1
  --stderr "^cadmorph morph: .*no valid step: from [0-9.]+ % of the motion .*worst: cell [0-9]+ at \\("
  --absent ${AW}/rejected.vtu -- ${MORPH_TILT} -o ${AW}/rejected.vtu)
cm_adaptive_cli(cli_morph_auto_partial ${CM_RUN_CLI} --exit 3 --stderr "no valid step" --
  ${MORPH_TILT} -o ${AW}/partial.vtu --keep-partial --report ${AW}/partial.csv)
cm_adaptive_cli(cli_morph_auto_partial_valid ${CM_RUN_CLI} --exit 0 --stdout "${CLEAN}" --
  $<TARGET_FILE:cadmorph> quality ${AW}/partial.vtu)
set_tests_properties(cli_morph_auto_partial_valid PROPERTIES DEPENDS cli_morph_auto_partial)
cm_adaptive_cli(cli_morph_keep_partial_alone ${CM_RUN_CLI} --exit 1 --stderr "--keep-partial goes with" --
  $<TARGET_FILE:cadmorph> morph --from ${AW}/tilt_0.step --to ${AW}/tilt_15.step
  --mesh ${AW}/tilt_0.msh -o ${AW}/x.vtu --keep-partial)
