/* What counts as an inverted cell (docs/DESIGN.md, "What counts as an inverted cell"): the
 * cells a solver rejects. A finite-volume solver (OpenFOAM) works on the cell's faces: a cell
 * is unusable when checkMesh finds its volume negative or one of its face pyramids
 * incorrectly oriented, whatever the tets of our decomposition of a polyhedron say (that
 * decomposition can fold on a concave but valid cell). Finite-element solvers reject a tet,
 * hex, wedge or pyramid whose Jacobian changes sign, which the scaled Jacobian measures. */
#define _POSIX_C_SOURCE 200809L
#include "quality_foam_internal.h"
#include "io/origin.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Verdict's value for a collapsed cell (as cm_quality_summarize reads it) */
#define COLLAPSED 1e30

cm_status cm_mesh_invalid_cells(cm_context *ctx, const cm_mesh *mesh, const double *sj, uint8_t *invalid,
                                size_t *count)
{
    if (!mesh || !sj || !count) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_invalid_cells: NULL argument");
    *count = 0;
    const int from_foam = cm_mesh_origin_state(mesh, CM_FORMAT_FOAM) != NULL;
    int has_poly = 0;
    for (size_t c = 0; c < mesh->n_cells && !has_poly; ++c) has_poly = mesh->type[c] == CM_CELL_POLYHEDRON;
    uint8_t *bad = NULL;
    if (from_foam || has_poly) {
        cm_foam_poly *p = NULL;
        cm_status s = cm_foam_of_mesh(ctx, mesh, &p);
        if (s == CM_OK) {
            cm_foam_geom g;
            s = cm_foam_geometry(ctx, p, mesh->xyz, &g);
            if (s == CM_OK) {
                bad = calloc((size_t)(p->n_cells ? p->n_cells : 1), 1);
                if (bad) cm_foam_bad_cells(p, &g, bad);
                cm_foam_geometry_free(&g);
            }
            cm_foam_poly_release(&p);
        }
        if (s == CM_ERR_NOMEM || (s == CM_OK && !bad))
            return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_invalid_cells: out of memory (%zu cells)", mesh->n_cells);
        /* faces that do not match up into a polyMesh (a broken mesh from another format):
         * the polyhedra are then judged by their scaled Jacobian like the other cells */
    }
    size_t k = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        int v = 0;
        if (info && info->dim == 3) {
            if (bad && (from_foam || mesh->type[c] == CM_CELL_POLYHEDRON)) v = bad[k] ? 2 : 0;
            else v = isnan(sj[c]) || fabs(sj[c]) >= COLLAPSED || sj[c] <= 0;
            ++k;
        }
        if (invalid) invalid[c] = (uint8_t)v;
        *count += v != 0;
    }
    free(bad);
    return CM_OK;
}
