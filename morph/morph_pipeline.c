/* cm_morph_run: the file-level wrapper of the morph engine behind `cadmorph morph`. Reads G,
 * the optional intermediate geometries and G', and M; morphs M along the chain with one
 * morpher, rebased on each intermediate result (a relative morph). */
#include "cadmorph/morph.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cm_morph_result_destroy(cm_morph_result **r)
{
    if (!r || !*r) return;
    cm_mesh_destroy(&(*r)->mesh);
    free((*r)->steps);
    free(*r);
    *r = NULL;
}

/* The first warning of the run is what cm_morph_run returns with CM_WARNING. */
static void note_warning(cm_context *ctx, cm_status s, cm_status *warned, char *msg, size_t size)
{
    if (s != CM_WARNING || *warned == CM_WARNING) return;
    *warned = CM_WARNING;
    snprintf(msg, size, "%s", cm_context_message(ctx));
}

/* The morphed mesh: M's connectivity at xyz, with the displacement and quality fields. */
static cm_status result_mesh(cm_context *ctx, const cm_morpher *mp, const double *xyz,
                             cm_morph_result *r)
{
    const cm_mesh *m0 = cm_morpher_mesh(mp);
    size_t nn = m0->n_nodes;
    cm_status s = cm_mesh_copy(ctx, m0, &r->mesh);
    double *disp = malloc(3 * (nn ? nn : 1) * sizeof *disp);
    if (s >= 0 && !disp) s = cm_error(ctx, CM_ERR_NOMEM, "cm_morph_run: out of memory");
    /* the morphed mesh lists scaled_jacobian before displacement (replaced where it stands) */
    if (s >= 0) s = cm_mesh_add_field(ctx, r->mesh, "scaled_jacobian", CM_FIELD_CELL, 1, NULL);
    if (s >= 0) {
        for (size_t i = 0; i < 3 * nn; ++i)
            disp[i] = xyz[i] - r->mesh->xyz[i];
        memcpy(r->mesh->xyz, xyz, 3 * nn * sizeof *xyz);
        /* measured again: the morpher's last trial may be a rejected adaptive step */
        s = cm_mesh_apply_displacement(ctx, r->mesh, disp, CM_DISPLACEMENT_QUALITY, &r->sj);
    }
    free(disp);
    return s;
}

