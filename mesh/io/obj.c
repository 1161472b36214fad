/* Wavefront .obj (ASCII) reader and writer for surface meshes: `v x y z [w]`, faces
 * `f a b c ...` (a, a/t, a/t/n, a//n; negative = relative to the last vertex), polylines
 * `l a b ...` (-> line segments), groups `g`/`o` (-> physical groups of dimension 2, one tag
 * per name in order of appearance). Texture coordinates, normals, materials and smoothing
 * groups are read over and not kept. The writer keeps the faces (triangles, quads, polygons;
 * the corners of higher-order faces) and line cells; it has no place for volume cells or
 * fields (volume cells are left out with a warning). Written with %.17g: a round trip is exact. */
#include "formats.h"
#include "surface_io.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A line of the file split in place into whitespace-separated words. */
enum { OBJ_MAX_WORDS = 4096 };

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

/* Parses a face/line vertex reference "a", "a/t", "a/t/n" or "a//n": the position index. */
static int vertex_ref(const char *w, size_t len, size_t n_defined, int64_t *out)
{
    char buf[32], *end;
    size_t k = 0;
    while (k < len && w[k] != '/') ++k;
    if (k == 0 || k >= sizeof buf) return -1;
    memcpy(buf, w, k);
    buf[k] = 0;
    long long v = strtoll(buf, &end, 10);
    if (*end) return -1;
    if (v > 0 && (unsigned long long)v <= n_defined) *out = v - 1;
    else if (v < 0 && (unsigned long long)(-v) <= n_defined) *out = (int64_t)n_defined + v;
    else return -2;
    return 0;
}

static cm_status read_obj(cm_context *ctx, const char *path, const char *data, size_t size,
                          cm_mesh *m)
{
    /* pass 1: count vertices, so xyz is allocated once */
    size_t nv = 0;
    for (size_t p = 0; p < size;) {
        while (p < size && is_space(data[p])) ++p;
        if (p + 1 < size && data[p] == 'v' && is_space(data[p + 1])) ++nv;
        while (p < size && data[p] != '\n') ++p;
        ++p;
    }
    cm_status s = cm_mesh_resize_nodes(ctx, m, nv, 0);
    if (s != CM_OK) return s;
    size_t iv = 0, n_groups = 0;
    int group = 0;
    char **names = NULL;
    long line = 0;
    int64_t *ids = malloc(OBJ_MAX_WORDS * sizeof *ids);
    if (!ids) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
    for (size_t p = 0; s == CM_OK && p < size;) {
        ++line;
        size_t b = p;
        while (p < size && data[p] != '\n') ++p;
        size_t e = p++;
        /* words of [b, e) */
        const char *w[OBJ_MAX_WORDS];
        size_t wl[OBJ_MAX_WORDS], nw = 0;
        for (size_t q = b; q < e;) {
            while (q < e && is_space(data[q])) ++q;
            if (q >= e || data[q] == '#') break;
            if (nw == OBJ_MAX_WORDS) {
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: more than %d words on a line", path, line,
                             OBJ_MAX_WORDS - 1);
                break;
            }
            w[nw] = data + q;
            while (q < e && !is_space(data[q])) ++q;
            wl[nw] = (size_t)(data + q - w[nw]);
            ++nw;
        }
        if (s != CM_OK || nw == 0) continue;
#define KW(str) (wl[0] == sizeof str - 1 && !memcmp(w[0], str, sizeof str - 1))
        if (KW("v")) {
            if (nw < 4 || nw > 7) {
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected 'v x y z [w]'", path, line);
                break;
            }
            for (int k = 0; k < 3 && s == CM_OK; ++k) {
                char buf[64], *end;
                if (wl[k + 1] >= sizeof buf) {
                    s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: coordinate '%.40s...' is too long", path, line, w[k + 1]);
                    break;
                }
                memcpy(buf, w[k + 1], wl[k + 1]);
                buf[wl[k + 1]] = 0;
                double x = strtod(buf, &end);
                if (*end) s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected a coordinate, got '%s'", path, line, buf);
                else if (!isfinite(x)) s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: vertex %zu: coordinate '%s' is not finite", path, line, iv + 1, buf);
                m->xyz[3 * iv + (size_t)k] = x;
            }
            ++iv;
        } else if (KW("f") || KW("l")) {
            int face = w[0][0] == 'f';
            size_t n = nw - 1;
            if (n < (face ? 3u : 2u)) {
                s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: a %s needs at least %d vertices, got %zu", path, line,
                             face ? "face" : "polyline", face ? 3 : 2, n);
                break;
            }
            for (size_t k = 0; k < n && s == CM_OK; ++k) {
                int r = vertex_ref(w[k + 1], wl[k + 1], iv, &ids[k]);
                if (r == -1)
                    s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: expected a vertex index, got '%.*s'", path, line,
                                 (int)(wl[k + 1] > 40 ? 40 : wl[k + 1]), w[k + 1]);
                else if (r == -2)
                    s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: vertex index '%.*s' out of range (%zu vertices defined so far)",
                                 path, line, (int)(wl[k + 1] > 40 ? 40 : wl[k + 1]), w[k + 1], iv);
            }
            if (s != CM_OK) break;
            if (face) {
                cm_cell_type t = n == 3 ? CM_CELL_TRI3 : n == 4 ? CM_CELL_QUAD4 : CM_CELL_POLYGON;
                s = cm_mesh_add_cell(ctx, m, t, ids, n, group, 0, 0);
            } else {
                for (size_t k = 0; k + 1 < n && s == CM_OK; ++k)
                    s = cm_mesh_add_cell(ctx, m, CM_CELL_LINE2, ids + k, 2, group, 0, 0);
            }
        } else if (KW("g") || KW("o")) {
            /* the name is the rest of the line (words joined by single spaces) */
            char name[256] = "";
            size_t len = 0;
            for (size_t k = 1; k < nw && len + wl[k] + 2 < sizeof name; ++k) {
                if (k > 1) name[len++] = ' ';
                memcpy(name + len, w[k], wl[k]);
                len += wl[k];
                name[len] = 0;
            }
            group = 0;
            for (size_t k = 0; k < n_groups; ++k)
                if (!strcmp(names[k], name)) group = (int)k + 1;
            if (!group && len) {
                char **nn = realloc(names, (n_groups + 1) * sizeof *nn);
                if (!nn || !(nn[n_groups] = strdup(name))) {
                    if (nn) names = nn;
                    s = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", path);
                    break;
                }
                names = nn;
                group = (int)++n_groups;
                s = cm_mesh_add_group(ctx, m, 2, group, name);
            }
        } else if (KW("vt") || KW("vn") || KW("vp") || KW("s") || KW("usemtl") || KW("mtllib") ||
                   KW("mg") || KW("p")) {
            /* appearance and grouping data cadmorph has no use for */
        } else {
            s = cm_error(ctx, CM_ERR_FORMAT, "%s:%ld: unknown OBJ statement '%.*s'", path, line,
                         (int)(wl[0] > 40 ? 40 : wl[0]), w[0]);
        }
