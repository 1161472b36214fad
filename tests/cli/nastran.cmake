# `cadmorph` on Nastran bulk data: a new deck from `model --hex-mesh`, then quality, morph,
# warp, deform and optimize reading .bdf and writing it back (only GRID cards change).
add_test(NAME cli_nastran COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/nastran_cli.py
  $<TARGET_FILE:cadmorph> ${CM_TEST_WORK})
set_tests_properties(cli_nastran PROPERTIES LABELS "cli" TIMEOUT 300)
