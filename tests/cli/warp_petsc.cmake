# `cadmorph warp --solver petsc`: under `mpirun -n 2` on the sphere-in-box mesh (fixture
# warp_sphere) the same moved mesh as the serial iterative solver, written once (rank 0) with
# one summary line; in a build without PETSc a usage error that says how to get it.
set(W ${CM_TEST_WORK}/warp)
if(CADMORPH_WITH_PETSC)
  set(ONE_SUMMARY "\\A(?:(?!min_scaled_jacobian)[\\s\\S])*min_scaled_jacobian=[^\\n]* inverted=0 cells=[1-9][0-9]*\\n?\\Z")
  add_test(NAME cli_warp_petsc_2ranks
    COMMAND ${CM_RUN_CLI} --exit 0 --stdout "${ONE_SUMMARY}" --
      ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 --oversubscribe $<TARGET_FILE:cadmorph>
      warp --mesh ${W}/sphere.msh --displacements ${W}/sphere_disp.csv
      -o ${W}/cli_petsc.vtu --solver petsc --threads 1)
  add_test(NAME cli_warp_petsc_serial
    COMMAND ${CM_RUN_CLI} --exit 0 -- $<TARGET_FILE:cadmorph> warp --mesh ${W}/sphere.msh
      --displacements ${W}/sphere_disp.csv -o ${W}/cli_petsc_serial.vtu --solver iterative)
  add_test(NAME cli_warp_petsc_same
    COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/compare_moved.py ${W}/cli_petsc_serial.vtu
            ${W}/cli_petsc.vtu 1e-9)
  set_tests_properties(cli_warp_petsc_2ranks cli_warp_petsc_serial cli_warp_petsc_same
    PROPERTIES LABELS "cli;petsc" FIXTURES_REQUIRED warp_sphere
    ENVIRONMENT "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1")
  cm_test_reads(cli_warp_petsc_same cli_warp_petsc_2ranks cli_warp_petsc_serial)
else()
  add_test(NAME cli_warp_petsc_missing
    COMMAND ${CM_RUN_CLI} --exit 1 --stderr "built without PETSc .*-DCADMORPH_WITH_PETSC=ON"
      --absent ${W}/cli_petsc_missing.vtu --
      $<TARGET_FILE:cadmorph> warp --mesh ${W}/sphere.msh --displacements ${W}/sphere_disp.csv
      -o ${W}/cli_petsc_missing.vtu --solver petsc)
  set_tests_properties(cli_warp_petsc_missing PROPERTIES LABELS "cli" FIXTURES_REQUIRED warp_sphere)
endif()
