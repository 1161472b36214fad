/* Design velocities and gradients of CAD parameters (study.h, docs/DESIGN.md "Gradients"):
 * for each parameter of a design table the rows chosen by cm_design_plan are read once, their
 * boundary positions made by the surface morph (cm_morpher_boundary), differenced, and
 * carried into the interior by the warp's forward product with the morpher's shared
 * factorisation, for a batch of parameters in one call; a gradient is <J^T S, V_b> with one
 * reverse product for every parameter. */
#include "cadmorph/study.h"

#include <stdlib.h>
#include <string.h>

/* Parameters whose interior velocities one warp apply computes together: 3 values per point
 * and parameter of scratch in the RBF warp, so a bound keeps large tables in memory. */
#define CM_DESIGN_WARP_BATCH 16

void cm_design_velocities_destroy(cm_design_velocities **v)
{
    if (!v || !*v) return;
    free((*v)->diff);
    free((*v)->v);
    free(*v);
    *v = NULL;
}

/* Row i of the table read and numbered like g0 (cm_cad_match, as the study does). */
static cm_status read_row(cm_context *ctx, const cm_design_table *t, size_t i,
                          const cm_cad_model *g0, const cm_cad_read_options *ro, cm_cad_model **g)
{
    const char *path = cm_design_table_path(t, i);
    cm_status s = cm_cad_read(ctx, path, ro, g);
    if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s: %s", path, cm_context_message(ctx));
    if (s >= 0) {
        s = cm_cad_match(ctx, g0, *g, 5, NULL);
        if (s < 0) s = cm_error_prefix(ctx, s, "%s is not a variant of the base geometry", path);
    } else {
        s = cm_error_prefix(ctx, s, "%s", path);
    }
    if (s < 0) cm_cad_destroy(g);
    return s;
}

/* The boundary positions of the morph onto row i into xyz. */
static cm_status boundary_of(cm_context *ctx, cm_morpher *mp, const cm_design_table *t, size_t i,
                             const cm_cad_model *g0, const cm_cad_read_options *ro, double *xyz,
                             cm_design_velocities *r)
{
    cm_cad_model *g = NULL;
    double t0 = cm_wtime();
    cm_status s = read_row(ctx, t, i, g0, ro, &g);
    double t1 = cm_wtime();
    r->t_read += t1 - t0;
    if (s < 0) return s;
    s = cm_morpher_boundary(ctx, mp, g, xyz);
    if (s == CM_WARNING)
        cm_log(ctx, CM_LOG_WARNING, "%s: %s", cm_design_table_path(t, i), cm_context_message(ctx));
    r->t_surface += cm_wtime() - t1;
    ++r->surface_morphs;
    cm_cad_destroy(&g);
    return s < 0 ? cm_error_prefix(ctx, s, "%s", cm_design_table_path(t, i)) : CM_OK;
}