cm_status cm_morph_run(cm_context *ctx, const char *g0_path, const char *g1_path,
                       const char *mesh_path, const char *const *via, size_t n_via,
                       const cm_morph_options *opt, cm_morph_result **result)
{
    if (result) *result = NULL;
    if (!g0_path || !g1_path || !mesh_path || !result || (n_via && !via))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morph_run: NULL input");
    cm_morph_options o;
    cm_morph_options_init(&o);
    if (opt) o = *opt;
    if (o.steps < 1 && o.steps != CM_MORPH_STEPS_AUTO)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_morph_run: steps must be >= 1 or auto");
    size_t n_geom = n_via + 2; /* G, the intermediates, G' */
    const char **path = malloc(n_geom * sizeof *path);
    cm_cad_model **g = calloc(n_geom, sizeof *g);
    cm_morph_result *r = calloc(1, sizeof *r);
    cm_morph_step *rows = NULL; /* every leg's rows, appended */
    size_t n_rows = 0;
    cm_mesh *mesh = NULL;
    cm_morpher *mp = NULL;
    double *xyz = NULL;
    cm_status warned = CM_OK;
    char warning[1024] = "";
    cm_status s = path && g && r ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "cm_morph_run: out of memory");
    if (s >= 0) {
        path[0] = g0_path;
        for (size_t i = 0; i < n_via; ++i)
            path[i + 1] = via[i];
        path[n_geom - 1] = g1_path;
    }
    double t = cm_wtime();
    cm_cad_read_options ro;
    cm_cad_read_options_init(&ro);
    if (o.cad_unit) ro.unit = o.cad_unit;
    for (size_t i = 0; i < n_geom && s >= 0; ++i) {
        s = cm_cad_read(ctx, path[i], &ro, &g[i]);
        if (s >= 0 && i > 0) {
            s = cm_cad_match(ctx, g[i - 1], g[i], 5, NULL); /* renumbers G' like G */
            if (s < 0)
                s = cm_error_prefix(ctx, s, "%s and %s do not correspond", path[i - 1], path[i]);
        }
    }
    if (s >= 0) s = cm_mesh_read(ctx, mesh_path, &mesh);
    double t_read = cm_wtime() - t; /* rows are filled by the morpher: stage times go in after */
    if (s >= 0) {
        s = cm_morpher_create(ctx, g[0], mesh, &o, &mp);
        if (s == CM_ERR_MISMATCH)
            s = cm_error_prefix(ctx, s, "%s is not a mesh of %s", mesh_path, g0_path);
        else if (s < 0)
            s = cm_error_prefix(ctx, s, "%s", mesh_path);
        note_warning(ctx, s, &warned, warning, sizeof warning);
    }
    if (s >= 0) {
        const cm_morpher_info *in = cm_morpher_get_info(mp);
        memcpy(r->counts, in->counts, sizeof r->counts);
        r->h = in->h;
        r->off_cad_nodes = in->off_cad_nodes;
        r->off_cad_components = in->off_cad_components;
        r->off_cad_slide = in->off_cad_slide;
        xyz = malloc(3 * (mesh->n_nodes ? mesh->n_nodes : 1) * sizeof *xyz);
        if (!xyz) s = cm_error(ctx, CM_ERR_NOMEM, "cm_morph_run: out of memory");
    }
    for (size_t i = 1; i < n_geom && s >= 0; ++i) {
        const cm_morpher_info *in = cm_morpher_get_info(mp);
        double t_sample = i == 1 ? in->t_sample : 0, t_classify = i == 1 ? in->t_classify : 0;
        if (i > 1) {
            t = cm_wtime();
            s = cm_morpher_rebase(ctx, mp, g[i - 1], xyz);
            t_classify = cm_wtime() - t;
            if (s < 0) {
                s = cm_error_prefix(ctx, s, "%s: relative step onto %s", mesh_path, path[i - 1]);
                break;
            }
            note_warning(ctx, s, &warned, warning, sizeof warning);
        }
        s = cm_morpher_apply(ctx, mp, g[i], xyz, NULL);
        /* this leg's rows, numbered on from the last leg's, with the stages spent before */
        size_t n_leg = 0;
        const cm_morph_step *leg = cm_morpher_steps(mp, &n_leg);
        cm_morph_step *grown = n_leg ? realloc(rows, (n_rows + n_leg) * sizeof *rows) : rows;
        if (!grown && n_leg) { /* no rows (apply failed before its first step): keep its error */
            s = cm_error(ctx, CM_ERR_NOMEM, "cm_morph_run: out of memory");
            break;
        }
        rows = grown;
        for (size_t k = 0; k < n_leg; ++k) {
            rows[n_rows + k] = leg[k];
            rows[n_rows + k].step = (int)(n_rows + k + 1);
        }
        if (n_leg) {
            rows[n_rows].t_read = i == 1 ? t_read : 0;
            rows[n_rows].t_sample += t_sample;
            rows[n_rows].t_classify = t_classify;
        }
        n_rows += n_leg;
        if (s < 0) {
            s = cm_error_prefix(ctx, s, "%s", mesh_path);
            break;
        }
        note_warning(ctx, s, &warned, warning, sizeof warning);
    }
    cm_status failed = s;
    /* a rejected adaptive morph hands back its last valid mesh */
    if (s == CM_ERR_REJECTED && n_rows) s = CM_OK;
    if (r) {
        r->steps = rows;
        r->n_steps = (int)n_rows;
        rows = NULL;
    }
    if (s >= 0) s = result_mesh(ctx, mp, xyz, r);
    if (s >= 0) {
        double bb[6];
        cm_cad_bbox(g[n_geom - 1], bb);
        r->diagonal = cm_bbox_diagonal(bb);
        size_t last = n_rows - 1;
        while (last > 0 && !r->steps[last].accepted)
            --last;
        r->max_dist = r->steps[last].max_dist;
        r->surface = *cm_morpher_surface_stats(mp);
    }
    cm_morpher_destroy(&mp);
    cm_mesh_destroy(&mesh);
    for (size_t i = 0; g && i < n_geom; ++i)
        cm_cad_destroy(&g[i]);
    free(g);
    free(path);
    free(xyz);
    free(rows);
    if (s < 0) {
        cm_morph_result_destroy(&r);
        return s;
    }
    *result = r;
    if (failed < 0) return failed; /* CM_ERR_REJECTED with the partial result */
    if (warned == CM_WARNING) return cm_error(ctx, CM_WARNING, "%s", warning);
    return CM_OK;
}
