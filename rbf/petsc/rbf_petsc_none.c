/* The distributed solver in a build without PETSc (-DCADMORPH_WITH_PETSC=OFF, the default):
 * asking for it is a clear error, the rest is inert. */
#include "rbf_internal.h"

static cm_status not_built(cm_context *ctx)
{
    return cm_error(ctx, CM_ERR_UNSUPPORTED,
                    "cm_rbf: this cadmorph was built without PETSc (configure with "
                    "-DCADMORPH_WITH_PETSC=ON for the distributed solver)");
}

cm_status cm_rbf_petsc_setup(cm_context *ctx, cm_rbf *r, int threads)
{
    (void)r;
    (void)threads;
    return not_built(ctx);
}

cm_status cm_rbf_petsc_solve(cm_context *ctx, cm_rbf *r, size_t nc, const double *f, double *w,
                             double *q)
{
    (void)r, (void)nc, (void)f, (void)w, (void)q;
    return not_built(ctx);
}

void cm_rbf_petsc_destroy(cm_rbf_petsc **ps) { (void)ps; }

int cm_rbf_petsc_evaluate(const cm_rbf *r, size_t n, const double *p, double *out, int threads)
{
    (void)r, (void)n, (void)p, (void)out, (void)threads;
    return 0;
}

int cm_rbf_petsc_evaluate_transpose(const cm_rbf *r, size_t n, const double *p, int nc,
                                    const double *v, double *out, int threads)
{
    (void)r, (void)n, (void)p, (void)nc, (void)v, (void)out, (void)threads;
    return 0;
}