cm_status cm_design_velocity(cm_context *ctx, cm_morpher *mp, const cm_cad_model *g0,
                             const cm_design_table *t, size_t base, const cm_cad_read_options *ro,
                             int interior, cm_design_velocities **out)
{
    if (out) *out = NULL;
    if (!mp || !g0 || !t || !out)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_design_velocity: NULL input");
    const size_t np = cm_design_table_n_parameters(t), nn = cm_morpher_mesh(mp)->n_nodes;
    cm_design_velocities *r = calloc(1, sizeof *r);
    if (r) r->diff = calloc(np ? np : 1, sizeof *r->diff);
    const size_t nv = np * nn * 3;
    if (r && r->diff) r->v = calloc(nv ? nv : 1, sizeof *r->v);
    double *plus = malloc(3 * (nn ? nn : 1) * sizeof *plus);
    double *minus = malloc(3 * (nn ? nn : 1) * sizeof *minus);
    cm_status s = r && r->diff && r->v && plus && minus
                      ? CM_OK
                      : cm_error(ctx, CM_ERR_NOMEM, "cm_design_velocity: out of memory for %zu "
                                 "parameters of %zu nodes", np, nn);
    if (s >= 0) {
        r->n_parameters = np;
        r->n_nodes = nn;
        r->interior = interior != 0;
        r->base = base;
        s = cm_design_plan(ctx, t, base, r->diff);
    }
    char warning[1024] = "";
    if (s == CM_WARNING) {
        cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
        snprintf(warning, sizeof warning, "%s", cm_context_message(ctx));
    }
    for (size_t j = 0; j < np && s >= 0; ++j) {
        const cm_design_difference *d = &r->diff[j];
        if (d->scheme == CM_DESIGN_NONE) continue;
        if ((s = cm_progress(ctx, "design velocities", (double)j, (double)np)) < 0) break;
        s = boundary_of(ctx, mp, t, d->plus, g0, ro, plus, r);
        if (s >= 0 && d->scheme == CM_DESIGN_CENTRAL)
            s = boundary_of(ctx, mp, t, d->minus, g0, ro, minus, r);
        if (s < 0) break;
        /* the boundary part only here: the interior follows for a batch of parameters */
        s = cm_morpher_velocity(ctx, mp, plus, d->dp_plus,
                                d->scheme == CM_DESIGN_CENTRAL ? minus : NULL, d->dp_minus, 0,
                                r->v + j * nn * 3);
        if (s < 0) s = cm_error_prefix(ctx, s, "parameter %s", cm_design_table_parameter(t, j));
        cm_log(ctx, CM_LOG_DEBUG, "design velocity of %s: %s differences, rows %ld and %ld",
               cm_design_table_parameter(t, j), cm_design_scheme_name(d->scheme),
               cm_design_table_line(t, d->plus),
               cm_design_table_line(t, d->scheme == CM_DESIGN_CENTRAL ? d->minus : base));
    }
    /* the interior by the warp's forward product of runs of consecutive parameters with a
     * velocity, in place: one cm_warp_apply_many per batch shares the RBF's kernel passes
     * between them (the per-parameter applies cost a solve and an evaluation each) */
    for (size_t j = 0; interior && j < np && s >= 0;) {
        if (r->diff[j].scheme == CM_DESIGN_NONE) {
            ++j;
            continue;
        }
        size_t e = j + 1;
        while (e < np && e - j < CM_DESIGN_WARP_BATCH && r->diff[e].scheme != CM_DESIGN_NONE)
            ++e;
        double t0 = cm_wtime();
        s = cm_morpher_warp_forward_many(ctx, mp, e - j, r->v + j * nn * 3);
        r->t_warp += cm_wtime() - t0;
        if (s < 0)
            s = e - j == 1
                    ? cm_error_prefix(ctx, s, "parameter %s", cm_design_table_parameter(t, j))
                    : cm_error_prefix(ctx, s, "parameters %s to %s",
                                      cm_design_table_parameter(t, j),
                                      cm_design_table_parameter(t, e - 1));
        j = e;
    }
    if (s >= 0) s = cm_progress(ctx, "design velocities", (double)np, (double)np);
    free(plus);
    free(minus);
    if (s < 0) {
        cm_design_velocities_destroy(&r);
        return s;
    }
    *out = r;
    return warning[0] ? cm_error(ctx, CM_WARNING, "%s", warning) : CM_OK;
}

/* dJdp[j] = sum over the boundary nodes of f . V_j (f: #nodes x 3). */
static void boundary_dots(const cm_morpher *mp, const cm_design_velocities *v, const double *f,
                          double *dJdp)
{
    const unsigned char *bnd = cm_morpher_boundary_flags(mp);
    const size_t nn = v->n_nodes;
    for (size_t j = 0; j < v->n_parameters; ++j) {
        const double *vj = v->v + j * nn * 3;
        double acc = 0;
        for (size_t k = 0; k < nn; ++k)
            if (bnd[k])
                acc += f[3 * k] * vj[3 * k] + f[3 * k + 1] * vj[3 * k + 1] +
                       f[3 * k + 2] * vj[3 * k + 2];
        dJdp[j] = acc;
    }
}

cm_status cm_design_gradient(cm_context *ctx, cm_morpher *mp, const cm_design_velocities *v,
                             const double *sens, int boundary_only, double *dJdp, int *reverse)
{
    if (reverse) *reverse = 0;
    if (!mp || !v || !sens || !dJdp)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_design_gradient: NULL input");
    const size_t nn = v->n_nodes;
    if (cm_morpher_mesh(mp)->n_nodes != nn)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_design_gradient: velocities of %zu nodes, "
                        "morpher of %zu", nn, cm_morpher_mesh(mp)->n_nodes);
    if (boundary_only) { /* S on the boundary only: sum_b S_b . V_b */
        boundary_dots(mp, v, sens, dJdp);
        return CM_OK;
    }
    /* J^T S once, then <J^T S, V_b> per parameter: the reverse product serves them all. A
     * warp without a reverse product is not linear (cm_warp_method_is_linear), and had no
     * forward product for the velocities either. */
    double *w = malloc(3 * (nn ? nn : 1) * sizeof *w);
    if (!w) return cm_error(ctx, CM_ERR_NOMEM, "cm_design_gradient: out of memory");
    cm_status s = cm_morpher_warp_transpose(ctx, mp, sens, w);
    if (s >= 0) {
        if (reverse) *reverse = 1;
        boundary_dots(mp, v, w, dJdp);
    }
    free(w);
    return s;
}
