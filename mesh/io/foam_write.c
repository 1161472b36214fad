/* OpenFOAM polyMesh writer. `-o` names a case directory or a polyMesh directory. A mesh read
 * from a polyMesh changes `points` only: every other file is copied byte for byte and
 * `points` keeps its header and its format (binary at full precision, plain or .gz; ASCII: a
 * point that did not move keeps its text, a moved one is written at the source case's
 * writePrecision, or in the shortest text that reads back exactly when the case gives none).
 * Written to a case, the whole source case is copied (system/, time directories, constant/),
 * so that the new case runs; written onto the case it came from, only `points` is replaced. A
 * decomposed case is written piece by piece (docs/DESIGN.md, the OpenFOAM row of the format
 * table). Any other mesh is converted (faces matched between cells, patches from the
 * physical groups of its 2D cells). Every file goes through a temporary and a rename. */
#define _POSIX_C_SOURCE 200809L
#include "formats.h"
#include "foam_internal.h"
#include "rewrite.h"

#include <dirent.h>
#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

/* Files are made in memory (cm_rewrite_buf), so that .gz files are compressed in one go. */

static int mkdirs(const char *path)
{
    char tmp[4096];
    size_t l = strlen(path);
    if (l >= sizeof tmp) return -1;
    memcpy(tmp, path, l + 1);
    for (size_t i = 1; i <= l; ++i)
        if (tmp[i] == '/' || tmp[i] == '\0') {
            char c = tmp[i];
            tmp[i] = '\0';
            if (mkdir(tmp, 0777) != 0 && errno != EEXIST) return -1;
            tmp[i] = c;
        }
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode) ? 0 : -1;
}

/* Writes data to dir/name atomically, gzip-compressed when gz (name then ends in .gz), and
 * removes a stale twin (name.gz beside name, or name beside name.gz). */
static cm_status write_file(cm_context *ctx, const char *dir, const char *name, const char *data,
                            size_t n, int gz)
{
    char path[4200], twin[4200];
    if (cm_foam_join(path, sizeof path, dir, name, gz ? ".gz" : NULL) ||
        cm_foam_join(twin, sizeof twin, dir, name, gz ? NULL : ".gz"))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: path too long", dir);
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    if (gz) {
        z_stream z;
        memset(&z, 0, sizeof z);
        if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
            cm_outfile_abort(&out);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: %s: zlib initialisation failed", path);
        }
        unsigned char chunk[1 << 16];
        z.next_in = (unsigned char *)(uintptr_t)data;
        int rc = Z_OK;
        size_t left = n;
        do {
            unsigned take = left > (1u << 30) ? (1u << 30) : (unsigned)left;
            z.next_in = (unsigned char *)(uintptr_t)(data + (n - left));
            z.avail_in = take;
            left -= take;
            int flush = left ? Z_NO_FLUSH : Z_FINISH;
            do {
                z.next_out = chunk;
                z.avail_out = sizeof chunk;
                rc = deflate(&z, flush);
                fwrite(chunk, 1, sizeof chunk - z.avail_out, out.f);
            } while (z.avail_out == 0);
        } while (left);
        deflateEnd(&z);
        if (rc != Z_STREAM_END) {
            cm_outfile_abort(&out);
            return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: compression failed", path);
        }
    } else if (n) {
        fwrite(data, 1, n, out.f);
    }
    s = cm_outfile_commit(ctx, &out);
    if (s == CM_OK) unlink(twin);
    return s;
}

static cm_status copy_file(cm_context *ctx, const char *src_dir, const char *dst_dir, const char *name)
{
    char src[4200], dst[4200];
    if (cm_foam_join(src, sizeof src, src_dir, name, NULL) || cm_foam_join(dst, sizeof dst, dst_dir, name, NULL))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: path too long", dst_dir);
    cm_status s = cm_foam_copy_file(ctx, src, dst);
    if (s == CM_OK) {
        /* a copied "faces" must not sit beside an old "faces.gz" (and the reverse) */
        size_t l = strlen(dst);
        if (l > 3 && !strcmp(dst + l - 3, ".gz")) dst[l - 3] = '\0';
        else cm_foam_join(dst, sizeof dst, dst_dir, name, ".gz");
        unlink(dst);
    }
    return s;
}

