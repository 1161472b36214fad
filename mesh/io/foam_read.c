/* OpenFOAM polyMesh reader: one polyMesh directory (points, faces, owner, neighbour,
 * boundary; optional cell/face/point zones), ASCII or binary, plain or .gz, and the mesh of
 * such a record (or of a decomposed case's merged one: foam_decomposed.c; which a path names:
 * foam_case.c).
 * Cells become polyhedra, or tet/hex/wedge/pyramid when their faces have exactly that shape
 * (so that the scaled Jacobian is Verdict's); boundary faces are added as 2D cells with the
 * patch as physical group (tag = patch index + 1), cells in a cellZone get the zone's group
 * (tags after the patches). The face-addressed original is kept for writing and checkMesh. */
#define _POSIX_C_SOURCE 200809L
#include "formats.h"
#include "foam_internal.h"
#include "cell_faces.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

/* ---- boundary and zones ---- */

static char *dup_n(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

static int tok_is(cm_foam_tok t, const char *w)
{
    size_t n = strlen(w);
    return t.kind == CM_FOAM_WORD && t.len == n && !memcmp(t.s, w, n);
}

/* Skips the value of an entry whose key was just read: up to its ';', or one {...} sub-dictionary. */
static cm_status skip_entry(cm_context *ctx, cm_foam_lex *lx)
{
    cm_foam_tok t = cm_foam_peek(lx);
    if (t.kind == CM_FOAM_PUNCT && t.s[0] == '{') {
        int depth = 0;
        for (;;) {
            t = cm_foam_next(lx);
            if (t.kind == CM_FOAM_EOF) return cm_foam_expect(ctx, lx, '}', "'}' closing a sub-dictionary");
            if (t.kind == CM_FOAM_PUNCT && t.s[0] == '{') ++depth;
            if (t.kind == CM_FOAM_PUNCT && t.s[0] == '}' && --depth == 0) return CM_OK;
        }
    }
    cm_status s = cm_foam_skip_value(ctx, lx, "';' ending the entry");
    if (s == CM_OK) s = cm_foam_expect(ctx, lx, ';', "';' ending the entry");
    return s;
}

/* Inflated-byte budgets of a .gz file per entry of its first count (foam_lex.c, read_gz):
 * generous, an entry written by OpenFOAM in ASCII at full precision takes a quarter or less:
 * a label ("-9223372036854775808" and a newline: 21 bytes), a point (three 24-character
 * scalars in brackets: 77), a face (1 KiB: some 45 vertices of 20 digits, where real meshes
 * average 4 to 6 vertices), a patch dictionary (type, inGroups, nFaces, startFace, the
 * processor and cyclic entries: under 1 KiB) or a zone (its labels, and a flipMap for a face
 * zone, at most one per cell, face or point). */
enum { LABEL_BYTES = 64, POINT_BYTES = 256, FACE_BYTES = 1024, PATCH_BYTES = 16384, ZONE_BYTES = 16384 };
/* more patches or zones than any case has (a decomposed piece has one per neighbour piece) */
enum { MAX_PATCHES = 1000000, MAX_ZONES = 1000000 };

static cm_status read_boundary(cm_context *ctx, const char *dir, cm_foam_poly *p)
{
    cm_foam_file f;
    cm_status s = cm_foam_file_load_bounded(ctx, dir, "boundary", 0, PATCH_BYTES, MAX_PATCHES, &f);
    if (s != CM_OK) return s;
    cm_foam_lex lx;
    cm_foam_lex_init(&lx, &f, f.body);
    int64_t n = 0;
    char w[600];
    s = cm_foam_label(ctx, &lx, "the number of patches", &n);
    /* a patch takes at least "p{nFaces 0;startFace 0;}" (24 bytes): a larger count is refused
     * before the patches are allocated */
    if (s == CM_OK && (n < 0 || n > MAX_PATCHES || (uint64_t)n > (f.size - lx.pos) / 24))
        s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %lld patches, more than the %zu bytes left can hold",
                     cm_foam_where(&lx, w, sizeof w), (long long)n, f.size - lx.pos);
    if (s == CM_OK) s = cm_foam_expect(ctx, &lx, '(', "'(' opening the patch list");
    if (s == CM_OK && n > 0 && !(p->patches = calloc((size_t)n, sizeof *p->patches)))
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    for (int64_t i = 0; s == CM_OK && i < n; ++i) {
        cm_foam_patch *pt = &p->patches[i];
        pt->start = pt->n = -1;
        cm_foam_tok name = cm_foam_next(&lx);
        if (name.kind != CM_FOAM_WORD && name.kind != CM_FOAM_STRING) {
            s = cm_foam_expect(ctx, &lx, '?', "a patch name");
            break;
        }
        p->n_patches = (size_t)i + 1;
        if (!(pt->name = dup_n(name.s, name.len))) s = CM_ERR_NOMEM;
        if (s == CM_OK) s = cm_foam_expect(ctx, &lx, '{', "'{' opening the patch dictionary");
        size_t begin = lx.pos;
        while (s == CM_OK) {
            cm_foam_tok key = cm_foam_next(&lx);
            if (key.kind == CM_FOAM_PUNCT && key.s[0] == '}') {
                if (!(pt->dict = dup_n(f.data + begin, key.at - begin))) s = CM_ERR_NOMEM;
                break;
            }
            if (key.kind != CM_FOAM_WORD) {
                s = cm_foam_expect(ctx, &lx, '}', "an entry or '}' in the patch dictionary");
                break;
            }
            if (tok_is(key, "type")) {
                cm_foam_tok v = cm_foam_next(&lx);
                if (!(pt->type = dup_n(v.s ? v.s : "", v.len))) s = CM_ERR_NOMEM;
                if (s == CM_OK) s = cm_foam_expect(ctx, &lx, ';', "';' after the patch type");
            } else if (tok_is(key, "nFaces") || tok_is(key, "startFace")) {
                s = cm_foam_label(ctx, &lx, key.s[0] == 'n' ? "nFaces" : "startFace", key.s[0] == 'n' ? &pt->n : &pt->start);
                if (s == CM_OK) s = cm_foam_expect(ctx, &lx, ';', "';' after the value");
            } else {
                s = skip_entry(ctx, &lx);
            }
        }
        if (s == CM_OK && (pt->n < 0 || pt->start < 0))
            s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: patch '%s': missing or negative nFaces/startFace",
                         f.path, pt->name);
    }
    if (s == CM_OK) s = cm_foam_expect(ctx, &lx, ')', "')' closing the patch list (more patches than its size?)");
    if (s == CM_ERR_NOMEM) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    cm_foam_file_free(&f);
    return s;
}

