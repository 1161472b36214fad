# kD-tree wrapper over FLANN's C API (FLANN is linked PRIVATE into cm_core).
list(APPEND CM_CORE_SOURCES kdtree.c)
