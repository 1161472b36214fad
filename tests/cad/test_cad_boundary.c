/* Face boundaries in parameter space and arc length on edges: the (u,v) samples of every
 * oriented edge evaluate to the edge's 3D points, sample i of G corresponds to sample i of G'
 * (same edge, same fraction), seams come twice, s <-> t round trips, and edge and vertex
 * location agree with closed forms. */
#include "cadmorph/cad.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static cm_cad_model *load(cm_context *ctx, const char *dir, const char *sub, const char *name)
{
    char path[2048];
    snprintf(path, sizeof path, "%s/%s%s.step", dir, sub, name);
    cm_cad_model *m = NULL;
    CHECK_MSG(cm_cad_read(ctx, path, NULL, &m) == CM_OK, "%s", cm_context_message(ctx));
    return m;
}

/* f_k(uv) of every boundary sample is the 3D point of its edge. */
static double boundary_error(cm_context *ctx, const cm_cad_model *m, int face,
                             const cm_cad_boundary *b)
{
    double worst = 0, *p = malloc(3 * b->n * sizeof *p + 1);
    CHECK(cm_cad_face_eval(ctx, m, face, b->uv, b->n, p, NULL) == CM_OK);
    for (size_t i = 0; i < b->n; ++i) {
        double e = sqrt(pow(p[3 * i] - b->xyz[3 * i], 2) + pow(p[3 * i + 1] - b->xyz[3 * i + 1], 2) +
                        pow(p[3 * i + 2] - b->xyz[3 * i + 2], 2));
        if (e > worst) worst = e;
    }
    free(p);
    return worst;
}

static void test_pair(cm_context *ctx, const char *data)
{
    cm_cad_model *a = load(ctx, data, "cad/", "bore_a"), *b = load(ctx, data, "cad/", "bore_b");
    if (!a || !b) return;
    cm_cad_counts c;
    cm_cad_get_counts(a, &c);
    /* per-edge counts from G's lengths, used for G' too */
    int *per_edge = malloc(c.edges * sizeof *per_edge);
    for (int e = 0; e < c.edges; ++e) {
        cm_cad_edge_info ei;
        cm_cad_edge_get_info(ctx, a, e, &ei);
        per_edge[e] = 2 + (int)(ei.length / 0.5);
    }
    double worst = 0;
    int seams = 0;
    for (int f = 0; f < c.faces; ++f) {
        cm_cad_boundary *ba = NULL, *bb = NULL;
        CHECK(cm_cad_face_boundary(ctx, a, f, per_edge, 0, &ba) == CM_OK);
        CHECK(cm_cad_face_boundary(ctx, b, f, per_edge, 0, &bb) == CM_OK);
        if (!ba || !bb) continue;
        CHECK(ba->n == bb->n && ba->n > 0);
        size_t same = 0;
        for (size_t i = 0; i < ba->n && i < bb->n; ++i)
            same += ba->edge[i] == bb->edge[i] && fabs(ba->s[i] - bb->s[i]) < 1e-9 &&
                    ba->wire[i] == bb->wire[i];
        CHECK(same == ba->n);
        double e1 = boundary_error(ctx, a, f, ba), e2 = boundary_error(ctx, b, f, bb);
        if (e1 > worst) worst = e1;
        if (e2 > worst) worst = e2;
        /* an edge used twice in one face is a seam: its two copies differ in u or v */
        for (size_t i = 0; i < ba->n; ++i)
            for (size_t j = i + 1; j < ba->n; ++j)
                if (ba->edge[i] == ba->edge[j] && fabs(ba->s[i] - ba->s[j]) < 1e-12) {
                    ++seams;
                    CHECK(fabs(ba->uv[2 * i] - ba->uv[2 * j]) + fabs(ba->uv[2 * i + 1] - ba->uv[2 * j + 1]) > 1);
                }
        cm_cad_boundary_destroy(&ba);
        cm_cad_boundary_destroy(&bb);
        CHECK(ba == NULL);
    }
    /* pcurves and 3D curves agree within the edge tolerance (1e-7 in gmsh's STEP) */
    CHECK_MSG(worst < 1e-6, "boundary (u,v) off the edge by %g", worst);
    CHECK(seams > 0);

    /* s -> t -> s on every edge of both models; s of an edge maps onto the same s of G' */
    for (int e = 0; e < c.edges; ++e) {
        double s[11], t[11], s2[11];
        for (int i = 0; i <= 10; ++i) s[i] = i / 10.0;
        CHECK(cm_cad_edge_s_to_t(ctx, b, e, s, 11, t) == CM_OK);
        CHECK(cm_cad_edge_t_to_s(ctx, b, e, t, 11, s2) == CM_OK);
        for (int i = 0; i <= 10; ++i) CHECK_NEAR(s2[i], s[i], 1e-9);
    }
    free(per_edge);
    cm_cad_destroy(&a);
    cm_cad_destroy(&b);
}