/* xyz0: the points as read (NULL: none); precision: digits for a moved point (0: shortest). */
static void points_list(cm_rewrite_buf *b, const double *xyz, int64_t n, const double *xyz0, int precision,
                        int binary, int scalar_bytes)
{
    cm_rewrite_putf(b, "%lld\n(", (long long)n);
    if (binary) {
        if (scalar_bytes == 8) {
            cm_rewrite_put(b, xyz, 3 * (size_t)n * sizeof(double));
        } else {
            for (int64_t i = 0; i < 3 * n; ++i) {
                float x = (float)xyz[i];
                cm_rewrite_put(b, &x, 4);
            }
        }
    } else {
        /* a point that did not move: the shortest text that reads back exactly, which is the
         * text OpenFOAM wrote (at its writePrecision); a moved one at the case's precision */
        cm_rewrite_put(b, "\n", 1);
        char x[3][40];
        int w[3];
        for (int64_t i = 0; i < n; ++i) {
            const double *v = xyz + 3 * i;
            int moved = precision > 0 && xyz0 && (v[0] != xyz0[3 * i] || v[1] != xyz0[3 * i + 1] || v[2] != xyz0[3 * i + 2]);
            for (int k = 0; k < 3; ++k) {
                if (moved) {
                    w[k] = snprintf(x[k], sizeof x[k], "%.*g", precision, v[k]);
                    if (w[k] < 0 || w[k] >= (int)sizeof x[k]) w[k] = 0;
                } else {
                    w[k] = cm_rewrite_number(x[k], sizeof x[k], v[k], NULL, 0);
                }
            }
            cm_rewrite_putf(b, "(%.*s %.*s %.*s)\n", w[0], x[0], w[1], x[1], w[2], x[2]);
        }
    }
    cm_rewrite_put(b, ")", 1);
}

static int same_dir(const char *a, const char *b)
{
    struct stat x, y;
    return stat(a, &x) == 0 && stat(b, &y) == 0 && x.st_dev == y.st_dev && x.st_ino == y.st_ino;
}

static int is_points(const char *name)
{
    return !strcmp(name, "points") || !strcmp(name, "points.gz");
}

/* q's points file into dir, the coordinates xyz (q->n_points of them). */
static cm_status write_points(cm_context *ctx, const cm_foam_poly *q, const double *xyz, int precision, const char *dir)
{
    cm_rewrite_buf b = {0};
    cm_rewrite_put(&b, q->points_head, q->points_head_len);
    points_list(&b, xyz, q->n_points, q->xyz0, precision, q->points_binary, q->scalar_bytes);
    cm_rewrite_put(&b, q->points_tail, q->points_tail_len);
    cm_status s = b.fail ? cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory for points")
                         : write_file(ctx, dir, "points", b.d, b.n, q->points_gz);
    free(b.d);
    return s;
}

/* Every regular file of q's polyMesh but points copied into dir (copy: 1), then points with
 * the coordinates xyz. */
static cm_status polymesh_out(cm_context *ctx, const cm_foam_poly *q, const double *xyz, int precision,
                              const char *dir, int copy)
{
    DIR *d = copy ? opendir(q->dir) : NULL;
    if (copy && !d)
        return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot list the source polyMesh: %s", q->dir, strerror(errno));
    cm_status s = CM_OK;
    struct dirent *e;
    while (d && s == CM_OK && (e = readdir(d))) {
        if (e->d_name[0] == '.' || is_points(e->d_name)) continue;
        char src[4200];
        struct stat st;
        if (cm_foam_join(src, sizeof src, q->dir, e->d_name, NULL) || stat(src, &st) != 0 || !S_ISREG(st.st_mode)) continue; /* sets/ and the like: see the case copy */
        s = copy_file(ctx, q->dir, dir, e->d_name);
    }
    if (d) closedir(d);
    if (s != CM_OK) return s;
    return write_points(ctx, q, xyz, precision, dir);
}

/* ---- a converted mesh: all five files, ASCII ---- */

