# `cadmorph warp --method femwarp|lbwarp|simplex` on a user's gmsh mesh with a D.csv (fixture
# warp_staten from tests/volume/warp.cmake): each method runs on tets (a box with a hole) and
# on graded hexes; FEMWARP's result equals scipy's spsolve of an independently assembled
# K_II x = -K_IB d_B; an affine D.csv is reproduced at every node by every method.
set(SW ${CM_TEST_WORK}/staten)
set(RUN ${CM_RUN_CLI})
set(CHK ${CM_PYTHON} ${PROJECT_SOURCE_DIR}/tests/volume/warp_staten.py)
set(SUMMARY "^min_scaled_jacobian=[-+0-9.e]+ mean_scaled_jacobian=[-+0-9.e]+ inverted=0 cells=[1-9][0-9]*\n?\\Z")

set(affine_outputs)
set(affine_tests)
foreach(method femwarp lbwarp simplex)
  foreach(mesh tets hexes)
    add_test(NAME cli_warp_${method}_${mesh}
      COMMAND ${RUN} --exit 0 --stdout "${SUMMARY}" -- $<TARGET_FILE:cadmorph> warp
              --method ${method} --mesh ${SW}/${mesh}.msh --displacements ${SW}/${mesh}_D.csv
              -o ${SW}/cli_${method}_${mesh}.vtu)
    set_tests_properties(cli_warp_${method}_${mesh} PROPERTIES LABELS "cli;volume"
      FIXTURES_REQUIRED warp_staten)
  endforeach()
  add_test(NAME cli_warp_${method}_affine
    COMMAND ${RUN} --exit 0 --stdout "${SUMMARY}" -- $<TARGET_FILE:cadmorph> warp
            --method ${method} --mesh ${SW}/tets.msh --displacements ${SW}/affine.csv
            -o ${SW}/cli_${method}_affine.vtu)
  set_tests_properties(cli_warp_${method}_affine PROPERTIES LABELS "cli;volume"
    FIXTURES_REQUIRED warp_staten)
  list(APPEND affine_outputs ${SW}/cli_${method}_affine.vtu)
  list(APPEND affine_tests cli_warp_${method}_affine)
endforeach()

foreach(mesh tets hexes)
  add_test(NAME cli_warp_femwarp_scipy_${mesh}
    COMMAND ${CHK} femwarp ${CM_TEST_WORK} ${mesh} ${SW}/cli_femwarp_${mesh}.vtu)
  set_tests_properties(cli_warp_femwarp_scipy_${mesh} PROPERTIES LABELS "cli;volume"
    FIXTURES_REQUIRED warp_staten)
  cm_test_reads(cli_warp_femwarp_scipy_${mesh} cli_warp_femwarp_${mesh})
endforeach()
add_test(NAME cli_warp_methods_affine COMMAND ${CHK} affine ${SW}/tets.msh ${affine_outputs})
set_tests_properties(cli_warp_methods_affine PROPERTIES LABELS "cli;volume"
  FIXTURES_REQUIRED warp_staten)
cm_test_reads(cli_warp_methods_affine ${affine_tests})

add_test(NAME cli_warp_method_unknown
  COMMAND ${RUN} --exit 1 --stderr "unknown method 'femwrap' \\(rbf\\|rbf-biharmonic\\|femwarp\\|lbwarp\\|simplex"
          -- $<TARGET_FILE:cadmorph> warp --method femwrap --mesh ${SW}/tets.msh
          --displacements ${SW}/tets_D.csv -o ${SW}/cli_unknown.vtu)
set_tests_properties(cli_warp_method_unknown PROPERTIES LABELS "cli;volume"
  FIXTURES_REQUIRED warp_staten)

# The benchmark models: bore and pipe, TetGen tets (cadmorph mesh) and O-grid hexes
# (cadmorph model --hex-mesh) at the sweeps' sizes, an affine motion of their boundary through
# each method.
# Each stage is a fixture of the next, so any one test can run alone (ctest -R).
set(BM ${CM_TEST_WORK}/staten_models)
add_test(NAME warp_methods_models_setup COMMAND ${CMAKE_COMMAND} -E make_directory ${BM})
set_tests_properties(warp_methods_models_setup PROPERTIES FIXTURES_SETUP staten_models_dir
  LABELS "cli;volume")
foreach(model bore pipe)
  add_test(NAME warp_methods_${model}_step
    COMMAND $<TARGET_FILE:cadmorph> model ${model} 0 ${BM}/${model}.step)
  add_test(NAME warp_methods_${model}_tet
    COMMAND $<TARGET_FILE:cadmorph> mesh ${BM}/${model}.step -o ${BM}/${model}_tet.msh --size 0.25 --mesher tetgen)
  add_test(NAME warp_methods_${model}_hex
    COMMAND $<TARGET_FILE:cadmorph> model ${model} 0 --hex-mesh ${BM}/${model}_hex.msh --scale 0.6667)
  set_tests_properties(warp_methods_${model}_step PROPERTIES LABELS "cli;volume"
    FIXTURES_REQUIRED staten_models_dir FIXTURES_SETUP staten_${model}_step)
  set_tests_properties(warp_methods_${model}_hex PROPERTIES LABELS "cli;volume"
    FIXTURES_REQUIRED staten_models_dir FIXTURES_SETUP staten_${model}_hex_mesh)
  set_tests_properties(warp_methods_${model}_tet PROPERTIES LABELS "cli;volume"
    FIXTURES_REQUIRED "staten_models_dir;staten_${model}_step"
    FIXTURES_SETUP staten_${model}_tet_mesh)
  foreach(kind tet hex)
    set(base ${BM}/${model}_${kind})
    add_test(NAME warp_methods_${model}_${kind}_csv COMMAND ${CHK} affine-csv ${base}.msh ${base}_affine.csv)
    set_tests_properties(warp_methods_${model}_${kind}_csv PROPERTIES LABELS "cli;volume"
      FIXTURES_REQUIRED staten_${model}_${kind}_mesh FIXTURES_SETUP staten_${model}_${kind})
    set(outs)
    foreach(method femwarp lbwarp simplex)
      add_test(NAME cli_warp_${method}_${model}_${kind}
        COMMAND $<TARGET_FILE:cadmorph> warp --method ${method} --mesh ${base}.msh
                --displacements ${base}_affine.csv -o ${base}_${method}.vtu)
      set_tests_properties(cli_warp_${method}_${model}_${kind} PROPERTIES LABELS "cli;volume"
        FIXTURES_REQUIRED staten_${model}_${kind}
        FIXTURES_SETUP staten_${model}_${kind}_warps)
      list(APPEND outs ${base}_${method}.vtu)
    endforeach()
    add_test(NAME cli_warp_methods_affine_${model}_${kind} COMMAND ${CHK} affine ${base}.msh ${outs})
    set_tests_properties(cli_warp_methods_affine_${model}_${kind} PROPERTIES LABELS "cli;volume"
      FIXTURES_REQUIRED "staten_${model}_${kind};staten_${model}_${kind}_warps")
  endforeach()
endforeach()