static void test_cylinder(cm_context *ctx, const char *work)
{
    /* cylinder of gen_shapes: axis (1,2,.) z in [3,8], radius 2 */
    cm_cad_model *m = load(ctx, work, "cad/", "cylinder");
    if (!m) return;
    cm_cad_counts c;
    cm_cad_get_counts(m, &c);
    int lateral = -1;
    for (int f = 0; f < c.faces; ++f) {
        cm_cad_face_info fi;
        cm_cad_face_get_info(ctx, m, f, &fi);
        if (fi.type == CM_CAD_CYLINDER) lateral = f;
    }
    CHECK(lateral >= 0);
    cm_cad_boundary *b = NULL;
    CHECK(cm_cad_face_boundary(ctx, m, lateral, NULL, 8, &b) == CM_OK);
    if (b) {
        CHECK(b->n == 4 * 8); /* two circles and the seam twice */
        CHECK(boundary_error(ctx, m, lateral, b) < 1e-9);
        int at0 = 0, at2pi = 0;
        for (size_t i = 0; i < b->n; ++i) {
            at0 += fabs(b->uv[2 * i]) < 1e-9;
            at2pi += fabs(b->uv[2 * i] - 2 * PI) < 1e-9;
        }
        CHECK(at0 >= 8 && at2pi >= 8);
    }
    cm_cad_boundary_destroy(&b);
    CHECK(cm_cad_face_boundary(ctx, m, lateral, NULL, 0, &b) == CM_ERR_ARGUMENT && b == NULL);

    /* periodic u: shifted by whole periods it is the same point; far values and NaN answer */
    {
        double uvp[10] = {1.0, 4.0, 1.0 + 6 * PI, 4.0, 1.0 - 4 * PI, 4.0, 1e18, 4.0, NAN, 4.0};
        int in[5] = {-1, -1, -1, -1, -1};
        CHECK(cm_cad_face_inside(ctx, m, lateral, uvp, 5, in) == CM_OK);
        CHECK(in[0] == 1 && in[1] == 1 && in[2] == 1);
        CHECK((in[3] == 0 || in[3] == 1) && in[4] == 0);
        double vout[2] = {1.0, 99.0};
        CHECK(cm_cad_face_inside(ctx, m, lateral, vout, 1, in) == CM_OK && in[0] == 0);
    }

    /* circle edges: arc length is linear in the angle */
    for (int e = 0; e < c.edges; ++e) {
        cm_cad_edge_info ei;
        cm_cad_edge_get_info(ctx, m, e, &ei);
        if (ei.type != CM_CAD_CIRCLE) continue;
        CHECK_NEAR(ei.length, 4 * PI, 1e-10);
        double s[5] = {0, 0.1, 0.37, 0.9, 1}, t[5];
        CHECK(cm_cad_edge_s_to_t(ctx, m, e, s, 5, t) == CM_OK);
        for (int i = 0; i < 5; ++i)
            CHECK_NEAR(t[i], ei.t_range[0] + s[i] * (ei.t_range[1] - ei.t_range[0]), 1e-10);
        /* projection onto the circle: distance by formula */
        double p[3] = {1 + 3 * cos(0.7), 2 + 3 * sin(0.7), 0}, xyz[3], tp, dp;
        CHECK(cm_cad_edge_eval(ctx, m, e, &ei.t_range[0], 1, xyz) == CM_OK);
        p[2] = xyz[2] + 0.5;
        CHECK(cm_cad_project_edge(ctx, m, e, p, 1, &tp, &dp) == CM_OK);
        CHECK_NEAR(dp, sqrt(1 + 0.25), 1e-12);
    }

    /* locate edges and vertices from points near them */
    cm_cad_locator *loc = NULL;
    cm_cad_sample_options o;
    cm_cad_sample_options_init(&o);
    o.h = 0.1;
    CHECK(cm_cad_locator_create(ctx, m, &o, &loc) == CM_OK);
    enum { N = 200 };
    double q[3 * N], t[N], d[N];
    int edge[N];
    for (int i = 0; i < N; ++i) {
        double ang = 2 * PI * i / N + 0.01, r = 2 + 0.05 * (i % 3), z = (i % 2) ? 8.03 : 2.97;
        q[3 * i] = 1 + r * cos(ang), q[3 * i + 1] = 2 + r * sin(ang), q[3 * i + 2] = z;
    }
    CHECK(cm_cad_locate_edges(ctx, loc, q, N, edge, t, d) == CM_OK);
    int bad = 0;
    for (int i = 0; i < N; ++i) {
        double r = 2 + 0.05 * (i % 3);
        double expect = sqrt((r - 2) * (r - 2) + 0.03 * 0.03);
        cm_cad_edge_info ei;
        cm_cad_edge_get_info(ctx, m, edge[i], &ei);
        bad += fabs(d[i] - expect) > 1e-12 || ei.type != CM_CAD_CIRCLE;
    }
    CHECK_MSG(bad == 0, "%d of %d edge locations off", bad, N);
    double v[3];
    int vi;
    double vd;
    CHECK(cm_cad_vertex_point(ctx, m, 0, v) == CM_OK);
    v[0] += 0.01;
    CHECK(cm_cad_locate_vertices(ctx, loc, v, 1, &vi, &vd) == CM_OK);
    CHECK(vi == 0);
    CHECK_NEAR(vd, 0.01, 1e-12);
    cm_cad_locator_destroy(&loc);
    cm_cad_destroy(&m);
}

