# Abaqus input decks (.inp): a C test on decks it writes itself (every element type's node
# order, keywords, includes, sets and surfaces, parts and instances, writing back, a new deck,
# hostile decks), then the cross-checks against meshio, gmsh and CalculiX ccx.
cm_add_unit_test(test_abaqus test_abaqus.c LIBS cm_mesh LABELS hostile)
