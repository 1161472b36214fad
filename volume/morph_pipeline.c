/* The morph pipeline of DESIGN.md: read G, G', M; check the correspondence of G and G';
 * sample G and classify M's boundary nodes; morph them onto G' (section 4); carry the motion
 * into the interior per component with the RBF warp (section 3), in equal increments. */
#include "cadmorph/surface.h"
#include "cadmorph/morph.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static size_t sample_cap(const cm_morph_options *o)
{
    return o->max_samples ? o->max_samples : CM_MORPH_MAX_SAMPLES;
}

void cm_morph_options_init(cm_morph_options *opt)
{
    opt->surface = CM_SURFACE_RBF;
    opt->kernel = CM_RBF_TRIHARMONIC;
    opt->steps = 1;
    opt->cad_unit = NULL;
    opt->max_samples = 0;
    cm_classify_options_init(&opt->classify);
    cm_surface_morph_options_init(&opt->morph);
}

void cm_morph_result_destroy(cm_morph_result **r)
{
    if (!r || !*r) return;
    cm_mesh_destroy(&(*r)->mesh);
    free((*r)->steps);
    free(*r);
    *r = NULL;
}

/* Prefixes the context message: "<what>: <message>", keeps the status. */
static cm_status prefixed(cm_context *ctx, cm_status s, const char *what)
{
    char msg[2048];
    snprintf(msg, sizeof msg, "%s", cm_context_message(ctx));
    return cm_error(ctx, s, "%s: %s", what, msg);
}

typedef struct pipeline {
    cm_cad_model *g0, *g1;
    cm_cad_locator *loc0, *loc1;
    cm_mesh *mesh;
    cm_mesh_boundary *b;
    cm_surface_nodes *nodes;
    double *target;   /* #boundary x 3: positions on G' */
    double *start;    /* #nodes x 3: M0's coordinates */
    double *disp;     /* #nodes x 3 */
    double *bxyz;     /* #boundary x 3: current boundary positions */
    cm_status warned; /* CM_WARNING once a stage warned */
    char warning[1024];
    /* Warnings before the mesh is known to lie on G are held back: a mesh in the wrong unit
     * makes the sampling warn about its cap, and the user should see only the real error. */
    int held, n_held;
    char held_msg[4][1024];
} pipeline;

static void note_warning(cm_context *ctx, pipeline *p, cm_status s)
{
    if (s != CM_WARNING) return;
    if (p->warned != CM_WARNING)
        snprintf(p->warning, sizeof p->warning, "%s", cm_context_message(ctx));
    p->warned = CM_WARNING;
    if (!p->held)
        cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
    else if (p->n_held < 4)
        snprintf(p->held_msg[p->n_held++], sizeof p->held_msg[0], "%s", cm_context_message(ctx));
}

static void release_warnings(cm_context *ctx, pipeline *p)
{
    for (int i = 0; i < p->n_held; ++i)
        cm_log(ctx, CM_LOG_WARNING, "%s", p->held_msg[i]);
    p->held = p->n_held = 0;
}

static cm_status read_inputs(cm_context *ctx, pipeline *p, const char *g0, const char *g1,
                             const char *mesh, const cm_morph_options *o)
{
    cm_cad_read_options ro;
    cm_cad_read_options_init(&ro);
    if (o->cad_unit) ro.unit = o->cad_unit;
    cm_status s = cm_cad_read(ctx, g0, &ro, &p->g0);
    if (s >= 0) s = cm_cad_read(ctx, g1, &ro, &p->g1);
    if (s < 0) return s;
    s = cm_cad_compare(ctx, p->g0, p->g1, 5);
    if (s < 0) {
        char what[2048];
        snprintf(what, sizeof what, "%s and %s do not correspond", g0, g1);
        return prefixed(ctx, s, what);
    }
    s = cm_mesh_read(ctx, mesh, &p->mesh);
    if (s < 0) return s;
    s = cm_mesh_boundary_create(ctx, p->mesh, &p->b);
    if (s < 0) return prefixed(ctx, s, mesh);
    note_warning(ctx, p, s);
    if (p->b->n_nodes == 0)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: no volume cells, nothing to morph", mesh);
    return CM_OK;
}

static cm_status sample(cm_context *ctx, pipeline *p, const char *mesh, const cm_morph_options *o,
                        double *h_used)
{
    double hmin = 0;
    cm_status s = cm_surface_edge_lengths(ctx, p->mesh, p->b, NULL, &hmin);
    if (s < 0) return s;
    if (!(hmin > 0))
        return cm_error(ctx, CM_ERR_FORMAT, "%s: all boundary edges have zero length", mesh);
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    so.h = hmin / 4;
    so.max_samples = sample_cap(o);
    s = cm_cad_locator_create(ctx, p->g0, &so, &p->loc0);
    if (s < 0) return s;
    note_warning(ctx, p, s);
    *h_used = cm_cad_locator_h(p->loc0);
    return CM_OK;
}

