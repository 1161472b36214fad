/* One TetGen run in a child process (child_process.h): the PLC in, the tets, points and
 * boundary triangles with their markers out, or a status saying how TetGen ended (its code,
 * a crash, an abort, the time limit). Private to meshgen/. */
#ifndef CADMORPH_MESHGEN_TETGEN_RUN_H
#define CADMORPH_MESHGEN_TETGEN_RUN_H

#include "cadmorph/core.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* A piecewise linear complex of triangles: xyz #P×3, tri #T×3 0-based, marker #T (> 0). */
typedef struct cm_tetgen_plc {
    size_t n_points, n_triangles;
    const double *xyz;
    const int64_t *tri;
    const int *marker;
} cm_tetgen_plc;

/* TetGen's output, malloc'd: xyz #P×3, tet #T×4, triface #F×3 (0-based), trimarker #F. */
typedef struct cm_tetgen_result {
    size_t n_points, n_tets, n_trifaces;
    int corners; /* nodes per tet TetGen reported (4 for linear tets) */
    double *xyz;
    int32_t *tet, *triface, *trimarker;
} cm_tetgen_result;

/* Runs tetrahedralize(switches) on plc in a child. CM_OK with *res filled; on failure
 * CM_ERR_NUMERIC (TetGen's error code, a crash or an abort: "TetGen crashed (signal 11, ...)
 * with switches ..."), CM_ERR_UNSUPPORTED for the time limit ("TetGen did not finish in 5 s
 * ..."), CM_ERR_NOMEM (TetGen's code 1), and *failure, when not NULL, set to 1 for a code,
 * 2 for a crash or abort, 3 for the time limit. `what` opens the message. */
cm_status cm_tetgen_run(cm_context *ctx, const char *what, const cm_tetgen_plc *plc,
                        const char *switches, double time_limit, cm_tetgen_result *res,
                        int *failure);

void cm_tetgen_result_free(cm_tetgen_result *res);

#ifdef __cplusplus
}
#endif
#endif
