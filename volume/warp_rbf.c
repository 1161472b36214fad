/* The RBF warp methods [SMB12 §3]: one polyharmonic RBF per connected component of volume
 * cells, centred at the component's constrained nodes, carries their displacement inside: per
 * component, deform.h's rbf deformation of its constrained and free nodes. Exact at the
 * centres, so the residual is 0. */
#include "warp_method.h"

#include "cadmorph/deform.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One component: the RBF is centred at `fixed`; `free_nodes` receive its values. The
 * deformation's points are the fixed nodes, then the free ones. */
typedef struct warp_component {
    cm_deform *def; /* NULL when every node of the component is constrained */
    size_t n_fixed;
    int64_t *fixed; /* constrained nodes of the component, ascending */
    size_t n_free;
    int64_t *free_nodes; /* unconstrained nodes owned by the component, ascending */
    double tolerance;    /* its iterative solver's (the option, or from the mesh) */
} warp_component;

typedef struct rbf_warp {
    size_t n_nodes;
    size_t n_components;
    warp_component *comp;
    double *values; /* scratch: max (n_fixed + n_free) x 3, one component's points */
    unsigned char *constrained; /* #nodes: the caller's flags (apply keeps those nodes) */
} rbf_warp;

static void rbf_destroy(void *state)
{
    rbf_warp *w = state;
    if (!w) return;
    for (size_t k = 0; w->comp && k < w->n_components; ++k) {
        cm_deform_destroy(&w->comp[k].def);
        free(w->comp[k].fixed);
        free(w->comp[k].free_nodes);
    }
    free(w->comp);
    free(w->values);
    free(w->constrained);
    free(w);
}

/* Calls visit(node) for each node of cell c, possibly repeatedly (polyhedra list a node once
 * per face); callers deduplicate. */
typedef struct node_visitor {
    int *stamp;    /* #nodes: last component that saw the node, + 1 */
    int mark;      /* component + 1 */
    int64_t *list; /* nodes seen for the first time in this component */
    size_t n;
} node_visitor;

static void visit_cell(const cm_mesh *mesh, size_t c, node_visitor *v)
{
    const int64_t *conn = mesh->conn;
    int64_t b = mesh->offset[c], e = mesh->offset[c + 1];
    if (mesh->type[c] == CM_CELL_POLYHEDRON) {
        for (cm_polyhedron_face f = cm_polyhedron_begin(conn + b, e - b); cm_polyhedron_more(&f);
             cm_polyhedron_next(&f))
            for (int64_t i = 0; i < f.n; ++i)
                if (v->stamp[f.nodes[i]] != v->mark) {
                    v->stamp[f.nodes[i]] = v->mark;
                    v->list[v->n++] = f.nodes[i];
                }
        return;
    }
    for (int64_t p = b; p < e; ++p)
        if (v->stamp[conn[p]] != v->mark) {
            v->stamp[conn[p]] = v->mark;
            v->list[v->n++] = conn[p];
        }
}

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Splits the node list of component k into constrained centres and owned free nodes.
 * owner: #nodes, the component that evaluates an unconstrained node (-1: none yet); a free
 * node shared by two components (only possible with a caller's mask that leaves a boundary
 * node free) goes to the first one, so that every node has exactly one displacement. */
static cm_status split_component(cm_context *ctx, const unsigned char *constrained, int k,
                                 const int64_t *list,
                                 size_t n, int *owner, warp_component *wc, size_t *n_shared_free)
{
    size_t nf = 0, nu = 0;
    for (size_t i = 0; i < n; ++i) {
        if (constrained[list[i]])
            ++nf;
        else if (owner[list[i]] < 0)
            ++nu;
        else
            ++*n_shared_free;
    }
    wc->fixed = malloc((nf ? nf : 1) * sizeof *wc->fixed);
    wc->free_nodes = malloc((nu ? nu : 1) * sizeof *wc->free_nodes);
    if (!wc->fixed || !wc->free_nodes)
        return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
    for (size_t i = 0; i < n; ++i) {
        int64_t v = list[i];
        if (constrained[v]) {
            wc->fixed[wc->n_fixed++] = v;
        } else if (owner[v] < 0) {
            owner[v] = k;
            wc->free_nodes[wc->n_free++] = v;
        }
    }
    return CM_OK;
}

