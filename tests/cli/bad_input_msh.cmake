# `cadmorph quality` on broken gmsh files (tests/data/msh/bad, from generate_bad.py there) must
# exit with 2 and name the file with its line (ASCII) or byte offset (binary).

set(_msh_bad
  "truncated|truncated\\.msh:18: expected"
  "wrong_count|wrong_count\\.msh:14: expected 5 nodes"
  "node_undefined|node_undefined\\.msh:19: expected a node tag defined in .Nodes, got 99"
  "nan_coord|nan_coord\\.msh:12: expected a finite node coordinate"
  "unknown_type|unknown_type\\.msh:18: expected a gmsh element type number, got 999"
  "big_endian|big_endian\\.msh: byte 20: big-endian"
  "binary_count|binary_count\\.msh: byte 55: expected number of nodes that fits"
  "binary_truncated|binary_truncated\\.msh: byte [0-9]+: expected"
  "version30|version30\\.msh:2: msh version 3\\.0 is not supported"
  "version40|version40\\.msh:2: msh version 4\\.0 is not supported"
  "partitioned|partitioned\\.msh:4: partitioned meshes"
  "v22_wrong_count|v22_wrong_count\\.msh:14: expected element tag"
)
foreach(_case IN LISTS _msh_bad)
  string(REPLACE "|" ";" _parts "${_case}")
  list(GET _parts 0 _name)
  list(GET _parts 1 _regex)
  add_test(NAME cli_bad_msh_${_name}
    COMMAND ${CM_RUN_CLI} --exit 2 --stderr "${_regex}" --
            $<TARGET_FILE:cadmorph> quality ${CM_TEST_DATA}/msh/bad/${_name}.msh)
  set_tests_properties(cli_bad_msh_${_name} PROPERTIES LABELS "cli")
endforeach()
