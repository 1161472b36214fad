/* The sweep driver (issue 6): writes G(t) as STEP, meshes G(0), and morphs M(0) onto every
 * G(t) by each method, absolutely (one classification and one warp factorisation on M(0),
 * reused for every t: the point of the design) and relatively (classification and warp redone
 * on M(t - dt) against G(t - dt) each step). */
#include "sweep.h"

#include "cadmorph/morph.h"
#include "cadmorph/tetmesh.h"
#include "hexmesh.h"
#include "models.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *const method_names[CM_SWEEP_N_METHODS] = {"rbf-s", "project",
                                                             "rbf-s-biharmonic"};

const char *cm_sweep_method_name(int method)
{
    return method >= 0 && method < CM_SWEEP_N_METHODS ? method_names[method] : NULL;
}

int cm_sweep_method_from_name(const char *name)
{
    for (int m = 0; m < CM_SWEEP_N_METHODS; ++m)
        if (!strcmp(name, method_names[m])) return m;
    return -1;
}

const char *cm_sweep_mode_name(int mode)
{
    return mode == CM_SWEEP_ABSOLUTE ? "absolute" : mode == CM_SWEEP_RELATIVE ? "relative" : "?";
}

static cm_surface_method method_surface(int m)
{
    return m == CM_SWEEP_PROJECT ? CM_SURFACE_PROJECT : CM_SURFACE_RBF;
}

static cm_warp_method method_kernel(int m)
{
    return m == CM_SWEEP_RBF_S_BIHARMONIC ? CM_WARP_RBF_BIHARMONIC : CM_WARP_RBF;
}

void cm_sweep_options_init(cm_sweep_options *opt)
{
    memset(opt, 0, sizeof *opt);
    opt->model = "bore";
    opt->mesh = "tet";
    opt->modes = CM_SWEEP_ABSOLUTE | CM_SWEEP_RELATIVE;
    opt->steps = 10;
    opt->out_dir = ".";
    opt->write_meshes = 1;
}

void cm_sweep_result_destroy(cm_sweep_result **r)
{
    if (!r || !*r) return;
    free((*r)->rows);
    free(*r);
    *r = NULL;
}

/* One method in one mode. */
typedef struct series {
    int mode, method, alive;
    cm_mesh *mesh; /* relative: M(t) so far (coordinates only; topology is M(0)'s) */
} series;

/* What the whole sweep shares. */
typedef struct sweep {
    const cm_sweep_options *o;
    cm_sweep_result *r;
    int n;                    /* steps */
    cm_cad_model *g_prev, *g; /* G(t - dt), G(t) */
    cm_cad_locator *loc_prev, *loc;
    cm_cad_model *g0;
    cm_mesh *mesh0;           /* M(0) */
    cm_mesh_boundary *b;      /* topology only: the same for every M(t) */
    cm_surface_nodes *nodes0; /* M(0)'s boundary classified on G(0) once */
    cm_warp *warp[2];         /* absolute: on M(0), triharmonic and biharmonic */
    double t_warp[2];         /* their factorisation times, reported in step 1 */
    double t_classify0;
    double h;                /* locator spacing */
    cm_mesh *work;           /* scratch copy of M(0) with the output fields */
    double *sj, *disp_field; /* the work mesh's fields */
    double *disp, *target;   /* #nodes x 3, #boundary x 3 */
    series s[2 * CM_SWEEP_N_METHODS];
    int n_series;
} sweep;

static cm_status prefixed(cm_context *ctx, cm_status s, const char *fmt, const char *arg)
{
    char msg[1024], what[512];
    snprintf(msg, sizeof msg, "%s", cm_context_message(ctx));
    snprintf(what, sizeof what, fmt, arg);
    return cm_error(ctx, s, "%s: %s", what, msg);
}

static void step_path(const sweep *w, int k, char *path, size_t size)
{
    snprintf(path, size, "%s/G_%.4f.step", w->o->out_dir, (double)k / w->n);
}

/* Writes G(k / n) as STEP through the model library and reads it back with the CAD layer
 * (what a user's STEP file goes through). */
static cm_status load_model(cm_context *ctx, sweep *w, int k, cm_cad_model **g)
{
    char path[4096];
    step_path(w, k, path, sizeof path);
    double t = (double)k / w->n;
    if (cm_model_write_step(w->o->model, t, path) != 0)
        return cm_error(ctx, CM_ERR_CAD, "sweep: %s at t = %g: %s", w->o->model, t,
                        cm_model_error());
    cm_status s = cm_cad_read(ctx, path, NULL, g);
    if (!w->o->write_step) remove(path);
    return s;
}