/* The tolerance from the mesh (cm_warp_options.tolerance 0; docs/DESIGN.md, "The warp's
 * tolerance"): the iterative solve misses the data at the centres by up to tolerance x the
 * largest displacement, and the constrained nodes are then set exactly, so a free node next
 * to the wall moves by about that miss against its wall neighbour. A share of the shortest
 * such spacing over the centres' diagonal keeps the error's stretch of any cell's edges
 * within about CM_WARP_TOL_SHARE for motions up to the diagonal (checked in strain, not in
 * displacement: tests/volume/test_warp_tolerance.c); never looser than CM_WARP_TOL_MAX (what
 * studies have been measured at), never tighter than the RBF's own default. */
#define CM_WARP_TOL_SHARE 1e-3
#define CM_WARP_TOL_MAX 1e-6

/* The shortest distance between a constrained and a free node of one cell, over the cells
 * cells[0..n) (INFINITY: no cell has both; -1: out of memory). */
static double wall_spacing(const cm_mesh *mesh, const unsigned char *constrained,
                           const size_t *cells, size_t n)
{
    double d2 = INFINITY;
    int64_t *nb = NULL;
    size_t cap = 0;
    for (size_t i = 0; i < n; ++i) {
        /* a cell has no more distinct nodes than connectivity entries */
        const size_t len = (size_t)(mesh->offset[cells[i] + 1] - mesh->offset[cells[i]]);
        if (len > cap) {
            int64_t *t = realloc(nb, len * sizeof *t);
            if (!t) {
                free(nb);
                return -1;
            }
            nb = t, cap = len;
        }
        const int k = cm_mesh_cell_nodes(mesh, cells[i], nb, (int)cap);
        for (int p = 0; p < k; ++p) {
            if (!constrained[nb[p]]) continue;
            const double *x = mesh->xyz + 3 * nb[p];
            for (int q = 0; q < k; ++q) {
                if (constrained[nb[q]]) continue;
                const double *y = mesh->xyz + 3 * nb[q];
                const double dx = x[0] - y[0], dy = x[1] - y[1], dz = x[2] - y[2];
                d2 = fmin(d2, dx * dx + dy * dy + dz * dz);
            }
        }
    }
    free(nb);
    return sqrt(d2);
}

/* The RBF of component k; its errors (coplanar centres, failed factorisation) get the
 * component number in front. spacing: wall_spacing of its cells (unused where opt gives the
 * tolerance). */
static cm_status fit_component(cm_context *ctx, const cm_mesh *mesh, cm_rbf_kernel kernel,
                               const cm_warp_options *opt, size_t k, double spacing,
                               warp_component *wc)
{
    if (wc->n_free == 0) return CM_OK; /* nothing to interpolate: every node is prescribed */
    if (wc->n_fixed == 0)
        return cm_error(ctx, CM_ERR_NUMERIC,
                        "cm_warp_create: component %zu: no constrained node, %zu free nodes", k,
                        wc->n_free);
    size_t np = wc->n_fixed + wc->n_free;
    double *xyz = malloc(np * 3 * sizeof *xyz);
    unsigned char *con = calloc(np, 1);
    if (!xyz || !con) {
        free(xyz), free(con);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
    }
    for (size_t i = 0; i < wc->n_fixed; ++i) {
        memcpy(xyz + 3 * i, mesh->xyz + 3 * wc->fixed[i], 3 * sizeof(double));
        con[i] = 1;
    }
    for (size_t i = 0; i < wc->n_free; ++i)
        memcpy(xyz + 3 * (wc->n_fixed + i), mesh->xyz + 3 * wc->free_nodes[i], 3 * sizeof(double));
    double bb[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < wc->n_fixed; ++i)
        for (int a = 0; a < 3; ++a) {
            bb[a] = fmin(bb[a], xyz[3 * i + a]);
            bb[3 + a] = fmax(bb[3 + a], xyz[3 * i + a]);
        }
    const double diag = cm_bbox_diagonal(bb);
    cm_rbf_options rbf_default;
    cm_rbf_options_init(&rbf_default);
    const double tol_min = rbf_default.tolerance; /* the RBF's own default */
    const double from_mesh = diag > 0 ? CM_WARP_TOL_SHARE * spacing / diag : tol_min;
    wc->tolerance = opt->tolerance > 0 ? opt->tolerance
                                       : fmax(tol_min, fmin(CM_WARP_TOL_MAX, from_mesh));
    cm_deform_options o;
    cm_deform_options_init(&o);
    o.method = CM_DEFORM_RBF;
    o.kernel = kernel;
    o.solver = opt->solver;
    o.tolerance = wc->tolerance;
    o.solves = opt->solves;
    o.warm_groups = opt->warm_groups;
    cm_status s = cm_deform_create(ctx, &o, np, xyz, con, NULL, &wc->def);
    free(xyz), free(con);
    if (s < 0)
        return cm_error_prefix(ctx, s, "cm_warp_create: component %zu (%zu constrained nodes)", k,
                               wc->n_fixed);
    cm_deform_stats st;
    cm_deform_get_stats(wc->def, &st);
    char why[96] = "";
    if (!(opt->tolerance > 0))
        snprintf(why, sizeof why, " (from the mesh: wall spacing %.3g, centres' diagonal %.3g)",
                 spacing, diag);
    cm_log(ctx, CM_LOG_DEBUG, "cm_warp_create: component %zu: %zu centres, %s solver%s, for %d "
           "solve(s), tolerance %.3g%s", k, wc->n_fixed, st.rbf.solver == CM_RBF_SOLVER_DENSE ?
           "dense" : st.rbf.solver == CM_RBF_SOLVER_PETSC ? "petsc" : "iterative",
           opt->solver == CM_RBF_SOLVER_AUTO ? " (auto)" : "", opt->solves > 1 ? opt->solves : 1,
           wc->tolerance, st.rbf.solver == CM_RBF_SOLVER_DENSE ? " (unused: exact)" : why);
    return CM_OK;
}

