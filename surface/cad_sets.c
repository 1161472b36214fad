/* The constraint sets a CAD model already knows ([CMLS §6], `--constraints-from-cad`): every
 * node of a planar face - on the face, its edges or their vertices - forms that face's
 * planarity set, of a cylindrical (conical) face its cylinder (cone) set, of a circular edge its circularity
 * set. The nodes are classified once and grouped by entity, so the cost is linear in the
 * nodes plus the entities' wire lengths, not nodes x entities. */
#include "surface_internal.h"

#include <stdlib.h>
#include <string.h>

void cm_surface_sets_destroy(cm_surface_sets **sets)
{
    if (!sets || !*sets) return;
    for (size_t i = 0; i < (*sets)->n; ++i)
        free((*sets)->set[i].nodes);
    free((*sets)->set);
    free(*sets);
    *sets = NULL;
}

static int listed(const int *ids, int n, int id)
{
    for (int i = 0; i < n; ++i)
        if (ids[i] == id) return 1;
    return 0;
}

/* Node groups of the classification, one per kind. */
typedef struct groups {
    size_t *first[3], *idx[3];
} groups;

/* Marks the nodes on entity e of `kind` (mark is indexed like nodes->node). */
static void mark_entity(const groups *gr, cm_surface_kind kind, int e, int n_entities,
                        unsigned char *mark)
{
    if (e < 0 || e >= n_entities) return;
    for (size_t k = gr->first[kind][e]; k < gr->first[kind][e + 1]; ++k)
        mark[gr->idx[kind][k]] = 1;
}

/* Appends the marked nodes as one set when there are at least min_nodes of them. */
static cm_status add_set(cm_context *ctx, cm_surface_sets *out, size_t *cap,
                         const cm_surface_nodes *sn, const unsigned char *mark,
                         cm_surface_set_type type, int entity, size_t min_nodes)
{
    size_t k = 0;
    for (size_t i = 0; i < sn->n; ++i)
        k += mark[i] != 0;
    if (k < min_nodes) return CM_OK; /* too few nodes for the fit: nothing to constrain */
    if (out->n == *cap) {
        size_t c = *cap ? 2 * *cap : 16;
        cm_surface_set *p = realloc(out->set, c * sizeof *p);
        if (!p) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_cad_sets: out of memory");
        out->set = p, *cap = c;
    }
    int64_t *nodes = malloc(k * sizeof *nodes);
    if (!nodes) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_cad_sets: out of memory");
    k = 0;
    for (size_t i = 0; i < sn->n; ++i) /* sn->node ascends, so the set does */
        if (mark[i]) nodes[k++] = sn->node[i];
    out->set[out->n++] = (cm_surface_set){type, entity, k, nodes};
    return CM_OK;
}

static cm_status check_ids(cm_context *ctx, const cm_surface_set_filter *f,
                           const cm_cad_counts *cnt)
{
    for (int i = 0; i < f->n_faces; ++i)
        if (f->faces[i] < 0 || f->faces[i] >= cnt->faces)
            return cm_error(ctx, CM_ERR_MISMATCH,
                            "constraint sets from CAD: face %d of a model of %d faces",
                            f->faces[i], cnt->faces);
    for (int i = 0; i < f->n_edges; ++i)
        if (f->edges[i] < 0 || f->edges[i] >= cnt->edges)
            return cm_error(ctx, CM_ERR_MISMATCH,
                            "constraint sets from CAD: edge %d of a model of %d edges",
                            f->edges[i], cnt->edges);
    return CM_OK;
}

static cm_status face_sets(cm_context *ctx, const cm_cad_model *g, const cm_surface_nodes *sn,
                           const groups *gr, const cm_cad_counts *cnt,
                           const cm_surface_set_filter *flt, unsigned char *mark,
                           cm_surface_sets *out, size_t *cap)
{
    cm_status s = CM_OK;
    for (int f = 0; f < cnt->faces && s >= 0; ++f) {
        cm_cad_face_info fi;
        s = cm_cad_face_get_info(ctx, g, f, &fi);
        if (s < 0) break;
        int by_id = listed(flt->faces, flt->n_faces, f);
        int plane = fi.type == CM_CAD_PLANE, cyl = fi.type == CM_CAD_CYLINDER;
        int cone = fi.type == CM_CAD_CONE;
        if (by_id && !plane && !cyl && !cone)
            return cm_error(ctx, CM_ERR_UNSUPPORTED,
                            "constraint sets from CAD: face %d is a %s: planes, cylinders and "
                            "cones only",
                            f, cm_cad_surface_type_name(fi.type));
        if (!((plane && (flt->plane || by_id)) || (cyl && (flt->cylinder || by_id)) ||
              (cone && (flt->cone || by_id))))
            continue;
        memset(mark, 0, sn->n ? sn->n : 1);
        mark_entity(gr, CM_SURFACE_ON_FACE, f, cnt->faces, mark);
        for (int w = 0; w < fi.n_wires && s >= 0; ++w) {
            const int *edges, *rev;
            int ne;
            s = cm_cad_face_wire(ctx, g, f, w, &edges, &rev, &ne);
            for (int q = 0; s >= 0 && q < ne; ++q) {
                cm_cad_edge_info ei;
                s = cm_cad_edge_get_info(ctx, g, edges[q], &ei);
                if (s < 0) break;
                mark_entity(gr, CM_SURFACE_ON_EDGE, edges[q], cnt->edges, mark);
                mark_entity(gr, CM_SURFACE_ON_VERTEX, ei.vertex[0], cnt->vertices, mark);
                mark_entity(gr, CM_SURFACE_ON_VERTEX, ei.vertex[1], cnt->vertices, mark);
            }
        }
        if (s >= 0)
            s = add_set(ctx, out, cap, sn, mark,
                        plane ? CM_SURFACE_SET_PLANE
                        : cyl ? CM_SURFACE_SET_CYLINDER
                              : CM_SURFACE_SET_CONE,
                        f, plane ? 3 : cyl ? 5 : 6);
    }
    return s;
}

