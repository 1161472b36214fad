/* cm_warp: affine boundary motion is reproduced inside (the linear polynomial makes it exact),
 * prescribed nodes keep their values, components move independently, thread count does not
 * change the result, degenerate and empty inputs are errors. Meshes are built in code. */
#include "cadmorph/warp.h"
#include "test_util.h"
#include "test_mesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static char last_warning[1024];

static void keep_warning(void *user, cm_log_level level, const char *message)
{
    (void)user;
    if (level == CM_LOG_WARNING) snprintf(last_warning, sizeof last_warning, "%s", message);
}

typedef struct affine {
    double a[3][3]; /* displacement d(x) = a x + t (the motion is x + d(x)) */
    double t[3];
} affine;

static void random_affine(uint64_t *seed, double scale, affine *f)
{
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            f->a[i][j] = scale * test_rand(seed);
        f->t[i] = scale * test_rand(seed);
    }
}

static void affine_eval(const affine *f, const double *x, double *d)
{
    for (int i = 0; i < 3; ++i)
        d[i] = f->a[i][0] * x[0] + f->a[i][1] * x[1] + f->a[i][2] * x[2] + f->t[i];
}

static unsigned char *boundary_mask(const cm_mesh *m, const cm_mesh_boundary *b)
{
    unsigned char *mask = calloc(m->n_nodes, 1);
    for (size_t i = 0; i < b->n_nodes; ++i)
        mask[b->nodes[i]] = 1;
    return mask;
}

/* Fills disp: f at constrained nodes, NaN elsewhere (apply must not read those). */
static double *prescribe(const cm_mesh *m, const unsigned char *mask, const affine *f)
{
    double *d = malloc(3 * m->n_nodes * sizeof *d);
    for (size_t v = 0; v < m->n_nodes; ++v)
        for (int c = 0; c < 3; ++c)
            d[3 * v + c] = NAN;
    for (size_t v = 0; v < m->n_nodes; ++v)
        if (mask[v]) affine_eval(f, m->xyz + 3 * v, d + 3 * v);
    return d;
}

/* max |d - f(x)| / max |f(x)| over nodes [first, last) */
static double affine_error(const cm_mesh *m, const double *d, const affine *f, size_t first,
                           size_t last, size_t *n_nan)
{
    double err = 0, range = 0;
    for (size_t v = first; v < last; ++v) {
        double e[3];
        affine_eval(f, m->xyz + 3 * v, e);
        for (int c = 0; c < 3; ++c) {
            if (!isfinite(d[3 * v + c])) ++*n_nan;
            err = fmax(err, fabs(d[3 * v + c] - e[c]));
            range = fmax(range, fabs(e[c]));
        }
    }
    return err / range;
}

