/* Tests of the gmsh .msh reader and writer on files gmsh itself wrote (tests/data/msh, see
 * generate.py there): the four encodings of one mesh agree, higher-order nodes land where
 * VTK's node order says, write -> read is bit-exact in every variant, broken files fail
 * with file and line/byte. Also dumps what it read for test_msh_crosscheck.py (meshio, gmsh). */
#include "cadmorph/mesh.h"
#include "test_files.h"
#include "test_util.h"

#include <dirent.h>
#include <stdlib.h>
#include <string.h>

static const char *data_dir, *work_dir;

static void join(char *out, size_t n, const char *dir, const char *name)
{
    snprintf(out, n, "%s/%s", dir, name);
}

static cm_mesh *read_fixture(cm_context *ctx, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/msh/%s", data_dir, name);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    CHECK_MSG(s == CM_OK && m, "%s: %s", path, cm_context_message(ctx));
    return s == CM_OK ? m : NULL;
}

static int64_t ntag(const cm_mesh *m, size_t i) { return m->node_tag ? m->node_tag[i] : (int64_t)i + 1; }
static int64_t ctag(const cm_mesh *m, size_t c) { return m->cell_tag ? m->cell_tag[c] : (int64_t)c + 1; }

/* Bit-exact comparison; returns 1 when equal (and says what differs otherwise). */
static int same_mesh_tol(const cm_mesh *a, const cm_mesh *b, int entities, int fields, double tol,
                         const char *what)
{
#define DIFF(cond, ...)                                                                            \
    do {                                                                                           \
        if (cond) {                                                                                \
            fprintf(stderr, "%s: ", what);                                                         \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            return 0;                                                                              \
        }                                                                                          \
    } while (0)
    DIFF(a->n_nodes != b->n_nodes, "nodes %zu vs %zu", a->n_nodes, b->n_nodes);
    if (tol == 0) DIFF(memcmp(a->xyz, b->xyz, 3 * a->n_nodes * sizeof(double)) != 0, "coordinates differ");
    for (size_t i = 0; i < 3 * a->n_nodes; ++i)
        DIFF(fabs(a->xyz[i] - b->xyz[i]) > tol * (1 + fabs(a->xyz[i])), "coordinate %zu: %.17g vs %.17g", i,
             a->xyz[i], b->xyz[i]);
    for (size_t i = 0; i < a->n_nodes; ++i) DIFF(ntag(a, i) != ntag(b, i), "node %zu tag", i);
    DIFF(a->n_cells != b->n_cells, "cells %zu vs %zu", a->n_cells, b->n_cells);
    for (size_t c = 0; c < a->n_cells; ++c) {
        DIFF(a->type[c] != b->type[c] || a->offset[c + 1] != b->offset[c + 1], "cell %zu type/size", c);
        DIFF(a->physical[c] != b->physical[c], "cell %zu physical %d vs %d", c, a->physical[c], b->physical[c]);
        DIFF(a->entity[c] != b->entity[c], "cell %zu entity %d vs %d", c, a->entity[c], b->entity[c]);
        DIFF(ctag(a, c) != ctag(b, c), "cell %zu tag", c);
    }
    DIFF(memcmp(a->conn, b->conn, (size_t)a->offset[a->n_cells] * sizeof(int64_t)) != 0, "connectivity differs");
    DIFF(a->n_groups != b->n_groups, "groups %zu vs %zu", a->n_groups, b->n_groups);
    for (size_t i = 0; i < a->n_groups; ++i)
        DIFF(a->groups[i].dim != b->groups[i].dim || a->groups[i].tag != b->groups[i].tag ||
                 strcmp(a->groups[i].name, b->groups[i].name),
             "group %zu", i);
    if (entities) {
        DIFF(a->n_entities != b->n_entities, "entities %zu vs %zu", a->n_entities, b->n_entities);
        for (size_t i = 0; i < a->n_entities; ++i) {
            const cm_mesh_entity *x = &a->entities[i], *y = &b->entities[i];
            DIFF(x->dim != y->dim || x->tag != y->tag || memcmp(x->bbox, y->bbox, sizeof x->bbox) ||
                     x->n_physical != y->n_physical || x->n_bounding != y->n_bounding,
                 "entity %zu (%d,%d)", i, x->dim, x->tag);
            for (int k = 0; k < x->n_physical; ++k) DIFF(x->physical[k] != y->physical[k], "entity %zu physical", i);
            for (int k = 0; k < x->n_bounding; ++k) DIFF(x->bounding[k] != y->bounding[k], "entity %zu bounding", i);
        }
    }
    if (fields) {
        DIFF(a->n_fields != b->n_fields, "fields %zu vs %zu", a->n_fields, b->n_fields);
        for (size_t i = 0; i < a->n_fields; ++i) {
            const cm_field *x = &a->fields[i];
            const cm_field *y = cm_mesh_find_field(b, x->name, x->location);
            DIFF(!y || y->components != x->components, "field %s", x->name);
            size_t n = (x->location == CM_FIELD_NODE ? a->n_nodes : a->n_cells) * (size_t)x->components;
            DIFF(memcmp(x->data, y->data, n * sizeof(double)) != 0, "field %s values", x->name);
        }
    }
    return 1;
#undef DIFF
}