#undef KW
    }
    for (size_t k = 0; k < n_groups; ++k) free(names[k]);
    free(names);
    free(ids);
    if (s == CM_OK && nv == 0) s = cm_error(ctx, CM_ERR_FORMAT, "%s: no vertices ('v' lines)", path);
    return s;
}

cm_status cm_mesh_read_obj(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    return cm_mesh_read_whole(ctx, "cm_mesh_read_obj", path, read_obj, mesh);
}

cm_status cm_mesh_write_obj(cm_context *ctx, const cm_mesh *mesh, const char *path,
                            const cm_mesh_write_options *opt)
{
    (void)opt;
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_obj: NULL argument");
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    FILE *f = out.f;
    fprintf(f, "# written by cadmorph: %zu vertices\n", mesh->n_nodes);
    for (size_t i = 0; i < mesh->n_nodes; ++i)
        fprintf(f, "v %.17g %.17g %.17g\n", mesh->xyz[3 * i], mesh->xyz[3 * i + 1], mesh->xyz[3 * i + 2]);
    size_t skipped = 0;
    int group = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        size_t n;
        const int64_t *v = cm_surface_io_corners(mesh, c, &n);
        if (!v) {
            ++skipped;
            continue;
        }
        if (mesh->physical[c] != group) {
            group = mesh->physical[c];
            const char *name = NULL;
            for (size_t g = 0; g < mesh->n_groups; ++g)
                if (mesh->groups[g].tag == group && mesh->groups[g].dim == cm_cell_type_info((cm_cell_type)mesh->type[c])->dim)
                    name = mesh->groups[g].name;
            if (name && *name && !strpbrk(name, "\n\r")) fprintf(f, "g %s\n", name);
            else fprintf(f, "g group_%d\n", group);
        }
        fputs(n == 2 ? "l" : "f", f);
        for (size_t k = 0; k < n; ++k) fprintf(f, " %lld", (long long)v[k] + 1);
        fputc('\n', f);
    }
    s = cm_outfile_commit(ctx, &out);
    if (s == CM_OK && skipped)
        return cm_error(ctx, CM_WARNING, "%s: %zu cells that are not faces or lines are not written (OBJ holds surfaces)",
                        path, skipped);
    return s;
}
