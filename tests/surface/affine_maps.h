/* The affine edits G1 = A G0 + b of the affine tests (test_affine.c), shared by the C test and
 * the C++ generator that writes G1 with OpenCASCADE (gen_affine.cpp). Row-major 3 x 4: the
 * first three columns are A, the last one b. */
#ifndef CM_TEST_AFFINE_MAPS_H
#define CM_TEST_AFFINE_MAPS_H

/* rotation by 0.9 rad about the unit axis k = (0.2, -0.5, 0.8) / |.|, then translation */
#define CM_AFFINE_RIGID_ANGLE 0.9
#define CM_AFFINE_RIGID_AXIS {0.2, -0.5, 0.8}
#define CM_AFFINE_RIGID_SHIFT {1.5, -0.7, 2.2}
/* uniform scale by 1.7 about the origin, then translation */
#define CM_AFFINE_SCALE 1.7
#define CM_AFFINE_SCALE_SHIFT {-0.4, 0.9, 0.3}
/* non-uniform scale and shear (BRepBuilderAPI_GTransform): det = 1.3*(1.2-0)-... > 0 */
#define CM_AFFINE_GENERAL                                                                         \
    {                                                                                             \
        {1.3, 0.25, 0.1, 0.6}, {0.0, 0.8, 0.2, -1.1}, {0.15, 0.0, 1.5, 0.4}                       \
    }

/* The 3 x 4 matrix of map `kind` ("rigid", "scale", "general") into m; 0 if unknown. */
static inline int cm_affine_map(const char *kind, double m[3][4])
{
    int i, j;
    if (kind[0] == 'r') { /* Rodrigues */
        double k[3] = CM_AFFINE_RIGID_AXIS, t[3] = CM_AFFINE_RIGID_SHIFT, a = CM_AFFINE_RIGID_ANGLE;
        double n = 0, c, s;
        for (i = 0; i < 3; ++i)
            n += k[i] * k[i];
        n = __builtin_sqrt(n);
        for (i = 0; i < 3; ++i)
            k[i] /= n;
        c = __builtin_cos(a), s = __builtin_sin(a);
        double K[3][3] = {{0, -k[2], k[1]}, {k[2], 0, -k[0]}, {-k[1], k[0], 0}};
        for (i = 0; i < 3; ++i) {
            for (j = 0; j < 3; ++j)
                m[i][j] = (i == j ? c : 0) + s * K[i][j] + (1 - c) * k[i] * k[j];
            m[i][3] = t[i];
        }
        return 1;
    }
    if (kind[0] == 's') {
        double t[3] = CM_AFFINE_SCALE_SHIFT;
        for (i = 0; i < 3; ++i) {
            for (j = 0; j < 3; ++j)
                m[i][j] = i == j ? CM_AFFINE_SCALE : 0;
            m[i][3] = t[i];
        }
        return 1;
    }
    if (kind[0] == 'g') {
        double g[3][4] = CM_AFFINE_GENERAL;
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 4; ++j)
                m[i][j] = g[i][j];
        return 1;
    }
    return 0;
}

#endif
