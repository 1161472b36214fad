/* Exodus II (.exo, .e, .ex2, .g): read through SEACAS's library (Debian libexodusii-dev) on
 * netCDF, classic or netCDF-4/HDF5. Element blocks become cells with a group per block
 * (its name, else "block <id>"), node sets CM_CELL_POINT cells with a group per set, side sets
 * the faces (edges in a 2-D file) they name with a group per set; node and element number maps
 * become node_tag and cell_tag. A mesh read from Exodus and written to an Exodus path is
 * written back: the file is copied and only its coordinate variables are replaced (in the
 * file's own float word size), so every other variable and attribute stays (docs/DESIGN.md,
 * "Writing back into the file a mesh came from"). Any other mesh is refused: writing a new
 * Exodus file is not implemented.
 *
 * Node order: Exodus numbers quadratic hexahedra and wedges differently from VTK (mid-edge
 * nodes of the top face before the vertical edges; face centres of HEX27 in another order),
 * and winds a wedge's first triangle towards the second (as gmsh does, the mirror of VTK's
 * wedge: msh_common.c). Side numbering follows the Exodus II manual's side tables (the
 * tables ex_get_side_set_node_list uses), outward for an element of positive volume. */
#define _POSIX_C_SOURCE 200809L
#include "formats.h"
#include "netcdf_header.h"
#include "rewrite.h"

#include <exodusII.h>

#include <dlfcn.h>

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* The library is opened (dlopen) when an Exodus file is first read or written, not linked:
 * with its MPI build of netCDF it brings OpenMPI, HDF5, libxml2 and ICU, whose address space
 * every run of cadmorph would otherwise map (tests/cli/ulimit.sh runs under ulimit -v). The
 * netCDF calls are looked up through it, so they reach the netCDF the library itself uses. */
#define EXO_FUNCTIONS(X)                                                                         \
    X(ex_open_int) X(ex_close) X(ex_get_err) X(ex_opts) X(ex_set_int64_status) X(ex_get_init_ext) \
    X(ex_set_max_name_length) X(ex_get_coord) X(ex_get_id_map) X(ex_get_ids) X(ex_get_names)    \
    X(ex_get_block) X(ex_get_conn) X(ex_get_set_param) X(ex_get_set) X(nc_inq_varid)            \
    X(nc_inq_varndims) X(nc_inq_vardimid) X(nc_inq_dimlen) X(nc_open) X(nc_inq_dimid)           \
    X(nc_put_var_double) X(nc_put_vara_double) X(nc_close) X(nc_strerror)
#define EXO_POINTER(f) __typeof__(&f) f;
static struct { EXO_FUNCTIONS(EXO_POINTER) } exo_fn;
static pthread_once_t exo_once = PTHREAD_ONCE_INIT;
static char exo_load_error[512];

