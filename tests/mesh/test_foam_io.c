/* OpenFOAM polyMesh I/O without OpenFOAM: meshes built in code are written as polyMesh
 * (converted), read back (same points, each cell recognised as the same tet/hex/wedge/pyramid
 * with the same scaled Jacobian, checkMesh metrics equal on both addressings), morphed and
 * written again (points only; the other files byte for byte), read from .gz and from binary
 * files with 64-bit labels; broken polyMeshes fail with the file and the place.
 * (The cross-check against the real OpenFOAM is test_foam_crosscheck.py.) */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/mesh.h"
#include "foam_internal.h"
#include "origin.h"
#include "test_files.h"
#include "test_mesh.h"
#include "test_util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

static cm_context *ctx;
static char work[2048];

static int same_file(const char *a, const char *b)
{
    size_t na, nb;
    char *x = test_read_file(a, &na), *y = test_read_file(b, &nb);
    int same = x && y && na == nb && !memcmp(x, y, na);
    free(x);
    free(y);
    return same;
}

static void path(char *out, size_t cap, const char *dir, const char *name)
{
    snprintf(out, cap, "%s/%s", dir, name);
}

static cm_mesh *hex_mesh(int tets, double jitter)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    test_block b = {3, 2, 2, {0, 0, 0}, {0.5, 0.7, 0.4}, tets, jitter};
    uint64_t seed = 7;
    test_add_block(ctx, m, &b, &seed);
    return m;
}

/* A unit cube as 2 wedges (tets == 0) or 6 pyramids about its centre (tets == 1). */
static cm_mesh *wedge_pyramid_mesh(int pyramids)
{
    cm_mesh *m = NULL;
    cm_mesh_create(ctx, &m);
    /* the apex only with the pyramids: checkMesh fails a mesh with an unused point */
    cm_mesh_resize_nodes(ctx, m, pyramids ? 9 : 8, 0);
    static const double c[9][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1},
                                   {1, 0, 1}, {1, 1, 1}, {0, 1, 1}, {0.5, 0.45, 0.55}};
    memcpy(m->xyz, c, (pyramids ? 9 : 8) * sizeof c[0]);
    if (!pyramids) {
        int64_t w1[6] = {0, 1, 2, 4, 5, 6}, w2[6] = {0, 2, 3, 4, 6, 7};
        /* VTK wedges: (0,1,2) and (3,4,5) with the triangle's normal away from the top */
        int64_t a[6] = {w1[0], w1[2], w1[1], w1[3], w1[5], w1[4]};
        int64_t b[6] = {w2[0], w2[2], w2[1], w2[3], w2[5], w2[4]};
        cm_mesh_add_cell(ctx, m, CM_CELL_WEDGE6, a, 6, 0, 0, 0);
        cm_mesh_add_cell(ctx, m, CM_CELL_WEDGE6, b, 6, 0, 0, 0);
    } else {
        /* the six faces of the cube, each a base seen from the centre */
        static const int64_t q[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1},
                                        {3, 2, 6, 7}, {0, 3, 7, 4}, {1, 5, 6, 2}};
        for (int f = 0; f < 6; ++f) {
            int64_t p[5] = {q[f][0], q[f][1], q[f][2], q[f][3], 8};
            cm_mesh_add_cell(ctx, m, CM_CELL_PYR5, p, 5, 0, 0, 0);
        }
    }
    return m;
}

static double *sj_of(const cm_mesh *m)
{
    double *sj = malloc(m->n_cells * sizeof *sj);
    cm_mesh_quality(ctx, m, sj);
    return sj;
}

/* written as polyMesh and read back: points, shapes and scaled Jacobians survive */
static void round_trip(const char *name, cm_mesh *m, cm_cell_type want)
{
    char dir[2300];
    path(dir, sizeof dir, work, name);
    cm_status s = cm_mesh_write(ctx, m, dir, NULL);
    CHECK_MSG(s == CM_OK, "%s: write: %s", name, cm_context_message(ctx));
    cm_mesh *r = NULL;
    s = cm_mesh_read(ctx, dir, &r);
    CHECK_MSG(s == CM_OK, "%s: read: %s", name, cm_context_message(ctx));
    if (!r) return;
    CHECK(r->n_nodes == m->n_nodes);
    int exact = 1;
    for (size_t i = 0; i < 3 * m->n_nodes && i < 3 * r->n_nodes; ++i) exact &= r->xyz[i] == m->xyz[i];
    CHECK_MSG(exact, "%s: ASCII points do not round-trip exactly", name);
    CHECK(cm_mesh_count_dim(r, 3) == cm_mesh_count_dim(m, 3));
    size_t typed = 0;
    for (size_t c = 0; c < r->n_cells; ++c) typed += r->type[c] == want;
    CHECK_MSG(typed == cm_mesh_count_dim(m, 3), "%s: %zu of %zu cells recognised as %s", name, typed,
              cm_mesh_count_dim(m, 3), cm_cell_type_info(want)->name);
    /* the polyMesh keeps cell order: cell c is cell c */
    double *a = sj_of(m), *b = sj_of(r);
    double worst = 0;
    for (size_t c = 0; c < m->n_cells; ++c)
        if (cm_cell_type_info((cm_cell_type)m->type[c])->dim == 3) worst = fmax(worst, fabs(a[c] - b[c]));
    CHECK_MSG(worst < 1e-12, "%s: scaled Jacobian differs by %g after the round trip", name, worst);
    free(a);
    free(b);
    /* checkMesh's metrics: the same on the cells' faces and on the polyMesh's faces */
    cm_foam_quality qa, qb;
    CHECK(cm_mesh_quality_foam(ctx, m, &qa) == CM_OK);
    CHECK(cm_mesh_quality_foam(ctx, r, &qb) == CM_OK);
    CHECK_NEAR(qa.total_volume, qb.total_volume, 1e-12);
    CHECK_NEAR(qa.max_non_orthogonality, qb.max_non_orthogonality, 1e-9);
    CHECK_NEAR(qa.max_skewness, qb.max_skewness, 1e-9);
    CHECK_NEAR(qa.max_aspect_ratio, qb.max_aspect_ratio, 1e-9);
    CHECK(qb.wrong_pyramids == 0 && qb.negative_volume_cells == 0 && qb.failed_checks == 0);
    cm_mesh_destroy(&r);
}

