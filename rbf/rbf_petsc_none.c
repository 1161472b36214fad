/* The distributed solver in a build without PETSc (-DCADMORPH_WITH_PETSC=OFF, the default):
 * asking for it is a clear error, the rest of the API is inert. */
#include "rbf_internal.h"

#include <stdlib.h>
#include <string.h>

int cm_rbf_petsc_available(void) { return 0; }

cm_status cm_rbf_petsc_initialize(cm_context *ctx)
{
    return cm_error(ctx, CM_ERR_UNSUPPORTED,
                    "cm_rbf: this cadmorph was built without PETSc (configure with "
                    "-DCADMORPH_WITH_PETSC=ON for the distributed solver)");
}

void cm_rbf_petsc_rank(int *rank, int *size)
{
    if (rank) *rank = 0;
    if (size) *size = 1;
}

void cm_rbf_petsc_finalize(void) {}

cm_status cm_rbf_petsc_allgather(cm_context *ctx, const void *mine, size_t n, size_t size,
                                 void **all, size_t *n_all)
{
    *all = malloc(n * size > 0 ? n * size : 1);
    *n_all = 0;
    if (!*all) return cm_error(ctx, CM_ERR_NOMEM, "cm_rbf_petsc_allgather: out of memory");
    if (n) memcpy(*all, mine, n * size);
    *n_all = n;
    return CM_OK;
}

cm_status cm_rbf_petsc_setup(cm_context *ctx, cm_rbf *r, int threads)
{
    (void)r;
    (void)threads;
    return cm_rbf_petsc_initialize(ctx);
}

cm_status cm_rbf_petsc_solve(cm_context *ctx, cm_rbf *r, size_t nc, const double *f, double *w,
                             double *q)
{
    (void)r, (void)nc, (void)f, (void)w, (void)q;
    return cm_rbf_petsc_initialize(ctx);
}

void cm_rbf_petsc_destroy(cm_rbf_petsc **ps) { (void)ps; }

int cm_rbf_petsc_evaluate(const cm_rbf *r, size_t n, const double *p, double *out, int threads)
{
    (void)r, (void)n, (void)p, (void)out, (void)threads;
    return 0;
}