static void exo_load_once(void)
{
    void *h = dlopen(CM_EXODUS_SONAME, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *e = dlerror();
        snprintf(exo_load_error, sizeof exo_load_error, "%s", e ? e : CM_EXODUS_SONAME);
        return;
    }
#define EXO_LOOKUP(f)                                                                            \
    if (!exo_load_error[0] && !(*(void **)(&exo_fn.f) = dlsym(h, #f)))                            \
        snprintf(exo_load_error, sizeof exo_load_error, "%s: no symbol %s", CM_EXODUS_SONAME, #f);
    EXO_FUNCTIONS(EXO_LOOKUP)
#undef EXO_LOOKUP
}

static cm_status exo_load(cm_context *ctx, const char *fn, const char *path)
{
    pthread_once(&exo_once, exo_load_once);
    if (!exo_load_error[0]) return CM_OK;
    return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: %s: cannot load the Exodus II library: %s", fn,
                    path, exo_load_error);
}

#define ex_open_int(...) exo_fn.ex_open_int(__VA_ARGS__)
#define ex_close(...) exo_fn.ex_close(__VA_ARGS__)
#define ex_get_err(...) exo_fn.ex_get_err(__VA_ARGS__)
#define ex_opts(...) exo_fn.ex_opts(__VA_ARGS__)
#define ex_set_int64_status(...) exo_fn.ex_set_int64_status(__VA_ARGS__)
#define ex_get_init_ext(...) exo_fn.ex_get_init_ext(__VA_ARGS__)
#define ex_set_max_name_length(...) exo_fn.ex_set_max_name_length(__VA_ARGS__)
#define ex_get_coord(...) exo_fn.ex_get_coord(__VA_ARGS__)
#define ex_get_id_map(...) exo_fn.ex_get_id_map(__VA_ARGS__)
#define ex_get_ids(...) exo_fn.ex_get_ids(__VA_ARGS__)
#define ex_get_names(...) exo_fn.ex_get_names(__VA_ARGS__)
#define ex_get_block(...) exo_fn.ex_get_block(__VA_ARGS__)
#define ex_get_conn(...) exo_fn.ex_get_conn(__VA_ARGS__)
#define ex_get_set_param(...) exo_fn.ex_get_set_param(__VA_ARGS__)
#define ex_get_set(...) exo_fn.ex_get_set(__VA_ARGS__)
#define nc_inq_varid(...) exo_fn.nc_inq_varid(__VA_ARGS__)
#define nc_inq_varndims(...) exo_fn.nc_inq_varndims(__VA_ARGS__)
#define nc_inq_vardimid(...) exo_fn.nc_inq_vardimid(__VA_ARGS__)
#define nc_inq_dimlen(...) exo_fn.nc_inq_dimlen(__VA_ARGS__)
#define nc_open(...) exo_fn.nc_open(__VA_ARGS__)
#define nc_inq_dimid(...) exo_fn.nc_inq_dimid(__VA_ARGS__)
#define nc_put_var_double(...) exo_fn.nc_put_var_double(__VA_ARGS__)
#define nc_put_vara_double(...) exo_fn.nc_put_vara_double(__VA_ARGS__)
#define nc_close(...) exo_fn.nc_close(__VA_ARGS__)
#define nc_strerror(...) exo_fn.nc_strerror(__VA_ARGS__)

/* The library keeps its open files, options and last error in globals: one call at a time. */
static pthread_mutex_t exo_lock = PTHREAD_MUTEX_INITIALIZER;

/* What a write back needs: the file and what it held when read. */
typedef struct exo_state {
    char *path;
    int64_t num_dim, num_nodes, num_elem;
    cm_file_stamp stamp;
} exo_state;

static void exo_state_free(void *p)
{
    exo_state *st = p;
    if (st) free(st->path);
    free(st);
}

/* Why the last library call failed: the library's own message, on one line (called under
 * exo_lock, and copied by cm_error at once). */
static const char *exo_reason(int rc)
{
    static char line[256];
    const char *msg = NULL, *func = NULL;
    int code = 0;
    ex_get_err(&msg, &func, &code);
    (void)rc;
    snprintf(line, sizeof line, "%s", msg && *msg ? msg : "the Exodus II library reports an error");
    for (char *p = line; *p; ++p)
        if (*p == '\n' || *p == '\r') *p = ' ';
    return line;
}

/* ---- element types ---- */

typedef struct exo_type {
    cm_cell_type type;
    const int *perm;   /* VTK node i is Exodus node perm[i]; NULL: the same order */
    int dim;           /* of the element */
    int shell;         /* a 2-D element in 3-D space whose sides 1 and 2 are its faces */
} exo_type;

static const int perm_hex20[20] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11,
                                   16, 17, 18, 19, 12, 13, 14, 15};
static const int perm_hex27[27] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 16, 17,
                                   18, 19, 12, 13, 14, 15, 23, 24, 25, 26, 21, 22, 20};
static const int perm_wedge6[6] = {0, 2, 1, 3, 5, 4};
static const int perm_wedge15[15] = {0, 2, 1, 3, 5, 4, 8, 7, 6, 14, 13, 12, 9, 11, 10};

static int starts(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

/* The cell type of an Exodus topology name with n nodes per element; 0 when unknown. */
static int exo_type_of(const char *topology, int64_t n, int num_dim, exo_type *t)
{
    char up[MAX_STR_LENGTH + 1];
    size_t l = 0;
    for (; topology[l] && l < MAX_STR_LENGTH; ++l) up[l] = (char)toupper((unsigned char)topology[l]);
    up[l] = '\0';
    memset(t, 0, sizeof *t);
    t->type = CM_CELL_TYPE_COUNT;
    if (starts(up, "TET")) {
        t->dim = 3;
        t->type = n == 4 ? CM_CELL_TET4 : n == 10 ? CM_CELL_TET10 : CM_CELL_TYPE_COUNT;
    } else if (starts(up, "HEX")) {
        t->dim = 3;
        if (n == 8) t->type = CM_CELL_HEX8;
        if (n == 20) t->type = CM_CELL_HEX20, t->perm = perm_hex20;
        if (n == 27) t->type = CM_CELL_HEX27, t->perm = perm_hex27;
    } else if (starts(up, "WEDGE")) {
        t->dim = 3;
        if (n == 6) t->type = CM_CELL_WEDGE6, t->perm = perm_wedge6;
        if (n == 15) t->type = CM_CELL_WEDGE15, t->perm = perm_wedge15;
    } else if (starts(up, "PYRA")) {
        t->dim = 3;
        t->type = n == 5 ? CM_CELL_PYR5 : n == 13 ? CM_CELL_PYR13 : CM_CELL_TYPE_COUNT;
    } else if (starts(up, "TRI")) {
        t->dim = 2;
        t->shell = num_dim == 3;
        t->type = n == 3 ? CM_CELL_TRI3 : n == 6 ? CM_CELL_TRI6 : CM_CELL_TYPE_COUNT;
    } else if (starts(up, "QUAD") || starts(up, "SHELL")) {
        t->dim = 2;
        t->shell = num_dim == 3;
        t->type = n == 4 ? CM_CELL_QUAD4 : n == 8 ? CM_CELL_QUAD8 : n == 9 ? CM_CELL_QUAD9
                                                                          : CM_CELL_TYPE_COUNT;
    } else if (starts(up, "BAR") || starts(up, "BEAM") || starts(up, "TRUSS") || starts(up, "EDGE")) {
        t->dim = 1;
        t->type = n == 2 ? CM_CELL_LINE2 : n == 3 ? CM_CELL_LINE3 : CM_CELL_TYPE_COUNT;
    } else if (starts(up, "SPHERE") || starts(up, "CIRCLE")) {
        t->type = n == 1 ? CM_CELL_POINT : CM_CELL_TYPE_COUNT;
    }
    return t->type != CM_CELL_TYPE_COUNT;
}

/* Side tables of the Exodus II manual, 0-based local Exodus node numbers: corners (outward),
 * then the mid-edge nodes in the same cycle, then the face centre (HEX27). */
static const int tet_sides[4][7] = {
    {0, 1, 3, 4, 8, 7}, {1, 2, 3, 5, 9, 8}, {0, 3, 2, 7, 9, 6}, {0, 2, 1, 6, 5, 4}};
static const int hex_sides[6][9] = {
    {0, 1, 5, 4, 8, 13, 16, 12, 25}, {1, 2, 6, 5, 9, 14, 17, 13, 24},
    {2, 3, 7, 6, 10, 15, 18, 14, 26}, {0, 4, 7, 3, 12, 19, 15, 11, 23},
    {0, 3, 2, 1, 11, 10, 9, 8, 21},  {4, 5, 6, 7, 16, 17, 18, 19, 22}};
static const int wedge_sides[5][8] = {
    {0, 1, 4, 3, 6, 10, 12, 9}, {1, 2, 5, 4, 7, 11, 13, 10}, {0, 3, 5, 2, 9, 14, 11, 8},
    {0, 2, 1, 8, 7, 6}, {3, 4, 5, 12, 13, 14}};
static const int wedge_side_corners[5] = {4, 4, 4, 3, 3};
static const int pyr_sides[5][8] = {
    {0, 1, 4, 5, 10, 9}, {1, 2, 4, 6, 11, 10}, {2, 3, 4, 7, 12, 11}, {0, 4, 3, 9, 12, 8},
    {0, 3, 2, 1, 8, 7, 6, 5}};
static const int pyr_side_corners[5] = {3, 3, 3, 3, 4};

/* The face (or edge) of side `side` (1-based) of an element of type t whose nodes are exo (in
 * Exodus order): its cell type and nodes; 0 when the side does not exist. */
static int exo_side(const exo_type *t, const int64_t *exo, int64_t side, cm_cell_type *type,
                    int64_t *nodes, int *n)
{
    const cm_cell_info *info = cm_cell_type_info(t->type);
    const int quadratic = info->nodes > info->corners;
    const int *row = NULL;
    int corners = 0;
    const int64_t s = side - 1;
    switch (info->linear) {
    case CM_CELL_TET4:
        if (s < 0 || s >= 4) return 0;
        row = tet_sides[s], corners = 3;
        break;
    case CM_CELL_HEX8:
        if (s < 0 || s >= 6) return 0;
        row = hex_sides[s], corners = 4;
        break;
    case CM_CELL_WEDGE6:
        if (s < 0 || s >= 5) return 0;
        row = wedge_sides[s], corners = wedge_side_corners[s];
        break;
    case CM_CELL_PYR5:
        if (s < 0 || s >= 5) return 0;
        row = pyr_sides[s], corners = pyr_side_corners[s];
        break;
    case CM_CELL_TRI3:
    case CM_CELL_QUAD4: {
        const int c = info->corners;
        int64_t e = s; /* an edge; a shell's sides 1 and 2 are its two faces */
        if (t->shell) {
            if (s == 0 || s == 1) {
                *type = t->type;
                *n = info->nodes;
                for (int i = 0; i < info->nodes; ++i) nodes[i] = exo[i];
                if (s == 1) { /* the back face: the same nodes wound the other way */
                    for (int i = 1; i < c - i; ++i) {
                        int64_t x = nodes[i];
                        nodes[i] = nodes[c - i], nodes[c - i] = x;
                    }
                    for (int i = 0; quadratic && i < c / 2; ++i) { /* edge i <-> edge c-1-i */
                        int64_t x = nodes[c + i];
                        nodes[c + i] = nodes[2 * c - 1 - i], nodes[2 * c - 1 - i] = x;
                    }
                }
                return 1;
            }
            e = s - 2;
        }
        if (e < 0 || e >= c) return 0;
        nodes[0] = exo[e];
        nodes[1] = exo[(e + 1) % c];
        *n = 2;
        if (quadratic) nodes[(*n)++] = exo[c + e];
        *type = quadratic ? CM_CELL_LINE3 : CM_CELL_LINE2;
        return 1;
    }
    default: return 0;
    }
    int k = corners;
    if (quadratic) k = 2 * corners + (t->type == CM_CELL_HEX27 && corners == 4);
    for (int i = 0; i < k; ++i) nodes[i] = exo[row[i]];
    *n = k;
    if (corners == 3) *type = quadratic ? CM_CELL_TRI6 : CM_CELL_TRI3;
    else *type = !quadratic ? CM_CELL_QUAD4 : k == 9 ? CM_CELL_QUAD9 : CM_CELL_QUAD8;
    return 1;
}

/* ---- the reader ---- */

typedef struct exo_block {
    exo_type t;
    int64_t first, count; /* its elements: Exodus element numbers first+1 .. first+count */
} exo_block;

typedef struct exo_reader {
    cm_context *ctx;
    const char *path;
    int exoid;
    ex_init_params par;
    cm_mesh *m;
    exo_block *blocks;
    int next_tag;      /* the next group tag */
    int64_t next_id;   /* the next cell id for set cells (after every element id) */
    char name[256];
} exo_reader;

/* Largest count taken from a file (entries of one array). */
#define EXO_MAX_COUNT ((int64_t)1 << 40)

/* Whether the netCDF variable `name`, if the file has one, holds exactly `want` values. The
 * library reads whole variables into arrays sized by the entity's own dimensions, so a hostile
 * file that declares a variable over other dimensions would overrun them (an Exodus id is the
 * file's netCDF id). */
static cm_status check_var(exo_reader *r, const char *name, int64_t want, const char *what)
{
    int var = -1, nd = 0;
    if (nc_inq_varid(r->exoid, name, &var) != NC_NOERR) return CM_OK;
    int dims[NC_MAX_VAR_DIMS];
    uint64_t total = 1;
    int ok = nc_inq_varndims(r->exoid, var, &nd) == NC_NOERR && nd >= 0 && nd <= NC_MAX_VAR_DIMS &&
             nc_inq_vardimid(r->exoid, var, dims) == NC_NOERR;
    for (int i = 0; ok && i < nd; ++i) {
        size_t len = 0;
        ok = nc_inq_dimlen(r->exoid, dims[i], &len) == NC_NOERR && (len == 0 || total <= UINT64_MAX / len);
        total *= len;
    }
    if (!ok || total != (uint64_t)want)
        return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %s: variable %s holds %llu values, "
                        "expected %lld", r->path, what, name, (unsigned long long)total, (long long)want);
    return CM_OK;
}

static int compare_id(const void *a, const void *b)
{
    const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* ids and names of the entities of one kind; names[i] is "" where the file has none. */
static cm_status entity_list(exo_reader *r, ex_entity_type kind, const char *what, int64_t n,
                             int64_t **ids, char ***names)
{
    *ids = NULL;
    *names = NULL;
    if (n <= 0) return CM_OK;
    *ids = calloc((size_t)n, sizeof **ids);
    *names = calloc((size_t)n, sizeof **names);
    char *buf = calloc((size_t)n, 256);
    if (!*ids || !*names || !buf) {
        free(buf);
        return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for %lld %ss",
                        r->path, (long long)n, what);
    }
    for (int64_t i = 0; i < n; ++i) (*names)[i] = buf + 256 * i;
    const char *prop = kind == EX_ELEM_BLOCK ? "eb_prop1" : kind == EX_NODE_SET ? "ns_prop1" : "ss_prop1";
    cm_status s = check_var(r, prop, n, what);
    if (s != CM_OK) return s;
    int rc = ex_get_ids(r->exoid, kind, *ids);
    if (rc < 0)
        return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: cannot read the %s ids: %s",
                        r->path, what, exo_reason(rc));
    /* the library finds an entity's variables by its id: two with one id would mix them up */
    int64_t *sorted = malloc((size_t)n * sizeof *sorted);
    if (!sorted) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
    memcpy(sorted, *ids, (size_t)n * sizeof *sorted);
    qsort(sorted, (size_t)n, sizeof *sorted, compare_id);
    for (int64_t i = 1; s == CM_OK && i < n; ++i)
        if (sorted[i] == sorted[i - 1])
            s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: two %ss have the id %lld", r->path,
                         what, (long long)sorted[i]);
    free(sorted);
    if (s != CM_OK) return s;
    rc = ex_get_names(r->exoid, kind, *names);
    if (rc < 0)
        for (int64_t i = 0; i < n; ++i) (*names)[i][0] = '\0';
    for (int64_t i = 0; i < n; ++i) (*names)[i][255] = '\0';
    return CM_OK;
}

