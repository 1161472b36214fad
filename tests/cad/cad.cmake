# Tests of cad/: shapes built in code with OpenCASCADE (gen_shapes, C++) and written as STEP
# into the work dir, gmsh-written STEP fixtures in tests/data/cad; assertions go through the
# C API (cadmorph/cad.h) or the CLI.
set(CM_CAD_WORK ${CM_TEST_WORK}/cad)
file(MAKE_DIRECTORY ${CM_CAD_WORK})

add_executable(gen_shapes gen_shapes.cpp)
target_link_libraries(gen_shapes PRIVATE cm_warnings cm_occ)
add_test(NAME cad_gen_shapes COMMAND gen_shapes ${CM_CAD_WORK})
set_tests_properties(cad_gen_shapes PROPERTIES FIXTURES_SETUP cad_shapes LABELS "unit;cad")

foreach(t model project sample boundary solids)
  cm_add_unit_test(test_cad_${t} test_cad_${t}.c LIBS cm_cad LABELS cad)
  set_tests_properties(test_cad_${t} PROPERTIES FIXTURES_REQUIRED cad_shapes)
endforeach()
# the correspondence of G and G' as graphs, and a morph onto a renumbered identical G'
cm_add_unit_test(test_cad_correspond test_cad_correspond.c LIBS cm_morph cm_meshgen cm_cad LABELS cad)
set_tests_properties(test_cad_correspond PROPERTIES FIXTURES_REQUIRED cad_shapes
                     FIXTURES_SETUP cad_part_mesh)

# cadmorph info: exit codes and one-line messages on real files (bad input: one stderr line).
function(cm_cad_cli name code regex)
  set(lines)
  if(code EQUAL 2)
    set(lines --stderr-lines 1)
  endif()
  add_test(NAME ${name} COMMAND ${CM_RUN_CLI} --exit ${code} --output "${regex}" ${lines} --
           $<TARGET_FILE:cadmorph> ${ARGN})
  set_tests_properties(${name} PROPERTIES LABELS "cad;cli" FIXTURES_REQUIRED cad_shapes)
endfunction()
set(D ${CM_TEST_DATA}/cad)
cm_cad_cli(cad_cli_info 0 "faces 9 +wires [0-9]+ +edges [0-9]+ +vertices" info ${D}/bore_a.step)
cm_cad_cli(cad_cli_info_unit 0 "unit: m " info ${D}/bore_a.step --cad-unit m)
cm_cad_cli(cad_cli_compare_same 0 "correspond" info ${D}/bore_a.step --compare ${D}/bore_b.step)
cm_cad_cli(cad_cli_compare_hole 2 "^cadmorph info: .*faces: 9 in G, 10 in G'" info ${D}/bore_a.step --compare ${D}/bore_2holes.step)
cm_cad_cli(cad_cli_missing 2 "^cadmorph info: .*no_such.step: (cannot open: )?No such file" info ${CM_CAD_WORK}/no_such.step)
cm_cad_cli(cad_cli_not_step 2 "^cadmorph info: .*not a STEP file" info ${CM_CAD_WORK}/not_step.step)
cm_cad_cli(cad_cli_no_solid 2 "^cadmorph info: .*no solid, shell or face" info ${CM_CAD_WORK}/edge_only.step)
cm_cad_cli(cad_cli_broken 2 "^cadmorph info: .*broken.step: " info ${D}/broken.step)
cm_cad_cli(cad_cli_usage 1 "usage" info)
cm_cad_cli(cad_cli_bad_unit 1 "unknown length unit" info ${D}/bore_a.step --cad-unit parsec)
# --compare: the correspondence (renumbered, flipped edges, type changes) and --map
cm_cad_cli(cad_cli_compare_renumbered 0 "corresponds to .*numbered otherwise.*\ncorrespondence: [1-9][0-9]* of 6 faces" info ${CM_CAD_WORK}/block.step --compare ${CM_CAD_WORK}/block_rebuilt.step --map ${CM_CAD_WORK}/block_map.csv)
cm_cad_cli(cad_cli_compare_types 0 "type changes: 9 faces" info ${CM_CAD_WORK}/part.step --compare ${CM_CAD_WORK}/part_gtrsf.step)
add_test(NAME cad_cli_compare_verbose_types COMMAND ${CM_RUN_CLI} --exit 0 --stderr "face 6: torus in G, bspline in G'" --
         $<TARGET_FILE:cadmorph> info ${CM_CAD_WORK}/part.step --compare ${CM_CAD_WORK}/part_nurbs.step --verbose)
