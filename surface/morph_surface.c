/* The CAD-aware surface morph G -> G' (paper section 4): vertex nodes to the matching vertex,
 * edge nodes to the same arc length, face nodes by a 2D thin-plate warp of their (u,v) fitted
 * on corresponding boundary samples of f_k and f'_k; or, as a baseline, closest points.
 * Edges and faces that an affine edit maps onto G' take the affine image (affine.c). */
#include "surface_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cm_surface_morph_options_init(cm_surface_morph_options *opt)
{
    opt->method = CM_SURFACE_RBF;
    opt->spacing = 0;
    opt->min_per_edge = 8;
    opt->max_per_edge = 200;
    opt->affine_tol = 1e-9;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Per face of G: its boundary samples and the thin-plate system of its parameter warp on
 * their (u,v), factorised. Neither depends on G': a study of many targets factors each face
 * once and pays per target only the samples of G', one solve and the evaluation
 * (docs/DESIGN.md, "Surface morph across targets"). */
typedef struct face_fit {
    cm_cad_boundary *ba;
    cm_rbf *rbf;
} face_fit;

struct cm_surface_morph_cache {
    /* the key: what everything below was computed from */
    const cm_cad_model *g;
    const cm_surface_nodes *s;
    size_t n;
    double spacing;
    int min_per_edge, max_per_edge;
    int filled;
    int faces;
    int *per_edge;                 /* boundary samples per edge */
    size_t *first[3], *idx[3];     /* the nodes grouped by vertex, edge, face */
    face_fit *face;                /* faces entries, filled when a face is first warped */
};

cm_status cm_surface_morph_cache_create(cm_context *ctx, cm_surface_morph_cache **cache)
{
    if (!cache) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_surface_morph_cache_create: NULL output");
    *cache = calloc(1, sizeof **cache);
    return *cache ? CM_OK
                  : cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph_cache_create: out of memory");
}

void cm_surface_morph_cache_clear(cm_surface_morph_cache *c)
{
    if (!c) return;
    for (int f = 0; c->face && f < c->faces; ++f) {
        cm_cad_boundary_destroy(&c->face[f].ba);
        cm_rbf_destroy(&c->face[f].rbf);
    }
    free(c->face);
    free(c->per_edge);
    for (int k = 0; k < 3; ++k) {
        free(c->first[k]);
        free(c->idx[k]);
    }
    memset(c, 0, sizeof *c);
}

void cm_surface_morph_cache_destroy(cm_surface_morph_cache **cache)
{
    if (!cache || !*cache) return;
    cm_surface_morph_cache_clear(*cache);
    free(*cache);
    *cache = NULL;
}

/* Boundary samples per edge: about length / spacing, from G's lengths so G and G' agree. */
static cm_status samples_per_edge(cm_context *ctx, const cm_cad_model *g, const cm_surface_nodes *s,
                                  const cm_surface_morph_options *o, int *per_edge)
{
    double spacing = o->spacing;
    if (!(spacing > 0) && s->n) {
        double *h = malloc(s->n * sizeof *h);
        if (!h) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
        memcpy(h, s->h, s->n * sizeof *h);
        qsort(h, s->n, sizeof *h, cmp_double);
        spacing = h[s->n / 2];
        free(h);
    }
    if (!(spacing > 0)) {
        double bb[6];
        cm_cad_bbox(g, bb);
        spacing = cm_bbox_diagonal(bb) / 100;
    }
    cm_cad_counts c;
    cm_cad_get_counts(g, &c);
    for (int e = 0; e < c.edges; ++e) {
        cm_cad_edge_info ei;
        cm_status st = cm_cad_edge_get_info(ctx, g, e, &ei);
        if (st < 0) return st;
        double k = ei.degenerate ? 0 : ceil(ei.length / spacing);
        if (k < o->min_per_edge) k = o->min_per_edge;
        if (k > o->max_per_edge) k = o->max_per_edge;
        per_edge[e] = (int)k;
    }
    return CM_OK;
}

/* Periodic parameters of G' may sit a whole period away from G's (another pcurve of the same
 * seam, another range): shift each run of samples of one edge by the multiple of the period
 * that brings it closest to G's run. Runs, not single samples, so that a legitimately large
 * change inside a run is never cut at half a period. */
static void unwrap_runs(const cm_cad_boundary *a, cm_cad_boundary *b, const cm_cad_face_info *fi)
{
    for (int d = 0; d < 2; ++d) {
        if (!fi->periodic[d] || !(fi->period[d] > 0)) continue;
        double P = fi->period[d];
        for (size_t i = 0; i < a->n;) {
            size_t j = i;
            double sum = 0;
            while (j < a->n && a->edge[j] == a->edge[i] && a->wire[j] == a->wire[i]) {
                sum += b->uv[2 * j + d] - a->uv[2 * j + d];
                ++j;
            }
            double shift = -P * round(sum / (double)(j - i) / P);
            for (size_t k = i; k < j; ++k)
                b->uv[2 * k + d] += shift;
            i = j;
        }
    }
}

/* The affine images of G's boundary samples ba on face f of G': for each sample the
 * parameter of its image on the edge of G' (NaN at the edge's ends, where the vertices match
 * and a projection could pick either end of a closed edge), then the samples there. */
static cm_status affine_boundary(cm_context *ctx, const cm_cad_model *g2, int f,
                                 const int *per_edge, const cm_surface_affine *aff,
                                 const cm_cad_boundary *ba, cm_cad_boundary **bb)
{
    double *t = malloc((ba->n ? ba->n : 1) * 4 * sizeof *t);
    if (!t) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    double *y = t + ba->n;
    cm_status r = CM_OK;
    for (size_t i = 0; i < ba->n && r >= 0;) {
        size_t j = i;
        while (j < ba->n && ba->edge[j] == ba->edge[i] && ba->wire[j] == ba->wire[i])
            ++j;
        cm_cad_edge_info ei;
        r = cm_cad_edge_get_info(ctx, g2, ba->edge[i], &ei);
        for (size_t q = i; q < j && r >= 0; ++q)
            cm_surface_affine_apply(aff, ba->xyz + 3 * q, y + 3 * (q - i));
        if (r >= 0 && !ei.degenerate)
            r = cm_cad_project_edge(ctx, g2, ba->edge[i], y, j - i, t + i, NULL);
        for (size_t q = i; q < j; ++q)
            if (ei.degenerate || ba->s[q] <= 0 || ba->s[q] >= 1) t[q] = NAN;
        i = j;
    }
    if (r >= 0) r = cm_cad_face_boundary_at(ctx, g2, f, per_edge, 0, t, bb);
    free(t);
    return r < 0 ? r : CM_OK;
}

/* Face nodes of an affine face (surface/affine.c): the projection of A x + b onto f'_k, x
 * the node's foot on f_k, seeded by the parameter warp's (u',v') (uv, updated), else by a
 * grid search. 1 in *ok when every image lies on f'_k within the tolerance; nothing is
 * written otherwise. */
static cm_status affine_face(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2, int f,
                             const cm_surface_affine *aff, const cm_surface_nodes *s,
                             const size_t *idx, size_t k, double *uv, double *xyz, int *ok)
{
    *ok = 0;
    double *w = malloc(k * 12 * sizeof *w);
    if (!w) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    double *x = w, *y = x + 3 * k, *foot = y + 3 * k, *uv0 = foot + 3 * k, *dist = uv0 + 2 * k;
    for (size_t j = 0; j < k; ++j)
        memcpy(uv0 + 2 * j, s->param + 2 * idx[j], 2 * sizeof(double));
    cm_status r = cm_cad_face_eval(ctx, g, f, uv0, k, x, NULL);
    for (size_t j = 0; j < k && r >= 0; ++j)
        cm_surface_affine_apply(aff, x + 3 * j, y + 3 * j);
    double *uv1 = uv0; /* reused: the parameters of the feet */
    if (r >= 0) r = cm_cad_project_face(ctx, g2, f, y, k, uv, uv1, dist, foot);
    int all = r >= 0;
    for (size_t j = 0; j < k && r >= 0; ++j) {
        if (dist[j] <= aff->tol) continue;
        /* the warp's seed led Newton elsewhere: search the face */
        double u2[2], d2, f2[3];
        r = cm_cad_project_face(ctx, g2, f, y + 3 * j, 1, NULL, u2, &d2, f2);
        if (r >= 0 && d2 <= aff->tol) {
            memcpy(uv1 + 2 * j, u2, sizeof u2);
            memcpy(foot + 3 * j, f2, sizeof f2);
        } else {
            all = 0;
            break;
        }
    }
    if (r >= 0 && all) {
        for (size_t j = 0; j < k; ++j) {
            memcpy(xyz + 3 * idx[j], foot + 3 * j, 3 * sizeof(double));
            memcpy(uv + 2 * j, uv1 + 2 * j, 2 * sizeof(double));
        }
        *ok = 1;
    }
    free(w);
    return r < 0 ? r : CM_OK;
}

/* Face nodes idx[0..k) of face f: warp their (u,v), evaluate f'_k; those that left the
 * trimmed domain go to the closest point of f'_k. When every edge of f is an affine image
 * (affine: the edge flags, NULL if none), the warp is fitted on the images of G's boundary
 * samples and the nodes go to the images of their feet if f is an affine image too. */
static cm_status morph_face(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2, int f,
                            const int *per_edge, const cm_surface_nodes *s, const size_t *idx,
                            size_t k, double *xyz, cm_surface_morph_stats *st,
                            const cm_surface_affine *aff, const int *affine_edge, face_fit *ff)
{
    cm_cad_boundary *bb = NULL;
    double *uv = malloc(2 * k * sizeof *uv), *d = malloc(2 * k * sizeof *d);
    double *p = malloc(3 * k * sizeof *p), *values = NULL;
    int *inside = malloc(k * sizeof *inside);
    cm_status r = uv && d && p && inside
                      ? CM_OK
                      : cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    cm_cad_face_info fi;
    if (r == CM_OK) r = cm_cad_face_get_info(ctx, g2, f, &fi);
    if (r == CM_OK && !ff->ba) r = cm_cad_face_boundary(ctx, g, f, per_edge, 0, &ff->ba);
    const cm_cad_boundary *ba = ff->ba;
    int candidate = affine_edge != NULL && r == CM_OK;
    for (size_t j = 0; candidate && j < ba->n; ++j)
        if (!affine_edge[ba->edge[j]]) candidate = 0;
    if (r == CM_OK)
        r = candidate ? affine_boundary(ctx, g2, f, per_edge, aff, ba, &bb)
                      : cm_cad_face_boundary(ctx, g2, f, per_edge, 0, &bb);
    if (r == CM_OK && ba->n != bb->n)
        r = cm_error(ctx, CM_ERR_MISMATCH, "face %d: %zu boundary samples in G, %zu in G'", f,
                     ba->n, bb->n);
    if (r == CM_OK && !(values = malloc(2 * ba->n * sizeof *values)))
        r = cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    if (r == CM_OK) {
        unwrap_runs(ba, bb, &fi);
        for (size_t i = 0; i < 2 * ba->n; ++i)
            values[i] = bb->uv[i] - ba->uv[i];
        for (size_t j = 0; j < k; ++j)
            memcpy(uv + 2 * j, s->param + 2 * idx[j], 2 * sizeof(double));
        if (!ff->rbf) r = cm_rbf_create(ctx, CM_RBF_THIN_PLATE, 2, ba->n, ba->uv, &ff->rbf);
        /* the factor of create serves every target: a solve is two triangular solves */
        if (r >= 0) r = cm_rbf_solve(ctx, ff->rbf, 2, values);
        if (r >= 0) r = cm_rbf_evaluate(ctx, ff->rbf, k, uv, d);
        if (r < 0) r = cm_error_prefix(ctx, r, "face %d: parameter warp", f);
    }
    if (r >= 0) {
        for (size_t j = 0; j < 2 * k; ++j)
            uv[j] += d[j];
    }
    int done = 0;
    if (r >= 0 && candidate) {
        r = affine_face(ctx, g, g2, f, aff, s, idx, k, uv, xyz, &done);
        st->faces_affine += (size_t)done;
    }
    if (r >= 0 && !done) r = cm_cad_face_inside(ctx, g2, f, uv, k, inside);
    if (r >= 0 && !done) r = cm_cad_face_eval(ctx, g2, f, uv, k, p, NULL);
    for (size_t j = 0; j < k && r >= 0 && !done; ++j) {
        memcpy(xyz + 3 * idx[j], p + 3 * j, 3 * sizeof(double));
        if (inside[j]) continue;
        double foot[3], dist;
        r = cm_cad_project_face(ctx, g2, f, p + 3 * j, 1, uv + 2 * j, NULL, &dist, foot);
        if (r < 0) break;
        memcpy(xyz + 3 * idx[j], foot, sizeof foot);
        st->outside++;
        if (dist > st->worst_outside_dist || st->worst_outside_node < 0) {
            st->worst_outside_dist = dist;
            st->worst_outside_node = s->node[idx[j]];
        }
    }
    cm_cad_boundary_destroy(&bb);
    free(uv);
    free(d);
    free(p);
    free(values);
    free(inside);
    return r;
}

/* Edge nodes: rbf keeps their arc length s, or on an edge that is an affine image (aff not
 * NULL) takes the image A x + b of their foot x on G; project takes the closest point on the
 * edge. */
static cm_status morph_edge(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2, int e,
                            cm_surface_method m, const cm_surface_affine *aff,
                            const cm_surface_nodes *s, const size_t *idx, size_t k, double *xyz)
{
    double *t = malloc(k * sizeof *t), *q = malloc(3 * k * sizeof *q),
           *p = malloc(3 * k * sizeof *p);
    cm_status r =
        t && q && p ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    if (r == CM_OK && m == CM_SURFACE_RBF && aff) {
        for (size_t j = 0; j < k; ++j)
            t[j] = s->param[2 * idx[j]];
        r = cm_cad_edge_eval(ctx, g, e, t, k, p);
        for (size_t j = 0; j < k && r >= 0; ++j)
            cm_surface_affine_apply(aff, p + 3 * j, q + 3 * j);
        if (r >= 0) r = cm_cad_project_edge(ctx, g2, e, q, k, t, NULL);
    } else if (r == CM_OK && m == CM_SURFACE_RBF) {
        for (size_t j = 0; j < k; ++j)
            q[j] = s->param[2 * idx[j] + 1];
        r = cm_cad_edge_s_to_t(ctx, g2, e, q, k, t);
    } else if (r == CM_OK) {
        for (size_t j = 0; j < k; ++j)
            memcpy(q + 3 * j, s->xyz + 3 * idx[j], 3 * sizeof(double));
        r = cm_cad_project_edge(ctx, g2, e, q, k, t, NULL);
    }
    if (r >= 0) r = cm_cad_edge_eval(ctx, g2, e, t, k, p);
    for (size_t j = 0; j < k && r >= 0; ++j)
        memcpy(xyz + 3 * idx[j], p + 3 * j, 3 * sizeof(double));
    free(t);
    free(q);
    free(p);
    return r;
}

/* Face nodes of the baseline: closest point on the matching face of G'. */
static cm_status project_face(cm_context *ctx, const cm_cad_model *g2, int f,
                              const cm_surface_nodes *s, const size_t *idx, size_t k, double *xyz)
{
    double *q = malloc(3 * k * sizeof *q), *p = malloc(3 * k * sizeof *p);
    cm_status r = q && p ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    for (size_t j = 0; j < k && r == CM_OK; ++j)
        memcpy(q + 3 * j, s->xyz + 3 * idx[j], 3 * sizeof(double));
    if (r == CM_OK) r = cm_cad_project_face(ctx, g2, f, q, k, NULL, NULL, NULL, p);
    for (size_t j = 0; j < k && r >= 0; ++j)
        memcpy(xyz + 3 * idx[j], p + 3 * j, 3 * sizeof(double));
    free(q);
    free(p);
    return r;
}

/* The cache for g, s and the sampling options o: kept when it was made for them, else emptied
 * and refilled with the nodes' groups and the samples per edge (the faces' fits come on
 * first use, in morph_face). */
static cm_status cache_prepare(cm_context *ctx, cm_surface_morph_cache *c, const cm_cad_model *g,
                               const cm_surface_nodes *s, const cm_surface_morph_options *o,
                               const cm_cad_counts *cc)
{
    if (c->filled && c->g == g && c->s == s && c->n == s->n && c->spacing == o->spacing &&
        c->min_per_edge == o->min_per_edge && c->max_per_edge == o->max_per_edge &&
        c->faces == cc->faces)
        return CM_OK;
    cm_surface_morph_cache_clear(c);
    int count[3] = {cc->vertices, cc->edges, cc->faces};
    c->per_edge = malloc((cc->edges > 0 ? (size_t)cc->edges : 1) * sizeof *c->per_edge);
    c->face = calloc(cc->faces > 0 ? (size_t)cc->faces : 1, sizeof *c->face);
    c->faces = cc->faces;
    cm_status r = c->per_edge && c->face
                      ? CM_OK
                      : cm_error(ctx, CM_ERR_NOMEM, "cm_surface_morph: out of memory");
    for (int k = 0; k < 3 && r == CM_OK; ++k)
        r = cm_surface_group(ctx, s, (cm_surface_kind)k, count[k], &c->first[k], &c->idx[k]);
    if (r == CM_OK) r = samples_per_edge(ctx, g, s, o, c->per_edge);
    if (r != CM_OK) {
        cm_surface_morph_cache_clear(c);
        return r;
    }
    c->g = g, c->s = s, c->n = s->n;
    c->spacing = o->spacing, c->min_per_edge = o->min_per_edge, c->max_per_edge = o->max_per_edge;
    c->filled = 1;
    return CM_OK;
}

cm_status cm_surface_morph(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                           const cm_surface_nodes *s, const cm_surface_morph_options *opt,
                           double *xyz, cm_surface_morph_stats *stats)
{
    return cm_surface_morph_cached(ctx, NULL, g, g2, s, opt, xyz, stats);
}

cm_status cm_surface_morph_cached(cm_context *ctx, cm_surface_morph_cache *cache,
                                  const cm_cad_model *g, const cm_cad_model *g2,
                                  const cm_surface_nodes *s, const cm_surface_morph_options *opt,
                                  double *xyz, cm_surface_morph_stats *stats)
{
    const char *fn = "cm_surface_morph";
    cm_surface_morph_stats st = {0, 0, 0, -1, 0, 0, 0, 0, INFINITY};
    if (stats) *stats = st;
    if (!g || !g2 || !s || !xyz) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL input", fn);
    cm_surface_morph_options o;
    cm_surface_morph_options_init(&o);
    if (opt) o = *opt;
    if (o.min_per_edge < 2 || o.max_per_edge < o.min_per_edge)
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: samples per edge must satisfy 2 <= min <= max",
                        fn);
    cm_cad_counts c, c2;
    cm_cad_get_counts(g, &c);
    cm_cad_get_counts(g2, &c2);
    if (c.faces != c2.faces || c.edges != c2.edges || c.vertices != c2.vertices)
        return cm_error(ctx, CM_ERR_MISMATCH, "%s: G and G' have different topology", fn);
    /* without a cache of the caller's, one for this call: the same code either way */
    cm_surface_morph_cache local;
    memset(&local, 0, sizeof local);
    cm_surface_morph_cache *cache_used = cache ? cache : &local;
    cm_status r = cache_prepare(ctx, cache_used, g, s, &o, &c);
    size_t *const *first = cache_used->first, *const *idx = cache_used->idx;
    const int *per_edge = cache_used->per_edge;
    /* affine edits: the map from the vertices, then which edges it maps onto G' */
    cm_surface_affine aff;
    int *affine_edge = NULL;
    memset(&aff, 0, sizeof aff);
    if (r == CM_OK && o.method == CM_SURFACE_RBF && o.affine_tol > 0) {
        double bb[6];
        cm_cad_bbox(g2, bb);
        r = cm_surface_affine_fit(ctx, g, g2, o.affine_tol * cm_bbox_diagonal(bb), &aff);
        st.affine_residual = aff.residual;
        st.affine = aff.valid;
    }
    if (r == CM_OK && aff.valid) {
        affine_edge = calloc(c.edges > 0 ? (size_t)c.edges : 1, sizeof *affine_edge);
        if (!affine_edge) r = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", fn);
        for (int e = 0; e < c.edges && r == CM_OK; ++e) {
            r = cm_surface_affine_edge(ctx, g, g2, &aff, e, per_edge[e] > 16 ? per_edge[e] : 16,
                                       &affine_edge[e]);
            st.edges_affine += (size_t)affine_edge[e];
        }
        if (r == CM_OK)
            cm_log(ctx, CM_LOG_DEBUG,
                   "surface morph: the edit is affine at the vertices (residual %.3g); %zu of %d "
                   "edges are affine images",
                   aff.residual, st.edges_affine, c.edges);
    }
    for (int v = 0; v < c.vertices && r >= 0; ++v) {
        const size_t *in = idx[0] + first[0][v], k = first[0][v + 1] - first[0][v];
        double p[3];
        if (k) r = cm_cad_vertex_point(ctx, g2, v, p);
        for (size_t j = 0; j < k && r >= 0; ++j)
            memcpy(xyz + 3 * in[j], p, sizeof p);
    }
    for (int e = 0; e < c.edges && r >= 0; ++e) {
        size_t k = first[1][e + 1] - first[1][e];
        if (k)
            r = morph_edge(ctx, g, g2, e, o.method, affine_edge && affine_edge[e] ? &aff : NULL,
                           s, idx[1] + first[1][e], k, xyz);
    }
    for (int f = 0; f < c.faces && r >= 0; ++f) {
        cm_status p = cm_progress(ctx, "surface", f, c.faces);
        if (p < 0) {
            r = p;
            break;
        }
        size_t k = first[2][f + 1] - first[2][f];
        const size_t *in = idx[2] + first[2][f];
        if (!k) {
            st.faces_skipped++;
            continue;
        }
        if (o.method == CM_SURFACE_RBF) {
            r = morph_face(ctx, g, g2, f, per_edge, s, in, k, xyz, &st, &aff, affine_edge,
                           &cache_used->face[f]);
            st.faces_warped++;
        } else {
            r = project_face(ctx, g2, f, s, in, k, xyz);
        }
    }
    if (r >= 0) {
        cm_status p = cm_progress(ctx, "surface", c.faces, c.faces);
        if (p < 0) r = p;
    }
    cm_surface_morph_cache_clear(&local);
    free(affine_edge);
    if (stats) *stats = st;
    if (r < 0) return r;
    if (st.outside)
        return cm_error(ctx, CM_WARNING,
                        "surface morph: %zu face nodes left the trimmed domain of their face in G' "
                        "and were put on its closest point (worst: node %lld, %.3g away)",
                        st.outside, (long long)st.worst_outside_node, st.worst_outside_dist);
    return CM_OK;
}

