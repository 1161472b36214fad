/* gmsh .msh helpers shared by reader and writer: the gmsh -> VTK node permutations and the
 * tag -> index map. */
#include "msh_internal.h"

#include <stdlib.h>
#include <string.h>

/* vtk[i] = gmsh[perm[i]]. Derived by matching each higher-order node to the corners it is
 * the centroid of, in gmsh's reference element (gmsh.model.mesh.getElementProperties) and in
 * VTK's (vtkCell::GetParametricCoords); tests/data/msh/check_perm.py recomputes them.
 * The ones meshio also has (tet10, hex20, hex27, pyramid13) agree with it.
 * Gmsh numbers edges differently from VTK (e.g. tet: gmsh edge 5 is 1-3, VTK's 8 is 0-3...),
 * so each type needs its own table; the other linear and 2D quadratic types agree. */
static const int perm_tet10[10] = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
static const int perm_hex20[20] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15};
static const int perm_hex27[27] = {0,  1,  2,  3,  4,  5,  6,  7,  8,  11, 13, 9,  16, 18,
                                   19, 17, 10, 12, 14, 15, 22, 23, 21, 24, 20, 25, 26};
/* Wedges are mirrored as well: gmsh winds the triangle (0,1,2) towards (3,4,5), VTK winds it
 * away (vtkWedge's documentation; meshio and gmsh's own VTK export swap 1<->2, 4<->5 too),
 * even though vtkWedge's parametric coordinates follow gmsh. Without the mirror every gmsh
 * prism reads as inverted. tests/data/msh/check_perm.py recomputes these with the mirror. */
static const int perm_wedge6[6] = {0, 2, 1, 3, 5, 4};
static const int perm_wedge15[15] = {0, 2, 1, 3, 5, 4, 7, 9, 6, 13, 14, 12, 8, 11, 10};
static const int perm_wedge18[18] = {0, 2, 1, 3, 5, 4, 7, 9, 6, 13, 14, 12, 8, 11, 10, 16, 17, 15};
static const int perm_pyr13[13] = {0, 1, 2, 3, 4, 5, 8, 10, 6, 7, 9, 11, 12};
static const int perm_pyr14[14] = {0, 1, 2, 3, 4, 5, 8, 10, 6, 7, 9, 11, 12, 13};

const int *cm_msh_perm(cm_cell_type type)
{
    switch (type) {
    case CM_CELL_TET10: return perm_tet10;
    case CM_CELL_HEX20: return perm_hex20;
    case CM_CELL_HEX27: return perm_hex27;
    case CM_CELL_WEDGE6: return perm_wedge6;
    case CM_CELL_WEDGE15: return perm_wedge15;
    case CM_CELL_WEDGE18: return perm_wedge18;
    case CM_CELL_PYR13: return perm_pyr13;
    case CM_CELL_PYR14: return perm_pyr14;
    default: return NULL;
    }
}

static uint64_t hash_tag(int64_t tag)
{
    uint64_t x = (uint64_t)tag;
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    return x;
}

cm_status cm_msh_tagmap_build(cm_context *ctx, const int64_t *tags, size_t n, cm_msh_tagmap *map,
                              size_t *dup_at)
{
    memset(map, 0, sizeof *map);
    if (n == 0) return CM_OK;
    int64_t lo = tags[0], hi = tags[0];
    for (size_t i = 1; i < n; ++i) {
        if (tags[i] < lo) lo = tags[i];
        if (tags[i] > hi) hi = tags[i];
    }
    /* Dense when the table costs at most a few times the tags themselves. */
    uint64_t range = (uint64_t)hi - (uint64_t)lo + 1;
    if (range != 0 && range <= 4 * (uint64_t)n + 1024) {
        map->slot = malloc((size_t)range * sizeof(int64_t));
        if (!map->slot) return cm_error(ctx, CM_ERR_NOMEM, "msh: out of memory for the tag map");
        memset(map->slot, 0xff, (size_t)range * sizeof(int64_t));
        map->min = lo;
        map->dense_len = (size_t)range;
        for (size_t i = 0; i < n; ++i) {
            int64_t *s = &map->slot[tags[i] - lo];
            if (*s >= 0) {
                *dup_at = i;
                cm_msh_tagmap_free(map);
                return CM_ERR_FORMAT;
            }
            *s = (int64_t)i;
        }
        return CM_OK;
    }
    size_t cap = 16;
    while (cap < 2 * n) cap *= 2;
    map->slot = malloc(cap * 2 * sizeof(int64_t));
    if (!map->slot) return cm_error(ctx, CM_ERR_NOMEM, "msh: out of memory for the tag map");
    for (size_t i = 0; i < cap; ++i) map->slot[2 * i] = INT64_MIN;
    map->hash_cap = cap;
    for (size_t i = 0; i < n; ++i) {
        size_t h = (size_t)hash_tag(tags[i]) & (cap - 1);
        while (map->slot[2 * h] != INT64_MIN) {
            if (map->slot[2 * h] == tags[i]) {
                *dup_at = i;
                cm_msh_tagmap_free(map);
                return CM_ERR_FORMAT;
            }
            h = (h + 1) & (cap - 1);
        }
        map->slot[2 * h] = tags[i];
        map->slot[2 * h + 1] = (int64_t)i;
    }
    return CM_OK;
}

int64_t cm_msh_tagmap_find(const cm_msh_tagmap *map, int64_t tag)
{
    if (map->dense_len) {
        uint64_t k = (uint64_t)tag - (uint64_t)map->min;
        return k < map->dense_len ? map->slot[k] : -1;
    }
    if (!map->hash_cap || tag == INT64_MIN) return -1;
    size_t h = (size_t)hash_tag(tag) & (map->hash_cap - 1);
    while (map->slot[2 * h] != INT64_MIN) {
        if (map->slot[2 * h] == tag) return map->slot[2 * h + 1];
        h = (h + 1) & (map->hash_cap - 1);
    }
    return -1;
}

void cm_msh_tagmap_free(cm_msh_tagmap *map)
{
    free(map->slot);
    memset(map, 0, sizeof *map);
}
