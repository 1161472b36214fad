/* The warp interface (warp.h): the method table, argument checks every method shares, and
 * the whole-mesh warp behind `cadmorph warp`. */
#include "motion_internal.h"
#include "warp_method.h"

#include <math.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* One row per cm_warp_method, in enum order. */
static const cm_warp_method_ops *const methods[CM_WARP_N_METHODS] = {
    [CM_WARP_RBF] = &cm_warp_rbf_triharmonic,
    [CM_WARP_RBF_BIHARMONIC] = &cm_warp_rbf_biharmonic,
    [CM_WARP_DMFFD] = &cm_warp_dmffd,
    [CM_WARP_FEMWARP] = &cm_warp_femwarp,
    [CM_WARP_LBWARP] = &cm_warp_lbwarp,
    [CM_WARP_SIMPLEX] = &cm_warp_simplex,
    [CM_WARP_MLS] = &cm_warp_mls,
};

struct cm_warp {
    cm_warp_method method;
    const cm_warp_method_ops *ops;
    void *state;
    size_t n_nodes;
    double residual;
};

const char *cm_warp_method_name(cm_warp_method method)
{
    return (int)method >= 0 && method < CM_WARP_N_METHODS ? methods[method]->name : NULL;
}

int cm_warp_method_from_name(const char *name)
{
    for (int m = 0; name && m < CM_WARP_N_METHODS; ++m)
        if (!strcmp(name, methods[m]->name)) return m;
    return -1;
}

const char *cm_warp_method_list(void)
{
    static char list[256];
    if (!list[0])
        for (int m = 0; m < CM_WARP_N_METHODS; ++m) {
            size_t n = strlen(list);
            snprintf(list + n, sizeof list - n, "%s%s", m ? "|" : "", methods[m]->name);
        }
    return list;
}

void cm_warp_options_init(cm_warp_options *opt)
{
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    opt->method = CM_WARP_RBF;
    cm_mls_options_init(&opt->mls);
}

cm_status cm_warp_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                         const unsigned char *constrained, const cm_warp_options *opt,
                         cm_warp **warp)
{
    if (!warp) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_create: warp is NULL");
    *warp = NULL;
    if (!mesh || !b)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_create: mesh or boundary is NULL");
    cm_warp_options defaults;
    cm_warp_options_init(&defaults);
    if (!opt) opt = &defaults;
    if ((int)opt->method < 0 || opt->method >= CM_WARP_N_METHODS)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_create: unknown method %d",
                        (int)opt->method);
    if (!(opt->tolerance >= 0 && opt->tolerance < 1))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_create: tolerance %g: need 0 <= t < 1",
                        opt->tolerance);
    if (b->n_components == 0)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_warp_create: the mesh has no volume cells");
    cm_warp *w = calloc(1, sizeof *w);
    unsigned char *own_mask = NULL;
    if (!constrained) {
        own_mask = calloc(mesh->n_nodes ? mesh->n_nodes : 1, 1);
        if (own_mask)
            for (size_t i = 0; i < b->n_nodes; ++i)
                if (b->nodes[i] >= 0 && (size_t)b->nodes[i] < mesh->n_nodes)
                    own_mask[b->nodes[i]] = 1;
        constrained = own_mask;
    }
    if (!w || !constrained) {
        free(w);
        free(own_mask);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
    }
    w->method = opt->method;
    w->ops = methods[opt->method];
    w->n_nodes = mesh->n_nodes;
    cm_status s = w->ops->create(ctx, mesh, b, constrained, opt, &w->state);
    free(own_mask);
    if (s < 0) {
        free(w);
        return s;
    }
    *warp = w;
    return s;
}

void cm_warp_destroy(cm_warp **warp)
{
    if (!warp || !*warp) return;
    (*warp)->ops->destroy((*warp)->state);
    free(*warp);
    *warp = NULL;
}

cm_status cm_warp_apply(cm_context *ctx, cm_warp *warp, double *disp)
{
    if (!warp || !disp)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_apply: warp or disp is NULL");
    return warp->ops->apply(ctx, warp->state, disp, &warp->residual);
}

cm_status cm_warp_apply_many(cm_context *ctx, cm_warp *warp, size_t k, double *disp)
{
    if (!warp || (k && !disp))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_apply_many: warp or disp is NULL");
    warp->residual = 0;
    if (k == 0) return CM_OK;
    if (warp->n_nodes && k > SIZE_MAX / (3 * sizeof(double) * warp->n_nodes))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_apply_many: %zu fields are too many", k);
    if (warp->ops->apply_many)
        return warp->ops->apply_many(ctx, warp->state, k, disp, &warp->residual);
    double r = 0;
    cm_status s = CM_OK, warn = CM_OK;
    for (size_t j = 0; j < k && s >= 0; ++j) {
        double rj = 0;
        s = warp->ops->apply(ctx, warp->state, disp + j * 3 * warp->n_nodes, &rj);
        if (s == CM_WARNING) warn = s;
        if (rj > r || rj != rj) r = rj;
    }
    warp->residual = r;
    return s < 0 ? s : s == CM_WARNING ? s : warn;
}