static void header(cm_rewrite_buf *b, const char *cls, const char *object, const char *note)
{
    cm_rewrite_putf(b, "/*--------------------------------*- C++ -*----------------------------------*\\\n"
            "  Written by cadmorph\n"
            "\\*---------------------------------------------------------------------------*/\n"
            "FoamFile\n{\n    version     2.0;\n    format      ascii;\n    class       %s;\n",
         cls);
    if (note) {
        cm_rewrite_put(b, "    note        \"", 17);
        cm_rewrite_put(b, note, strlen(note));
        cm_rewrite_put(b, "\";\n", 3);
    }
    cm_rewrite_putf(b, "    location    \"constant/polyMesh\";\n    object      %s;\n}\n"
            "// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //\n\n\n",
         object);
}

static const char footer[] = "\n\n\n// ************************************************************************* //\n";

static cm_status flush(cm_context *ctx, cm_rewrite_buf *b, const char *dir, const char *name)
{
    cm_status s = b->fail ? cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory for %s", name)
                          : write_file(ctx, dir, name, b->d, b->n, 0);
    free(b->d);
    memset(b, 0, sizeof *b);
    return s;
}

static void labels(cm_rewrite_buf *b, const int64_t *v, int64_t n)
{
    cm_rewrite_putf(b, "%lld\n(\n", (long long)n);
    for (int64_t i = 0; i < n; ++i) cm_rewrite_putf(b, "%lld\n", (long long)v[i]);
    cm_rewrite_put(b, ")", 1);
    cm_rewrite_put(b, footer, sizeof footer - 1);
}

/* The lines of a patch dictionary but its nFaces and startFace entries (OpenFOAM writes one
 * entry a line). */
static void patch_entries(cm_rewrite_buf *b, const char *dict)
{
    const char *at = dict;
    while (*at) {
        const char *end = strchr(at, '\n');
        size_t n = end ? (size_t)(end - at) + 1 : strlen(at);
        const char *w = at;
        while (w < at + n && (*w == ' ' || *w == '\t')) ++w;
        int range = (!strncmp(w, "nFaces", 6) && (w[6] == ' ' || w[6] == '\t')) ||
                    (!strncmp(w, "startFace", 9) && (w[9] == ' ' || w[9] == '\t'));
        if (!range && w < at + n && *w != '\n' && *w != '\r') cm_rewrite_put(b, at, n);
        else if (!range && at == dict) cm_rewrite_put(b, "\n", 1);
        at += n;
    }
}

/* own: the addressing to write (a decomposed case's merged one), else built from the cells. */
static cm_status write_converted(cm_context *ctx, const cm_mesh *mesh, const char *dir, cm_foam_poly *own)
{
    cm_foam_poly *p = cm_foam_poly_retain(own);
    cm_status s = p ? CM_OK : cm_foam_build(ctx, mesh, &p);
    if (s != CM_OK) return cm_error_prefix(ctx, s, "cm_mesh_write");
    char note[200];
    snprintf(note, sizeof note, "nPoints:%lld  nCells:%lld  nFaces:%lld  nInternalFaces:%lld", (long long)p->n_points,
             (long long)p->n_cells, (long long)p->n_faces, (long long)p->n_internal);
    cm_rewrite_buf b = {0};
    header(&b, "faceList", "faces", NULL);
    cm_rewrite_putf(&b, "%lld\n(\n", (long long)p->n_faces);
    for (int64_t f = 0; f < p->n_faces; ++f) {
        cm_rewrite_putf(&b, "%lld(", (long long)(p->face_off[f + 1] - p->face_off[f]));
        for (int64_t k = p->face_off[f]; k < p->face_off[f + 1]; ++k)
            cm_rewrite_putf(&b, k + 1 < p->face_off[f + 1] ? "%lld " : "%lld", (long long)p->face_nodes[k]);
        cm_rewrite_put(&b, ")\n", 2);
    }
    cm_rewrite_put(&b, ")", 1);
    cm_rewrite_put(&b, footer, sizeof footer - 1);
    s = flush(ctx, &b, dir, "faces");
    if (s == CM_OK) {
        header(&b, "labelList", "owner", note);
        labels(&b, p->owner, p->n_faces);
        s = flush(ctx, &b, dir, "owner");
    }
    if (s == CM_OK) {
        header(&b, "labelList", "neighbour", note);
        labels(&b, p->neighbour, p->n_internal);
        s = flush(ctx, &b, dir, "neighbour");
    }
    if (s == CM_OK) {
        header(&b, "polyBoundaryMesh", "boundary", NULL);
        cm_rewrite_putf(&b, "%zu\n(\n", p->n_patches);
        for (size_t i = 0; i < p->n_patches; ++i) {
            if (own && p->patches[i].dict) {
                /* a decomposed case's merged patch: its entries as read (a cyclic's
                 * neighbourPatch, inGroups, ...), the face range its own */
                cm_rewrite_putf(&b, "    %s\n    {", p->patches[i].name);
                patch_entries(&b, p->patches[i].dict);
                cm_rewrite_putf(&b, "        nFaces          %lld;\n        startFace       %lld;\n    }\n",
                                (long long)p->patches[i].n, (long long)p->patches[i].start);
                continue;
            }
            cm_rewrite_putf(&b, "    %s\n    {\n        type            %s;\n        nFaces          %lld;\n        startFace       %lld;\n    }\n",
                 p->patches[i].name, p->patches[i].type, (long long)p->patches[i].n, (long long)p->patches[i].start);
        }
        cm_rewrite_put(&b, ")", 1);
        cm_rewrite_put(&b, footer, sizeof footer - 1);
        s = flush(ctx, &b, dir, "boundary");
    }
    if (s == CM_OK) {
        header(&b, "vectorField", "points", NULL);
        points_list(&b, mesh->xyz, (int64_t)mesh->n_nodes, NULL, 0, 0, 8);
        cm_rewrite_put(&b, footer, sizeof footer - 1);
        s = flush(ctx, &b, dir, "points");
    }
    free(b.d);
    cm_foam_poly_release(&p);
    return s;
}