static void entity_list_free(int64_t *ids, char **names)
{
    free(ids);
    if (names) free(names[0]);
    free(names);
}

/* The group name of an entity: its name in the file, else "<what> <id>". */
static const char *group_name(exo_reader *r, const char *name, const char *what, int64_t id)
{
    size_t l = strlen(name);
    while (l && name[l - 1] == ' ') --l;
    if (l) snprintf(r->name, sizeof r->name, "%.*s", (int)l, name);
    else snprintf(r->name, sizeof r->name, "%s %lld", what, (long long)id);
    return r->name;
}

static cm_status read_nodes(exo_reader *r)
{
    const int64_t n = r->par.num_nodes;
    cm_status s = cm_mesh_resize_nodes(r->ctx, r->m, (size_t)n, 0);
    if (s != CM_OK || n == 0) return s;
    double *c = malloc((size_t)n * 3 * sizeof *c);
    if (!c) return cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for %lld nodes",
                            r->path, (long long)n);
    for (int64_t i = 0; i < 3 * n; ++i) c[i] = 0.0;
    static const char *const names[3] = {"coordx", "coordy", "coordz"};
    for (int k = 0; s == CM_OK && k < r->par.num_dim; ++k) s = check_var(r, names[k], n, "coordinates");
    if (s == CM_OK) s = check_var(r, "coord", n * r->par.num_dim, "coordinates");
    if (s == CM_OK) s = check_var(r, "node_num_map", n, "node number map");
    if (s != CM_OK) {
        free(c);
        return s;
    }
    int rc = ex_get_coord(r->exoid, c, c + n, r->par.num_dim == 3 ? c + 2 * n : NULL);
    if (rc < 0) {
        free(c);
        return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: cannot read the coordinates: %s",
                        r->path, exo_reason(rc));
    }
    for (int64_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) r->m->xyz[3 * i + k] = c[k * n + i];
    /* the node number map, kept where it is not 1..n */
    int64_t *map = (int64_t *)(void *)c; /* n int64 fit in 3n doubles */
    rc = ex_get_id_map(r->exoid, EX_NODE_MAP, map);
    int identity = 1;
    for (int64_t i = 0; rc >= 0 && i < n; ++i) identity &= map[i] == i + 1;
    if (rc >= 0 && !identity) {
        s = cm_mesh_resize_nodes(r->ctx, r->m, (size_t)n, 1);
        for (int64_t i = 0; s == CM_OK && i < n; ++i) r->m->node_tag[i] = map[i];
    }
    free(c);
    return s;
}

