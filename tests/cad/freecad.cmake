# Parts made by FreeCAD 0.20 (tests/data/freecad/make_parts.py; benchmarks/RESULTS.md, FreeCAD-made parts): an L bracket whose
# shoulder annulus (boss radius 6, outer radius 14) is edited to 8 (bracket_2, 4x narrower) and
# FreeCAD's own re-export of it (bracket_re). Pins what worked on them: the re-export corresponds
# and leaves every node in place; and what failed: one step of the 4x compression inverts
# interior cells (refused unless --allow-inverted); no step length of the default adaptive
# steps saves the cell (every full step inverts the same interior cell), so it escalates to
# interior optimisation, which lifts it (as --steps auto --optimize does from the start).
set(FC_DATA ${PROJECT_SOURCE_DIR}/tests/data/freecad)
set(FC_WORK ${CM_TEST_WORK}/freecad)
file(MAKE_DIRECTORY ${FC_WORK})
add_test(NAME cad_cli_freecad_mesh COMMAND ${CM_RUN_CLI} --exit 0 --stdout "inverted=0 cells=[1-9]" --
         $<TARGET_FILE:cadmorph> mesh ${FC_DATA}/bracket_0.step -o ${FC_WORK}/bracket_0.msh
         --mesher gmsh --threads 1)
set_tests_properties(cad_cli_freecad_mesh PROPERTIES LABELS "cad;cli" FIXTURES_SETUP cad_freecad_mesh)
add_test(NAME cad_cli_freecad_reexport_compare COMMAND ${CM_RUN_CLI} --exit 0
         --stdout "corresponds to .*bracket_0.step: 13 faces, 27 edges, 18 vertices" --
         $<TARGET_FILE:cadmorph> info ${FC_DATA}/bracket_0.step --compare ${FC_DATA}/bracket_re.step)
set_tests_properties(cad_cli_freecad_reexport_compare PROPERTIES LABELS "cad;cli")
add_test(NAME cad_cli_freecad_reexport_morph COMMAND ${CM_RUN_CLI} --exit 0 --stdout "inverted=0" --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_re.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_re.vtu --threads 1)
set_tests_properties(cad_cli_freecad_reexport_morph PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_mesh FIXTURES_SETUP cad_freecad_re)
add_test(NAME cad_cli_freecad_reexport_in_place COMMAND ${CM_PYTHON}
         ${PROJECT_SOURCE_DIR}/tests/cli/compare_moved.py ${FC_WORK}/bracket_0.msh
         ${FC_WORK}/bracket_re.vtu 1e-9 diagonal)
set_tests_properties(cad_cli_freecad_reexport_in_place PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_re)
# the outputs that a refused morph must not write, removed before the runs that check it
add_test(NAME cad_cli_freecad_guard_clean COMMAND ${CMAKE_COMMAND} -E rm -f
         ${FC_WORK}/bracket_2_1.vtu ${FC_WORK}/bracket_2_1.csv ${FC_WORK}/bracket_2_n.vtu
         ${FC_WORK}/bracket_2_allowed.vtu)
set_tests_properties(cad_cli_freecad_guard_clean PROPERTIES LABELS "cad;cli"
                     FIXTURES_SETUP cad_freecad_guard)
# the plain one-step morph (--steps 1) inverts interior cells: exit 3, nothing written, the
# report written with the rejected row naming them
add_test(NAME cad_cli_freecad_shoulder_one_step COMMAND ${CM_RUN_CLI} --exit 3 --stderr-lines 1
         --stderr "^cadmorph morph: .*step 1 of 1: the one-step morph leaves [1-9][0-9]* inverted cells \\(worst: cell [0-9]+ at .*--allow-inverted keeps them"
         --absent ${FC_WORK}/bracket_2_1.vtu --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_1.vtu --steps 1
         --report ${FC_WORK}/bracket_2_1.csv --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_one_step PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED "cad_freecad_mesh;cad_freecad_guard")
add_test(NAME cad_cli_freecad_shoulder_one_step_report COMMAND ${CM_PYTHON}
         ${PROJECT_SOURCE_DIR}/tests/surface/check_morph.py report ${FC_WORK}/bracket_2_1.csv rejected)
set_tests_properties(cad_cli_freecad_shoulder_one_step_report PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_guard)
cm_test_reads(cad_cli_freecad_shoulder_one_step_report cad_cli_freecad_shoulder_one_step)
# asked for: --allow-inverted writes the inverted mesh, exit 0 with the warning naming them
add_test(NAME cad_cli_freecad_shoulder_one_step_allowed COMMAND ${CM_RUN_CLI} --exit 0
         --stderr "warning: [1-9][0-9]* inverted cells? \\(scaled Jacobian <= 0\\); the worst is cell"
         --stdout "inverted=[1-9][0-9]* cells=" --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_allowed.vtu --steps 1
         --allow-inverted --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_one_step_allowed PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED "cad_freecad_mesh;cad_freecad_guard")
