/* Prints the layout of every struct the Python package reads (python/cadmorph/_capi.py
 * declares them again for cffi): "struct size" and "struct.field offset" lines, which
 * test_layout.py compares with cffi's view. */
#include <stddef.h>
#include <stdio.h>

#include "cadmorph/mesh.h"

#define SIZE(s) printf("%s %zu\n", #s, sizeof(s))
#define FIELD(s, f) printf("%s.%s %zu\n", #s, #f, offsetof(s, f))

int main(void)
{
    SIZE(cm_cell_info);
    FIELD(cm_cell_info, name);
    FIELD(cm_cell_info, nodes);
    FIELD(cm_cell_info, gmsh);
    SIZE(cm_field);
    FIELD(cm_field, name);
    FIELD(cm_field, location);
    FIELD(cm_field, components);
    FIELD(cm_field, data);
    SIZE(cm_mesh_group);
    FIELD(cm_mesh_group, dim);
    FIELD(cm_mesh_group, tag);
    FIELD(cm_mesh_group, name);
    SIZE(cm_mesh_entity);
    FIELD(cm_mesh_entity, bounding);
    SIZE(cm_mesh);
    FIELD(cm_mesh, n_nodes);
    FIELD(cm_mesh, xyz);
    FIELD(cm_mesh, n_cells);
    FIELD(cm_mesh, type);
    FIELD(cm_mesh, offset);
    FIELD(cm_mesh, conn);
    FIELD(cm_mesh, n_fields);
    FIELD(cm_mesh, fields);
    FIELD(cm_mesh, n_groups);
    FIELD(cm_mesh, groups);
    FIELD(cm_mesh, origin);
    SIZE(cm_mesh_write_options);
    FIELD(cm_mesh_write_options, appended);
    SIZE(cm_quality_stats);
    FIELD(cm_quality_stats, min);
    FIELD(cm_quality_stats, mean);
    FIELD(cm_quality_stats, p01);
    FIELD(cm_quality_stats, inverted);
    printf("cm_status %zu\ncm_cell_type %zu\n", sizeof(cm_status), sizeof(cm_cell_type));
    return 0;
}
