/* Classification of the boundary nodes of a volume mesh against the CAD model G (paper
 * section 4): vertex, else edge (t, s), else face (u, v), with a tolerance relative to the
 * local mesh size; nodes off G are a mismatch whose message hints at a unit error. */
#include "surface_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cm_classify_options_init(cm_classify_options *opt)
{
    opt->rel_tol = 1e-6;
    opt->abs_tol = 1e-9;
    opt->keep_off = 0;
}

void cm_surface_nodes_destroy(cm_surface_nodes **p)
{
    if (!p || !*p) return;
    cm_surface_nodes *s = *p;
    free(s->node);
    free(s->xyz);
    free(s->kind);
    free(s->entity);
    free(s->param);
    free(s->dist);
    free(s->h);
    free(s->off);
    free(s->off_dist);
    free(s);
    *p = NULL;
}

/* Index of node in the ascending list b->nodes, -1 if absent. */
static int64_t boundary_index(const cm_mesh_boundary *b, int64_t node)
{
    size_t lo = 0, hi = b->n_nodes;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (b->nodes[mid] < node)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < b->n_nodes && b->nodes[lo] == node ? (int64_t)lo : -1;
}

cm_status cm_surface_edge_lengths(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                                  double *h_node, double *h_min)
{
    if (!mesh || !b) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_surface_edge_lengths: NULL input");
    double global = INFINITY;
    if (h_node)
        for (size_t i = 0; i < b->n_nodes; ++i)
            h_node[i] = INFINITY;
    for (size_t f = 0; f < b->n_faces; ++f) {
        int64_t a = b->face_offset[f], e = b->face_offset[f + 1];
        for (int64_t k = a; k < e; ++k) {
            int64_t p = b->face_nodes[k], q = b->face_nodes[k + 1 < e ? k + 1 : a];
            const double *x = mesh->xyz + 3 * p, *y = mesh->xyz + 3 * q;
            double l = sqrt((x[0] - y[0]) * (x[0] - y[0]) + (x[1] - y[1]) * (x[1] - y[1]) +
                            (x[2] - y[2]) * (x[2] - y[2]));
            if (!(l > 0)) continue;
            if (l < global) global = l;
            if (!h_node) continue;
            int64_t ip = boundary_index(b, p), iq = boundary_index(b, q);
            if (ip >= 0 && l < h_node[ip]) h_node[ip] = l;
            if (iq >= 0 && l < h_node[iq]) h_node[iq] = l;
        }
    }
    if (!isfinite(global)) global = 0;
    if (h_node)
        for (size_t i = 0; i < b->n_nodes; ++i)
            if (!isfinite(h_node[i])) h_node[i] = global;
    if (h_min) *h_min = global;
    return CM_OK;
}

static cm_surface_nodes *nodes_alloc(size_t n)
{
    cm_surface_nodes *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    size_t m = n ? n : 1;
    s->n = n;
    s->node = malloc(m * sizeof *s->node);
    s->xyz = malloc(3 * m * sizeof *s->xyz);
    s->kind = malloc(m);
    s->entity = malloc(m * sizeof *s->entity);
    s->param = calloc(2 * m, sizeof *s->param);
    s->dist = malloc(m * sizeof *s->dist);
    s->h = malloc(m * sizeof *s->h);
    if (!s->node || !s->xyz || !s->kind || !s->entity || !s->param || !s->dist || !s->h)
        cm_surface_nodes_destroy(&s);
    return s;
}

/* Millimetres per unit of the names cm_cad_read_options.unit accepts. */
static const struct {
    const char *name;
    double mm;
} units[] = {{"um", 1e-3},  {"mm", 1},   {"cm", 10},  {"in", 25.4},
             {"ft", 304.8}, {"m", 1000}, {"km", 1e6}, {"mi", 1609344}};

/* "; the mesh is 1000x smaller than the model: a unit mismatch? (mesh in m: read the CAD in
 * m)" when the sizes of the boundary and the model differ by the ratio of two units; ""
 * otherwise. */
