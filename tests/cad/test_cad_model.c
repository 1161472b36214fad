/* cad model: STEP read through OpenCASCADE, topology index and info of shapes whose answer is
 * known (a box: 6 planes, 12 lines, 8 vertices, area 52), units, write + read back, the
 * correspondence check on gmsh-written pairs, and the bad inputs. */
#include "cadmorph/cad.h"
#include "test_util.h"

#include <stdio.h>
#include <string.h>

#define PI 3.14159265358979323846

static char data_dir[1024], work_dir[1024];

static const char *path_of(const char *dir, const char *sub, const char *name)
{
    static char buf[4][2048];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s%s", dir, sub, name);
    return buf[k];
}

static void test_box(cm_context *ctx)
{
    cm_cad_model *m = NULL;
    CHECK(cm_cad_read(ctx, path_of(work_dir, "cad/", "box.step"), NULL, &m) == CM_OK);
    if (!m) return;
    cm_cad_counts c;
    cm_cad_get_counts(m, &c);
    CHECK(c.faces == 6 && c.edges == 12 && c.vertices == 8 && c.wires == 6 && c.solids == 1);
    CHECK(!strcmp(cm_cad_unit(m), "mm"));
    CHECK_MSG(strstr(cm_cad_file_unit(m), "MILLI") || strstr(cm_cad_file_unit(m), "milli") ||
                  strstr(cm_cad_file_unit(m), "mm"),
              "file unit '%s'", cm_cad_file_unit(m));
    double area = 0, bb[6];
    for (int f = 0; f < c.faces; ++f) {
        cm_cad_face_info fi;
        CHECK(cm_cad_face_get_info(ctx, m, f, &fi) == CM_OK);
        CHECK(fi.type == CM_CAD_PLANE && fi.n_wires == 1);
        area += fi.area;
        const int *e, *rev;
        int n;
        CHECK(cm_cad_face_wire(ctx, m, f, 0, &e, &rev, &n) == CM_OK && n == 4);
        /* consecutive oriented edges share a vertex: the wire is closed and in order */
        for (int k = 0; k < n; ++k) {
            cm_cad_edge_info a, b;
            cm_cad_edge_get_info(ctx, m, e[k], &a);
            cm_cad_edge_get_info(ctx, m, e[(k + 1) % n], &b);
            int a_end = a.vertex[rev[k] ? 0 : 1], b_start = b.vertex[rev[(k + 1) % n] ? 1 : 0];
            CHECK(a_end == b_start);
        }
    }
    CHECK_NEAR(area, 2 * (3 * 4 + 3 * 2 + 4 * 2), 1e-9);
    double len = 0;
    for (int e = 0; e < c.edges; ++e) {
        cm_cad_edge_info ei;
        CHECK(cm_cad_edge_get_info(ctx, m, e, &ei) == CM_OK);
        CHECK(ei.type == CM_CAD_LINE && !ei.degenerate && ei.vertex[0] != ei.vertex[1]);
        len += ei.length;
        const int *faces;
        int n;
        CHECK(cm_cad_edge_faces(ctx, m, e, &faces, &n) == CM_OK && n == 2);
    }
    CHECK_NEAR(len, 4 * (3 + 4 + 2), 1e-9);
    cm_cad_bbox(m, bb);
    CHECK(bb[0] <= -1 + 1e-6 && bb[0] > -1 - 1e-3 && bb[5] >= 1.5 - 1e-6 && bb[5] < 1.5 + 1e-3);
    cm_cad_face_info fi;
    CHECK(cm_cad_face_get_info(ctx, m, 6, &fi) == CM_ERR_ARGUMENT);
    CHECK(strstr(cm_context_message(ctx), "face 6") != NULL);

    /* the same model in metres: coordinates scale by 1e-3 */
    cm_cad_read_options o;
    cm_cad_read_options_init(&o);
    o.unit = "m";
    cm_cad_model *mm = NULL;
    CHECK(cm_cad_read(ctx, path_of(work_dir, "cad/", "box.step"), &o, &mm) == CM_OK);
    if (mm) {
        double b2[6];
        cm_cad_bbox(mm, b2);
        double v[3], w[3];
        CHECK(cm_cad_vertex_point(ctx, m, 3, v) == CM_OK);
        CHECK(cm_cad_vertex_point(ctx, mm, 3, w) == CM_OK);
        for (int i = 0; i < 3; ++i) CHECK_NEAR(w[i], 1e-3 * v[i], 1e-15);
        CHECK(!strcmp(cm_cad_unit(mm), "m"));
        /* written in metres and read back in millimetres: the original coordinates */
        const char *out = path_of(work_dir, "cad/", "box_m.step");
        CHECK(cm_cad_write(ctx, mm, out) == CM_OK);
        cm_cad_model *back = NULL;
        CHECK(cm_cad_read(ctx, out, NULL, &back) == CM_OK);
        if (back) {
            CHECK(cm_cad_compare(ctx, m, back, 5) == CM_OK);
            CHECK(cm_cad_vertex_point(ctx, back, 3, w) == CM_OK);
            for (int i = 0; i < 3; ++i) CHECK_NEAR(w[i], v[i], 1e-9);
        }
        cm_cad_destroy(&back);
    }
    cm_cad_destroy(&mm);
    o.unit = "furlong";
    CHECK(cm_cad_read(ctx, path_of(work_dir, "cad/", "box.step"), &o, &mm) == CM_ERR_ARGUMENT);

    /* box vs cylinder: refused, the message names the differences */
    cm_cad_model *cyl = NULL;
    CHECK(cm_cad_read(ctx, path_of(work_dir, "cad/", "cylinder.step"), NULL, &cyl) == CM_OK);
    if (cyl) {
        CHECK(cm_cad_compare(ctx, m, cyl, 3) == CM_ERR_MISMATCH);
        CHECK_MSG(strstr(cm_context_message(ctx), "faces: 6 in G, 3 in G'") != NULL, "%s",
                  cm_context_message(ctx));
    }
    cm_cad_destroy(&cyl);
    cm_cad_destroy(&m);
    CHECK(m == NULL);
    cm_cad_destroy(&m);
}

