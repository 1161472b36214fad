/* Projection (paper section 4): 10,000 points near a box, a cylinder, a sphere, a torus, a box
 * with a cylindrical hole and a B-spline face, all read back from STEP. The distance matches
 * closed-form formulas for the primitives (no OpenCASCADE involved) and, for every shape, the
 * foot point, face and (u,v) by which gen_shapes constructed the point, to 1e-10 relative. */
#include "cadmorph/cad.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct pts {
    size_t n;
    double *xyz, *uv, *dist, *foot;
    int *face;
} pts;

static int read_pts(const char *path, pts *p)
{
    FILE *f = fopen(path, "r");
    if (!f) return 0;
    size_t cap = 10000;
    memset(p, 0, sizeof *p);
    p->xyz = malloc(3 * cap * sizeof(double));
    p->uv = malloc(2 * cap * sizeof(double));
    p->dist = malloc(cap * sizeof(double));
    p->foot = malloc(3 * cap * sizeof(double));
    p->face = malloc(cap * sizeof(int));
    char line[1024];
    while (fgets(line, sizeof line, f) && p->n < cap) {
        if (line[0] == '#') continue;
        size_t i = p->n;
        if (sscanf(line, "%lf %lf %lf %d %lf %lf %lf %lf %lf %lf", &p->xyz[3 * i],
                   &p->xyz[3 * i + 1], &p->xyz[3 * i + 2], &p->face[i], &p->uv[2 * i],
                   &p->uv[2 * i + 1], &p->dist[i], &p->foot[3 * i], &p->foot[3 * i + 1],
                   &p->foot[3 * i + 2]) == 10)
            ++p->n;
    }
    fclose(f);
    return p->n > 0;
}

static void free_pts(pts *p)
{
    free(p->xyz), free(p->uv), free(p->dist), free(p->foot), free(p->face);
}

static double sq(double x) { return x * x; }
static double pos(double x) { return x > 0 ? x : 0; }

/* Closed-form distances to the primitives of gen_shapes (points lie outside the solids). */
static double analytic(const char *name, const double *p)
{
    double x = p[0], y = p[1], z = p[2];
    if (!strcmp(name, "box")) /* [-1,2] x [-2,2] x [-0.5,1.5] */
        return sqrt(sq(pos(fmax(-1 - x, x - 2))) + sq(pos(fmax(-2 - y, y - 2))) +
                    sq(pos(fmax(-0.5 - z, z - 1.5))));
    if (!strcmp(name, "cylinder")) { /* axis (1,2,.) z in [3,8], r 2 */
        double r = sqrt(sq(x - 1) + sq(y - 2));
        return sqrt(sq(pos(r - 2)) + sq(pos(fmax(3 - z, z - 8))));
    }
    if (!strcmp(name, "sphere")) return sqrt(sq(x - 0.5) + sq(y + 1) + sq(z - 2)) - 3;
    if (!strcmp(name, "torus")) {
        double r = sqrt(sq(x - 1) + sq(y - 1));
        return sqrt(sq(r - 5) + sq(z - 1)) - 1.5;
    }
    return NAN;
}

static double wrapdiff(double a, double b, double period)
{
    double d = a - b;
    if (period > 0) d -= period * floor(d / period + 0.5);
    return fabs(d);
}