static int same_mesh(const cm_mesh *a, const cm_mesh *b, int entities, int fields, const char *what)
{
    return same_mesh_tol(a, b, entities, fields, 0, what);
}

/* ---- the four encodings of box_hole ---- */

static void test_variants(cm_context *ctx)
{
    const char *names[4] = {"box_hole_22.msh", "box_hole_22b.msh", "box_hole_41.msh", "box_hole_41b.msh"};
    cm_mesh *m[4];
    for (int i = 0; i < 4; ++i) m[i] = read_fixture(ctx, names[i]);
    if (!m[0] || !m[1] || !m[2] || !m[3]) goto done;
    /* gmsh prints 16 significant digits in ASCII: binary and ASCII agree to rounding */
    CHECK(same_mesh_tol(m[0], m[1], 0, 0, 1e-15, "22 vs 22b"));
    CHECK(same_mesh(m[0], m[2], 0, 0, "22 vs 41"));
    CHECK(same_mesh(m[1], m[3], 0, 0, "22b vs 41b"));
    CHECK(same_mesh_tol(m[2], m[3], 1, 0, 1e-15, "41 vs 41b"));
    const cm_mesh *a = m[3];
    CHECK(a->n_nodes > 100 && cm_mesh_count_dim(a, 3) > 300 && cm_mesh_count_dim(a, 2) > 50);
    CHECK(a->n_groups == 3);
    int solid = 0;
    for (size_t i = 0; i < a->n_groups; ++i)
        if (!strcmp(a->groups[i].name, "solid")) solid = a->groups[i].dim == 3 && a->groups[i].tag == 10;
    CHECK(solid);
    /* every tet is in "solid" (10); hole triangles (20) lie on the r = 0.25 cylinder about
     * (1, 0.5); "left" triangles (21) on x = 0 */
    size_t bad = 0, hole = 0, left = 0;
    for (size_t c = 0; c < a->n_cells; ++c) {
        int t = a->type[c];
        if (t == CM_CELL_TET4 && a->physical[c] != 10) ++bad;
        if (t != CM_CELL_TRI3) continue;
        for (int64_t k = a->offset[c]; k < a->offset[c + 1]; ++k) {
            const double *p = a->xyz + 3 * a->conn[k];
            if (a->physical[c] == 20) bad += fabs(hypot(p[0] - 1, p[1] - 0.5) - 0.25) > 1e-9;
            if (a->physical[c] == 21) bad += fabs(p[0]) > 1e-12;
        }
        hole += a->physical[c] == 20;
        left += a->physical[c] == 21;
    }
    CHECK_MSG(bad == 0 && hole > 10 && left > 4, "bad %zu hole %zu left %zu", bad, hole, left);
    /* $Entities: the volume carries physical 10 and the box's bounding box */
    int vol = 0;
    for (size_t i = 0; i < a->n_entities; ++i) {
        const cm_mesh_entity *e = &a->entities[i];
        if (e->dim != 3) continue;
        vol = e->n_physical == 1 && e->physical[0] == 10 && e->n_bounding >= 6 &&
              fabs(e->bbox[0]) < 1e-6 && fabs(e->bbox[3] - 2) < 1e-6 && fabs(e->bbox[5] - 1) < 1e-6;
    }
    CHECK(vol);
done:
    for (int i = 0; i < 4; ++i) cm_mesh_destroy(&m[i]);
}

