/* The reverse product of the warps that are not RBF (cm_warp_apply_transpose: femwarp, lbwarp,
 * simplex, dmffd, mls). For random D (at the constrained nodes) and V (everywhere),
 * <V, J D> = <J^T V, D> to 1e-10 relative, on jittered hex and tet blocks, a mesh of two
 * components (hexes and tets) with a constrained node of no cell and a free node of no cell,
 * polyhedra (FEMWARP's centroid unknowns), gmsh's mixed mesh (tets, hexes, wedges, pyramids)
 * and the bore's O-grid, each with interior nodes pinned besides the boundary. Each method's
 * claim that it has a transpose at all rests on apply being linear in D: checked as
 * J(a D1 + b D2) = a J D1 + b J D2. Also: J^T V is 0 at the free nodes and V itself at a
 * constrained node of no cell, repeated calls agree bit for bit (apply in between), and the
 * argument errors. argv[2]/staten/mixed.msh comes from warp_staten.py setup. */
#include "cadmorph/models.h"
#include "cadmorph/warp.h"
#include "test_mesh.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static const cm_warp_method methods[] = {CM_WARP_FEMWARP, CM_WARP_LBWARP, CM_WARP_SIMPLEX,
                                         CM_WARP_DMFFD, CM_WARP_MLS};
enum { N_METHODS = sizeof methods / sizeof *methods };

static double dot(const double *a, const double *b, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; ++i)
        s += a[i] * b[i];
    return s;
}

/* The boundary, and every 5th node that is not on it (pinned interior nodes) */
static unsigned char *constrained_mask(const cm_mesh *m, const cm_mesh_boundary *b)
{
    unsigned char *mask = calloc(m->n_nodes, 1);
    for (size_t i = 0; i < b->n_nodes; ++i)
        mask[b->nodes[i]] = 1;
    size_t k = 0;
    for (size_t v = 0; v < m->n_nodes; ++v)
        if (!mask[v] && k++ % 5 == 2) mask[v] = 1;
    return mask;
}

/* D: random at the constrained nodes, 0 elsewhere (apply reads only the former) */
static void random_d(const unsigned char *mask, size_t n, uint64_t *seed, double *d)
{
    for (size_t v = 0; v < n; ++v)
        for (int k = 0; k < 3; ++k)
            d[3 * v + k] = mask[v] ? test_rand(seed) : 0;
}

/* The dot-product test, linearity and the shape of J^T V for one method on one mesh.
 * loose: a constrained node of no volume cell (-1: none). */