/* sum of the cells' volumes from their tets = checkMesh's total volume */
static void volume_check(void)
{
    cm_mesh *m = hex_mesh(1, 0.3);
    double v = 0;
    for (size_t c = 0; c < m->n_cells; ++c) v += test_tet_volume_at(m->xyz, m->conn + m->offset[c]);
    cm_foam_quality q;
    CHECK(cm_mesh_quality_foam(ctx, m, &q) == CM_OK);
    CHECK_NEAR(q.total_volume, v, 1e-12);
    CHECK_NEAR(q.total_volume, 1.5 * 1.4 * 0.8, 1e-12);
    CHECK(q.cells == m->n_cells && q.tetrahedra == m->n_cells);
    cm_mesh_destroy(&m);
}

/* patch names from hostile group names: one OpenFOAM word each, distinct */
static void hostile_patch_names(void)
{
    cm_mesh *m = hex_mesh(0, 0.0);
    /* two boundary quads of the block (z = 0 face) in groups with names no word holds */
    const int64_t q1[4] = {0, 4, 5, 1}, q2[4] = {1, 5, 6, 2};
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, q1, 4, 7, 7, 0) == CM_OK);
    CHECK(cm_mesh_add_cell(ctx, m, CM_CELL_QUAD4, q2, 4, 8, 8, 0) == CM_OK);
    CHECK(cm_mesh_add_group(ctx, m, 2, 7, "in let;{\"x\"}") == CM_OK);
    CHECK(cm_mesh_add_group(ctx, m, 2, 8, "in let;{'x'}") == CM_OK);
    char dir[2300];
    path(dir, sizeof dir, work, "foam_hostile_names");
    CHECK_MSG(cm_mesh_write(ctx, m, dir, NULL) == CM_OK, "%s", cm_context_message(ctx));
    cm_mesh *r = NULL;
    CHECK_MSG(cm_mesh_read(ctx, dir, &r) == CM_OK, "%s", cm_context_message(ctx));
    if (r) {
        CHECK(r->n_groups == 3);
        for (size_t g = 0; g < r->n_groups; ++g) CHECK(strpbrk(r->groups[g].name, " ;{}\"'") == NULL);
        CHECK(r->n_groups == 3 && strcmp(r->groups[0].name, r->groups[1].name) != 0);
        size_t in_first = 0;
        for (size_t c = 0; c < r->n_cells; ++c) in_first += r->physical[c] == 1;
        CHECK(in_first == 1);
    }
    cm_mesh_destroy(&r);
    cm_mesh_destroy(&m);
}

