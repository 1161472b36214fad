# Hostile and broken input: one ctest per case of hostile.py, which writes each
# input itself and checks exit code, the one stderr line naming the file, time and memory.
set(_hostile_py ${CMAKE_CURRENT_LIST_DIR}/hostile.py)
execute_process(COMMAND ${CM_PYTHON} ${_hostile_py} list OUTPUT_VARIABLE _hostile_cases
                OUTPUT_STRIP_TRAILING_WHITESPACE)
string(REPLACE "\n" ";" _hostile_cases "${_hostile_cases}")
file(MAKE_DIRECTORY ${CM_TEST_WORK}/hostile_cli)
foreach(_case IN LISTS _hostile_cases)
  add_test(NAME cli_hostile_${_case}
    COMMAND ${CM_PYTHON} ${_hostile_py} $<TARGET_FILE:cadmorph> ${CM_TEST_DATA}
            ${CM_TEST_WORK}/hostile_cli/${_case} ${_case})
  set_tests_properties(cli_hostile_${_case} PROPERTIES LABELS "cli;hostile"
    PASS_REGULAR_EXPRESSION "\nok\n" FAIL_REGULAR_EXPRESSION "FAIL:")
  if(CADMORPH_SANITIZE)
    set_tests_properties(cli_hostile_${_case} PROPERTIES ENVIRONMENT "CM_MEM_FACTOR=4")
  endif()
endforeach()
