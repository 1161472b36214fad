/* Topology and volume of the benchmark models: G(t) keeps the topology of G(0) (counts,
 * surface/curve types, face-edge and edge-vertex incidence, in MapShapes order) for
 * t = 0, 0.25, 0.5, 0.75, 1, and its volume (BRepGProp) matches the closed formula. A model's
 * STEP file is in mm whatever unit a read before it used (OpenCASCADE's session unit is
 * process-wide). Arguments: the test data and work directories. */
#include "cadmorph/cad.h"
#include "cadmorph/models.h"

#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#include <stdio.h>
#include <string.h>

static int failed;

/* A tilted bore meets the block's top and bottom in ellipses, the upright one (t = 0) in
 * circles: the same topology with a circle for an ellipse (GeomAbs 1 and 2). Edge lines
 * "edge <i> 2:" are read as "edge <i> 1:" before comparing. */
static void conics_as_circles(char *sig)
{
    for (char *p = strstr(sig, "\nedge "); p; p = strstr(p + 1, "\nedge ")) {
        char *q = p + 6;
        while (*q >= '0' && *q <= '9') ++q;
        if (q[0] == ' ' && q[1] == '2' && q[2] == ':') q[1] = '1';
    }
}

static double bore_volume(double t)
{
    cm_model_bore p;
    cm_model_bore_at(t, &p);
    /* the horizontal section of the tilted bore is an ellipse of area pi r^2 / cos(tilt) */
    return 4.0 * 4.0 * 2.0 - M_PI * p.radius * p.radius * 2.0 / cos(p.tilt_deg * M_PI / 180.0);
}

static double pipe_volume(double t)
{
    cm_model_pipe p;
    cm_model_pipe_at(t, &p);
    /* Pappus: disc area times the length of the centreline */
    return M_PI * p.radius * p.radius *
           (p.inlet + p.bend_radius * p.bend_deg * M_PI / 180.0 + p.outlet);
}

static double bracket_volume(double t)
{
    cm_model_bracket p;
    cm_model_bracket_at(t, &p);
    const double profile = 2.0 * p.leg * p.width - p.width * p.width +
                           p.fillet * p.fillet * (1.0 - M_PI / 4.0);
    return profile * p.height - 2.0 * M_PI * p.hole_radius * p.hole_radius * p.width;
}

/* Reads a STEP file in metres, then writes the bore and reads it back in mm: its block is
 * [-2,2] x [-2,2] x [0,2], not 1000 times that. */
static void unit_after_a_read_in_metres(cm_context *ctx, const char *data, const char *work)
{
    char in[4096], out[4096];
    snprintf(in, sizeof in, "%s/freecad/bracket_0.step", data);
    snprintf(out, sizeof out, "%s/test_models_bore.step", work);
    cm_cad_read_options opt;
    cm_cad_read_options_init(&opt);
    opt.unit = "m";
    cm_cad_model *g = NULL, *bore = NULL;
    double bb[6] = {0};
    if (cm_cad_read(ctx, in, &opt, &g) != CM_OK ||
        cm_model_write_step(ctx, "bore", 0, out) != CM_OK ||
        cm_cad_read(ctx, out, NULL, &bore) != CM_OK) {
        fprintf(stderr, "unit after a read in metres: %s\n", cm_context_message(ctx));
        ++failed;
    } else {
        cm_cad_bbox(bore, bb);
        if (!(fabs(bb[0] + 2) < 1e-6 && fabs(bb[3] - 2) < 1e-6 && fabs(bb[5] - 2) < 1e-6)) {
            fprintf(stderr, "bore written after a read in metres: bbox x [%g, %g] z [%g, %g]\n",
                    bb[0], bb[3], bb[2], bb[5]);
            ++failed;
        }
    }
    cm_cad_destroy(&g);
    cm_cad_destroy(&bore);
    remove(out);
}

int main(int argc, char **argv)
{
    cm_context *ctx = NULL;
    if (argc < 3) {
        fprintf(stderr, "usage: test_models DATA_DIR WORK_DIR\n");
        return 2;
    }
    if (cm_context_create(&ctx) != CM_OK) return 1;
    static const char *models[] = {"bore", "pipe", "bracket"};
    static double (*const volume[])(double) = {bore_volume, pipe_volume, bracket_volume};
    static const int faces[] = {7, 5, 11};  /* box + bore; 2 caps + 3 sweeps; 7 sides + 2 + 2 holes */
    static char ref[1 << 16], sig[1 << 16];
    for (int m = 0; m < 3; ++m) {
        for (int k = 0; k <= 4; ++k) {
            const double t = 0.25 * k;
            double vol = 0;
            char *out = k == 0 ? ref : sig;
            if (cm_model_signature(ctx, models[m], t, out, sizeof ref, &vol) < 0) {
                fprintf(stderr, "%s t=%g: %s\n", models[m], t, cm_context_message(ctx));
                ++failed;
                continue;
            }
            int nf = -1;
            sscanf(out, "solids %*d faces %d", &nf);
            if (strncmp(out, "solids 1 ", 9) || nf != faces[m]) {
                fprintf(stderr, "%s t=%g: expected 1 solid and %d faces:\n%s", models[m], t,
                        faces[m], out);
                ++failed;
            }
            conics_as_circles(out);
            if (k > 0 && strcmp(ref, sig)) {
                fprintf(stderr, "%s t=%g: topology differs from t=0:\n--- t=0\n%s--- t=%g\n%s",
                        models[m], t, ref, t, sig);
                ++failed;
            }
            const double expect = volume[m](t);
            if (!(fabs(vol - expect) <= 1e-6 * expect)) {
                fprintf(stderr, "%s t=%g: volume %.12g, expected %.12g\n", models[m], t, vol, expect);
                ++failed;
            }
        }
    }
    if (cm_model_signature(ctx, "cube", 0.5, sig, sizeof sig, NULL) != CM_ERR_ARGUMENT) {
        fprintf(stderr, "unknown model accepted\n");
        ++failed;
    }
    if (cm_model_signature(ctx, "bore", 1.5, sig, sizeof sig, NULL) != CM_ERR_ARGUMENT) {
        fprintf(stderr, "t = 1.5 accepted\n");
        ++failed;
    }
    unit_after_a_read_in_metres(ctx, argv[1], argv[2]);
    cm_context_destroy(&ctx);
    printf("%s\n", failed ? "FAILED" : "ok");
    return failed != 0;
}