/* ---- whole cases ---- */

typedef struct skip_rule {
    const char *src;  /* the source case */
    int undecomposed; /* the source was read from constant/polyMesh */
    size_t n_pieces;
} skip_rule;

/* What the case copy leaves out: the files directly in the polyMesh directories read (written
 * after it, `points` replaced, a stale .gz twin removed), and for a case read undecomposed its
 * processor* directories (pieces of the mesh before the morph, which a parallel run would take
 * instead of the morphed mesh: decompose the new case again). */
static int skip_in_copy(const char *rel, void *arg)
{
    const skip_rule *r = arg;
    if (!strncmp(rel, "processor", 9) && !strchr(rel, '/')) {
        if (r->undecomposed) return 1;
        char *end;
        unsigned long k = strtoul(rel + 9, &end, 10);
        return end == rel + 9 || *end || k >= r->n_pieces; /* not one of the pieces read */
    }
    const char *pm = strstr(rel, "constant/polyMesh/");
    if (!pm || strchr(pm + 18, '/')) return 0;
    if (r->undecomposed ? pm != rel : strncmp(rel, "processor", 9) != 0 || strchr(rel, '/') + 1 != pm) return 0;
    char src[4200];
    struct stat st;
    return snprintf(src, sizeof src, "%s/%s", r->src, rel) < (int)sizeof src && stat(src, &st) == 0 && S_ISREG(st.st_mode);
}

/* The pieces (each's points from the merged coordinates) into case_dir/processorN; copy: the
 * other files of each piece's polyMesh too. */
static cm_status write_pieces(cm_context *ctx, const cm_mesh *mesh, const cm_foam_poly *p, const char *case_dir,
                              int copy)
{
    cm_status s = CM_OK;
    for (size_t i = 0; s == CM_OK && i < p->n_pieces; ++i) {
        const cm_foam_poly *q = p->pieces[i];
        double *xyz = malloc(((size_t)q->n_points * 3 + 1) * sizeof *xyz);
        if (!xyz) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory");
        for (int64_t k = 0; k < q->n_points; ++k) memcpy(xyz + 3 * k, mesh->xyz + 3 * p->piece_points[i][k], 3 * sizeof *xyz);
        char dir[4200];
        snprintf(dir, sizeof dir, "%s/processor%zu/constant/polyMesh", case_dir, i);
        if (mkdirs(dir) != 0)
            s = cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", dir, strerror(errno));
        else
            s = polymesh_out(ctx, q, xyz, p->write_precision, dir, copy);
        free(xyz);
    }
    return s;
}

