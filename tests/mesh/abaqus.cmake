# Abaqus input decks (.inp): a C test on decks it writes itself (every element type's node
# order, keywords, includes, sets and surfaces, parts and instances, writing back, a new deck,
# hostile decks), then the cross-checks against meshio, gmsh and CalculiX ccx.
cm_add_unit_test(test_abaqus test_abaqus.c LIBS cm_mesh LABELS hostile)
# roundtrip: gmsh- and meshio-written decks, cadmorph's new deck read by meshio and run by ccx,
# an affine motion written back; ccx: the C3D10 bore morphed (mid-side nodes on the new bore)
# and run by CalculiX; cli: quality, warp, deform (an *NSET as the constraint set), optimize.
foreach(case roundtrip ccx cli)
  add_test(NAME test_abaqus_${case}
    COMMAND ${CM_PYTHON_LIB} ${CMAKE_CURRENT_SOURCE_DIR}/test_abaqus_crosscheck.py $<TARGET_FILE:cadmorph>
            ${PROJECT_BINARY_DIR}/python ${CM_TEST_WORK}/abaqus_${case} ${case})
  set_tests_properties(test_abaqus_${case} PROPERTIES LABELS "unit;cli" TIMEOUT 300 SKIP_RETURN_CODE 77
    ENVIRONMENT "PYTHONDONTWRITEBYTECODE=1")
endforeach()
