/* `cadmorph deform --constraints-from-cad G.step`: the constraint sets a CAD model already
 * knows. The boundary nodes are classified on G (surface/classify.c: vertex | edge | face);
 * every node of a planar face - on the face, its edges or their vertices - goes into that
 * face's planarity set, of a cylindrical face into its cylinder set, of a circular edge into
 * its circularity set. A filter picks types or ids. Selection only: the projections and the
 * alternation are deform/'s. */
#include "deform_constraints.h"

#include "cli.h"

#include "cadmorph/surface.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The filter: "plane,cylinder,circle" (types) and/or "face:N" / "edge:N" (0-based ids). */
typedef struct cad_filter {
    int plane, cylinder, circle;
    int n_faces, n_edges;
    int faces[256], edges[256];
} cad_filter;

static cm_status parse_filter(cm_context *ctx, const char *spec, cad_filter *f)
{
    memset(f, 0, sizeof *f);
    if (!spec || !*spec) {
        f->plane = f->cylinder = f->circle = 1;
        return CM_OK;
    }
    const char *s = spec;
    while (*s) {
        size_t len = strcspn(s, ",");
        char item[64];
        if (len >= sizeof item) len = sizeof item - 1;
        memcpy(item, s, len);
        item[len] = 0;
        int id;
        char tail;
        if (!strcmp(item, "plane"))
            f->plane = 1;
        else if (!strcmp(item, "cylinder"))
            f->cylinder = 1;
        else if (!strcmp(item, "circle"))
            f->circle = 1;
        else if (sscanf(item, "face:%d%c", &id, &tail) == 1 && id >= 0 && f->n_faces < 256)
            f->faces[f->n_faces++] = id;
        else if (sscanf(item, "edge:%d%c", &id, &tail) == 1 && id >= 0 && f->n_edges < 256)
            f->edges[f->n_edges++] = id;
        else
            return cm_error(ctx, CM_ERR_ARGUMENT,
                            "--cad-constraints '%s': '%s' is none of plane, cylinder, circle, "
                            "face:N, edge:N",
                            spec, item);
        s += strcspn(s, ",");
        if (*s == ',') ++s;
    }
    return CM_OK;
}

static int listed(const int *ids, int n, int id)
{
    for (int i = 0; i < n; ++i)
        if (ids[i] == id) return 1;
    return 0;
}

/* Adds one set (nodes marked in mark) to c and sets. */
static cm_status add_set(cm_context *ctx, cli_constraints *c, cm_shape_set *sets, cm_shape_type t,
                         const char *label, size_t n, const unsigned char *mark)
{
    size_t k = 0;
    for (size_t i = 0; i < n; ++i)
        k += mark[i] != 0;
    if (k < (t == CM_SHAPE_CYLINDER ? 5u : 3u)) return CM_OK; /* too few nodes to constrain */
    if (c->n >= CLI_MAX_CONSTRAINTS)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "more than %d constraint sets: filter them",
                        CLI_MAX_CONSTRAINTS);
    int64_t *nodes = malloc(k * sizeof *nodes);
    char *name = malloc(strlen(label) + 1);
    if (!nodes || !name) {
        free(nodes), free(name);
        return cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    }
    strcpy(name, label);
    k = 0;
    for (size_t i = 0; i < n; ++i)
        if (mark[i]) nodes[k++] = (int64_t)i;
    sets[c->n].type = t, sets[c->n].n = k, sets[c->n].nodes = nodes;
    c->type[c->n] = t;
    c->set[c->n] = name;
    c->owned[c->n] = name;
    ++c->n;
    return CM_OK;
}

cm_status cli_cad_constraints(cm_context *ctx, const cm_mesh *mesh, cli_constraints *c,
                              cm_shape_set *sets)
{
    cad_filter flt;
    cm_status s = parse_filter(ctx, c->cad_filter, &flt);
    if (s < 0) return s;
    if (cm_mesh_count_dim(mesh, 3) == 0)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "--constraints-from-cad: the nodes are classified on the boundary of a "
                        "volume mesh; this mesh has no volume cells");
    cm_cad_model *g = NULL;
    cm_cad_locator *loc = NULL;
    cm_mesh_boundary *b = NULL;
    cm_surface_nodes *sn = NULL;
    unsigned char *mark = NULL;
    int *node_kind_entity = NULL;
    size_t n = mesh->n_nodes;
    s = cm_cad_read(ctx, c->cad, NULL, &g);
    if (s >= 0) s = cm_mesh_boundary_create(ctx, mesh, &b);
    double hmin = 0;
    if (s >= 0) s = cm_surface_edge_lengths(ctx, mesh, b, NULL, &hmin);
    if (s >= 0) {
        cm_cad_sample_options so;
        cm_cad_sample_options_init(&so);
        so.h = hmin / 4;
        s = cm_cad_locator_create(ctx, g, &so, &loc);
    }
    if (s >= 0) s = cm_surface_classify(ctx, g, loc, mesh, b, NULL, &sn);
    if (s < 0) goto done;
    s = CM_OK;
    cm_cad_counts cnt;
    cm_cad_get_counts(g, &cnt);
    /* per mesh node: kind * 2^28 + entity + 1 (0: not on the boundary) */
    node_kind_entity = calloc(n ? n : 1, sizeof *node_kind_entity);
    mark = malloc(n ? n : 1);
    if (!node_kind_entity || !mark) {
        s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < sn->n; ++i)
        node_kind_entity[sn->node[i]] = (sn->kind[i] << 28) + sn->entity[i] + 1;
