/* Boundary extraction and components on meshes built in code: structured hex blocks, the same
 * blocks split into tets (and tet10), disjoint blocks, duplicates and non-manifold faces,
 * single higher-order cells, wedge, pyramid and polyhedron. */
#include "cadmorph/mesh.h"
#include "test_mesh.h"
#include "test_util.h"

#define _USE_MATH_DEFINES
#include <math.h>
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;

/* An n x n x n block of unit cubes at offset x0 (hexes, or 6 Kuhn tets each) appended to m. */
static void add_block(cm_mesh *m, int n, double x0, int tets)
{
    const test_block blk = {n, n, n, {x0, 0, 0}, {1, 1, 1}, tets, 0.0};
    uint64_t seed = 1; /* no jitter: unused */
    CHECK(test_add_block(ctx, m, &blk, &seed) >= 0);
}

static void add_hex_block(cm_mesh *m, int n, double x0) { add_block(m, n, x0, 0); }
static void add_tet_block(cm_mesh *m, int n) { add_block(m, n, 0, 1); }

static void cell_centroid(const cm_mesh *m, size_t c, double cc[3])
{
    const cm_cell_info *info = cm_cell_type_info((cm_cell_type)m->type[c]);
    const int64_t *conn = m->conn + m->offset[c];
    int n = 0;
    cc[0] = cc[1] = cc[2] = 0;
    if (m->type[c] == CM_CELL_POLYHEDRON) {
        const int64_t *s = conn + 1;
        for (int64_t f = 0; f < conn[0]; ++f, s += 1 + s[0])
            for (int64_t i = 0; i < s[0]; ++i, ++n)
                for (int d = 0; d < 3; ++d) cc[d] += m->xyz[3 * s[1 + i] + d];
    } else {
        for (int i = 0; i < info->corners; ++i, ++n)
            for (int d = 0; d < 3; ++d) cc[d] += m->xyz[3 * conn[i] + d];
    }
    for (int d = 0; d < 3; ++d) cc[d] /= n;
}

/* Each boundary face's area vector points away from its cell's centroid; the area vectors
 * of a closed surface sum to zero. Returns the number of faces that point inward. */
static int check_orientation(const cm_mesh *m, const cm_mesh_boundary *b, double *sum_norm)
{
    double sum[3] = {0, 0, 0}, total = 0;
    int inward = 0;
    for (size_t f = 0; f < b->n_faces; ++f) {
        const int64_t *v = b->face_nodes + b->face_offset[f];
        const int64_t n = b->face_offset[f + 1] - b->face_offset[f];
        double a[3] = {0, 0, 0}, fc[3] = {0, 0, 0}, cc[3];
        for (int64_t i = 0; i < n; ++i) { /* Newell's formula */
            const double *p = m->xyz + 3 * v[i], *q = m->xyz + 3 * v[(i + 1) % n];
            a[0] += 0.5 * (p[1] * q[2] - p[2] * q[1]);
            a[1] += 0.5 * (p[2] * q[0] - p[0] * q[2]);
            a[2] += 0.5 * (p[0] * q[1] - p[1] * q[0]);
            for (int d = 0; d < 3; ++d) fc[d] += p[d] / (double)n;
        }
        cell_centroid(m, (size_t)b->face_cell[f], cc);
        if (a[0] * (fc[0] - cc[0]) + a[1] * (fc[1] - cc[1]) + a[2] * (fc[2] - cc[2]) <= 0) ++inward;
        for (int d = 0; d < 3; ++d) sum[d] += a[d];
        total += sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    }
    *sum_norm = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]) / (total > 0 ? total : 1);
    return inward;
}

static int on_box_surface(const double *p, double lo, double hi)
{
    for (int d = 0; d < 3; ++d)
        if (fabs(p[d] - lo) < 1e-12 || fabs(p[d] - hi) < 1e-12) return 1;
    return 0;
}