static cm_status make_locator(cm_context *ctx, const sweep *w, const cm_cad_model *g,
                              cm_cad_locator **loc)
{
    cm_cad_sample_options so;
    cm_cad_sample_options_init(&so);
    so.h = w->h;
    so.max_samples = CM_MORPH_MAX_SAMPLES; /* as cm_morph_run: beyond it h grows, with a warning */
    cm_status s = cm_cad_locator_create(ctx, g, &so, loc);
    if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
    return s < 0 ? s : CM_OK;
}

static cm_status make_mesh(cm_context *ctx, sweep *w)
{
    const cm_sweep_options *o = w->o;
    cm_sweep_result *r = w->r;
    cm_status s;
    if (!strcmp(o->mesh, "tet")) {
        snprintf(r->mesh, sizeof r->mesh, "tet");
        cm_tetmesh_options to;
        cm_tetmesh_options_init(&to);
        to.size = o->size > 0 ? o->size : 0.2;
        s = cm_tetmesh_create(ctx, w->g0, &to, &w->mesh0);
    } else if (!strcmp(o->mesh, "hex")) {
        snprintf(r->mesh, sizeof r->mesh, "hex");
        double scale = o->size > 0 ? 0.1 / o->size : 1.0;
        int nt = 8 * (int)(12 * scale + 0.5), nr = (int)(20 * scale + 0.5),
            nz = (int)(16 * scale + 0.5), np = (int)(8 * scale + 0.5),
            nring = (int)(6 * scale + 0.5);
        if (!strcmp(o->model, "bore"))
            s = cm_hexmesh_bore(ctx, nt < 8 ? 8 : nt, nr < 1 ? 1 : nr, nz < 1 ? 1 : nz, 1.05,
                                &w->mesh0);
        else if (!strcmp(o->model, "pipe"))
            s = cm_hexmesh_pipe(ctx, np < 1 ? 1 : np, nring < 1 ? 1 : nring, 0.1 / scale,
                                &w->mesh0);
        else
            return cm_error(ctx, CM_ERR_UNSUPPORTED,
                            "sweep: no hex mesh of %s (bore and pipe only)", o->model);
    } else {
        snprintf(r->mesh, sizeof r->mesh, "file");
        s = cm_mesh_read(ctx, o->mesh, &w->mesh0);
    }
    if (s < 0) return s;
    s = cm_mesh_boundary_create(ctx, w->mesh0, &w->b);
    if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
    if (s < 0) return s;
    if (w->b->n_nodes == 0)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "sweep: mesh %s has no volume cells", o->mesh);
    r->nodes = w->mesh0->n_nodes;
    r->cells = cm_mesh_count_dim(w->mesh0, 3);
    r->boundary_nodes = w->b->n_nodes;
    return CM_OK;
}

static cm_status add_row(cm_context *ctx, cm_sweep_result *r, const cm_sweep_row *row)
{
    if (r->n_rows == r->cap_rows) {
        size_t cap = r->cap_rows ? 2 * r->cap_rows : 64;
        cm_sweep_row *p = realloc(r->rows, cap * sizeof *p);
        if (!p) return cm_error(ctx, CM_ERR_NOMEM, "sweep: out of memory for rows");
        r->rows = p;
        r->cap_rows = cap;
    }
    r->rows[r->n_rows++] = *row;
    return CM_OK;
}

/* Quality of the coordinates xyz (#nodes x 3) and, at 50 and 100 %, the mesh for ParaView. */
static cm_status evaluate(cm_context *ctx, sweep *w, const series *se, int k, const double *xyz,
                          cm_sweep_row *row)
{
    cm_mesh *m = w->work;
    memcpy(m->xyz, xyz, 3 * m->n_nodes * sizeof *m->xyz);
    double t0 = cm_wtime();
    cm_quality_stats all;
    cm_status s = cm_mesh_quality(ctx, m, w->sj);
    if (s >= 0) s = cm_quality_summarize(ctx, m, w->sj, NULL, &all);
    if (s < 0) return s;
    row->min_sj = all.min;
    row->mean_sj = all.mean;
    row->inverted = all.inverted;
    row->cells = all.count;
    double t1 = cm_wtime();
    row->t_quality = t1 - t0;
    int half = (w->n + 1) / 2;
    if (w->o->write_meshes && (k == half || k == w->n)) {
        for (size_t i = 0; i < 3 * m->n_nodes; ++i)
            w->disp_field[i] = xyz[i] - w->mesh0->xyz[i];
        char path[4096];
        snprintf(path, sizeof path, "%s/%s_%s_%03d.vtu", w->o->out_dir,
                 cm_sweep_method_name(se->method), cm_sweep_mode_name(se->mode),
                 (int)lround(100.0 * k / w->n));
        s = cm_mesh_write(ctx, m, path, NULL);
        if (s < 0) return s;
        row->t_write = cm_wtime() - t1;
    }
    return CM_OK;
}

