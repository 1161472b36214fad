/* The topology builder (mesh/topology.h) on a small hand-built mixed mesh - a hex, a hex
 * written as a polyhedron, a pyramid, a wedge, a tet and a quad on the boundary - checked by
 * invariants: every instance lies on exactly one face, faces are numbered by first instance,
 * owner < neighbour, each face is oriented out of its owner, the boundary faces are those of
 * cm_mesh_boundary_create in the same order, the result does not depend on the thread count;
 * then the faults: a face of three cells and a face of two nodes. */
#include "cadmorph/mesh.h"
#include "test_mesh.h"
#include "test_util.h"
#include "topology.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;

static const double xyz[][3] = {
    {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},       /* 0-3: hex A bottom */
    {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1},       /* 4-7: hex A top */
    {2, 0, 0}, {2, 1, 0}, {2, 0, 1}, {2, 1, 1},       /* 8-11: hex B's other corners */
    {0.5, 0.5, 1.5},                                  /* 12: pyramid apex */
    {1.5, 0, 1.5}, {1.5, 1, 1.5},                     /* 13-14: wedge ridge */
    {0.5, -0.5, 1.2},                                 /* 15: tet apex */
};

/* A tet with its corners in positive order. */
static void add_tet(cm_mesh *m, int64_t a, int64_t b, int64_t c, int64_t d)
{
    int64_t t[4] = {a, b, c, d};
    if (test_tet_volume_at(m->xyz, t) < 0) {
        t[1] = c;
        t[2] = b;
    }
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, t, 4, 0, 0, 0) == CM_OK);
}

static cm_mesh *mixed_mesh(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    const size_t nn = sizeof xyz / sizeof xyz[0];
    CHECK(cm_mesh_resize_nodes(ctx, m, nn, 0) == CM_OK);
    memcpy(m->xyz, xyz, sizeof xyz);
    const int64_t hex_a[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, hex_a, 8, 0, 0, 0) == CM_OK);
    /* a quad on hex A's x = 0 side: a 2D cell adds no face */
    const int64_t quad[4] = {0, 4, 7, 3};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, quad, 4, 1, 0, 0) == CM_OK);
    /* hex B = the hex on x in [1, 2] as a polyhedron, faces outward as the hex table has them */
    const int64_t b[8] = {1, 8, 9, 2, 5, 10, 11, 6};
    const int hf[6][4] = {{0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 3, 2, 1}, {4, 5, 6, 7}};
    int64_t stream[1 + 6 * 5];
    int k = 0;
    stream[k++] = 6;
    for (int f = 0; f < 6; ++f) {
        stream[k++] = 4;
        for (int i = 0; i < 4; ++i) stream[k++] = b[hf[f][i]];
    }
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POLYHEDRON, stream, (size_t)k, 0, 0, 0) == CM_OK);
    const int64_t pyr[5] = {4, 5, 6, 7, 12};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_PYR5, pyr, 5, 0, 0, 0) == CM_OK);
    const int64_t wedge[6] = {5, 10, 13, 6, 11, 14};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_WEDGE6, wedge, 6, 0, 0, 0) == CM_OK);
    add_tet(m, 4, 5, 12, 15); /* on the pyramid's y = 0 side */
    return m;
}

static void centroid(const cm_mesh *m, size_t c, double out[3])
{
    int64_t nodes[64];
    const int n = cm_mesh_cell_nodes(m, c, nodes, 64);
    CHECK(n > 0);
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) out[d] += m->xyz[3 * nodes[i] + d] / n;
}