cm_status cm_warp_apply_transpose(cm_context *ctx, cm_warp *warp, const double *v, double *out)
{
    if (!warp || !v || !out)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_apply_transpose: warp, v or out is NULL");
    if (!warp->ops->apply_transpose)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_warp_apply_transpose: method %s is not linear in the prescribed "
                        "displacement, so it has no transpose",
                        warp->ops->name);
    size_t n3 = 3 * warp->n_nodes;
    if ((v < out + n3 && out < v + n3))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_apply_transpose: v and out overlap");
    memset(out, 0, n3 * sizeof *out);
    return warp->ops->apply_transpose(ctx, warp->state, v, out);
}

int cm_warp_method_is_linear(cm_warp_method method)
{
    return (int)method >= 0 && method < CM_WARP_N_METHODS && methods[method]->apply_transpose;
}

cm_warp_method cm_warp_get_method(const cm_warp *warp) { return warp->method; }

double cm_warp_residual(const cm_warp *warp) { return warp ? warp->residual : 0; }

double cm_warp_tolerance(const cm_warp *warp)
{
    return warp && warp->ops->tolerance ? warp->ops->tolerance(warp->state) : 0;
}

size_t cm_warp_fallback_nodes(const cm_warp *warp)
{
    return warp && warp->ops->fallback_nodes ? warp->ops->fallback_nodes(warp->state) : 0;
}

/* One create + apply with the given constrained nodes; times and residual into st. */
static cm_status warp_once(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                           const unsigned char *constrained, const cm_warp_options *opt,
                           double *disp, cm_warp_mesh_stats *st)
{
    cm_warp *w = NULL;
    double t0 = cm_wtime();
    cm_status s = cm_warp_create(ctx, mesh, b, constrained, opt, &w);
    double t1 = cm_wtime();
    if (s >= 0) s = cm_warp_apply(ctx, w, disp);
    st->t_create += t1 - t0;
    st->t_apply += cm_wtime() - t1;
    st->residual = fmax(st->residual, cm_warp_residual(w));
    st->fallback_nodes += cm_warp_fallback_nodes(w);
    cm_warp_destroy(&w);
    return s;
}

/* The warp under a boundary motion (docs/DESIGN.md, "Boundary motion by patch kind"), in its
 * work space (a wedge: the slab): pass 1 with the slide nodes free, their motion projected
 * onto their constraints (and a 2-D pair given one motion), pass 2 with them held there so
 * that the interior follows (skipped where no node is free). constrained: out, the nodes held
 * by the last pass. */
static cm_status warp_motion(cm_context *ctx, cm_mesh *mesh, const cm_mesh_boundary *b,
                             const cm_boundary_motion *motion, const cm_warp_options *opt,
                             double *disp, unsigned char *constrained, cm_warp_mesh_stats *st)
{
    size_t nn = mesh->n_nodes, worst0 = 0, worst1 = 0;
    double *work = malloc(3 * (nn ? nn : 1) * sizeof *work), dropped1 = 0;
    if (!work) return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_mesh: out of memory");
    double dropped0 = cm_motion_to_work(motion, disp, work, &worst0);
    cm_motion_project_work(motion, work, &dropped1, &worst1);
    if (fmax(dropped0, dropped1) > 1e-12 * motion->diag)
        cm_log(ctx, CM_LOG_WARNING,
               "%s mesh: the prescribed motion out of its plane is dropped (largest %.3g, at "
               "node %zu)",
               motion->reduction == CM_MOTION_2D ? "2-D" : "axisymmetric",
               fmax(dropped0, dropped1), dropped0 >= dropped1 ? worst0 : worst1);
    size_t slides = 0, free_nodes = 0;
    for (size_t i = 0; i < nn; ++i) {
        cm_motion_kind k = (cm_motion_kind)motion->kind[i];
        constrained[i] = k == CM_MOTION_FIXED || k == CM_MOTION_PRESCRIBED;
        slides += k >= CM_MOTION_SLIDE_PLANE;
        free_nodes += k == CM_MOTION_FREE;
    }
    double *xyz = mesh->xyz;
    if (motion->slab) mesh->xyz = motion->slab; /* the warp sees the slab */
    cm_status s = warp_once(ctx, mesh, b, constrained, opt, work, st);
    if (s >= 0 && slides) {
        cm_motion_project_work(motion, work, &dropped1, &worst1);
        for (size_t i = 0; i < nn; ++i)
            constrained[i] = motion->kind[i] != CM_MOTION_FREE;
        if (free_nodes) s = warp_once(ctx, mesh, b, constrained, opt, work, st);
    }
    mesh->xyz = xyz;
    if (s >= 0) cm_motion_from_work(motion, work, disp);
    st->slide_nodes = slides;
    free(work);
    return s;
}

