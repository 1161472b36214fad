# `cadmorph mesh` (cmd_mesh.c): TetGen meshing lives in cm_volume, the STEP reading in cm_cad.
target_link_libraries(cadmorph PRIVATE cm_volume cm_cad)
