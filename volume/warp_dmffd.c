/* The DM-FFD warp method [SMB14 §2.2, Fig. 13-14]: deform.h's dmffd deformation of the
 * constrained nodes (the handles) and the other nodes of volume cells: one cubic B-spline
 * lattice whose valid domain is their bounding box. The SVD is done once in create; apply is
 * C = Phi^+ H and one sparse product per node. Least squares, not interpolation: the
 * constrained nodes keep their prescribed displacement (the interface contract) and the
 * residual says how far the space deformation itself misses them.
 * Reverse product (docs/DESIGN.md, "Gradients"): apply is linear in the prescribed
 * displacement - the truncation of the singular values is fixed by create (the handle
 * positions and the clamp), not by the data, and the constrained nodes keep their value - so
 * J^T v is deform.h's transposed DM-FFD: the free nodes' v through the transposed FFD and
 * the transposed pseudo-inverse onto the constrained nodes. */
#include "warp_method.h"

#include "cadmorph/deform.h"

#include <stdlib.h>
#include <string.h>

/* The deformation's points are the constrained nodes (ascending), then the free nodes of
 * volume cells (ascending): the same arrays, in the same order, as the lattice always saw. */
typedef struct dmffd_warp {
    cm_deform *def;
    size_t n_fixed, n_free;
    int64_t *fixed, *free_nodes;
    double *pts; /* apply's scratch: (n_fixed + n_free) x 3 displacements */
} dmffd_warp;

static void dmffd_destroy(void *state)
{
    dmffd_warp *w = state;
    if (!w) return;
    cm_deform_destroy(&w->def);
    free(w->fixed);
    free(w->free_nodes);
    free(w->pts);
    free(w);
}

/* in_volume[v] = 1 for the nodes of volume cells (polyhedra: their face stream). */
static void mark_volume_nodes(const cm_mesh *mesh, unsigned char *in_volume)
{
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *ci = cm_cell_type_info(mesh->type[c]);
        if (!ci || ci->dim != 3) continue;
        int64_t b = mesh->offset[c], e = mesh->offset[c + 1];
        if (mesh->type[c] == CM_CELL_POLYHEDRON) {
            int64_t p = b + 1;
            for (int64_t f = 0; f < mesh->conn[b] && p < e; ++f) {
                int64_t n = mesh->conn[p++];
                for (int64_t i = 0; i < n && p < e; ++i, ++p)
                    in_volume[mesh->conn[p]] = 1;
            }
        } else {
            for (int64_t p = b; p < e; ++p)
                in_volume[mesh->conn[p]] = 1;
        }
    }
}