/* zones: read (binary-free ASCII here), cell zones as physical groups, copied on a morph */
static void zones(void)
{
    char dir[2300], f[2500];
    path(dir, sizeof dir, work, "foam_zones");
    cm_mesh *m = hex_mesh(0, 0.1);
    CHECK(cm_mesh_write(ctx, m, dir, NULL) == CM_OK);
    snprintf(f, sizeof f, "%s/constant/polyMesh/cellZones", dir);
    const char *cz = "FoamFile\n{\n    version 2.0;\n    format ascii;\n    class regIOobject;\n    object cellZones;\n}\n"
                     "2\n(\nporous\n{\n    type cellZone;\n    cellLabels List<label> 3(0 1 2);\n}\n"
                     "rest\n{\n    type cellZone;\n    cellLabels List<label> 2{5};\n    meta { a 1; }\n}\n)\n";
    test_write_file(f, cz, strlen(cz));
    snprintf(f, sizeof f, "%s/constant/polyMesh/faceZones", dir);
    const char *fz = "FoamFile\n{\n    version 2.0;\n    format ascii;\n    class regIOobject;\n    object faceZones;\n}\n"
                     "1\n(\nbaffle\n{\n    type faceZone;\n    faceLabels List<label> 2(0 1);\n    flipMap List<bool> 2(0 1);\n}\n)\n";
    test_write_file(f, fz, strlen(fz));
    cm_mesh *r = NULL;
    cm_status s = cm_mesh_read(ctx, dir, &r);
    CHECK_MSG(s == CM_OK, "zones: %s", cm_context_message(ctx));
    if (r) {
        int tag = -1;
        for (size_t g = 0; g < r->n_groups; ++g)
            if (r->groups[g].dim == 3 && !strcmp(r->groups[g].name, "porous")) tag = r->groups[g].tag;
        CHECK(tag > 0 && r->physical[0] == tag && r->physical[2] == tag && r->physical[3] != tag);
        CHECK(r->physical[5] > 0 && r->physical[5] != tag);
        cm_mesh *w = NULL;
        cm_mesh_copy(ctx, r, &w);
        w->xyz[0] += 0.001;
        char out[2300], a[2500];
        path(out, sizeof out, work, "foam_zones_out");
        CHECK(cm_mesh_write(ctx, w, out, NULL) == CM_OK);
        snprintf(a, sizeof a, "%s/constant/polyMesh/faceZones", out);
        CHECK(same_file(a, f));
        cm_mesh_destroy(&w);
    }
    cm_mesh_destroy(&r);
    /* a zone label out of range */
    const char *czbad = "FoamFile\n{\n    version 2.0;\n    format ascii;\n    class regIOobject;\n    object cellZones;\n}\n"
                        "1\n(\nz\n{\n    type cellZone;\n    cellLabels List<label> 1(999);\n}\n)\n";
    snprintf(f, sizeof f, "%s/constant/polyMesh/cellZones", dir);
    test_write_file(f, czbad, strlen(czbad));
    s = cm_mesh_read(ctx, dir, &r);
    CHECK_MSG(s == CM_ERR_FORMAT && strstr(cm_context_message(ctx), "cellZones") &&
                  strstr(cm_context_message(ctx), "out of range"),
              "zone out of range: %s", cm_context_message(ctx));
    cm_mesh_destroy(&r);
    cm_mesh_destroy(&m);
}

static const char *const files[] = {"faces", "owner", "neighbour", "boundary"};

/* a morph of a read polyMesh: points only */
static void points_only(const char *src_name, const char *dst_name, int gz)
{
    char src[2300], dst[2300], a[2400], b[2400];
    path(src, sizeof src, work, src_name);
    path(dst, sizeof dst, work, dst_name);
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, src, &m);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (!m) return;
    if (!gz) {
        /* nothing moved: `points` too is a byte copy (numbers in the shortest exact text) */
        char same[2400], pa[2600], pb[2600];
        snprintf(same, sizeof same, "%s_same", dst);
        CHECK_MSG(cm_mesh_write(ctx, m, same, NULL) == CM_OK, "%s", cm_context_message(ctx));
        path(pa, sizeof pa, src, "constant/polyMesh/points");
        path(pb, sizeof pb, same, "constant/polyMesh/points");
        CHECK_MSG(same_file(pa, pb), "%s is not a byte copy of %s", pb, pa);
    }
    cm_mesh *w = NULL;
    cm_mesh_copy(ctx, m, &w);
    for (size_t i = 0; i < w->n_nodes; ++i) w->xyz[3 * i] += 0.01 * sin((double)i) * (1.0 / 3.0);
    s = cm_mesh_write(ctx, w, dst, NULL);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    for (int i = 0; i < 4; ++i) {
        char name[64];
        snprintf(name, sizeof name, "constant/polyMesh/%s%s", files[i], gz ? ".gz" : "");
        path(a, sizeof a, src, name);
        path(b, sizeof b, dst, name);
        CHECK_MSG(same_file(a, b), "%s is not a byte copy of %s", b, a);
    }
    char pts[64];
    snprintf(pts, sizeof pts, "constant/polyMesh/points%s", gz ? ".gz" : "");
    path(b, sizeof b, dst, pts);
    struct stat st;
    CHECK_MSG(stat(b, &st) == 0, "%s missing", b);
    cm_mesh *r = NULL;
    s = cm_mesh_read(ctx, dst, &r);
    CHECK_MSG(s == CM_OK, "%s", cm_context_message(ctx));
    if (r) {
        int exact = r->n_nodes == w->n_nodes;
        for (size_t i = 0; exact && i < 3 * w->n_nodes; ++i) exact &= r->xyz[i] == w->xyz[i];
        CHECK_MSG(exact, "%s: morphed points do not round-trip", dst_name);
    }
    /* a new case inside the source case, or holding it, is refused (the case copy would
     * copy itself) */
    char inner[2500];
    snprintf(inner, sizeof inner, "%s/inner", src);
    s = cm_mesh_write(ctx, w, inner, NULL);
    CHECK_MSG(s == CM_ERR_ARGUMENT && strstr(cm_context_message(ctx), "one inside the other"), "%s",
              cm_context_message(ctx));
    CHECK(stat(inner, &st) != 0);
    CHECK(cm_mesh_write(ctx, w, work, NULL) == CM_ERR_ARGUMENT);
    /* written onto the case it came from: points replaced in place, the rest untouched */
    s = cm_mesh_write(ctx, w, src, NULL);
    CHECK_MSG(s == CM_OK, "in place: %s", cm_context_message(ctx));
    for (int i = 0; i < 5; ++i) {
        char name[64];
        snprintf(name, sizeof name, "constant/polyMesh/%s%s", i < 4 ? files[i] : "points", gz ? ".gz" : "");
        path(a, sizeof a, src, name);
        path(b, sizeof b, dst, name);
        CHECK_MSG(same_file(a, b), "in place: %s differs from %s", a, b);
    }
    cm_mesh_destroy(&r);
    cm_mesh_destroy(&w);
    cm_mesh_destroy(&m);
}

