/* RANSAC primitive detection (ransac.h) on meshes built in code: the six faces of a
 * triangulated box are six planes holding all faces, with their normals and offsets; an open
 * tube is one cylinder of the right axis and radius (barycentres of chords lie inside it: to
 * the sag); vertices of box edges belong to two primitives; the same seed gives the same
 * result; bad arguments. */
#include "cadmorph/ransac.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

typedef struct tri_mesh {
    size_t nn, nf;
    double *xyz;
    int64_t *off, *nodes;
} tri_mesh;

static void add_node(tri_mesh *m, double x, double y, double z)
{
    m->xyz[3 * m->nn] = x, m->xyz[3 * m->nn + 1] = y, m->xyz[3 * m->nn + 2] = z;
    ++m->nn;
}

static void add_tri(tri_mesh *m, int64_t a, int64_t b, int64_t c)
{
    int64_t o = m->off[m->nf];
    m->nodes[o] = a, m->nodes[o + 1] = b, m->nodes[o + 2] = c;
    m->off[++m->nf] = o + 3;
}

/* a box [0,2]x[0,1]x[0,1], each face an n x n grid of node-sharing triangles (shared edge nodes) */
static tri_mesh box(int n)
{
    tri_mesh m = {0, 0, malloc(6 * (n + 1) * (n + 1) * 3 * sizeof(double)),
                  calloc(12 * n * n + 1, sizeof(int64_t)), malloc(36 * n * n * sizeof(int64_t))};
    /* nodes of the box surface by a key on the (n+1)^3 lattice: shared between faces */
    int64_t *id = malloc((size_t)(n + 1) * (n + 1) * (n + 1) * sizeof *id);
    for (int i = 0; i < (n + 1) * (n + 1) * (n + 1); ++i)
        id[i] = -1;
#define LID(i, j, k) (((k) * (n + 1) + (j)) * (n + 1) + (i))
    for (int f = 0; f < 6; ++f) {
        int ax = f / 2, side = f % 2, u = (ax + 1) % 3, v = (ax + 2) % 3;
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
                int64_t q[4];
                for (int c = 0; c < 4; ++c) {
                    int g[3];
                    g[ax] = side * n, g[u] = a + (c == 1 || c == 2), g[v] = b + (c >= 2);
                    int l = LID(g[0], g[1], g[2]);
                    if (id[l] < 0) id[l] = (int64_t)m.nn, add_node(&m, 2.0 * g[0] / n, (double)g[1] / n, (double)g[2] / n);
                    q[c] = id[l];
                }
                add_tri(&m, q[0], q[1], q[2]);
                add_tri(&m, q[0], q[2], q[3]);
            }
    }
#undef LID
    free(id);
    return m;
}

static tri_mesh tube(int na, int nz, double r, double h)
{
    tri_mesh m = {0, 0, malloc((size_t)na * (nz + 1) * 3 * sizeof(double)),
                  calloc(2 * na * nz + 1, sizeof(int64_t)), malloc(6 * na * nz * sizeof(int64_t))};
    for (int k = 0; k <= nz; ++k)
        for (int i = 0; i < na; ++i)
            add_node(&m, r * cos(2 * PI * i / na), r * sin(2 * PI * i / na), h * k / nz);
    for (int k = 0; k < nz; ++k)
        for (int i = 0; i < na; ++i) {
            int64_t a = k * na + i, b = k * na + (i + 1) % na, c = a + na, d = b + na;
            add_tri(&m, a, b, d);
            add_tri(&m, a, d, c);
        }
    return m;
}

static void free_mesh(tri_mesh *m)
{
    free(m->xyz), free(m->off), free(m->nodes);
}

