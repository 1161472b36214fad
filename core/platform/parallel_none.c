/* The process runtime in a build without PETSc (-DCADMORPH_WITH_PETSC=OFF, the default):
 * one rank; asking to initialise MPI is a clear error, the rest is inert. */
#include "cadmorph/parallel.h"

#include <stdlib.h>
#include <string.h>

int cm_parallel_available(void) { return 0; }

cm_status cm_parallel_initialize(cm_context *ctx)
{
    return cm_error(ctx, CM_ERR_UNSUPPORTED,
                    "cm_parallel_initialize: this cadmorph was built without PETSc/MPI "
                    "(configure with -DCADMORPH_WITH_PETSC=ON)");
}

void cm_parallel_rank(int *rank, int *size)
{
    if (rank) *rank = 0;
    if (size) *size = 1;
}

void cm_parallel_finalize(void) {}

cm_status cm_parallel_allgather(cm_context *ctx, const void *mine, size_t n, size_t size,
                                void **all, size_t *n_all)
{
    *all = malloc(n * size > 0 ? n * size : 1);
    *n_all = 0;
    if (!*all) return cm_error(ctx, CM_ERR_NOMEM, "cm_parallel_allgather: out of memory");
    if (n) memcpy(*all, mine, n * size);
    *n_all = n;
    return CM_OK;
}
