/* Helpers of the VTK / Medit I/O tests: exact mesh comparison and a text dump that
 * tests/mesh/test_vtk_crosscheck.py compares with what VTK and meshio read. */
#ifndef CADMORPH_TEST_VTK_COMMON_H
#define CADMORPH_TEST_VTK_COMMON_H

#include "cadmorph/mesh.h"
#include "test_util.h"

#include <stdio.h>
#include <string.h>

enum { CMP_FIELDS = 1, CMP_TAGS = 2 };

/* Bit-exact comparison; prints the first difference. Returns 1 if equal. */
static inline int mesh_same(const cm_mesh *a, const cm_mesh *b, int what, const char *label)
{
    if (a->n_nodes != b->n_nodes || a->n_cells != b->n_cells) {
        fprintf(stderr, "%s: %zu/%zu nodes, %zu/%zu cells\n", label, a->n_nodes, b->n_nodes, a->n_cells, b->n_cells);
        return 0;
    }
    if (memcmp(a->xyz, b->xyz, 3 * a->n_nodes * sizeof(double))) {
        for (size_t i = 0; i < 3 * a->n_nodes; ++i)
            if (memcmp(&a->xyz[i], &b->xyz[i], sizeof(double))) {
                fprintf(stderr, "%s: coordinate %zu: %.17g vs %.17g\n", label, i, a->xyz[i], b->xyz[i]);
                break;
            }
        return 0;
    }
    for (size_t c = 0; c < a->n_cells; ++c) {
        if (a->type[c] != b->type[c] || a->offset[c + 1] - a->offset[c] != b->offset[c + 1] - b->offset[c] ||
            memcmp(a->conn + a->offset[c], b->conn + b->offset[c],
                   (size_t)(a->offset[c + 1] - a->offset[c]) * sizeof(int64_t))) {
            fprintf(stderr, "%s: cell %zu differs (type %d vs %d)\n", label, c, a->type[c], b->type[c]);
            return 0;
        }
        if ((what & CMP_TAGS) && (a->physical[c] != b->physical[c] || a->entity[c] != b->entity[c])) {
            fprintf(stderr, "%s: cell %zu: tags %d/%d vs %d/%d\n", label, c, a->physical[c], a->entity[c],
                    b->physical[c], b->entity[c]);
            return 0;
        }
    }
    if (what & CMP_FIELDS) {
        if (a->n_fields != b->n_fields) {
            fprintf(stderr, "%s: %zu vs %zu fields\n", label, a->n_fields, b->n_fields);
            return 0;
        }
        for (size_t i = 0; i < a->n_fields; ++i) {
            const cm_field *fa = &a->fields[i];
            const cm_field *fb = cm_mesh_find_field(b, fa->name, fa->location);
            size_t n = (fa->location == CM_FIELD_NODE ? a->n_nodes : a->n_cells) * (size_t)fa->components;
            if (!fb || fb->components != fa->components || memcmp(fa->data, fb->data, n * sizeof(double))) {
                fprintf(stderr, "%s: field '%s' differs\n", label, fa->name);
                return 0;
            }
        }
    }
    return 1;
}

/* Points as hex floats, then each cell as "vtk_type n ids..." (polyhedra: face stream). */
static inline int mesh_dump(const cm_mesh *m, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) return 0;
    fprintf(f, "points %zu\n", m->n_nodes);
    for (size_t i = 0; i < m->n_nodes; ++i)
        fprintf(f, "%a %a %a\n", m->xyz[3 * i], m->xyz[3 * i + 1], m->xyz[3 * i + 2]);
    fprintf(f, "cells %zu\n", m->n_cells);
    for (size_t c = 0; c < m->n_cells; ++c) {
        fprintf(f, "%d %lld", cm_cell_type_info((cm_cell_type)m->type[c])->vtk,
                (long long)(m->offset[c + 1] - m->offset[c]));
        for (int64_t k = m->offset[c]; k < m->offset[c + 1]; ++k) fprintf(f, " %lld", (long long)m->conn[k]);
        fprintf(f, " %d %d\n", m->physical[c], m->entity[c]);
    }
    return fclose(f) == 0;
}

#endif
