# Hostile and broken input: one ctest per case of hostile.py and of the hostile_*.py scripts
# that share its frame; each case writes its input itself and checks exit code, the one
# stderr line naming the file, time and memory.
file(GLOB _hostile_scripts ${CMAKE_CURRENT_LIST_DIR}/hostile*.py)
file(MAKE_DIRECTORY ${CM_TEST_WORK}/hostile_cli)
foreach(_script IN LISTS _hostile_scripts)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${_script})
  execute_process(COMMAND ${CM_PYTHON} ${_script} list OUTPUT_VARIABLE _hostile_cases
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  string(REPLACE "\n" ";" _hostile_cases "${_hostile_cases}")
  foreach(_case IN LISTS _hostile_cases)
    add_test(NAME cli_hostile_${_case}
      COMMAND ${CM_PYTHON} ${_script} $<TARGET_FILE:cadmorph> ${CM_TEST_DATA}
              ${CM_TEST_WORK}/hostile_cli/${_case} ${_case})
    set_tests_properties(cli_hostile_${_case} PROPERTIES LABELS "cli;hostile"
      PASS_REGULAR_EXPRESSION "\nok\n" FAIL_REGULAR_EXPRESSION "FAIL:")
    if(CADMORPH_SANITIZE)
      set_tests_properties(cli_hostile_${_case} PROPERTIES ENVIRONMENT "CM_MEM_FACTOR=4;CM_TIME_FACTOR=${CM_TIME_FACTOR}")
    endif()
  endforeach()
endforeach()