static void test_hex_block(void)
{
    for (int n = 1; n <= 5; n += 2) {
        cm_mesh *m = NULL;
        CHECK(cm_mesh_create(ctx, &m) == CM_OK);
        add_hex_block(m, n, 0);
        cm_mesh_boundary *b = NULL;
        CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
        CHECK_MSG(b->n_faces == (size_t)(6 * n * n), "n=%d: %zu faces", n, b->n_faces);
        const size_t surf = (size_t)((n + 1) * (n + 1) * (n + 1) - (n - 1) * (n - 1) * (n - 1));
        CHECK_MSG(b->n_nodes == surf, "n=%d: %zu boundary nodes, expected %zu", n, b->n_nodes, surf);
        int all_on_surface = 1;
        for (size_t i = 0; i < b->n_nodes; ++i) {
            all_on_surface &= on_box_surface(m->xyz + 3 * b->nodes[i], 0, n);
            if (i) all_on_surface &= b->nodes[i] > b->nodes[i - 1];
        }
        CHECK(all_on_surface);
        CHECK(b->n_components == 1 && b->n_nonmanifold == 0 && b->n_duplicate == 0);
        double sum;
        CHECK(check_orientation(m, b, &sum) == 0);
        CHECK_NEAR(sum, 0.0, 1e-14);
        cm_mesh_boundary_destroy(&b);
        CHECK(b == NULL);
        cm_mesh_destroy(&m);
    }
    cm_mesh_boundary_destroy(NULL);
}

static void test_tet_block_and_tet10(void)
{
    const int n = 4;
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    add_tet_block(m, n);
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    CHECK_MSG(b->n_faces == (size_t)(12 * n * n), "%zu faces", b->n_faces);
    CHECK(b->n_nodes == (size_t)((n + 1) * (n + 1) * (n + 1) - (n - 1) * (n - 1) * (n - 1)));
    CHECK(b->n_components == 1 && b->n_nonmanifold == 0 && b->n_duplicate == 0);
    double sum;
    CHECK(check_orientation(m, b, &sum) == 0);
    CHECK_NEAR(sum, 0.0, 1e-14);
    cm_mesh_boundary_destroy(&b);

    /* tet10: mid-edge nodes (shared between cells through a small edge table) */
    cm_mesh *q = NULL;
    CHECK(cm_mesh_create(ctx, &q) == CM_OK);
    const size_t nv = m->n_nodes;
    CHECK(cm_mesh_resize_nodes(ctx, q, nv, 0) == CM_OK);
    memcpy(q->xyz, m->xyz, nv * 3 * sizeof(double));
    int64_t *edge_a = malloc(m->n_cells * 6 * sizeof *edge_a), *edge_b = malloc(m->n_cells * 6 * sizeof *edge_b);
    size_t ne = 0;
    static const int tet_edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
    for (size_t c = 0; c < m->n_cells; ++c) {
        const int64_t *t = m->conn + m->offset[c];
        int64_t t10[10];
        memcpy(t10, t, 4 * sizeof *t10);
        for (int e = 0; e < 6; ++e) {
            int64_t a = t[tet_edges[e][0]], bb = t[tet_edges[e][1]];
            if (a > bb) {
                int64_t s = a;
                a = bb;
                bb = s;
            }
            size_t k = 0;
            while (k < ne && !(edge_a[k] == a && edge_b[k] == bb)) ++k;
            if (k == ne) {
                edge_a[ne] = a;
                edge_b[ne++] = bb;
                CHECK(cm_mesh_resize_nodes(ctx, q, nv + ne, 0) == CM_OK);
                for (int d = 0; d < 3; ++d)
                    q->xyz[3 * (nv + k) + d] = 0.5 * (q->xyz[3 * a + d] + q->xyz[3 * bb + d]);
            }
            t10[4 + e] = (int64_t)(nv + k);
        }
        CHECK(cm_mesh_add_cell(ctx, q, CM_CELL_TET10, t10, 10, 0, 0, 0) == CM_OK);
    }
    free(edge_a);
    free(edge_b);
    CHECK(cm_mesh_boundary_create(ctx, q, &b) == CM_OK);
    CHECK(b->n_faces == (size_t)(12 * n * n));
    size_t expected = 0;
    for (size_t v = 0; v < q->n_nodes; ++v) expected += on_box_surface(q->xyz + 3 * v, 0, n);
    CHECK_MSG(b->n_nodes == expected, "%zu boundary nodes of tet10, %zu on the surface", b->n_nodes, expected);
    int ok = 1;
    for (size_t i = 0; i < b->n_nodes; ++i) ok &= on_box_surface(q->xyz + 3 * b->nodes[i], 0, n);
    CHECK(ok);
    CHECK(expected > (size_t)((n + 1) * (n + 1) * (n + 1) - (n - 1) * (n - 1) * (n - 1)));
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&q);
    cm_mesh_destroy(&m);
}