static cm_status read_blocks(exo_reader *r, int64_t *elem_map)
{
    const int64_t nb = r->par.num_elem_blk;
    int64_t *ids;
    char **names;
    cm_status s = entity_list(r, EX_ELEM_BLOCK, "element block", nb, &ids, &names);
    if (s != CM_OK) goto done;
    r->blocks = calloc((size_t)(nb > 0 ? nb : 1), sizeof *r->blocks);
    if (!r->blocks) {
        s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", r->path);
        goto done;
    }
    int64_t first = 0;
    int64_t *conn = NULL;
    for (int64_t b = 0; s == CM_OK && b < nb; ++b) {
        char topology[MAX_STR_LENGTH + 1] = "";
        int64_t n_el = 0, n_per = 0, n_edge = 0, n_face = 0, n_attr = 0;
        const char *gname = group_name(r, names[b], "block", ids[b]);
        int rc = ex_get_block(r->exoid, EX_ELEM_BLOCK, ids[b], topology, &n_el, &n_per, &n_edge,
                              &n_face, &n_attr);
        topology[MAX_STR_LENGTH] = '\0';
        if (rc < 0) {
            s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: element block \"%s\": %s",
                         r->path, gname, exo_reason(rc));
            break;
        }
        if (n_el < 0 || n_el > r->par.num_elem - first || n_per < 0 || n_per > 64) {
            s = cm_error(r->ctx, CM_ERR_FORMAT,
                         "cm_mesh_read: %s: element block \"%s\": %lld elements of %lld nodes "
                         "(the file has %lld elements in all, %lld before this block)",
                         r->path, gname, (long long)n_el, (long long)n_per,
                         (long long)r->par.num_elem, (long long)first);
            break;
        }
        exo_block *blk = &r->blocks[b];
        blk->first = first;
        blk->count = n_el;
        if (n_el == 0) continue;
        if (!exo_type_of(topology, n_per, (int)r->par.num_dim, &blk->t)) {
            s = cm_error(r->ctx, CM_ERR_UNSUPPORTED,
                         "cm_mesh_read: %s: element block \"%s\": element type %s with %lld "
                         "nodes is not supported", r->path, gname, topology, (long long)n_per);
            break;
        }
        const int tag = r->next_tag++;
        if ((s = cm_mesh_add_group(r->ctx, r->m, blk->t.dim, tag, gname)) != CM_OK) break;
        conn = malloc((size_t)(n_el * n_per) * sizeof *conn);
        if (!conn) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: element block \"%s\": out of memory",
                         r->path, gname);
            break;
        }
        char var[32];
        snprintf(var, sizeof var, "connect%lld", (long long)(b + 1));
        if ((s = check_var(r, var, n_el * n_per, "element block")) != CM_OK) break;
        rc = ex_get_conn(r->exoid, EX_ELEM_BLOCK, ids[b], conn, NULL, NULL);
        if (rc < 0) {
            s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: element block \"%s\": cannot read "
                         "the connectivity: %s", r->path, gname, exo_reason(rc));
            break;
        }
        s = cm_mesh_reserve_cells(r->ctx, r->m, (size_t)n_el, (size_t)(n_el * n_per));
        for (int64_t e = 0; s == CM_OK && e < n_el; ++e) {
            int64_t v[64];
            const int64_t *x = conn + e * n_per;
            for (int64_t i = 0; i < n_per; ++i) {
                const int64_t k = blk->t.perm ? x[blk->t.perm[i]] : x[i];
                if (k < 1 || k > r->par.num_nodes) {
                    s = cm_error(r->ctx, CM_ERR_FORMAT,
                                 "cm_mesh_read: %s: element block \"%s\": element %lld: node %lld "
                                 "out of range 1..%lld", r->path, gname, (long long)(e + 1),
                                 (long long)k, (long long)r->par.num_nodes);
                    break;
                }
                v[i] = k - 1;
            }
            if (s == CM_OK)
                s = cm_mesh_add_cell(r->ctx, r->m, blk->t.type, v, (size_t)n_per, tag, tag,
                                     elem_map ? elem_map[first + e] : 0);
        }
        free(conn);
        conn = NULL;
        first += n_el;
    }
    free(conn);
    if (s == CM_OK && first != r->par.num_elem)
        s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: the element blocks hold %lld "
                     "elements, the file says %lld", r->path, (long long)first,
                     (long long)r->par.num_elem);