add_test(NAME cad_cli_freecad_shoulder_one_step_allowed_written COMMAND ${CM_RUN_CLI} --exit 0
         --stdout "inverted=[1-9][0-9]* cells=" --
         $<TARGET_FILE:cadmorph> quality ${FC_WORK}/bracket_2_allowed.vtu)
set_tests_properties(cad_cli_freecad_shoulder_one_step_allowed_written PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_guard)
cm_test_reads(cad_cli_freecad_shoulder_one_step_allowed_written
              cad_cli_freecad_shoulder_one_step_allowed)
# the default (--steps auto): no step length saves the squeezed interior cell, so the rest of
# the motion is morphed with interior optimisation (a warning) and the mesh is valid;
# --no-escalate keeps the refusal: exit 3, nothing written
add_test(NAME cad_cli_freecad_shoulder_auto COMMAND ${CM_RUN_CLI} --exit 0
         --stderr "no step down to .* is valid without interior optimisation .*the rest is morphed with it"
         --stdout "inverted=0 cells=[1-9]" --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_a.vtu --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_auto PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_mesh)
add_test(NAME cad_cli_freecad_shoulder_no_escalate COMMAND ${CM_RUN_CLI} --exit 3
         --stderr "no valid step: .*--optimize. may lift them" --absent ${FC_WORK}/bracket_2_n.vtu --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_n.vtu --no-escalate
         --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_no_escalate PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED "cad_freecad_mesh;cad_freecad_guard")
# --allow-inverted with adaptive steps: where no step is valid the rest goes in one step,
# written with its inverted cells and both warnings (why, and which cells)
add_test(NAME cad_cli_freecad_shoulder_auto_allowed COMMAND ${CM_RUN_CLI} --exit 0
         --stderr "no step is valid; inverted cells are allowed, so the rest was morphed in one step [(][1-9][0-9]* inverted"
         --stderr "warning: [1-9][0-9]* inverted cells? \\(scaled Jacobian <= 0\\); the worst is cell"
         --stdout "inverted=[1-9][0-9]* cells=" --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_na.vtu --no-escalate
         --allow-inverted --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_auto_allowed PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_mesh)
add_test(NAME cad_cli_freecad_shoulder_optimize COMMAND ${CM_RUN_CLI} --exit 0 --stdout "inverted=0 cells=[1-9]" --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_o.vtu --steps auto --optimize
         --fail-on-inverted --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_optimize PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_mesh)
# a study of the bracket's re-export and its shoulder edit: with the plain one-step morph the
# edit's row is refused (no mesh) while the re-export's mesh is written, and the study exits 3
# at the end; --allow-inverted keeps the inverted result; the default (adaptive steps with the
# escalation) makes both valid
set(FC_STUDY $<TARGET_FILE:cadmorph> study --from ${FC_DATA}/bracket_0.step
    --mesh ${FC_WORK}/bracket_0.msh --variants ${FC_DATA}/bracket_[2r]*.step --threads 1)
set(FC_GUARD ${CM_PYTHON} ${PROJECT_SOURCE_DIR}/tests/study/check_guard.py)
add_test(NAME cad_cli_freecad_study_one_step COMMAND ${FC_GUARD} --dir ${FC_WORK}/study_1
         --exit 3 --ok bracket_re --failed bracket_2 -- ${FC_STUDY} -o ${FC_WORK}/study_1 --steps 1)
add_test(NAME cad_cli_freecad_study_one_step_allowed COMMAND ${FC_GUARD} --dir ${FC_WORK}/study_1a
         --exit 0 --ok bracket_re --inverted bracket_2 --
         ${FC_STUDY} -o ${FC_WORK}/study_1a --steps 1 --allow-inverted)
add_test(NAME cad_cli_freecad_study_default COMMAND ${FC_GUARD} --dir ${FC_WORK}/study_auto
         --exit 0 --ok bracket_re,bracket_2 -- ${FC_STUDY} -o ${FC_WORK}/study_auto)
set_tests_properties(cad_cli_freecad_study_one_step cad_cli_freecad_study_one_step_allowed
                     cad_cli_freecad_study_default PROPERTIES LABELS "cad;cli;study"
                     FIXTURES_REQUIRED cad_freecad_mesh)