static cm_status dmffd_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                              const unsigned char *constrained, const cm_warp_options *opt,
                              void **state)
{
    (void)b;
    int n = opt->lattice ? opt->lattice : 10;
    if (n < 4 || n > 200)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_warp_create: dmffd lattice of %d control points per axis (4..200)", n);
    size_t nn = mesh->n_nodes;
    dmffd_warp *w = calloc(1, sizeof *w);
    unsigned char *in_volume = calloc(nn ? nn : 1, 1), *con = NULL;
    double *xyz = NULL;
    cm_status s = CM_OK;
    if (!w || !in_volume) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
        goto fail;
    }
    mark_volume_nodes(mesh, in_volume);
    for (size_t v = 0; v < nn; ++v) {
        if (constrained[v])
            ++w->n_fixed;
        else if (in_volume[v])
            ++w->n_free;
    }
    if (w->n_fixed == 0) {
        s = cm_error(ctx, CM_ERR_NUMERIC, "cm_warp_create: dmffd: no constrained node");
        goto fail;
    }
    size_t np = w->n_fixed + w->n_free;
    w->fixed = malloc(w->n_fixed * sizeof *w->fixed);
    w->free_nodes = malloc((w->n_free ? w->n_free : 1) * sizeof *w->free_nodes);
    w->pts = malloc(np * 3 * sizeof *w->pts);
    xyz = malloc(np * 3 * sizeof *xyz);
    con = calloc(np, 1);
    if (!w->fixed || !w->free_nodes || !w->pts || !xyz || !con) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
        goto fail;
    }
    size_t kf = 0, ku = 0, stray = 0;
    for (size_t v = 0; v < nn; ++v) {
        if (constrained[v]) {
            w->fixed[kf] = (int64_t)v;
            con[kf] = 1;
            memcpy(xyz + 3 * kf++, mesh->xyz + 3 * v, 3 * sizeof(double));
        } else if (in_volume[v]) {
            w->free_nodes[ku] = (int64_t)v;
            memcpy(xyz + 3 * (w->n_fixed + ku++), mesh->xyz + 3 * v, 3 * sizeof(double));
        } else {
            ++stray;
        }
    }
    if (stray)
        cm_log(ctx, CM_LOG_WARNING,
               "cm_warp_create: %zu unconstrained nodes belong to no volume cell; they are left "
               "where they are",
               stray);
    cm_deform_options dopt;
    cm_deform_options_init(&dopt);
    dopt.method = CM_DEFORM_DMFFD;
    dopt.lattice = n;
    dopt.clamp = opt->clamp;
    s = cm_deform_create(ctx, &dopt, np, xyz, con, NULL, &w->def);
    if (s < 0) {
        s = cm_error_prefix(ctx, s, "cm_warp_create: dmffd-%d", n);
        goto fail;
    }
    cm_deform_stats st;
    cm_deform_get_stats(w->def, &st);
    cm_log(ctx, CM_LOG_DEBUG,
           "dmffd-%d: %zu handles, %zu of %zu control points active, rank %zu (%zu clamped), "
           "sigma %.3g .. %.3g",
           n, st.dmffd.handles, st.dmffd.active, st.control_points, st.dmffd.rank,
           st.dmffd.clamped, st.dmffd.sigma_max, st.dmffd.sigma_min);
    free(in_volume), free(con), free(xyz);
    *state = w;
    return CM_OK;
fail:
    free(in_volume), free(con), free(xyz);
    dmffd_destroy(w);
    return s;
}

static cm_status dmffd_apply(cm_context *ctx, void *state, double *disp, double *residual)
{
    dmffd_warp *w = state;
    for (size_t i = 0; i < w->n_fixed; ++i)
        memcpy(w->pts + 3 * i, disp + 3 * w->fixed[i], 3 * sizeof(double));
    cm_status s = cm_deform_apply(ctx, w->def, w->pts, residual);
    if (s < 0) return cm_error_prefix(ctx, s, "cm_warp_apply: dmffd");
    for (size_t i = 0; i < w->n_free; ++i)
        memcpy(disp + 3 * w->free_nodes[i], w->pts + 3 * (w->n_fixed + i), 3 * sizeof(double));
    return CM_OK;
}

static cm_status dmffd_apply_transpose(cm_context *ctx, void *state, const double *v, double *out)
{
    dmffd_warp *w = state;
    size_t np = w->n_fixed + w->n_free;
    double *op = malloc(np * 3 * sizeof *op);
    if (!op) return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_apply_transpose: out of memory");
    /* the deformation's point order (apply's scratch holds v) */
    for (size_t i = 0; i < w->n_fixed; ++i)
        memcpy(w->pts + 3 * i, v + 3 * w->fixed[i], 3 * sizeof(double));
    for (size_t i = 0; i < w->n_free; ++i)
        memcpy(w->pts + 3 * (w->n_fixed + i), v + 3 * w->free_nodes[i], 3 * sizeof(double));
    cm_status s = cm_deform_apply_transpose(ctx, w->def, w->pts, op);
    if (s >= 0)
        for (size_t i = 0; i < w->n_fixed; ++i)
            for (int k = 0; k < 3; ++k)
                out[3 * w->fixed[i] + k] += op[3 * i + k];
    free(op);
    return s < 0 ? cm_error_prefix(ctx, s, "cm_warp_apply_transpose: dmffd") : s;
}

const cm_warp_method_ops cm_warp_dmffd = {
    "dmffd", dmffd_create, dmffd_apply, dmffd_destroy, NULL, dmffd_apply_transpose, NULL,
    NULL};
