# kD-tree: exact nearest neighbours against a brute-force scan.
cm_add_unit_test(test_kdtree test_kdtree.c LIBS cm_cad LABELS cad)
