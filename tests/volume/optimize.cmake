# Interior optimisation (volume/optimize.c) on blocks built in code.
cm_add_unit_test(test_optimize test_optimize.c LIBS cm_volume LABELS volume)
