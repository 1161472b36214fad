/* Staten-style parameter sweeps of the benchmark models (issue 6): M(0) morphed onto G(t) for
 * t = 1/N .. 1 by several methods, absolutely (each from M(0)) or relatively (each from the
 * previous step), with quality, distance to G(t) and stage times per step; and the SVG plot. */
#ifndef CADMORPH_BENCH_SWEEP_H
#define CADMORPH_BENCH_SWEEP_H

#include "cadmorph/mesh.h"
#include "cadmorph/rbf.h"
#include "cadmorph/surface.h"

enum { CM_SWEEP_ABSOLUTE = 1, CM_SWEEP_RELATIVE = 2 };

/* The methods compared: surface morph + volume warp kernel. */
enum {
    CM_SWEEP_RBF_S = 0,
    CM_SWEEP_PROJECT = 1,
    CM_SWEEP_RBF_S_BIHARMONIC = 2,
    CM_SWEEP_N_METHODS = 3
};

/* "rbf-s", "project", "rbf-s-biharmonic"; NULL out of range. */
const char *cm_sweep_method_name(int method);
/* Index of a method name, -1 if unknown. */
int cm_sweep_method_from_name(const char *name);
/* "absolute" / "relative". */
const char *cm_sweep_mode_name(int mode);

typedef struct cm_sweep_options {
    const char *model;   /* bore | pipe | bracket */
    const char *mesh;    /* "tet", "hex" or the path of a mesh of G(0) */
    double size;         /* tet: target edge (<= 0: 0.2); hex: cells of about this size
                            (<= 0: 0.1; resolution scales as 0.1 / size) */
    int modes;           /* CM_SWEEP_ABSOLUTE | CM_SWEEP_RELATIVE */
    int steps;           /* N >= 1 */
    unsigned methods;    /* bit m for method m; 0: all */
    const char *out_dir; /* existing directory for G_<t>.step (removed unless write_step),
                            the meshes at 50 and 100 %, and nothing else */
    int write_step;      /* keep DIR/G_<t>.step */
    int write_meshes;    /* write DIR/<method>_<mode>_<pct>.vtu at 50 % and 100 % */
} cm_sweep_options;

void cm_sweep_options_init(cm_sweep_options *opt);

/* One row: one model x mesh x mode x method x step. Times in seconds. In absolute mode the
 * classification of M(0) and the warp factorisation happen once (one warp per kernel, shared
 * by rbf-s and project): their times are repeated in each method's step-1 row. t_sample:
 * writing, reading and sampling G(t), shared by every method and mode of the step. */
typedef struct cm_sweep_row {
    int mode, method, step;
    double t;
    double min_sj, mean_sj;
    size_t inverted, cells;
    double max_dist;
    size_t outside; /* face nodes whose (u',v') left the trimmed face (put on its closest
                       point instead; cm_surface_morph_stats) */
    double t_sample, t_classify, t_surface, t_volume_solve, t_evaluation, t_quality, t_distance,
        t_write;
} cm_sweep_row;

typedef struct cm_sweep_result {
    char model[16];
    char mesh[16]; /* "tet", "hex" or "file" */
    size_t nodes, cells, boundary_nodes;
    double diagonal;          /* bbox diagonal of G(0) */
    double min_sj0, mean_sj0; /* quality of M(0) (the curves start there) */
    size_t inverted0;
    int threads;
    size_t n_rows, cap_rows;
    cm_sweep_row *rows;
    /* series that stopped on an error: bit (mode - 1) * 3 + method; message of the first */
    unsigned failed;
    char failure[512];
} cm_sweep_result;

/* Runs the sweep. A method whose step fails (a numerical error, a surface morph that cannot
 * go on) ends that series with a CM_LOG_WARNING and a CM_WARNING return; the others go on.
 * Progress: cm_progress stage "sweep", one unit per model step. */
cm_status cm_sweep_run(cm_context *ctx, const cm_sweep_options *opt, cm_sweep_result **result);
void cm_sweep_result_destroy(cm_sweep_result **result);

/* DIR/sweep.csv: header then one row per cm_sweep_row. */
cm_status cm_sweep_write_csv(cm_context *ctx, const cm_sweep_result *r, const char *path);

/* The plot: min scaled Jacobian against percent of parameter change, one polyline per
 * method x mode (solid absolute, dashed relative), axes, ticks, legend, title. */
cm_status cm_sweep_write_svg(cm_context *ctx, const cm_sweep_result *r, const char *path);

#endif