static void check_method(const cm_mesh *m, const cm_mesh_boundary *b, const unsigned char *mask,
                         cm_warp_method method, const char *what, int64_t loose)
{
    const char *name = cm_warp_method_name(method);
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = method;
    cm_warp *w = NULL;
    cm_status s = cm_warp_create(ctx, m, b, mask, &opt, &w);
    CHECK_MSG(s >= 0, "%s %s: %s", what, name, cm_context_message(ctx));
    if (s < 0) return;
    size_t n = m->n_nodes, n3 = 3 * n;
    double *d1 = malloc(n3 * sizeof *d1), *d2 = malloc(n3 * sizeof *d2);
    double *jd1 = malloc(n3 * sizeof *jd1), *jd2 = malloc(n3 * sizeof *jd2);
    double *v = malloc(n3 * sizeof *v), *out = malloc(n3 * sizeof *out);
    double *again = malloc(n3 * sizeof *again);
    uint64_t seed = 1000 + (uint64_t)method;
    double worst_dot = 0, worst_lin = 0;
    for (int trial = 0; trial < 3; ++trial) {
        random_d(mask, n, &seed, d1);
        random_d(mask, n, &seed, d2);
        for (size_t i = 0; i < n3; ++i)
            v[i] = test_rand(&seed);
        memcpy(jd1, d1, n3 * sizeof *jd1);
        memcpy(jd2, d2, n3 * sizeof *jd2);
        s = cm_warp_apply(ctx, w, jd1);
        if (s >= 0) s = cm_warp_apply(ctx, w, jd2);
        if (s >= 0) s = cm_warp_apply_transpose(ctx, w, v, out);
        CHECK_MSG(s >= 0, "%s %s: %s", what, name, cm_context_message(ctx));
        if (s < 0) break;
        /* <V, J D> = <J^T V, D>, relative to the terms' size (a sum of n random products
         * can come out near 0 while each term is not) */
        double lhs = dot(v, jd1, n3), rhs = dot(out, d1, n3);
        double scale = 0;
        for (size_t i = 0; i < n3; ++i)
            scale += fabs(v[i] * jd1[i]);
        worst_dot = fmax(worst_dot, fabs(lhs - rhs) / scale);
        /* J(a D1 + b D2) = a J D1 + b J D2 */
        const double a = 0.75, bb = -1.5;
        double *mix = again, jmax = 0, err = 0;
        for (size_t i = 0; i < n3; ++i)
            mix[i] = a * d1[i] + bb * d2[i];
        s = cm_warp_apply(ctx, w, mix);
        CHECK(s >= 0);
        for (size_t i = 0; i < n3; ++i) {
            jmax = fmax(jmax, fabs(a * jd1[i]) + fabs(bb * jd2[i]));
            err = fmax(err, fabs(mix[i] - (a * jd1[i] + bb * jd2[i])));
        }
        worst_lin = fmax(worst_lin, err / jmax);
        /* where J^T V lives: 0 at the free nodes; V at a constrained node of no cell, which
         * apply leaves alone (mls writes every node: its own rule) */
        int zero_free = 1;
        for (size_t u = 0; u < n; ++u)
            if (!mask[u])
                for (int k = 0; k < 3; ++k)
                    zero_free &= out[3 * u + k] == 0;
        CHECK_MSG(zero_free, "%s %s: J^T V is not 0 at the free nodes", what, name);
        if (loose >= 0 && method != CM_WARP_MLS && method != CM_WARP_DMFFD)
            for (int k = 0; k < 3; ++k)
                CHECK(out[3 * loose + k] == v[3 * loose + k]);
        /* bit for bit again, after an apply that used the same buffers */
        s = cm_warp_apply_transpose(ctx, w, v, again);
        CHECK(s >= 0 && !memcmp(out, again, n3 * sizeof *out));
    }
    printf("%-10s %-8s dot %.2e  linearity %.2e\n", what, name, worst_dot, worst_lin);
    CHECK_MSG(worst_dot <= 1e-10, "%s %s: <V, J D> - <J^T V, D> = %.3g relative", what, name,
              worst_dot);
    CHECK_MSG(worst_lin <= 1e-12, "%s %s: J is not linear in D (%.3g)", what, name, worst_lin);
    free(d1), free(d2), free(jd1), free(jd2), free(v), free(out), free(again);
    cm_warp_destroy(&w);
}

static void check_mesh(const cm_mesh *m, const char *what, int64_t loose,
                       const unsigned char *extra)
{
    cm_mesh_boundary *b = NULL;
    cm_status s = cm_mesh_boundary_create(ctx, m, &b);
    CHECK_MSG(s >= 0, "%s: %s", what, cm_context_message(ctx));
    if (s < 0) return;
    unsigned char *mask = constrained_mask(m, b);
    for (size_t v = 0; extra && v < m->n_nodes; ++v)
        mask[v] = extra[v];
    size_t pinned = 0;
    for (size_t v = 0; v < m->n_nodes; ++v)
        pinned += mask[v];
    printf("%s: %zu nodes, %zu boundary, %zu constrained, %zu components\n", what, m->n_nodes,
           b->n_nodes, pinned, b->n_components);
    CHECK(pinned > b->n_nodes); /* interior nodes pinned too */
    for (int i = 0; i < N_METHODS; ++i)
        check_method(m, b, mask, methods[i], what, loose);
    free(mask);
    cm_mesh_boundary_destroy(&b);
}

static cm_mesh *block_mesh(int tets, uint64_t seed)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block blk = {5, 4, 4, {0, 0, 0}, {0.2, 0.25, 0.3}, tets, 0.25};
    test_add_block(ctx, m, &blk, &seed);
    return m;
}

/* Two components (a hex block, a tet block beside it), a constrained node of no cell (the
 * last but one) and a free node of no cell (the last); returns the former's index */
