/* The mesh container: type table, growth, fields, groups, entities, copy, validation. */
#include "cadmorph/mesh.h"
#include "io/origin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* name, dim, nodes, corners, linear, vtk, gmsh */
static const cm_cell_info cell_table[CM_CELL_TYPE_COUNT] = {
    [CM_CELL_POINT] = {"point", 0, 1, 1, CM_CELL_POINT, 1, 15},
    [CM_CELL_LINE2] = {"line2", 1, 2, 2, CM_CELL_LINE2, 3, 1},
    [CM_CELL_LINE3] = {"line3", 1, 3, 2, CM_CELL_LINE2, 21, 8},
    [CM_CELL_TRI3] = {"tri3", 2, 3, 3, CM_CELL_TRI3, 5, 2},
    [CM_CELL_TRI6] = {"tri6", 2, 6, 3, CM_CELL_TRI3, 22, 9},
    [CM_CELL_QUAD4] = {"quad4", 2, 4, 4, CM_CELL_QUAD4, 9, 3},
    [CM_CELL_QUAD8] = {"quad8", 2, 8, 4, CM_CELL_QUAD4, 23, 16},
    [CM_CELL_QUAD9] = {"quad9", 2, 9, 4, CM_CELL_QUAD4, 28, 10},
    [CM_CELL_TET4] = {"tet4", 3, 4, 4, CM_CELL_TET4, 10, 4},
    [CM_CELL_TET10] = {"tet10", 3, 10, 4, CM_CELL_TET4, 24, 11},
    [CM_CELL_HEX8] = {"hex8", 3, 8, 8, CM_CELL_HEX8, 12, 5},
    [CM_CELL_HEX20] = {"hex20", 3, 20, 8, CM_CELL_HEX8, 25, 17},
    [CM_CELL_HEX27] = {"hex27", 3, 27, 8, CM_CELL_HEX8, 29, 12},
    [CM_CELL_WEDGE6] = {"wedge6", 3, 6, 6, CM_CELL_WEDGE6, 13, 6},
    [CM_CELL_WEDGE15] = {"wedge15", 3, 15, 6, CM_CELL_WEDGE6, 26, 18},
    [CM_CELL_WEDGE18] = {"wedge18", 3, 18, 6, CM_CELL_WEDGE6, 32, 13},
    [CM_CELL_PYR5] = {"pyramid5", 3, 5, 5, CM_CELL_PYR5, 14, 7},
    [CM_CELL_PYR13] = {"pyramid13", 3, 13, 5, CM_CELL_PYR5, 27, 19},
    [CM_CELL_PYR14] = {"pyramid14", 3, 14, 5, CM_CELL_PYR5, 37, 14},
    [CM_CELL_POLYGON] = {"polygon", 2, -1, -1, CM_CELL_POLYGON, 7, 0},
    [CM_CELL_POLYHEDRON] = {"polyhedron", 3, -1, -1, CM_CELL_POLYHEDRON, 42, 0},
};

const cm_cell_info *cm_cell_type_info(cm_cell_type type)
{
    return (unsigned)type < CM_CELL_TYPE_COUNT ? &cell_table[type] : NULL;
}

cm_cell_type cm_cell_type_from_vtk(int vtk_id)
{
    for (int t = 0; t < CM_CELL_TYPE_COUNT; ++t)
        if (cell_table[t].vtk == vtk_id) return (cm_cell_type)t;
    return CM_CELL_TYPE_COUNT;
}

cm_cell_type cm_cell_type_from_gmsh(int gmsh_id)
{
    for (int t = 0; t < CM_CELL_TYPE_COUNT; ++t)
        if (gmsh_id != 0 && cell_table[t].gmsh == gmsh_id) return (cm_cell_type)t;
    return CM_CELL_TYPE_COUNT;
}

