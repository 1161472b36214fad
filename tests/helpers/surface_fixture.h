/* Shared set-up of the surface tests: STEP fixtures of tests/data/surface, gmsh meshes made at
 * test time (make_meshes.py) in <work>/surface, and the closed-form motions they undergo. */
#ifndef CADMORPH_TEST_SURFACE_FIXTURE_H
#define CADMORPH_TEST_SURFACE_FIXTURE_H

#include "cadmorph/surface.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *fx_data, *fx_work;

static inline void fx_step_path(char *out, size_t n, const char *name)
{
    snprintf(out, n, "%s/surface/%s.step", fx_data, name);
}

static inline void fx_mesh_path(char *out, size_t n, const char *name)
{
    snprintf(out, n, "%s/surface/%s.msh", fx_work, name);
}

static inline cm_cad_model *fx_model(cm_context *ctx, const char *name)
{
    char path[2048];
    fx_step_path(path, sizeof path, name);
    cm_cad_model *m = NULL;
    cm_status s = cm_cad_read(ctx, path, NULL, &m);
    CHECK_MSG(s == CM_OK, "%s: %s", path, cm_context_message(ctx));
    return m;
}

static inline cm_mesh *fx_mesh(cm_context *ctx, const char *name)
{
    char path[2048];
    fx_mesh_path(path, sizeof path, name);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    CHECK_MSG(s == CM_OK, "%s: %s", path, cm_context_message(ctx));
    return m;
}

static inline double fx_diagonal(const cm_cad_model *m)
{
    double b[6];
    cm_cad_bbox(m, b);
    return sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) +
                (b[5] - b[2]) * (b[5] - b[2]));
}

static inline double fx_dist(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* The rigid motion of hole_rigid (gen_fixtures.py): rotation by 0.7 about the axis
 * (0.3, 0.5, 1.0) through (1, 2, 0), then translation by (3.5, -2, 1.25). Rodrigues. */
static inline void fx_rigid(const double *x, double *y)
{
    double k[3] = {0.3, 0.5, 1.0}, c[3] = {1, 2, 0}, t[3] = {3.5, -2.0, 1.25}, a = 0.7;
    double kn = sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]);
    for (int i = 0; i < 3; ++i)
        k[i] /= kn;
    double p[3] = {x[0] - c[0], x[1] - c[1], x[2] - c[2]};
    double kxp[3] = {k[1] * p[2] - k[2] * p[1], k[2] * p[0] - k[0] * p[2],
                     k[0] * p[1] - k[1] * p[0]};
    double kp = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
    for (int i = 0; i < 3; ++i)
        y[i] = p[i] * cos(a) + kxp[i] * sin(a) + k[i] * kp * (1 - cos(a)) + c[i] + t[i];
}

/* cyl_a -> cyl_b: radius 2 -> 2.6, height 6 -> 8, axis z through the origin. A (u,v) warp
 * that is linear on the boundary stays linear (the RBF reproduces linear functions), so the
 * morph is this affine map on every face. */
static inline void fx_cylinder(const double *x, double *y)
{
    y[0] = 1.3 * x[0];
    y[1] = 1.3 * x[1];
    y[2] = x[2] * 8.0 / 6.0;
}

/* sphere_a -> sphere_b: centre 0 -> (1.5, 0, 0), radius 3 -> 3.3: (u,v) unchanged. */
static inline void fx_sphere(const double *x, double *y)
{
    y[0] = 1.5 + 1.1 * x[0];
    y[1] = 1.1 * x[1];
    y[2] = 1.1 * x[2];
}

#endif
