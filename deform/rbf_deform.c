/* The RBF space deformation of the handle metaphor (DESIGN.md: deform/): one triharmonic RBF
 * (r^3 + linear) through the constrained points, evaluated at the others. Unlike the volume
 * warp (warp.h) it needs no volume cells, so it deforms surface meshes too. */
#include "cadmorph/deform.h"
#include "cadmorph/rbf.h"

#include <stdlib.h>
#include <string.h>

cm_status cm_deform_rbf(cm_context *ctx, size_t n, const double *xyz,
                        const unsigned char *constrained, double *disp)
{
    if (!xyz || !constrained || !disp)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_rbf: NULL input");
    size_t nc = 0;
    for (size_t i = 0; i < n; ++i)
        nc += constrained[i] != 0;
    size_t nf = n - nc;
    double *c = malloc((nc ? nc : 1) * 3 * sizeof *c), *v = malloc((nc ? nc : 1) * 3 * sizeof *v);
    double *f = malloc((nf ? nf : 1) * 3 * sizeof *f), *out = malloc((nf ? nf : 1) * 3 * sizeof *out);
    cm_rbf *rbf = NULL;
    cm_status s = c && v && f && out ? CM_OK
                                     : cm_error(ctx, CM_ERR_NOMEM, "cm_deform_rbf: out of memory");
    for (size_t i = 0, a = 0, b = 0; s >= 0 && i < n; ++i)
        if (constrained[i]) {
            memcpy(c + 3 * a, xyz + 3 * i, 3 * sizeof *c);
            memcpy(v + 3 * a++, disp + 3 * i, 3 * sizeof *v);
        } else {
            memcpy(f + 3 * b++, xyz + 3 * i, 3 * sizeof *f);
        }
    if (s >= 0) s = cm_rbf_create(ctx, CM_RBF_TRIHARMONIC, 3, nc, c, &rbf);
    if (s >= 0) s = cm_rbf_solve(ctx, rbf, 3, v);
    if (s >= 0 && nf) s = cm_rbf_evaluate(ctx, rbf, nf, f, out);
    for (size_t i = 0, b = 0; s >= 0 && i < n; ++i)
        if (!constrained[i]) memcpy(disp + 3 * i, out + 3 * b++, 3 * sizeof *disp);
    cm_rbf_destroy(&rbf);
    free(c);
    free(v);
    free(f);
    free(out);
    return s;
}