static cm_status read_zones(cm_context *ctx, const char *dir, const char *name, cm_foam_zone_kind kind,
                            cm_foam_poly *p)
{
    const int64_t limit = kind == CM_FOAM_CELL_ZONE ? p->n_cells : kind == CM_FOAM_FACE_ZONE ? p->n_faces : p->n_points;
    const char *things = kind == CM_FOAM_CELL_ZONE ? "cells" : kind == CM_FOAM_FACE_ZONE ? "faces" : "points";
    cm_foam_file f;
    /* a zone: its dictionary, at most one label (and flipMap entry) per cell, face or point */
    cm_status s = cm_foam_file_load_bounded(ctx, dir, name, 1, ZONE_BYTES + (uint64_t)limit * (LABEL_BYTES + 4),
                                            MAX_ZONES, &f);
    if (s != CM_OK || !f.data) return s;
    cm_foam_lex lx;
    cm_foam_lex_init(&lx, &f, f.body);
    int64_t n = 0;
    char w[600];
    s = cm_foam_label(ctx, &lx, "the number of zones", &n);
    /* a zone takes at least "z{}" (3 bytes) */
    if (s == CM_OK && (n < 0 || n > MAX_ZONES || (uint64_t)n > (f.size - lx.pos) / 3))
        s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %lld zones, more than the %zu bytes left can hold",
                     cm_foam_where(&lx, w, sizeof w), (long long)n, f.size - lx.pos);
    if (s == CM_OK) s = cm_foam_expect(ctx, &lx, '(', "'(' opening the zone list");
    cm_foam_zone *z = NULL;
    if (s == CM_OK && n > 0) {
        z = realloc(p->zones, (p->n_zones + (size_t)n) * sizeof *z);
        if (!z) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        else p->zones = z;
    }
    const char *labels = kind == CM_FOAM_CELL_ZONE ? "cellLabels" : kind == CM_FOAM_FACE_ZONE ? "faceLabels" : "pointLabels";
    /* a zone holds each of its cells, faces or points once: no more labels than there are */
    char expect[160];
    snprintf(expect, sizeof expect, "at most the %lld %s of the mesh, each once", (long long)limit, things);
    const cm_foam_limit zone_lim = {0, limit, limit, expect};
    /* a uniform list "N{c}" repeats one label: all such lists of the file together (and any
     * list whose first, middle and last labels are equal, a cheap test that a valid zone never
     * meets) hold at most as many labels as the mesh has cells (faces, points), so that a few
     * bytes cannot become zones of the mesh's size, many times over */
    int64_t repeated = 0;
    for (int64_t i = 0; s == CM_OK && i < n; ++i) {
        cm_foam_zone *zn = &p->zones[p->n_zones];
        memset(zn, 0, sizeof *zn);
        zn->kind = kind;
        ++p->n_zones;
        cm_foam_tok nm = cm_foam_next(&lx);
        if (nm.kind != CM_FOAM_WORD && nm.kind != CM_FOAM_STRING) {
            s = cm_foam_expect(ctx, &lx, '?', "a zone name");
            break;
        }
        if (!(zn->name = dup_n(nm.s, nm.len))) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
        if (s == CM_OK) s = cm_foam_expect(ctx, &lx, '{', "'{' opening the zone");
        int64_t n_flip = -1;
        while (s == CM_OK) {
            cm_foam_tok key = cm_foam_next(&lx);
            if (key.kind == CM_FOAM_PUNCT && key.s[0] == '}') break;
            if (key.kind != CM_FOAM_WORD) {
                s = cm_foam_expect(ctx, &lx, '}', "an entry or '}' in the zone");
                break;
            }
            if (tok_is(key, labels) && !zn->ids) {
                s = cm_foam_label_list_in(ctx, &lx, labels, &zone_lim, &zn->ids, &zn->n);
                if (s == CM_OK && zn->n > 1 && zn->ids[0] == zn->ids[zn->n - 1] && zn->ids[0] == zn->ids[zn->n / 2] &&
                    (repeated += zn->n) > limit)
                    s = cm_error(ctx, CM_ERR_FORMAT,
                                 "cm_mesh_read: %s: zone '%s': %lld labels repeated in the zones so far, more than the "
                                 "%lld %s of the mesh",
                                 f.path, zn->name, (long long)repeated, (long long)limit, things);
                for (int64_t k = 0; s == CM_OK && k < zn->n; ++k)
                    if (zn->ids[k] < 0 || zn->ids[k] >= limit)
                        s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: zone '%s': label %lld out of range [0, %lld)",
                                     f.path, zn->name, (long long)zn->ids[k], (long long)limit);
                if (s == CM_OK) s = cm_foam_expect(ctx, &lx, ';', "';' after the labels");
            } else if (tok_is(key, "flipMap") && !zn->flip) {
                /* all false is written "N{0}" */
                const cm_foam_limit flip_lim = {0, limit, limit, expect};
                s = cm_foam_bool_list(ctx, &lx, "flipMap", &flip_lim, &zn->flip, &n_flip);
                if (s == CM_OK) s = cm_foam_expect(ctx, &lx, ';', "';' after flipMap");
            } else {
                s = skip_entry(ctx, &lx);
            }
        }
        if (s == CM_OK && n_flip >= 0 && n_flip != zn->n)
            s = cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: zone '%s': flipMap has %lld entries, %s has %lld",
                         f.path, zn->name, (long long)n_flip, labels, (long long)zn->n);
    }
    if (s == CM_OK) s = cm_foam_expect(ctx, &lx, ')', "')' closing the zone list");
    cm_foam_file_free(&f);
    return s;
}

