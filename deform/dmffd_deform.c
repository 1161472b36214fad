/* The DM-FFD space deformation of the handle metaphor (`cadmorph deform --method dmffd`): one
 * cubic B-spline lattice of n^3 control points enclosing the whole mesh, DM-FFD (dmffd.c)
 * through the constrained points, evaluated at the others. Like cm_deform_rbf it needs no
 * cells; unlike the RBF it is least squares, so the constrained points keep their prescribed
 * value and the residual says how far the lattice itself misses them. */
#include "cadmorph/deform.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The lattice's margin around the bounding box, relative to its diagonal (as the warp's):
 * every node lies strictly inside the valid domain. */
#define DEFORM_DMFFD_MARGIN 1e-3

cm_status cm_deform_dmffd(cm_context *ctx, size_t n, const double *xyz,
                          const unsigned char *constrained, int lattice, double clamp,
                          double *disp, double *residual)
{
    if (!xyz || !constrained || !disp)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_dmffd: NULL input");
    if (lattice < 4 || lattice > 200)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_dmffd: lattice of %d control points per axis (4..200)",
                        lattice);
    size_t nc = 0;
    double bb[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; ++i) {
        nc += constrained[i] != 0;
        for (int a = 0; a < 3; ++a) bb[a] = fmin(bb[a], xyz[3 * i + a]), bb[a + 3] = fmax(bb[a + 3], xyz[3 * i + a]);
    }
    if (nc == 0) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_dmffd: no constrained point");
    size_t nf = n - nc;
    double *c = malloc(nc * 3 * sizeof *c), *h = malloc(nc * 3 * sizeof *h);
    double *f = malloc((nf ? nf : 1) * 3 * sizeof *f), *out = malloc((nf ? nf : 1) * 3 * sizeof *out);
    double *dc = NULL;
    cm_ffd *ffd = NULL;
    cm_dmffd *dm = NULL;
    cm_status s = c && h && f && out ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "cm_deform_dmffd: out of memory");
    for (size_t i = 0, a = 0, b = 0; s >= 0 && i < n; ++i)
        if (constrained[i]) {
            memcpy(c + 3 * a, xyz + 3 * i, 3 * sizeof *c);
            memcpy(h + 3 * a++, disp + 3 * i, 3 * sizeof *h);
        } else {
            memcpy(f + 3 * b++, xyz + 3 * i, 3 * sizeof *f);
        }
    cm_ffd_desc desc;
    cm_ffd_desc_enclosing(&desc, bb, DEFORM_DMFFD_MARGIN, lattice);
    if (s >= 0) s = cm_ffd_create(ctx, &desc, &ffd);
    if (s >= 0 && !(dc = malloc(cm_ffd_control_count(ffd) * 3 * sizeof *dc)))
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_deform_dmffd: out of memory");
    cm_dmffd_options o;
    cm_dmffd_options_init(&o);
    if (clamp > 0) o.eps = clamp;
    if (s >= 0) s = cm_dmffd_create(ctx, ffd, nc, c, &o, &dm);
    if (s >= 0) s = cm_dmffd_solve(ctx, dm, h, dc);
    if (s >= 0 && nf) s = cm_ffd_deform(ctx, ffd, dc, nf, f, out, NULL);
    for (size_t i = 0, b = 0; s >= 0 && i < n; ++i)
        if (!constrained[i]) memcpy(disp + 3 * i, out + 3 * b++, 3 * sizeof *disp);
    if (s >= 0 && residual) {
        cm_dmffd_info info;
        cm_dmffd_get_info(dm, &info);
        *residual = info.residual_abs;
        cm_log(ctx, CM_LOG_DEBUG, "deform dmffd-%d: %zu handles, %zu of %zu control points active, rank %zu (%zu clamped)",
               lattice, info.handles, info.active, cm_ffd_control_count(ffd), info.rank, info.clamped);
    }
    if (s < 0) s = cm_error_prefix(ctx, s, "cm_deform_dmffd");
    cm_dmffd_destroy(&dm);
    cm_ffd_destroy(&ffd);
    free(c), free(h), free(f), free(out), free(dc);
    return s;
}