cm_status cm_mesh_create(cm_context *ctx, cm_mesh **mesh)
{
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_create: mesh is NULL");
    *mesh = calloc(1, sizeof **mesh);
    if (!*mesh) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_create: out of memory");
    (*mesh)->offset = calloc(1, sizeof(int64_t));
    if (!(*mesh)->offset) {
        free(*mesh);
        *mesh = NULL;
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_create: out of memory");
    }
    return CM_OK;
}

static void free_entity(cm_mesh_entity *e)
{
    free(e->physical);
    free(e->bounding);
}

void cm_mesh_destroy(cm_mesh **mesh)
{
    if (!mesh || !*mesh) return;
    cm_mesh *m = *mesh;
    free(m->xyz);
    free(m->node_tag);
    free(m->type);
    free(m->offset);
    free(m->conn);
    free(m->physical);
    free(m->entity);
    free(m->cell_tag);
    for (size_t i = 0; i < m->n_fields; ++i) {
        free(m->fields[i].name);
        free(m->fields[i].data);
    }
    free(m->fields);
    for (size_t i = 0; i < m->n_groups; ++i) free(m->groups[i].name);
    free(m->groups);
    for (size_t i = 0; i < m->n_entities; ++i) free_entity(&m->entities[i]);
    free(m->entities);
    cm_mesh_origin_release(&m->origin);
    free(m);
    *mesh = NULL;
}

/* realloc that leaves *p untouched on failure. */
static int grow(void **p, size_t count, size_t size)
{
    if (count == 0) count = 1;
    void *q = realloc(*p, count * size);
    if (!q) return 0;
    *p = q;
    return 1;
}

cm_status cm_mesh_resize_nodes(cm_context *ctx, cm_mesh *mesh, size_t n_nodes, int with_tags)
{
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_resize_nodes: mesh is NULL");
    if (n_nodes > SIZE_MAX / (3 * sizeof(double)))
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_resize_nodes: %zu nodes is too many", n_nodes);
    if (!grow((void **)&mesh->xyz, 3 * n_nodes, sizeof(double)))
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_resize_nodes: out of memory for %zu nodes",
                        n_nodes);
    if (with_tags || mesh->node_tag) {
        if (!grow((void **)&mesh->node_tag, n_nodes, sizeof(int64_t)))
            return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_resize_nodes: out of memory");
        for (size_t i = mesh->n_nodes; i < n_nodes; ++i) mesh->node_tag[i] = (int64_t)i + 1;
    }
    mesh->n_nodes = mesh->cap_nodes = n_nodes;
    return CM_OK;
}

/* Capacity for at least `want`: half as much again as now, so that many small reservations
 * (a .msh with one element block per entity) cost amortised linear time, not quadratic. */
static size_t grown(size_t cap, size_t want)
{
    size_t g = cap + cap / 2;
    if (g < 16) g = 16;
    return g > want ? g : want;
}

cm_status cm_mesh_reserve_cells(cm_context *ctx, cm_mesh *mesh, size_t n_cells, size_t n_conn)
{
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_reserve_cells: mesh is NULL");
    if (n_cells > SIZE_MAX / 2 - mesh->n_cells || n_conn > SIZE_MAX / 16 - (size_t)mesh->offset[mesh->n_cells])
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh: %zu cells with %zu nodes is too many", n_cells, n_conn);
    size_t want_cells = mesh->n_cells + n_cells;
    size_t want_conn = (size_t)mesh->offset[mesh->n_cells] + n_conn;
    if (want_cells > mesh->cap_cells) {
        const size_t cap = grown(mesh->cap_cells, want_cells);
        int ok = grow((void **)&mesh->type, cap, sizeof(uint8_t)) &&
                 grow((void **)&mesh->offset, cap + 1, sizeof(int64_t)) &&
                 grow((void **)&mesh->physical, cap, sizeof(int)) &&
                 grow((void **)&mesh->entity, cap, sizeof(int)) &&
                 (!mesh->cell_tag || grow((void **)&mesh->cell_tag, cap, sizeof(int64_t)));
        if (!ok) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh: out of memory for %zu cells", want_cells);
        mesh->cap_cells = cap;
    }
    if (want_conn > mesh->cap_conn) {
        const size_t cap = grown(mesh->cap_conn, want_conn);
        if (!grow((void **)&mesh->conn, cap, sizeof(int64_t)))
            return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh: out of memory for %zu cell nodes", want_conn);
        mesh->cap_conn = cap;
    }
    return CM_OK;
}