static void unit_hint(const cm_surface_nodes *s, const cm_cad_model *g, char *out, size_t len)
{
    double bb[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY}, cb[6];
    for (size_t i = 0; i < s->n; ++i)
        for (int k = 0; k < 3; ++k) {
            double x = s->xyz[3 * i + k];
            if (x < bb[k]) bb[k] = x;
            if (x > bb[k + 3]) bb[k + 3] = x;
        }
    cm_cad_bbox(g, cb);
    out[0] = 0;
    double dm = cm_bbox_diagonal(bb), dg = cm_bbox_diagonal(cb), model_mm = 0;
    if (!(dm > 0) || !(dg > 0)) return;
    const size_t nu = sizeof units / sizeof *units;
    for (size_t i = 0; i < nu; ++i)
        if (!strcmp(units[i].name, cm_cad_unit(g))) model_mm = units[i].mm;
    if (!(model_mm > 0)) return;
    /* mesh values = model values x r, so one mesh unit is model unit / r */
    double r = dm / dg, mesh_mm = model_mm / r;
    for (size_t i = 0; i < nu; ++i) {
        if (units[i].mm == model_mm || fabs(mesh_mm / units[i].mm - 1) > 0.05) continue;
        if (r > 1)
            snprintf(out, len,
                     "; the mesh is %.4gx larger than the model: a unit mismatch? "
                     "(mesh in %s: read the CAD in %s)",
                     r, units[i].name, units[i].name);
        else
            snprintf(out, len,
                     "; the mesh is %.4gx smaller than the model: a unit mismatch? "
                     "(mesh in %s: read the CAD in %s)",
                     1 / r, units[i].name, units[i].name);
        return;
    }
}

/* Arc length s of the edge nodes, one call per edge. */
static cm_status edge_arc_lengths(cm_context *ctx, const cm_cad_model *g, cm_surface_nodes *s)
{
    cm_cad_counts c;
    cm_cad_get_counts(g, &c);
    size_t *first = NULL, *idx = NULL;
    cm_status st = cm_surface_group(ctx, s, CM_SURFACE_ON_EDGE, c.edges, &first, &idx);
    if (st < 0) return st;
    size_t ne = first[c.edges > 0 ? c.edges : 0];
    double *t = malloc(2 * (ne ? ne : 1) * sizeof *t);
    if (!t) st = cm_error(ctx, CM_ERR_NOMEM, "cm_surface_classify: out of memory");
    for (int e = 0; e < c.edges && st == CM_OK; ++e) {
        size_t a = first[e], k = first[e + 1] - a;
        if (!k) continue;
        for (size_t j = 0; j < k; ++j)
            t[j] = s->param[2 * idx[a + j]];
        st = cm_cad_edge_t_to_s(ctx, g, e, t, k, t + ne);
        for (size_t j = 0; j < k && st == CM_OK; ++j)
            s->param[2 * idx[a + j] + 1] = t[ne + j];
    }
    free(first);
    free(idx);
    free(t);
    return st;
}

/* Nodes still unclassified (kind 255) whose location `dist` is within tolerance take `kind`. */
static void take(cm_surface_nodes *s, const size_t *rest, size_t nr, const double *tol,
                 unsigned char kind, const int *ent, const double *par, const double *dist)
{
    for (size_t j = 0; j < nr; ++j) {
        size_t i = rest[j];
        if (!(dist[j] <= tol[i])) continue;
        s->kind[i] = kind;
        s->entity[i] = ent[j];
        s->dist[i] = dist[j];
        if (kind == CM_SURFACE_ON_FACE) {
            s->param[2 * i] = par[2 * j];
            s->param[2 * i + 1] = par[2 * j + 1];
        } else if (kind == CM_SURFACE_ON_EDGE) {
            s->param[2 * i] = par[j];
        }
    }
}

