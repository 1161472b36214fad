/* cadmorph process runtime: the MPI ranks a program was started on (through PETSc, in builds
 * with -DCADMORPH_WITH_PETSC=ON). The distributed RBF solver (CM_RBF_SOLVER_PETSC, rbf.h)
 * and the distributed study (cm_study_run with ranks > 1, study.h) run on it; a program
 * started by mpirun initialises it first when it needs its rank, and finalises it before it
 * ends. Without PETSc every call below is inert: one rank, rank 0. Conventions: see core.h.
 */
#ifndef CADMORPH_PARALLEL_H
#define CADMORPH_PARALLEL_H

#include "cadmorph/core.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* 1 if this build has the MPI runtime (-DCADMORPH_WITH_PETSC=ON), else 0 and the calls
 * below do nothing. */
CM_API int cm_parallel_available(void);
/* Initialises PETSc (and MPI) once per process, collectively over the ranks that mpirun
 * started, unless the caller already did; PETSc's own options come from the PETSC_OPTIONS
 * environment variable (prefix cm_: PETSC_OPTIONS=-cm_ksp_monitor). cm_rbf_create calls it
 * for the PETSC solver by itself; a program calls it first when it needs the rank earlier.
 * CM_ERR_UNSUPPORTED without PETSc. */
CM_API cm_status cm_parallel_initialize(cm_context *ctx);
/* This process's rank and the number of ranks (0 and 1 before initialisation or without
 * PETSc); either pointer may be NULL. */
CM_API void cm_parallel_rank(int *rank, int *size);
/* Finalises PETSc (and MPI) if cm_parallel_initialize initialised it; collective, call it
 * once before the program ends, after destroying every PETSC-solver cm_rbf. */
CM_API void cm_parallel_finalize(void);
/* Every rank's n records of `size` bytes (mine) to every rank: *all (malloc'd, free() it)
 * gets them in rank order, *n_all their count; collective. On one rank, or without PETSc, a
 * copy of mine. Plain-data records only (a study's rows: cm_study_run with ranks > 1). */
CM_API cm_status cm_parallel_allgather(cm_context *ctx, const void *mine, size_t n, size_t size,
                                       void **all, size_t *n_all);

#ifdef __cplusplus
}
#endif
#endif