static void test_inside(cm_context *ctx, const char *work)
{
    /* box with a bore: on the top face, the bore's centre is outside the trimmed domain */
    cm_cad_model *m = load(ctx, work, "cad/", "holed");
    if (!m) return;
    cm_cad_counts c;
    cm_cad_get_counts(m, &c);
    int checked = 0;
    for (int f = 0; f < c.faces; ++f) {
        cm_cad_face_info fi;
        cm_cad_face_get_info(ctx, m, f, &fi);
        if (fi.type != CM_CAD_PLANE || fi.n_wires != 2) continue;
        double p[6] = {5, 4, 0, 1, 1, 0}, uv[4], d[2];
        p[2] = p[5] = fi.bbox[2] + 0.5 * (fi.bbox[5] - fi.bbox[2]);
        /* project the centre and a corner-ish point onto the plane face's surface by uv of
         * the nearest point: the centre's foot must land on the hole's rim */
        CHECK(cm_cad_project_face(ctx, m, f, p, 2, NULL, uv, d, NULL) == CM_OK);
        CHECK_NEAR(d[0], 2, 1e-9);
        CHECK_NEAR(d[1], 0, 1e-9);
        int in[2];
        CHECK(cm_cad_face_inside(ctx, m, f, uv, 2, in) == CM_OK);
        CHECK(in[0] == 1 && in[1] == 1);
        /* a grid over the parameter box: inside exactly where the point is off the bore */
        enum { G = 41 };
        double g[2 * G * G], x[3 * G * G];
        int gin[G * G], wrong = 0, holes = 0;
        for (int i = 0; i < G; ++i)
            for (int j = 0; j < G; ++j) {
                g[2 * (i * G + j)] = fi.uv_range[0] + (fi.uv_range[1] - fi.uv_range[0]) * (i + 0.3) / G;
                g[2 * (i * G + j) + 1] = fi.uv_range[2] + (fi.uv_range[3] - fi.uv_range[2]) * (j + 0.3) / G;
            }
        CHECK(cm_cad_face_eval(ctx, m, f, g, G * G, x, NULL) == CM_OK);
        CHECK(cm_cad_face_inside(ctx, m, f, g, G * G, gin) == CM_OK);
        for (int k = 0; k < G * G; ++k) {
            double r = sqrt(pow(x[3 * k] - 5, 2) + pow(x[3 * k + 1] - 4, 2));
            if (fabs(r - 2) < 1e-6) continue;
            holes += r < 2;
            wrong += gin[k] != (r > 2);
        }
        CHECK(holes > 20);
        CHECK_MSG(wrong == 0, "face %d: %d grid points classified wrongly", f, wrong);
        ++checked;
    }
    CHECK(checked == 2);
    cm_cad_destroy(&m);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_pair(ctx, argv[1]);
    test_cylinder(ctx, argv[2]);
    test_inside(ctx, argv[2]);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