static void test_affine(int tets, cm_warp_method kernel)
{
    uint64_t seed = 12345 + (unsigned)tets;
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block blk = {7, 5, 4, {-0.3, 0.2, 1.0}, {0.25, 0.3, 0.2}, tets, tets ? 0.2 : 0.0};
    CHECK(test_add_block(ctx, m, &blk, &seed) == 0);
    cm_mesh_boundary *b = NULL;
    cm_status s = cm_mesh_boundary_create(ctx, m, &b);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (s != CM_OK) {
        cm_mesh_destroy(&m);
        return;
    }
    CHECK(b->n_components == 1);
    affine f;
    random_affine(&seed, 0.3, &f);
    unsigned char *mask = boundary_mask(m, b);
    double *d = prescribe(m, mask, &f);
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    CHECK(opt.method == CM_WARP_RBF);
    opt.method = kernel;
    cm_warp *w = NULL;
    s = cm_warp_create(ctx, m, b, NULL, &opt, &w); /* NULL: the boundary nodes */
    CHECK_MSG(s == CM_OK && w, "%s", cm_context_message(ctx));
    if (w) {
        s = cm_warp_apply(ctx, w, d);
        CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
        size_t n_nan = 0, exact = 0, n_interior = 0;
        double err = affine_error(m, d, &f, 0, m->n_nodes, &n_nan);
        CHECK(n_nan == 0);
        CHECK_MSG(err <= 1e-10, "%s method %d: affine motion reproduced to %.3g relative",
                  tets ? "tet" : "hex", (int)kernel, err);
        for (size_t v = 0; v < m->n_nodes; ++v) {
            double e[3];
            affine_eval(&f, m->xyz + 3 * v, e);
            if (mask[v])
                exact += !memcmp(e, d + 3 * v, sizeof e);
            else
                ++n_interior;
        }
        CHECK(n_interior > 0);
        CHECK_MSG(exact == b->n_nodes, "%zu of %zu boundary nodes kept their value bit for bit",
                  exact, b->n_nodes);
        printf("affine %s method %d: %zu nodes, %zu boundary, max rel error %.3g\n",
               tets ? "tet" : "hex", (int)kernel, m->n_nodes, b->n_nodes, err);
        /* a second displacement on the same factorisation (absolute sweep) */
        affine g;
        random_affine(&seed, 0.1, &g);
        free(d);
        d = prescribe(m, mask, &g);
        CHECK(cm_warp_apply(ctx, w, d) == CM_OK);
        n_nan = 0;
        CHECK(affine_error(m, d, &g, 0, m->n_nodes, &n_nan) <= 1e-10);
    }
    cm_warp_destroy(&w);
    CHECK(w == NULL);
    free(mask);
    free(d);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* Smooth non-affine boundary motion: 1 thread vs 2 threads. */
static void test_threads(void)
{
    uint64_t seed = 99;
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block blk = {8, 7, 6, {0, 0, 0}, {0.125, 0.15, 0.2}, 1, 0.2};
    test_add_block(ctx, m, &blk, &seed);
    cm_mesh_boundary *b = NULL;
    if (cm_mesh_boundary_create(ctx, m, &b) != CM_OK) {
        CHECK_MSG(0, "%s", cm_context_message(ctx));
        cm_mesh_destroy(&m);
        return;
    }
    double *d[2];
    for (int r = 0; r < 2; ++r) {
        d[r] = calloc(3 * m->n_nodes, sizeof(double));
        for (size_t i = 0; i < b->n_nodes; ++i) {
            const double *x = m->xyz + 3 * b->nodes[i];
            double *u = d[r] + 3 * b->nodes[i];
            u[0] = 0.05 * sin(3 * x[1]) * cos(2 * x[2]);
            u[1] = 0.04 * x[0] * x[0] - 0.02 * x[2];
            u[2] = 0.03 * cos(4 * x[0] + x[1]);
        }
        cm_context_set_threads(ctx, r + 1);
        cm_warp *w = NULL;
        cm_status s = cm_warp_create(ctx, m, b, NULL, NULL, &w);
        if (s == CM_OK) s = cm_warp_apply(ctx, w, d[r]);
        CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
        cm_warp_destroy(&w);
    }
    cm_context_set_threads(ctx, 0);
    double diff = 0, range = 0;
    for (size_t i = 0; i < 3 * m->n_nodes; ++i) {
        diff = fmax(diff, fabs(d[0][i] - d[1][i]));
        range = fmax(range, fabs(d[0][i]));
    }
    CHECK(range > 0.01);
    CHECK_MSG(diff <= 1e-12 * range, "1 vs 2 threads differ by %.3g (range %.3g)", diff, range);
    printf("threads: %zu nodes, 1 vs 2 threads max diff %.3g (range %.3g)\n", m->n_nodes, diff,
           range);
    free(d[0]);
    free(d[1]);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* Two blocks, each moved by its own affine map. touching: the second block shares one corner
 * node with the first (components meet at a vertex); the maps agree there. */
static void test_two_components(int touching)
{
    uint64_t seed = 777 + (unsigned)touching;
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block b1 = {4, 4, 4, {0, 0, 0}, {0.25, 0.25, 0.25}, 1, 0.15};
    test_block b2 = {5, 3, 4, {1.5, 0, 0}, {0.2, 0.3, 0.25}, 0, 0};
    test_add_block(ctx, m, &b1, &seed);
    size_t first2 = m->n_nodes;
    int64_t corner1 = 4 + 5 * (4 + 5 * 4); /* node (4,4,4) of block 1: x = y = z = 1 */
    if (touching) {
        /* block 2 starts at block 1's far corner; its node (0,0,0) is replaced by corner1 */
        b2.origin[0] = b2.origin[1] = b2.origin[2] = 1.0;
    }
    test_add_block(ctx, m, &b2, &seed);
    if (touching) {
        for (size_t c = 0; c < m->n_cells; ++c)
            for (int64_t k = m->offset[c]; k < m->offset[c + 1]; ++k)
                if (m->conn[k] == (int64_t)first2) m->conn[k] = corner1;
    }
    affine f1, f2;
    random_affine(&seed, 0.2, &f1);
    random_affine(&seed, 0.2, &f2);
    if (touching) {
        /* f2(corner) = f1(corner): shift f2's translation */
        double e1[3], e2[3];
        affine_eval(&f1, m->xyz + 3 * corner1, e1);
        affine_eval(&f2, m->xyz + 3 * corner1, e2);
        for (int c = 0; c < 3; ++c)
            f2.t[c] += e1[c] - e2[c];
    }
    cm_mesh_boundary *b = NULL;
    if (cm_mesh_boundary_create(ctx, m, &b) < 0) {
        CHECK_MSG(0, "%s", cm_context_message(ctx));
        cm_mesh_destroy(&m);
        return;
    }
    CHECK(b->n_components == 2);
    unsigned char *mask = boundary_mask(m, b);
    CHECK(mask[corner1]);
    double *d = prescribe(m, mask, &f1);
    for (size_t v = first2; v < m->n_nodes; ++v)
        if (mask[v]) affine_eval(&f2, m->xyz + 3 * v, d + 3 * v);
    cm_warp *w = NULL;
    cm_status s = cm_warp_create(ctx, m, b, NULL, NULL, &w);
    if (s == CM_OK) s = cm_warp_apply(ctx, w, d);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    size_t n_nan = 0;
    double e1 = affine_error(m, d, &f1, 0, first2, &n_nan);
    double e2 = affine_error(m, d, &f2, first2 + (touching ? 1 : 0), m->n_nodes, &n_nan);
    CHECK(n_nan == 0);
    if (touching) CHECK(isnan(d[3 * first2])); /* block 2's replaced corner: in no cell, unread */
    CHECK_MSG(e1 <= 1e-10 && e2 <= 1e-10, "two components%s: errors %.3g %.3g",
              touching ? " (touching)" : "", e1, e2);
    /* and the blocks did not follow each other's motion */
    double other = affine_error(m, d, &f2, 0, first2, &n_nan);
    CHECK(other > 1e-3);
    printf("two components%s: errors %.3g %.3g\n", touching ? " touching at a vertex" : "", e1, e2);
    cm_warp_destroy(&w);
    if (touching) {
        /* the shared corner left free: evaluated once, by the first component */
        mask[corner1] = 0;
        d[3 * corner1] = d[3 * corner1 + 1] = d[3 * corner1 + 2] = NAN;
        last_warning[0] = '\0';
        s = cm_warp_create(ctx, m, b, mask, NULL, &w);
        if (s == CM_OK) s = cm_warp_apply(ctx, w, d);
        CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
        CHECK_MSG(strstr(last_warning, "1 unconstrained nodes are shared"), "warning '%s'",
                  last_warning);
        double e[3];
        affine_eval(&f1, m->xyz + 3 * corner1, e);
        for (int c = 0; c < 3; ++c)
            CHECK(fabs(d[3 * corner1 + c] - e[c]) <= 1e-10);
        cm_warp_destroy(&w);
    }
    free(mask);
    free(d);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* An interior node pinned by the caller keeps its value and bends the warp around it; a node
 * of no volume cell (here: of a stray line element) is left alone. */
static void test_pinned_and_stray(void)
{
    uint64_t seed = 4242;
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block blk = {6, 6, 6, {0, 0, 0}, {1.0 / 6, 1.0 / 6, 1.0 / 6}, 1, 0.1};
    test_add_block(ctx, m, &blk, &seed);
    size_t n_block = m->n_nodes;
    cm_mesh_resize_nodes(ctx, m, n_block + 2, 0);
    double far[6] = {3, 3, 3, 4, 3, 3};
    memcpy(m->xyz + 3 * n_block, far, sizeof far);
    int64_t line[2] = {(int64_t)n_block, (int64_t)n_block + 1};
    cm_mesh_add_cell(ctx, m, CM_CELL_LINE2, line, 2, 0, 0, 0);
    cm_mesh_boundary *b = NULL;
    if (cm_mesh_boundary_create(ctx, m, &b) < 0) {
        CHECK_MSG(0, "%s", cm_context_message(ctx));
        cm_mesh_destroy(&m);
        return;
    }
    CHECK(b->n_components == 1);
    int64_t centre = 3 + 7 * (3 + 7 * 3), near = 4 + 7 * (3 + 7 * 3);
    unsigned char *mask = boundary_mask(m, b);
    CHECK(!mask[centre] && !mask[near]);
    affine zero;
    memset(&zero, 0, sizeof zero);
    double *d[2];
    for (int pin = 0; pin < 2; ++pin) {
        d[pin] = prescribe(m, mask, &zero); /* boundary fixed */
        d[pin][3 * n_block] = 123.0;        /* stray: must stay */
        if (pin) {
            mask[centre] = 1;
            d[pin][3 * centre] = 0.05;
            d[pin][3 * centre + 1] = -0.02;
            d[pin][3 * centre + 2] = 0.01;
        }
        cm_warp *w = NULL;
        last_warning[0] = '\0';
        cm_status s = cm_warp_create(ctx, m, b, mask, NULL, &w);
        if (s == CM_OK) s = cm_warp_apply(ctx, w, d[pin]);
        CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
        CHECK_MSG(strstr(last_warning, "2 unconstrained nodes belong to no volume cell"),
                  "warning '%s'", last_warning);
        cm_warp_destroy(&w);
        CHECK(d[pin][3 * n_block] == 123.0);
        CHECK(isnan(d[pin][3 * n_block + 1])); /* not written */
    }
    CHECK(d[1][3 * centre] == 0.05 && d[1][3 * centre + 1] == -0.02 &&
          d[1][3 * centre + 2] == 0.01);
    CHECK(fabs(d[0][3 * near]) < 1e-14);                   /* fixed boundary, no pin: no motion */
    CHECK(d[1][3 * near] > 0.01 && d[1][3 * near] < 0.05); /* the pin pulls its neighbour */
    free(d[0]);
    free(d[1]);
    free(mask);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

/* Errors: coplanar constraints name the component; a mesh without volume cells; unknown method. */
static void test_errors(void)
{
    uint64_t seed = 5;
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block b1 = {3, 3, 3, {0, 0, 0}, {1, 1, 1}, 0, 0};
    test_block b2 = {3, 3, 3, {5, 0, 0}, {1, 1, 1}, 1, 0};
    test_add_block(ctx, m, &b1, &seed);
    size_t first2 = m->n_nodes;
    test_add_block(ctx, m, &b2, &seed);
    cm_mesh_boundary *b = NULL;
    if (cm_mesh_boundary_create(ctx, m, &b) < 0) {
        CHECK_MSG(0, "%s", cm_context_message(ctx));
        cm_mesh_destroy(&m);
        return;
    }
    unsigned char *mask = boundary_mask(m, b);
    /* component of block 2: keep only its z = 0 nodes constrained */
    for (size_t v = first2; v < m->n_nodes; ++v)
        if (m->xyz[3 * v + 2] != 0.0) mask[v] = 0;
    cm_warp *w = NULL;
    cm_status s = cm_warp_create(ctx, m, b, mask, NULL, &w);
    int k2 = b->cell_component[m->n_cells - 1];
    char want[32];
    snprintf(want, sizeof want, "component %d", k2);
    CHECK_MSG(s == CM_ERR_NUMERIC && w == NULL, "status %d", (int)s);
    CHECK_MSG(strstr(cm_context_message(ctx), want) != NULL, "message '%s' lacks '%s'",
              cm_context_message(ctx), want);
    printf("coplanar: %s\n", cm_context_message(ctx));
    /* fewer than 4 constrained nodes, then none */
    int kept = 0;
    for (size_t v = first2; v < m->n_nodes; ++v)
        if (mask[v] && ++kept > 3) mask[v] = 0;
    s = cm_warp_create(ctx, m, b, mask, NULL, &w);
    CHECK_MSG(s == CM_ERR_NUMERIC && strstr(cm_context_message(ctx), want), "status %d: %s", (int)s,
              cm_context_message(ctx));
    memset(mask + first2, 0, m->n_nodes - first2);
    s = cm_warp_create(ctx, m, b, mask, NULL, &w);
    CHECK_MSG(s == CM_ERR_NUMERIC && strstr(cm_context_message(ctx), want), "status %d: %s", (int)s,
              cm_context_message(ctx));
    printf("unconstrained: %s\n", cm_context_message(ctx));

    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = (cm_warp_method)CM_WARP_N_METHODS;
    CHECK(cm_warp_create(ctx, m, b, NULL, &opt, &w) == CM_ERR_ARGUMENT && w == NULL);
    CHECK(cm_warp_create(ctx, m, NULL, NULL, NULL, &w) == CM_ERR_ARGUMENT);
    CHECK(cm_warp_apply(ctx, NULL, NULL) == CM_ERR_ARGUMENT);
    cm_warp_destroy(NULL);
    cm_warp_destroy(&w);
    free(mask);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);

    /* only surface cells: nothing to warp */
    cm_mesh_create(ctx, &m);
    cm_mesh_resize_nodes(ctx, m, 3, 0);
    double tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    memcpy(m->xyz, tri, sizeof tri);
    int64_t t[3] = {0, 1, 2};
    cm_mesh_add_cell(ctx, m, CM_CELL_TRI3, t, 3, 0, 0, 0);
    if (cm_mesh_boundary_create(ctx, m, &b) >= 0) {
        s = cm_warp_create(ctx, m, b, NULL, NULL, &w);
        CHECK_MSG(s < 0 && w == NULL, "status %d", (int)s);
        CHECK(strstr(cm_context_message(ctx), "no volume cells") != NULL);
    }
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    cm_context_create(&ctx);
    cm_context_set_log(ctx, keep_warning, NULL);
    test_affine(0, CM_WARP_RBF);
    test_affine(1, CM_WARP_RBF);
    test_affine(1, CM_WARP_RBF_BIHARMONIC);
    test_threads();
    test_two_components(0);
    test_two_components(1);
    test_pinned_and_stray();
    test_errors();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