cm_status cm_warp_mesh(cm_context *ctx, cm_mesh *mesh, double *disp, const unsigned char *listed,
                       const cm_boundary_motion *motion, const cm_warp_options *opt,
                       const cm_optimize_options *optimize, double **sj,
                       cm_warp_mesh_stats *stats)
{
    if (sj) *sj = NULL;
    if (!mesh || !disp) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_mesh: NULL input");
    if (motion && motion->n != mesh->n_nodes)
        return cm_error(ctx, CM_ERR_MISMATCH, "cm_warp_mesh: the motion has %zu nodes, the mesh %zu",
                        motion->n, mesh->n_nodes);
    cm_warp_mesh_stats st;
    memset(&st, 0, sizeof st);
    cm_mesh_boundary *b = NULL;
    size_t nn = mesh->n_nodes;
    unsigned char *constrained = calloc(nn ? nn : 1, 1);
    if (!constrained) return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_mesh: out of memory");
    cm_status s = cm_mesh_boundary_create(ctx, mesh, &b);
    /* a boundary warning (non-manifold faces) is worth showing, and the warp goes on */
    if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
    if (s >= 0) {
        st.boundary_nodes = b->n_nodes;
        st.components = b->n_components;
        if (motion) {
            s = warp_motion(ctx, mesh, b, motion, opt, disp, constrained, &st);
        } else {
            if (listed) memcpy(constrained, listed, nn);
            for (size_t i = 0; i < b->n_nodes; ++i)
                constrained[b->nodes[i]] = 1;
            s = warp_once(ctx, mesh, b, constrained, opt, disp, &st);
        }
        for (size_t i = 0; i < nn; ++i)
            st.constrained_nodes += constrained[i] != 0;
    }
    cm_mesh_boundary_destroy(&b);
    double *q = NULL;
    if (s >= 0) {
        for (size_t i = 0; i < 3 * nn; ++i)
            mesh->xyz[i] += disp[i];
    }
    if (s >= 0 && optimize) {
        double t0 = cm_wtime(), *before = malloc(3 * (nn ? nn : 1) * sizeof *before);
        cm_optimize_stats os;
        s = before ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "cm_warp_mesh: out of memory");
        if (s >= 0) {
            memcpy(before, mesh->xyz, 3 * nn * sizeof *before);
            s = cm_mesh_optimize(ctx, mesh, constrained, optimize, &os);
        }
        if (s >= 0) {
            for (size_t i = 0; i < 3 * nn; ++i)
                disp[i] += mesh->xyz[i] - before[i];
            st.optimized_moves = os.moves;
        }
        free(before);
        st.t_optimize = cm_wtime() - t0;
    }
    free(constrained);
    /* the nodes already stand where disp (with the optimisation's moves) brought them */
    if (s >= 0) s = cm_mesh_apply_displacement(ctx, mesh, disp, CM_DISPLACEMENT_QUALITY, &q);
    if (s < 0) return s;
    if (sj) *sj = q;
    if (stats) *stats = st;
    return CM_OK;
}

cm_status cm_warp_correct(cm_context *ctx, const cm_mesh *mesh, const cm_boundary_motion *motion,
                          double *disp, const cm_warp_options *opt)
{
    if (!mesh || !motion || !disp)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_warp_correct: NULL input");
    if (motion->n != mesh->n_nodes)
        return cm_error(ctx, CM_ERR_MISMATCH, "cm_warp_correct: the motion has %zu nodes, the mesh %zu",
                        motion->n, mesh->n_nodes);
    size_t nn = mesh->n_nodes;
    double *target = malloc(3 * (nn ? nn : 1) * sizeof *target);
    double *corr = calloc(3 * (nn ? nn : 1), sizeof *corr);
    unsigned char *held = calloc(nn ? nn : 1, 1);
    cm_status s = target && corr && held ? CM_OK
                                         : cm_error(ctx, CM_ERR_NOMEM, "cm_warp_correct: out of memory");
    cm_status warn = CM_OK;
    if (s >= 0) {
        memcpy(target, disp, 3 * nn * sizeof *target);
        s = cm_boundary_motion_project(ctx, motion, target);
        if (s == CM_WARNING) warn = s;
    }
    size_t n_free = 0, changed = 0;
    for (size_t i = 0; s >= 0 && i < nn; ++i) {
        held[i] = motion->kind[i] != CM_MOTION_FREE;
        n_free += !held[i];
        for (int k = 0; held[i] && k < 3; ++k) {
            corr[3 * i + k] = target[3 * i + k] - disp[3 * i + k];
            changed += corr[3 * i + k] != 0;
        }
    }
    if (s >= 0 && n_free && changed) {
        cm_mesh_boundary *b = NULL;
        cm_warp *w = NULL;
        s = cm_mesh_boundary_create(ctx, mesh, &b);
        if (s >= 0) s = cm_warp_create(ctx, mesh, b, held, opt, &w);
        if (s >= 0) s = cm_warp_apply(ctx, w, corr);
        cm_warp_destroy(&w);
        cm_mesh_boundary_destroy(&b);
    }
    /* the held nodes exactly at their target, the free ones moved by the correction */
    for (size_t i = 0; s >= 0 && i < nn; ++i)
        for (int k = 0; k < 3; ++k)
            disp[3 * i + k] = held[i] ? target[3 * i + k] : disp[3 * i + k] + corr[3 * i + k];
    free(target), free(corr), free(held);
    return s < 0 ? s : warn;
}