static void gzip_copy(const char *src_name, const char *dst_name)
{
    char dir[2400];
    snprintf(dir, sizeof dir, "%s/%s/constant", work, dst_name);
    mkdir(dir, 0777);
    snprintf(dir, sizeof dir, "%s/%s", work, dst_name);
    mkdir(dir, 0777);
    snprintf(dir, sizeof dir, "%s/%s/constant", work, dst_name);
    mkdir(dir, 0777);
    snprintf(dir, sizeof dir, "%s/%s/constant/polyMesh", work, dst_name);
    mkdir(dir, 0777);
    const char *all[] = {"points", "faces", "owner", "neighbour", "boundary"};
    for (int i = 0; i < 5; ++i) {
        char a[2400], b[2500];
        snprintf(a, sizeof a, "%s/%s/constant/polyMesh/%s", work, src_name, all[i]);
        snprintf(b, sizeof b, "%s/%s.gz", dir, all[i]);
        size_t n;
        char *d = test_read_file(a, &n);
        gzFile g = gzopen(b, "wb");
        if (d && g) gzwrite(g, d, (unsigned)n);
        if (g) gzclose(g);
        free(d);
    }
}

/* ---- binary files with 64-bit labels, written here from a read ASCII polyMesh ---- */

static void bin_header(FILE *f, const char *cls, const char *obj)
{
    fprintf(f, "FoamFile\n{\n    version 2.0;\n    format binary;\n    class %s;\n"
               "    arch \"LSB;label=64;scalar=64\";\n    object %s;\n}\n\n",
            cls, obj);
}

static void bin_labels(FILE *f, const int64_t *v, int64_t n)
{
    fprintf(f, "%lld\n(", (long long)n);
    fwrite(v, 8, (size_t)n, f);
    fprintf(f, ")\n");
}

static char *binary_case(const cm_mesh *m, const char *name, int truncate)
{
    /* the addressing comes from the ASCII files: read them as lists */
    static char dir[2400];
    snprintf(dir, sizeof dir, "%s/%s", work, name);
    mkdir(dir, 0777);
    char pm[2500];
    snprintf(pm, sizeof pm, "%s/constant", dir);
    mkdir(pm, 0777);
    snprintf(pm, sizeof pm, "%s/constant/polyMesh", dir);
    mkdir(pm, 0777);
    const struct cm_foam_poly *p = cm_mesh_origin_state(m, CM_FORMAT_FOAM);
    (void)p;
    char f[2600];
    /* points */
    snprintf(f, sizeof f, "%s/points", pm);
    FILE *o = fopen(f, "wb");
    bin_header(o, "vectorField", "points");
    fprintf(o, "%zu\n(", m->n_nodes);
    fwrite(m->xyz, 8, 3 * m->n_nodes - (truncate ? 5 : 0), o);
    if (!truncate) fprintf(o, ")\n");
    fclose(o);
    return dir;
}

/* Zones in binary files as decomposePar writes them for a piece a zone does not reach: an
 * empty list is its size alone ("cellLabels 0;"); beside them "0()", "0{0}" and a non-empty
 * binary block. */