/* keep_off: the nodes still unclassified after the face pass (rest[0..nr), their face
 * distances in dist) move to s->off / s->off_dist, and the classified ones close up (the order,
 * ascending node, is kept). */
static cm_status set_aside_off(cm_context *ctx, cm_surface_nodes *s, const size_t *rest,
                               size_t nr, const double *dist, size_t off)
{
    s->off = malloc(off * sizeof *s->off);
    s->off_dist = malloc(off * sizeof *s->off_dist);
    if (!s->off || !s->off_dist)
        return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_classify: out of memory");
    size_t k = 0;
    for (size_t j = 0; j < nr; ++j) /* rest is ascending in i, so off is ascending in node */
        if (s->kind[rest[j]] == 255) {
            s->off[k] = s->node[rest[j]];
            s->off_dist[k++] = dist[j];
        }
    s->n_off = off;
    size_t m = 0;
    for (size_t i = 0; i < s->n; ++i) {
        if (s->kind[i] == 255) continue;
        s->node[m] = s->node[i];
        memcpy(s->xyz + 3 * m, s->xyz + 3 * i, 3 * sizeof *s->xyz);
        s->kind[m] = s->kind[i];
        s->entity[m] = s->entity[i];
        s->param[2 * m] = s->param[2 * i];
        s->param[2 * m + 1] = s->param[2 * i + 1];
        s->dist[m] = s->dist[i];
        s->h[m] = s->h[i];
        ++m;
    }
    s->n = m;
    return CM_OK;
}

/* Nodes per call of a locate in a pass: each is a Newton projection with OpenCASCADE (tens
 * of microseconds), so 10^5 nodes are about a second; a progress point between chunks lets
 * the caller stop there. The nodes are independent: the same results as in one call. */
#define CM_CLASSIFY_CHUNK 8192

/* cm_cad_locate_edges (pass 1: par n) or cm_cad_locate_faces (pass 2: par n x 2) of q (n x
 * 3) in chunks, with progress "classify" between them. */
static cm_status locate_chunks(cm_context *ctx, const cm_cad_locator *locator, int pass,
                               const double *q, size_t n, int *ent, double *par, double *dist)
{
    cm_status st = CM_OK, warned = CM_OK; /* a chunk's warning stays the result */
    for (size_t j0 = 0; j0 < n; j0 += CM_CLASSIFY_CHUNK) {
        const size_t k = n - j0 < CM_CLASSIFY_CHUNK ? n - j0 : CM_CLASSIFY_CHUNK;
        if (j0 > 0) {
            cm_status p = cm_progress(ctx, "classify", pass + (double)j0 / (double)n, 3);
            if (p < 0) return p;
        }
        st = pass == 1 ? cm_cad_locate_edges(ctx, locator, q + 3 * j0, k, ent + j0, par + j0,
                                             dist + j0)
                       : cm_cad_locate_faces(ctx, locator, q + 3 * j0, k, ent + j0,
                                             par + 2 * j0, dist + j0, NULL);
        if (st < 0) return st;
        if (st > 0) warned = st;
    }
    return warned;
}