/* ---- cell shapes ---- */

/* Does the cyclic sequence a (n) equal b (n) up to rotation? */
static int same_cycle(const int64_t *a, const int64_t *b, int n)
{
    for (int r = 0; r < n; ++r) {
        int k = 0;
        while (k < n && a[k] == b[(k + r) % n]) ++k;
        if (k == n) return 1;
    }
    return 0;
}

/* The cell's outward faces: nf faces, sizes fs[], nodes fn[i][0..fs[i]). Tries to order the
 * corners as the VTK type `type` (whose face table must match face for face); returns 1 and
 * fills out[] on success. */
static int match_shape(cm_cell_type type, int nf, const int *fs, int64_t (*fn)[4], int64_t *out)
{
    const cm_face_table *t = cm_cell_face_table(type);
    const int corners = cm_cell_type_info(type)->corners;
    if (!t || t->n_faces != nf) return 0;
    /* face sizes must be a permutation of the table's */
    int want[5] = {0}, have[5] = {0};
    for (int i = 0; i < nf; ++i) {
        ++want[t->size[i]];
        if (fs[i] > 4) return 0;
        ++have[fs[i]];
    }
    if (want[3] != have[3] || want[4] != have[4]) return 0;
    /* anchor: table face 0 onto the first cell face of the same size */
    int a = 0;
    while (fs[a] != t->size[0]) ++a;
    int64_t g[8];
    for (int i = 0; i < 8; ++i) g[i] = -1;
    for (int k = 0; k < t->size[0]; ++k) g[t->node[0][k]] = fn[a][k];
    /* each other corner: the unique node joined by an edge to an anchored one and not in the
     * anchor face */
    for (int pass = 0; pass < 2; ++pass)
        for (int L = 0; L < corners; ++L) {
            if (g[L] >= 0) continue;
            for (int tf = 0; tf < nf && g[L] < 0; ++tf)
                for (int k = 0; k < t->size[tf] && g[L] < 0; ++k) {
                    int u = t->node[tf][k], v = t->node[tf][(k + 1) % t->size[tf]];
                    int K = u == L ? v : v == L ? u : -1;
                    if (K < 0 || g[K] < 0) continue;
                    /* candidate: the cell edge from g[K] to a node not yet used */
                    int64_t cand = -1;
                    int many = 0;
                    for (int cf = 0; cf < nf; ++cf)
                        for (int j = 0; j < fs[cf]; ++j) {
                            int64_t p = fn[cf][j], q = fn[cf][(j + 1) % fs[cf]];
                            int64_t o = p == g[K] ? q : q == g[K] ? p : -1;
                            if (o < 0) continue;
                            int used = 0;
                            for (int m = 0; m < corners; ++m) used |= g[m] == o;
                            if (used) continue;
                            if (cand >= 0 && cand != o) many = 1;
                            cand = o;
                        }
                    if (cand >= 0 && !many) g[L] = cand;
                }
        }
    for (int L = 0; L < corners; ++L)
        if (g[L] < 0) return 0;
    for (int i = 0; i < corners; ++i)
        for (int j = i + 1; j < corners; ++j)
            if (g[i] == g[j]) return 0;
    /* every table face must be a cell face with the same orientation */
    int usedf[6] = {0};
    for (int tf = 0; tf < nf; ++tf) {
        int64_t want_nodes[4];
        for (int k = 0; k < t->size[tf]; ++k) want_nodes[k] = g[t->node[tf][k]];
        int found = 0;
        for (int cf = 0; cf < nf && !found; ++cf)
            if (!usedf[cf] && fs[cf] == t->size[tf] && same_cycle(want_nodes, fn[cf], fs[cf])) found = usedf[cf] = 1;
        if (!found) return 0;
    }
    memcpy(out, g, (size_t)corners * sizeof *g);
    return 1;
}

