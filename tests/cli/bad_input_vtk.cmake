# `cadmorph quality <broken .vtu/.vtk/.mesh>` (tests/data/vtk/bad, made by
# tests/data/vtk/generate.py from real VTK/meshio files): exit code 2 and exactly one stderr
# line that names the file and where (path:LINE or "byte offset N") and what is wrong.
#
# Run with -P this file is its own checker:
#   cmake -DCADMORPH=... -DINPUT=... -DWHERE=line|offset|none -DWHAT=regex -P bad_input_vtk.cmake
if(CMAKE_SCRIPT_MODE_FILE)
  execute_process(COMMAND ${CADMORPH} quality ${INPUT}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 2)
    message(FATAL_ERROR "exit code ${rc}, expected 2; stderr: ${err}")
  endif()
  string(REGEX MATCHALL "\n" newlines "${err}")
  list(LENGTH newlines n)
  if(NOT n EQUAL 1 OR NOT err MATCHES "\n$")
    message(FATAL_ERROR "expected exactly one stderr line, got: ${err}")
  endif()
  string(FIND "${err}" "${INPUT}" at)
  if(at LESS 0)
    message(FATAL_ERROR "stderr does not name ${INPUT}: ${err}")
  endif()
  if(WHERE STREQUAL "line" AND NOT err MATCHES ":[1-9][0-9]*: ")
    message(FATAL_ERROR "stderr has no line number: ${err}")
  elseif(WHERE STREQUAL "offset" AND NOT err MATCHES "byte offset [0-9]+")
    message(FATAL_ERROR "stderr has no byte offset: ${err}")
  endif()
  if(NOT err MATCHES "${WHAT}")
    message(FATAL_ERROR "stderr does not match '${WHAT}': ${err}")
  endif()
  return()
endif()

set(VTK_BAD ${CM_TEST_DATA}/vtk/bad)
# name; file; where; what the message says
set(VTK_BAD_CASES
  "truncated_vtu|truncated_appended.vtu|offset|truncated"
  "truncated_inline_vtu|truncated_inline.vtu|line|truncated"
  "bad_base64|bad_base64.vtu|offset|invalid base64"
  "corrupt_zlib|bad_zlib.vtu|offset|corrupt zlib"
  "wrong_npoints_vtu|wrong_npoints.vtu|line|expected 69 values"
  "node_range_vtu|node_out_of_range.vtu|line|node id 999 out of range"
  "unknown_type_vtu|unknown_type.vtu|line|cell type 99"
  "nan_vtu|nan.vtu|line|not finite"
  "node_range_vtk|node_out_of_range.vtk|line|node id 999 out of range"
  "unknown_type_vtk|unknown_type.vtk|line|cell type 99"
  "nan_vtk|nan.vtk|line|not finite"
  "truncated_vtk|truncated_binary.vtk|line|truncated"
  "truncated_mesh|truncated.mesh|line|truncated"
  "node_range_mesh|node_out_of_range.mesh|line|out of range"
  "nan_mesh|nan.mesh|line|not finite"
  "wrong_count_mesh|wrong_count.mesh|line|expected vertex coordinate"
  "unknown_extension|unknown.xyz|none|unknown mesh extension"
  "missing_file|does_not_exist.vtu|none|cannot open"
  "big_endian|../vtk_bigendian.vtu|none|BigEndian")
foreach(c IN LISTS VTK_BAD_CASES)
  string(REPLACE "|" ";" f "${c}")
  list(GET f 0 name)
  list(GET f 1 file)
  list(GET f 2 where)
  list(GET f 3 what)
  add_test(NAME cli_bad_input_vtk_${name}
    COMMAND ${CMAKE_COMMAND} -DCADMORPH=$<TARGET_FILE:cadmorph> -DINPUT=${VTK_BAD}/${file}
            -DWHERE=${where} -DWHAT=${what} -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(cli_bad_input_vtk_${name} PROPERTIES LABELS "unit;cli")
endforeach()
