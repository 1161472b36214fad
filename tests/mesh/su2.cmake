# SU2 native .su2: the reader, the write back and new files on files written in the test
# (hostile ones too), and against gmsh's and meshio's .su2 (su2_crosscheck.py).
cm_add_unit_test(test_su2 test_su2.c LIBS cm_mesh)
set_tests_properties(test_su2 PROPERTIES LABELS "unit;hostile")