/* Boundary to target, interior by the warp, measured. warp: NULL to create one on `from`. */
static cm_status morph_step(cm_context *ctx, sweep *w, series *se, int k,
                            const cm_surface_nodes *nodes, const cm_cad_model *ga,
                            const cm_mesh *from, cm_warp *warp, cm_sweep_row *row)
{
    size_t nn = from->n_nodes, nb = nodes->n;
    cm_surface_morph_options mo;
    cm_surface_morph_options_init(&mo);
    mo.method = method_surface(se->method);
    double t0 = cm_wtime();
    cm_surface_morph_stats st;
    memset(&st, 0, sizeof st);
    cm_status s = cm_surface_morph(ctx, ga, w->g, nodes, &mo, w->target, &st);
    row->outside = st.outside;
    if (s == CM_WARNING)
        cm_log(ctx, CM_LOG_DEBUG, "sweep: %s %s step %d: %s", cm_sweep_method_name(se->method),
               cm_sweep_mode_name(se->mode), k, cm_context_message(ctx));
    if (s < 0) return s;
    double t1 = cm_wtime();
    row->t_surface = t1 - t0;
    cm_warp *own = NULL;
    if (!warp) {
        cm_warp_options wo;
        cm_warp_options_init(&wo);
        wo.method = method_kernel(se->method);
        s = cm_warp_create(ctx, from, w->b, NULL, &wo, &own);
        if (s < 0) return s;
        warp = own;
    }
    double t2 = cm_wtime();
    row->t_volume_solve += t2 - t1;
    memset(w->disp, 0, 3 * nn * sizeof *w->disp);
    for (size_t i = 0; i < nb; ++i)
        for (int c = 0; c < 3; ++c)
            w->disp[3 * nodes->node[i] + c] =
                w->target[3 * i + c] - from->xyz[3 * nodes->node[i] + c];
    s = cm_warp_apply(ctx, warp, w->disp);
    cm_warp_destroy(&own);
    if (s < 0) return s;
    for (size_t i = 0; i < 3 * nn; ++i)
        w->disp[i] += from->xyz[i];
    /* boundary nodes exactly where the surface morph sent them */
    for (size_t i = 0; i < nb; ++i)
        memcpy(w->disp + 3 * nodes->node[i], w->target + 3 * i, 3 * sizeof(double));
    double t3 = cm_wtime();
    row->t_evaluation = t3 - t2;
    s = cm_surface_max_distance(ctx, w->loc, w->target, nb, &row->max_dist, NULL);
    if (s < 0) return s;
    row->t_distance = cm_wtime() - t3;
    return evaluate(ctx, w, se, k, w->disp, row);
}

static cm_status absolute_step(cm_context *ctx, sweep *w, series *se, int k, cm_sweep_row *row)
{
    int kern = method_kernel(se->method) == CM_WARP_RBF_BIHARMONIC;
    if (!w->warp[kern]) {
        cm_warp_options wo;
        cm_warp_options_init(&wo);
        wo.method = method_kernel(se->method);
        double t0 = cm_wtime();
        cm_status s = cm_warp_create(ctx, w->mesh0, w->b, NULL, &wo, &w->warp[kern]);
        if (s < 0) return s;
        w->t_warp[kern] = cm_wtime() - t0;
    }
    if (k == 1) {
        row->t_classify = w->t_classify0;
        row->t_volume_solve = w->t_warp[kern];
    }
    return morph_step(ctx, w, se, k, w->nodes0, w->g0, w->mesh0, w->warp[kern], row);
}