static void empty_binary_zones(const char *dir, size_t n_cells)
{
    char f[2600];
    const char *names[] = {"cellZones", "faceZones", "pointZones"};
    const char *bodies[] = {"2\n(\nnone\n{\n    type cellZone;\ncellLabels      0;\n}\nsome\n{\n    type cellZone;\n"
                            "cellLabels      2(",
                            "2\n(\nnoFaces\n{\n    type faceZone;\nfaceLabels      0;\nflipMap         0;\n}\n"
                            "uniform\n{\n    type faceZone;\nfaceLabels      0();\nflipMap         0{0};\n}\n)\n",
                            "1\n(\nnoPoints\n{\n    type pointZone;\npointLabels     0;\n}\n)\n"};
    for (int k = 0; k < 3; ++k) {
        snprintf(f, sizeof f, "%s/constant/polyMesh/%s", dir, names[k]);
        FILE *o = fopen(f, "wb");
        bin_header(o, "regIOobject", names[k]);
        fputs(bodies[k], o);
        if (k == 0) {
            int64_t two[2] = {0, (int64_t)n_cells - 1};
            fwrite(two, 8, 2, o);
            fputs(");\n}\n)\n", o);
        }
        fclose(o);
    }
    cm_mesh *z = NULL;
    cm_status s = cm_mesh_read(ctx, dir, &z);
    CHECK_MSG(s == CM_OK, "empty binary zones: %s", cm_context_message(ctx));
    const struct cm_foam_poly *p = z ? cm_mesh_origin_state(z, CM_FORMAT_FOAM) : NULL;
    CHECK(p && p->n_zones == 5);
    for (size_t i = 0; p && i < p->n_zones; ++i)
        CHECK_MSG(p->zones[i].n == (strcmp(p->zones[i].name, "some") ? 0 : 2), "zone %s: %lld labels",
                  p->zones[i].name, (long long)p->zones[i].n);
    int some = -1;
    for (size_t g = 0; z && g < z->n_groups; ++g)
        if (z->groups[g].dim == 3 && !strcmp(z->groups[g].name, "some")) some = z->groups[g].tag;
    CHECK(z && some > 0 && z->physical[0] == some && z->physical[n_cells - 1] == some && z->physical[1] != some);
    cm_mesh_destroy(&z);
    for (int k = 0; k < 3; ++k) {
        snprintf(f, sizeof f, "%s/constant/polyMesh/%s", dir, names[k]);
        remove(f);
    }
}

static void binary_read(void)
{
    /* the converted hex mesh, re-expressed in binary (faceCompactList, label=64) */
    cm_mesh *m = hex_mesh(0, 0.2);
    char src[2300];
    path(src, sizeof src, work, "foam_hex_bin_src");
    CHECK(cm_mesh_write(ctx, m, src, NULL) == CM_OK);
    cm_mesh *r = NULL;
    CHECK(cm_mesh_read(ctx, src, &r) == CM_OK);
    if (!r) {
        cm_mesh_destroy(&m);
        return;
    }
    char *dir = binary_case(r, "foam_hex_bin", 0);
    char pm[2500], f[2600];
    snprintf(pm, sizeof pm, "%s/constant/polyMesh", dir);
    /* faces, owner, neighbour from the ASCII polyMesh via our own reader's addressing: parse
     * the ASCII files again here by reading the mesh's 2D+3D structure is not possible, so
     * convert the ASCII lists with a tiny parser */
    const char *lists[] = {"owner", "neighbour"};
    for (int k = 0; k < 2; ++k) {
        char a[2400];
        snprintf(a, sizeof a, "%s/constant/polyMesh/%s", src, lists[k]);
        char *d = test_read_file(a, NULL);
        char *at = d ? strstr(d, "}") : NULL;
        long long n = at ? strtoll(strchr(at, '\n') ? strpbrk(at, "0123456789") : at, &at, 10) : 0;
        int64_t *v = malloc((size_t)(n ? n : 1) * 8);
        at = at ? strchr(at, '(') + 1 : NULL;
        for (long long i = 0; at && i < n; ++i) v[i] = strtoll(at, &at, 10);
        snprintf(f, sizeof f, "%s/%s", pm, lists[k]);
        FILE *o = fopen(f, "wb");
        bin_header(o, "labelList", lists[k]);
        bin_labels(o, v, n);
        fclose(o);
        free(v);
        free(d);
    }
    {
        char a[2400];
        snprintf(a, sizeof a, "%s/constant/polyMesh/faces", src);
        char *d = test_read_file(a, NULL);
        char *at = strpbrk(strstr(d, "}"), "0123456789");
        long long n = strtoll(at, &at, 10);
        at = strchr(at, '(') + 1;
        int64_t *off = malloc((size_t)(n + 1) * 8), *nodes = malloc((size_t)(n * 8 + 8) * 8);
        off[0] = 0;
        for (long long i = 0; i < n; ++i) {
            long long k = strtoll(at, &at, 10);
            at = strchr(at, '(') + 1;
            for (long long j = 0; j < k; ++j) nodes[off[i] + j] = strtoll(at, &at, 10);
            at = strchr(at, ')') + 1;
            off[i + 1] = off[i] + k;
        }
        snprintf(f, sizeof f, "%s/faces", pm);
        FILE *o = fopen(f, "wb");
        bin_header(o, "faceCompactList", "faces");
        bin_labels(o, off, n + 1);
        bin_labels(o, nodes, off[n]);
        fclose(o);
        free(off);
        free(nodes);
        free(d);
        char b[2700];
        snprintf(a, sizeof a, "%s/constant/polyMesh/boundary", src);
        snprintf(b, sizeof b, "%s/boundary", pm);
        d = test_read_file(a, NULL);
        test_write_file(b, d, strlen(d));
        free(d);
    }
    cm_mesh *bm = NULL;
    cm_status s = cm_mesh_read(ctx, dir, &bm);
    CHECK_MSG(s == CM_OK, "binary label=64: %s", cm_context_message(ctx));
    if (bm) {
        int exact = bm->n_nodes == r->n_nodes && bm->n_cells == r->n_cells;
        for (size_t i = 0; exact && i < 3 * r->n_nodes; ++i) exact &= bm->xyz[i] == r->xyz[i];
        for (size_t i = 0; exact && i < (size_t)r->offset[r->n_cells]; ++i) exact &= bm->conn[i] == r->conn[i];
        CHECK_MSG(exact, "binary polyMesh differs from the ASCII one");
        /* a morph of a binary polyMesh writes binary points */
        cm_mesh *w = NULL;
        cm_mesh_copy(ctx, bm, &w);
        w->xyz[0] += 1e-3 / 3.0;
        char out[2300];
        path(out, sizeof out, work, "foam_hex_bin_out/constant/polyMesh");
        CHECK_MSG(cm_mesh_write(ctx, w, out, NULL) == CM_OK, "%s", cm_context_message(ctx));
        char pts[2500];
        snprintf(pts, sizeof pts, "%s/points", out);
        size_t n;
        char *d = test_read_file(pts, &n);
        CHECK(d && strstr(d, "format binary;") && n > 3 * 8 * w->n_nodes);
        free(d);
        cm_mesh *rr = NULL;
        CHECK(cm_mesh_read(ctx, out, &rr) == CM_OK);
        CHECK(rr && rr->xyz[0] == w->xyz[0] && rr->xyz[3 * w->n_nodes - 1] == w->xyz[3 * w->n_nodes - 1]);
        cm_mesh_destroy(&rr);
        cm_mesh_destroy(&w);
    }
    cm_mesh_destroy(&bm);
    const cm_foam_poly *rp = cm_mesh_origin_state(r, CM_FORMAT_FOAM);
    if (rp) empty_binary_zones(dir, (size_t)rp->n_cells);
    /* truncated binary block */
    binary_case(r, "foam_hex_bin", 1);
    s = cm_mesh_read(ctx, dir, &bm);
    CHECK_MSG(s == CM_ERR_FORMAT && strstr(cm_context_message(ctx), "truncated") &&
                  strstr(cm_context_message(ctx), "points: byte"),
              "truncated binary: %d %s", s, cm_context_message(ctx));
    cm_mesh_destroy(&r);
    cm_mesh_destroy(&m);
}

