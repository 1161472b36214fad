/* The O-grid hex meshes of bore and pipe at t = 0: no inverted hex (Verdict scaled Jacobian),
 * every node of the mesh boundary exactly on the model (analytic surfaces, 1e-12), the hex
 * volume close to the solid's (the faceted bore/pipe wall loses a little: 1e-2), and sizes
 * within the 10k - 50k nodes. */
#include "cadmorph/models.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int failed;
#define EXPECT(cond, ...)                                                                          \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: %s: ", __FILE__, __LINE__, #cond);                             \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            ++failed;                                                                              \
        }                                                                                          \
    } while (0)

static double bore_distance(const double *x)
{
    double d = fabs(hypot(x[0], x[1]) - 0.6);
    const double f[6] = {fabs(x[0] - 2), fabs(x[0] + 2), fabs(x[1] - 2),
                         fabs(x[1] + 2), fabs(x[2]),     fabs(x[2] - 2)};
    for (int k = 0; k < 6; ++k) d = fmin(d, f[k]);
    return d;
}

/* distance from the pipe's surface: wall (radius 0.5 about the centreline) or an end cap */
static double pipe_distance(const double *x)
{
    cm_model_pipe p;
    cm_model_pipe_at(0, &p);
    const double a = p.bend_deg * M_PI / 180.0;
    double best = INFINITY;
    /* inlet */
    if (x[0] >= -1e-12 && x[0] <= p.inlet + 1e-12) {
        best = fmin(best, fabs(hypot(x[1], x[2]) - p.radius));
        if (hypot(x[1], x[2]) <= p.radius + 1e-12) best = fmin(best, fabs(x[0]));
    }
    /* bend: torus about (inlet, R, z) */
    const double rx = x[0] - p.inlet, ry = x[1] - p.bend_radius;
    const double phi = atan2(rx, -ry);
    if (phi >= -1e-12 && phi <= a + 1e-12)
        best = fmin(best, fabs(hypot(hypot(rx, ry) - p.bend_radius, x[2]) - p.radius));
    /* outlet */
    const double o[3] = {p.inlet + p.bend_radius * sin(a), p.bend_radius * (1 - cos(a)), 0};
    const double t[3] = {cos(a), sin(a), 0};
    const double l = (x[0] - o[0]) * t[0] + (x[1] - o[1]) * t[1];
    if (l >= -1e-12 && l <= p.outlet + 1e-12) {
        const double q[3] = {x[0] - o[0] - l * t[0], x[1] - o[1] - l * t[1], x[2]};
        const double r = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        best = fmin(best, fabs(r - p.radius));
        if (r <= p.radius + 1e-12) best = fmin(best, fabs(l - p.outlet));
    }
    return best;
}

static double hex_volume(const cm_mesh *m, const int64_t *n)
{
    /* 6 tets of the hex's diagonal 0-6 decomposition (exact for planar faces, close otherwise) */
    static const int tets[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6},
                                   {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    double v = 0;
    for (int t = 0; t < 6; ++t) {
        const double *a = &m->xyz[3 * n[tets[t][0]]], *b = &m->xyz[3 * n[tets[t][1]]],
                     *c = &m->xyz[3 * n[tets[t][2]]], *d = &m->xyz[3 * n[tets[t][3]]];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double z[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
        v += (u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0]) +
              u[2] * (w[0] * z[1] - w[1] * z[0])) / 6.0;
    }
    return v;
}

static void check(cm_context *ctx, const char *name, cm_mesh *m, double (*dist)(const double *),
                  double volume)
{
    double *sj = malloc(m->n_cells * sizeof *sj);
    cm_quality_stats all;
    EXPECT(cm_mesh_quality(ctx, m, sj) == CM_OK && cm_quality_summarize(ctx, m, sj, NULL, &all) == CM_OK,
           "%s", cm_context_message(ctx));
    EXPECT(all.inverted == 0 && all.min > 0, "%s: %zu inverted, min SJ %g", name, all.inverted, all.min);
    EXPECT(m->n_nodes >= 10000 && m->n_nodes <= 50000, "%s: %zu nodes", name, m->n_nodes);
    cm_mesh_boundary *b = NULL;
    EXPECT(cm_mesh_boundary_create(ctx, m, &b) == CM_OK, "%s", cm_context_message(ctx));
    double worst = 0;
    for (size_t i = 0; b && i < b->n_nodes; ++i) worst = fmax(worst, dist(&m->xyz[3 * b->nodes[i]]));
    EXPECT(worst <= 1e-12, "%s: a boundary node %g off the surface", name, worst);
    EXPECT(b && b->n_components == 1 && b->n_nonmanifold == 0, "%s: boundary", name);
    double v = 0;
    for (size_t c = 0; c < m->n_cells; ++c) v += hex_volume(m, m->conn + m->offset[c]);
    EXPECT(fabs(v - volume) <= 1e-2 * volume, "%s: volume %.9g, solid %.9g", name, v, volume);
    printf("%s: %zu nodes, %zu hexes, min SJ %.4g, boundary %g off, volume %.6f of %.6f\n", name,
           m->n_nodes, m->n_cells, all.min, worst, v, volume);
    cm_mesh_boundary_destroy(&b);
    free(sj);
}

int main(void)
{
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_mesh *m = NULL;
    EXPECT(cm_hexmesh_bore(ctx, 96, 20, 16, 1.05, &m) == CM_OK, "%s", cm_context_message(ctx));
    if (m) check(ctx, "bore", m, bore_distance, 32.0 - M_PI * 0.36 * 2.0);
    cm_mesh_destroy(&m);
    EXPECT(cm_hexmesh_pipe(ctx, 8, 6, 0.1, &m) == CM_OK, "%s", cm_context_message(ctx));
    if (m) check(ctx, "pipe", m, pipe_distance, M_PI * 0.25 * (2.0 + M_PI + 2.0));
    cm_mesh_destroy(&m);
    EXPECT(cm_hexmesh_bore(ctx, 90, 20, 16, 1.05, &m) == CM_ERR_ARGUMENT && !m, "n_theta 90 accepted");
    cm_context_destroy(&ctx);
    printf("%s\n", failed ? "FAILED" : "ok");
    return failed != 0;
}
