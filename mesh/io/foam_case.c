/* An OpenFOAM case around its polyMesh: which form a path names (the reconstructed
 * constant/polyMesh or the processorN pieces), the case's writePrecision, and the copy of a
 * whole case that makes `-o newcase/` runnable (docs/DESIGN.md, the OpenFOAM row of the
 * format table). */
#define _XOPEN_SOURCE 700 /* realpath */
#include "formats.h"
#include "foam_internal.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

static int exists(const char *dir, const char *name)
{
    char buf[4096];
    struct stat st;
    return cm_foam_join(buf, sizeof buf, dir, name, NULL) == 0 && stat(buf, &st) == 0;
}

char *cm_foam_polymesh_dir(const char *path)
{
    size_t l = strlen(path);
    while (l > 1 && path[l - 1] == '/') --l;
    const char *base = path + l;
    while (base > path && base[-1] != '/') --base;
    char *d;
    int as_is = (size_t)(path + l - base) == 8 && !memcmp(base, "polyMesh", 8);
    if (!as_is && l < 4000) {
        char tmp[4096];
        memcpy(tmp, path, l);
        tmp[l] = '\0';
        /* a directory that holds the polyMesh files itself, whatever its name */
        as_is = is_dir(tmp) && (exists(tmp, "faces") || exists(tmp, "faces.gz")) && !exists(tmp, "constant");
    }
    if (as_is) {
        d = malloc(l + 1);
        if (d) {
            memcpy(d, path, l);
            d[l] = '\0';
        }
        return d;
    }
    d = malloc(l + sizeof "/constant/polyMesh");
    if (d) {
        memcpy(d, path, l);
        memcpy(d + l, "/constant/polyMesh", sizeof "/constant/polyMesh");
    }
    return d;
}

static int ends_with(const char *s, size_t l, const char *tail)
{
    size_t t = strlen(tail);
    return l >= t && !memcmp(s + l - t, tail, t);
}

int cm_foam_decomposed_path(const char *path, char **case_dir)
{
    *case_dir = NULL;
    size_t l = strlen(path);
    while (l > 1 && path[l - 1] == '/') --l;
    if (l >= 3000) return 0;
    char c[4096];
    /* "case/processor*" (quoted in a shell): the pieces, whatever else the case holds */
    const char *base = path + l;
    while (base > path && base[-1] != '/') --base;
    if ((size_t)(path + l - base) == 10 && !memcmp(base, "processor*", 10)) {
        size_t k = (size_t)(base - path);
        while (k > 1 && path[k - 1] == '/') --k;
        if (k == 0) {
            strcpy(c, ".");
        } else {
            memcpy(c, path, k);
            c[k] = '\0';
        }
        return (*case_dir = strdup(c)) != NULL;
    }
    memcpy(c, path, l);
    c[l] = '\0';
    char *pm = cm_foam_polymesh_dir(path);
    int pieces = 0;
    if (pm && ends_with(pm, strlen(pm), "/constant/polyMesh") && !is_dir(pm)) {
        char p0[4200];
        snprintf(p0, sizeof p0, "%s/processor0/constant/polyMesh", c);
        pieces = is_dir(p0);
    }
    free(pm);
    if (pieces) *case_dir = strdup(c);
    return *case_dir != NULL;
}

char *cm_foam_case_of(const char *dir)
{
    size_t l = strlen(dir);
    while (l > 1 && dir[l - 1] == '/') --l;
    static const char tail[] = "constant/polyMesh";
    if (!ends_with(dir, l, tail)) return NULL;
    size_t k = l - (sizeof tail - 1);
    if (k > 0 && dir[k - 1] != '/') return NULL;
    if (k > 1) --k; /* the '/' before constant */
    char *c = malloc(k + 2);
    if (!c) return NULL;
    if (k == 0) {
        strcpy(c, ".");
    } else {
        memcpy(c, dir, k);
        c[k] = '\0';
    }
    return c;
}