/* ---- broken polyMeshes ---- */

typedef struct bad {
    const char *file;   /* the file to change */
    const char *from;   /* text to replace (first occurrence after the header) */
    const char *to;
    cm_status status;
    const char *words;  /* in the message */
} bad;

static void hostile(void)
{
    const bad cases[] = {
        {"owner", NULL, NULL, CM_ERR_IO, "owner: no such file"},
        {"owner", NULL, "foam_tet", CM_ERR_FORMAT, "entries, expected as many as the"},
        {"owner", "\n(\n", "\n(\n0\n", CM_ERR_FORMAT, "more entries than its size"},
        {"owner", "\n0\n", "\n", CM_ERR_FORMAT, "entries of owner"},
        {"faces", "4(0 ", "4(100000 ", CM_ERR_FORMAT, "out of range"},
        {"faces", "4(0 ", "4(-1 ", CM_ERR_FORMAT, "out of range"},
        {"points", ")\n)", ")\n", CM_ERR_FORMAT, "points:"},
        {"boundary", "nFaces          ", "nFaces          1", CM_ERR_FORMAT, "boundary"},
        {"neighbour", "\n(\n", "\n(\n-3\n", CM_ERR_FORMAT, "neighbour"},
        {"faces", "FoamFile", "FoamFail", CM_ERR_FORMAT, "FoamFile header"},
        {"points", "(0 0 0)", "(0 0 zero)", CM_ERR_FORMAT, "points:"},
    };
    cm_mesh *m = hex_mesh(0, 0.0);
    char good[2300];
    path(good, sizeof good, work, "foam_bad_src");
    CHECK(cm_mesh_write(ctx, m, good, NULL) == CM_OK);
    for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
        const bad *c = &cases[i];
        char dir[2300];
        snprintf(dir, sizeof dir, "%s/foam_bad_%zu", work, i);
        CHECK(cm_mesh_write(ctx, m, dir, NULL) == CM_OK);
        char f[2500];
        snprintf(f, sizeof f, "%s/constant/polyMesh/%s", dir, c->file);
        if (!c->from && !c->to) {
            remove(f);
        } else if (!c->from) {
            char g[2500];
            snprintf(g, sizeof g, "%s/%s/constant/polyMesh/%s", work, c->to, c->file);
            size_t n;
            char *d = test_read_file(g, &n);
            if (d) test_write_file(f, d, n);
            free(d);
        } else {
            size_t n;
            char *d = test_read_file(f, &n);
            char *body = d ? (strcmp(c->from, "FoamFile") ? strstr(d, "// * *") : d) : NULL;
            char *at = body ? strstr(body, c->from) : NULL;
            CHECK_MSG(at != NULL, "case %zu: '%s' not in %s", i, c->from, f);
            if (!at) {
                free(d);
                continue;
            }
            size_t lf = strlen(c->from), lt = strlen(c->to), pre = (size_t)(at - d);
            char *e = malloc(n - lf + lt + 1);
            memcpy(e, d, pre);
            memcpy(e + pre, c->to, lt);
            memcpy(e + pre + lt, at + lf, n - pre - lf);
            test_write_file(f, e, n - lf + lt);
            free(e);
            free(d);
        }
        cm_mesh *r = NULL;
        cm_status s = cm_mesh_read(ctx, dir, &r);
        const char *msg = cm_context_message(ctx);
        CHECK_MSG(s == c->status && !r, "case %zu (%s): status %d, expected %d: %s", i, c->file, s, c->status, msg);
        CHECK_MSG(strstr(msg, c->words) != NULL, "case %zu: message lacks '%s': %s", i, c->words, msg);
        CHECK_MSG(strstr(msg, dir) != NULL, "case %zu: message lacks the path: %s", i, msg);
        cm_mesh_destroy(&r);
    }
    cm_mesh *r = NULL;
    char none[2300];
    path(none, sizeof none, work, "foam_no_such_case");
    CHECK(cm_mesh_read(ctx, none, &r) == CM_ERR_IO && strstr(cm_context_message(ctx), "no polyMesh"));
    cm_mesh_destroy(&m);
}

