/* Scaled Jacobian on cells whose value follows by hand from Verdict's definitions (the
 * derivations are in the comments), plus per-mesh quality and its summary statistics. */
#include "cadmorph/mesh.h"
#include "test_util.h"

#include <math.h>
#include <string.h>

#define TOL 1e-12
#define VERDICT_DBL_MAX 1.0e+30

static double sj(cm_cell_type t, const double (*p)[3]) { return cm_quality_scaled_jacobian(t, &p[0][0]); }

static void test_tet(void)
{
    /* regular tet: 1 */
    const double s3 = sqrt(3.0);
    double reg[4][3] = {{0, 0, 0}, {1, 0, 0}, {0.5, s3 / 2, 0}, {0.5, s3 / 6, sqrt(2.0 / 3.0)}};
    CHECK_NEAR(sj(CM_CELL_TET4, reg), 1.0, TOL);
    /* unit right-corner tet: det = 1; edge-length products at the corners: 1 (node 0) and
     * 1 * sqrt2 * sqrt2 = 2 (nodes 1..3), max 2 -> sqrt2 * 1 / 2 = 1/sqrt2 */
    double right[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    CHECK_NEAR(sj(CM_CELL_TET4, right), 1 / sqrt(2.0), TOL);
    /* inverted: swap nodes 1 and 2 -> -1/sqrt2 */
    double inv[4][3] = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}};
    CHECK_NEAR(sj(CM_CELL_TET4, inv), -1 / sqrt(2.0), TOL);
    /* flattened regular tet: apex height t * sqrt(2/3). det = (sqrt3/2) t sqrt(2/3) = t/sqrt2;
     * lateral edge L^2 = 1/3 + 2t^2/3; for t < 1 the largest corner product is a base corner
     * 1 * 1 * L -> SJ = sqrt2 (t/sqrt2) / L = t / L. t = 0.5: L = sqrt(0.5), SJ = 1/sqrt2. */
    for (double t = 0.1; t < 1.0; t += 0.2) {
        double f[4][3];
        memcpy(f, reg, sizeof f);
        f[3][2] = t * sqrt(2.0 / 3.0);
        CHECK_NEAR(sj(CM_CELL_TET4, f), t / sqrt(1.0 / 3 + 2 * t * t / 3), TOL);
    }
    /* sheared: apex moved sideways by s at the height of the right tet: (s, 0, 1).
     * det = 1, edges at node 0: 1, 1, sqrt(1+s^2); node 1: |01|=1, |12|=sqrt2, |13|^2=(s-1)^2+1;
     * node 2: sqrt2, 1, |23|^2 = s^2+2; node 3: sqrt(1+s^2), |13|, |23|. s = 2: products^2:
     * 5, 1*2*2=4, 2*1*6=12, 5*2*6=60 -> SJ = sqrt2/sqrt60 */
    double sh[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 1}};
    CHECK_NEAR(sj(CM_CELL_TET4, sh), sqrt(2.0) / sqrt(60.0), TOL);
    /* degenerate: all four nodes in a plane -> 0; all four at one point -> Verdict's +1e30 */
    double flat[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    CHECK_NEAR(sj(CM_CELL_TET4, flat), 0.0, TOL);
    double point[4][3] = {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}};
    CHECK(sj(CM_CELL_TET4, point) == VERDICT_DBL_MAX);
    /* higher order: tet10 uses its corners only */
    double t10[10][3];
    memcpy(t10, right, sizeof right);
    for (int i = 4; i < 10; ++i) t10[i][0] = t10[i][1] = t10[i][2] = 7.0 * i;
    CHECK_NEAR(sj(CM_CELL_TET10, t10), 1 / sqrt(2.0), TOL);
    /* scale invariance */
    double big[4][3];
    for (int i = 0; i < 4; ++i)
        for (int d = 0; d < 3; ++d) big[i][d] = 1e3 * sh[i][d] + 5;
    CHECK_NEAR(sj(CM_CELL_TET4, big), sqrt(2.0) / sqrt(60.0), 1e-10);
}

