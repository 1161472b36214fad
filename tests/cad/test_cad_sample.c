/* Dense sampling of trimmed faces: every sample lies on its face and inside its trimming (never
 * in the hole of the box with a bore), counts follow area / h^2, and the cap on the count is
 * reported as a warning with h raised, never silently. */
#include "cadmorph/cad.h"
#include "test_rng.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cm_cad_model *load(cm_context *ctx, const char *work, const char *name)
{
    char path[2048];
    snprintf(path, sizeof path, "%s/cad/%s.step", work, name);
    cm_cad_model *m = NULL;
    CHECK_MSG(cm_cad_read(ctx, path, NULL, &m) == CM_OK, "%s", cm_context_message(ctx));
    return m;
}

static size_t sample(cm_context *ctx, const cm_cad_model *m, double h, cm_cad_locator **loc)
{
    cm_cad_sample_options o;
    cm_cad_sample_options_init(&o);
    o.h = h;
    CHECK(cm_cad_locator_create(ctx, m, &o, loc) == CM_OK);
    return cm_cad_locator_samples(*loc, NULL, NULL, NULL);
}

/* Every sample: f_k(u,v) is the stored point, (u,v) is inside face k's trimming. */
static void check_on_faces(cm_context *ctx, const cm_cad_model *m, const cm_cad_locator *loc,
                           const char *name)
{
    const double *xyz, *uv;
    const int *face;
    size_t n = cm_cad_locator_samples(loc, &xyz, &face, &uv);
    double *p = malloc(3 * sizeof *p);
    size_t off = 0, outside = 0;
    for (size_t i = 0; i < n; ++i) {
        int in = 0;
        CHECK(cm_cad_face_eval(ctx, m, face[i], &uv[2 * i], 1, p, NULL) == CM_OK);
        CHECK(cm_cad_face_inside(ctx, m, face[i], &uv[2 * i], 1, &in) == CM_OK);
        double e = fabs(p[0] - xyz[3 * i]) + fabs(p[1] - xyz[3 * i + 1]) + fabs(p[2] - xyz[3 * i + 2]);
        off += e > 1e-9;
        outside += !in;
    }
    CHECK_MSG(off == 0, "%s: %zu samples off their face", name, off);
    CHECK_MSG(outside == 0, "%s: %zu samples outside the trimming", name, outside);
    free(p);
}

/* No part of a face is left out (the row-wise trimming test, cad/scanline.cpp, decides most
 * candidates without the exact classifier): random points inside each face's trimming, by
 * the exact classifier, have a sample of their face within 2 h. */