cm_status cm_mesh_add_cell(cm_context *ctx, cm_mesh *mesh, cm_cell_type type, const int64_t *nodes,
                           size_t n, int physical, int entity, int64_t tag)
{
    if (!mesh || (!nodes && n > 0))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_add_cell: NULL argument");
    if ((unsigned)type >= CM_CELL_TYPE_COUNT)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_add_cell: unknown cell type %d", (int)type);
    size_t c = mesh->n_cells;
    /* nodes may point into this mesh's own connectivity (copying a cell): growing conn would
     * free it under us, so keep its position and find it again after the reallocation */
    const int64_t *conn0 = mesh->conn;
    const int inside = conn0 && nodes >= conn0 && nodes < conn0 + mesh->cap_conn;
    const size_t at = inside ? (size_t)(nodes - conn0) : 0;
    if (c + 1 > mesh->cap_cells || (size_t)mesh->offset[c] + n > mesh->cap_conn) {
        cm_status s = cm_mesh_reserve_cells(ctx, mesh, 1, n);
        if (s != CM_OK) return s;
        if (inside) nodes = mesh->conn + at;
    }
    if (tag != 0 && !mesh->cell_tag) {
        mesh->cell_tag = malloc(mesh->cap_cells * sizeof(int64_t));
        if (!mesh->cell_tag) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_add_cell: out of memory");
        for (size_t i = 0; i < c; ++i) mesh->cell_tag[i] = (int64_t)i + 1;
    }
    int64_t o = mesh->offset[c];
    memmove(mesh->conn + o, nodes, n * sizeof(int64_t));
    mesh->type[c] = (uint8_t)type;
    mesh->physical[c] = physical;
    mesh->entity[c] = entity;
    if (mesh->cell_tag) mesh->cell_tag[c] = tag != 0 ? tag : (int64_t)c + 1;
    mesh->offset[c + 1] = o + (int64_t)n;
    mesh->n_cells = c + 1;
    return CM_OK;
}

static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

cm_field *cm_mesh_find_field(const cm_mesh *mesh, const char *name, cm_field_location location)
{
    if (!mesh || !name) return NULL;
    for (size_t i = 0; i < mesh->n_fields; ++i)
        if (mesh->fields[i].location == location && strcmp(mesh->fields[i].name, name) == 0)
            return &mesh->fields[i];
    return NULL;
}

cm_status cm_mesh_add_field(cm_context *ctx, cm_mesh *mesh, const char *name,
                            cm_field_location location, int components, double **data)
{
    if (!mesh || !name || components < 1)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_add_field: bad argument");
    size_t n = location == CM_FIELD_NODE ? mesh->n_nodes : mesh->n_cells;
    double *d = calloc(n ? n * (size_t)components : 1, sizeof(double));
    if (!d) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_add_field: out of memory for '%s'", name);
    cm_field *f = cm_mesh_find_field(mesh, name, location);
    if (f) {
        free(f->data);
        f->data = d;
        f->components = components;
    } else {
        char *nm = dup_string(name);
        if (!nm || !grow((void **)&mesh->fields, mesh->n_fields + 1, sizeof(cm_field))) {
            free(nm);
            free(d);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_add_field: out of memory");
        }
        f = &mesh->fields[mesh->n_fields++];
        f->name = nm;
        f->location = location;
        f->components = components;
        f->data = d;
    }
    if (data) *data = d;
    return CM_OK;
}