/* Nodes of volume cells grouped by component: cells are bucketed by component first so that
 * one pass per component with a stamp array deduplicates its nodes. */
static cm_status build_components(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                                  const unsigned char *constrained, cm_rbf_kernel kernel,
                                  const cm_warp_options *opt, rbf_warp *w,
                                  size_t *n_shared_free)
{
    size_t nc = b->n_components, nn = mesh->n_nodes;
    size_t *start = calloc(nc + 1, sizeof *start);
    size_t *cells = malloc((mesh->n_cells ? mesh->n_cells : 1) * sizeof *cells);
    int *stamp = calloc(nn ? nn : 1, sizeof *stamp);
    int *owner = malloc((nn ? nn : 1) * sizeof *owner);
    int64_t *list = malloc((nn ? nn : 1) * sizeof *list);
    cm_status s = CM_OK;
    if (!start || !cells || !stamp || !owner || !list) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
        goto done;
    }
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        int k = b->cell_component[c];
        if (k >= 0 && (size_t)k < nc) ++start[k + 1];
    }
    for (size_t k = 0; k < nc; ++k)
        start[k + 1] += start[k];
    {
        size_t *fill = malloc((nc ? nc : 1) * sizeof *fill);
        if (!fill) {
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
            goto done;
        }
        memcpy(fill, start, nc * sizeof *fill);
        for (size_t c = 0; c < mesh->n_cells; ++c) {
            int k = b->cell_component[c];
            if (k >= 0 && (size_t)k < nc) cells[fill[k]++] = c;
        }
        free(fill);
    }
    for (size_t v = 0; v < nn; ++v)
        owner[v] = -1;
    for (size_t k = 0; k < nc; ++k) {
        node_visitor vis = {stamp, (int)k + 1, list, 0};
        for (size_t i = start[k]; i < start[k + 1]; ++i)
            visit_cell(mesh, cells[i], &vis);
        /* ascending order: the centres, hence the result, do not depend on cell order */
        qsort(list, vis.n, sizeof *list, cmp_i64);
        s = split_component(ctx, constrained, (int)k, list, vis.n, owner, &w->comp[k],
                            n_shared_free);
        if (s < 0) goto done;
        /* (only a tolerance from the mesh needs it) */
        const double spacing =
            opt->tolerance > 0
                ? 0.0
                : wall_spacing(mesh, constrained, cells + start[k], start[k + 1] - start[k]);
        if (spacing < 0) {
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
            goto done;
        }
        s = fit_component(ctx, mesh, kernel, opt, k, spacing, &w->comp[k]);
        if (s < 0) goto done;
        if ((s = cm_progress(ctx, "warp factorise", (double)(k + 1), (double)nc)) < 0) goto done;
    }
    /* nodes of no volume cell and not constrained: nothing defines their motion */
    {
        size_t stray = 0;
        for (size_t v = 0; v < nn; ++v)
            if (!stamp[v] && !constrained[v]) ++stray;
        if (stray)
            cm_log(ctx, CM_LOG_WARNING,
                   "cm_warp_create: %zu unconstrained nodes belong to no volume cell; they are "
                   "left where they are",
                   stray);
    }
done:
    free(start);
    free(cells);
    free(stamp);
    free(owner);
    free(list);
    return s;
}