int cm_foam_write_precision(const char *case_dir)
{
    char path[4200];
    if (cm_foam_join(path, sizeof path, case_dir, "system/controlDict", NULL)) return 0;
    FILE *in = fopen(path, "rb");
    if (!in) {
        /* one piece of a decomposed case read alone: the case's controlDict */
        size_t l = strlen(case_dir);
        while (l > 1 && case_dir[l - 1] == '/') --l;
        size_t b = l;
        while (b > 0 && case_dir[b - 1] >= '0' && case_dir[b - 1] <= '9') --b;
        if (b == l || b < 9 || strncmp(case_dir + b - 9, "processor", 9) || (b > 9 && case_dir[b - 10] != '/'))
            return 0;
        size_t k = b - 9;
        int n = snprintf(path, sizeof path, "%.*ssystem/controlDict", (int)k, k ? case_dir : "");
        if (n < 0 || (size_t)n >= sizeof path || !(in = fopen(path, "rb"))) return 0;
    }
    cm_foam_file f;
    memset(&f, 0, sizeof f);
    f.path = path;
    size_t cap = 1 << 14;
    f.data = malloc(cap);
    while (f.data) {
        f.size += fread(f.data + f.size, 1, cap - f.size, in);
        if (f.size < cap) break;
        char *g = cap < (1u << 26) ? realloc(f.data, 2 * cap) : NULL;
        if (!g) free(f.data);
        f.data = g;
        cap *= 2;
    }
    fclose(in);
    if (!f.data) return 0;
    /* the top-level entry "writePrecision N;" (sub-dictionaries such as FoamFile skipped) */
    cm_foam_lex lx;
    cm_foam_lex_init(&lx, &f, 0);
    int depth = 0, p = 0;
    for (;;) {
        cm_foam_tok t = cm_foam_next(&lx);
        if (t.kind == CM_FOAM_EOF) break;
        if (t.kind == CM_FOAM_PUNCT) {
            if (t.s[0] == '{' || t.s[0] == '(') ++depth;
            if ((t.s[0] == '}' || t.s[0] == ')') && depth > 0) --depth;
            continue;
        }
        if (depth == 0 && t.kind == CM_FOAM_WORD && t.len == 14 && !memcmp(t.s, "writePrecision", 14)) {
            cm_foam_tok v = cm_foam_next(&lx);
            char b[16];
            if (v.kind == CM_FOAM_WORD && v.len < sizeof b) {
                memcpy(b, v.s, v.len);
                b[v.len] = '\0';
                char *end;
                long x = strtol(b, &end, 10);
                /* a double has at most 17 significant digits */
                if (!*end && x > 0) p = x > 17 ? 17 : (int)x;
            }
        }
    }
    free(f.data);
    return p;
}

/* The absolute path of p with symbolic links resolved, p's missing tail kept as written. */
static int resolve(const char *p, char *out)
{
    char buf[PATH_MAX];
    size_t l = strlen(p);
    while (l > 1 && p[l - 1] == '/') --l;
    if (l >= sizeof buf) return 0;
    memcpy(buf, p, l);
    buf[l] = '\0';
    if (realpath(buf, out)) return 1;
    char *slash = strrchr(buf, '/');
    const char *tail = slash ? slash + 1 : buf;
    char parent[PATH_MAX];
    if (!slash) strcpy(parent, ".");
    else if (slash == buf) strcpy(parent, "/");
    else {
        *slash = '\0';
        strcpy(parent, buf);
    }
    char rp[PATH_MAX];
    if (!resolve(parent, rp)) return 0;
    size_t a = strlen(rp), t = strlen(tail), sep = strcmp(rp, "/") != 0;
    if (a + sep + t + 1 > PATH_MAX) return 0;
    memcpy(out, rp, a);
    if (sep) out[a] = '/';
    memcpy(out + a + sep, tail, t + 1);
    return 1;
}

int cm_foam_nested(const char *a, const char *b)
{
    char ra[PATH_MAX], rb[PATH_MAX];
    if (!resolve(a, ra) || !resolve(b, rb)) return 0;
    size_t la = strlen(ra), lb = strlen(rb);
    size_t m = la < lb ? la : lb;
    if (memcmp(ra, rb, m)) return 0;
    if (la == lb) return 1;
    const char *longer = la > lb ? ra : rb;
    return m == 1 || longer[m] == '/'; /* "/" holds everything */
}