done:
    entity_list_free(ids, names);
    return s;
}

/* The entry count of set id (kind: node or side set, what: its name in messages). */
static cm_status set_size(exo_reader *r, ex_entity_type kind, const char *what, int64_t id,
                          const char *gname, int64_t *n)
{
    int64_t n_df = 0;
    *n = 0;
    const int rc = ex_get_set_param(r->exoid, kind, id, n, &n_df);
    if (rc < 0 || *n < 0 || *n > EXO_MAX_COUNT)
        return cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: %s \"%s\": %s", r->path, what, gname,
                        rc < 0 ? exo_reason(rc) : "bad entry count");
    return CM_OK;
}

static cm_status read_node_sets(exo_reader *r)
{
    const int64_t ns = r->par.num_node_sets;
    int64_t *ids;
    char **names;
    cm_status s = entity_list(r, EX_NODE_SET, "node set", ns, &ids, &names);
    for (int64_t k = 0; s == CM_OK && k < ns; ++k) {
        int64_t n = 0;
        const char *gname = group_name(r, names[k], "nodeset", ids[k]);
        if ((s = set_size(r, EX_NODE_SET, "node set", ids[k], gname, &n)) != CM_OK) break;
        const int tag = r->next_tag++;
        if ((s = cm_mesh_add_group(r->ctx, r->m, 0, tag, gname)) != CM_OK || n == 0) continue;
        int64_t *list = malloc((size_t)n * sizeof *list);
        if (!list) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: node set \"%s\": out of memory",
                         r->path, gname);
            break;
        }
        char var[32];
        snprintf(var, sizeof var, "node_ns%lld", (long long)(k + 1));
        s = check_var(r, var, n, "node set");
        const int rc = s == CM_OK ? ex_get_set(r->exoid, EX_NODE_SET, ids[k], list, NULL) : 0;
        if (rc < 0)
            s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: node set \"%s\": %s", r->path,
                         gname, exo_reason(rc));
        for (int64_t i = 0; s == CM_OK && i < n; ++i) {
            if (list[i] < 1 || list[i] > r->par.num_nodes) {
                s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: node set \"%s\": entry %lld: "
                             "node %lld out of range 1..%lld", r->path, gname, (long long)(i + 1),
                             (long long)list[i], (long long)r->par.num_nodes);
                break;
            }
            const int64_t v = list[i] - 1;
            s = cm_mesh_add_cell(r->ctx, r->m, CM_CELL_POINT, &v, 1, tag, tag, r->next_id++);
        }
        free(list);
    }
    entity_list_free(ids, names);
    return s;
}