static cm_status rbf_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                            const unsigned char *constrained, cm_rbf_kernel kernel,
                            const cm_warp_options *opt, void **state)
{
    if (b->n_components > (size_t)(~0u >> 1))
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_warp_create: too many components");
    rbf_warp *w = calloc(1, sizeof *w);
    if (!w) return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
    w->n_nodes = mesh->n_nodes;
    w->n_components = b->n_components;
    w->comp = calloc(b->n_components, sizeof *w->comp);
    cm_status s = CM_OK;
    if (!w->comp) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
        goto fail;
    }
    size_t n_shared_free = 0;
    s = build_components(ctx, mesh, b, constrained, kernel, opt, w, &n_shared_free);
    if (s < 0) goto fail;
    if (n_shared_free)
        cm_log(ctx, CM_LOG_WARNING,
               "cm_warp_create: %zu unconstrained nodes are shared by several components; each "
               "follows the first",
               n_shared_free);

    size_t max_points = 1;
    for (size_t k = 0; k < w->n_components; ++k)
        if (w->comp[k].n_fixed + w->comp[k].n_free > max_points)
            max_points = w->comp[k].n_fixed + w->comp[k].n_free;
    w->values = malloc(max_points * 3 * sizeof *w->values);
    w->constrained = malloc(w->n_nodes ? w->n_nodes : 1);
    if (!w->values || !w->constrained) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
        goto fail;
    }
    if (w->n_nodes) memcpy(w->constrained, constrained, w->n_nodes);
    *state = w;
    return CM_OK;
fail:
    rbf_destroy(w);
    return s;
}

/* k displacement fields (cm_warp_apply: k = 1; cm_warp_apply_many): per component, the k
 * blocks of its points side by side for one cm_deform_apply_many (3k columns in one solve and
 * one evaluation; k = 1 in the warp's own scratch). fn names the caller in messages. */
static cm_status apply_fields(cm_context *ctx, rbf_warp *warp, size_t k, double *disp,
                              const char *fn)
{
    size_t max_points = 1;
    for (size_t c = 0; c < warp->n_components; ++c)
        if (warp->comp[c].def && warp->comp[c].n_fixed + warp->comp[c].n_free > max_points)
            max_points = warp->comp[c].n_fixed + warp->comp[c].n_free;
    if (k > SIZE_MAX / (3 * sizeof(double) * max_points))
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: %zu fields are too many", fn, k);
    double *pv = k == 1 ? warp->values : malloc(k * max_points * 3 * sizeof *pv);
    if (!pv)
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory for %zu fields of %zu points", fn,
                        k, max_points);
    const size_t n3 = 3 * warp->n_nodes;
    cm_status s = CM_OK;
    for (size_t c = 0; c < warp->n_components; ++c) {
        warp_component *wc = &warp->comp[c];
        if (!wc->def) continue;
        const size_t np3 = 3 * (wc->n_fixed + wc->n_free);
        for (size_t j = 0; j < k; ++j)
            for (size_t i = 0; i < wc->n_fixed; ++i)
                memcpy(pv + j * np3 + 3 * i, disp + j * n3 + 3 * wc->fixed[i], 3 * sizeof *pv);
        double r = 0;
        s = cm_deform_apply_many(ctx, wc->def, k, pv, &r);
        if (s < 0) {
            s = cm_error_prefix(ctx, s, "%s: component %zu", fn, c);
            break;
        }
        /* the split that says where a large warp's time goes: an iterative fit's solve (its
         * Krylov matvecs, m^2 kernel pairs each) or the evaluation (n_free x m pairs) */
        cm_deform_stats st;
        cm_deform_get_stats(wc->def, &st);
        cm_log(ctx, CM_LOG_DEBUG,
               "%s: component %zu: %zu field(s), %zu centres, solve %.3f s (%s, %d iterations), "
               "evaluation at %zu nodes %.3f s (%s; %d columns combined from the others)",
               fn, c, k, wc->n_fixed, st.t_solve,
               st.rbf.solver == CM_RBF_SOLVER_DENSE ? "dense" : "iterative", st.rbf.iterations,
               wc->n_free, st.t_evaluate,
               st.rbf.solver == CM_RBF_SOLVER_DENSE || st.rbf.eval_plain ? "plain sums"
               : st.rbf.eval_fast ? "treecode" : "compensated sums", st.rbf.eval_combined);
        for (size_t j = 0; j < k; ++j) {
            const double *out = pv + j * np3 + 3 * wc->n_fixed;
            for (size_t i = 0; i < wc->n_free; ++i)
                memcpy(disp + j * n3 + 3 * wc->free_nodes[i], out + 3 * i, 3 * sizeof *pv);
        }
        if ((s = cm_progress(ctx, "warp", (double)(c + 1), (double)warp->n_components)) < 0)
            break;
    }
    if (pv != warp->values) free(pv);
    return s;
}