/* G' is sampled like G, for measuring the distance of the morphed nodes to it. */
static cm_status sample_g1(cm_context *ctx, pipeline *p, const cm_morph_options *o, double h)
{
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    so.h = h;
    so.max_samples = sample_cap(o);
    cm_status s = cm_cad_locator_create(ctx, p->g1, &so, &p->loc1);
    if (s < 0) return s;
    note_warning(ctx, p, s);
    return CM_OK;
}

/* One increment: boundary to start + frac x (target - start), warp from the current mesh. */
static cm_status step(cm_context *ctx, pipeline *p, const cm_morph_options *o, double frac,
                      double *sj, cm_morph_step *row)
{
    cm_mesh *m = p->mesh;
    const cm_surface_nodes *n = p->nodes;
    memset(p->disp, 0, 3 * m->n_nodes * sizeof *p->disp);
    for (size_t i = 0; i < n->n; ++i)
        for (int k = 0; k < 3; ++k) {
            double want = n->xyz[3 * i + k] + frac * (p->target[3 * i + k] - n->xyz[3 * i + k]);
            if (frac == 1.0) want = p->target[3 * i + k];
            p->bxyz[3 * i + k] = want;
            p->disp[3 * n->node[i] + k] = want - m->xyz[3 * n->node[i] + k];
        }
    cm_warp_options wo;
    cm_warp_options_init(&wo);
    wo.kernel = o->kernel;
    cm_warp *w = NULL;
    double t0 = cm_wtime();
    cm_status s = cm_warp_create(ctx, m, p->b, NULL, &wo, &w);
    double t1 = cm_wtime();
    if (s >= 0) s = cm_warp_apply(ctx, w, p->disp);
    cm_warp_destroy(&w);
    if (s < 0) return s;
    for (size_t i = 0; i < 3 * m->n_nodes; ++i)
        m->xyz[i] += p->disp[i];
    /* boundary nodes exactly where they were sent (no round-off from the increments) */
    for (size_t i = 0; i < n->n; ++i)
        memcpy(m->xyz + 3 * n->node[i], p->bxyz + 3 * i, 3 * sizeof(double));
    s = cm_mesh_quality(ctx, m, sj);
    cm_quality_stats all;
    if (s >= 0) s = cm_quality_summarize(ctx, m, sj, NULL, &all);
    if (s >= 0) s = cm_surface_max_distance(ctx, p->loc1, p->bxyz, n->n, &row->max_dist, NULL);
    if (s < 0) return s;
    row->min_sj = all.min;
    row->mean_sj = all.mean;
    row->inverted = all.inverted;
    row->cells = all.count;
    row->t_volume_solve = t1 - t0;
    row->t_evaluation = cm_wtime() - t1;
    return CM_OK;
}

static void pipeline_free(pipeline *p)
{
    cm_cad_locator_destroy(&p->loc0);
    cm_cad_locator_destroy(&p->loc1);
    cm_cad_destroy(&p->g0);
    cm_cad_destroy(&p->g1);
    cm_mesh_destroy(&p->mesh);
    cm_mesh_boundary_destroy(&p->b);
    cm_surface_nodes_destroy(&p->nodes);
    free(p->target);
    free(p->start);
    free(p->disp);
    free(p->bxyz);
}

