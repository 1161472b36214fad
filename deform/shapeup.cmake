# Shape constraints in the MLS deformation (shapeup.h, paper section 6): the projections and
# their fits (LAPACKE) and the Shape-Up alternation on the MLS factor (CHOLMOD update). Part
# of the library cm_mls, whose private CHOLMOD factor the alternation updates.
target_sources(cm_mls PRIVATE
  ${CMAKE_CURRENT_LIST_DIR}/shape_fit.c  # plane, circle, cylinder, similar/rigid projections
  ${CMAKE_CURRENT_LIST_DIR}/shapeup.c    # the alternation, eq. 17, sparse C of section 6.1
  ${CMAKE_CURRENT_LIST_DIR}/shapeup_snap.c  # the snap onto the shapes after the exact constraints
  ${CMAKE_CURRENT_LIST_DIR}/ransac.c     # primitive detection (section 6.3), ransac.h
)