const char *cm_patch_kind_name(cm_patch_kind kind)
{
    static const char *const names[CM_PATCH_N_KINDS] = {"plain", "symmetry", "empty", "wedge",
                                                        "cyclic", "processor"};
    return (unsigned)kind < CM_PATCH_N_KINDS ? names[kind] : NULL;
}

cm_status cm_mesh_add_group(cm_context *ctx, cm_mesh *mesh, int dim, int tag, const char *name)
{
    if (!mesh || !name) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_add_group: bad argument");
    char *nm = dup_string(name);
    if (!nm || !grow((void **)&mesh->groups, mesh->n_groups + 1, sizeof(cm_mesh_group))) {
        free(nm);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_add_group: out of memory");
    }
    mesh->groups[mesh->n_groups++] = (cm_mesh_group){dim, tag, nm, CM_PATCH_PLAIN};
    return CM_OK;
}

static int *dup_ints(const int *a, int n)
{
    if (n <= 0) return NULL;
    int *d = malloc((size_t)n * sizeof(int));
    if (d) memcpy(d, a, (size_t)n * sizeof(int));
    return d;
}

cm_status cm_mesh_add_entity(cm_context *ctx, cm_mesh *mesh, const cm_mesh_entity *entity)
{
    if (!mesh || !entity) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_add_entity: bad argument");
    cm_mesh_entity e = *entity;
    e.physical = dup_ints(entity->physical, entity->n_physical);
    e.bounding = dup_ints(entity->bounding, entity->n_bounding);
    if ((entity->n_physical > 0 && !e.physical) || (entity->n_bounding > 0 && !e.bounding) ||
        !grow((void **)&mesh->entities, mesh->n_entities + 1, sizeof(cm_mesh_entity))) {
        free_entity(&e);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_add_entity: out of memory");
    }
    mesh->entities[mesh->n_entities++] = e;
    return CM_OK;
}

cm_status cm_mesh_copy(cm_context *ctx, const cm_mesh *mesh, cm_mesh **copy)
{
    if (!mesh || !copy) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_copy: NULL argument");
    *copy = NULL;
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_create(ctx, &m);
    if (s == CM_OK) s = cm_mesh_resize_nodes(ctx, m, mesh->n_nodes, mesh->node_tag != NULL);
    if (s == CM_OK) s = cm_mesh_reserve_cells(ctx, m, mesh->n_cells, (size_t)mesh->offset[mesh->n_cells]);
    if (s == CM_OK) {
        memcpy(m->xyz, mesh->xyz, 3 * mesh->n_nodes * sizeof(double));
        if (mesh->node_tag) memcpy(m->node_tag, mesh->node_tag, mesh->n_nodes * sizeof(int64_t));
    }
    for (size_t c = 0; s == CM_OK && c < mesh->n_cells; ++c)
        s = cm_mesh_add_cell(ctx, m, (cm_cell_type)mesh->type[c], mesh->conn + mesh->offset[c],
                             (size_t)(mesh->offset[c + 1] - mesh->offset[c]), mesh->physical[c],
                             mesh->entity[c], mesh->cell_tag ? mesh->cell_tag[c] : 0);
    for (size_t i = 0; s == CM_OK && i < mesh->n_fields; ++i) {
        const cm_field *f = &mesh->fields[i];
        double *d = NULL;
        s = cm_mesh_add_field(ctx, m, f->name, f->location, f->components, &d);
        size_t n = f->location == CM_FIELD_NODE ? mesh->n_nodes : mesh->n_cells;
        if (s == CM_OK) memcpy(d, f->data, n * (size_t)f->components * sizeof(double));
    }
    for (size_t i = 0; s == CM_OK && i < mesh->n_groups; ++i)
        if ((s = cm_mesh_add_group(ctx, m, mesh->groups[i].dim, mesh->groups[i].tag,
                                   mesh->groups[i].name)) == CM_OK)
            m->groups[m->n_groups - 1].kind = mesh->groups[i].kind;
    for (size_t i = 0; s == CM_OK && i < mesh->n_entities; ++i)
        s = cm_mesh_add_entity(ctx, m, &mesh->entities[i]);
    if (s != CM_OK) {
        cm_mesh_destroy(&m);
        return s;
    }
    m->origin = cm_mesh_origin_retain(mesh->origin);
    *copy = m;
    return CM_OK;
}