static void run(cm_context *ctx, const char *work, const char *name)
{
    char path[2048];
    snprintf(path, sizeof path, "%s/cad/%s.step", work, name);
    cm_cad_model *m = NULL;
    CHECK_MSG(cm_cad_read(ctx, path, NULL, &m) == CM_OK, "%s", cm_context_message(ctx));
    snprintf(path, sizeof path, "%s/cad/%s.pts", work, name);
    pts p;
    CHECK(read_pts(path, &p));
    if (!m || !p.n) return;
    double bb[6];
    cm_cad_bbox(m, bb);
    const double L = cm_bbox_diagonal(bb);
    const double tol = 1e-10 * L;

    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    so.h = L / 100;
    cm_cad_locator *loc = NULL;
    CHECK(cm_cad_locator_create(ctx, m, &so, &loc) == CM_OK);
    size_t n = p.n;
    int *face = malloc(n * sizeof *face);
    double *uv = malloc(2 * n * sizeof *uv), *dist = malloc(n * sizeof *dist),
           *foot = malloc(3 * n * sizeof *foot);
    double t0 = cm_wtime();
    CHECK(cm_cad_locate_faces(ctx, loc, p.xyz, n, face, uv, dist, foot) == CM_OK);
    double t1 = cm_wtime();
    size_t bad_dist = 0, bad_analytic = 0, bad_foot = 0, bad_uv = 0, other_face = 0;
    double worst_d = 0, worst_a = 0, worst_uv = 0;
    for (size_t i = 0; i < n; ++i) {
        double e = fabs(dist[i] - p.dist[i]);
        if (e > worst_d) worst_d = e;
        if (e > tol) ++bad_dist;
        double a = analytic(name, &p.xyz[3 * i]);
        if (!isnan(a)) {
            if (fabs(dist[i] - a) > worst_a) worst_a = fabs(dist[i] - a);
            if (fabs(dist[i] - a) > tol) ++bad_analytic;
        }
        double fe = sqrt(sq(foot[3 * i] - p.foot[3 * i]) + sq(foot[3 * i + 1] - p.foot[3 * i + 1]) +
                         sq(foot[3 * i + 2] - p.foot[3 * i + 2]));
        if (fe > 1e-9 * L) ++bad_foot;
        /* the same foot can belong to two faces only on their common edge */
        if (face[i] != p.face[i]) {
            ++other_face;
            continue;
        }
        cm_cad_face_info fi;
        cm_cad_face_get_info(ctx, m, face[i], &fi);
        double du = wrapdiff(uv[2 * i], p.uv[2 * i], fi.period[0]) / (fi.uv_range[1] - fi.uv_range[0]);
        double dv = wrapdiff(uv[2 * i + 1], p.uv[2 * i + 1], fi.period[1]) /
                    (fi.uv_range[3] - fi.uv_range[2]);
        double duv = fmax(du, dv);
        /* (u,v) is ill-conditioned where the surface metric vanishes (sphere poles): compare
         * it where the foot is not within 1e-3 of the axis */
        if (!strcmp(name, "sphere") && fabs(fabs(p.foot[3 * i + 2] - 2) - 3) < 3e-3) continue;
        if (duv > worst_uv) worst_uv = duv;
        if (duv > 1e-10) ++bad_uv;
    }
    printf("%-9s faces %zu samples, h %.3g: %zu points in %.3f s; worst |d - d0| %.2e, "
           "|d - analytic| %.2e, uv %.2e (relative); %zu on another face\n",
           name, cm_cad_locator_samples(loc, NULL, NULL, NULL), cm_cad_locator_h(loc), n, t1 - t0,
           worst_d, worst_a, worst_uv, other_face);
    CHECK_MSG(bad_dist == 0, "%s: %zu distances off by more than %g", name, bad_dist, tol);
    CHECK_MSG(bad_analytic == 0, "%s: %zu distances differ from the formula", name, bad_analytic);
    CHECK_MSG(bad_foot == 0, "%s: %zu foot points off", name, bad_foot);
    CHECK_MSG(bad_uv == 0, "%s: %zu (u,v) off", name, bad_uv);
    CHECK_MSG(other_face <= n / 1000, "%s: %zu points on another face", name, other_face);

    /* the single-face projection without a start value agrees on the constructed face */
    size_t m1 = 300, agree = 0;
    for (size_t i = 0; i < m1; ++i) {
        double u2[2], d2, f2[3];
        if (cm_cad_project_face(ctx, m, p.face[i], &p.xyz[3 * i], 1, NULL, u2, &d2, f2) != CM_OK)
            continue;
        agree += fabs(d2 - p.dist[i]) <= tol;
    }
    CHECK_MSG(agree == m1, "%s: project_face agrees on %zu of %zu", name, agree, m1);

    /* thread count does not change the answer */
    cm_context_set_threads(ctx, 1);
    double *dist1 = malloc(n * sizeof *dist1);
    CHECK(cm_cad_locate_faces(ctx, loc, p.xyz, n, NULL, NULL, dist1, NULL) == CM_OK);
    size_t diff = 0;
    for (size_t i = 0; i < n; ++i) diff += fabs(dist1[i] - dist[i]) > tol;
    CHECK(diff == 0);
    cm_context_set_threads(ctx, 0);
    free(dist1);

    free(face), free(uv), free(dist), free(foot);
    free_pts(&p);
    cm_cad_locator_destroy(&loc);
    CHECK(loc == NULL);
    cm_cad_destroy(&m);
}

/* A gmsh-written model (planes, a bore, a boss with a sphere cap: seams, a pole): samples moved
 * off the surface along the outward normal by d. The nearest point is never farther than d
 * (the constructed foot is a candidate), and equals d away from concave edges. */
static void run_gmsh(cm_context *ctx, const char *data, const char *name)
{
    char path[2048];
    snprintf(path, sizeof path, "%s/cad/%s.step", data, name);
    cm_cad_model *m = NULL;
    CHECK(cm_cad_read(ctx, path, NULL, &m) == CM_OK);
    if (!m) return;
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    so.h = 0.05;
    cm_cad_locator *loc = NULL;
    CHECK(cm_cad_locator_create(ctx, m, &so, &loc) == CM_OK);
    const double *xyz, *uv;
    const int *face;
    size_t ns = cm_cad_locator_samples(loc, &xyz, &face, &uv);
    enum { N = 5000 };
    double *q = malloc(3 * N * sizeof *q), *d0 = malloc(N * sizeof *d0), nrm[3], p[3];
    for (size_t i = 0; i < N; ++i) {
        size_t j = (i * 7919u * 104729u) % ns;
        CHECK(cm_cad_face_eval(ctx, m, face[j], &uv[2 * j], 1, p, nrm) == CM_OK);
        d0[i] = (i % 5) * 0.01;
        for (int k = 0; k < 3; ++k) q[3 * i + k] = p[k] + d0[i] * nrm[k];
    }
    double *d = malloc(N * sizeof *d);
    CHECK(cm_cad_locate_faces(ctx, loc, q, N, NULL, NULL, d, NULL) == CM_OK);
    size_t farther = 0, equal = 0;
    for (size_t i = 0; i < N; ++i) {
        farther += d[i] > d0[i] + 1e-9;
        equal += fabs(d[i] - d0[i]) <= 1e-9;
    }
    CHECK_MSG(farther == 0, "%s: %zu points projected farther than their construction", name,
              farther);
    CHECK_MSG(equal >= N * 97 / 100, "%s: %zu of %d at the constructed distance", name, equal, N);
    free(q), free(d0), free(d);
    cm_cad_locator_destroy(&loc);
    cm_cad_destroy(&m);
}