/* ---- higher-order node positions in VTK order ---- */

/* VTK's node order: node k (>= corners) is the centroid of these corners (-1 ends a list). */
typedef struct ho_rule {
    cm_cell_type type;
    int first;      /* first higher-order node */
    int set[20][9]; /* corner lists */
} ho_rule;

static const ho_rule rules[] = {
    {CM_CELL_LINE3, 2, {{0, 1, -1}}},
    {CM_CELL_TRI6, 3, {{0, 1, -1}, {1, 2, -1}, {2, 0, -1}}},
    {CM_CELL_QUAD8, 4, {{0, 1, -1}, {1, 2, -1}, {2, 3, -1}, {3, 0, -1}}},
    {CM_CELL_QUAD9, 4, {{0, 1, -1}, {1, 2, -1}, {2, 3, -1}, {3, 0, -1}, {0, 1, 2, 3, -1}}},
    {CM_CELL_TET10, 4, {{0, 1, -1}, {1, 2, -1}, {2, 0, -1}, {0, 3, -1}, {1, 3, -1}, {2, 3, -1}}},
    {CM_CELL_HEX20, 8, {{0, 1, -1}, {1, 2, -1}, {2, 3, -1}, {3, 0, -1}, {4, 5, -1}, {5, 6, -1}, {6, 7, -1},
                        {7, 4, -1}, {0, 4, -1}, {1, 5, -1}, {2, 6, -1}, {3, 7, -1}}},
    {CM_CELL_HEX27, 8, {{0, 1, -1}, {1, 2, -1}, {2, 3, -1}, {3, 0, -1}, {4, 5, -1}, {5, 6, -1}, {6, 7, -1},
                        {7, 4, -1}, {0, 4, -1}, {1, 5, -1}, {2, 6, -1}, {3, 7, -1}, {0, 4, 7, 3, -1},
                        {1, 2, 6, 5, -1}, {0, 1, 5, 4, -1}, {3, 2, 6, 7, -1}, {0, 1, 2, 3, -1},
                        {4, 5, 6, 7, -1}, {0, 1, 2, 3, 4, 5, 6, 7, -1}}},
    {CM_CELL_WEDGE15, 6, {{0, 1, -1}, {1, 2, -1}, {2, 0, -1}, {3, 4, -1}, {4, 5, -1}, {5, 3, -1},
                          {0, 3, -1}, {1, 4, -1}, {2, 5, -1}}},
    {CM_CELL_WEDGE18, 6, {{0, 1, -1}, {1, 2, -1}, {2, 0, -1}, {3, 4, -1}, {4, 5, -1}, {5, 3, -1},
                          {0, 3, -1}, {1, 4, -1}, {2, 5, -1}, {0, 1, 4, 3, -1}, {1, 2, 5, 4, -1},
                          {2, 0, 3, 5, -1}}},
    {CM_CELL_PYR13, 5, {{0, 1, -1}, {1, 2, -1}, {2, 3, -1}, {3, 0, -1}, {0, 4, -1}, {1, 4, -1}, {2, 4, -1},
                        {3, 4, -1}}},
    {CM_CELL_PYR14, 5, {{0, 1, -1}, {1, 2, -1}, {2, 3, -1}, {3, 0, -1}, {0, 4, -1}, {1, 4, -1}, {2, 4, -1},
                        {3, 4, -1}, {0, 1, 2, 3, -1}}},
};

/* For every cell of the listed types: higher-order nodes at the centroids VTK's order names
 * (the fixtures are straight-sided). Returns a bit mask of the types seen. */
