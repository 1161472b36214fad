/* Sweeps of the built-in models [SKM11] as studies: the family G(k / N), k = 1 .. N, is
 * written as STEP by the model library and read back by the CAD layer (what a user's file goes
 * through), M(0) is a TetGen or O-grid mesh of G(0) or a file, and cm_study_run does the rest. */
#include "cadmorph/models.h"
#include "cadmorph/study.h"
#include "cadmorph/tetmesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cm_sweep_options_init(cm_sweep_options *opt)
{
    memset(opt, 0, sizeof *opt);
    opt->model = "bore";
    opt->mesh = "tet";
    opt->modes = CM_STUDY_BOTH;
    opt->steps = 10;
    opt->out_dir = ".";
    opt->write_meshes = 1;
}

typedef struct sweep_family {
    const cm_sweep_options *o;
} sweep_family;

static double t_of(const sweep_family *f, int k) { return (double)k / f->o->steps; }

/* G(k / N) through a STEP file in out_dir (kept with --write-step). */
static cm_status load_step(cm_context *ctx, const sweep_family *f, int k, cm_cad_model **g)
{
    char path[4096];
    double t = t_of(f, k);
    snprintf(path, sizeof path, "%s/G_%.4f.step", f->o->out_dir, t);
    cm_status s = cm_model_write_step(ctx, f->o->model, t, path);
    if (s >= 0) s = cm_cad_read(ctx, path, NULL, g);
    if (!f->o->write_step) remove(path);
    return s < 0 ? cm_error_prefix(ctx, s, "G(%g)", t) : s;
}

static cm_status family_load(cm_context *ctx, void *user, size_t i, cm_cad_model **g)
{
    return load_step(ctx, user, (int)i + 1, g);
}

static void family_label(void *user, size_t i, char *buf, size_t size)
{
    snprintf(buf, size, "%03d", (int)lround(100 * t_of(user, (int)i + 1)));
}

static double family_param(void *user, size_t i) { return t_of(user, (int)i + 1); }

static cm_status make_mesh(cm_context *ctx, const cm_sweep_options *o, const cm_cad_model *g0,
                           cm_mesh **mesh, const char **kind)
{
    if (!strcmp(o->mesh, "tet")) {
        *kind = "tet";
        cm_tetmesh_options to;
        cm_tetmesh_options_init(&to);
        to.size = o->size > 0 ? o->size : 0.2;
        return cm_tetmesh_create(ctx, g0, &to, mesh);
    }
    if (!strcmp(o->mesh, "hex")) {
        *kind = "hex";
        double scale = o->size > 0 ? 0.1 / o->size : 1.0;
        int nt = 8 * (int)(12 * scale + 0.5), nr = (int)(20 * scale + 0.5),
            nz = (int)(16 * scale + 0.5), np = (int)(8 * scale + 0.5),
            nring = (int)(6 * scale + 0.5);
        if (!strcmp(o->model, "bore"))
            return cm_hexmesh_bore(ctx, nt < 8 ? 8 : nt, nr < 1 ? 1 : nr, nz < 1 ? 1 : nz, 1.05,
                                   mesh);
        if (!strcmp(o->model, "pipe"))
            return cm_hexmesh_pipe(ctx, np < 1 ? 1 : np, nring < 1 ? 1 : nring, 0.1 / scale,
                                   mesh);
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "sweep: no hex mesh of %s (bore and pipe only)",
                        o->model);
    }
    *kind = "file";
    return cm_mesh_read(ctx, o->mesh, mesh);
}

cm_status cm_sweep_run(cm_context *ctx, const cm_sweep_options *opt, cm_study_result **result)
{
    if (result) *result = NULL;
    if (!opt || !result || !opt->model || !opt->mesh || !opt->out_dir)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_sweep_run: NULL input");
    if (opt->steps < 1 || !(opt->modes & CM_STUDY_BOTH))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_sweep_run: steps %d, modes %d", opt->steps,
                        opt->modes);
    if (!cm_model_known(opt->model))
        return cm_error(ctx, CM_ERR_ARGUMENT, "sweep: unknown model '%s' (%s)", opt->model,
                        cm_model_list());
    sweep_family sf = {opt};
    cm_study_family fam = {0};
    fam.n = (size_t)opt->steps;
    fam.load = family_load;
    fam.label = family_label;
    fam.param = family_param;
    fam.user = &sf;
    fam.x_label = "parameter change (%)";
    fam.x_max = 100;
    fam.x_tick = 10;

    cm_cad_model *g0 = NULL;
    cm_mesh *mesh = NULL;
    const char *kind = "file";
    unsigned char *listed = calloc(fam.n, 1);
    cm_status s = listed ? load_step(ctx, &sf, 0, &g0)
                         : cm_error(ctx, CM_ERR_NOMEM, "sweep: out of memory");
    if (s >= 0) s = make_mesh(ctx, opt, g0, &mesh, &kind);
    if (s >= 0) {
        cm_study_options so;
        cm_study_options_init(&so);
        so.modes = opt->modes;
        so.methods = opt->methods;
        so.n_methods = opt->n_methods;
        /* the sweeps reproduce [SKM11]: the plain one-step morph, whose inverted cells are
         * what they measure (rows and meshes keep them); adaptive: the guarded morph */
        so.morph.steps = opt->adaptive ? CM_MORPH_STEPS_AUTO : 1;
        so.morph.allow_inverted = !opt->adaptive;
        so.morph.optimize = opt->optimize;
        so.out_dir = opt->out_dir;
        so.model = opt->model;
        so.mesh = kind;
        /* the meshes at 50 % (for an odd N the step just past it) and 100 % */
        so.write_meshes = opt->write_meshes ? CM_STUDY_WRITE_LISTED : CM_STUDY_WRITE_NONE;
        listed[(opt->steps + 1) / 2 - 1] = listed[opt->steps - 1] = 1;
        so.write_listed = listed;
        s = cm_study_run(ctx, g0, mesh, &fam, &so, result);
        if (s < 0 && !strcmp(kind, "file")) s = cm_error_prefix(ctx, s, "%s", opt->mesh);
    }
    free(listed);
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&g0);
    return s;
}