static cm_status relative_step(cm_context *ctx, sweep *w, series *se, int k, cm_sweep_row *row)
{
    cm_surface_nodes *nodes = NULL;
    double t0 = cm_wtime();
    cm_status s = cm_surface_classify(ctx, w->g_prev, w->loc_prev, se->mesh, w->b, NULL, &nodes);
    row->t_classify = cm_wtime() - t0;
    if (s >= 0) s = morph_step(ctx, w, se, k, nodes, w->g_prev, se->mesh, NULL, row);
    cm_surface_nodes_destroy(&nodes);
    if (s >= 0) memcpy(se->mesh->xyz, w->disp, 3 * se->mesh->n_nodes * sizeof(double));
    return s;
}

static void sweep_free(sweep *w)
{
    cm_cad_locator_destroy(&w->loc_prev);
    cm_cad_locator_destroy(&w->loc);
    if (w->g_prev != w->g0) cm_cad_destroy(&w->g_prev);
    if (w->g != w->g0 && w->g != w->g_prev) cm_cad_destroy(&w->g);
    cm_cad_destroy(&w->g0);
    cm_mesh_destroy(&w->mesh0);
    cm_mesh_destroy(&w->work);
    cm_mesh_boundary_destroy(&w->b);
    cm_surface_nodes_destroy(&w->nodes0);
    cm_warp_destroy(&w->warp[0]);
    cm_warp_destroy(&w->warp[1]);
    for (int i = 0; i < w->n_series; ++i)
        cm_mesh_destroy(&w->s[i].mesh);
    free(w->disp);
    free(w->target);
}

/* G(0), M(0), its classification, the series and the scratch arrays. */
static cm_status setup(cm_context *ctx, sweep *w)
{
    const cm_sweep_options *o = w->o;
    cm_status s = load_model(ctx, w, 0, &w->g0);
    if (s < 0) return s;
    double bb[6];
    cm_cad_bbox(w->g0, bb);
    w->r->diagonal = sqrt((bb[3] - bb[0]) * (bb[3] - bb[0]) + (bb[4] - bb[1]) * (bb[4] - bb[1]) +
                          (bb[5] - bb[2]) * (bb[5] - bb[2]));
    if ((s = make_mesh(ctx, w)) < 0) return s;
    double hmin = 0;
    if ((s = cm_surface_edge_lengths(ctx, w->mesh0, w->b, NULL, &hmin)) < 0) return s;
    if (!(hmin > 0))
        return cm_error(ctx, CM_ERR_FORMAT, "sweep: all boundary edges of %s have zero length",
                        o->mesh);
    w->h = hmin / 4;
    if ((s = make_locator(ctx, w, w->g0, &w->loc_prev)) < 0) return s;
    w->g_prev = w->g0;
    double t0 = cm_wtime();
    s = cm_surface_classify(ctx, w->g0, w->loc_prev, w->mesh0, w->b, NULL, &w->nodes0);
    if (s < 0) return prefixed(ctx, s, "sweep: %s is not a mesh of G(0)", o->mesh);
    w->t_classify0 = cm_wtime() - t0;
    size_t nn = w->mesh0->n_nodes;
    w->disp = malloc(3 * nn * sizeof *w->disp);
    w->target = malloc(3 * w->nodes0->n * sizeof *w->target);
    if (!w->disp || !w->target) return cm_error(ctx, CM_ERR_NOMEM, "sweep: out of memory");
    if ((s = cm_mesh_copy(ctx, w->mesh0, &w->work)) < 0) return s;
    if ((s = cm_mesh_add_field(ctx, w->work, "scaled_jacobian", CM_FIELD_CELL, 1, &w->sj)) < 0 ||
        (s = cm_mesh_add_field(ctx, w->work, "displacement", CM_FIELD_NODE, 3, &w->disp_field)) < 0)
        return s;
    /* adding the second field may have moved the first */
    w->sj = cm_mesh_find_field(w->work, "scaled_jacobian", CM_FIELD_CELL)->data;
    cm_quality_stats q0;
    if ((s = cm_mesh_quality(ctx, w->work, w->sj)) < 0 ||
        (s = cm_quality_summarize(ctx, w->work, w->sj, NULL, &q0)) < 0)
        return s;
    w->r->min_sj0 = q0.min;
    w->r->mean_sj0 = q0.mean;
    w->r->inverted0 = q0.inverted;
    unsigned methods = o->methods ? o->methods : (1u << CM_SWEEP_N_METHODS) - 1;
    for (int mode = CM_SWEEP_ABSOLUTE; mode <= CM_SWEEP_RELATIVE; ++mode) {
        if (!(o->modes & mode)) continue;
        for (int m = 0; m < CM_SWEEP_N_METHODS; ++m) {
            if (!(methods & (1u << m))) continue;
            series *se = &w->s[w->n_series++];
            se->mode = mode;
            se->method = m;
            se->alive = 1;
            if (mode == CM_SWEEP_RELATIVE && (s = cm_mesh_copy(ctx, w->mesh0, &se->mesh)) < 0)
                return s;
        }
    }
    return CM_OK;
}