/* ---- the reader ---- */

typedef struct reader {
    cm_context *ctx;
    const char *path;
    char *dir;
    cm_foam_poly *p;
    double *xyz;
    char *faces_path, *owner_path, *nei_path; /* the files read (X or X.gz), for messages */
} reader;

static cm_status read_points(reader *r)
{
    cm_foam_file f;
    cm_status s = cm_foam_file_load_bounded(r->ctx, r->dir, "points", 0, POINT_BYTES, -1, &f);
    if (s != CM_OK) return s;
    cm_foam_lex lx;
    cm_foam_lex_init(&lx, &f, f.body);
    size_t head = cm_foam_peek(&lx).at;
    /* the faces were read first: a uniform list (all points equal) is at most as long as the
     * faces' vertex lists together (a mesh may keep unused points, so a list of points
     * written one by one is bounded by the file only) */
    char expect[160];
    const int64_t used = r->p->face_off[r->p->n_faces];
    snprintf(expect, sizeof expect, "the %lld vertices of the faces", (long long)used);
    const cm_foam_limit lim = {0, INT64_MAX, used, expect};
    s = cm_foam_scalar_list(r->ctx, &lx, "points", 3, &lim, &r->xyz, &r->p->n_points);
    if (s == CM_OK) {
        cm_foam_poly *p = r->p;
        p->points_head = dup_n(f.data, head);
        p->points_head_len = head;
        p->points_tail = dup_n(f.data + lx.pos, f.size - lx.pos);
        p->points_tail_len = f.size - lx.pos;
        p->points_binary = f.binary;
        p->points_gz = f.gz;
        p->scalar_bytes = f.scalar_bytes;
        p->label_bytes = f.label_bytes;
        if (!p->points_head || !p->points_tail) s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    }
    cm_foam_file_free(&f);
    return s;
}

