/* The process runtime on PETSc and MPI (-DCADMORPH_WITH_PETSC=ON): PETSc initialised once
 * per process over the ranks mpirun started, rank and size on PETSC_COMM_WORLD, and the
 * gather of plain records that a distributed study uses. The distributed RBF solver
 * (rbf/petsc/rbf_petsc.c) builds on it. */
#include "cadmorph/parallel.h"
#include "cm_platform.h"

#include <petscsys.h>
#include <stdlib.h>
#include <string.h>

static int g_initialised_here; /* we called PetscInitialize, so we finalise */

int cm_parallel_available(void) { return 1; }

cm_status cm_parallel_petsc_error(cm_context *ctx, int code, const char *who, const char *what)
{
    const char *text = NULL;
    PetscErrorMessage(code, &text, NULL);
    return cm_error(ctx, code == PETSC_ERR_MEM ? CM_ERR_NOMEM : CM_ERR_INTERNAL,
                    "%s (PETSc): %s failed: %s (PETSc error %d)", who, what,
                    text ? text : "unknown error", code);
}

#define P(call) CM_PETSC_TRY("cm_parallel", call)

cm_status cm_parallel_initialize(cm_context *ctx)
{
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (up) return CM_OK;
    cm_status st = CM_OK;
    /* the program's signal handlers stay (they remove temporary outputs); PETSc's errors
     * come back as codes, not as printed tracebacks: the library never prints */
    P(PetscOptionsSetValue(NULL, "-no_signal_handler", NULL));
    P(PetscInitializeNoArguments());
    g_initialised_here = 1;
    P(PetscPushErrorHandler(PetscReturnErrorHandler, NULL));
done:
    return st;
}

void cm_parallel_rank(int *rank, int *size)
{
    int rk = 0, sz = 1;
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (up) {
        MPI_Comm_rank(PETSC_COMM_WORLD, &rk);
        MPI_Comm_size(PETSC_COMM_WORLD, &sz);
    }
    if (rank) *rank = rk;
    if (size) *size = sz;
}

void cm_parallel_finalize(void)
{
    PetscBool up = PETSC_FALSE;
    PetscInitialized(&up);
    if (up && g_initialised_here) PetscFinalize();
    g_initialised_here = 0;
}

cm_status cm_parallel_allgather(cm_context *ctx, const void *mine, size_t n, size_t size,
                                 void **all, size_t *n_all)
{
    int rank, ranks;
    cm_parallel_rank(&rank, &ranks);
    *all = NULL;
    *n_all = 0;
    long long my = (long long)n, *cnt = malloc((size_t)ranks * sizeof *cnt);
    int *bytes = malloc(2 * (size_t)ranks * sizeof *bytes);
    cm_status st = CM_OK;
    if (!cnt || !bytes) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_parallel_allgather: out of memory");
        goto done;
    }
    /* a rank out of memory still takes part, or the others would wait for it forever */
    if (ranks > 1 &&
        MPI_Allgather(&my, 1, MPI_LONG_LONG, cnt, 1, MPI_LONG_LONG, PETSC_COMM_WORLD) != MPI_SUCCESS) {
        st = cm_error(ctx, CM_ERR_INTERNAL, "cm_parallel_allgather: MPI_Allgather failed");
        goto done;
    }
    if (ranks == 1) cnt[0] = my;
    size_t total = 0;
    for (int q = 0; q < ranks; ++q) {
        if ((double)total * (double)size + (double)cnt[q] * (double)size > 2e9) {
            st = cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_parallel_allgather: more than 2 GB");
            goto done;
        }
        bytes[q] = (int)((size_t)cnt[q] * size);
        bytes[ranks + q] = (int)(total * size);
        total += (size_t)cnt[q];
    }
    *all = malloc(total * size > 0 ? total * size : 1);
    if (!*all) {
        st = cm_error(ctx, CM_ERR_NOMEM, "cm_parallel_allgather: out of memory");
        goto done;
    }
    if (ranks == 1) {
        if (n) memcpy(*all, mine, n * size);
    } else if (MPI_Allgatherv(mine, bytes[rank], MPI_BYTE, *all, bytes, bytes + ranks, MPI_BYTE,
                              PETSC_COMM_WORLD) != MPI_SUCCESS) {
        st = cm_error(ctx, CM_ERR_INTERNAL, "cm_parallel_allgather: MPI_Allgatherv failed");
        free(*all);
        *all = NULL;
        goto done;
    }
    *n_all = total;
done:
    free(cnt);
    free(bytes);
    return st;
}
