# CGNS files: a C test on files the CGNS library writes (every element type in SIDS order,
# MIXED, NGON_n/NFACE_n, two zones with BCs and families, ADF and HDF5, affine write-back,
# structured zones and hostile files refused), then the trees of the files written back
# compared node by node with the originals (h5py, cgnsdiff, cgnscheck), and new files read by
# meshio.
cm_add_unit_test(test_cgns test_cgns.c LIBS cm_mesh cm_cgns LABELS "cgns;hostile")
set_tests_properties(test_cgns PROPERTIES FIXTURES_SETUP cgns_files)
add_test(NAME test_cgns_tree
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_cgns_tree.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK}/cgns)
set_tests_properties(test_cgns_tree PROPERTIES LABELS "unit;cgns" FIXTURES_REQUIRED cgns_files SKIP_RETURN_CODE 77)
# the CLI (quality, morph, warp with an affine motion of every node, optimize, deform with a
# constraint on a BC family) on the bore model's hex mesh as CGNS and on the two-zone file
add_test(NAME test_cgns_cli
  COMMAND ${CM_PYTHON} ${CMAKE_CURRENT_SOURCE_DIR}/test_cgns_cli.py $<TARGET_FILE:cadmorph> ${CM_TEST_WORK})
set_tests_properties(test_cgns_cli PROPERTIES LABELS "cli;cgns" FIXTURES_REQUIRED cgns_files TIMEOUT 300)