cm_status cm_surface_classify(cm_context *ctx, const cm_cad_model *g, const cm_cad_locator *locator,
                              const cm_mesh *mesh, const cm_mesh_boundary *b,
                              const cm_classify_options *opt, cm_surface_nodes **out)
{
    const char *fn = "cm_surface_classify";
    if (out) *out = NULL;
    if (!g || !locator || !mesh || !b || !out)
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL input", fn);
    cm_classify_options o;
    cm_classify_options_init(&o);
    if (opt) o = *opt;
    size_t n = b->n_nodes;
    if (!n) return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: the mesh has no boundary nodes", fn);
    cm_surface_nodes *s = nodes_alloc(n);
    double *tol = malloc(n * sizeof *tol), *q = malloc(3 * n * sizeof *q);
    double *dist = malloc(n * sizeof *dist), *par = malloc(2 * n * sizeof *par);
    int *ent = malloc(n * sizeof *ent);
    size_t *rest = malloc(n * sizeof *rest);
    cm_status st = CM_OK;
    if (!s || !tol || !q || !dist || !par || !ent || !rest) {
        st = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory for %zu nodes", fn, n);
        goto done;
    }
    double cb[6];
    cm_cad_bbox(g, cb);
    double diag = cm_bbox_diagonal(cb);
    st = cm_surface_edge_lengths(ctx, mesh, b, s->h, NULL);
    if (st < 0) goto done;
    for (size_t i = 0; i < n; ++i) {
        s->node[i] = b->nodes[i];
        memcpy(s->xyz + 3 * i, mesh->xyz + 3 * b->nodes[i], 3 * sizeof(double));
        s->kind[i] = 255;
        tol[i] = o.rel_tol * s->h[i] + o.abs_tol * diag;
        rest[i] = i;
    }
    cm_cad_counts c;
    cm_cad_get_counts(g, &c);
    size_t nr = n;
    for (int pass = 0; pass < 3 && nr; ++pass) {
        for (size_t j = 0; j < nr; ++j)
            memcpy(q + 3 * j, s->xyz + 3 * rest[j], 3 * sizeof(double));
        if ((st = cm_progress(ctx, "classify", pass, 3)) < 0) goto done;
        if (pass == 0 && c.vertices > 0) {
            st = cm_cad_locate_vertices(ctx, locator, q, nr, ent, dist);
            if (st < 0) goto done;
            take(s, rest, nr, tol, CM_SURFACE_ON_VERTEX, ent, par, dist);
        } else if (pass == 1 && c.edges > 0) {
            st = locate_chunks(ctx, locator, 1, q, nr, ent, par, dist);
            if (st < 0) goto done;
            take(s, rest, nr, tol, CM_SURFACE_ON_EDGE, ent, par, dist);
        } else if (pass == 2) {
            st = locate_chunks(ctx, locator, 2, q, nr, ent, par, dist);
            if (st < 0) goto done;
            take(s, rest, nr, tol, CM_SURFACE_ON_FACE, ent, par, dist);
            /* what is left is off G: report count, worst node and a unit hint */
            size_t off = 0, worst = 0;
            double wd = -1;
            for (size_t j = 0; j < nr; ++j)
                if (s->kind[rest[j]] == 255) {
                    ++off;
                    if (dist[j] > wd) wd = dist[j], worst = rest[j];
                }
            if (off && o.keep_off && off < n) {
                st = set_aside_off(ctx, s, rest, nr, dist, off);
                if (st < 0) goto done;
            } else if (off) {
                char hint[192];
                unit_hint(s, g, hint, sizeof hint);
                st = cm_error(ctx, CM_ERR_MISMATCH,
                              "%zu of %zu boundary nodes are off the CAD model (worst: node %lld "
                              "at distance %.6g %s, tolerance %.3g)%s",
                              off, n, (long long)s->node[worst], wd, cm_cad_unit(g), tol[worst],
                              hint);
                goto done;
            }
        }
        if (pass == 2) break; /* every node classified or set aside (rest is stale) */
        size_t k = 0;
        for (size_t j = 0; j < nr; ++j)
            if (s->kind[rest[j]] == 255) rest[k++] = rest[j];
        nr = k;
    }
    if ((st = cm_progress(ctx, "classify", 3, 3)) < 0) goto done;
    st = edge_arc_lengths(ctx, g, s);
    if (st < 0) goto done;
    for (size_t i = 0; i < s->n; ++i) {
        if (s->kind[i] == CM_SURFACE_ON_VERTEX) s->param[2 * i] = s->param[2 * i + 1] = 0;
        s->count[s->kind[i]]++;
        if (s->dist[i] > s->max_dist) s->max_dist = s->dist[i];
    }
done:
    free(tol);
    free(q);
    free(dist);
    free(par);
    free(ent);
    free(rest);
    if (st < 0)
        cm_surface_nodes_destroy(&s);
    else
        *out = s;
    return st;
}