static void box(double (*p)[3], double a, double b, double c)
{
    const double u[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (int i = 0; i < 8; ++i) {
        p[i][0] = a * u[i][0];
        p[i][1] = b * u[i][1];
        p[i][2] = c * u[i][2];
    }
}

static void test_hex(void)
{
    double h[27][3];
    box(h, 1, 1, 1);
    CHECK_NEAR(sj(CM_CELL_HEX8, h), 1.0, TOL);
    box(h, 1, 2, 3); /* any box: every corner and the centre have orthogonal edges */
    CHECK_NEAR(sj(CM_CELL_HEX8, h), 1.0, TOL);
    /* sheared: top face shifted by s in x. Every corner: edges (+-1,0,0), (0,+-1,0),
     * +-(s,0,1), det 1 (right-handed), lengths 1*1*sqrt(1+s^2); centre vectors 4x the same.
     * SJ = 1/sqrt(1+s^2); s = 1 -> 1/sqrt2 */
    for (double s = 0.25; s <= 2.0; s += 0.25) {
        box(h, 1, 1, 1);
        for (int i = 4; i < 8; ++i) h[i][0] += s;
        CHECK_NEAR(sj(CM_CELL_HEX8, h), 1 / sqrt(1 + s * s), TOL);
    }
    /* tapered: top face x-extent shrunk to [0, 0.5]: at corner 1 the edges are (-1,0,0),
     * (0,1,0), (-0.5,0,1): det = 1 (|(-1,0,0).((0,1,0)x(-0.5,0,1))| = 1), lengths sqrt(1.25)
     * -> 1/sqrt(1.25); the other corners and the centre are >= that. */
    box(h, 1, 1, 1);
    h[5][0] = h[6][0] = 0.5;
    CHECK_NEAR(sj(CM_CELL_HEX8, h), 1 / sqrt(1.25), TOL);
    /* inverted: top and bottom swapped -> -1 */
    double inv[8][3];
    box(h, 1, 1, 1);
    for (int i = 0; i < 4; ++i) {
        memcpy(inv[i], h[i + 4], sizeof inv[i]);
        memcpy(inv[i + 4], h[i], sizeof inv[i]);
    }
    CHECK_NEAR(sj(CM_CELL_HEX8, inv), -1.0, TOL);
    /* flattened: top shifted onto the bottom plane along x (zeta = (1,0,0) parallel to xi):
     * every det = 0 with non-zero edges -> 0 */
    box(h, 1, 1, 1);
    for (int i = 4; i < 8; ++i) {
        h[i][0] += 1.0;
        h[i][2] = 0;
    }
    CHECK_NEAR(sj(CM_CELL_HEX8, h), 0.0, TOL);
    /* zero-length edge (node 1 on node 0): Verdict returns +1e30 */
    box(h, 1, 1, 1);
    memcpy(h[1], h[0], sizeof h[1]);
    CHECK(sj(CM_CELL_HEX8, h) == VERDICT_DBL_MAX);
    /* hex20 / hex27: corners only */
    box(h, 1, 1, 1);
    for (int i = 8; i < 27; ++i) h[i][0] = h[i][1] = h[i][2] = -3.0 * i;
    CHECK_NEAR(sj(CM_CELL_HEX20, h), 1.0, TOL);
    CHECK_NEAR(sj(CM_CELL_HEX27, h), 1.0, TOL);
}

/* Right wedge in VTK order: triangle 0-1-2 turning clockwise seen from 3-4-5 (VTK's
 * orientation, whose face 0-1-2 points outward), i.e. Verdict's wedge mirrored. */
static void wedge(double (*p)[3], const double tri[3][2], double h, double sx)
{
    static const int vtk_from_tri[3] = {0, 2, 1};
    for (int i = 0; i < 3; ++i) {
        const double *t = tri[vtk_from_tri[i]];
        p[i][0] = t[0];
        p[i][1] = t[1];
        p[i][2] = 0;
        p[i + 3][0] = t[0] + sx;
        p[i + 3][1] = t[1];
        p[i + 3][2] = h;
    }
}

static void test_wedge(void)
{
    const double s3 = sqrt(3.0);
    const double equi[3][2] = {{0, 0}, {1, 0}, {0.5, s3 / 2}};
    const double right[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    double w[18][3];
    /* each corner: two triangle edges of length 1 at 60 degrees and the vertical edge h:
     * det = h sin60, lengths h -> sqrt3/2, times Verdict's 2/sqrt3 = 1, for any height */
    wedge(w, equi, 1.0, 0);
    CHECK_NEAR(sj(CM_CELL_WEDGE6, w), 1.0, TOL);
    wedge(w, equi, 5.0, 0);
    CHECK_NEAR(sj(CM_CELL_WEDGE6, w), 1.0, TOL);
    /* right-isosceles triangle: at a 45 degree corner det = 1*sqrt2*sin45*h = h, lengths
     * 1*sqrt2*h -> 1/sqrt2; times 2/sqrt3 -> sqrt(2/3) */
    wedge(w, right, 1.0, 0);
    CHECK_NEAR(sj(CM_CELL_WEDGE6, w), sqrt(2.0 / 3.0), TOL);
    /* sheared: top shifted by s in x; vertical edges (s,0,1): det = sqrt3/2, lengths
     * sqrt(1+s^2) -> 1/sqrt(1+s^2) */
    for (double s = 0.5; s <= 2.0; s += 0.5) {
        wedge(w, equi, 1.0, s);
        CHECK_NEAR(sj(CM_CELL_WEDGE6, w), 1 / sqrt(1 + s * s), TOL);
    }
    /* inverted: Verdict's own (gmsh) numbering is VTK's mirror -> -1 */
    wedge(w, equi, 1.0, 0);
    double inv[6][3];
    static const int mirror[6] = {0, 2, 1, 3, 5, 4};
    for (int i = 0; i < 6; ++i) memcpy(inv[i], w[mirror[i]], sizeof inv[i]);
    CHECK_NEAR(sj(CM_CELL_WEDGE6, inv), -1.0, TOL);
    /* flattened: top triangle in the bottom plane, shifted so that no edge is zero -> 0 */
    wedge(w, equi, 0.0, 0.5);
    CHECK_NEAR(sj(CM_CELL_WEDGE6, w), 0.0, TOL);
    /* collapsed edge: counted as inverted (-1e30, as VTK 9.1's Verdict build returns) */
    wedge(w, equi, 0.0, 0.0);
    CHECK(sj(CM_CELL_WEDGE6, w) == -VERDICT_DBL_MAX);
    /* wedge15 / wedge18 use corners */
    wedge(w, equi, 1.0, 0);
    for (int i = 6; i < 18; ++i) w[i][0] = w[i][1] = w[i][2] = 11.0 * i;
    CHECK_NEAR(sj(CM_CELL_WEDGE15, w), 1.0, TOL);
    CHECK_NEAR(sj(CM_CELL_WEDGE18, w), 1.0, TOL);
}

static void pyramid(double (*p)[3], double ax, double ay, double h)
{
    const double base[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    memcpy(p, base, sizeof base);
    p[4][0] = ax;
    p[4][1] = ay;
    p[4][2] = h;
}

static void test_pyramid(void)
{
    double p[14][3];
    /* unit square base, apex (0.5, 0.5, h). Each of Verdict's four sub-tets (three base corners
     * + apex) has det = h and largest corner product sqrt(max(2 (0.5+h^2), (0.5+h^2)^3)), so
     * SJ = sqrt2 * [sqrt2 h / that]. All edges equal (h = 1/sqrt2): 1. */
    pyramid(p, 0.5, 0.5, 1 / sqrt(2.0));
    CHECK_NEAR(sj(CM_CELL_PYR5, p), 1.0, TOL);
    /* flattened, h = 0.1: max product sqrt(2 * 0.51) -> SJ = sqrt2 * 0.1 / sqrt(0.51) */
    pyramid(p, 0.5, 0.5, 0.1);
    CHECK_NEAR(sj(CM_CELL_PYR5, p), sqrt(2.0) * 0.1 / sqrt(0.51), TOL);
    /* tall, h = 2: max product (4.5)^(3/2) -> SJ = sqrt2 * sqrt2 * 2 / 4.5^1.5 */
    pyramid(p, 0.5, 0.5, 2.0);
    CHECK_NEAR(sj(CM_CELL_PYR5, p), 4.0 / pow(4.5, 1.5), TOL);
    /* sheared: apex above corner 0 at height 1. Sub-tets: (0,1,2,4) det 1, max product sqrt6
     * -> 1/sqrt3; (0,1,3,4) is the right tet -> 1/sqrt2; (1,2,3,4) det 1, max product
     * sqrt2 sqrt3 sqrt2 -> 1/sqrt6; min 1/sqrt6 times sqrt2 = 1/sqrt3 */
    pyramid(p, 0.0, 0.0, 1.0);
    CHECK_NEAR(sj(CM_CELL_PYR5, p), 1 / sqrt(3.0), TOL);
    /* inverted (apex below the base): Verdict returns 0, not a negative value */
    pyramid(p, 0.5, 0.5, -0.7);
    CHECK(sj(CM_CELL_PYR5, p) == 0.0);
    /* flat (apex in the base plane): 0 */
    pyramid(p, 0.5, 0.5, 0.0);
    CHECK_NEAR(sj(CM_CELL_PYR5, p), 0.0, TOL);
    /* pyramid13 / 14: corners only */
    pyramid(p, 0.5, 0.5, 1 / sqrt(2.0));
    for (int i = 5; i < 14; ++i) p[i][0] = p[i][1] = p[i][2] = 13.0 * i;
    CHECK_NEAR(sj(CM_CELL_PYR13, p), 1.0, TOL);
    CHECK_NEAR(sj(CM_CELL_PYR14, p), 1.0, TOL);
    /* no definition for other types */
    CHECK(isnan(sj(CM_CELL_TRI3, p)));
    CHECK(isnan(sj(CM_CELL_POLYHEDRON, p)));
}

static void test_polyhedron(void)
{
    double xyz[8][3];
    box(xyz, 1, 1, 1);
    /* the unit cube as a polyhedron, VTK's hex faces (outward) */
    const int64_t cube[] = {6, 4, 0, 4, 7, 3, 4, 1, 2, 6, 5, 4, 0, 1, 5, 4,
                            4, 3, 7, 6, 2, 4, 0, 3, 2, 1, 4, 4, 5, 6, 7};
    /* every sub-tet (a, face centre, b, cell centre) is congruent to the one of the bottom
     * face with a = (0,0,0), b = (0,1,0): det 1/4, corner products^2 0.375, 0.0625, 0.375,
     * 0.140625 -> SJ = sqrt2 * 0.25 / sqrt(0.375) = 1/sqrt3 */
    CHECK_NEAR(cm_quality_polyhedron(&xyz[0][0], cube), 1 / sqrt(3.0), TOL);
    /* faces turned inward: every sub-tet is mirrored -> -1/sqrt3 */
    int64_t inward[sizeof cube / sizeof *cube];
    memcpy(inward, cube, sizeof cube);
    for (size_t f = 0, k = 1; f < 6; ++f, k += 5) {
        int64_t t = inward[k + 2];
        inward[k + 2] = inward[k + 4];
        inward[k + 4] = t;
    }
    CHECK_NEAR(cm_quality_polyhedron(&xyz[0][0], inward), -1 / sqrt(3.0), TOL);
    /* a node pushed through the opposite face: some sub-tet inverts */
    double dent[8][3];
    memcpy(dent, xyz, sizeof dent);
    dent[6][0] = dent[6][1] = dent[6][2] = -0.5;
    CHECK(cm_quality_polyhedron(&dent[0][0], cube) <= 0);
    const int64_t empty[] = {0};
    CHECK(isnan(cm_quality_polyhedron(&xyz[0][0], empty)));
}

static void test_mesh_and_summary(void)
{
    cm_context *ctx = NULL;
    cm_mesh *m = NULL;
    CHECK(cm_context_create(&ctx) == CM_OK);
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, 8, 0) == CM_OK);
    box((double(*)[3])m->xyz, 1, 1, 1);
    const int64_t tet[4] = {0, 1, 3, 4}, tet_inv[4] = {0, 3, 1, 4}, hex[8] = {0, 1, 2, 3, 4, 5, 6, 7};
    const int64_t tri[3] = {0, 1, 2};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, tri, 3, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet, 4, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet_inv, 4, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_HEX8, hex, 8, 0, 0, 0) == CM_OK);
    double q[4];
    CHECK(cm_mesh_quality(ctx, m, q) == CM_OK);
    CHECK(isnan(q[0]));
    CHECK_NEAR(q[1], 1 / sqrt(2.0), TOL);
    CHECK_NEAR(q[2], -1 / sqrt(2.0), TOL);
    CHECK_NEAR(q[3], 1.0, TOL);
    cm_quality_stats per[CM_CELL_TYPE_COUNT], all;
    CHECK(cm_quality_summarize(ctx, m, q, per, &all) == CM_OK);
    CHECK(all.count == 3 && all.inverted == 1);
    CHECK_NEAR(all.min, -1 / sqrt(2.0), TOL);
    CHECK_NEAR(all.mean, 1.0 / 3.0, TOL);
    CHECK(per[CM_CELL_TET4].count == 2 && per[CM_CELL_TET4].inverted == 1);
    CHECK(per[CM_CELL_HEX8].count == 1 && per[CM_CELL_HEX8].inverted == 0);
    CHECK_NEAR(per[CM_CELL_HEX8].p01, 1.0, TOL);
    CHECK(per[CM_CELL_TRI3].count == 0 && per[CM_CELL_WEDGE6].count == 0);
    cm_mesh_destroy(&m);

    /* percentile: 1000 cells with values 0.001 * perm(i); rank floor(0.01 * 999) = 9 */
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, 8, 0) == CM_OK);
    box((double(*)[3])m->xyz, 1, 1, 1);
    enum { N = 1000 };
    static double v[N];
    for (int i = 0; i < N; ++i) {
        CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet, 4, 0, 0, 0) == CM_OK);
        v[i] = 0.001 * (double)((i * 7919) % N); /* a permutation of 0..999 */
    }
    CHECK(cm_quality_summarize(ctx, m, v, NULL, &all) == CM_OK);
    CHECK_NEAR(all.p01, 0.009, 1e-15);
    CHECK_NEAR(all.min, 0.0, 0);
    CHECK(all.inverted == 1);
    CHECK_NEAR(all.mean, 0.4995, 1e-12);
    /* many equal values */
    for (int i = 0; i < N; ++i) v[i] = i < 500 ? 0.5 : 0.25;
    CHECK(cm_quality_summarize(ctx, m, v, NULL, &all) == CM_OK);
    CHECK_NEAR(all.p01, 0.25, 0);
    /* Verdict's 1e30 for a collapsed cell is no quality: 0 in the summary, inverted */
    v[3] = 1e30;
    v[4] = -1e30;
    CHECK(cm_quality_summarize(ctx, m, v, NULL, &all) == CM_OK);
    CHECK(all.inverted == 2);
    CHECK_NEAR(all.min, 0.0, 0);
    CHECK(all.mean < 0.5);
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
}

