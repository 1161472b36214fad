target_link_libraries(cadmorph PRIVATE cm_morph cm_surface cm_volume cm_cad)