/* random corruptions of a good polyMesh: never a crash, and a mesh only if it is valid */
static void corruptions(void)
{
    cm_mesh *m = wedge_pyramid_mesh(1);
    char good[2300], bad[2300];
    path(good, sizeof good, work, "foam_fuzz_src");
    path(bad, sizeof bad, work, "foam_fuzz");
    CHECK(cm_mesh_write(ctx, m, good, NULL) == CM_OK);
    CHECK(cm_mesh_write(ctx, m, bad, NULL) == CM_OK);
    const char *all[] = {"points", "faces", "owner", "neighbour", "boundary"};
    static const char junk[] = "0123456789(){}; \n-e.\"/*x";
    uint64_t seed = 11;
    int errors = 0, valid = 0, bad_mesh = 0;
    for (int it = 0; it < 600; ++it) {
        int f = (int)(test_rng_range(&seed, 0, 5));
        char a[2500], b[2500];
        snprintf(a, sizeof a, "%s/constant/polyMesh/%s", good, all[f]);
        snprintf(b, sizeof b, "%s/constant/polyMesh/%s", bad, all[f]);
        size_t n;
        char *d = test_read_file(a, &n);
        if (!d) continue;
        int edits = 1 + (int)test_rng_range(&seed, 0, 4);
        for (int e = 0; e < edits; ++e) {
            size_t at = (size_t)test_rng_range(&seed, 0, (double)n);
            if (test_rng_range(&seed, 0, 1) < 0.2) n = at; /* truncate */
            else if (at < n) d[at] = junk[(int)test_rng_range(&seed, 0, sizeof junk - 1)];
        }
        test_write_file(b, d, n);
        cm_mesh *r = NULL;
        cm_status s = cm_mesh_read(ctx, bad, &r);
        if (s < 0) {
            ++errors;
            if (r || !strstr(cm_context_message(ctx), "cm_mesh_read")) ++bad_mesh;
        } else {
            ++valid;
            if (!r || cm_mesh_validate(ctx, r, "fuzz") != CM_OK) ++bad_mesh;
        }
        cm_mesh_destroy(&r);
        /* restore the good file */
        free(d);
        d = test_read_file(a, &n);
        if (d) test_write_file(b, d, n);
        free(d);
    }
    CHECK_MSG(bad_mesh == 0, "%d corrupted reads returned a broken mesh or an unnamed error", bad_mesh);
    CHECK(errors > 300);
    printf("corruptions: %d rejected, %d still valid\n", errors, valid);
    cm_mesh_destroy(&m);
}

