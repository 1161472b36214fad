# The morph engine (volume/morpher.c, volume/morph_pipeline.c) on the gmsh meshes of the
# surface fixtures (fixture surface_meshes of tests/surface).
cm_add_unit_test(test_morpher test_morpher.c LIBS cm_morph LABELS "cad;volume")
set_tests_properties(test_morpher PROPERTIES FIXTURES_REQUIRED surface_meshes)
