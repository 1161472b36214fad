/* `cadmorph deform --constraint TYPE:SET`: parsing of the constraint specs, the node sets
 * they name (a node-list file, a physical group, a field of the mesh) and the Shape-Up run
 * with its report. No algorithm here: the projections and the alternation are deform/'s. */
#include "deform_constraints.h"

#include "cli.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

void cli_constraints_init(cli_constraints *c)
{
    memset(c, 0, sizeof *c);
    cm_shapeup_options_init(&c->opt);
}

int cli_parse_constraint(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    (void)o;
    cli_constraints *c = dest;
    const char *colon = strchr(v, ':');
    char name[16];
    size_t len = colon ? (size_t)(colon - v) : 0;
    if (!colon || len == 0 || len >= sizeof name || !colon[1])
        return cli_usage(p->cmd, p->usage, "--constraint '%s': expected TYPE:SET", v);
    memcpy(name, v, len);
    name[len] = 0;
    cm_shape_type t;
    if (cm_shape_type_parse(NULL, name, &t) < 0)
        return cli_usage(p->cmd, p->usage,
                         "--constraint '%s': unknown type '%s' (plane|circle|cylinder|cone|line|rigid)",
                         v, name);
    if (c->n >= CLI_MAX_CONSTRAINTS)
        return cli_usage(p->cmd, p->usage, "more than %d --constraint options", CLI_MAX_CONSTRAINTS);
    c->type[c->n] = t;
    c->set[c->n++] = colon + 1;
    return 0;
}

int cli_parse_dense_constraints(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    (void)p, (void)o, (void)v;
    ((cli_constraints *)dest)->opt.sparse = 0;
    return 0;
}

static int parse_number(const char *v, double *out)
{
    char *end;
    errno = 0;
    double d = strtod(v, &end);
    if (errno || *end || end == v || !isfinite(d)) return -1;
    *out = d;
    return 0;
}

static void mark_cell(const cm_mesh *m, size_t c, unsigned char *mark)
{
    if (m->type[c] == CM_CELL_POLYHEDRON) {
        int64_t p = m->offset[c], nf = m->conn[p++];
        for (int64_t f = 0; f < nf; ++f) {
            int64_t k = m->conn[p++];
            for (int64_t j = 0; j < k; ++j)
                mark[m->conn[p++]] = 1;
        }
        return;
    }
    for (int64_t p = m->offset[c]; p < m->offset[c + 1]; ++p)
        mark[m->conn[p]] = 1;
}

/* SET as a group or a field of the mesh; CM_ERR_ARGUMENT naming what the mesh has when
 * nothing matches. */
static cm_status mesh_set(cm_context *ctx, const cm_mesh *m, const char *set, unsigned char *mark)
{
    int found = 0;
    for (size_t g = 0; g < m->n_groups; ++g) {
        const cm_mesh_group *gr = m->groups + g;
        if (!gr->name || strcmp(gr->name, set)) continue;
        found = 1;
        for (size_t c = 0; c < m->n_cells; ++c) {
            const cm_cell_info *inf = cm_cell_type_info((cm_cell_type)m->type[c]);
            if (m->physical && m->physical[c] == gr->tag && inf && inf->dim == gr->dim)
                mark_cell(m, c, mark);
        }
    }
    if (found) return CM_OK;
    char name[256];
    const char *eq = strchr(set, '=');
    size_t len = eq ? (size_t)(eq - set) : strlen(set);
    double value = 0;
    if (len >= sizeof name) len = sizeof name - 1;
    memcpy(name, set, len);
    name[len] = 0;
    if (eq && parse_number(eq + 1, &value))
        return cm_error(ctx, CM_ERR_MISMATCH, "constraint set '%s': '%s' is not a number", set, eq + 1);
    for (int loc = 0; loc < 2 && !found; ++loc) {
        const cm_field *f = cm_mesh_find_field(m, name, loc ? CM_FIELD_CELL : CM_FIELD_NODE);
        if (!f) continue;
        found = 1;
        size_t count = loc ? m->n_cells : m->n_nodes;
        for (size_t i = 0; i < count; ++i) {
            double v = f->data[(size_t)f->components * i];
            if (eq ? v == value : v != 0) {
                if (loc)
                    mark_cell(m, i, mark);
                else
                    mark[i] = 1;
            }
        }
    }
    if (found) return CM_OK;
    char have[512] = "";
    size_t used = 0;
    for (size_t g = 0; g < m->n_groups && used + 64 < sizeof have; ++g)
        if (m->groups[g].name)
            used += (size_t)snprintf(have + used, sizeof have - used, "%s%s", used ? ", " : "",
                                     m->groups[g].name);
    for (size_t f = 0; f < m->n_fields && used + 64 < sizeof have; ++f)
        used += (size_t)snprintf(have + used, sizeof have - used, "%s%s (field)", used ? ", " : "",
                                 m->fields[f].name);
    return cm_error(ctx, CM_ERR_MISMATCH,
                    "constraint set '%s': no such file, physical group or field (the mesh has: %s)",
                    set, used ? have : "none");
}

