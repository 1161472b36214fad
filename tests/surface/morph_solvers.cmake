# The iterative RBF solver against the dense one on real boundary sets (benchmarks/RESULTS.md, Iterative solver):
# the bore and the thin-walled bracket, gmsh tets of G(0) with about 5k boundary nodes
# (bore 5,338 at size 0.125, bracket 4,505 at 0.15), morphed onto G(1) once with each
# solver. The moved meshes agree to 1e-9 of the displacement range (measured 1.4e-11 and
# 3.3e-11; the dense residual is refined to 1e-15 here, so no higher floor applies), and the
# iterative warp takes at most 15 iterations (measured 5 and 6: a bound with margin, not a
# count). Each stage is a fixture of the next, so any one test runs alone (ctest -R).
set(SV ${CM_TEST_WORK}/morph_solvers)
add_test(NAME morph_solvers_dir COMMAND ${CMAKE_COMMAND} -E make_directory ${SV})
set_tests_properties(morph_solvers_dir PROPERTIES FIXTURES_SETUP morph_solvers_dir
  LABELS "cli;cad")
foreach(case bore:0.125 bracket:0.15)
  string(REPLACE ":" ";" parts ${case})
  list(GET parts 0 model)
  list(GET parts 1 size)
  set(base ${SV}/${model})
  foreach(t 0 1)
    add_test(NAME morph_solvers_${model}_step${t}
      COMMAND $<TARGET_FILE:cadmorph> model ${model} ${t} ${base}_${t}.step)
    set_tests_properties(morph_solvers_${model}_step${t} PROPERTIES LABELS "cli;cad"
      FIXTURES_REQUIRED morph_solvers_dir FIXTURES_SETUP morph_solvers_${model}_steps)
  endforeach()
  add_test(NAME morph_solvers_${model}_mesh
    COMMAND $<TARGET_FILE:cadmorph> mesh ${base}_0.step -o ${base}.vtu --size ${size})
  set_tests_properties(morph_solvers_${model}_mesh PROPERTIES LABELS "cli;cad"
    FIXTURES_REQUIRED morph_solvers_${model}_steps FIXTURES_SETUP morph_solvers_${model}_mesh)
  foreach(solver dense iterative)
    if(solver STREQUAL "dense")
      set(used "\\(dense, ")
    else()
      set(used "\\(iterative, ([1-9]|1[0-5]) iterations\\)")
    endif()
    add_test(NAME cli_morph_solvers_${model}_${solver}
      COMMAND ${CM_RUN_CLI} --exit 0 --stderr "cm_warp_apply: .* centres, solve .* ${used}" --
        $<TARGET_FILE:cadmorph> morph --from ${base}_0.step --to ${base}_1.step
        --mesh ${base}.vtu -o ${base}_${solver}.vtu --solver ${solver} --verbose)
    set_tests_properties(cli_morph_solvers_${model}_${solver} PROPERTIES LABELS "cli;cad"
      FIXTURES_REQUIRED morph_solvers_${model}_mesh
      FIXTURES_SETUP morph_solvers_${model}_moved)
  endforeach()
  add_test(NAME cli_morph_solvers_${model}_agree
    COMMAND ${CM_PYTHON} ${PROJECT_SOURCE_DIR}/tests/cli/compare_moved.py
            ${base}_dense.vtu ${base}_iterative.vtu 1e-9)
  set_tests_properties(cli_morph_solvers_${model}_agree PROPERTIES LABELS "cli;cad"
    FIXTURES_REQUIRED morph_solvers_${model}_moved)
endforeach()