set_tests_properties(cad_cli_compare_verbose_types PROPERTIES LABELS "cad;cli" FIXTURES_REQUIRED cad_shapes)
cm_cad_cli(cad_cli_compare_part_hole 2 "^cadmorph info: .*face [0-9]+ \\(plane, 5 edges, 1 hole\\) has no counterpart: G' has a hole there" info ${CM_CAD_WORK}/part.step --compare ${CM_CAD_WORK}/part_hole.step)
cm_cad_cli(cad_cli_map_needs_compare 1 "--map needs --compare" info ${CM_CAD_WORK}/part.step --map ${CM_CAD_WORK}/x.csv)

add_test(NAME cad_cli_compare_map_csv COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_LIST_DIR}/check_map.py
         ${CM_CAD_WORK}/block_map.csv 6 12 8)
set_tests_properties(cad_cli_compare_map_csv PROPERTIES LABELS "cad;cli")
cm_test_reads(cad_cli_compare_map_csv cad_cli_compare_renumbered)
# cadmorph morph renumbers G' (a re-sewn, reordered copy of G) and says so under --verbose
add_test(NAME cad_cli_morph_renumbered COMMAND ${CM_RUN_CLI} --exit 0
         --stderr "correspondence: G' is numbered otherwise than G: renumbered"
         --stdout "inverted=0 cells=[1-9]" --
         $<TARGET_FILE:cadmorph> morph --from ${CM_CAD_WORK}/part.step --to ${CM_CAD_WORK}/part_renumbered.step
         --mesh ${CM_CAD_WORK}/part_m.vtu -o ${CM_CAD_WORK}/part_renumbered_m.vtu --verbose)
set_tests_properties(cad_cli_morph_renumbered PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED "cad_shapes;cad_part_mesh")
# NurbsConvert changes the parameterisation only: the morph must leave every node in place
# (the surface morph finds the identity as an affine map; a (u,v) warp alone slid face nodes
# by 1 % of the diagonal along G')
add_test(NAME cad_cli_morph_nurbs COMMAND $<TARGET_FILE:cadmorph> morph
         --from ${CM_CAD_WORK}/part.step --to ${CM_CAD_WORK}/part_nurbs.step
         --mesh ${CM_CAD_WORK}/part_m.vtu -o ${CM_CAD_WORK}/part_nurbs_m.vtu)
set_tests_properties(cad_cli_morph_nurbs PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED "cad_shapes;cad_part_mesh" FIXTURES_SETUP cad_part_nurbs_m)
add_test(NAME cad_cli_morph_nurbs_in_place COMMAND ${CM_PYTHON}
         ${PROJECT_SOURCE_DIR}/tests/cli/compare_moved.py ${CM_CAD_WORK}/part_m.vtu
         ${CM_CAD_WORK}/part_nurbs_m.vtu 1e-9 diagonal)
set_tests_properties(cad_cli_morph_nurbs_in_place PROPERTIES LABELS "cad;cli"
                     FIXTURES_REQUIRED cad_part_nurbs_m)

# An independent distance of a mesh's boundary nodes to a STEP model (OpenCASCADE's reader and
# BRepExtrema_DistShapeShape, no cadmorph CAD code): checks the distance figures cadmorph reports.
add_executable(brep_distance brep_distance.cpp)
target_link_libraries(brep_distance PRIVATE cm_warnings cm_occ cm_mesh cm_core)
# The FreeCAD shaft's TetGen mesh asks for a sampling step of 1/6000 of the part: G is sampled
# within its boundary-node budget, without a warning, and the largest distance to G' that the
# morph reports is BRepExtrema's (benchmarks/RESULTS.md, "Sampling memory and the boundary
# distance").
foreach(mode samples distance)
  add_test(NAME cad_morph_sampling_${mode} COMMAND ${CM_PYTHON}
           ${CMAKE_CURRENT_LIST_DIR}/check_sampling.py $<TARGET_FILE:cadmorph>
           $<TARGET_FILE:brep_distance> ${CM_TEST_DATA} ${CM_CAD_WORK} ${mode})
  set_tests_properties(cad_morph_sampling_${mode} PROPERTIES LABELS "cad;cli")
endforeach()