static void test_components(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    add_hex_block(m, 2, 0);
    add_hex_block(m, 3, 10);
    /* a boundary triangle (dim 2) is not a volume cell */
    const int64_t tri[3] = {0, 1, 3};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, tri, 3, 0, 0, 0) == CM_OK);
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    CHECK(b->n_components == 2);
    CHECK(b->n_faces == 6 * 4 + 6 * 9);
    int ok = 1;
    for (size_t c = 0; c < 8; ++c) ok &= b->cell_component[c] == 0;
    for (size_t c = 8; c < 8 + 27; ++c) ok &= b->cell_component[c] == 1;
    CHECK(ok);
    CHECK(b->cell_component[m->n_cells - 1] == -1);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

static void test_duplicate_and_nonmanifold(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    add_hex_block(m, 3, 0);
    /* duplicate of the centre cell (13 of 27): its 6 faces are now shared by 3 cells */
    int64_t h[8];
    memcpy(h, m->conn + m->offset[13], sizeof h);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, h, 8, 0, 0, 0) == CM_OK);
    cm_mesh_boundary *b = NULL;
    cm_status s = cm_mesh_boundary_create(ctx, m, &b);
    CHECK(s == CM_WARNING);
    CHECK(b != NULL);
    if (b) {
        CHECK_MSG(b->n_duplicate == 1, "%zu duplicates", b->n_duplicate);
        CHECK_MSG(b->n_nonmanifold == 6, "%zu non-manifold", b->n_nonmanifold);
        CHECK(b->n_faces == 54 && b->n_components == 1);
    }
    const char *msg = cm_context_message(ctx);
    CHECK_MSG(strstr(msg, "6 non-manifold") && strstr(msg, "1 duplicate"), "message: %s", msg);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);

    /* a single face shared by three cells: two more hexes on top of one top face of a block */
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    add_hex_block(m, 1, 0);
    const size_t v0 = m->n_nodes;
    CHECK(cm_mesh_resize_nodes(ctx, m, v0 + 8, 0) == CM_OK);
    for (int t = 0; t < 2; ++t)
        for (int a = 0; a < 4; ++a) {
            double *p = m->xyz + 3 * (v0 + 4 * t + a);
            memcpy(p, m->xyz + 3 * (4 + a), 3 * sizeof(double));
            p[2] = 2.0 + t; /* different tops: not duplicates */
        }
    for (int t = 0; t < 2; ++t) {
        int64_t top[8] = {4, 5, 6, 7, (int64_t)v0 + 4 * t, (int64_t)v0 + 4 * t + 1, (int64_t)v0 + 4 * t + 2,
                          (int64_t)v0 + 4 * t + 3};
        CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, top, 8, 0, 0, 0) == CM_OK);
    }
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_WARNING);
    if (b) {
        CHECK(b->n_nonmanifold == 1 && b->n_duplicate == 0);
        CHECK(b->n_components == 1);
        CHECK(b->n_faces == 5 + 5 + 5);
    }
    msg = cm_context_message(ctx);
    CHECK_MSG(strstr(msg, "1 non-manifold") && strstr(msg, "0 duplicate"), "message: %s", msg);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* One cell of the given type with coordinates x; checks faces, orientation, node count. */