/* owner (exact: one per face) or neighbour (at most one per face), counted against the faces
 * before anything is allocated or inflated further */
static cm_status read_labels(reader *r, const char *name, int exact, int64_t **v, int64_t *n)
{
    const int64_t nf = r->p->n_faces;
    cm_foam_file f;
    cm_status s = cm_foam_file_load_bounded(r->ctx, r->dir, name, 0, LABEL_BYTES, nf, &f);
    if (s != CM_OK) return s;
    cm_foam_lex lx;
    cm_foam_lex_init(&lx, &f, f.body);
    char expect[160];
    snprintf(expect, sizeof expect, "%s the %lld faces in faces", exact ? "as many as" : "at most", (long long)nf);
    const cm_foam_limit lim = {exact ? nf : 0, nf, nf, expect};
    s = cm_foam_label_list_in(r->ctx, &lx, name, &lim, v, n);
    char **keep = exact ? &r->owner_path : &r->nei_path;
    if (s == CM_OK) {
        *keep = f.path;
        f.path = NULL;
    }
    cm_foam_file_free(&f);
    return s;
}

static cm_status read_faces(reader *r)
{
    cm_foam_file f;
    cm_status s = cm_foam_file_load_bounded(r->ctx, r->dir, "faces", 0, FACE_BYTES, -1, &f);
    if (s != CM_OK) return s;
    cm_foam_lex lx;
    cm_foam_lex_init(&lx, &f, f.body);
    int compact = strcmp(f.cls, "faceCompactList") == 0;
    s = cm_foam_face_list(r->ctx, &lx, compact, "faces", &r->p->face_off, &r->p->face_nodes, &r->p->n_faces);
    for (int64_t i = 0; s == CM_OK && i < r->p->n_faces; ++i) {
        int64_t b = r->p->face_off[i], e = r->p->face_off[i + 1];
        if (e - b < 3)
            s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: face %lld has %lld nodes (at least 3 expected)",
                         f.path, (long long)i, (long long)(e - b));
    }
    if (s == CM_OK && !(r->faces_path = strdup(f.path))) s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    cm_foam_file_free(&f);
    return s;
}

/* After the points: every vertex of a face is one of them. */
static cm_status check_face_points(reader *r)
{
    const cm_foam_poly *p = r->p;
    for (int64_t i = 0; i < p->n_faces; ++i)
        for (int64_t k = p->face_off[i]; k < p->face_off[i + 1]; ++k)
            if (p->face_nodes[k] < 0 || p->face_nodes[k] >= p->n_points)
                return cm_error(r->ctx, CM_ERR_FORMAT,
                                "cm_mesh_read: %s: face %lld: point index %lld out of range [0, %lld) (points has %lld)",
                                r->faces_path, (long long)i, (long long)p->face_nodes[k], (long long)p->n_points,
                                (long long)p->n_points);
    return CM_OK;
}