/* The largest distance of n points (x: n x 3) from their least-squares plane, or -1. */
static double off_plane(size_t n, const double *x, double *scratch)
{
    double fit[6];
    if (n < 3 || cm_shape_project_plane(NULL, n, x, scratch, fit) < 0) return -1;
    double m = 0;
    for (size_t i = 0; i < n; ++i) {
        double e = 0;
        for (int a = 0; a < 3; ++a)
            e += (x[3 * i + a] - fit[a]) * fit[3 + a];
        m = fmax(m, fabs(e));
    }
    return m;
}

static int64_t find_root(int64_t *parent, int64_t i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* A plane set named by a group whose faces form separate pieces that do not lie in one
 * plane (the front and back planes of a 2-D mesh are one `empty` patch; the two walls of a
 * channel one `wall` patch): one plane set per piece, each of which must be planar itself,
 * else an error (one least-squares plane through two parallel planes would squash the mesh
 * between them). nodes (k, ascending) is the set; *pieces gets the piece index of each
 * node and the return value their count (1: nothing to split), or -1 after an error. */
static int plane_pieces(cm_context *ctx, const cm_mesh *m, const char *set, const int64_t *nodes,
                        size_t k, int *piece)
{
    const cm_mesh_group *gr = NULL;
    for (size_t g = 0; g < m->n_groups && !gr; ++g)
        if (m->groups[g].name && !strcmp(m->groups[g].name, set)) gr = m->groups + g;
    if (!gr || !m->physical || k < 3) return 1;
    size_t n = m->n_nodes;
    int64_t *parent = malloc((n ? n : 1) * sizeof *parent);
    double *x = malloc(k * 6 * sizeof *x);
    if (!parent || !x) {
        free(parent), free(x);
        cm_error(ctx, CM_ERR_NOMEM, "out of memory");
        return -1;
    }
    for (size_t i = 0; i < n; ++i)
        parent[i] = (int64_t)i;
    for (size_t c = 0; c < m->n_cells; ++c) {
        const cm_cell_info *inf = cm_cell_type_info((cm_cell_type)m->type[c]);
        if (m->physical[c] != gr->tag || !inf || inf->dim != gr->dim) continue;
        if (m->type[c] == CM_CELL_POLYHEDRON) continue; /* a group of faces has no polyhedra */
        for (int64_t p = m->offset[c] + 1; p < m->offset[c + 1]; ++p) {
            int64_t a = find_root(parent, m->conn[m->offset[c]]), b = find_root(parent, m->conn[p]);
            if (a != b) parent[b] = a;
        }
    }
    /* a piece's index at its root: parent[] of a root is free for it once every node of the
     * set knows its root (kept in x as scratch: k <= n) */
    int64_t *root = (int64_t *)x;
    for (size_t i = 0; i < k; ++i)
        root[i] = find_root(parent, nodes[i]);
    for (size_t i = 0; i < k; ++i)
        parent[root[i]] = -1;
    int count = 0;
    for (size_t i = 0; i < k; ++i) {
        if (parent[root[i]] == -1) parent[root[i]] = -2 - count++;
        piece[i] = (int)(-2 - parent[root[i]]);
    }
    for (size_t i = 0; i < k; ++i)
        memcpy(x + 3 * i, m->xyz + 3 * nodes[i], 3 * sizeof *x);
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < k; ++i)
        for (int a = 0; a < 3; ++a)
            lo[a] = fmin(lo[a], x[3 * i + a]), hi[a] = fmax(hi[a], x[3 * i + a]);
    double tol = 1e-6 * sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                             (hi[2] - lo[2]) * (hi[2] - lo[2]));
    int rc = 1;
    if (count > 1 && off_plane(k, x, x + 3 * k) > tol) {
        rc = count;
        for (int q = 0; q < count && rc > 0; ++q) {
            size_t kq = 0;
            for (size_t i = 0; i < k; ++i)
                if (piece[i] == q) memcpy(x + 3 * kq++, m->xyz + 3 * nodes[i], 3 * sizeof *x);
            double off = off_plane(kq, x, x + 3 * k);
            if (count > 64 || off < 0 || off > tol) {
                cm_error(ctx, CM_ERR_MISMATCH,
                         "constraint plane:%s: its nodes are not one plane but %s%d separate "
                         "pieces, and piece %d (%zu nodes) is not planar itself (%.3g off its "
                         "plane): give each plane its own set (a node-list file)",
                         set, count > 64 ? "over " : "", count > 64 ? 64 : count, q + 1, kq,
                         off);
                rc = -1;
            }
        }
    }
    free(parent), free(x);
    return rc;
}