/* What counts as an inverted cell (docs/DESIGN.md): polyhedra by checkMesh's negative volume
 * and face-pyramid test, other cells of a mesh not read from a polyMesh by their scaled
 * Jacobian; checkMesh's cell models and point usage on a mesh built in memory. */
static void test_invalid_cells(void)
{
    cm_context *ctx = NULL;
    cm_mesh *m = NULL;
    CHECK(cm_context_create(&ctx) == CM_OK);
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    /* a unit cube (nodes 0-7) as a polyhedron, a second cube beside it (nodes 8-15, the
     * first's top corner 6 pushed below its bottom: the tets of the decomposition fold, the
     * face pyramids about the cell centre stay positive), a tet and its mirror, one unused
     * node */
    CHECK(cm_mesh_resize_nodes(ctx, m, 17, 0) == CM_OK);
    box((double(*)[3])m->xyz, 1, 1, 1);
    box((double(*)[3])(m->xyz + 24), 1, 1, 1);
    for (int i = 8; i < 16; ++i) m->xyz[3 * i] += 3;
    m->xyz[3 * 14 + 2] = -0.1;
    m->xyz[3 * 16] = m->xyz[3 * 16 + 1] = m->xyz[3 * 16 + 2] = 9;
    const int64_t cube[] = {6, 4, 0, 4, 7, 3, 4, 1, 2, 6, 5, 4, 0, 1, 5, 4,
                            4, 3, 7, 6, 2, 4, 0, 3, 2, 1, 4, 4, 5, 6, 7};
    int64_t cube2[sizeof cube / sizeof *cube];
    memcpy(cube2, cube, sizeof cube);
    for (size_t f = 0, k = 1; f < 6; ++f, k += 5)
        for (int j = 1; j <= 4; ++j) cube2[k + (size_t)j] += 8;
    const int64_t tet[4] = {0, 1, 3, 4}, tet_inv[4] = {0, 3, 1, 4};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POLYHEDRON, cube, sizeof cube / sizeof *cube, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POLYHEDRON, cube2, sizeof cube2 / sizeof *cube2, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet, 4, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet_inv, 4, 0, 0, 0) == CM_OK);
    double q[4];
    CHECK(cm_mesh_quality(ctx, m, q) == CM_OK);
    CHECK(q[0] > 0 && q[1] < 0 && q[2] > 0 && q[3] < 0);
    uint8_t bad[4];
    size_t n = 0;
    CHECK(cm_mesh_invalid_cells(ctx, m, q, bad, &n) == CM_OK);
    CHECK_MSG(n == 1 && !bad[0] && !bad[1] && !bad[2] && bad[3] == 1, "%zu invalid: %d %d %d %d", n, bad[0], bad[1],
              bad[2], bad[3]);
    cm_quality_stats per[CM_CELL_TYPE_COUNT], all;
    CHECK(cm_quality_summarize(ctx, m, q, per, &all) == CM_OK);
    CHECK(all.inverted == 1 && per[CM_CELL_POLYHEDRON].inverted == 0 && per[CM_CELL_TET4].inverted == 1);
    CHECK(per[CM_CELL_POLYHEDRON].min < 0); /* the scaled Jacobian stays a quality measure */
    cm_mesh_destroy(&m);

    /* the cube with its faces turned inward: checkMesh's negative volume */
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    CHECK(cm_mesh_resize_nodes(ctx, m, 9, 0) == CM_OK);
    box((double(*)[3])m->xyz, 1, 1, 1);
    m->xyz[24] = m->xyz[25] = m->xyz[26] = 5; /* node 8: used by no cell */
    int64_t inward[sizeof cube / sizeof *cube];
    memcpy(inward, cube, sizeof cube);
    for (size_t f = 0, k = 1; f < 6; ++f, k += 5) {
        int64_t t = inward[k + 2];
        inward[k + 2] = inward[k + 4];
        inward[k + 4] = t;
    }
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POLYHEDRON, inward, sizeof inward / sizeof *inward, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_quality(ctx, m, q) == CM_OK);
    CHECK(cm_mesh_invalid_cells(ctx, m, q, bad, &n) == CM_OK);
    CHECK(n == 1 && bad[0] == 2);
    /* checkMesh on it: a hexahedron by OpenFOAM's cell models, the unused point fails */
    memcpy(m->conn, cube, sizeof cube);
    cm_foam_quality fq;
    CHECK(cm_mesh_quality_foam(ctx, m, &fq) == CM_OK);
    CHECK(fq.hexahedra == 1 && fq.polyhedra == 0 && fq.cells == 1);
    CHECK(fq.unused_points_faces == 1 && fq.unused_points_cells == 1 && fq.failed_checks == 1);
    CHECK(fq.directions[0] == 1 && fq.directions[1] == 1 && fq.directions[2] == 1 && fq.regions == 1);
    CHECK(!fq.upper_triangular_error && fq.bad_vertex_faces == 0 && fq.illegal_cells == 0);
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
}

