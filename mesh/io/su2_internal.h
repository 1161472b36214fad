/* The SU2 reader's and writer's shared table (not public; su2.c, su2_write.c). */
#ifndef CADMORPH_MESH_IO_SU2_INTERNAL_H
#define CADMORPH_MESH_IO_SU2_INTERNAL_H

#include "cadmorph/mesh.h"

/* The cell type of an SU2 element id (VTK's ids for the linear types SU2 has) and its node
 * count; 0 for an id SU2 does not have. */
int cm_su2_cell(int64_t id, cm_cell_type *type);

#endif