int cli_constraints_any(const cli_constraints *c)
{
    return c->n > 0 || c->cad != NULL;
}

/* Set t (a plane, named by a group) split into its planar pieces when they are not one
 * plane (plane_pieces): the first piece stays set t, the others are appended, each labelled
 * SET[piece] and reported on stdout. */
static cm_status split_plane(cm_context *ctx, const cm_mesh *mesh, cli_constraints *c,
                             cm_shape_set *sets, int t)
{
    size_t k = sets[t].n;
    int *piece = malloc((k ? k : 1) * sizeof *piece);
    if (!piece) return cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    int count = plane_pieces(ctx, mesh, c->set[t], sets[t].nodes, k, piece);
    cm_status s = count < 0 ? CM_ERR_MISMATCH : CM_OK;
    if (count > 1 && c->n + count - 1 > CLI_MAX_CONSTRAINTS)
        s = cm_error(ctx, CM_ERR_ARGUMENT, "constraint plane:%s: %d pieces make more than %d sets",
                     c->set[t], count, CLI_MAX_CONSTRAINTS);
    int64_t *all = (int64_t *)sets[t].nodes;
    const char *name = c->set[t];
    for (int q = count - 1; s >= 0 && count > 1 && q >= 0; --q) {
        size_t kq = 0;
        for (size_t i = 0; i < k; ++i)
            kq += piece[i] == q;
        int64_t *nodes = malloc((kq ? kq : 1) * sizeof *nodes);
        char *label = malloc(strlen(name) + 16);
        if (!nodes || !label) {
            free(nodes), free(label);
            s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
            break;
        }
        kq = 0;
        for (size_t i = 0; i < k; ++i)
            if (piece[i] == q) nodes[kq++] = all[i];
        sprintf(label, "%s[%d]", name, q + 1);
        int to = q == 0 ? t : c->n++;
        free(c->owned[to]);
        c->owned[to] = label;
        c->type[to] = CM_SHAPE_PLANE;
        c->set[to] = label;
        sets[to].type = CM_SHAPE_PLANE;
        sets[to].n = kq;
        sets[to].nodes = nodes;
        if (q == 0) free(all);
    }
    if (s >= 0 && count > 1)
        printf("constraint plane:%s: %d separate planes, one constraint each (%s[1] .. %s[%d])\n",
               name, count, name, name, count);
    free(piece);
    return s;
}