size_t cm_mesh_count_dim(const cm_mesh *mesh, int dim)
{
    size_t n = 0;
    for (size_t c = 0; mesh && c < mesh->n_cells; ++c)
        if (cell_table[mesh->type[c]].dim == dim) ++n;
    return n;
}

static cm_status check_polyhedron(cm_context *ctx, const cm_mesh *mesh, size_t c, const char *what)
{
    const int64_t *s = mesh->conn + mesh->offset[c];
    int64_t len = mesh->offset[c + 1] - mesh->offset[c];
    if (len < 1 || s[0] < 4)
        return cm_error(ctx, CM_ERR_FORMAT, "%s: polyhedron cell %zu: needs at least 4 faces", what, c);
    cm_polyhedron_face f = cm_polyhedron_begin(s, len);
    for (; cm_polyhedron_more(&f) && f.n >= 3; cm_polyhedron_next(&f))
        for (int64_t k = 0; k < f.n; ++k)
            if (f.nodes[k] < 0 || (size_t)f.nodes[k] >= mesh->n_nodes)
                return cm_error(ctx, CM_ERR_FORMAT,
                                "%s: polyhedron cell %zu: node index %lld out of range [0, %zu)",
                                what, c, (long long)f.nodes[k], mesh->n_nodes);
    if (f.face < f.n_faces)
        return cm_error(ctx, CM_ERR_FORMAT,
                        "%s: polyhedron cell %zu: face %lld: face stream is inconsistent", what, c,
                        (long long)f.face);
    if (f.at != s + len)
        return cm_error(ctx, CM_ERR_FORMAT, "%s: polyhedron cell %zu: %lld trailing entries", what, c,
                        (long long)(s + len - f.at));
    return CM_OK;
}

cm_status cm_mesh_validate(cm_context *ctx, const cm_mesh *mesh, const char *what)
{
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_validate: mesh is NULL");
    if (!what) what = "mesh";
    for (size_t i = 0; i < 3 * mesh->n_nodes; ++i)
        if (!isfinite(mesh->xyz[i]))
            return cm_error(ctx, CM_ERR_FORMAT, "%s: node %zu (tag %lld): coordinate is not finite",
                            what, i / 3,
                            (long long)(mesh->node_tag ? mesh->node_tag[i / 3] : (int64_t)(i / 3) + 1));
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!info) return cm_error(ctx, CM_ERR_FORMAT, "%s: cell %zu: unknown type", what, c);
        int64_t len = mesh->offset[c + 1] - mesh->offset[c];
        if (mesh->type[c] == CM_CELL_POLYHEDRON) {
            cm_status s = check_polyhedron(ctx, mesh, c, what);
            if (s != CM_OK) return s;
            continue;
        }
        if (info->nodes >= 0 ? len != info->nodes : len < 3)
            return cm_error(ctx, CM_ERR_FORMAT, "%s: cell %zu (%s): expected %d nodes, got %lld",
                            what, c, info->name, info->nodes, (long long)len);
        for (int64_t k = mesh->offset[c]; k < mesh->offset[c + 1]; ++k)
            if (mesh->conn[k] < 0 || (size_t)mesh->conn[k] >= mesh->n_nodes)
                return cm_error(ctx, CM_ERR_FORMAT,
                                "%s: cell %zu (%s): node index %lld out of range [0, %zu)", what, c,
                                info->name, (long long)mesh->conn[k], mesh->n_nodes);
    }
    return CM_OK;
}
