/* cm_mesh_apply_displacement (mesh.h): the nodes move by exactly disp, the "displacement" field
 * is disp, "scaled_jacobian" is cm_mesh_quality of the moved mesh, fields the mesh already has
 * keep their place (the order of a written .msh file's data blocks), and without the flags
 * nothing moves and no quality is added. */
#include "cadmorph/mesh.h"
#include "test_mesh.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static uint64_t seed = 7;

static cm_mesh *tet_block(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    test_block b = {3, 2, 2, {0, 0, 0}, {0.5, 0.5, 0.5}, 1, 0.2};
    CHECK(test_add_block(ctx, m, &b, &seed) == 0);
    return m;
}

static double *random_disp(size_t n)
{
    double *d = malloc(n * 3 * sizeof *d);
    for (size_t i = 0; i < 3 * n; ++i)
        d[i] = 0.05 * test_rand(&seed);
    return d;
}

static size_t field_index(const cm_mesh *m, const char *name)
{
    for (size_t f = 0; f < m->n_fields; ++f)
        if (!strcmp(m->fields[f].name, name)) return f;
    return (size_t)-1;
}

/* move + quality on a mesh without fields */
static void test_move_quality(void)
{
    cm_mesh *m = tet_block();
    size_t n = m->n_nodes;
    double *before = malloc(n * 3 * sizeof *before), *disp = random_disp(n);
    memcpy(before, m->xyz, n * 3 * sizeof *before);
    double *sj = NULL;
    CHECK(cm_mesh_apply_displacement(ctx, m, disp, CM_DISPLACEMENT_MOVE | CM_DISPLACEMENT_QUALITY,
                                     &sj) == CM_OK);
    int moved = 1;
    for (size_t i = 0; i < 3 * n; ++i)
        moved &= m->xyz[i] == before[i] + disp[i];
    CHECK(moved);
    const cm_field *f = cm_mesh_find_field(m, "displacement", CM_FIELD_NODE);
    CHECK(f && f->components == 3 && !memcmp(f->data, disp, n * 3 * sizeof *disp));
    const cm_field *q = cm_mesh_find_field(m, "scaled_jacobian", CM_FIELD_CELL);
    CHECK(q && q->components == 1 && sj == q->data);
    double *ref = malloc(m->n_cells * sizeof *ref);
    CHECK(cm_mesh_quality(ctx, m, ref) == CM_OK);
    CHECK(q && !memcmp(q->data, ref, m->n_cells * sizeof *ref));
    CHECK(m->n_fields == 2 && field_index(m, "displacement") == 0 &&
          field_index(m, "scaled_jacobian") == 1);
    free(before), free(disp), free(ref);
    cm_mesh_destroy(&m);
}

/* the nodes already moved, the fields already there (scaled_jacobian first): no move, both
 * fields replaced where they stand */
static void test_moved_fields_kept(void)
{
    cm_mesh *m = tet_block();
    size_t n = m->n_nodes;
    double *old = NULL, *disp = random_disp(n);
    CHECK(cm_mesh_add_field(ctx, m, "scaled_jacobian", CM_FIELD_CELL, 1, &old) == CM_OK);
    CHECK(cm_mesh_add_field(ctx, m, "other", CM_FIELD_NODE, 1, NULL) == CM_OK);
    CHECK(cm_mesh_add_field(ctx, m, "displacement", CM_FIELD_NODE, 3, NULL) == CM_OK);
    double *xyz = malloc(n * 3 * sizeof *xyz);
    memcpy(xyz, m->xyz, n * 3 * sizeof *xyz);
    double *sj = NULL;
    CHECK(cm_mesh_apply_displacement(ctx, m, disp, CM_DISPLACEMENT_QUALITY, &sj) == CM_OK);
    CHECK(!memcmp(xyz, m->xyz, n * 3 * sizeof *xyz));
    CHECK(m->n_fields == 3 && field_index(m, "scaled_jacobian") == 0 &&
          field_index(m, "other") == 1 && field_index(m, "displacement") == 2);
    const cm_field *f = cm_mesh_find_field(m, "displacement", CM_FIELD_NODE);
    CHECK(f && !memcmp(f->data, disp, n * 3 * sizeof *disp));
    int positive = sj != NULL;
    for (size_t c = 0; sj && c < m->n_cells; ++c)
        positive &= sj[c] > 0;
    CHECK(positive);
    free(disp), free(xyz);
    cm_mesh_destroy(&m);
}

/* move without quality (a surface mesh's record), and the argument checks */
static void test_move_only(void)
{
    cm_mesh *m = tet_block();
    size_t n = m->n_nodes;
    double *disp = random_disp(n), *sj = disp;
    double x0 = m->xyz[0];
    CHECK(cm_mesh_apply_displacement(ctx, m, disp, CM_DISPLACEMENT_MOVE, &sj) == CM_OK);
    CHECK(sj == NULL && m->xyz[0] == x0 + disp[0]);
    CHECK(m->n_fields == 1 && cm_mesh_find_field(m, "scaled_jacobian", CM_FIELD_CELL) == NULL);
    CHECK(cm_mesh_apply_displacement(ctx, m, NULL, 0, NULL) == CM_ERR_ARGUMENT);
    CHECK(cm_mesh_apply_displacement(ctx, NULL, disp, 0, NULL) == CM_ERR_ARGUMENT);
    free(disp);
    cm_mesh_destroy(&m);
}

int main(void)
{
    CHECK(cm_context_create(&ctx) == CM_OK);
    test_move_quality();
    test_moved_fields_kept();
    test_move_only();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