/* Nodes of face f as its owner sees it; returns their count. */
static int face_of(const cm_mesh *m, const cm_topology *t, size_t f, int64_t *nodes)
{
    const cm_topo_idx inst = t->face_inst[f], c = t->owner[f];
    const int64_t local = inst - t->inst_off[c];
    const int64_t *conn = m->conn + m->offset[c];
    if (m->type[c] == CM_CELL_POLYHEDRON) {
        cm_polyhedron_face p = cm_polyhedron_begin(conn, m->offset[c + 1] - m->offset[c]);
        while (cm_polyhedron_more(&p) && p.face < local) cm_polyhedron_next(&p);
        for (int64_t i = 0; i < p.n; ++i) nodes[i] = p.nodes[i];
        return (int)p.n;
    }
    /* the standard types: from the boundary of a mesh holding only this cell */
    cm_mesh *one = NULL;
    CHECK(cm_mesh_create(ctx, &one) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, one, m->n_nodes, 0) == CM_OK);
    memcpy(one->xyz, m->xyz, m->n_nodes * 3 * sizeof *m->xyz);
    CHECK(cm_mesh_add_cell(ctx, one, (cm_cell_type)m->type[c], conn, (size_t)(m->offset[c + 1] - m->offset[c]), 0, 0,
                           0) == CM_OK);
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, one, &b) == CM_OK);
    int n = 0;
    if (b && (size_t)local < b->n_faces) {
        n = (int)(b->face_offset[local + 1] - b->face_offset[local]);
        memcpy(nodes, b->face_nodes + b->face_offset[local], (size_t)n * sizeof *nodes);
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&one);
    return n;
}

