/* The distance of the morphed boundary nodes to G': each node to its own vertex, edge or face
 * of G' (the one its G entity corresponds to), by projection onto that entity of the CAD
 * model itself. A nearest-sample search on a sampled G' would need a second set of samples
 * (memory) and, on a part whose small features force a coarse sampling, its Newton start
 * values land on other faces and report distances that are not there (benchmarks/RESULTS.md,
 * "Sampling memory and the boundary distance"). The figure is an upper bound of the distance to
 * G' that is exact for every node that lies on its entity, the case the figure is there to
 * confirm. */
#include "morpher_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The nodes of one kind grouped by entity (counting sort): entity e's are
 * idx[first[e] .. first[e+1]). */
static cm_status group(cm_context *ctx, const cm_surface_nodes *nd, int kind, int n_ent,
                       size_t **first, size_t **idx)
{
    *first = calloc((size_t)n_ent + 2, sizeof **first);
    *idx = malloc((nd->n ? nd->n : 1) * sizeof **idx);
    if (!*first || !*idx) return cm_error(ctx, CM_ERR_NOMEM, "morph: out of memory");
    size_t *f = *first;
    for (size_t i = 0; i < nd->n; ++i)
        if (nd->kind[i] == kind && nd->entity[i] >= 0 && nd->entity[i] < n_ent)
            f[nd->entity[i] + 2]++;
    for (int e = 0; e < n_ent; ++e)
        f[e + 2] += f[e + 1];
    for (size_t i = 0; i < nd->n; ++i)
        if (nd->kind[i] == kind && nd->entity[i] >= 0 && nd->entity[i] < n_ent)
            (*idx)[f[nd->entity[i] + 1]++] = i;
    return CM_OK;
}

static double dist3(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* Face nodes whose projection from their (u,v) on G did not reach them (d above slack:
 * another parameterisation of the face in G'): projected again from the projection's own
 * start on a grid of the face, keeping the nearer foot. */
static cm_status face_again(cm_context *ctx, const cm_cad_model *g2, int f, const size_t *in,
                            size_t k, const double *xyz, double slack, double *d)
{
    size_t n2 = 0;
    for (size_t j = 0; j < k; ++j)
        n2 += !(d[in[j]] <= slack);
    if (!n2) return CM_OK;
    double *q = malloc(3 * n2 * sizeof *q), *d2 = malloc(n2 * sizeof *d2);
    size_t *again = malloc(n2 * sizeof *again);
    cm_status r = q && d2 && again ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "morph: out of memory");
    n2 = 0;
    for (size_t j = 0; j < k && r == CM_OK; ++j)
        if (!(d[in[j]] <= slack)) {
            memcpy(q + 3 * n2, xyz + 3 * in[j], 3 * sizeof *q);
            again[n2++] = in[j];
        }
    if (r == CM_OK) r = cm_cad_project_face(ctx, g2, f, q, n2, NULL, NULL, d2, NULL);
    for (size_t j = 0; j < n2 && r >= 0; ++j)
        if (d2[j] < d[again[j]]) d[again[j]] = d2[j];
    free(q);
    free(d2);
    free(again);
    return r;
}

/* Edge and face nodes, each onto its own entity of g2 (faces by Newton from the node's (u,v)
 * on G, which the morph moves little), in one pass over every entity: a part with many small
 * faces and edges would otherwise start a team of threads per entity, for a few nodes each
 * (benchmarks/RESULTS.md, "Study"). In chunks with a progress point between them. */
static cm_status project_all(cm_context *ctx, const cm_cad_model *g2, const cm_surface_nodes *nd,
                             size_t *const *first, size_t *const *idx, const int *count,
                             const double *xyz, double *d)
{
    size_t m = first[1][count[1]] + first[2][count[2]];
    if (!m) return CM_OK;
    int *kind = malloc(2 * m * sizeof *kind);
    double *q = malloc(6 * m * sizeof *q);
    size_t *which = malloc(m * sizeof *which);
    cm_status r = kind && q && which ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "morph: out of memory");
    if (r < 0) goto done;
    int *ent = kind + m;
    double *uv = q + 3 * m, *dd = uv + 2 * m;
    size_t j = 0;
    for (int k = 1; k <= 2; ++k) /* grouped by entity: each thread meets few entities */
        for (int e = 0; e < count[k]; ++e)
            for (size_t p = first[k][e]; p < first[k][e + 1]; ++p, ++j) {
                size_t i = idx[k][p];
                which[j] = i, kind[j] = k, ent[j] = e;
                memcpy(q + 3 * j, xyz + 3 * i, 3 * sizeof *q);
                memcpy(uv + 2 * j, nd->param + 2 * i, 2 * sizeof *uv);
            }
    const size_t chunk = 16384;
    for (size_t j0 = 0; j0 < m && r >= 0; j0 += chunk) {
        if (j0) r = cm_progress(ctx, "distance", (double)j0, (double)m);
        size_t c = m - j0 < chunk ? m - j0 : chunk;
        if (r >= 0)
            r = cm_cad_project_each(ctx, g2, c, kind + j0, ent + j0, q + 3 * j0, uv + 2 * j0,
                                    dd + j0);
    }
    if (r >= 0 && m > chunk) r = cm_progress(ctx, "distance", (double)m, (double)m);
    for (size_t p = 0; p < m && r >= 0; ++p)
        d[which[p]] = dd[p];
done:
    free(kind);
    free(q);
    free(which);
    return r;
}

cm_status cm_morph_node_distances(cm_context *ctx, const cm_cad_model *g2,
                                  const cm_surface_nodes *nd, const double *xyz, int thorough,
                                  double *max_dist, size_t *worst)
{
    *max_dist = 0;
    if (worst) *worst = 0;
    if (!nd->n) return CM_OK;
    cm_cad_counts c;
    cm_cad_get_counts(g2, &c);
    double bb[6];
    cm_cad_bbox(g2, bb);
    /* a node not on its face after Newton from its G (u,v) gets a start from the face's grid
     * too, for the final positions only (intermediate steps are off G' by design) */
    const double slack = thorough ? 1e-12 * cm_bbox_diagonal(bb) : INFINITY;
    double *d = malloc(nd->n * sizeof *d);
    size_t *first[3] = {NULL, NULL, NULL}, *idx[3] = {NULL, NULL, NULL};
    const int count[3] = {c.vertices, c.edges, c.faces};
    cm_status r = d ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "morph: out of memory for distances");
    for (int k = 0; k < 3 && r >= 0; ++k)
        r = group(ctx, nd, k, count[k], &first[k], &idx[k]);
    for (int v = 0; v < c.vertices && r >= 0; ++v) {
        size_t k = first[0][v + 1] - first[0][v];
        double p[3];
        if (k) r = cm_cad_vertex_point(ctx, g2, v, p);
        for (size_t j = 0; j < k && r >= 0; ++j) {
            size_t i = idx[0][first[0][v] + j];
            d[i] = dist3(xyz + 3 * i, p);
        }
    }
    if (r >= 0) r = project_all(ctx, g2, nd, first, idx, count, xyz, d);
    for (int f = 0; f < c.faces && r >= 0; ++f) {
        size_t k = first[2][f + 1] - first[2][f];
        if (k) r = face_again(ctx, g2, f, idx[2] + first[2][f], k, xyz, slack, d);
    }
    for (size_t i = 0; i < nd->n && r >= 0; ++i)
        if (d[i] > *max_dist) {
            *max_dist = d[i];
            if (worst) *worst = i;
        }
    for (int k = 0; k < 3; ++k) {
        free(first[k]);
        free(idx[k]);
    }
    free(d);
    return r;
}
