# Adaptive steps and interior optimisation through `cadmorph morph` on gmsh meshes of blocks
# with a bore (make_adaptive.py): a motion that inverts cells in one step (refused by --steps 1,
# written with --allow-inverted) reaches 100 % with --steps auto in more than one step; an easy
# one takes one step; a cell that the boundary motion itself flattens ends in exit 3 naming
# it, with or without the last valid mesh.
set(AW ${CM_TEST_WORK}/adaptive)
set(CHECK ${CM_PYTHON} ${PROJECT_SOURCE_DIR}/tests/surface/check_morph.py)
set(CLEAN "inverted=0 cells=[1-9][0-9]*\n?\\Z")
add_test(NAME adaptive_setup
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/make_adaptive.py ${CM_TEST_WORK})
set_tests_properties(adaptive_setup PROPERTIES FIXTURES_SETUP adaptive LABELS unit)

function(cm_adaptive_cli name)
  add_test(NAME ${name} COMMAND ${ARGN})
  set_tests_properties(${name} PROPERTIES LABELS cli FIXTURES_REQUIRED adaptive)
endfunction()

set(MORPH_MOVED $<TARGET_FILE:cadmorph> morph --from ${AW}/hole_0.step --to ${AW}/hole_moved.step
  --mesh ${AW}/hole_0.msh)
# the plain one-step morph (--steps 1) inverts cells: exit 3, nothing written (the default;
# --fail-on-inverted, which says so, is still accepted)
add_test(NAME adaptive_guard_clean COMMAND ${CMAKE_COMMAND} -E rm -f ${AW}/one_step.vtu
  ${AW}/one_step_default.vtu ${AW}/one_step_partial.vtu)
set_tests_properties(adaptive_guard_clean PROPERTIES FIXTURES_SETUP adaptive_guard LABELS cli)
cm_adaptive_cli(cli_morph_one_step_inverts ${CM_RUN_CLI} --exit 3 --stderr-lines 1
  --stderr "^cadmorph morph: .*step 1 of 1: the one-step morph leaves [1-9][0-9]* inverted cells"
  --absent ${AW}/one_step.vtu -- ${MORPH_MOVED} -o ${AW}/one_step.vtu --steps 1 --fail-on-inverted)
cm_adaptive_cli(cli_morph_one_step_refused ${CM_RUN_CLI} --exit 3 --stderr-lines 1
  --stderr "^cadmorph morph: .*step 1 of 1: the one-step morph leaves [1-9][0-9]* inverted cells"
  --absent ${AW}/one_step_default.vtu -- ${MORPH_MOVED} -o ${AW}/one_step_default.vtu --steps 1)
# --keep-partial: the last valid mesh of one step is M0 itself, written as such
cm_adaptive_cli(cli_morph_one_step_partial ${CM_RUN_CLI} --exit 3 --stderr-lines 1
  --stderr "^cadmorph morph: .*step 1 of 1" --stdout "${CLEAN}" --
  ${MORPH_MOVED} -o ${AW}/one_step_partial.vtu --steps 1 --keep-partial)
set_tests_properties(cli_morph_one_step_inverts cli_morph_one_step_refused
  cli_morph_one_step_partial PROPERTIES FIXTURES_REQUIRED "adaptive;adaptive_guard")
cm_adaptive_cli(cli_morph_one_step_partial_is_m0 ${CM_PYTHON}
  ${PROJECT_SOURCE_DIR}/tests/cli/compare_moved.py ${AW}/hole_0.msh ${AW}/one_step_partial.vtu
  0 diagonal)
cm_test_reads(cli_morph_one_step_partial_is_m0 cli_morph_one_step_partial)
# asked for (--allow-inverted): written, exit 0, and one warning line naming the count and the
# worst cell (the summary line alone is easy to miss)
cm_adaptive_cli(cli_morph_one_step_warns ${CM_RUN_CLI} --exit 0 --stderr-lines 1
  --stderr "^cadmorph morph: warning: [1-9][0-9]* inverted cells? \\(scaled Jacobian <= 0\\). the worst is cell [0-9]+ \\(0-based, tet4, scaled Jacobian -?[0-9.e+-]+\\) at \\("
  --stdout "inverted=[1-9][0-9]* cells=" -- ${MORPH_MOVED} -o ${AW}/one_step_warned.vtu
  --steps 1 --allow-inverted)
cm_adaptive_cli(cli_morph_auto ${CM_RUN_CLI} --exit 0 --stdout "${CLEAN}" --
  ${MORPH_MOVED} -o ${AW}/auto.vtu --steps auto --report ${AW}/auto.csv)
cm_adaptive_cli(cli_morph_auto_report ${CHECK} report ${AW}/auto.csv auto+2)
cm_test_reads(cli_morph_auto_report cli_morph_auto)
cm_adaptive_cli(cli_morph_auto_optimize ${CM_RUN_CLI} --exit 0 --stdout "${CLEAN}" --
  ${MORPH_MOVED} -o ${AW}/auto_opt.vtu --steps auto --optimize)

# easy: the surface fixture's bore edit goes in one step
add_test(NAME cli_morph_auto_easy COMMAND ${CM_RUN_CLI} --exit 0 --stdout "${CLEAN}" --
  $<TARGET_FILE:cadmorph> morph --from ${CM_TEST_DATA}/surface/hole_a.step
  --to ${CM_TEST_DATA}/surface/hole_b.step --mesh ${CM_TEST_WORK}/surface/hole_a.msh
  -o ${AW}/easy.vtu --steps auto --report ${AW}/easy.csv)
set_tests_properties(cli_morph_auto_easy PROPERTIES LABELS cli
  FIXTURES_REQUIRED "adaptive;surface_meshes")
cm_adaptive_cli(cli_morph_auto_easy_report ${CHECK} report ${AW}/easy.csv 1)
cm_test_reads(cli_morph_auto_easy_report cli_morph_auto_easy)

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
cm_test_reads(cli_morph_auto_partial_valid cli_morph_auto_partial)
cm_adaptive_cli(cli_morph_keep_partial_allow_inverted ${CM_RUN_CLI} --exit 1
  --stderr "--keep-partial .* and --allow-inverted .*: one or the other" --
  $<TARGET_FILE:cadmorph> morph --from ${AW}/tilt_0.step --to ${AW}/tilt_15.step
  --mesh ${AW}/tilt_0.msh -o ${AW}/x.vtu --keep-partial --allow-inverted)
cm_adaptive_cli(cli_morph_fail_on_inverted_allow_inverted ${CM_RUN_CLI} --exit 1
  --stderr "--fail-on-inverted and --allow-inverted contradict" --
  $<TARGET_FILE:cadmorph> morph --from ${AW}/tilt_0.step --to ${AW}/tilt_15.step
  --mesh ${AW}/tilt_0.msh -o ${AW}/x.vtu --fail-on-inverted --allow-inverted)
