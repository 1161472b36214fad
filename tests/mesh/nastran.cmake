# Nastran bulk data: a C test on decks written in code (numbers, layouts, systems, quadratic
# node order, INCLUDE, hostile decks, writing back), and the cross-check against decks that gmsh
# and meshio write and read.
cm_add_unit_test(test_nastran test_nastran.c LIBS cm_mesh_internal LABELS hostile)