cm_status cli_constraints_resolve(cm_context *ctx, const cm_mesh *mesh, cli_constraints *c,
                                  cm_shape_set *sets)
{
    size_t n = mesh->n_nodes;
    memset(sets, 0, CLI_MAX_CONSTRAINTS * sizeof *sets);
    unsigned char *mark = malloc(n ? n : 1);
    if (!mark) return cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    cm_status s = CM_OK;
    const int given = c->n; /* the pieces of split plane sets are appended after them */
    for (int t = 0; t < given && s >= 0; ++t) {
        memset(mark, 0, n ? n : 1);
        struct stat st;
        int file = stat(c->set[t], &st) == 0 && S_ISREG(st.st_mode);
        if (file)
            s = cm_mesh_read_node_list(ctx, c->set[t], n, mark);
        else
            s = mesh_set(ctx, mesh, c->set[t], mark);
        if (s < 0) break;
        size_t k = 0;
        for (size_t i = 0; i < n; ++i)
            k += mark[i] != 0;
        int64_t *nodes = malloc((k ? k : 1) * sizeof *nodes);
        if (!nodes) {
            s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
            break;
        }
        k = 0;
        for (size_t i = 0; i < n; ++i)
            if (mark[i]) nodes[k++] = (int64_t)i;
        sets[t].type = c->type[t];
        sets[t].n = k;
        sets[t].nodes = nodes;
        if (k == 0) s = cm_error(ctx, CM_ERR_MISMATCH, "constraint set '%s': no node", c->set[t]);
        if (s >= 0 && !file && c->type[t] == CM_SHAPE_PLANE) s = split_plane(ctx, mesh, c, sets, t);
    }
    free(mark);
    if (s >= 0 && c->cad) s = cli_cad_constraints(ctx, mesh, c, sets);
    if (s >= 0 && c->cad && c->n == 0)
        s = cm_error(ctx, CM_ERR_MISMATCH, "%s: no plane, cylinder or circle to constrain (filter %s)",
                     c->cad, c->cad_filter ? c->cad_filter : "all");
    return s;
}

void cli_constraints_free(cli_constraints *c, cm_shape_set *sets)
{
    for (int t = 0; t < CLI_MAX_CONSTRAINTS; ++t) {
        free((void *)sets[t].nodes);
        sets[t].nodes = NULL;
        free(c->owned[t]);
        c->owned[t] = NULL;
    }
}

cm_status cli_constraints_run(cm_context *ctx, cm_mls *mls, cm_mesh *mesh,
                              const cli_constraints *c, const cm_shape_set *sets, double *disp,
                              double *fix_residual)
{
    cm_shapeup *su = NULL;
    cm_status s = cm_shapeup_create(ctx, mls, mesh, (size_t)c->n, sets, &c->opt, &su);
    if (s < 0) return s;
    double *r0 = malloc((size_t)c->n * 2 * sizeof *r0);
    if (!r0) {
        cm_shapeup_destroy(&su);
        return cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    }
    double *r1 = r0 + c->n;
    cm_shapeup_report rep;
    s = cm_shapeup_apply(ctx, su, disp, r0, r1, &rep);
    cm_shapeup_destroy(&su);
    /* which set each node is in (the last one listed), for ParaView and the tests */
    double *field = NULL;
    if (s >= 0) {
        cm_status fs = cm_mesh_add_field(ctx, mesh, "constraint_set", CM_FIELD_NODE, 1, &field);
        if (fs < 0) s = fs;
    }
    if (field) {
        for (size_t i = 0; i < mesh->n_nodes; ++i)
            field[i] = -1;
        for (int t = 0; t < c->n; ++t)
            for (size_t i = 0; i < sets[t].n; ++i)
                field[sets[t].nodes[i]] = t;
    }
    if (s >= 0) {
        double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
        for (size_t i = 0; i < mesh->n_nodes; ++i)
            for (int a = 0; a < 3; ++a)
                lo[a] = fmin(lo[a], mesh->xyz[3 * i + a]), hi[a] = fmax(hi[a], mesh->xyz[3 * i + a]);
        double diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                           (hi[2] - lo[2]) * (hi[2] - lo[2]));
        for (int t = 0; t < c->n; ++t)
            printf("constraint %s:%s: %zu nodes, residual before %.6g after %.6g (%.3g of the "
                   "diagonal)\n",
                   cm_shape_type_name(c->type[t]), c->set[t], sets[t].n, r0[t], r1[t],
                   diag > 0 ? r1[t] / diag : r1[t]);
        printf("shape-up: %d iterations, %s (last move %.3g), C %s with %zu entries, factor %zu "
               "entries, update %.3f s, iterations %.3f s\n",
               rep.iterations, rep.converged ? "converged" : "NOT converged", rep.last_move,
               c->opt.sparse ? "sparse" : "mean-centred", rep.c_nonzeros, rep.factor_nonzeros,
               rep.t_factor, rep.t_iterate);
        if (c->opt.snap)
            printf("snap: constrained nodes moved onto their projections by at most %.6g\n",
                   rep.snap_move);
        if (s > 0) {
            /* the cap was hit: a result, with the warning on stderr */
            fprintf(stderr, "cadmorph deform: warning: %s\n", cm_context_message(ctx));
            s = CM_OK;
        }
        *fix_residual = rep.fix_residual;
    }
    free(r0);
    return s;
}