/* A B-spline face whose boundary curves lie 2e-5 off its surface (gen_shapes: pcurves by
 * projection, tolerances up to ~1e-4, as in industrial STEP files): points of the surface just
 * beyond the trimming curve, within the edges' tolerance, are on the face; their distance is
 * that of the final Newton projection (~1e-16), not the gap to the edge curves. Points well
 * beyond the tolerance keep their true distance to the trimmed face. */
static void run_loose(cm_context *ctx, const char *work)
{
    char path[2048];
    snprintf(path, sizeof path, "%s/cad/loose_bspline.step", work);
    cm_cad_model *m = NULL;
    cm_cad_locator *loc = NULL;
    CHECK(cm_cad_read(ctx, path, NULL, &m) == CM_OK);
    if (!m) return;
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    CHECK(cm_cad_locator_create(ctx, m, &so, &loc) >= 0);
    cm_cad_boundary *b = NULL;
    CHECK(cm_cad_face_boundary(ctx, m, 0, NULL, 40, &b) == CM_OK);
    cm_cad_face_info fi;
    CHECK(cm_cad_face_get_info(ctx, m, 0, &fi) == CM_OK);
    if (!loc || !b) goto done;
    const double cu = 0.5 * (fi.uv_range[0] + fi.uv_range[1]), cv = 0.5 * (fi.uv_range[2] + fi.uv_range[3]);
    const double shifts[2] = {1e-6, 0.02}; /* x the parameter range, outward */
    for (int k = 0; k < 2; ++k) {
        size_t n = b->n;
        double *uv = malloc(2 * n * sizeof *uv), *xyz = malloc(3 * n * sizeof *xyz);
        double *d = malloc(n * sizeof *d), *dp = malloc(n * sizeof *dp);
        for (size_t i = 0; uv && i < n; ++i) {
            /* outward, across the nearer side of the rectangle of pcurves */
            double u = b->uv[2 * i], v = b->uv[2 * i + 1];
            double ru = (u - cu) / (fi.uv_range[1] - fi.uv_range[0]), rv = (v - cv) / (fi.uv_range[3] - fi.uv_range[2]);
            if (fabs(ru) >= fabs(rv))
                u += (ru > 0 ? 1 : -1) * shifts[k] * (fi.uv_range[1] - fi.uv_range[0]);
            else
                v += (rv > 0 ? 1 : -1) * shifts[k] * (fi.uv_range[3] - fi.uv_range[2]);
            uv[2 * i] = u, uv[2 * i + 1] = v;
        }
        CHECK(cm_cad_face_eval(ctx, m, 0, uv, n, xyz, NULL) == CM_OK);
        CHECK(cm_cad_locate_faces(ctx, loc, xyz, n, NULL, NULL, d, NULL) == CM_OK);
        CHECK(cm_cad_project_face(ctx, m, 0, xyz, n, uv, NULL, dp, NULL) == CM_OK);
        double worst = 0, least = INFINITY;
        for (size_t i = 0; i < n; ++i) worst = fmax(worst, fmax(d[i], dp[i])), least = fmin(least, fmin(d[i], dp[i]));
        printf("loose_bspline: %zu surface points %g x range beyond the trimming: distance %.3g .. %.3g\n",
               n, shifts[k], least, worst);
        if (k == 0)
            CHECK_MSG(worst <= 1e-12, "within tolerance of the boundary: reported %g", worst);
        else
            CHECK_MSG(least > 1e-3, "beyond the tolerance: reported %g", least);
        free(uv), free(xyz), free(d), free(dp);
    }
done:
    cm_cad_boundary_destroy(&b);
    cm_cad_locator_destroy(&loc);
    cm_cad_destroy(&m);
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    run_gmsh(ctx, argv[1], "bore_a");
    run_gmsh(ctx, argv[1], "bore_b");
    const char *names[] = {"box", "cylinder", "sphere", "torus", "holed", "bspline"};
    for (size_t i = 0; i < sizeof names / sizeof *names; ++i) run(ctx, argv[2], names[i]);
    run_loose(ctx, argv[2]);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