static cm_status check_addressing(reader *r, int64_t n_owner, int64_t n_nei)
{
    cm_foam_poly *p = r->p;
    const char *own = r->owner_path, *nei = r->nei_path;
    if (n_owner != p->n_faces)
        return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %lld entries, but faces has %lld faces", own,
                        (long long)n_owner, (long long)p->n_faces);
    if (n_nei > p->n_faces)
        return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %lld entries, more than the %lld faces", nei,
                        (long long)n_nei, (long long)p->n_faces);
    p->n_internal = n_nei;
    /* Every cell has at least 4 faces, and a face is seen by its owner and, if internal, its
     * neighbour: the faces can bound (faces + internal faces) / 4 cells at most. A label
     * beyond is refused here, naming its file and entry, before anything is allocated per
     * cell (a label near 2^63 would otherwise be an allocation, or an overflow). */
    const int64_t most = (p->n_faces + n_nei) / 4;
    int64_t maxc = -1;
    for (int k = 0; k < 2; ++k) {
        const int64_t *v = k ? p->neighbour : p->owner, n = k ? n_nei : p->n_faces;
        const char *file = k ? nei : own;
        for (int64_t i = 0; i < n; ++i) {
            if (v[i] < 0 || v[i] >= most)
                return cm_error(r->ctx, CM_ERR_FORMAT,
                                v[i] < 0 ? "cm_mesh_read: %s: entry %lld: cell label %lld is negative"
                                         : "cm_mesh_read: %s: entry %lld: cell label %lld beyond the %lld cells "
                                           "that %lld faces can bound (each cell has at least 4 faces)",
                                file, (long long)i, (long long)v[i], (long long)most, (long long)p->n_faces);
            if (k && v[i] == p->owner[i])
                return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: entry %lld: owner and neighbour are both cell %lld",
                                file, (long long)i, (long long)v[i]);
            if (v[i] > maxc) maxc = v[i];
        }
    }
    p->n_cells = maxc + 1;
    if (p->n_cells == 0)
        return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: no cells (owner is empty)", own);
    /* Cells are numbered without gaps and have at least 4 faces each. The first cell c with
     * fewer is blamed on the file and entry of the smallest label >= c: a label beyond the
     * c cells before it when no cell from c on is complete (a label out of range), else cell
     * c itself. */
    {
        int64_t *count = calloc((size_t)p->n_cells, sizeof *count);
        if (!count) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory for %lld cells", (long long)p->n_cells);
        for (int64_t i = 0; i < p->n_faces; ++i) ++count[p->owner[i]];
        for (int64_t i = 0; i < n_nei; ++i) ++count[p->neighbour[i]];
        int64_t c = 0;
        while (c < p->n_cells && count[c] >= 4) ++c;
        int trailing = 1;
        for (int64_t d = c; d < p->n_cells && trailing; ++d) trailing = count[d] < 4;
        const int64_t faces_c = c < p->n_cells ? count[c] : 0;
        free(count);
        if (c < p->n_cells) {
            const char *file = own;
            int64_t at = -1, label = INT64_MAX;
            for (int k = 0; k < 2; ++k) {
                const int64_t *v = k ? p->neighbour : p->owner, n = k ? n_nei : p->n_faces;
                for (int64_t i = 0; i < n; ++i)
                    if (v[i] >= c && v[i] < label) {
                        label = v[i];
                        at = i;
                        file = k ? nei : own;
                    }
            }
            if (trailing || faces_c == 0)
                return cm_error(r->ctx, CM_ERR_FORMAT,
                                "cm_mesh_read: %s: entry %lld: cell label %lld beyond the %lld cells numbered 0 to %lld "
                                "(cell %lld has %lld faces, at least 4 expected)",
                                file, (long long)at, (long long)label, (long long)c, (long long)(c - 1),
                                (long long)c, (long long)faces_c);
            return cm_error(r->ctx, CM_ERR_FORMAT,
                            "cm_mesh_read: %s: entry %lld: cell %lld has %lld faces (at least 4 expected)", file,
                            (long long)at, (long long)c, (long long)faces_c);
        }
    }
    /* patches: contiguous, from the first boundary face to the last face */
    int64_t at = p->n_internal;
    for (size_t i = 0; i < p->n_patches; ++i) {
        const cm_foam_patch *pt = &p->patches[i];
        if (pt->start != at || pt->n > p->n_faces - at)
            return cm_error(r->ctx, CM_ERR_FORMAT,
                            "cm_mesh_read: %s/boundary: patch '%s': startFace %lld nFaces %lld, expected startFace %lld "
                            "and at most %lld faces",
                            r->dir, pt->name, (long long)pt->start, (long long)pt->n, (long long)at,
                            (long long)(p->n_faces - at));
        at += pt->n;
    }
    if (at != p->n_faces)
        return cm_error(r->ctx, CM_ERR_FORMAT,
                        "cm_mesh_read: %s/boundary: the patches cover faces up to %lld, but there are %lld faces "
                        "(%lld internal)",
                        r->dir, (long long)at, (long long)p->n_faces, (long long)p->n_internal);
    return CM_OK;
}

/* The motion rule OpenFOAM's patch type implies (docs/DESIGN.md, "Boundary motion by patch
 * kind"). */
static cm_patch_kind patch_kind(const char *type)
{
    static const struct {
        const char *type;
        cm_patch_kind kind;
    } kinds[] = {{"symmetryPlane", CM_PATCH_SYMMETRY}, {"symmetry", CM_PATCH_SYMMETRY},
                 {"empty", CM_PATCH_EMPTY},            {"wedge", CM_PATCH_WEDGE},
                 {"cyclic", CM_PATCH_CYCLIC},          {"cyclicAMI", CM_PATCH_CYCLIC},
                 {"cyclicACMI", CM_PATCH_CYCLIC},      {"cyclicSlip", CM_PATCH_CYCLIC},
                 {"processor", CM_PATCH_PROCESSOR},    {"processorCyclic", CM_PATCH_PROCESSOR}};
    for (size_t i = 0; type && i < sizeof kinds / sizeof kinds[0]; ++i)
        if (strcmp(type, kinds[i].type) == 0) return kinds[i].kind;
    return CM_PATCH_PLAIN;
}