static cm_status edge_sets(cm_context *ctx, const cm_cad_model *g, const cm_surface_nodes *sn,
                           const groups *gr, const cm_cad_counts *cnt,
                           const cm_surface_set_filter *flt, unsigned char *mark,
                           cm_surface_sets *out, size_t *cap)
{
    cm_status s = CM_OK;
    for (int e = 0; e < cnt->edges && s >= 0; ++e) {
        cm_cad_edge_info ei;
        s = cm_cad_edge_get_info(ctx, g, e, &ei);
        if (s < 0) break;
        int by_id = listed(flt->edges, flt->n_edges, e);
        if (by_id && ei.type != CM_CAD_CIRCLE)
            return cm_error(ctx, CM_ERR_UNSUPPORTED,
                            "constraint sets from CAD: edge %d is a %s, not a circle", e,
                            cm_cad_curve_type_name(ei.type));
        if (ei.type != CM_CAD_CIRCLE || !(flt->circle || by_id)) continue;
        memset(mark, 0, sn->n ? sn->n : 1);
        mark_entity(gr, CM_SURFACE_ON_EDGE, e, cnt->edges, mark);
        mark_entity(gr, CM_SURFACE_ON_VERTEX, ei.vertex[0], cnt->vertices, mark);
        mark_entity(gr, CM_SURFACE_ON_VERTEX, ei.vertex[1], cnt->vertices, mark);
        s = add_set(ctx, out, cap, sn, mark, CM_SURFACE_SET_CIRCLE, e, 3);
    }
    return s;
}

cm_status cm_surface_cad_sets(cm_context *ctx, const cm_cad_model *g, const cm_mesh *mesh,
                              const cm_surface_set_filter *filter, cm_surface_sets **sets)
{
    if (!g || !mesh || !sets)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_surface_cad_sets: NULL argument");
    *sets = NULL;
    cm_surface_set_filter all = {1, 1, 1, 1, 0, 0, NULL, NULL};
    const cm_surface_set_filter *flt = filter ? filter : &all;
    if (cm_mesh_count_dim(mesh, 3) == 0)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "constraint sets from CAD: the nodes are classified on the boundary of "
                        "a volume mesh; this mesh has no volume cells");
    cm_cad_counts cnt;
    cm_cad_get_counts(g, &cnt);
    cm_status s = check_ids(ctx, flt, &cnt);
    if (s < 0) return s;

    cm_cad_locator *loc = NULL;
    cm_mesh_boundary *b = NULL;
    cm_surface_nodes *sn = NULL;
    unsigned char *mark = NULL;
    groups gr = {{NULL, NULL, NULL}, {NULL, NULL, NULL}};
    cm_surface_sets *out = calloc(1, sizeof *out);
    size_t cap = 0;
    if (!out) return cm_error(ctx, CM_ERR_NOMEM, "cm_surface_cad_sets: out of memory");
    s = cm_mesh_boundary_create(ctx, mesh, &b);
    double hmin = 0;
    if (s >= 0) s = cm_surface_edge_lengths(ctx, mesh, b, NULL, &hmin);
    if (s >= 0) {
        cm_cad_sample_options so;
        cm_cad_sample_options_init(&so);
        so.h = hmin / 4;
        so.max_samples = cm_cad_sample_cap(b->n_nodes, 0);
        s = cm_cad_locator_create(ctx, g, &so, &loc);
    }
    if (s >= 0) s = cm_surface_classify(ctx, g, loc, mesh, b, NULL, &sn);
    const int n_ent[3] = {cnt.vertices, cnt.edges, cnt.faces};
    for (int k = 0; s >= 0 && k < 3; ++k)
        s = cm_surface_group(ctx, sn, (cm_surface_kind)k, n_ent[k], &gr.first[k], &gr.idx[k]);
    if (s >= 0) {
        mark = malloc(sn->n ? sn->n : 1);
        if (!mark) s = cm_error(ctx, CM_ERR_NOMEM, "cm_surface_cad_sets: out of memory");
    }
    if (s >= 0) s = face_sets(ctx, g, sn, &gr, &cnt, flt, mark, out, &cap);
    if (s >= 0) s = edge_sets(ctx, g, sn, &gr, &cnt, flt, mark, out, &cap);
    free(mark);
    for (int k = 0; k < 3; ++k)
        free(gr.first[k]), free(gr.idx[k]);
    cm_surface_nodes_destroy(&sn);
    cm_mesh_boundary_destroy(&b);
    cm_cad_locator_destroy(&loc);
    if (s < 0) {
        cm_surface_sets_destroy(&out);
        return s;
    }
    *sets = out;
    return CM_OK;
}