#define KIND(v) ((v) >> 28)
#define ENT(v) (((v) & ((1 << 28) - 1)) - 1)
    for (int f = 0; f < cnt.faces && s >= 0; ++f) {
        cm_cad_face_info fi;
        s = cm_cad_face_get_info(ctx, g, f, &fi);
        if (s < 0) break;
        int by_id = listed(flt.faces, flt.n_faces, f);
        int want = (fi.type == CM_CAD_PLANE && (flt.plane || by_id)) ||
                   (fi.type == CM_CAD_CYLINDER && (flt.cylinder || by_id));
        if (!want) {
            if (by_id)
                s = cm_error(ctx, CM_ERR_UNSUPPORTED,
                             "--cad-constraints: face %d is a %s: planes and cylinders only", f,
                             cm_cad_surface_type_name(fi.type));
            continue;
        }
        memset(mark, 0, n ? n : 1);
        for (int w = 0; w < fi.n_wires && s >= 0; ++w) {
            const int *edges, *rev;
            int ne;
            s = cm_cad_face_wire(ctx, g, f, w, &edges, &rev, &ne);
            for (int q = 0; s >= 0 && q < ne; ++q) {
                cm_cad_edge_info ei;
                s = cm_cad_edge_get_info(ctx, g, edges[q], &ei);
                for (size_t i = 0; s >= 0 && i < n; ++i) {
                    int v = node_kind_entity[i];
                    if (!v) continue;
                    if ((KIND(v) == CM_SURFACE_ON_EDGE && ENT(v) == edges[q]) ||
                        (KIND(v) == CM_SURFACE_ON_VERTEX && (ENT(v) == ei.vertex[0] || ENT(v) == ei.vertex[1])))
                        mark[i] = 1;
                }
            }
        }
        for (size_t i = 0; s >= 0 && i < n; ++i) {
            int v = node_kind_entity[i];
            if (v && KIND(v) == CM_SURFACE_ON_FACE && ENT(v) == f) mark[i] = 1;
        }
        char label[64];
        snprintf(label, sizeof label, "cad-face-%d", f);
        if (s >= 0)
            s = add_set(ctx, c, sets, fi.type == CM_CAD_PLANE ? CM_SHAPE_PLANE : CM_SHAPE_CYLINDER,
                        label, n, mark);
    }
    for (int e = 0; e < cnt.edges && s >= 0; ++e) {
        cm_cad_edge_info ei;
        s = cm_cad_edge_get_info(ctx, g, e, &ei);
        if (s < 0) break;
        int by_id = listed(flt.edges, flt.n_edges, e);
        if (ei.type != CM_CAD_CIRCLE || !(flt.circle || by_id)) {
            if (by_id)
                s = cm_error(ctx, CM_ERR_UNSUPPORTED, "--cad-constraints: edge %d is a %s, not a circle",
                             e, cm_cad_curve_type_name(ei.type));
            continue;
        }
        memset(mark, 0, n ? n : 1);
        for (size_t i = 0; i < n; ++i) {
            int v = node_kind_entity[i];
            if (!v) continue;
            if ((KIND(v) == CM_SURFACE_ON_EDGE && ENT(v) == e) ||
                (KIND(v) == CM_SURFACE_ON_VERTEX && (ENT(v) == ei.vertex[0] || ENT(v) == ei.vertex[1])))
                mark[i] = 1;
        }
        char label[64];
        snprintf(label, sizeof label, "cad-edge-%d", e);
        s = add_set(ctx, c, sets, CM_SHAPE_CIRCLE, label, n, mark);
    }
#undef KIND
#undef ENT
    for (int i = 0; s >= 0 && i < flt.n_faces; ++i)
        if (flt.faces[i] >= cnt.faces)
            s = cm_error(ctx, CM_ERR_MISMATCH, "--cad-constraints: face %d of a model of %d faces",
                         flt.faces[i], cnt.faces);
    for (int i = 0; s >= 0 && i < flt.n_edges; ++i)
        if (flt.edges[i] >= cnt.edges)
            s = cm_error(ctx, CM_ERR_MISMATCH, "--cad-constraints: edge %d of a model of %d edges",
                         flt.edges[i], cnt.edges);
done:
    free(mark), free(node_kind_entity);
    cm_surface_nodes_destroy(&sn);
    cm_mesh_boundary_destroy(&b);
    cm_cad_locator_destroy(&loc);
    cm_cad_destroy(&g);
    return s;
}