static unsigned check_high_order(const cm_mesh *m, const char *what)
{
    unsigned seen = 0;
    size_t bad = 0;
    for (size_t c = 0; c < m->n_cells; ++c) {
        const ho_rule *r = NULL;
        for (size_t i = 0; i < sizeof rules / sizeof rules[0]; ++i)
            if (rules[i].type == m->type[c]) r = &rules[i];
        if (!r) continue;
        seen |= 1u << m->type[c];
        const int64_t *v = m->conn + m->offset[c];
        int n = (int)(m->offset[c + 1] - m->offset[c]);
        double h = 0; /* cell size for the tolerance */
        for (int k = 0; k < 3; ++k) h = fmax(h, fabs(m->xyz[3 * v[1] + k] - m->xyz[3 * v[0] + k]));
        for (int k = r->first; k < n; ++k) {
            const int *s = r->set[k - r->first];
            double mid[3] = {0, 0, 0};
            int cnt = 0;
            for (; cnt < 9 && s[cnt] >= 0; ++cnt)
                for (int j = 0; j < 3; ++j) mid[j] += m->xyz[3 * v[s[cnt]] + j];
            double d = 0;
            for (int j = 0; j < 3; ++j) d = fmax(d, fabs(mid[j] / cnt - m->xyz[3 * v[k] + j]));
            if (d > 1e-9 * (1 + h)) {
                if (bad++ < 5)
                    fprintf(stderr, "%s: cell %zu (%s) node %d is %g off the centroid of its corners\n",
                            what, c, cm_cell_type_info((cm_cell_type)m->type[c])->name, k, d);
            }
        }
    }
    CHECK_MSG(bad == 0, "%s: %zu misplaced higher-order nodes", what, bad);
    return seen;
}

static void test_high_order(cm_context *ctx)
{
    cm_mesh *a = read_fixture(ctx, "hybrid_o2_41.msh");
    cm_mesh *b = read_fixture(ctx, "hybrid_o2i_22b.msh");
    if (a) {
        unsigned seen = check_high_order(a, "hybrid_o2_41");
        unsigned want = 1u << CM_CELL_TET10 | 1u << CM_CELL_HEX27 | 1u << CM_CELL_WEDGE18 |
                        1u << CM_CELL_PYR14 | 1u << CM_CELL_QUAD9 | 1u << CM_CELL_TRI6;
        CHECK_MSG((seen & want) == want, "types seen 0x%x", seen);
    }
    if (b) {
        unsigned seen = check_high_order(b, "hybrid_o2i_22b");
        unsigned want = 1u << CM_CELL_TET10 | 1u << CM_CELL_HEX20 | 1u << CM_CELL_WEDGE15 |
                        1u << CM_CELL_PYR13 | 1u << CM_CELL_QUAD8 | 1u << CM_CELL_TRI6;
        CHECK_MSG((seen & want) == want, "types seen 0x%x", seen);
    }
    /* the same geometry and mesh, so the same cells by linear type */
    if (a && b) {
        size_t na[CM_CELL_TYPE_COUNT] = {0}, nb[CM_CELL_TYPE_COUNT] = {0}, diff = 0;
        for (size_t c = 0; c < a->n_cells; ++c) ++na[cm_cell_type_info((cm_cell_type)a->type[c])->linear];
        for (size_t c = 0; c < b->n_cells; ++c) ++nb[cm_cell_type_info((cm_cell_type)b->type[c])->linear];
        for (int t = 0; t < CM_CELL_TYPE_COUNT; ++t) diff += na[t] != nb[t];
        CHECK_MSG(diff == 0, "cell counts by type differ between complete and incomplete order 2");
    }
    cm_mesh_destroy(&a);
    cm_mesh_destroy(&b);
}

/* ---- dumps for the meshio / gmsh cross-check ---- */

static void dump(const cm_mesh *m, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/msh_dump_%s.txt", work_dir, name);
    FILE *f = fopen(path, "w");
    CHECK_MSG(f != NULL, "cannot write %s", path);
    if (!f) return;
    fprintf(f, "nodes %zu\n", m->n_nodes);
    for (size_t i = 0; i < m->n_nodes; ++i)
        fprintf(f, "%lld %.17g %.17g %.17g\n", (long long)ntag(m, i), m->xyz[3 * i], m->xyz[3 * i + 1], m->xyz[3 * i + 2]);
    fprintf(f, "cells %zu\n", m->n_cells);
    for (size_t c = 0; c < m->n_cells; ++c) {
        fprintf(f, "%lld %s %d %d", (long long)ctag(m, c), cm_cell_type_info((cm_cell_type)m->type[c])->name,
                m->physical[c], m->entity[c]);
        for (int64_t k = m->offset[c]; k < m->offset[c + 1]; ++k) fprintf(f, " %lld", (long long)ntag(m, (size_t)m->conn[k]));
        fputc('\n', f);
    }
    fclose(f);
}