cm_status cm_morph_run(cm_context *ctx, const char *g0_path, const char *g1_path,
                       const char *mesh_path, const cm_morph_options *opt, cm_morph_result **result)
{
    if (result) *result = NULL;
    if (!g0_path || !g1_path || !mesh_path || !result)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morph_run: NULL input");
    cm_morph_options o;
    cm_morph_options_init(&o);
    if (opt) o = *opt;
    if (o.steps < 1) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morph_run: steps must be >= 1");
    pipeline p;
    memset(&p, 0, sizeof p);
    p.held = 1;
    cm_morph_result *r = calloc(1, sizeof *r);
    cm_morph_step *rows = calloc((size_t)o.steps, sizeof *rows);
    cm_status s = r && rows ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "cm_morph_run: out of memory");
    if (r) r->steps = rows, r->n_steps = o.steps;
    double t = cm_wtime();
    if (s >= 0) s = read_inputs(ctx, &p, g0_path, g1_path, mesh_path, &o);
    if (rows) rows[0].t_read = cm_wtime() - t;
    t = cm_wtime();
    if (s >= 0) s = sample(ctx, &p, mesh_path, &o, &r->h);
    if (rows) rows[0].t_sample = cm_wtime() - t;
    t = cm_wtime();
    if (s >= 0) {
        s = cm_surface_classify(ctx, p.g0, p.loc0, p.mesh, p.b, &o.classify, &p.nodes);
        if (s < 0) {
            char what[2048];
            snprintf(what, sizeof what, "%s is not a mesh of %s", mesh_path, g0_path);
            s = prefixed(ctx, s, what);
        }
    }
    if (s >= 0) {
        r->counts[0] = p.nodes->count[0];
        r->counts[1] = p.nodes->count[1];
        r->counts[2] = p.nodes->count[2];
        cm_log(ctx, CM_LOG_DEBUG,
               "classify: %zu boundary nodes: %zu on vertices, %zu on edges, "
               "%zu on faces (largest distance to G %.3g); sampling h %.4g",
               p.nodes->n, r->counts[0], r->counts[1], r->counts[2], p.nodes->max_dist, r->h);
    }
    if (s >= 0) release_warnings(ctx, &p);
    if (rows) rows[0].t_classify = cm_wtime() - t;
    t = cm_wtime();
    if (s >= 0) s = sample_g1(ctx, &p, &o, r->h);
    if (rows) rows[0].t_sample += cm_wtime() - t;
    t = cm_wtime();
    size_t nn = p.mesh ? p.mesh->n_nodes : 0, nb = p.nodes ? p.nodes->n : 0;
    if (s >= 0) {
        p.target = malloc(3 * nb * sizeof *p.target);
        p.bxyz = malloc(3 * nb * sizeof *p.bxyz);
        p.start = malloc(3 * nn * sizeof *p.start);
        p.disp = malloc(3 * nn * sizeof *p.disp);
        if (!p.target || !p.bxyz || !p.start || !p.disp)
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_morph_run: out of memory for %zu nodes", nn);
    }
    cm_surface_morph_options mo = o.morph;
    mo.method = o.surface;
    if (s >= 0) s = cm_surface_morph(ctx, p.g0, p.g1, p.nodes, &mo, p.target, &r->surface);
    if (s >= 0) note_warning(ctx, &p, s);
    if (rows) rows[0].t_surface = cm_wtime() - t;
    double *sj = NULL;
    if (s >= 0) {
        memcpy(p.start, p.mesh->xyz, 3 * nn * sizeof *p.start);
        s = cm_mesh_add_field(ctx, p.mesh, "scaled_jacobian", CM_FIELD_CELL, 1, &sj);
    }
    for (int k = 1; k <= o.steps && s >= 0; ++k) {
        cm_progress(ctx, "morph", k - 1, o.steps);
        rows[k - 1].step = k;
        s = step(ctx, &p, &o, (double)k / o.steps, sj, &rows[k - 1]);
        if (s < 0) {
            char what[2048];
            snprintf(what, sizeof what, "%s: step %d of %d", mesh_path, k, o.steps);
            s = prefixed(ctx, s, what);
        }
    }
    if (s >= 0) cm_progress(ctx, "morph", o.steps, o.steps);
    double *field = NULL;
    if (s >= 0) s = cm_mesh_add_field(ctx, p.mesh, "displacement", CM_FIELD_NODE, 3, &field);
    if (s >= 0) {
        /* the scaled_jacobian field may have moved when the displacement field was added */
        r->sj = cm_mesh_find_field(p.mesh, "scaled_jacobian", CM_FIELD_CELL)->data;
        for (size_t i = 0; i < 3 * nn; ++i)
            field[i] = p.mesh->xyz[i] - p.start[i];
        if (p.b) {
            double bb[6];
            cm_cad_bbox(p.g1, bb);
            r->diagonal =
                sqrt((bb[3] - bb[0]) * (bb[3] - bb[0]) + (bb[4] - bb[1]) * (bb[4] - bb[1]) +
                     (bb[5] - bb[2]) * (bb[5] - bb[2]));
        }
        r->max_dist = rows[o.steps - 1].max_dist;
        r->mesh = p.mesh;
        p.mesh = NULL;
    }
    pipeline_free(&p);
    if (s < 0) {
        if (!r) free(rows);
        cm_morph_result_destroy(&r);
        return s;
    }
    *result = r;
    if (p.warned == CM_WARNING) return cm_error(ctx, CM_WARNING, "%s", p.warning);
    return CM_OK;
}
