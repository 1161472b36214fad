# `cadmorph warp --method femwarp|lbwarp|simplex` on a user's gmsh mesh with a D.csv (fixture
# warp_staten from tests/volume/warp.cmake): each method runs on tets (a box with a hole) and
# on graded hexes; FEMWARP's result equals scipy's spsolve of an independently assembled
# K_II x = -K_IB d_B; an affine D.csv is reproduced at every node by every method.
set(SW ${CM_TEST_WORK}/staten)
set(RUN ${CM_PYTHON} ${PROJECT_SOURCE_DIR}/tests/volume/run_cli.py)
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
    FIXTURES_REQUIRED warp_staten DEPENDS cli_warp_femwarp_${mesh})
endforeach()
add_test(NAME cli_warp_methods_affine COMMAND ${CHK} affine ${CM_TEST_WORK} ${affine_outputs})
set_tests_properties(cli_warp_methods_affine PROPERTIES LABELS "cli;volume"
  FIXTURES_REQUIRED warp_staten DEPENDS "${affine_tests}")

add_test(NAME cli_warp_method_unknown
  COMMAND ${RUN} --exit 1 --stderr "unknown method 'femwrap' \\(rbf\\|rbf-biharmonic\\|femwarp\\|lbwarp\\|simplex"
          -- $<TARGET_FILE:cadmorph> warp --method femwrap --mesh ${SW}/tets.msh
          --displacements ${SW}/tets_D.csv -o ${SW}/cli_unknown.vtu)
set_tests_properties(cli_warp_method_unknown PROPERTIES LABELS "cli;volume"
  FIXTURES_REQUIRED warp_staten)