static void test_dumps(cm_context *ctx)
{
    const char *names[] = {"box_hole_22", "box_hole_22b", "box_hole_41", "box_hole_41b", "hybrid_o2_41", "hybrid_o2i_22b"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
        char file[256];
        snprintf(file, sizeof file, "%s.msh", names[i]);
        cm_mesh *m = read_fixture(ctx, file);
        if (m) dump(m, names[i]);
        cm_mesh_destroy(&m);
    }
}

/* ---- round trips ---- */

static void add_fields(cm_context *ctx, cm_mesh *m)
{
    double *sj = NULL, *d = NULL;
    CHECK(cm_mesh_add_field(ctx, m, "scaled_jacobian", CM_FIELD_CELL, 1, &sj) == CM_OK);
    CHECK(cm_mesh_add_field(ctx, m, "displacement", CM_FIELD_NODE, 3, &d) == CM_OK);
    for (size_t c = 0; sj && c < m->n_cells; ++c) sj[c] = sin((double)c) / 3.0;
    for (size_t i = 0; d && i < 3 * m->n_nodes; ++i) d[i] = 1e-3 * cos((double)i) + 1.0 / 7.0; /* i = 3 node + k */
}

static const struct {
    int version, binary;
    const char *tag;
} variants[4] = {{22, 0, "22"}, {22, 1, "22b"}, {41, 0, "41"}, {41, 1, "41b"}};

static void test_round_trip(cm_context *ctx, const char *fixture, const char *name)
{
    cm_mesh *m = read_fixture(ctx, fixture);
    if (!m) return;
    add_fields(ctx, m);
    for (int v = 0; v < 4; ++v) {
        char path[1024], what[1300];
        snprintf(path, sizeof path, "%s/msh_rt_%s_%s.msh", work_dir, name, variants[v].tag);
        snprintf(what, sizeof what, "%s -> %s", fixture, path);
        cm_mesh_write_options opt;
        cm_mesh_write_options_init(&opt);
        opt.msh_version = variants[v].version;
        opt.binary = variants[v].binary;
        cm_status s = cm_mesh_write(ctx, m, path, &opt);
        CHECK_MSG(s == CM_OK, "%s: %s", what, cm_context_message(ctx));
        cm_mesh *b = NULL;
        s = cm_mesh_read(ctx, path, &b);
        CHECK_MSG(s == CM_OK, "%s: %s", what, cm_context_message(ctx));
        if (!b) continue;
        /* entities survive 4.1 -> 4.1; a 2.2 source gets them synthesized */
        int ents = variants[v].version == 41 && m->n_entities > 0;
        CHECK_MSG(same_mesh(m, b, ents, 1, what), "%s", what);
        if (variants[v].version == 41) {
            CHECK_MSG(b->n_entities > 0, "%s: no entities", what);
            /* second generation: 4.1 with synthesized entities -> 4.1 keeps them exactly */
            char path2[1100];
            snprintf(path2, sizeof path2, "%s.2.msh", path);
            cm_mesh *c = NULL;
            s = cm_mesh_write(ctx, b, path2, &opt);
            if (s == CM_OK) s = cm_mesh_read(ctx, path2, &c);
            CHECK_MSG(s == CM_OK && c && same_mesh(b, c, 1, 1, path2), "%s: %s", path2, cm_context_message(ctx));
            cm_mesh_destroy(&c);
            remove(path2);
        }
        cm_mesh_destroy(&b);
    }
    cm_mesh_destroy(&m);
}

