/* `cadmorph deform --constraints-from-cad G.step [--cad-constraints FILTER]`: argument
 * handling only. The sets a CAD model knows are found by cm_surface_cad_sets (surface/
 * cad_sets.c); the projections and the alternation are deform/'s. */
#include "deform_constraints.h"

#include "cli.h"

#include "cadmorph/surface.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The filter: "plane,cylinder,cone,circle" (types) and/or "face:N" / "edge:N" (0-based ids). */
typedef struct cad_filter {
    int plane, cylinder, circle, cone;
    int n_faces, n_edges;
    int faces[256], edges[256];
} cad_filter;

static cm_status parse_filter(cm_context *ctx, const char *spec, cad_filter *f)
{
    memset(f, 0, sizeof *f);
    if (!spec || !*spec) {
        f->plane = f->cylinder = f->circle = f->cone = 1;
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
        else if (!strcmp(item, "cone"))
            f->cone = 1;
        else if (sscanf(item, "face:%d%c", &id, &tail) == 1 && id >= 0 && f->n_faces < 256)
            f->faces[f->n_faces++] = id;
        else if (sscanf(item, "edge:%d%c", &id, &tail) == 1 && id >= 0 && f->n_edges < 256)
            f->edges[f->n_edges++] = id;
        else
            return cm_error(ctx, CM_ERR_ARGUMENT,
                            "--cad-constraints '%s': '%s' is none of plane, cylinder, cone, "
                            "circle, face:N, edge:N",
                            spec, item);
        s += strcspn(s, ",");
        if (*s == ',') ++s;
    }
    return CM_OK;
}

/* Copies the library's sets into c and sets (the CLI's fixed-size tables). */
static cm_status add_set(cm_context *ctx, cli_constraints *c, cm_shape_set *sets,
                         const cm_surface_set *in)
{
    if (c->n >= CLI_MAX_CONSTRAINTS)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "more than %d constraint sets: filter them",
                        CLI_MAX_CONSTRAINTS);
    int64_t *nodes = malloc((in->n ? in->n : 1) * sizeof *nodes);
    char *name = malloc(32);
    if (!nodes || !name) {
        free(nodes), free(name);
        return cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    }
    memcpy(nodes, in->nodes, in->n * sizeof *nodes);
    snprintf(name, 32, "cad-%s-%d", in->type == CM_SURFACE_SET_CIRCLE ? "edge" : "face",
             in->entity);
    cm_shape_type t = in->type == CM_SURFACE_SET_PLANE      ? CM_SHAPE_PLANE
                      : in->type == CM_SURFACE_SET_CYLINDER ? CM_SHAPE_CYLINDER
                      : in->type == CM_SURFACE_SET_CONE     ? CM_SHAPE_CONE
                                                            : CM_SHAPE_CIRCLE;
    sets[c->n].type = t, sets[c->n].n = in->n, sets[c->n].nodes = nodes;
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
    cm_surface_set_filter sf = {flt.plane,   flt.cylinder, flt.circle, flt.cone,
                                flt.n_faces, flt.n_edges,  flt.faces,  flt.edges};
    cm_cad_model *g = NULL;
    cm_surface_sets *ss = NULL;
    s = cm_cad_read(ctx, c->cad, NULL, &g);
    if (s >= 0) s = cm_surface_cad_sets(ctx, g, mesh, &sf, &ss);
    for (size_t i = 0; s >= 0 && i < ss->n; ++i)
        s = add_set(ctx, c, sets, &ss->set[i]);
    cm_surface_sets_destroy(&ss);
    cm_cad_destroy(&g);
    return s < 0 ? s : CM_OK;
}