/* The block of Exodus element e (0-based). */
static const exo_block *block_of(const exo_reader *r, int64_t e)
{
    int64_t lo = 0, hi = r->par.num_elem_blk - 1;
    while (lo < hi) {
        const int64_t mid = (lo + hi + 1) / 2;
        if (r->blocks[mid].first <= e) lo = mid;
        else hi = mid - 1;
    }
    return &r->blocks[lo];
}

static cm_status read_side_sets(exo_reader *r)
{
    const int64_t ns = r->par.num_side_sets;
    int64_t *ids;
    char **names;
    cm_status s = entity_list(r, EX_SIDE_SET, "side set", ns, &ids, &names);
    for (int64_t k = 0; s == CM_OK && k < ns; ++k) {
        int64_t n = 0;
        const char *gname = group_name(r, names[k], "sideset", ids[k]);
        if ((s = set_size(r, EX_SIDE_SET, "side set", ids[k], gname, &n)) != CM_OK) break;
        const int tag = r->next_tag++;
        if (n == 0) {
            s = cm_mesh_add_group(r->ctx, r->m, (int)r->par.num_dim - 1, tag, gname);
            continue;
        }
        int64_t *elem = malloc(2 * (size_t)n * sizeof *elem);
        if (!elem) {
            s = cm_error(r->ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: side set \"%s\": out of memory",
                         r->path, gname);
            break;
        }
        int64_t *side = elem + n;
        char var[32];
        snprintf(var, sizeof var, "elem_ss%lld", (long long)(k + 1));
        s = check_var(r, var, n, "side set");
        snprintf(var, sizeof var, "side_ss%lld", (long long)(k + 1));
        if (s == CM_OK) s = check_var(r, var, n, "side set");
        const int rc = s == CM_OK ? ex_get_set(r->exoid, EX_SIDE_SET, ids[k], elem, side) : 0;
        if (rc < 0)
            s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: side set \"%s\": %s", r->path,
                         gname, exo_reason(rc));
        int dims = 0; /* bit d: the set has cells of dimension d */
        for (int64_t i = 0; s == CM_OK && i < n; ++i) {
            if (elem[i] < 1 || elem[i] > r->par.num_elem) {
                s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: side set \"%s\": entry %lld: "
                             "element %lld out of range 1..%lld", r->path, gname, (long long)(i + 1),
                             (long long)elem[i], (long long)r->par.num_elem);
                break;
            }
            const int64_t e = elem[i] - 1;
            const exo_block *blk = block_of(r, e);
            /* the element's nodes back in Exodus order */
            const int64_t *vtk = r->m->conn + r->m->offset[e];
            const int nn = (int)(r->m->offset[e + 1] - r->m->offset[e]);
            int64_t exo[64], face[9];
            for (int i2 = 0; i2 < nn; ++i2) exo[blk->t.perm ? blk->t.perm[i2] : i2] = vtk[i2];
            cm_cell_type ft;
            int fn = 0;
            if (!exo_side(&blk->t, exo, side[i], &ft, face, &fn)) {
                s = cm_error(r->ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: side set \"%s\": entry %lld: "
                             "element %lld (%s) has no side %lld", r->path, gname, (long long)(i + 1),
                             (long long)elem[i], cm_cell_type_info(blk->t.type)->name,
                             (long long)side[i]);
                break;
            }
            dims |= 1 << cm_cell_type_info(ft)->dim;
            s = cm_mesh_add_cell(r->ctx, r->m, ft, face, (size_t)fn, tag, tag, r->next_id++);
        }
        for (int d = 0; s == CM_OK && d < 4; ++d)
            if (dims & (1 << d)) s = cm_mesh_add_group(r->ctx, r->m, d, tag, gname);
        free(elem);
    }
    entity_list_free(ids, names);
    return s;
}