static void single_cell(cm_cell_type type, const double *x, size_t n_nodes, const int64_t *conn, size_t n_conn,
                        size_t faces, size_t boundary_nodes)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, n_nodes, 0) == CM_OK);
    memcpy(m->xyz, x, n_nodes * 3 * sizeof(double));
    CHECK(cm_mesh_add_cell(ctx, m, type, conn, n_conn, 0, 0, 0) == CM_OK);
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    if (b) {
        CHECK_MSG(b->n_faces == faces, "%s: %zu faces", cm_cell_type_info(type)->name, b->n_faces);
        CHECK_MSG(b->n_nodes == boundary_nodes, "%s: %zu boundary nodes", cm_cell_type_info(type)->name,
                  b->n_nodes);
        double sum;
        CHECK_MSG(check_orientation(m, b, &sum) == 0, "%s: inward faces", cm_cell_type_info(type)->name);
        CHECK_NEAR(sum, 0.0, 1e-14);
        CHECK(b->n_components == 1);
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

static void test_single_cells(void)
{
    /* hex27 on the unit cube at VTK's parametric positions: every node but the centre (26)
     * lies on a face */
    static const double hx[27][3] = {
        {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1},
        {0, 1, 1}, {.5, 0, 0}, {1, .5, 0}, {.5, 1, 0}, {0, .5, 0}, {.5, 0, 1}, {1, .5, 1},
        {.5, 1, 1}, {0, .5, 1}, {0, 0, .5}, {1, 0, .5}, {1, 1, .5}, {0, 1, .5}, {0, .5, .5},
        {1, .5, .5}, {.5, 0, .5}, {.5, 1, .5}, {.5, .5, 0}, {.5, .5, 1}, {.5, .5, .5}};
    int64_t id[27];
    for (int i = 0; i < 27; ++i) id[i] = i;
    single_cell(CM_CELL_HEX27, &hx[0][0], 27, id, 27, 6, 26);
    single_cell(CM_CELL_HEX20, &hx[0][0], 27, id, 20, 6, 20);
    single_cell(CM_CELL_HEX8, &hx[0][0], 27, id, 8, 6, 8);
    /* VTK wedge (0-1-2 outward), then wedge18: 15 + 3 quad-face centres, all on faces */
    const double s3 = sqrt(3.0);
    const double wx[18][3] = {{0, 0, 0}, {.5, s3 / 2, 0}, {1, 0, 0}, {0, 0, 1}, {.5, s3 / 2, 1}, {1, 0, 1},
                              {.25, s3 / 4, 0}, {.75, s3 / 4, 0}, {.5, 0, 0}, {.25, s3 / 4, 1},
                              {.75, s3 / 4, 1}, {.5, 0, 1}, {0, 0, .5}, {.5, s3 / 2, .5}, {1, 0, .5},
                              {.25, s3 / 4, .5}, {.75, s3 / 4, .5}, {.5, 0, .5}};
    CHECK(cm_quality_scaled_jacobian(CM_CELL_WEDGE6, &wx[0][0]) > 0.99);
    single_cell(CM_CELL_WEDGE6, &wx[0][0], 18, id, 6, 5, 6);
    single_cell(CM_CELL_WEDGE18, &wx[0][0], 18, id, 18, 5, 18);
    const double px[14][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {.5, .5, .7}, {.5, 0, 0}, {1, .5, 0},
                              {.5, 1, 0}, {0, .5, 0}, {.25, .25, .35}, {.75, .25, .35}, {.75, .75, .35},
                              {.25, .75, .35}, {.5, .5, 0}};
    single_cell(CM_CELL_PYR5, &px[0][0], 14, id, 5, 5, 5);
    single_cell(CM_CELL_PYR14, &px[0][0], 14, id, 14, 5, 14);
    /* the unit cube as a polyhedron (VTK's hex faces) */
    const int64_t cube[] = {6, 4, 0, 4, 7, 3, 4, 1, 2, 6, 5, 4, 0, 1, 5, 4,
                            4, 3, 7, 6, 2, 4, 0, 3, 2, 1, 4, 4, 5, 6, 7};
    single_cell(CM_CELL_POLYHEDRON, &hx[0][0], 27, cube, sizeof cube / sizeof *cube, 6, 8);
}

/* Two polyhedral cubes sharing a face match like hexes do. */
static void test_polyhedra(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    cm_mesh *hexes = NULL; /* two unit cubes side by side, their hexes made polyhedra */
    CHECK(cm_mesh_create(ctx, &hexes) == CM_OK);
    const test_block blk = {2, 1, 1, {0, 0, 0}, {1, 1, 1}, 0, 0.0};
    uint64_t seed = 1;
    CHECK(test_add_block(ctx, hexes, &blk, &seed) == 0);
    CHECK(cm_mesh_resize_nodes(ctx, m, hexes->n_nodes, 0) == CM_OK);
    memcpy(m->xyz, hexes->xyz, 3 * hexes->n_nodes * sizeof(double));
    for (int i = 0; i < 2; ++i) {
        const int64_t *h = hexes->conn + hexes->offset[i];
        const int64_t s[] = {6, 4, h[0], h[4], h[7], h[3], 4, h[1], h[2], h[6], h[5], 4, h[0], h[1], h[5], h[4],
                             4, h[3], h[7], h[6], h[2], 4, h[0], h[3], h[2], h[1], 4, h[4], h[5], h[6], h[7]};
        CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POLYHEDRON, s, sizeof s / sizeof *s, 0, 0, 0) == CM_OK);
    }
    cm_mesh_destroy(&hexes);
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    if (b) {
        CHECK(b->n_faces == 10 && b->n_components == 1 && b->n_nodes == 12);
        double sum;
        CHECK(check_orientation(m, b, &sum) == 0);
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* A fan of 2m tets around node 0 (the smallest index): node 0's bucket holds 6m faces, more
 * than the pairwise matcher takes, so the sorting path runs. */
static void test_large_bucket(void)
{
    const int ring = 20;
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, (size_t)ring + 3, 0) == CM_OK);
    double *x = m->xyz;
    x[0] = x[1] = x[2] = 0;
    for (int i = 0; i < ring; ++i) {
        x[3 * (1 + i)] = cos(2 * M_PI * i / ring);
        x[3 * (1 + i) + 1] = sin(2 * M_PI * i / ring);
        x[3 * (1 + i) + 2] = 0;
    }
    const int64_t top = ring + 1, bottom = ring + 2;
    x[3 * top] = x[3 * top + 1] = x[3 * bottom] = x[3 * bottom + 1] = 0;
    x[3 * top + 2] = 1;
    x[3 * bottom + 2] = -1;
    for (int i = 0; i < ring; ++i) {
        const int64_t a = 1 + i, b = 1 + (i + 1) % ring;
        const int64_t t1[4] = {0, a, b, top}, t2[4] = {0, b, a, bottom};
        CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, t1, 4, 0, 0, 0) == CM_OK);
        CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, t2, 4, 0, 0, 0) == CM_OK);
    }
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    if (b) {
        CHECK_MSG(b->n_faces == (size_t)(2 * ring), "%zu faces", b->n_faces);
        CHECK(b->n_nodes == (size_t)ring + 2 && b->nodes[0] == 1);
        CHECK(b->n_components == 1 && b->n_nonmanifold == 0);
        double sum;
        CHECK(check_orientation(m, b, &sum) == 0);
        CHECK_NEAR(sum, 0.0, 1e-14);
    }
    cm_mesh_boundary_destroy(&b);
    /* the same fan twice over: every face doubled, each copy a duplicate */
    const size_t nc = m->n_cells;
    for (size_t c = 0; c < nc; ++c)
        CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, m->conn + m->offset[c], 4, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_WARNING);
    if (b) {
        CHECK_MSG(b->n_duplicate == nc, "%zu duplicates", b->n_duplicate);
        CHECK(b->n_faces == 0);
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* A real gmsh tet mesh of a 1 x 1 x 0.5 box (meshio-written VTU): the boundary is a closed
 * triangulated sphere (V = 2 + F/2), all its nodes on the box faces, one component. */
static void test_gmsh_box(const char *data_dir)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/quality/box_tets.vtu", data_dir);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    if (s < 0) return;
    cm_mesh_boundary *b = NULL;
    CHECK(cm_mesh_boundary_create(ctx, m, &b) == CM_OK);
    if (b) {
        CHECK(b->n_faces > 100);
        CHECK_MSG(b->n_nodes == 2 + b->n_faces / 2, "%zu nodes, %zu faces", b->n_nodes, b->n_faces);
        int ok = 1;
        for (size_t i = 0; i < b->n_nodes; ++i) {
            const double *p = m->xyz + 3 * b->nodes[i];
            ok &= fabs(p[0]) < 1e-9 || fabs(p[0] - 1) < 1e-9 || fabs(p[1]) < 1e-9 || fabs(p[1] - 1) < 1e-9 ||
                  fabs(p[2]) < 1e-9 || fabs(p[2] - 0.5) < 1e-9;
        }
        CHECK(ok);
        CHECK(b->n_components == 1 && b->n_nonmanifold == 0 && b->n_duplicate == 0);
        /* boundary triangles of the file are not volume cells */
        size_t other = 0;
        for (size_t c = 0; c < m->n_cells; ++c) other += b->cell_component[c] == -1;
        CHECK(other == m->n_cells - cm_mesh_count_dim(m, 3));
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* Results independent of the thread count: the same arrays with 1 and 2 threads on a block
 * large enough for the parallel paths. */
static void test_threads(void)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    add_tet_block(m, 28);
    cm_mesh_boundary *b1 = NULL, *b2 = NULL;
    cm_context_set_threads(ctx, 1);
    CHECK(cm_mesh_boundary_create(ctx, m, &b1) == CM_OK);
    cm_context_set_threads(ctx, 2);
    CHECK(cm_mesh_boundary_create(ctx, m, &b2) == CM_OK);
    cm_context_set_threads(ctx, 0);
    if (b1 && b2) {
        CHECK(b1->n_faces == 12 * 28 * 28 && b1->n_faces == b2->n_faces && b1->n_nodes == b2->n_nodes);
        CHECK(memcmp(b1->face_offset, b2->face_offset, (b1->n_faces + 1) * sizeof(int64_t)) == 0);
        CHECK(memcmp(b1->face_nodes, b2->face_nodes, (size_t)b1->face_offset[b1->n_faces] * sizeof(int64_t)) == 0);
        CHECK(memcmp(b1->face_cell, b2->face_cell, b1->n_faces * sizeof(int64_t)) == 0);
        CHECK(memcmp(b1->nodes, b2->nodes, b1->n_nodes * sizeof(int64_t)) == 0);
        CHECK(memcmp(b1->cell_component, b2->cell_component, m->n_cells * sizeof(int)) == 0);
    }
    cm_mesh_boundary_destroy(&b1);
    cm_mesh_boundary_destroy(&b2);
    cm_mesh_destroy(&m);
}

int main(int argc, char **argv)
{
    CHECK(cm_context_create(&ctx) == CM_OK);
    if (argc > 1) test_gmsh_box(argv[1]);
    else CHECK_MSG(0, "usage: test_boundary DATA_DIR WORK_DIR");
    test_hex_block();
    test_tet_block_and_tet10();
    test_components();
    test_duplicate_and_nonmanifold();
    test_single_cells();
    test_polyhedra();
    test_large_bucket();
    test_threads();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
