target_link_libraries(cadmorph PRIVATE cm_cad)
