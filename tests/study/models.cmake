# The built-in models (include/cadmorph/models.h; the solids live in cad/, the hex meshes in
# study/) through `cadmorph model`: G(0) and G(1) written as STEP and read back by the CAD
# layer, same topology in the same order (`cadmorph info --compare`; the tilted bore's rims
# turn from circles into ellipses, which cm_cad_compare accepts).
set(CM_MODELS_WORK ${CM_TEST_WORK}/models)
file(MAKE_DIRECTORY ${CM_MODELS_WORK})
foreach(model bore pipe bracket)
  foreach(t 0 1)
    add_test(NAME models_write_${model}_${t}
      COMMAND cadmorph model ${model} ${t} ${CM_MODELS_WORK}/${model}_${t}.step)
    set_tests_properties(models_write_${model}_${t} PROPERTIES
      FIXTURES_SETUP models_${model} LABELS "unit;cad")
  endforeach()
endforeach()
foreach(model bore pipe bracket)
  add_test(NAME models_compare_${model} COMMAND cadmorph info ${CM_MODELS_WORK}/${model}_0.step
    --compare ${CM_MODELS_WORK}/${model}_1.step)
  set_tests_properties(models_compare_${model} PROPERTIES FIXTURES_REQUIRED models_${model}
    LABELS "unit;cad;cli")
endforeach()
# the tet mesher on every model at t = 1 (tilted bore, 135 degree bend): no inverted tet
foreach(model bore pipe bracket)
  add_test(NAME models_mesh_${model}_1 COMMAND ${CM_RUN_CLI}
    --exit 0 --last-line ".* inverted=0 .*" --
    $<TARGET_FILE:cadmorph> mesh ${CM_MODELS_WORK}/${model}_1.step -o ${CM_MODELS_WORK}/${model}_1.vtu
    --size 0.3)
  set_tests_properties(models_mesh_${model}_1 PROPERTIES FIXTURES_REQUIRED models_${model}
    LABELS "unit;cad;cli")
endforeach()

# `cadmorph model` itself: the README's first step (write G(0), read it back), the signature,
# the hex mesh of G(0), the help and the usage errors.
add_test(NAME cli_model_info COMMAND ${CM_RUN_CLI} --exit 0
  --stdout "^solids 1  shells 1  faces 7 " --
  $<TARGET_FILE:cadmorph> info ${CM_MODELS_WORK}/bore_0.step)
set_tests_properties(cli_model_info PROPERTIES FIXTURES_REQUIRED models_bore
  LABELS "unit;cad;cli")
add_test(NAME cli_model_signature COMMAND ${CM_RUN_CLI} --exit 0 --last-line "^volume 2[0-9.]+$" --
  $<TARGET_FILE:cadmorph> model bore 0.5 --signature)
add_test(NAME cli_model_hex_mesh COMMAND ${CM_RUN_CLI} --exit 0
  --stdout "^nodes=[0-9]+ hexes=[0-9]+$" --last-line "^min_scaled_jacobian=.* inverted=0 cells=[0-9]+$" --
  $<TARGET_FILE:cadmorph> model pipe 0 --hex-mesh ${CM_MODELS_WORK}/pipe_hex.msh --scale 0.5)
add_test(NAME cli_model_help COMMAND ${CM_RUN_CLI} --exit 0 --stdout "^usage: cadmorph model"
  --stdout "--hex-mesh MESH" -- $<TARGET_FILE:cadmorph> model --help)
add_test(NAME cli_model_unknown COMMAND ${CM_RUN_CLI} --exit 1 --stderr-lines 2
  --stderr "^cadmorph model: unknown model 'cube' \\(bore, pipe, bracket\\)"
  -- $<TARGET_FILE:cadmorph> model cube 0 ${CM_MODELS_WORK}/cube.step)
add_test(NAME cli_model_bad_t COMMAND ${CM_RUN_CLI} --exit 1
  --stderr "T must be a number in \\[0, 1\\], got '1.5'"
  -- $<TARGET_FILE:cadmorph> model bore 1.5 ${CM_MODELS_WORK}/bad.step)
add_test(NAME cli_model_hex_bracket COMMAND ${CM_RUN_CLI} --exit 1
  --stderr "no hex mesh of the bracket"
  -- $<TARGET_FILE:cadmorph> model bracket 0 --hex-mesh ${CM_MODELS_WORK}/bad.msh)
set_tests_properties(cli_model_signature cli_model_hex_mesh cli_model_help cli_model_unknown
  cli_model_bad_t cli_model_hex_bracket PROPERTIES LABELS "unit;cad;cli")
