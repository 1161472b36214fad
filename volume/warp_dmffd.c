/* The DM-FFD warp method (paper shape-deformation-benchmarks section 2.2, Fig. 13-14): one
 * cubic B-spline lattice whose valid domain is the mesh's bounding box, DM-FFD from the
 * constrained nodes (the handles), evaluated at every other node of a volume cell. The SVD is
 * done once in create; apply is C = Phi^+ H and one sparse product per node. Least squares,
 * not interpolation: the constrained nodes keep their prescribed displacement (the interface
 * contract) and the residual says how far the space deformation itself misses them. */
#include "warp_method.h"

#include "cadmorph/deform.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Margin around the bounding box, relative to its diagonal: the boundary nodes then lie
 * strictly inside the domain (not on its faces) and the lattice still hugs the mesh. */
#define DMFFD_MARGIN 1e-3

typedef struct dmffd_warp {
    cm_ffd *ffd;
    cm_dmffd *dm;
    size_t n_fixed, n_free;
    int64_t *fixed, *free_nodes;
    double *free_xyz, *fixed_xyz;
    double *h, *dc, *out;
} dmffd_warp;

static void dmffd_destroy(void *state)
{
    dmffd_warp *w = state;
    if (!w) return;
    cm_dmffd_destroy(&w->dm);
    cm_ffd_destroy(&w->ffd);
    free(w->fixed);
    free(w->free_nodes);
    free(w->free_xyz);
    free(w->fixed_xyz);
    free(w->h);
    free(w->dc);
    free(w->out);
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
    unsigned char *in_volume = calloc(nn ? nn : 1, 1);
    cm_status s = CM_OK;
    if (!w || !in_volume) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
        goto fail;
    }
    mark_volume_nodes(mesh, in_volume);
    double bb[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (size_t v = 0; v < nn; ++v) {
        if (constrained[v])
            ++w->n_fixed;
        else if (in_volume[v])
            ++w->n_free;
        if (!constrained[v] && !in_volume[v]) continue;
        for (int a = 0; a < 3; ++a) {
            bb[a] = fmin(bb[a], mesh->xyz[3 * v + a]);
            bb[a + 3] = fmax(bb[a + 3], mesh->xyz[3 * v + a]);
        }
    }
    if (w->n_fixed == 0) {
        s = cm_error(ctx, CM_ERR_NUMERIC, "cm_warp_create: dmffd: no constrained node");
        goto fail;
    }
    w->fixed = malloc(w->n_fixed * sizeof *w->fixed);
    w->fixed_xyz = malloc(w->n_fixed * 3 * sizeof *w->fixed_xyz);
    w->h = malloc(w->n_fixed * 3 * sizeof *w->h);
    w->free_nodes = malloc((w->n_free ? w->n_free : 1) * sizeof *w->free_nodes);
    w->free_xyz = malloc((w->n_free ? w->n_free : 1) * 3 * sizeof *w->free_xyz);
    w->out = malloc((w->n_free ? w->n_free : 1) * 3 * sizeof *w->out);
    if (!w->fixed || !w->fixed_xyz || !w->h || !w->free_nodes || !w->free_xyz || !w->out) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
        goto fail;
    }
    size_t kf = 0, ku = 0, stray = 0;
    for (size_t v = 0; v < nn; ++v) {
        if (constrained[v]) {
            w->fixed[kf] = (int64_t)v;
            memcpy(w->fixed_xyz + 3 * kf++, mesh->xyz + 3 * v, 3 * sizeof(double));
        } else if (in_volume[v]) {
            w->free_nodes[ku] = (int64_t)v;
            memcpy(w->free_xyz + 3 * ku++, mesh->xyz + 3 * v, 3 * sizeof(double));
        } else {
            ++stray;
        }
    }
    if (stray)
        cm_log(ctx, CM_LOG_WARNING,
               "cm_warp_create: %zu unconstrained nodes belong to no volume cell; they are left "
               "where they are",
               stray);
    cm_ffd_desc desc;
    cm_ffd_desc_enclosing(&desc, bb, DMFFD_MARGIN, n);
    s = cm_ffd_create(ctx, &desc, &w->ffd);
    if (s < 0) goto fail;
    w->dc = malloc(cm_ffd_control_count(w->ffd) * 3 * sizeof *w->dc);
    if (!w->dc) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: out of memory");
        goto fail;
    }
    cm_dmffd_options dopt;
    cm_dmffd_options_init(&dopt);
    if (opt->clamp > 0) dopt.eps = opt->clamp;
    s = cm_dmffd_create(ctx, w->ffd, w->n_fixed, w->fixed_xyz, &dopt, &w->dm);
    if (s < 0) {
        s = cm_error_prefix(ctx, s, "cm_warp_create: dmffd-%d", n);
        goto fail;
    }
    cm_dmffd_info info;
    cm_dmffd_get_info(w->dm, &info);
    cm_log(ctx, CM_LOG_DEBUG,
           "dmffd-%d: %zu handles, %zu of %zu control points active, rank %zu (%zu clamped), "
           "sigma %.3g .. %.3g",
           n, info.handles, info.active, cm_ffd_control_count(w->ffd), info.rank, info.clamped,
           info.sigma_max, info.sigma_min);
    free(in_volume);
    *state = w;
    return CM_OK;
fail:
    free(in_volume);
    dmffd_destroy(w);
    return s;
}

static cm_status dmffd_apply(cm_context *ctx, void *state, double *disp, double *residual)
{
    dmffd_warp *w = state;
    for (size_t i = 0; i < w->n_fixed; ++i)
        memcpy(w->h + 3 * i, disp + 3 * w->fixed[i], 3 * sizeof(double));
    cm_status s = cm_dmffd_solve(ctx, w->dm, w->h, w->dc);
    if (s >= 0) s = cm_ffd_deform(ctx, w->ffd, w->dc, w->n_free, w->free_xyz, w->out, NULL);
    if (s < 0) return cm_error_prefix(ctx, s, "cm_warp_apply: dmffd");
    for (size_t i = 0; i < w->n_free; ++i)
        memcpy(disp + 3 * w->free_nodes[i], w->out + 3 * i, 3 * sizeof(double));
    cm_dmffd_info info;
    cm_dmffd_get_info(w->dm, &info);
    *residual = info.residual_abs;
    return CM_OK;
}

const cm_warp_method_ops cm_warp_dmffd = {"dmffd", dmffd_create, dmffd_apply, dmffd_destroy,
                                          NULL};