static cm_status build_cells(reader *r, cm_mesh *m)
{
    cm_foam_poly *p = r->p;
    const int64_t nc = p->n_cells;
    int64_t *cstart = calloc((size_t)nc + 1, sizeof *cstart);
    int64_t *cface = malloc((size_t)(p->n_faces + p->n_internal + 1) * sizeof *cface);
    int64_t *stream = NULL;
    size_t stream_cap = 0;
    cm_status s = CM_OK;
    if (!cstart || !cface) {
        s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory for the cells");
        goto done;
    }
    for (int64_t f = 0; f < p->n_faces; ++f) ++cstart[p->owner[f] + 1];
    for (int64_t f = 0; f < p->n_internal; ++f) ++cstart[p->neighbour[f] + 1];
    for (int64_t c = 0; c < nc; ++c) {
        if (cstart[c + 1] < 4) {
            s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s/owner: cell %lld has %lld faces (at least 4 expected)",
                         r->dir, (long long)c, (long long)cstart[c + 1]);
            goto done;
        }
        cstart[c + 1] += cstart[c];
    }
    {
        int64_t *fill = malloc((size_t)nc * sizeof *fill);
        if (!fill) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
            goto done;
        }
        memcpy(fill, cstart, (size_t)nc * sizeof *fill);
        /* signed: -(f+1) marks a face the cell sees from the neighbour side */
        for (int64_t f = 0; f < p->n_faces; ++f) cface[fill[p->owner[f]]++] = f + 1;
        for (int64_t f = 0; f < p->n_internal; ++f) cface[fill[p->neighbour[f]]++] = -(f + 1);
        free(fill);
    }
    s = cm_mesh_reserve_cells(r->ctx, m, (size_t)(nc + p->n_faces - p->n_internal),
                              (size_t)(p->face_off[p->n_faces] * 2 + 2 * nc));
    for (int64_t c = 0; s == CM_OK && c < nc; ++c) {
        const int nf = (int)(cstart[c + 1] - cstart[c]);
        size_t need = 1;
        for (int i = 0; i < nf; ++i) {
            int64_t f = llabs(cface[cstart[c] + i]) - 1;
            need += 1 + (size_t)(p->face_off[f + 1] - p->face_off[f]);
        }
        if (need > stream_cap) {
            int64_t *ns = realloc(stream, 2 * need * sizeof *ns);
            if (!ns) {
                s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
                break;
            }
            stream = ns;
            stream_cap = 2 * need;
        }
        size_t k = 0;
        stream[k++] = nf;
        int fs[6];
        int64_t fn[6][4];
        int small = nf <= 6;
        for (int i = 0; i < nf; ++i) {
            int64_t sf = cface[cstart[c] + i], f = llabs(sf) - 1;
            const int64_t *nodes = p->face_nodes + p->face_off[f];
            int64_t n = p->face_off[f + 1] - p->face_off[f];
            stream[k++] = n;
            for (int64_t j = 0; j < n; ++j)
                /* outward: as stored for the owner, reversed (first node kept) for the neighbour */
                stream[k + (size_t)j] = sf > 0 ? nodes[j] : nodes[(n - j) % n];
            if (small && n <= 4) {
                fs[i] = (int)n;
                memcpy(fn[i], stream + k, (size_t)n * sizeof *stream);
            } else {
                small = 0;
            }
            k += (size_t)n;
        }
        int64_t corners[8];
        static const cm_cell_type shapes[] = {CM_CELL_HEX8, CM_CELL_TET4, CM_CELL_WEDGE6, CM_CELL_PYR5};
        cm_cell_type type = CM_CELL_POLYHEDRON;
        for (int t = 0; small && t < 4 && type == CM_CELL_POLYHEDRON; ++t)
            if (match_shape(shapes[t], nf, fs, fn, corners)) type = shapes[t];
        if (type == CM_CELL_POLYHEDRON) s = cm_mesh_add_cell(r->ctx, m, type, stream, k, 0, 0, 0);
        else s = cm_mesh_add_cell(r->ctx, m, type, corners, (size_t)cm_cell_type_info(type)->corners, 0, 0, 0);
    }
    /* boundary faces as 2D cells, physical group = patch index + 1 */
    for (size_t i = 0; s == CM_OK && i < p->n_patches; ++i) {
        const cm_foam_patch *pt = &p->patches[i];
        s = cm_mesh_add_group(r->ctx, m, 2, (int)i + 1, pt->name);
        if (s == CM_OK) m->groups[m->n_groups - 1].kind = patch_kind(pt->type);
        for (int64_t f = pt->start; s == CM_OK && f < pt->start + pt->n; ++f) {
            int64_t n = p->face_off[f + 1] - p->face_off[f];
            cm_cell_type t = n == 3 ? CM_CELL_TRI3 : n == 4 ? CM_CELL_QUAD4 : CM_CELL_POLYGON;
            s = cm_mesh_add_cell(r->ctx, m, t, p->face_nodes + p->face_off[f], (size_t)n, (int)i + 1, (int)i + 1, 0);
        }
    }
