/* Shared by the surface-only formats (.obj, .off, .stl; not public): which cells they hold. */
#ifndef CADMORPH_MESH_IO_SURFACE_IO_H
#define CADMORPH_MESH_IO_SURFACE_IO_H

#include "cadmorph/mesh.h"

/* Cell c's corner nodes if it is a face (triangle, quad, polygon; higher-order faces by their
 * corners) or a line (its two end nodes), with *n their count; NULL for any other cell. */
static inline const int64_t *cm_surface_io_corners(const cm_mesh *mesh, size_t c, size_t *n)
{
    const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
    if (!info || (info->dim != 2 && info->dim != 1)) return NULL;
    *n = info->nodes < 0 ? (size_t)(mesh->offset[c + 1] - mesh->offset[c]) : (size_t)info->corners;
    return mesh->conn + mesh->offset[c];
}

#endif
