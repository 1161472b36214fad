/* The platform layer's internal interface (library cm_platform): what the numerical modules
 * need from the machine beside the public blas.h and parallel.h. Not a public header: the
 * modules that link cm_platform see it on their include path.
 *
 * Conventions: see core.h. */
#ifndef CADMORPH_PLATFORM_INTERNAL_H
#define CADMORPH_PLATFORM_INTERNAL_H

#include "cadmorph/core.h"

#include <stddef.h>

/* Sets OpenBLAS's thread count for the calls that follow to `want`, or fewer if the
 * address-space limit cannot back their 128 MB buffers (blas.h, point 2); got (may be NULL)
 * receives the count. CM_ERR_NOMEM, with a message starting with who, if not even the
 * calling thread's buffer fits: OpenBLAS would spin forever trying to allocate it. */
cm_status cm_blas_threads(cm_context *ctx, const char *who, int want, int *got);
/* How many of `want` threads can call one-thread BLAS at the same time (each needs its own
 * OpenBLAS buffer) under the address-space limit: want if there is none, at least 1. */
int cm_blas_callers(int want);

/* A buffer of bytes that may be large (alloc_large.c): from 2 MB on, on 2 MB boundaries and
 * marked for transparent huge pages; populate: faulted in now, in one call (for a buffer one
 * thread fills; leave it 0 where threads fill their own parts). Freed with free(). */
void *cm_alloc_large(size_t bytes, int populate);

/* PETSc builds: a nonzero PETSc error code as a status (CM_ERR_NOMEM for PETSc's out of
 * memory, else CM_ERR_INTERNAL) with PETSc's message: "<who> (PETSc): <what> failed: ...". */
cm_status cm_parallel_petsc_error(cm_context *ctx, int code, const char *who, const char *what);
/* Runs a PETSc call in a function that has a cm_context *ctx, a cm_status st and a label
 * done: on an error code, st gets the status and control goes to done. */
#define CM_PETSC_TRY(who, call)                                          \
    do {                                                                 \
        int cm_e_ = (int)(call);                                         \
        if (cm_e_) {                                                     \
            st = cm_parallel_petsc_error(ctx, cm_e_, who, #call);        \
            goto done;                                                   \
        }                                                                \
    } while (0)

#endif
