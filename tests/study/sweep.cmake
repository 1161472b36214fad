# Staten-style sweeps [SKM11]: `cadmorph sweep` (study/'s cm_sweep_run) and `cadmorph demo`,
# checked on what they write (check_sweep.py). The sweeps of benchmarks/RESULTS.md are run by
# benchmarks/sweep/run_sweeps.sh.

# bore, coarse tet mesh, 4 absolute RBF-S steps through the CLI: no inverted cell, boundary
# on G(t) to 1e-9 x diagonal at every step, the expected CSV rows, an SVG that parses as XML.
set(CM_SWEEP_WORK ${CM_TEST_WORK}/sweep)
add_test(NAME sweep_bore_tet_absolute
  COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_sweep.py
    --dir ${CM_SWEEP_WORK}/bore_tet --steps 4 --modes absolute --methods rbf-s
    --max-inverted 0 --max-distance-rel 1e-9 --
    $<TARGET_FILE:cadmorph> sweep bore --mesh tet --size 0.4 --steps 4 --mode absolute
    --methods rbf-s -o ${CM_SWEEP_WORK}/bore_tet --threads 2)
set_tests_properties(sweep_bore_tet_absolute PROPERTIES LABELS "unit;cad;cli" TIMEOUT 120)

# relative mode and the three methods on the coarse O-grid hex mesh of the bore: every series
# complete, its boundary on G(t), its meshes' quality as VTK computes it (no bound on inversions:
# the project baseline is allowed to fail, which is what the sweep shows).
add_test(NAME sweep_bore_hex_both
  COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_sweep.py
    --dir ${CM_SWEEP_WORK}/bore_hex --steps 3 --modes absolute,relative
    --methods rbf-s,project,rbf-s-biharmonic --max-distance-rel 1e-9 --
    $<TARGET_FILE:cadmorph> sweep bore --mesh hex --size 0.3 --steps 3 --mode both
    -o ${CM_SWEEP_WORK}/bore_hex --threads 2)
set_tests_properties(sweep_bore_hex_both PROPERTIES LABELS "unit;cad;cli" TIMEOUT 120)

# `cadmorph demo` (the README's first command) is the sweep with fixed arguments: the same
# checks on what it writes.
add_test(NAME cli_demo
  COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/check_sweep.py
    --dir ${CM_SWEEP_WORK}/demo --steps 10 --modes absolute
    --methods rbf-s,project,rbf-s-biharmonic --max-distance-rel 1e-9 --
    $<TARGET_FILE:cadmorph> demo -o ${CM_SWEEP_WORK}/demo)
math(EXPR _cm_demo_timeout "300 * ${CM_TIME_FACTOR}")
set_tests_properties(cli_demo PROPERTIES LABELS "unit;cad;cli" TIMEOUT ${_cm_demo_timeout})