static void test_periodic(cm_context *ctx)
{
    /* sphere: one face, a seam (used twice in the wire), two degenerate pole edges */
    cm_cad_model *m = NULL;
    CHECK(cm_cad_read(ctx, path_of(work_dir, "cad/", "sphere.step"), NULL, &m) == CM_OK);
    if (!m) return;
    cm_cad_counts c;
    cm_cad_get_counts(m, &c);
    CHECK(c.faces == 1);
    cm_cad_face_info fi;
    CHECK(cm_cad_face_get_info(ctx, m, 0, &fi) == CM_OK);
    CHECK(fi.type == CM_CAD_SPHERE && fi.periodic[0] && !fi.periodic[1]);
    CHECK_NEAR(fi.period[0], 2 * PI, 1e-12);
    CHECK_NEAR(fi.area, 4 * PI * 9, 1e-6);
    int degenerate = 0, seam_uses = 0;
    const int *e, *rev;
    int n;
    CHECK(cm_cad_face_wire(ctx, m, 0, 0, &e, &rev, &n) == CM_OK);
    for (int k = 0; k < n; ++k) {
        cm_cad_edge_info ei;
        cm_cad_edge_get_info(ctx, m, e[k], &ei);
        degenerate += ei.degenerate;
        if (!ei.degenerate) {
            ++seam_uses;
            CHECK_NEAR(ei.length, PI * 3, 1e-9);
        }
    }
    CHECK(degenerate == 2 && seam_uses == 2);
    cm_cad_destroy(&m);

    cm_cad_model *t = NULL;
    CHECK(cm_cad_read(ctx, path_of(work_dir, "cad/", "torus.step"), NULL, &t) == CM_OK);
    if (t) {
        CHECK(cm_cad_face_get_info(ctx, t, 0, &fi) == CM_OK);
        CHECK(fi.type == CM_CAD_TORUS && fi.periodic[0] && fi.periodic[1]);
        CHECK_NEAR(fi.area, 4 * PI * PI * 5 * 1.5, 1e-6);
    }
    cm_cad_destroy(&t);
}

static void test_correspondence(cm_context *ctx)
{
    cm_cad_model *a = NULL, *b = NULL, *h = NULL;
    CHECK(cm_cad_read(ctx, path_of(data_dir, "cad/", "bore_a.step"), NULL, &a) == CM_OK);
    CHECK(cm_cad_read(ctx, path_of(data_dir, "cad/", "bore_b.step"), NULL, &b) == CM_OK);
    CHECK(cm_cad_read(ctx, path_of(data_dir, "cad/", "bore_2holes.step"), NULL, &h) == CM_OK);
    if (a && b && h) {
        CHECK_MSG(cm_cad_compare(ctx, a, b, 5) == CM_OK, "%s", cm_context_message(ctx));
        CHECK(cm_cad_compare(ctx, a, h, 5) == CM_ERR_MISMATCH);
        CHECK_MSG(strstr(cm_context_message(ctx), "faces: 9 in G, 10 in G'") != NULL, "%s",
                  cm_context_message(ctx));
        /* same topology, other dimensions: the areas differ */
        cm_cad_face_info fa, fb;
        double da = 0;
        for (int f = 0; f < 9; ++f) {
            cm_cad_face_get_info(ctx, a, f, &fa);
            cm_cad_face_get_info(ctx, b, f, &fb);
            da += fabs(fa.area - fb.area);
        }
        CHECK(da > 1);
    }
    cm_cad_destroy(&a);
    cm_cad_destroy(&b);
    cm_cad_destroy(&h);
}

static void test_bad_input(cm_context *ctx)
{
    cm_cad_model *m = (cm_cad_model *)1;
    CHECK(cm_cad_read(ctx, path_of(work_dir, "cad/", "no_such.step"), NULL, &m) == CM_ERR_IO);
    CHECK(m == NULL);
    CHECK(strstr(cm_context_message(ctx), "no_such.step") != NULL);
    CHECK(cm_cad_read(ctx, path_of(work_dir, "cad/", "not_step.step"), NULL, &m) ==
          CM_ERR_FORMAT);
    CHECK(cm_cad_read(ctx, path_of(work_dir, "cad/", "edge_only.step"), NULL, &m) ==
          CM_ERR_FORMAT);
    CHECK(strstr(cm_context_message(ctx), "no solid, shell or face") != NULL);
    cm_status s = cm_cad_read(ctx, path_of(data_dir, "cad/", "broken.step"), NULL, &m);
    CHECK_MSG(cm_status_is_input_error(s) && m == NULL, "status %d: %s", (int)s,
              cm_context_message(ctx));
    CHECK(cm_cad_read(ctx, NULL, NULL, &m) == CM_ERR_ARGUMENT);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    snprintf(data_dir, sizeof data_dir, "%s", argv[1]);
    snprintf(work_dir, sizeof work_dir, "%s", argv[2]);
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    test_box(ctx);
    test_periodic(ctx);
    test_correspondence(ctx);
    test_bad_input(ctx);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
