/* OpenFOAM polyMesh writer. `-o` names a case directory (its constant/polyMesh is created
 * and written, nothing else in the case is touched) or a polyMesh directory. A mesh read from
 * a polyMesh changes `points` only: every other file of the source polyMesh is copied byte
 * for byte and `points` keeps its header and its format (ASCII with 17 significant digits,
 * which round-trips doubles, or binary, plain or .gz). Any other mesh is converted (faces
 * matched between cells, patches from the physical groups of its 2D cells). Every file goes
 * through a temporary and a rename. */
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
    FILE *in = fopen(src, "rb");
    if (!in) return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot open: %s", src, strerror(errno));
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, dst, &out);
    if (s != CM_OK) {
        fclose(in);
        return s;
    }
    char chunk[1 << 16];
    size_t got;
    while ((got = fread(chunk, 1, sizeof chunk, in)) > 0) fwrite(chunk, 1, got, out.f);
    int err = ferror(in);
    fclose(in);
    if (err) {
        cm_outfile_abort(&out);
        return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: read error", src);
    }
    s = cm_outfile_commit(ctx, &out);
    if (s == CM_OK) {
        /* a copied "faces" must not sit beside an old "faces.gz" (and the reverse) */
        size_t l = strlen(dst);
        if (l > 3 && !strcmp(dst + l - 3, ".gz")) dst[l - 3] = '\0';
        else cm_foam_join(dst, sizeof dst, dst_dir, name, ".gz");
        unlink(dst);
    }
    return s;
}

static void points_list(cm_rewrite_buf *b, const cm_mesh *m, int binary, int scalar_bytes)
{
    cm_rewrite_putf(b, "%zu\n(", m->n_nodes);
    if (binary) {
        if (scalar_bytes == 8) {
            cm_rewrite_put(b, m->xyz, 3 * m->n_nodes * sizeof(double));
        } else {
            for (size_t i = 0; i < 3 * m->n_nodes; ++i) {
                float x = (float)m->xyz[i];
                cm_rewrite_put(b, &x, 4);
            }
        }
    } else {
        /* the shortest text that reads back exactly: a point OpenFOAM wrote (at its
         * writePrecision) and nothing moved is written with the same digits */
        cm_rewrite_put(b, "\n", 1);
        char x[3][40];
        int n[3];
        for (size_t i = 0; i < m->n_nodes; ++i) {
            for (int k = 0; k < 3; ++k) n[k] = cm_rewrite_number(x[k], sizeof x[k], m->xyz[3 * i + k], NULL, 0);
            cm_rewrite_putf(b, "(%.*s %.*s %.*s)\n", n[0], x[0], n[1], x[1], n[2], x[2]);
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

static cm_status write_points_only(cm_context *ctx, const cm_mesh *mesh, const cm_foam_poly *p, const char *dir)
{
    if (same_dir(p->dir, dir))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s is the polyMesh the mesh was read from; refusing to overwrite it", dir);
    DIR *d = opendir(p->dir);
    if (!d) return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot list the source polyMesh: %s", p->dir, strerror(errno));
    cm_status s = CM_OK;
    struct dirent *e;
    while (s == CM_OK && (e = readdir(d))) {
        if (e->d_name[0] == '.' || is_points(e->d_name)) continue;
        char src[4200];
        struct stat st;
        if (cm_foam_join(src, sizeof src, p->dir, e->d_name, NULL) || stat(src, &st) != 0 || !S_ISREG(st.st_mode)) continue; /* sets/ and the like stay behind */
        s = copy_file(ctx, p->dir, dir, e->d_name);
    }
    closedir(d);
    if (s != CM_OK) return s;
    cm_rewrite_buf b = {0};
    cm_rewrite_put(&b, p->points_head, p->points_head_len);
    points_list(&b, mesh, p->points_binary, p->scalar_bytes);
    cm_rewrite_put(&b, p->points_tail, p->points_tail_len);
    if (b.fail) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory for points");
    else s = write_file(ctx, dir, "points", b.d, b.n, p->points_gz);
    free(b.d);
    return s;
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

static cm_status write_converted(cm_context *ctx, const cm_mesh *mesh, const char *dir)
{
    cm_foam_poly *p = NULL;
    cm_status s = cm_foam_build(ctx, mesh, &p);
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
        for (size_t i = 0; i < p->n_patches; ++i)
            cm_rewrite_putf(&b, "    %s\n    {\n        type            %s;\n        nFaces          %lld;\n        startFace       %lld;\n    }\n",
                 p->patches[i].name, p->patches[i].type, (long long)p->patches[i].n, (long long)p->patches[i].start);
        cm_rewrite_put(&b, ")", 1);
        cm_rewrite_put(&b, footer, sizeof footer - 1);
        s = flush(ctx, &b, dir, "boundary");
    }
    if (s == CM_OK) {
        header(&b, "vectorField", "points", NULL);
        points_list(&b, mesh, 0, 8);
        cm_rewrite_put(&b, footer, sizeof footer - 1);
        s = flush(ctx, &b, dir, "points");
    }
    free(b.d);
    cm_foam_poly_release(&p);
    return s;
}

cm_status cm_mesh_write_foam(cm_context *ctx, const cm_mesh *mesh, const char *path,
                             const cm_mesh_write_options *opt)
{
    (void)opt;
    char *dir = cm_foam_polymesh_dir(path);
    if (!dir) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: out of memory");
    cm_status s = CM_OK;
    const cm_foam_poly *own = cm_mesh_origin_state(mesh, CM_FORMAT_FOAM);
    if (mkdirs(dir) != 0) {
        s = cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", dir, strerror(errno));
    } else if (own && own->dir) {
        s = write_points_only(ctx, mesh, own, dir);
    } else {
        s = write_converted(ctx, mesh, dir);
    }
    free(dir);
    return s;
}