/* How a path names a case: reconstructed, decomposed, writePrecision, nesting. */
static void case_paths(void)
{
    char *c = NULL;
    CHECK(cm_foam_decomposed_path("a/b/processor*", &c) == 1 && c && !strcmp(c, "a/b"));
    free(c);
    CHECK(cm_foam_decomposed_path("processor*/", &c) == 1 && c && !strcmp(c, "."));
    free(c);
    CHECK(cm_foam_decomposed_path("/processor*", &c) == 1 && c && !strcmp(c, "/"));
    free(c);
    CHECK(cm_foam_decomposed_path("a/processor*x", &c) == 0 && !c);
    c = cm_foam_case_of("x/y/constant/polyMesh/");
    CHECK(c && !strcmp(c, "x/y"));
    free(c);
    c = cm_foam_case_of("constant/polyMesh");
    CHECK(c && !strcmp(c, "."));
    free(c);
    CHECK(cm_foam_case_of("x/polyMesh") == NULL && cm_foam_case_of("x/myconstant/polyMesh") == NULL);

    char dir[2300], f[2600];
    path(dir, sizeof dir, work, "foam_case_paths");
    /* left by an earlier run: start empty */
    const char *old[] = {"system/controlDict", "system", "constant/polyMesh", "constant", "processor0/constant/polyMesh",
                         "processor0/constant", "processor0"};
    for (int k = 0; k < 7; ++k) {
        snprintf(f, sizeof f, "%s/%s", dir, old[k]);
        remove(f);
    }
    snprintf(f, sizeof f, "%s/system", dir);
    mkdir(dir, 0777);
    mkdir(f, 0777);
    CHECK(cm_foam_write_precision(dir) == 0);
    snprintf(f, sizeof f, "%s/system/controlDict", dir);
    const char *cd = "FoamFile { version 2.0; format ascii; class dictionary; object controlDict; }\n"
                     "functions { probe { writePrecision 3; } }\n// writePrecision 4;\nwritePrecision   9 ;\n";
    test_write_file(f, cd, strlen(cd));
    CHECK(cm_foam_write_precision(dir) == 9);
    snprintf(f, sizeof f, "%s/processor12", dir);
    CHECK(cm_foam_write_precision(f) == 9); /* a piece read alone: the case's */
    snprintf(f, sizeof f, "%s/xprocessor12", dir);
    CHECK(cm_foam_write_precision(f) == 0);
    /* processor0 alone: case/ reads the pieces; with constant/polyMesh too, the reconstructed one */
    snprintf(f, sizeof f, "%s/processor0", dir);
    mkdir(f, 0777);
    snprintf(f, sizeof f, "%s/processor0/constant", dir);
    mkdir(f, 0777);
    snprintf(f, sizeof f, "%s/processor0/constant/polyMesh", dir);
    mkdir(f, 0777);
    CHECK(cm_foam_decomposed_path(dir, &c) == 1 && c && !strcmp(c, dir));
    free(c);
    snprintf(f, sizeof f, "%s/constant", dir);
    mkdir(f, 0777);
    snprintf(f, sizeof f, "%s/constant/polyMesh", dir);
    mkdir(f, 0777);
    CHECK(cm_foam_decomposed_path(dir, &c) == 0 && !c);
    /* the pieces' addressing files missing: named in the message */
    cm_mesh *m = NULL;
    snprintf(f, sizeof f, "%s/processor*", dir);
    cm_status s = cm_mesh_read(ctx, f, &m);
    CHECK_MSG(s != CM_OK && strstr(cm_context_message(ctx), "processor0/constant/polyMesh"), "%s",
              cm_context_message(ctx));
    /* a converted mesh is not written as pieces */
    m = hex_mesh(0, 0.25);
    CHECK(cm_mesh_write(ctx, m, f, NULL) == CM_ERR_UNSUPPORTED);
    struct stat st;
    CHECK(stat(f, &st) != 0);
    cm_mesh_destroy(&m);
    snprintf(f, sizeof f, "%s/new/deeper", dir);
    CHECK(cm_foam_nested(dir, f) && cm_foam_nested(f, dir) && cm_foam_nested(dir, dir));
    snprintf(f, sizeof f, "%s_other", dir);
    CHECK(!cm_foam_nested(dir, f));
}

int main(int argc, char **argv)
{
    snprintf(work, sizeof work, "%s", argc > 2 ? argv[2] : ".");
    cm_context_create(&ctx);
    CHECK(cm_mesh_format_from_path("case/") == CM_FORMAT_FOAM);
    CHECK(cm_mesh_format_from_path("a/constant/polyMesh") == CM_FORMAT_FOAM);
    CHECK(cm_mesh_format_from_path("no_extension_case") == CM_FORMAT_FOAM);
    CHECK(cm_mesh_format_from_path("m.vtu") == CM_FORMAT_VTU);

    cm_mesh *m = hex_mesh(0, 0.25);
    round_trip("foam_hex", m, CM_CELL_HEX8);
    cm_mesh_destroy(&m);
    m = hex_mesh(1, 0.25);
    round_trip("foam_tet", m, CM_CELL_TET4);
    cm_mesh_destroy(&m);
    m = wedge_pyramid_mesh(0);
    round_trip("foam_wedge", m, CM_CELL_WEDGE6);
    cm_mesh_destroy(&m);
    m = wedge_pyramid_mesh(1);
    round_trip("foam_pyramid", m, CM_CELL_PYR5);
    cm_mesh_destroy(&m);
    volume_check();
    hostile_patch_names();
    zones();
    case_paths();

    points_only("foam_hex", "foam_hex_morphed", 0);
    gzip_copy("foam_tet", "foam_tet_gz");
    points_only("foam_tet_gz", "foam_tet_gz_morphed", 1);
    binary_read();
    hostile();
    corruptions();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