int main(void)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    tri_mesh b = box(8);
    cm_ransac_result *r = NULL, *r2 = NULL;
    CHECK(cm_ransac_detect(ctx, b.nn, b.xyz, b.nf, b.off, b.nodes, NULL, &r) == CM_OK);
    if (r) {
        CHECK_MSG(r->n_primitives == 6, "box: %zu primitives", r->n_primitives);
        size_t covered = 0;
        int seen[6] = {0};
        for (size_t i = 0; i < r->n_primitives; ++i) {
            const cm_primitive *p = r->primitives + i;
            CHECK(p->type == CM_PRIMITIVE_PLANE);
            covered += p->n_faces;
            CHECK_MSG(p->n_faces == 128, "box: plane %zu has %zu faces", i, p->n_faces);
            CHECK(p->rms < 1e-12);
            /* normal along an axis, point on that face */
            int ax = fabs(p->p[3]) > 0.5 ? 0 : fabs(p->p[4]) > 0.5 ? 1 : 2;
            CHECK_NEAR(fabs(p->p[3 + ax]), 1, 1e-12);
            double ext = ax == 0 ? 2 : 1;
            int side = p->p[ax] > ext / 2;
            CHECK_NEAR(p->p[ax], side * ext, 1e-12);
            seen[2 * ax + side]++;
            /* the 81 nodes of its face grid */
            CHECK(r->node_offset[i + 1] - r->node_offset[i] == 81);
        }
        for (int f = 0; f < 6; ++f)
            CHECK_MSG(seen[f] == 1, "box face %d found %d times", f, seen[f]);
        CHECK(covered == b.nf);
        /* a box corner is in three primitives, an edge node in two */
        size_t corner = 0;
        for (size_t i = 0; i < r->n_primitives; ++i)
            for (int64_t q = r->node_offset[i]; q < r->node_offset[i + 1]; ++q)
                corner += r->nodes[q] == 0;
        CHECK(corner == 3);
        /* the same seed, the same result */
        CHECK(cm_ransac_detect(ctx, b.nn, b.xyz, b.nf, b.off, b.nodes, NULL, &r2) == CM_OK);
        CHECK(r2 && r2->n_primitives == r->n_primitives &&
              !memcmp(r2->face_primitive, r->face_primitive, b.nf * sizeof *r->face_primitive));
    }
    cm_ransac_result_destroy(&r);
    cm_ransac_result_destroy(&r2);
    CHECK(r == NULL);

    tri_mesh t = tube(48, 20, 0.3, 1.2);
    CHECK(cm_ransac_detect(ctx, t.nn, t.xyz, t.nf, t.off, t.nodes, NULL, &r) == CM_OK);
    if (r) {
        CHECK_MSG(r->n_primitives == 1 && r->primitives[0].type == CM_PRIMITIVE_CYLINDER,
                  "tube: %zu primitives, first %s", r->n_primitives,
                  r->n_primitives ? cm_primitive_type_name(r->primitives[0].type) : "-");
        if (r->n_primitives) {
            const cm_primitive *p = r->primitives;
            CHECK(p->n_faces == t.nf);
            CHECK_NEAR(fabs(p->p[5]), 1, 1e-9);
            CHECK_NEAR(hypot(p->p[0], p->p[1]), 0, 1e-9);
            /* barycentres of triangles of a regular 48-gon: between 0.3 cos(pi/48) and 0.3 */
            CHECK(p->p[6] > 0.3 * cos(PI / 48) - 1e-9 && p->p[6] < 0.3);
        }
    }
    cm_ransac_result_destroy(&r);
    /* only spheres asked: at most spheres of the tube's radius on the axis, each on a band
     * (within epsilon and the angle of a sphere), nothing else */
    cm_ransac_options o;
    cm_ransac_options_init(&o);
    o.types = 1u << CM_PRIMITIVE_SPHERE;
    CHECK(cm_ransac_detect(ctx, t.nn, t.xyz, t.nf, t.off, t.nodes, &o, &r) == CM_OK);
    for (size_t i = 0; r && i < r->n_primitives; ++i) {
        const cm_primitive *p = r->primitives + i;
        CHECK(p->type == CM_PRIMITIVE_SPHERE && fabs(p->p[3] - 0.3) < 0.02 &&
              hypot(p->p[0], p->p[1]) < 0.02 && p->n_faces < t.nf / 4);
    }
    cm_ransac_result_destroy(&r);
    /* bad arguments */
    o.types = 0xF, o.normal_angle = 95;
    CHECK(cm_ransac_detect(ctx, t.nn, t.xyz, t.nf, t.off, t.nodes, &o, &r) == CM_ERR_ARGUMENT && !r);
    int64_t bad[3] = {0, 1, (int64_t)t.nn};
    int64_t boff[2] = {0, 3};
    CHECK(cm_ransac_detect(ctx, t.nn, t.xyz, 1, boff, bad, NULL, &r) == CM_ERR_ARGUMENT && !r);
    free_mesh(&b);
    free_mesh(&t);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
