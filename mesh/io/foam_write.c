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

/* dir/name (name.gz when gz) into the temporary *out, gzip-compressed when gz, not committed;
 * twin: the stale other form (name.gz beside name, or name beside name.gz), to remove once
 * committed. */
static cm_status fill_file(cm_context *ctx, const char *dir, const char *name, const char *data, size_t n, int gz,
                           cm_outfile *out, char *twin, size_t cap)
{
    char path[4200];
    if (cm_foam_join(path, sizeof path, dir, name, gz ? ".gz" : NULL) ||
        cm_foam_join(twin, cap, dir, name, gz ? NULL : ".gz"))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: path too long", dir);
    cm_status s = cm_outfile_open(ctx, path, out);
    if (s != CM_OK) return s;
    if (gz) {
        z_stream z;
        memset(&z, 0, sizeof z);
        if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
            cm_outfile_abort(out);
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
                fwrite(chunk, 1, sizeof chunk - z.avail_out, out->f);
            } while (z.avail_out == 0);
        } while (left);
        deflateEnd(&z);
        if (rc != Z_STREAM_END) {
            cm_outfile_abort(out);
            return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: compression failed", path);
        }
    } else if (n) {
        fwrite(data, 1, n, out->f);
    }
    return CM_OK;
}

/* Writes data to dir/name atomically (see fill_file). */
static cm_status write_file(cm_context *ctx, const char *dir, const char *name, const char *data,
                            size_t n, int gz)
{
    char twin[4200];
    cm_outfile out;
    cm_status s = fill_file(ctx, dir, name, data, n, gz, &out, twin, sizeof twin);
    if (s == CM_OK) s = cm_outfile_commit(ctx, &out);
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

/* q's points file (the coordinates xyz, q->n_points of them) into dir, left in the temporary
 * *out (see fill_file). */
static cm_status fill_points(cm_context *ctx, const cm_foam_poly *q, const double *xyz, int precision,
                             const char *dir, cm_outfile *out, char *twin, size_t cap)
{
    cm_rewrite_buf b = {0};
    cm_rewrite_put(&b, q->points_head, q->points_head_len);
    points_list(&b, xyz, q->n_points, q->xyz0, precision, q->points_binary, q->scalar_bytes);
    cm_rewrite_put(&b, q->points_tail, q->points_tail_len);
    cm_status s = b.fail ? cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory for points")
                         : fill_file(ctx, dir, "points", b.d, b.n, q->points_gz, out, twin, cap);
    free(b.d);
    return s;
}

/* q's points file into dir, committed: one rename, so that the old or the new points are
 * there whatever happens. */
static cm_status write_points(cm_context *ctx, const cm_foam_poly *q, const double *xyz, int precision, const char *dir)
{
    char twin[4200];
    cm_outfile out;
    cm_status s = fill_points(ctx, q, xyz, precision, dir, &out, twin, sizeof twin);
    if (s == CM_OK) s = cm_outfile_commit(ctx, &out);
    if (s == CM_OK) unlink(twin);
    return s;
}

/* Everything in q's polyMesh but points copied into dir (copy: 1; subdirectories such as
 * sets/ whole), then points with the coordinates xyz. */
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
        if (cm_foam_join(src, sizeof src, q->dir, e->d_name, NULL) || stat(src, &st) != 0) continue;
        if (S_ISREG(st.st_mode)) {
            s = copy_file(ctx, q->dir, dir, e->d_name);
        } else if (S_ISDIR(st.st_mode)) {
            char dst[4200];
            if (cm_foam_join(dst, sizeof dst, dir, e->d_name, NULL))
                s = cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: path too long", dir);
            else
                s = cm_foam_copy_tree(ctx, src, dst, NULL, NULL);
        }
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

/* What the case copy leaves out: the polyMesh directories read (each written whole after it,
 * see swap_polymesh), and for a case read undecomposed its processor* directories (pieces of
 * the mesh before the morph, which a parallel run would take instead of the morphed mesh:
 * decompose the new case again). */
static int skip_in_copy(const char *rel, void *arg)
{
    const skip_rule *r = arg;
    if (!strncmp(rel, "processor", 9) && !strchr(rel, '/')) {
        if (r->undecomposed) return 1;
        char *end;
        unsigned long k = strtoul(rel + 9, &end, 10);
        return end == rel + 9 || *end || k >= r->n_pieces; /* not one of the pieces read */
    }
    if (r->undecomposed) return !strcmp(rel, "constant/polyMesh");
    const char *slash = strchr(rel, '/');
    return !strncmp(rel, "processor", 9) && slash && !strcmp(slash, "/constant/polyMesh");
}

/* The directory a write into the polyMesh directory dir locks: the case X of
 * "X/constant/polyMesh", else the directory holding dir. Created when missing. */
static cm_status lock_for(cm_context *ctx, const char *dir, int *fd)
{
    *fd = -1;
    char *c = cm_foam_case_of(dir);
    if (!c) {
        size_t l = strlen(dir);
        while (l > 1 && dir[l - 1] == '/') --l;
        while (l > 0 && dir[l - 1] != '/') --l;
        while (l > 1 && dir[l - 1] == '/') --l;
        c = malloc(l + 2);
        if (c && l) {
            memcpy(c, dir, l);
            c[l] = '\0';
        } else if (c) {
            strcpy(c, ".");
        }
    }
    if (!c) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory");
    cm_status s = mkdirs(c) ? cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", c, strerror(errno))
                            : cm_output_lock(ctx, c, fd);
    free(c);
    return s;
}

/* The polyMesh directory dir written whole into a temporary sibling (od), not yet committed:
 * the mesh converted (src NULL; conv: a decomposed case's merged addressing or NULL), or src's
 * files with the coordinates xyz. */
static cm_status fill_polymesh(cm_context *ctx, const cm_mesh *mesh, const char *dir, const cm_foam_poly *src,
                               const double *xyz, int precision, cm_foam_poly *conv, cm_outdir *od)
{
    cm_status s = cm_outdir_open(ctx, dir, od);
    if (s != CM_OK) return cm_error_prefix(ctx, s, "cm_mesh_write");
    s = src ? polymesh_out(ctx, src, xyz, precision, od->tmp, 1) : write_converted(ctx, mesh, od->tmp, conv);
    if (s != CM_OK) {
        /* the message names the file as it would have been, not its temporary */
        const char *msg = cm_context_message(ctx);
        size_t t = strlen(od->tmp);
        char *at = msg ? strstr(msg, od->tmp) : NULL;
        if (at && at[t] == '/') {
            char *copy = malloc(strlen(msg) + 1);
            if (copy) {
                strcpy(copy, msg);
                s = cm_error(ctx, s, "%.*s%s%s", (int)(at - msg), copy, dir, copy + (at - msg) + t);
                free(copy);
            }
        }
        cm_outdir_abort(od);
    }
    return s;
}

/* fill_polymesh, then swapped in: the old polyMesh (its zones and sets included) is replaced
 * in one step by a complete new one (docs/DESIGN.md, "Command line contract"). */
static cm_status swap_polymesh(cm_context *ctx, const cm_mesh *mesh, const char *dir, const cm_foam_poly *src,
                               const double *xyz, int precision, cm_foam_poly *conv)
{
    cm_outdir od;
    cm_status s = fill_polymesh(ctx, mesh, dir, src, xyz, precision, conv, &od);
    return s == CM_OK ? cm_outdir_commit(ctx, &od) : s;
}

/* Piece i's points, from the merged coordinates (malloc'ed; NULL: out of memory). */
static double *piece_xyz(const cm_mesh *mesh, const cm_foam_poly *p, size_t i)
{
    const cm_foam_poly *q = p->pieces[i];
    double *xyz = malloc(((size_t)q->n_points * 3 + 1) * sizeof *xyz);
    if (xyz)
        for (int64_t k = 0; k < q->n_points; ++k) memcpy(xyz + 3 * k, mesh->xyz + 3 * p->piece_points[i][k], 3 * sizeof *xyz);
    return xyz;
}

/* The pieces into case_dir/processorN. In place (copy 0): each piece's points only, every
 * temporary complete before the first rename, the renames one group (cm_outfile_commit_all).
 * Into another case (copy 1): each piece's polyMesh whole in a temporary directory, all
 * written before the first is swapped in. */
static cm_status write_pieces(cm_context *ctx, const cm_mesh *mesh, const cm_foam_poly *p, const char *case_dir,
                              int copy)
{
    size_t n = p->n_pieces;
    cm_outfile *outs = calloc(n + 1, sizeof *outs);
    cm_outdir *ods = calloc(n + 1, sizeof *ods);
    char(*twins)[4200] = calloc(n + 1, sizeof *twins);
    if (!outs || !ods || !twins) {
        free(outs);
        free(ods);
        free(twins);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory");
    }
    cm_status s = CM_OK;
    size_t done = 0;
    for (; s == CM_OK && done < n; ++done) {
        const cm_foam_poly *q = p->pieces[done];
        double *xyz = piece_xyz(mesh, p, done);
        char dir[4200];
        snprintf(dir, sizeof dir, "%s/processor%zu/constant/polyMesh", case_dir, done);
        if (!xyz)
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory");
        else if (copy)
            s = fill_polymesh(ctx, mesh, dir, q, xyz, p->write_precision, NULL, &ods[done]);
        else
            s = fill_points(ctx, q, xyz, p->write_precision, dir, &outs[done], twins[done], sizeof twins[done]);
        free(xyz);
        if (s != CM_OK) break;
    }
    if (s != CM_OK) {
        for (size_t i = 0; i < done; ++i) {
            cm_outfile_abort(&outs[i]);
            cm_outdir_abort(&ods[i]);
        }
    } else if (copy) {
        for (size_t i = 0; i < n; ++i) {
            cm_status e = s == CM_OK ? cm_outdir_commit(ctx, &ods[i]) : CM_OK;
            if (s != CM_OK) cm_outdir_abort(&ods[i]);
            s = e;
        }
    } else {
        s = cm_outfile_commit_all(ctx, outs, n, NULL, NULL);
        for (size_t i = 0; s == CM_OK && i < n; ++i) unlink(twins[i]);
    }
    free(outs);
    free(ods);
    free(twins);
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

/* A mesh read from a case or polyMesh, written to path, under the lock of the case written. */
static cm_status write_back(cm_context *ctx, const cm_mesh *mesh, cm_foam_poly *own, const char *path,
                            const char *dir)
{
    int pieces = 0, lock = -1;
    char *tcase = target_case(path, dir, &pieces);
    cm_status s = CM_OK;
    const char *scase = own->case_dir;
    if (own->n_pieces && !tcase) {
        /* a polyMesh directory named: the reconstructed mesh */
        s = lock_for(ctx, dir, &lock);
        if (s == CM_OK) s = swap_polymesh(ctx, mesh, dir, NULL, NULL, 0, own);
    } else if (pieces && !own->n_pieces) {
        s = cm_error(ctx, CM_ERR_UNSUPPORTED,
                     "cm_mesh_write: %s: the mesh was read undecomposed; write the case and run decomposePar on it", path);
    } else if (own->n_pieces && same_dir(scase, tcase)) {
        s = cm_output_lock(ctx, scase, &lock);
        if (s == CM_OK) s = write_pieces(ctx, mesh, own, scase, 0); /* in place: points only */
    } else if (!own->n_pieces && same_dir(own->dir, dir)) {
        s = lock_for(ctx, dir, &lock);
        if (s == CM_OK) s = write_points(ctx, own, mesh->xyz, own->write_precision, dir); /* in place: one file */
    } else if (tcase && scase && cm_foam_nested(scase, tcase)) {
        s = cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: the new case and the source case %s lie one inside the other; "
                     "write it beside the source", tcase, scase);
    } else if (tcase && scase) {
        /* the other files of the source case copied over (each one atomically; files of the
         * target case that the source lacks stay), then the polyMesh swapped in whole */
        skip_rule rule = {scase, !own->n_pieces, own->n_pieces};
        s = mkdirs(tcase) ? cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", tcase, strerror(errno))
                          : cm_output_lock(ctx, tcase, &lock);
        if (s == CM_OK) s = cm_foam_copy_tree(ctx, scase, tcase, skip_in_copy, &rule);
        if (s == CM_OK && own->n_pieces) s = write_pieces(ctx, mesh, own, tcase, 1);
        else if (s == CM_OK) s = swap_polymesh(ctx, mesh, dir, own, mesh->xyz, own->write_precision, NULL);
    } else {
        s = lock_for(ctx, dir, &lock);
        if (s == CM_OK) s = swap_polymesh(ctx, mesh, dir, own, mesh->xyz, own->write_precision, NULL);
    }
    cm_output_unlock(&lock);
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
    } else {
        /* a converted mesh: a whole new polyMesh swapped in; nothing else of the case touched */
        int lock = -1;
        s = lock_for(ctx, dir, &lock);
        if (s == CM_OK) s = swap_polymesh(ctx, mesh, dir, NULL, NULL, 0, NULL);
        cm_output_unlock(&lock);
    }
    free(pieces);
    free(dir);
    return s;
}