done:
    free(cstart);
    free(cface);
    free(stream);
    return s;
}

cm_status cm_foam_read_poly(cm_context *ctx, const char *dir, cm_foam_poly *p)
{
    reader r = {ctx, dir, (char *)dir, p, NULL, NULL, NULL, NULL};
    if (!is_dir(dir)) return cm_error(ctx, CM_ERR_IO, "cm_mesh_read: no polyMesh directory %s", dir);
    int64_t n_owner = 0, n_nei = 0;
    cm_status s = CM_OK;
    if (!p->dir && !(p->dir = strdup(dir))) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    /* faces first: every other count is checked against theirs before it is allocated */
    if (s == CM_OK) s = read_faces(&r);
    if (s == CM_OK) s = read_points(&r);
    p->xyz0 = r.xyz;
    if (s == CM_OK) s = check_face_points(&r);
    free(r.faces_path);
    if (s == CM_OK) s = read_labels(&r, "owner", 1, &p->owner, &n_owner);
    if (s == CM_OK) s = read_labels(&r, "neighbour", 0, &p->neighbour, &n_nei);
    if (s == CM_OK) s = read_boundary(ctx, dir, p);
    if (s == CM_OK) s = check_addressing(&r, n_owner, n_nei);
    free(r.owner_path);
    free(r.nei_path);
    if (s == CM_OK) s = read_zones(ctx, dir, "cellZones", CM_FOAM_CELL_ZONE, p);
    if (s == CM_OK) s = read_zones(ctx, dir, "faceZones", CM_FOAM_FACE_ZONE, p);
    if (s == CM_OK) s = read_zones(ctx, dir, "pointZones", CM_FOAM_POINT_ZONE, p);
    return s;
}

cm_status cm_foam_mesh_of_poly(cm_context *ctx, cm_foam_poly *p, const char *where, cm_mesh **mesh)
{
    *mesh = NULL;
    reader r = {ctx, where, (char *)where, p, NULL, NULL, NULL, NULL};
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_create(ctx, &m);
    if (s == CM_OK) s = cm_mesh_resize_nodes(ctx, m, (size_t)p->n_points, 0);
    if (s == CM_OK) {
        if (p->n_points) memcpy(m->xyz, p->xyz0, (size_t)p->n_points * 3 * sizeof(double));
        s = build_cells(&r, m);
    }
    /* cell zones become the volume cells' physical groups (zone k: tag k + 1; a cell in
     * several zones keeps the last) */
    for (size_t z = 0, k = 0; s == CM_OK && z < p->n_zones; ++z) {
        const cm_foam_zone *zn = &p->zones[z];
        if (zn->kind != CM_FOAM_CELL_ZONE) continue;
        ++k;
        s = cm_mesh_add_group(ctx, m, 3, (int)(p->n_patches + k), zn->name);
        for (int64_t i = 0; s == CM_OK && i < zn->n; ++i)
            m->physical[zn->ids[i]] = m->entity[zn->ids[i]] = (int)(p->n_patches + k);
    }
    if (s == CM_OK) {
        s = cm_mesh_set_origin(ctx, m, CM_FORMAT_FOAM, p, cm_foam_poly_free);
        p = NULL; /* the origin owns it, or has freed it */
    }
    cm_foam_poly_release(&p);
    if (s != CM_OK) {
        cm_mesh_destroy(&m);
        return s < 0 ? s : CM_ERR_FORMAT;
    }
    *mesh = m;
    return CM_OK;
}
