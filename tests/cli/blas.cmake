# The BLAS set-up of cli/blas_reexec.c (README.md, the OpenBLAS core) and the resource bounds:
# --version names the BLAS, its core and threads (on a Sapphire-Rapids-class Xeon OpenBLAS
# 0.3.21 picks Prescott and the real re-exec happens; elsewhere OpenBLAS's choice stands);
# the re-exec with OPENBLAS_CORETYPE (on machines where OpenBLAS chooses well,
# CADMORPH_TEST_BLAS_PICKED pretends it did not); the user's OPENBLAS_CORETYPE stands;
# ulimit -v never hangs (item 5); --threads is capped (item 7).
set(BRUN ${CM_RUN_CLI})
set(BW ${CM_TEST_WORK}/warp)
add_test(NAME cli_version_blas COMMAND ${CMAKE_COMMAND} -E env --unset=OPENBLAS_CORETYPE
  ${BRUN} --exit 0
  --stdout "^cadmorph [0-9.]+\nBLAS: OpenBLAS [0-9.]+.*\nBLAS core: \\w+ \\((chosen by OpenBLAS|OpenBLAS picked \\w+; cadmorph set OPENBLAS_CORETYPE=\\w+)\\)\nBLAS threads: [1-9][0-9]* for factorisations \\(1 at start"
  -- $<TARGET_FILE:cadmorph> --version)
# OpenBLAS "picked" Prescott: one re-exec, the child reports the core it asked for
add_test(NAME cli_blas_reexec COMMAND ${CMAKE_COMMAND} -E env --unset=OPENBLAS_CORETYPE
  CADMORPH_TEST_BLAS_PICKED=Prescott ${BRUN} --exit 0
  --stdout "^BLAS: OpenBLAS .*(SkylakeX|Haswell).*\nBLAS core: (SkylakeX|Haswell) \\(OpenBLAS picked Prescott; cadmorph set OPENBLAS_CORETYPE=\\2\\)"
  --stderr "^cadmorph: OpenBLAS picked its Prescott kernels, .*OPENBLAS_CORETYPE=(SkylakeX|Haswell)"
  -- $<TARGET_FILE:cadmorph> --version --verbose)
# the user's choice stands, and --verbose says when it is the weaker one
add_test(NAME cli_blas_user_coretype COMMAND ${CMAKE_COMMAND} -E env OPENBLAS_CORETYPE=Prescott
  CADMORPH_TEST_BLAS_PICKED=Prescott ${BRUN} --exit 0
  --stdout "\nBLAS core: Prescott \\(OPENBLAS_CORETYPE=Prescott, set by the user\\)"
  --stderr "OPENBLAS_CORETYPE=Prescott is set; this CPU would run OpenBLAS's (SkylakeX|Haswell) kernels"
  -- $<TARGET_FILE:cadmorph> --version -v)
set_tests_properties(cli_version_blas cli_blas_reexec cli_blas_user_coretype PROPERTIES LABELS "cli")

# bounded time and a clean exit code under ulimit -v
add_test(NAME cli_ulimit COMMAND sh ${CMAKE_CURRENT_LIST_DIR}/ulimit.sh $<TARGET_FILE:cadmorph>
  ${BW}/sphere.msh ${BW}/sphere_disp.csv ${BW})
set_tests_properties(cli_ulimit PROPERTIES LABELS "cli" FIXTURES_REQUIRED warp_sphere
  SKIP_RETURN_CODE 77 TIMEOUT 600)

# libgomp aborts at --threads 512..4096: a usage error naming the cap instead
foreach(t 512 4096 100000)
  add_test(NAME cli_threads_cap_${t} COMMAND ${BRUN} --exit 1 --stderr-lines 2
    --stderr "^cadmorph warp: --threads ${t} is more than 4 per core \\([0-9]+ cores: at most [0-9]+\\)"
    --absent ${BW}/cli_threads_${t}.vtu --
    $<TARGET_FILE:cadmorph> warp --mesh ${BW}/sphere.msh --displacements ${BW}/sphere_disp.csv
    -o ${BW}/cli_threads_${t}.vtu --threads ${t})
  set_tests_properties(cli_threads_cap_${t} PROPERTIES LABELS "cli" FIXTURES_REQUIRED warp_sphere)
endforeach()
add_test(NAME cli_threads_cap_quality COMMAND ${BRUN} --exit 1
  --stderr "^cadmorph quality: --threads 4096 is more than 4 per core" --
  $<TARGET_FILE:cadmorph> quality ${CM_TEST_DATA}/quality/box_tets.vtu --threads 4096)
# the cap itself is accepted: 4 per core runs
add_test(NAME cli_threads_at_cap COMMAND sh -c
  "exec \"$1\" quality \"$2\" --threads $((4 * $(nproc)))" sh $<TARGET_FILE:cadmorph>
  ${CM_TEST_DATA}/quality/box_tets.vtu)
set_tests_properties(cli_threads_cap_quality cli_threads_at_cap PROPERTIES LABELS "cli")