/* Sparse, huge and shuffled tags go through the hash map; 2.2 cannot hold tags > 2^31. */
static void test_sparse_tags(cm_context *ctx)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    if (!m) return;
    CHECK(cm_mesh_resize_nodes(ctx, m, 5, 1) == CM_OK);
    const double xyz[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
    const int64_t tags[5] = {7, 1000000007, 3, 5000000000LL, 99};
    memcpy(m->xyz, xyz, sizeof xyz);
    memcpy(m->node_tag, tags, sizeof tags);
    const int64_t t1[4] = {0, 1, 2, 3}, t2[4] = {1, 2, 3, 4};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, t1, 4, 5, 2, 42) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, t2, 4, 6, 3, 9000000000LL) == CM_OK);
    CHECK(cm_mesh_add_group(ctx, m, 3, 5, "with space") == CM_OK);
    for (int v = 0; v < 4; ++v) {
        char path[1024];
        snprintf(path, sizeof path, "%s/msh_sparse_%s.msh", work_dir, variants[v].tag);
        cm_mesh_write_options opt;
        cm_mesh_write_options_init(&opt);
        opt.msh_version = variants[v].version;
        opt.binary = variants[v].binary;
        cm_status s = cm_mesh_write(ctx, m, path, &opt);
        if (variants[v].version == 22) {
            CHECK_MSG(s == CM_ERR_UNSUPPORTED && strstr(cm_context_message(ctx), "5000000000"), "%s", cm_context_message(ctx));
            continue;
        }
        cm_mesh *b = NULL;
        if (s == CM_OK) s = cm_mesh_read(ctx, path, &b);
        CHECK_MSG(s == CM_OK && b && same_mesh(m, b, 0, 1, path), "%s: %s", path, cm_context_message(ctx));
        cm_mesh_destroy(&b);
    }
    cm_mesh_destroy(&m);
}

/* A grid of cubes split into 6 tets: blocks bigger than any write buffer. */
static void test_grid(cm_context *ctx)
{
    const int n = 16, p = n + 1;
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    if (!m) return;
    CHECK(cm_mesh_resize_nodes(ctx, m, (size_t)p * p * p, 0) == CM_OK);
    for (int i = 0; i < p * p * p; ++i) {
        m->xyz[3 * i] = (i % p) / (double)n;
        m->xyz[3 * i + 1] = (i / p % p) / (double)n;
        m->xyz[3 * i + 2] = (i / (p * p)) / (double)n;
    }
    static const int kuhn[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                int64_t c[8], o = (int64_t)(k * p + j) * p + i;
                c[0] = o, c[1] = o + 1, c[2] = o + p + 1, c[3] = o + p;
                for (int q = 0; q < 4; ++q) c[4 + q] = c[q] + (int64_t)p * p;
                for (int t = 0; t < 6; ++t) {
                    int64_t v[4] = {c[kuhn[t][0]], c[kuhn[t][1]], c[kuhn[t][2]], c[kuhn[t][3]]};
                    cm_mesh_add_cell(ctx, m, CM_CELL_TET4, v, 4, 0, 1, 0);
                }
            }
    add_fields(ctx, m);
    for (int v = 0; v < 4; ++v) {
        char path[1024];
        snprintf(path, sizeof path, "%s/msh_grid_%s.msh", work_dir, variants[v].tag);
        cm_mesh_write_options opt;
        cm_mesh_write_options_init(&opt);
        opt.msh_version = variants[v].version;
        opt.binary = variants[v].binary;
        cm_mesh *b = NULL;
        cm_status s = cm_mesh_write(ctx, m, path, &opt);
        if (s == CM_OK) s = cm_mesh_read(ctx, path, &b);
        CHECK_MSG(s == CM_OK && b && same_mesh(m, b, 0, 1, path), "%s: %s", path, cm_context_message(ctx));
        cm_mesh_destroy(&b);
        remove(path);
    }
    cm_mesh_destroy(&m);
}

static int count_prefix(const char *dir, const char *prefix)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        n += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
    if (d) closedir(d);
    return n;
}

static void test_write_errors(cm_context *ctx)
{
    cm_mesh *m = NULL;
    CHECK(cm_mesh_create(ctx, &m) == CM_OK);
    if (!m) return;
    CHECK(cm_mesh_resize_nodes(ctx, m, 4, 0) == CM_OK);
    const double xyz[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(m->xyz, xyz, sizeof xyz);
    const int64_t tet[4] = {0, 1, 2, 3};
    const int64_t poly[17] = {4, 3, 0, 2, 1, 3, 0, 1, 3, 3, 1, 2, 3, 3, 2, 0, 3};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_TET4, tet, 4, 0, 0, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_POLYHEDRON, poly, 17, 0, 0, 0) == CM_OK);
    char path[1024];
    join(path, sizeof path, work_dir, "msh_poly_out.msh");
    remove(path);
    cm_status s = cm_mesh_write(ctx, m, path, NULL);
    CHECK_MSG(s == CM_ERR_UNSUPPORTED && strstr(cm_context_message(ctx), "cell 1") &&
                  strstr(cm_context_message(ctx), "polyhedron"),
              "%d %s", (int)s, cm_context_message(ctx));
    CHECK(count_prefix(work_dir, "msh_poly_out.msh") == 0);
    /* unwritable target: an error and no temporary left behind */
    join(path, sizeof path, work_dir, "no_such_dir/out.msh");
    m->n_cells = 1;
    s = cm_mesh_write(ctx, m, path, NULL);
    CHECK_MSG(s == CM_ERR_IO, "%d %s", (int)s, cm_context_message(ctx));
    m->n_cells = 2;
    cm_mesh_destroy(&m);
}