/* Whether the file starts as netCDF classic/64-bit/CDF-5 or HDF5 (netCDF-4) does. */
static cm_status check_signature(cm_context *ctx, const char *path, struct stat *st)
{
    /* the input rule (core.h): regular files only, never a blocking open */
    FILE *f = NULL;
    cm_status s = cm_file_open_read(ctx, path, &f);
    if (s != CM_OK) return cm_error_prefix(ctx, s, "cm_mesh_read");
    unsigned char head[8] = {0};
    const int sr = fstat(fileno(f), st);
    const size_t n = fread(head, 1, sizeof head, f);
    fclose(f);
    if (sr != 0) return cm_error(ctx, CM_ERR_IO, "cm_mesh_read: %s: %s", path, strerror(errno));
    const int cdf = n >= 4 && !memcmp(head, "CDF", 3) && (head[3] == 1 || head[3] == 2 || head[3] == 5);
    const int hdf = n == 8 && !memcmp(head, "\x89HDF\r\n\x1a\n", 8);
    if (!cdf && !hdf)
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: not an Exodus II file (neither the "
                        "netCDF nor the HDF5 signature)", path);
    return CM_OK;
}

static cm_status read_locked(exo_reader *r, const struct stat *fst)
{
    cm_context *ctx = r->ctx;
    const char *path = r->path;
    int comp_ws = 8, io_ws = 0;
    float version = 0.0f;
    cm_status hs = cm_netcdf_check_header(ctx, path, (uint64_t)fst->st_size);
    if (hs != CM_OK) return hs;
    r->exoid = ex_open(path, EX_READ, &comp_ws, &io_ws, &version);
    if (r->exoid < 0)
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: cannot open as Exodus II: %s", path,
                        exo_reason(r->exoid));
    ex_set_int64_status(r->exoid, EX_ALL_INT64_API);
    int rc = ex_get_init_ext(r->exoid, &r->par);
    if (rc < 0)
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: cannot read the sizes: %s", path,
                        exo_reason(rc));
    const ex_init_params *p = &r->par;
    if (p->num_dim < 1 || p->num_dim > 3 || p->num_nodes < 0 || p->num_nodes > EXO_MAX_COUNT ||
        p->num_elem < 0 || p->num_elem > EXO_MAX_COUNT || p->num_elem_blk < 0 ||
        p->num_elem_blk > p->num_elem + 1000000 || p->num_node_sets < 0 ||
        p->num_node_sets > 1000000 || p->num_side_sets < 0 || p->num_side_sets > 1000000)
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_read: %s: bad sizes: %lld dimensions, %lld "
                        "nodes, %lld elements, %lld blocks, %lld node sets, %lld side sets", path,
                        (long long)p->num_dim, (long long)p->num_nodes, (long long)p->num_elem,
                        (long long)p->num_elem_blk, (long long)p->num_node_sets,
                        (long long)p->num_side_sets);
    if (p->num_dim == 1)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_read: %s: a 1-D Exodus II mesh is not "
                        "supported (2-D and 3-D are)", path);
    ex_set_max_name_length(r->exoid, 255);
    cm_status s = read_nodes(r);
    if (s != CM_OK) return s;
    int64_t *elem_map = NULL;
    if (p->num_elem > 0) {
        elem_map = malloc((size_t)p->num_elem * sizeof *elem_map);
        if (!elem_map)
            return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory for %lld elements",
                            path, (long long)p->num_elem);
        if ((s = check_var(r, "elem_num_map", p->num_elem, "element number map")) != CM_OK) {
            free(elem_map);
            return s;
        }
        rc = ex_get_id_map(r->exoid, EX_ELEM_MAP, elem_map);
        int identity = 1;
        for (int64_t i = 0; rc >= 0 && i < p->num_elem; ++i) {
            identity &= elem_map[i] == i + 1;
            if (elem_map[i] > r->next_id) r->next_id = elem_map[i];
        }
        if (rc < 0 || identity) {
            free(elem_map);
            elem_map = NULL;
            r->next_id = p->num_elem;
        }
    }
    ++r->next_id;
    s = read_blocks(r, elem_map);
    free(elem_map);
    if (s == CM_OK) s = read_node_sets(r);
    if (s == CM_OK) s = read_side_sets(r);
    if (s != CM_OK) return s;
    exo_state *st = calloc(1, sizeof *st);
    if (st) st->path = strdup(path);
    if (!st || !st->path) {
        exo_state_free(st);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_read: %s: out of memory", path);
    }
    st->num_dim = p->num_dim;
    st->num_nodes = p->num_nodes;
    st->num_elem = p->num_elem;
    st->stamp = (cm_file_stamp){(int64_t)fst->st_size, (int64_t)fst->st_mtim.tv_sec, (int64_t)fst->st_mtim.tv_nsec};
    return cm_mesh_set_origin(ctx, r->m, CM_FORMAT_EXODUS, st, exo_state_free);
}