static cm_mesh *two_components(int64_t *loose, unsigned char **mask)
{
    cm_mesh *m = block_mesh(0, 5);
    uint64_t seed = 6;
    test_block blk = {4, 4, 3, {1.5, 0, 0}, {0.25, 0.25, 0.3}, 1, 0.25};
    test_add_block(ctx, m, &blk, &seed);
    size_t n = m->n_nodes;
    cm_mesh_resize_nodes(ctx, m, n + 2, 0);
    const double p[6] = {0.5, 2, 0.5, 0.6, 2.1, 0.4};
    memcpy(m->xyz + 3 * n, p, sizeof p);
    cm_mesh_boundary *b = NULL;
    cm_mesh_boundary_create(ctx, m, &b);
    *mask = constrained_mask(m, b);
    (*mask)[n] = 1;
    (*mask)[n + 1] = 0;
    cm_mesh_boundary_destroy(&b);
    *loose = (int64_t)n;
    return m;
}

/* The hex block with every hex written as a polyhedron. */
static cm_mesh *polyhedron_mesh(void)
{
    cm_mesh *h = block_mesh(0, 9), *m = test_hexes_as_polyhedra(ctx, h);
    cm_mesh_destroy(&h);
    return m;
}

static void test_meshes(const char *work)
{
    for (int tets = 0; tets < 2; ++tets) {
        cm_mesh *m = block_mesh(tets, 42 + (uint64_t)tets);
        check_mesh(m, tets ? "tet" : "hex", -1, NULL);
        cm_mesh_destroy(&m);
    }
    int64_t loose = -1;
    unsigned char *mask = NULL;
    cm_mesh *two = two_components(&loose, &mask);
    check_mesh(two, "two-comp", loose, mask);
    free(mask);
    cm_mesh_destroy(&two);
    cm_mesh *p = polyhedron_mesh();
    check_mesh(p, "polyhedra", -1, NULL);
    cm_mesh_destroy(&p);

    cm_mesh *bore = NULL;
    cm_status s = cm_hexmesh_bore(ctx, 24, 4, 6, 1.05, &bore);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    if (s >= 0) check_mesh(bore, "bore-hex", -1, NULL);
    cm_mesh_destroy(&bore);

    char path[1024];
    snprintf(path, sizeof path, "%s/staten/mixed.msh", work);
    cm_mesh *mixed = NULL;
    s = cm_mesh_read(ctx, path, &mixed);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (s != CM_OK) return;
    size_t count[CM_CELL_TYPE_COUNT] = {0};
    for (size_t c = 0; c < mixed->n_cells; ++c)
        ++count[mixed->type[c]];
    CHECK(count[CM_CELL_TET4] > 0 && count[CM_CELL_HEX8] > 0 && count[CM_CELL_WEDGE6] > 0 &&
          count[CM_CELL_PYR5] > 0);
    check_mesh(mixed, "mixed", -1, NULL);
    cm_mesh_destroy(&mixed);
}

/* NULL arguments and overlapping v and out are CM_ERR_ARGUMENT, naming the function */
static void test_errors(void)
{
    cm_mesh *m = block_mesh(1, 3);
    cm_mesh_boundary *b = NULL;
    cm_mesh_boundary_create(ctx, m, &b);
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = CM_WARP_FEMWARP;
    cm_warp *w = NULL;
    CHECK(cm_warp_create(ctx, m, b, NULL, &opt, &w) == CM_OK);
    size_t n3 = 3 * m->n_nodes;
    double *v = calloc(2 * n3, sizeof *v), *out = calloc(n3, sizeof *out);
    CHECK(cm_warp_apply_transpose(ctx, NULL, v, out) == CM_ERR_ARGUMENT);
    CHECK(strstr(cm_context_message(ctx), "cm_warp_apply_transpose") != NULL);
    CHECK(cm_warp_apply_transpose(ctx, w, NULL, out) == CM_ERR_ARGUMENT);
    CHECK(cm_warp_apply_transpose(ctx, w, v, NULL) == CM_ERR_ARGUMENT);
    CHECK(cm_warp_apply_transpose(ctx, w, v, v + 3) == CM_ERR_ARGUMENT);
    CHECK(strstr(cm_context_message(ctx), "overlap") != NULL);
    CHECK(cm_warp_apply_transpose(ctx, w, v + n3 - 1, v) == CM_ERR_ARGUMENT);
    CHECK(cm_warp_apply_transpose(ctx, w, v + n3, v) == CM_OK); /* adjacent, not overlapping */
    CHECK(cm_warp_apply_transpose(ctx, w, v, out) == CM_OK);
    free(v), free(out);
    cm_warp_destroy(&w);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&m);
}

int main(int argc, char **argv)
{
    cm_context_create(&ctx);
    test_errors();
    test_meshes(argc > 2 ? argv[2] : ".");
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