/* Exact at the centres: the residual is 0. */
static cm_status rbf_apply(cm_context *ctx, void *state, double *disp, double *residual)
{
    *residual = 0;
    return apply_fields(ctx, state, 1, disp, "cm_warp_apply");
}

static cm_status rbf_apply_many(cm_context *ctx, void *state, size_t k, double *disp,
                                double *residual)
{
    *residual = 0;
    return apply_fields(ctx, state, k, disp, "cm_warp_apply_many");
}

/* J^T v: apply keeps every constrained node's value (v back once), and each component's
 * free nodes send theirs back to its fixed nodes through the deformation's reverse product
 * (which adds v at the fixed nodes too: taken off again, so that a node fixed in several
 * components counts it once). */
static cm_status rbf_apply_transpose(cm_context *ctx, void *state, const double *v, double *out)
{
    rbf_warp *warp = state;
    for (size_t i = 0; i < warp->n_nodes; ++i)
        if (warp->constrained[i]) memcpy(out + 3 * i, v + 3 * i, 3 * sizeof *out);
    size_t max_points = 1;
    for (size_t k = 0; k < warp->n_components; ++k)
        if (warp->comp[k].n_fixed + warp->comp[k].n_free > max_points)
            max_points = warp->comp[k].n_fixed + warp->comp[k].n_free;
    double *po = malloc(max_points * 3 * sizeof *po);
    if (!po) return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_apply_transpose: out of memory");
    double *pv = warp->values;
    cm_status s = CM_OK;
    for (size_t k = 0; k < warp->n_components; ++k) {
        warp_component *wc = &warp->comp[k];
        if (!wc->def) continue;
        for (size_t i = 0; i < wc->n_fixed; ++i)
            memcpy(pv + 3 * i, v + 3 * wc->fixed[i], 3 * sizeof(double));
        for (size_t i = 0; i < wc->n_free; ++i)
            memcpy(pv + 3 * (wc->n_fixed + i), v + 3 * wc->free_nodes[i], 3 * sizeof(double));
        s = cm_deform_apply_transpose(ctx, wc->def, pv, po);
        if (s < 0) {
            s = cm_error_prefix(ctx, s, "cm_warp_apply_transpose: component %zu", k);
            break;
        }
        cm_deform_stats st;
        cm_deform_get_stats(wc->def, &st);
        cm_log(ctx, CM_LOG_DEBUG,
               "cm_warp_apply_transpose: component %zu: %zu centres, %zu free nodes, "
               "transposed evaluation and solve %.3f s (%s, %d iterations)",
               k, wc->n_fixed, wc->n_free, st.t_solve,
               st.rbf.solver == CM_RBF_SOLVER_DENSE ? "dense" : "iterative", st.rbf.iterations);
        for (size_t i = 0; i < wc->n_fixed; ++i)
            for (int c = 0; c < 3; ++c) out[3 * wc->fixed[i] + c] += po[3 * i + c] - pv[3 * i + c];
        if ((s = cm_progress(ctx, "warp", (double)(k + 1), (double)warp->n_components)) < 0)
            break;
    }
    free(po);
    return s;
}

static cm_status triharmonic_create(cm_context *ctx, const cm_mesh *mesh,
                                    const cm_mesh_boundary *b, const unsigned char *constrained,
                                    const cm_warp_options *opt, void **state)
{
    return rbf_create(ctx, mesh, b, constrained, CM_RBF_TRIHARMONIC, opt, state);
}

static cm_status biharmonic_create(cm_context *ctx, const cm_mesh *mesh,
                                   const cm_mesh_boundary *b, const unsigned char *constrained,
                                   const cm_warp_options *opt, void **state)
{
    return rbf_create(ctx, mesh, b, constrained, CM_RBF_BIHARMONIC, opt, state);
}

/* the tightest of the components' tolerances (0: no component has a fit) */
static double rbf_tolerance(const void *state)
{
    const rbf_warp *w = state;
    double t = INFINITY;
    for (size_t k = 0; k < w->n_components; ++k)
        if (w->comp[k].def) t = fmin(t, w->comp[k].tolerance);
    return t < INFINITY ? t : 0.0;
}

const cm_warp_method_ops cm_warp_rbf_triharmonic = {
    "rbf", triharmonic_create, rbf_apply, rbf_destroy, NULL, rbf_apply_transpose,
    rbf_apply_many, rbf_tolerance};
const cm_warp_method_ops cm_warp_rbf_biharmonic = {
    "rbf-biharmonic", biharmonic_create, rbf_apply, rbf_destroy, NULL, rbf_apply_transpose,
    rbf_apply_many, rbf_tolerance};
