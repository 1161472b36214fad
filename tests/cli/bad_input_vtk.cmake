# `cadmorph quality <broken .vtu/.vtk/.mesh>` (tests/data/vtk/bad, made by
# tests/data/vtk/generate.py from real VTK/meshio files): exit code 2 and exactly one stderr
# line (ending in a newline) that names the file and where (path:LINE or "byte offset N") and
# what is wrong.

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
  set(where_rx)
  if(where STREQUAL "line")
    set(where_rx --stderr ":[1-9][0-9]*: ")
  elseif(where STREQUAL "offset")
    set(where_rx --stderr "byte offset [0-9]+")
  endif()
  add_test(NAME cli_bad_input_vtk_${name}
    COMMAND ${CM_RUN_CLI} --exit 2 --stderr-lines 1 --stderr "\n\\Z"
            --stderr-has ${VTK_BAD}/${file} ${where_rx} --stderr "${what}" --
            $<TARGET_FILE:cadmorph> quality ${VTK_BAD}/${file})
  set_tests_properties(cli_bad_input_vtk_${name} PROPERTIES LABELS "unit;cli")
endforeach()