cm_status cm_sweep_run(cm_context *ctx, const cm_sweep_options *opt, cm_sweep_result **result)
{
    if (result) *result = NULL;
    if (!opt || !result || !opt->model || !opt->mesh || !opt->out_dir)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_sweep_run: NULL input");
    if (opt->steps < 1 || !(opt->modes & 3))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_sweep_run: steps %d, modes %d", opt->steps,
                        opt->modes);
    sweep w;
    memset(&w, 0, sizeof w);
    w.o = opt;
    w.n = opt->steps;
    w.r = calloc(1, sizeof *w.r);
    if (!w.r) return cm_error(ctx, CM_ERR_NOMEM, "cm_sweep_run: out of memory");
    snprintf(w.r->model, sizeof w.r->model, "%s", opt->model);
    w.r->threads = cm_context_threads(ctx);
    if (w.r->threads <= 0) w.r->threads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    cm_status s = setup(ctx, &w);
    for (int k = 1; k <= w.n && s >= 0; ++k) {
        cm_progress(ctx, "sweep", k - 1, w.n);
        double t0 = cm_wtime();
        s = load_model(ctx, &w, k, &w.g);
        if (s >= 0) s = cm_cad_compare(ctx, w.g0, w.g, 5);
        if (s >= 0) s = make_locator(ctx, &w, w.g, &w.loc);
        if (s < 0) {
            char what[64];
            snprintf(what, sizeof what, "%g", (double)k / w.n);
            s = prefixed(ctx, s, "sweep: G(%s)", what);
            break;
        }
        double t_sample = cm_wtime() - t0;
        for (int i = 0; i < w.n_series && s >= 0; ++i) {
            series *se = &w.s[i];
            if (!se->alive) continue;
            cm_sweep_row row;
            memset(&row, 0, sizeof row);
            row.mode = se->mode;
            row.method = se->method;
            row.step = k;
            row.t = (double)k / w.n;
            row.t_sample = t_sample;
            cm_status e = se->mode == CM_SWEEP_ABSOLUTE ? absolute_step(ctx, &w, se, k, &row)
                                                        : relative_step(ctx, &w, se, k, &row);
            if (e == CM_ERR_NOMEM || e == CM_ERR_IO || e == CM_ERR_INTERNAL) {
                s = e; /* not the method's fault: stop */
            } else if (e < 0) {
                se->alive = 0;
                unsigned bit = 1u << ((se->mode - 1) * CM_SWEEP_N_METHODS + se->method);
                if (!w.r->failed)
                    snprintf(w.r->failure, sizeof w.r->failure, "%s %s, step %d: %s",
                             cm_sweep_method_name(se->method), cm_sweep_mode_name(se->mode), k,
                             cm_context_message(ctx));
                w.r->failed |= bit;
                cm_log(ctx, CM_LOG_WARNING, "sweep: %s %s stopped at step %d: %s",
                       cm_sweep_method_name(se->method), cm_sweep_mode_name(se->mode), k,
                       cm_context_message(ctx));
            } else {
                s = add_row(ctx, w.r, &row);
            }
        }
        /* G(t) becomes G(t - dt) */
        cm_cad_locator_destroy(&w.loc_prev);
        if (w.g_prev != w.g0) cm_cad_destroy(&w.g_prev);
        w.loc_prev = w.loc;
        w.g_prev = w.g;
        w.loc = NULL;
        w.g = NULL;
    }
    if (s >= 0) cm_progress(ctx, "sweep", w.n, w.n);
    sweep_free(&w);
    if (s < 0) {
        cm_sweep_result_destroy(&w.r);
        return s;
    }
    *result = w.r;
    if (w.r->failed) return cm_error(ctx, CM_WARNING, "sweep: %s", w.r->failure);
    return CM_OK;
}