cm_status cm_foam_copy_file(cm_context *ctx, const char *src, const char *dst)
{
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
    return cm_outfile_commit(ctx, &out);
}

static cm_status copy_rec(cm_context *ctx, const char *src, const char *dst, char *rel, size_t rl,
                          int (*skip)(const char *, void *), void *arg)
{
    char s_dir[4200], d_dir[4200];
    if (snprintf(s_dir, sizeof s_dir, "%s%s%s", src, rl ? "/" : "", rel) >= (int)sizeof s_dir ||
        snprintf(d_dir, sizeof d_dir, "%s%s%s", dst, rl ? "/" : "", rel) >= (int)sizeof d_dir)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s: path too long", dst);
    if (mkdir(d_dir, 0777) != 0 && errno != EEXIST)
        return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot create the directory: %s", d_dir, strerror(errno));
    DIR *d = opendir(s_dir);
    if (!d) return cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot list: %s", s_dir, strerror(errno));
    cm_status s = CM_OK;
    struct dirent *e;
    while (s == CM_OK && (e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
        size_t nl = strlen(e->d_name);
        if (rl + nl + 2 > 2048) {
            s = cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write: %s/%s: path too long", s_dir, e->d_name);
            break;
        }
        if (rl) rel[rl] = '/';
        memcpy(rel + rl + (rl ? 1 : 0), e->d_name, nl + 1);
        size_t nrl = rl + (rl ? 1 : 0) + nl;
        char sp[4200], dp[4200];
        struct stat st;
        snprintf(sp, sizeof sp, "%s/%s", src, rel);
        snprintf(dp, sizeof dp, "%s/%s", dst, rel);
        if (!(skip && skip(rel, arg)) && stat(sp, &st) == 0) {
            if (S_ISDIR(st.st_mode)) s = copy_rec(ctx, src, dst, rel, nrl, skip, arg);
            else if (S_ISREG(st.st_mode)) s = cm_foam_copy_file(ctx, sp, dp);
        }
        rel[rl] = '\0';
    }
    closedir(d);
    return s;
}

cm_status cm_foam_copy_tree(cm_context *ctx, const char *src, const char *dst,
                            int (*skip)(const char *rel, void *arg), void *arg)
{
    char rel[2048] = "";
    return copy_rec(ctx, src, dst, rel, 0, skip, arg);
}

static int is_dir_path(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

cm_status cm_mesh_read_foam(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    *mesh = NULL;
    char *case_dir = NULL;
    int decomposed = cm_foam_decomposed_path(path, &case_dir);
    char *dir = decomposed ? NULL : cm_foam_polymesh_dir(path);
    cm_foam_poly *p = cm_foam_poly_new();
    cm_status s = CM_OK;
    if (!p || (!decomposed && !dir)) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    } else if (decomposed) {
        s = cm_foam_read_decomposed(ctx, case_dir, p);
        if (!(p->case_dir = strdup(case_dir))) s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: out of memory");
    } else if (!is_dir_path(dir)) {
        s = cm_error(ctx, CM_ERR_IO, "cm_mesh_read: %s: no polyMesh directory %s", path, dir);
    } else {
        s = cm_foam_read_poly(ctx, dir, p);
        p->case_dir = cm_foam_case_of(dir);
    }
    /* OpenFOAM's mesh utilities (blockMesh, snappyHexMesh) write points at writePrecision but
     * at least 10 digits: at 6, a wedge's points leave their plane by more than checkMesh's
     * wedge check allows (docs/DESIGN.md, the OpenFOAM row of the format table) */
    if (s == CM_OK && p->case_dir) {
        const int wp = cm_foam_write_precision(p->case_dir);
        p->write_precision = wp > 0 && wp < 10 ? 10 : wp;
    }
    if (s == CM_OK) s = cm_foam_mesh_of_poly(ctx, p, decomposed ? case_dir : dir, mesh);
    else cm_foam_poly_release(&p);
    free(case_dir);
    free(dir);
    return s == CM_OK || s < 0 ? s : CM_ERR_FORMAT;
}