/* The target's case directory: "X" for X naming a case (written as X/constant/polyMesh, or
 * as X/processorN/... for "X/processor*"), NULL for a path naming a polyMesh directory. */
static char *target_case(const char *path, const char *polymesh_dir, int *pieces)
{
    char *c = NULL;
    *pieces = cm_foam_decomposed_path(path, &c) && c;
    if (*pieces) return c;
    free(c);
    size_t l = strlen(path), d = strlen(polymesh_dir);
    while (l > 1 && path[l - 1] == '/') --l;
    if (d != l + sizeof "/constant/polyMesh" - 1 || strncmp(polymesh_dir, path, l)) return NULL;
    c = malloc(l + 1);
    if (c) {
        memcpy(c, path, l);
        c[l] = '\0';
    }
    return c;
}

/* A mesh read from a case or polyMesh, written to path. */
static cm_status write_back(cm_context *ctx, const cm_mesh *mesh, cm_foam_poly *own, const char *path,
                            const char *dir)
{
    int pieces = 0;
    char *tcase = target_case(path, dir, &pieces);
    cm_status s = CM_OK;
    const char *scase = own->case_dir;
    if (own->n_pieces && !tcase) {
        /* a polyMesh directory named: the reconstructed mesh */
        s = mkdirs(dir) ? cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", dir, strerror(errno))
                        : write_converted(ctx, mesh, dir, own);
    } else if (pieces && !own->n_pieces) {
        s = cm_error(ctx, CM_ERR_UNSUPPORTED,
                     "cm_mesh_write: %s: the mesh was read undecomposed; write the case and run decomposePar on it", path);
    } else if (own->n_pieces && same_dir(scase, tcase)) {
        s = write_pieces(ctx, mesh, own, scase, 0); /* in place: points only */
    } else if (!own->n_pieces && same_dir(own->dir, dir)) {
        s = polymesh_out(ctx, own, mesh->xyz, own->write_precision, dir, 0); /* in place: points only */
    } else if (tcase && scase && cm_foam_nested(scase, tcase)) {
        s = cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: the new case and the source case %s lie one inside the other; "
                     "write it beside the source", tcase, scase);
    } else if (tcase && scase) {
        skip_rule rule = {scase, !own->n_pieces, own->n_pieces};
        s = mkdirs(tcase) ? cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", tcase, strerror(errno))
                          : cm_foam_copy_tree(ctx, scase, tcase, skip_in_copy, &rule);
        if (s == CM_OK && own->n_pieces) s = write_pieces(ctx, mesh, own, tcase, 1);
        else if (s == CM_OK && mkdirs(dir) != 0)
            s = cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", dir, strerror(errno));
        else if (s == CM_OK) s = polymesh_out(ctx, own, mesh->xyz, own->write_precision, dir, 1);
    } else {
        s = mkdirs(dir) ? cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", dir, strerror(errno))
                        : polymesh_out(ctx, own, mesh->xyz, own->write_precision, dir, 1);
    }
    free(tcase);
    return s;
}

cm_status cm_mesh_write_foam(cm_context *ctx, const cm_mesh *mesh, const char *path,
                             const cm_mesh_write_options *opt)
{
    (void)opt;
    char *dir = cm_foam_polymesh_dir(path);
    if (!dir) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory");
    cm_status s = CM_OK;
    cm_foam_poly *own = cm_mesh_origin_state(mesh, CM_FORMAT_FOAM);
    char *pieces = NULL;
    if (own && (own->dir || own->n_pieces)) {
        s = write_back(ctx, mesh, own, path, dir);
    } else if (cm_foam_decomposed_path(path, &pieces) && pieces) {
        s = cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_write: %s: only a mesh read from a decomposed case is written as "
                     "processor pieces; write the case and run decomposePar on it", path);
    } else if (mkdirs(dir) != 0) {
        s = cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", dir, strerror(errno));
    } else {
        s = write_converted(ctx, mesh, dir, NULL);
    }
    free(pieces);
    free(dir);
    return s;
}