cm_status cm_mesh_read_exodus(cm_context *ctx, const char *path, cm_mesh **mesh)
{
    if (!mesh || !path)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_read_exodus: NULL argument");
    *mesh = NULL;
    struct stat fst;
    cm_status s = check_signature(ctx, path, &fst);
    if (s == CM_OK) s = exo_load(ctx, "cm_mesh_read", path);
    if (s != CM_OK) return s;
    exo_reader r;
    memset(&r, 0, sizeof r);
    r.ctx = ctx;
    r.path = path;
    r.exoid = -1;
    r.next_tag = 1;
    if ((s = cm_mesh_create(ctx, &r.m)) != CM_OK) return s;
    pthread_mutex_lock(&exo_lock);
    ex_opts(0); /* the library prints nothing and never exits: errors come back as codes */
    s = read_locked(&r, &fst);
    if (r.exoid >= 0) ex_close(r.exoid);
    pthread_mutex_unlock(&exo_lock);
    free(r.blocks);
    if (s != CM_OK) {
        cm_mesh_destroy(&r.m);
        return s;
    }
    *mesh = r.m;
    return CM_OK;
}

/* ---- the writer: back into the file the mesh was read from ---- */

/* The coordinates go in through netCDF itself, not ex_open(EX_WRITE): opening for writing,
 * the Exodus library adds what older writers (meshio) leave out (the len_name dimension, the
 * maximum_name_length attribute), which would change more than the coordinates. netCDF
 * converts the doubles to the variable's own type (float files stay float). */
static cm_status put_coordinates(cm_context *ctx, const cm_mesh *mesh, const exo_state *st,
                                 const char *path, const char *tmp)
{
    const int64_t n = st->num_nodes;
    double *c = malloc((size_t)(n > 0 ? n : 1) * sizeof *c);
    if (!c) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_write: %s: out of memory", path);
    cm_status s = CM_OK;
    pthread_mutex_lock(&exo_lock);
    int ncid = -1, rc = nc_open(tmp, NC_WRITE, &ncid);
    int dim_nodes = -1, var = -1, split = 0;
    size_t len = 0;
    if (rc == NC_NOERR) rc = nc_inq_dimid(ncid, "num_nodes", &dim_nodes);
    if (rc == NC_NOERR) rc = nc_inq_dimlen(ncid, dim_nodes, &len);
    if (rc == NC_NOERR && (int64_t)len != n) rc = NC_EDIMSIZE;
    if (rc == NC_NOERR) {
        split = nc_inq_varid(ncid, "coordx", &var) == NC_NOERR;
        if (!split) rc = nc_inq_varid(ncid, "coord", &var);
    }
    static const char *const names[3] = {"coordx", "coordy", "coordz"};
    for (int k = 0; rc == NC_NOERR && n > 0 && k < st->num_dim; ++k) {
        for (int64_t i = 0; i < n; ++i) c[i] = mesh->xyz[3 * i + k];
        if (split) {
            rc = nc_inq_varid(ncid, names[k], &var);
            if (rc == NC_NOERR) rc = nc_put_var_double(ncid, var, c);
        } else {
            const size_t start[2] = {(size_t)k, 0}, count[2] = {1, (size_t)n};
            rc = nc_put_vara_double(ncid, var, start, count, c);
        }
    }
    const int rc_close = ncid >= 0 ? nc_close(ncid) : NC_NOERR;
    if (rc == NC_NOERR) rc = rc_close;
    if (rc != NC_NOERR)
        s = cm_error(ctx, CM_ERR_IO, "cm_mesh_write: %s: cannot write the coordinates into the copy "
                     "of %s: %s", path, st->path, nc_strerror(rc));
    pthread_mutex_unlock(&exo_lock);
    free(c);
    return s;
}

cm_status cm_mesh_write_exodus(cm_context *ctx, const cm_mesh *mesh, const char *path,
                               const cm_mesh_write_options *opt)
{
    (void)opt;
    if (!mesh || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_write_exodus: NULL argument");
    const exo_state *st = cm_mesh_origin_state(mesh, CM_FORMAT_EXODUS);
    if (!st)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_mesh_write: %s: Exodus II is written only back into the file a mesh "
                        "was read from (with the same nodes and cells); write this mesh in "
                        "another format", path);
    if (st->num_dim == 2)
        for (size_t i = 0; i < mesh->n_nodes; ++i)
            if (mesh->xyz[3 * i + 2] != 0.0)
                return cm_error(ctx, CM_ERR_UNSUPPORTED,
                                "cm_mesh_write: %s: %s is a 2-D Exodus II file, but node %zu has "
                                "z = %g", path, st->path, i, mesh->xyz[3 * i + 2]);
    cm_status s = exo_load(ctx, "cm_mesh_write", path);
    if (s != CM_OK) return s;
    cm_outfile out;
    s = cm_rewrite_copy_open(ctx, st->path, &st->stamp, path, &out);
    if (s != CM_OK) return s;
    s = put_coordinates(ctx, mesh, st, path, out.tmp);
    if (s != CM_OK) {
        cm_outfile_abort(&out);
        return s;
    }
    return cm_outfile_commit(ctx, &out);
}