cm_status cm_surface_max_distance(cm_context *ctx, const cm_cad_locator *locator, const double *xyz,
                                  size_t n, double *max_dist, size_t *worst)
{
    double *d = malloc((n ? n : 1) * sizeof *d);
    if (!d) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_max_distance: out of memory");
    /* in chunks with a progress point between them: a Newton projection per node is tens of
     * microseconds, 10^5 nodes a second (each node on its own: the same distances) */
    const size_t chunk = 8192;
    cm_status r = CM_OK;
    for (size_t j0 = 0; j0 < n && r >= 0; j0 += chunk) {
        const size_t k = n - j0 < chunk ? n - j0 : chunk;
        cm_status p = j0 > 0 ? cm_progress(ctx, "distance", (double)j0, (double)n) : CM_OK;
        if (p < 0) {
            r = p;
            break;
        }
        p = cm_cad_locate_faces(ctx, locator, xyz + 3 * j0, k, NULL, NULL, d + j0, NULL);
        if (p != CM_OK) r = p;
    }
    if (r >= 0 && n > chunk) { /* the points above were reported: end the line at 100 % */
        cm_status p = cm_progress(ctx, "distance", (double)n, (double)n);
        if (p < 0) r = p;
    }
    double m = 0;
    size_t w = 0;
    for (size_t i = 0; i < n && r >= 0; ++i)
        if (d[i] > m) m = d[i], w = i;
    free(d);
    if (max_dist) *max_dist = m;
    if (worst) *worst = w;
    return r;
}