/* Area vector (Newell) and centre of a face. */
static void face_geometry(const cm_mesh *m, const int64_t *v, int n, double a[3], double fc[3])
{
    a[0] = a[1] = a[2] = fc[0] = fc[1] = fc[2] = 0;
    for (int i = 0; i < n; ++i) {
        const double *p = m->xyz + 3 * v[i], *q = m->xyz + 3 * v[(i + 1) % n];
        a[0] += 0.5 * (p[1] * q[2] - p[2] * q[1]);
        a[1] += 0.5 * (p[2] * q[0] - p[0] * q[2]);
        a[2] += 0.5 * (p[0] * q[1] - p[1] * q[0]);
        for (int d = 0; d < 3; ++d) fc[d] += p[d] / n;
    }
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void test_mixed(void)
{
    cm_mesh *m = mixed_mesh();
    cm_topology t;
    cm_topology_problem why;
    CHECK(cm_topology_build(m, CM_TOPOLOGY_MAX_FACE_NODES, 1, &t, &why) == CM_OK);
    CHECK(why.what == CM_TOPOLOGY_OK);
    CHECK(cm_topology_faces(&t) == CM_OK);
    CHECK(t.n_nonmanifold == 0);
    CHECK(cm_topology_first_overshared(&t) == -1);
    /* instances: the faces of the 3D cells, none of the quad */
    const int64_t faces_per_cell[6] = {6, 0, 6, 5, 5, 4};
    size_t expect = 0;
    CHECK(m->n_cells == 6);
    for (size_t c = 0; c < m->n_cells; ++c) {
        const int64_t nf = t.inst_off[c + 1] - t.inst_off[c];
        CHECK(nf == faces_per_cell[c]);
        expect += (size_t)nf;
        for (int64_t i = t.inst_off[c]; i < t.inst_off[c + 1]; ++i) CHECK(t.inst_cell[i] == (cm_topo_idx)c);
    }
    CHECK(t.n_inst == expect);
    /* every instance on one face: a face of two cells counts twice */
    size_t seen = 0, interior = 0;
    for (size_t f = 0; f < t.n_faces; ++f) {
        CHECK(f == 0 || t.face_inst[f] > t.face_inst[f - 1]);
        CHECK(t.owner[f] == t.inst_cell[t.face_inst[f]]);
        seen += t.neighbour[f] >= 0 ? 2 : 1;
        if (t.neighbour[f] < 0) continue;
        ++interior;
        CHECK(t.owner[f] < t.neighbour[f]);
        CHECK(t.mate[t.mate[t.face_inst[f]]] == t.face_inst[f]);
    }
    CHECK(seen == t.n_inst);
    /* hex A | polyhedron, hex A | pyramid, polyhedron | wedge, pyramid | tet */
    CHECK(interior == 4);
    /* each face found by its nodes in any order; oriented out of its owner */
    for (size_t f = 0; f < t.n_faces; ++f) {
        int64_t v[8], key[8];
        const int n = face_of(m, &t, f, v);
        CHECK(n >= 3 && n <= 4);
        for (int i = 0; i < n; ++i) key[i] = v[n - 1 - i];
        CHECK(cm_topology_find(&t, m, key, n) == (int64_t)f);
        double a[3], fc[3], co[3], toward[3];
        face_geometry(m, v, n, a, fc);
        centroid(m, (size_t)t.owner[f], co);
        if (t.neighbour[f] >= 0) centroid(m, (size_t)t.neighbour[f], toward);
        else memcpy(toward, fc, sizeof fc);
        const double dir[3] = {toward[0] - co[0], toward[1] - co[1], toward[2] - co[2]};
        CHECK_MSG(dot3(a, dir) > 0, "face %zu points into its owner %d", f, (int)t.owner[f]);
    }
    const int64_t missing[3] = {0, 1, 15};
    int64_t probe[3];
    memcpy(probe, missing, sizeof probe);
    CHECK(cm_topology_find(&t, m, probe, 3) == -1);
    const int64_t outside[3] = {0, 1, 99};
    memcpy(probe, outside, sizeof probe);
    CHECK(cm_topology_find(&t, m, probe, 3) == -1);
    /* the boundary extraction: the faces without a neighbour, in the same order */
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    size_t k = 0;
    for (size_t f = 0; b && f < t.n_faces; ++f) {
        if (t.neighbour[f] >= 0) continue;
        int64_t v[8];
        const int n = face_of(m, &t, f, v);
        CHECK(k < b->n_faces && b->face_cell[k] == t.owner[f]);
        CHECK(k < b->n_faces && b->face_offset[k + 1] - b->face_offset[k] == n);
        CHECK(k < b->n_faces && !memcmp(b->face_nodes + b->face_offset[k], v, (size_t)n * sizeof *v));
        ++k;
    }
    CHECK(b && k == b->n_faces);
    CHECK(b && b->n_components == 1);
    cm_mesh_boundary_destroy(&b);
    /* the same with 4 threads */
    cm_topology t4;
    CHECK(cm_topology_build(m, CM_TOPOLOGY_MAX_FACE_NODES, 4, &t4, &why) == CM_OK);
    CHECK(cm_topology_faces(&t4) == CM_OK);
    CHECK(t4.n_faces == t.n_faces && t4.n_inst == t.n_inst);
    CHECK(!memcmp(t4.mate, t.mate, t.n_inst * sizeof *t.mate));
    CHECK(!memcmp(t4.neighbour, t.neighbour, t.n_faces * sizeof *t.neighbour));
    cm_topology_free(&t4);
    cm_topology_free(&t);
    cm_mesh_destroy(&m);
}

/* A copy of the pyramid makes its faces three-cell ones; the first such instance in cell
 * order is the copy's first shared face. A polyhedron face of two nodes is refused and the
 * instances before it are still matched. */
static void test_faults(void)
{
    cm_mesh *m = mixed_mesh();
    const int64_t pyr[5] = {4, 5, 6, 7, 12};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_PYR5, pyr, 5, 0, 0, 0) == CM_OK);
    const size_t copy = m->n_cells - 1;
    cm_topology t;
    cm_topology_problem why;
    CHECK(cm_topology_build(m, CM_TOPOLOGY_MAX_FACE_NODES, 1, &t, &why) == CM_OK);
    CHECK(cm_topology_faces(&t) == CM_OK);
    CHECK(t.n_nonmanifold == 2); /* the base (hex A) and the y = 0 side (tet) */
    const int64_t third = cm_topology_first_overshared(&t);
    CHECK(third >= 0 && (size_t)t.inst_cell[third] == copy);
    cm_topology_free(&t);

    const int64_t bad[] = {2, 3, 0, 1, 2, 2, 0, 1}; /* faces of 3 and 2 nodes */
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POLYHEDRON, bad, sizeof bad / sizeof bad[0], 0, 0, 0) == CM_OK);
    CHECK(cm_topology_build(m, CM_TOPOLOGY_MAX_FACE_NODES, 1, &t, &why) == CM_ERR_FORMAT);
    CHECK(why.what == CM_TOPOLOGY_BAD_FACE && why.cell == copy + 1 && why.face == 1 && why.n == 2);
    CHECK(t.n_inst == (size_t)t.inst_off[copy + 1] + 1);
    CHECK(cm_topology_faces(&t) == CM_OK);
    CHECK(t.n_nonmanifold == 2 && cm_topology_first_overshared(&t) == third);
    cm_topology_free(&t);
    cm_mesh_destroy(&m);
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    CHECK(cm_context_create(&ctx) == CM_OK);
    test_mixed();
    test_faults();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