/* Same values with 1 and 2 threads (above the parallel threshold). */
static void test_threads(void)
{
    cm_context *ctx = NULL;
    cm_mesh *m = NULL;
    CHECK(cm_context_create(&ctx) == CM_OK);
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    enum { N = 20000 };
    CHECK(cm_mesh_resize_nodes(ctx, m, 4 * N, 0) == CM_OK);
    unsigned r = 12345;
    for (size_t i = 0; i < 12 * (size_t)N; ++i) {
        r = r * 1103515245u + 12345u;
        m->xyz[i] = (double)(r >> 8) / (double)(1u << 24);
    }
    for (int64_t c = 0; c < N; ++c) {
        const int64_t t[4] = {4 * c, 4 * c + 1, 4 * c + 2, 4 * c + 3};
        CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, t, 4, 0, 0, 0) == CM_OK);
    }
    static double q1[N], q2[N];
    cm_context_set_threads(ctx, 1);
    CHECK(cm_mesh_quality(ctx, m, q1) == CM_OK);
    cm_context_set_threads(ctx, 2);
    CHECK(cm_mesh_quality(ctx, m, q2) == CM_OK);
    CHECK(memcmp(q1, q2, sizeof q1) == 0);
    cm_quality_stats all;
    CHECK(cm_quality_summarize(ctx, m, q1, NULL, &all) == CM_OK);
    CHECK(all.count == N && all.inverted > N / 4 && all.inverted < 3 * N / 4); /* random: ~half */
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
}

int main(void)
{
    test_tet();
    test_invalid_cells();
    test_hex();
    test_wedge();
    test_pyramid();
    test_polyhedron();
    test_mesh_and_summary();
    test_threads();
    return TEST_REPORT();
}