/* ---- broken input ---- */

static cm_status read_text(cm_context *ctx, const char *name, const char *text, size_t len, char *path, size_t n)
{
    join(path, n, work_dir, name);
    if (test_write_file(path, text, len) != 0) return CM_ERR_IO;
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    cm_mesh_destroy(&m);
    return s;
}

#define HDR41 "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
#define NODES41 "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"

static const struct {
    const char *name, *text, *want; /* want: substring of the message after the path */
    cm_status status;
} bad_cases[] = {
    {"ok", HDR41 NODES41 "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n", NULL, CM_OK},
    {"empty", "", ":1: expected $MeshFormat", CM_ERR_FORMAT},
    {"v30", "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", ":2: msh version 3.0 is not supported", CM_ERR_UNSUPPORTED},
    {"v40", "$MeshFormat\n4 0 8\n$EndMeshFormat\n", ":2: msh version 4 is not supported", CM_ERR_UNSUPPORTED},
    {"truncated", HDR41 "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0", ":5: expected number of nodes that fits the 30 bytes left, got 4", CM_ERR_FORMAT},
    {"count", HDR41 "$Nodes\n1 5 1 5\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n", ":14: expected 5 nodes (numNodes), got 4", CM_ERR_FORMAT},
    {"count2", HDR41 "$Nodes\n1 3 1 3\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n", ":6: expected at most 3 nodes", CM_ERR_FORMAT},
    {"undefined", HDR41 NODES41 "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 99\n$EndElements\n", ":19: expected a node tag defined in $Nodes, got 99", CM_ERR_FORMAT},
    {"nan", HDR41 "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 nan 0\n0 1 0\n0 0 1\n$EndNodes\n", ":12: expected a finite node coordinate", CM_ERR_FORMAT},
    {"type", HDR41 NODES41 "$Elements\n1 1 1 1\n3 1 999 1\n1 1 2 3 4\n$EndElements\n", ":18: expected a gmsh element type number, got 999", CM_ERR_FORMAT},
    {"type20", HDR41 NODES41 "$Elements\n1 1 1 1\n3 1 29 1\n1 1 2 3 4\n$EndElements\n", ":18: gmsh element type 29 is not supported", CM_ERR_UNSUPPORTED},
    {"dup", HDR41 "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n2\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n", "got tag 2 twice", CM_ERR_FORMAT},
    {"huge", HDR41 "$Nodes\n1 999999999999999 1 4\n", ":5: expected number of nodes that fits", CM_ERR_FORMAT},
    {"overflow", HDR41 "$Nodes\n1 99999999999999999999 1 4\n", ":5: expected number of nodes, got '99999999999999999999'", CM_ERR_FORMAT},
    {"partitioned", HDR41 "$PartitionedEntities\n0\n$EndPartitionedEntities\n", ":4: partitioned meshes", CM_ERR_UNSUPPORTED},
    {"unclosed", HDR41 "$Periodic\n0\n", ":4: expected $EndPeriodic to close $Periodic", CM_ERR_FORMAT},
    {"noelements", HDR41 NODES41, "expected an $Elements section", CM_ERR_FORMAT},
    {"skip", HDR41 "$Comments\nanything $Nodes\n$EndComments\n" NODES41 "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n$NodeData\n1\n\"d\"\n1\n0.0\n3\n0\n1\n1\n4 2.5\n$EndNodeData\n", NULL, CM_OK},
    {"data", HDR41 NODES41 "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n$NodeData\n1\n\"d\"\n1\n0.0\n3\n0\n1\n1\n5 2.5\n$EndNodeData\n", ":30: expected a node tag in $NodeData, got 5", CM_ERR_FORMAT},
    {"22count", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n2\n1 4 2 0 1 1 2 3 4\n$EndElements\n", ":14: expected element tag, got '$EndElements'", CM_ERR_FORMAT},
};

static void test_bad_input(cm_context *ctx)
{
    /* the intact twin of the binary CLI cases (tests/data/msh/bad) reads, so they fail for
     * the reason they were broken for */
    cm_mesh *ok = read_fixture(ctx, "bad/ok_binary.msh");
    CHECK(ok && ok->n_nodes == 4 && ok->n_cells == 1 && ok->type[0] == CM_CELL_TET4);
    cm_mesh_destroy(&ok);
    for (size_t i = 0; i < sizeof bad_cases / sizeof bad_cases[0]; ++i) {
        char path[1024], name[128];
        snprintf(name, sizeof name, "msh_bad_%s.msh", bad_cases[i].name);
        cm_status s = read_text(ctx, name, bad_cases[i].text, strlen(bad_cases[i].text), path, sizeof path);
        const char *msg = cm_context_message(ctx);
        int ok = s == bad_cases[i].status;
        if (bad_cases[i].want) ok = ok && strncmp(msg, path, strlen(path)) == 0 && strstr(msg, bad_cases[i].want);
        CHECK_MSG(ok, "%s: status %d, message '%s'", bad_cases[i].name, (int)s, s ? msg : "");
    }
}

/* Every cut of a file before its $EndElements fails with the file's name (never crashes);
 * random byte changes never crash and never give an invalid mesh. */
static void test_truncate_and_fuzz(cm_context *ctx, const char *fixture)
{
    char src[1024], path[1024];
    snprintf(src, sizeof src, "%s/msh/%s", data_dir, fixture);
    size_t len = 0;
    char *d = test_read_file(src, &len);
    CHECK_MSG(d != NULL, "cannot read %s", src);
    if (!d) return;
    size_t end = 0;
    for (size_t i = 0; i + 12 <= len; ++i)
        if (memcmp(d + i, "$EndElements", 12) == 0) end = i + 12;
    size_t failed_ok = 0, bad_msg = 0;
    for (size_t cut = 0; cut < end; cut += 1 + cut / 40) {
        cm_status s = read_text(ctx, "msh_cut.msh", d, cut, path, sizeof path);
        if (s == CM_OK) ++failed_ok;
        else if (!strstr(cm_context_message(ctx), path) ||
                 !(strstr(cm_context_message(ctx), ": byte ") || strstr(cm_context_message(ctx), ".msh:")))
            if (bad_msg++ < 3) fprintf(stderr, "cut %zu: %s\n", cut, cm_context_message(ctx));
    }
    CHECK_MSG(failed_ok == 0 && bad_msg == 0, "%s: %zu cuts read fine, %zu messages without place", fixture,
              failed_ok, bad_msg);
    srand(12345);
    size_t ok = 0;
    for (int trial = 0; trial < 300; ++trial) {
        char *e = malloc(len);
        memcpy(e, d, len);
        for (int k = 0; k < 1 + trial % 4; ++k) e[(size_t)rand() % len] = (char)(rand() & 0xff);
        cm_status s = read_text(ctx, "msh_fuzz.msh", e, len, path, sizeof path);
        ok += s == CM_OK;
        free(e);
    }
    printf("%s: %zu of 300 randomly changed copies still read (and validated)\n", fixture, ok);
    free(d);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_msh <tests/data> <work dir>\n");
        return 2;
    }
    data_dir = argv[1];
    work_dir = argv[2];
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    test_variants(ctx);
    test_high_order(ctx);
    test_dumps(ctx);
    test_round_trip(ctx, "box_hole_41b.msh", "box_hole");
    test_round_trip(ctx, "box_hole_22.msh", "box_hole_from22");
    test_round_trip(ctx, "hybrid_o2_41.msh", "hybrid_o2");
    test_round_trip(ctx, "hybrid_o2i_22b.msh", "hybrid_o2i");
    test_sparse_tags(ctx);
    test_grid(ctx);
    test_write_errors(ctx);
    test_bad_input(ctx);
    test_truncate_and_fuzz(ctx, "box_hole_41.msh");
    test_truncate_and_fuzz(ctx, "box_hole_41b.msh");
    test_truncate_and_fuzz(ctx, "box_hole_22b.msh");
    test_truncate_and_fuzz(ctx, "hybrid_o2_41.msh");
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