static void check_complete(cm_context *ctx, const cm_cad_model *m, const cm_cad_locator *loc,
                           double h, const char *name)
{
    const double *xyz;
    const int *face;
    size_t n = cm_cad_locator_samples(loc, &xyz, &face, NULL), far = 0, tried = 0;
    cm_cad_counts c;
    cm_cad_get_counts(m, &c);
    uint64_t seed = 18;
    double worst = 0;
    for (int f = 0; f < c.faces; ++f) {
        cm_cad_face_info fi;
        CHECK(cm_cad_face_get_info(ctx, m, f, &fi) == CM_OK);
        for (int k = 0; k < 200; ++k) {
            double uv[2] = {test_rng_range(&seed, fi.uv_range[0], fi.uv_range[1]),
                            test_rng_range(&seed, fi.uv_range[2], fi.uv_range[3])}, p[3];
            int in = 0;
            CHECK(cm_cad_face_inside(ctx, m, f, uv, 1, &in) == CM_OK);
            if (!in) continue;
            CHECK(cm_cad_face_eval(ctx, m, f, uv, 1, p, NULL) == CM_OK);
            double best = INFINITY;
            for (size_t i = 0; i < n; ++i) {
                if (face[i] != f) continue;
                double d = (p[0] - xyz[3 * i]) * (p[0] - xyz[3 * i]) +
                           (p[1] - xyz[3 * i + 1]) * (p[1] - xyz[3 * i + 1]) +
                           (p[2] - xyz[3 * i + 2]) * (p[2] - xyz[3 * i + 2]);
                if (d < best) best = d;
            }
            best = sqrt(best);
            if (best > worst) worst = best;
            far += best > 2 * h;
            ++tried;
        }
    }
    CHECK_MSG(tried > 100 && far == 0, "%s: %zu of %zu points inside a face have no sample within "
              "2 h (worst %.3g h)", name, far, tried, worst / h);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    const char *work = argv[2];

    /* box with a bore of radius 2 around (5, 4): no sample inside the bore */
    cm_cad_model *m = load(ctx, work, "holed");
    if (m) {
        cm_cad_locator *loc = NULL;
        size_t n1 = sample(ctx, m, 0.2, &loc);
        const double *xyz;
        const int *face;
        size_t n = cm_cad_locator_samples(loc, &xyz, &face, NULL), in_hole = 0, on_caps = 0;
        for (size_t i = 0; i < n; ++i) {
            double r2 = (xyz[3 * i] - 5) * (xyz[3 * i] - 5) + (xyz[3 * i + 1] - 4) * (xyz[3 * i + 1] - 4);
            in_hole += r2 < 4 * (1 - 1e-9);
            on_caps += fabs(xyz[3 * i + 2]) < 1e-12 || fabs(xyz[3 * i + 2] - 4) < 1e-12;
        }
        CHECK_MSG(in_hole == 0, "%zu samples in the hole", in_hole);
        CHECK(on_caps > 100);
        check_on_faces(ctx, m, loc, "holed");
        check_complete(ctx, m, loc, 0.2, "holed");
        /* samples follow area / h^2: total area 2(80 + 40 + 32) - 2 pi 4 + 2 pi 2 4 */
        double area = 2 * (80 + 40 + 32) - 2 * 3.14159265358979 * 4 + 2 * 3.14159265358979 * 2 * 4;
        double ratio = n1 / (area / (0.2 * 0.2));
        CHECK_MSG(ratio > 0.8 && ratio < 1.6, "samples / (area / h^2) = %g", ratio);
        cm_cad_locator *loc2 = NULL;
        size_t n2 = sample(ctx, m, 0.1, &loc2);
        CHECK_MSG(n2 > 3.3 * n1 && n2 < 4.4 * n1, "h 0.2: %zu samples, h 0.1: %zu", n1, n2);
        cm_cad_locator_destroy(&loc2);

        /* the cap: h grows, the call warns and says so */
        cm_cad_sample_options o;
        cm_cad_sample_options_init(&o);
        o.h = 0.1;
        o.max_samples = n2 / 4;
        cm_status s = cm_cad_locator_create(ctx, m, &o, &loc2);
        CHECK(s == CM_WARNING && loc2 != NULL);
        CHECK_MSG(strstr(cm_context_message(ctx), "cap") && strstr(cm_context_message(ctx), "h raised"),
                  "%s", cm_context_message(ctx));
        CHECK(cm_cad_locator_samples(loc2, NULL, NULL, NULL) <= o.max_samples);
        CHECK(cm_cad_locator_h(loc2) > 0.1);
        cm_cad_locator_destroy(&loc2);
        cm_cad_locator_destroy(&loc);
    }
    cm_cad_destroy(&m);

    /* periodic faces, seams, poles, a B-spline: all samples on their face, inside, and the
     * count near area / h^2 (the sphere's rows shrink towards the poles) */
    const struct {
        const char *name;
        double area, h;
    } shapes[] = {{"sphere", 4 * 3.14159265358979 * 9, 0.1},
                  {"torus", 4 * 3.14159265358979 * 3.14159265358979 * 5 * 1.5, 0.1},
                  {"cylinder", 2 * 3.14159265358979 * 2 * (5 + 2), 0.1},
                  {"bspline", 12.0, 0.05}};
    for (size_t k = 0; k < sizeof shapes / sizeof *shapes; ++k) {
        m = load(ctx, work, shapes[k].name);
        if (!m) continue;
        cm_cad_locator *loc = NULL;
        size_t n = sample(ctx, m, shapes[k].h, &loc);
        double ratio = n / (shapes[k].area / (shapes[k].h * shapes[k].h));
        /* the B-spline's area exceeds its 4 x 3 footprint a little */
        CHECK_MSG(ratio > 0.8 && ratio < 1.6, "%s: samples / (area / h^2) = %g", shapes[k].name,
                  ratio);
        check_on_faces(ctx, m, loc, shapes[k].name);
        check_complete(ctx, m, loc, shapes[k].h, shapes[k].name);
        cm_cad_locator_destroy(&loc);
        cm_cad_destroy(&m);
    }

    /* errors */
    m = load(ctx, work, "box");
    cm_cad_locator *loc = (cm_cad_locator *)1;
    cm_cad_sample_options o;
    cm_cad_sample_options_init(&o);
    o.h = NAN;
    CHECK(cm_cad_locator_create(ctx, m, &o, &loc) == CM_ERR_ARGUMENT && loc == NULL);
    CHECK(cm_cad_locator_create(ctx, NULL, NULL, &loc) == CM_ERR_ARGUMENT);
    /* default h: the bbox diagonal / 200 */
    CHECK(cm_cad_locator_create(ctx, m, NULL, &loc) == CM_OK);
    CHECK_NEAR(cm_cad_locator_h(loc), sqrt(9 + 16 + 4) / 200, 1e-3);
    cm_cad_locator_destroy(&loc);
    cm_cad_destroy(&m);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
