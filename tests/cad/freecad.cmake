# Parts made by FreeCAD 0.20 (tests/data/freecad/make_parts.py; benchmarks/RESULTS.md, FreeCAD-made parts): an L bracket whose
# shoulder annulus (boss radius 6, outer radius 14) is edited to 8 (bracket_2, 4x narrower) and
# FreeCAD's own re-export of it (bracket_re). Pins what worked on them: the re-export corresponds
# and leaves every node in place; and what failed: one step of the 4x compression inverts
# interior cells (a warning on stderr); no step length of --steps auto saves the cell (every
# full step inverts the same interior cell), so it escalates to interior optimisation, which
# lifts it (as --steps auto --optimize does from the start).
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
add_test(NAME cad_cli_freecad_shoulder_one_step COMMAND ${CM_RUN_CLI} --exit 0
         --stderr "warning: [1-9][0-9]* inverted cells? \\(scaled Jacobian <= 0\\); the worst is cell" --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_1.vtu --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_one_step PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_mesh)
# --steps auto alone: no step length saves the squeezed interior cell, so the rest of the
# motion is morphed with interior optimisation (a warning); --no-escalate keeps the refusal
add_test(NAME cad_cli_freecad_shoulder_auto COMMAND ${CM_RUN_CLI} --exit 0
         --stderr "no step down to .* is valid without interior optimisation .*the rest is morphed with it"
         --stdout "inverted=0 cells=[1-9]" --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_a.vtu --steps auto --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_auto PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_mesh)
add_test(NAME cad_cli_freecad_shoulder_no_escalate COMMAND ${CM_RUN_CLI} --exit 3
         --stderr "no valid step: .*--optimize. may lift them" --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_n.vtu --steps auto --no-escalate
         --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_no_escalate PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_mesh)
add_test(NAME cad_cli_freecad_shoulder_optimize COMMAND ${CM_RUN_CLI} --exit 0 --stdout "inverted=0 cells=[1-9]" --
         $<TARGET_FILE:cadmorph> morph --from ${FC_DATA}/bracket_0.step --to ${FC_DATA}/bracket_2.step
         --mesh ${FC_WORK}/bracket_0.msh -o ${FC_WORK}/bracket_2_o.vtu --steps auto --optimize
         --fail-on-inverted --threads 1)
set_tests_properties(cad_cli_freecad_shoulder_optimize PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_freecad_mesh)
