/* cadmorph studies: a mesh M0 of G0 morphed onto every member of a family of geometries
 * G(1..n) of G0's topology (DESIGN.md, study/), by several methods, absolutely and/or
 * relatively, with quality, distance to G and stage times per variant; the CSV table and the
 * SVG plot of the results. Conventions: see core.h.
 *
 *   absolute: one cm_morpher on M0 (one classification, one factorisation per warp method)
 *             shared by every variant: cm_morpher_apply_batch onto batches of G(i) (one
 *             multi-column warp apply per batch; cm_study_options.batch);
 *   relative: G(i-1) -> G(i) step by step, one morpher per method re-based
 *             (cm_morpher_rebase) on its previous result and that result's geometry.
 * The family comes from a callback (cm_study_family: the built-in models of models.h use one
 * through cm_sweep_run) or from a list of STEP files (cm_study_family_files). A variant that
 * cannot be read or whose topology differs from G0 is a row with its error, not the end of
 * the study. Progress: cm_progress stage "study", done/total = variants (before each batch:
 * done jumps by the batch size).
 */
#ifndef CADMORPH_STUDY_H
#define CADMORPH_STUDY_H

#include "cadmorph/morph.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { CM_STUDY_ABSOLUTE = 1, CM_STUDY_RELATIVE = 2, CM_STUDY_BOTH = 3 };

/* No longer used (targets are not sampled: the distance check projects each boundary node
 * onto its own CAD entity of the target); kept so that code naming it still compiles. */
#define CM_STUDY_TARGET_H_SCALE 4.0

/* The largest automatic batch of absolute variants (cm_study_options.batch 0): 60 columns. */
#define CM_STUDY_BATCH_MAX 20

/* "absolute" / "relative" ("?" otherwise). */
CM_API const char *cm_study_mode_name(int mode);

/* ---- methods: a surface morph and a warp, named ----
 * Names (one table in the study module; a new warp method of warp.h is a study method without
 * changes here):
 *   "rbf-s"              RBF-S surface morph + triharmonic RBF warp (the method)
 *   "project"            closest-point surface + triharmonic RBF warp (baseline)
 *   "rbf-s-biharmonic"   RBF-S + biharmonic RBF warp (the paper's comparison)
 *   "<warp>"             closest-point surface + that warp: "rbf", "rbf-biharmonic", ...
 *   "rbf-s-<warp>", "project-<warp>"   RBF-S / closest-point surface + that warp
 * where <warp> is any name of cm_warp_method_name. A method keeps the name it was given
 * (rows and files say "rbf" when asked for "rbf", although it is the same as "project"). */
#define CM_STUDY_METHOD_NAME 48

typedef struct cm_study_method {
    char name[CM_STUDY_METHOD_NAME];
    cm_morph_method method;
} cm_study_method;

/* CM_ERR_ARGUMENT (message lists the accepted forms) for an unknown name. */
CM_API cm_status cm_study_method_parse(cm_context *ctx, const char *name, cm_study_method *out);
/* A comma-separated list into out (cap entries); *n: how many. Empty entries, duplicates and
 * more than cap methods are CM_ERR_ARGUMENT. */
CM_API cm_status cm_study_methods_parse(cm_context *ctx, const char *list, cm_study_method *out,
                                 size_t cap, size_t *n);
/* The three methods the sweeps compare (rbf-s, project, rbf-s-biharmonic) into out (cap >= 3);
 * returns how many were written. */
CM_API size_t cm_study_default_methods(cm_study_method *out, size_t cap);
/* A stable colour slot of a method for plots: its row in the named table (0, 1, 2), others
 * from 3 on in the order given (k: the method's position in its study). */
CM_API int cm_study_method_slot(const cm_study_method *m, size_t k);
/* The accepted forms for usage and help text, e.g. "rbf-s, project, rbf-s-biharmonic, <warp>,
 * rbf-s-<warp>, project-<warp> (<warp>: rbf|rbf-biharmonic)", into buf (size bytes). */
CM_API void cm_study_method_help(char *buf, size_t size);

/* ---- the family of geometries ---- */

typedef struct cm_study_family {
    size_t n; /* variants 0 .. n-1 (the morph targets; G0 is given separately) */
    /* G of variant i into *g (the study destroys it). Any error becomes variant i's rows
     * (its message with them); only CM_ERR_NOMEM (and CM_ERR_INTERRUPTED) ends the study. */
    cm_status (*load)(cm_context *ctx, void *user, size_t i, cm_cad_model **g);
    /* A short name of variant i for file names and the CSV (the STEP file's stem, "050"). */
    void (*label)(void *user, size_t i, char *buf, size_t size);
    /* Its parameter t in [0, 1] (CSV columns t, percent; the plot's x = t * x_max).
     * NULL: (i + 1) / n. */
    double (*param)(void *user, size_t i);
    void (*destroy)(void *user); /* frees user; NULL if nothing to free */
    void *user;
    const char *x_label; /* the plot's x axis; NULL: "variant" */
    double x_max;        /* the plot's x range [0, x_max]; 0: n */
    double x_tick;       /* its tick spacing; 0: 1, 2 or 5 x 10^k for about 6 ticks */
    /* The x range is [x_min, x_max] (x_min default 0: x = t * x_max) and M0 sits at x0
     * (default 0): a design table's sweep of one parameter plots against its values. */
    double x_min, x0;
    /* Named values of each variant for extra CSV columns (a design table's parameters):
     * n_values names, and values(user, i) the n_values of variant i. 0 / NULL: none. */
    size_t n_values;
    const char *const *value_names;
    const double *(*values)(void *user, size_t i);
} cm_study_family;

/* A family of STEP files: variant i is paths[i] read by cm_cad_read (opt may be NULL), its
 * label the file name without directory and extension. paths are copied. */
CM_API cm_status cm_study_family_files(cm_context *ctx, const char *const *paths, size_t n,
                                const cm_cad_read_options *opt, cm_study_family *family);
/* Calls family->destroy and clears *family. */
CM_API void cm_study_family_release(cm_study_family *family);

/* The variants of `cadmorph study --variants LIST`: LIST is a text file of STEP paths (one per
 * line; blank lines and '#' comments skipped, surrounding blanks trimmed, a relative path is
 * relative to the list file's directory) or, when it is not an existing file and contains
 * '*', '?' or '[', a glob(3) pattern (matches sorted). Every path must name a readable
 * regular file. Errors: CM_ERR_IO "LIST: cannot open: ...", "LIST: not a regular file (a
 * FIFO)" or "LIST:<line>: <path>: cannot open: No such file ..." (or "not a regular file
 * (...)"), CM_ERR_FORMAT "LIST: no STEP paths" for an empty list, "LIST:<line>: longer than K
 * bytes: not a list of STEP paths" (K = PATH_MAX + 256), a NUL byte, or a STEP file given as
 * the list; CM_ERR_IO for a glob matching no file. *paths: *n strings, free with cm_study_paths_free. */
CM_API cm_status cm_study_read_list(cm_context *ctx, const char *list, char ***paths, size_t *n);

/* The variants of a design table (a `--variants T.csv` whose header is `step,<p1>,...`,
 * cm_design_table_detect): every row but row base (G0's), in table order, read by cm_cad_read
 * (opt may be NULL), labelled by the file name without extension, with the parameters as
 * named values (CSV columns). When exactly one parameter differs between the rows (a
 * one-parameter sweep) the plot's x is that parameter (x_label its name, range its values,
 * M0 at the base row's value); otherwise the row (x = variant). table is borrowed while the
 * family lives. */
typedef struct cm_design_table cm_design_table;
CM_API cm_status cm_study_family_design(cm_context *ctx, const cm_design_table *table,
                                        size_t base, const cm_cad_read_options *opt,
                                        cm_study_family *family);
CM_API void cm_study_paths_free(char ***paths, size_t n);

/* ---- running a study ---- */

enum {
    CM_STUDY_WRITE_NONE = 0,
    CM_STUDY_WRITE_ALL = 1,    /* every variant's mesh, per method and mode */
    CM_STUDY_WRITE_FAILED = 2, /* the complete results with inverted cells (morph options
                                  with allow_inverted: the others refuse such results) */
    CM_STUDY_WRITE_LISTED = 3  /* the variants flagged in write_listed */
};

typedef struct cm_study_options {
    int modes;                     /* CM_STUDY_ABSOLUTE | CM_STUDY_RELATIVE (default both) */
    const cm_study_method *methods; /* NULL: cm_study_default_methods */
    size_t n_methods;
    cm_morph_options morph; /* everything but the method (default cm_morph_options_init:
                               adaptive steps, a morph that reaches no valid mesh a row with
                               CM_ERR_REJECTED and no mesh) */
    int write_meshes;       /* CM_STUDY_WRITE_* (default NONE) */
    const unsigned char *write_listed; /* #variants flags for CM_STUDY_WRITE_LISTED */
    const char *out_dir;    /* meshes go to <out_dir>/<method>_<mode>_<label>.vtu, with
                               per-cell scaled_jacobian and per-node displacement (from M0) */
    const char *model;      /* names for the CSV columns model and mesh and the plot title */
    const char *mesh;       /*   (NULL: "G0", "file") */
    int rank, ranks;        /* distributed over MPI ranks (ranks > 1; default 0, 1): this
                               process runs the absolute rows of variants i with
                               i mod ranks = rank, and the relative series of method m when
                               m mod ranks = rank (a relative series is one chain: it cannot
                               be split, so a relative study spreads over the ranks by
                               method), and writes their meshes; the result, on every rank,
                               has all rows in the serial order (cm_parallel_allgather).
                               Every rank calls cm_study_run with the same inputs; an
                               error on any rank is every rank's (its message names the
                               rank), as it would end a serial study. */
    /* Absolute variants morphed together (cm_morpher_apply_batch: one multi-column warp
     * apply for the batch; rows equal to one-at-a-time to the solver's tolerance, in the same
     * order; the warp solves a batch in 4 groups, each later group warm from the solutions
     * before it, cm_warp_options.warm_groups). 0 (default): all the variants, as many as half
     * the available memory holds, up to CM_STUDY_BATCH_MAX
     * (docs/DESIGN.md, "Studies in batches"); 1: one variant at a time;
     * K: K variants. Relative series run one variant at a time whatever it is. */
    int batch;
} cm_study_options;

CM_API void cm_study_options_init(cm_study_options *opt);

/* One variant x method x mode. Times in seconds. status: CM_OK, CM_WARNING (complete, the
 * message says what was odd: face nodes left their trimmed face) or the error that stopped
 * this row (the quality fields are then 0; CM_ERR_REJECTED: the morph reached no valid mesh,
 * the message names the worst cells). In absolute mode the classification of M0 and the
 * factorisation of each warp happen once: t_classify (sampling G0 and classifying M0) is in
 * each method's first row, t_volume_solve in the first row of each warp method; relative rows
 * have the re-base onto the previous variant in t_classify. t_sample: reading G (writing and
 * reading it, for the models) and checking it against G0, in every row of the variant, plus
 * sampling G for the distance in the first row of each morpher that measures against it.
 * t_evaluation includes the scaled Jacobian (t_quality stays 0: the morph engine measures
 * both together). */
typedef struct cm_study_row {
    int mode;
    size_t method;  /* index into the result's methods */
    size_t variant; /* 0-based; the CSV's step is variant + 1 */
    char label[64]; /* the family's label of the variant */
    double t;
    cm_status status;
    char message[512];
    double min_sj, mean_sj;
    size_t inverted, cells;
    double max_dist; /* largest distance of the boundary nodes to their G */
    size_t outside;  /* face nodes whose (u',v') left the trimmed face */
    double residual; /* the warp's miss at the constrained nodes */
    double t_sample, t_classify, t_surface, t_volume_solve, t_evaluation, t_quality, t_distance,
        t_write;
} cm_study_row;

typedef struct cm_study_result {
    char model[64], mesh[64];
    size_t nodes, cells, boundary_nodes;
    double diagonal;          /* bbox diagonal of G0 */
    double min_sj0, mean_sj0; /* quality of M0 (the curves start there) */
    size_t inverted0;
    int threads;
    size_t n_methods;
    cm_study_method *methods;
    size_t n_variants;
    char x_label[64];
    double x_max, x_tick;
    double x_min, x0;   /* the plot's x range starts at x_min, M0 sits at x0 */
    size_t n_values;    /* named values per variant (cm_study_family.n_values) */
    char (*value_names)[64];
    double *values;     /* n_variants x n_values */
    size_t n_rows, cap_rows;
    cm_study_row *rows; /* variant-major: per variant, the absolute rows then the relative */
    size_t n_failed;    /* rows with status < 0 */
    double t_total;
} cm_study_result;

/* Morphs mesh (of g0; both borrowed for the call) onto every variant of family. Errors that
 * end the study: M not a mesh of G0 and the other errors of cm_morpher_create, out of memory,
 * a mesh that cannot be written, CM_ERR_INTERRUPTED (no result; the meshes of the variants
 * finished before stay written). Returns CM_WARNING (message: the first failed row) when rows
 * failed; their errors also go to the log as warnings. */
CM_API cm_status cm_study_run(cm_context *ctx, const cm_cad_model *g0, const cm_mesh *mesh,
                       const cm_study_family *family, const cm_study_options *opt,
                       cm_study_result **result);
CM_API void cm_study_result_destroy(cm_study_result **result);

/* ---- outputs ---- */

enum {
    CM_STUDY_CSV_FULL = 0, /* study.csv: every row, with columns variant, status, message */
    CM_STUDY_CSV_SWEEP = 1 /* sweep.csv of `cadmorph sweep`: its columns only, complete rows only */
};

/* Header, then one row per cm_study_row (through a temporary file, renamed at the end).
 * Columns: model,mesh,mode,method,step,t,percent,min_scaled_jacobian,mean_scaled_jacobian,
 * inverted,cells,max_distance,max_distance_rel,outside,nodes,boundary_nodes,threads,t_sample,
 * t_classify,t_surface,t_volume_solve,t_evaluation,t_quality,t_distance,t_write and, FULL,
 * variant (label),status (cm_status_name),message (RFC 4180 quoting), then FULL, one column
 * per named value of the family (a design table's parameters, by their names). */
CM_API cm_status cm_study_write_csv(cm_context *ctx, const cm_study_result *r, const char *path,
                             int format);

/* The plot: min scaled Jacobian against t * x_max, one polyline per method x mode (solid
 * absolute, dashed relative) from M0 through its complete rows, axes, ticks, legend, title;
 * failed variants are marked on the x axis. */
CM_API cm_status cm_study_write_svg(cm_context *ctx, const cm_study_result *r, const char *path);

/* ---- the general line plot (the benchmarks' figures) ---- */

typedef struct cm_plot_series {
    const char *name; /* legend */
    size_t n;
    const double *x, *y; /* n points each; non-finite ones (and <= 0 on a log axis) skipped */
    int dashed;          /* dashed line */
    int markers;         /* a dot per point */
    int colour;          /* slot in the colour table; -1: the series' index */
} cm_plot_series;

typedef struct cm_plot {
    const char *title, *x_label, *y_label;
    const char *note; /* a line under the plot, or NULL */
    int log_x, log_y;
    double y_min, y_max; /* linear y range if y_min < y_max (values outside are drawn on the
                            frame as triangles), else fitted to the data */
    size_t n_series;
    const cm_plot_series *series;
} cm_plot;

/* Writes the plot as SVG (atomically, like the meshes). */
CM_API cm_status cm_plot_write_svg(cm_context *ctx, const cm_plot *p, const char *path);

/* ---- design tables, design velocities and gradients (docs/DESIGN.md, "Gradients") ----
 * A design table is the CSV a CAD program exports for a family of designs: a header
 * `step,<p1>,<p2>,...` and one row per STEP file with its parameter values. For a base row
 * (G0, the geometry the morpher's mesh lies on) each parameter is differenced over the rows
 * that change it alone (cm_design_plan); cm_design_velocity gives dX/dp of every node for
 * every parameter, cm_design_gradient dJ/dp = sum over nodes of S . dX/dp for a sensitivity
 * S = dJ/dX. Velocities are in mesh units per parameter unit. */
/* Reads a design table: the header `step,<p1>,...` (the first column's name "step" in any
 * case; an UTF-8 byte order mark, blank lines, CRLF line ends, blanks around fields and
 * RFC 4180 quoting - "a, b" and "" for a quote - as spreadsheet and CAD exports write them),
 * then rows `<STEP path>,<value>,...`, a relative path relative to the table's directory.
 * Errors name path:line and what was expected: CM_ERR_FORMAT for another header, a parameter
 * named twice or without a name, a row with another column count, a value that is not a
 * finite number, no rows; CM_ERR_IO for a STEP file that cannot be read. */
CM_API cm_status cm_design_table_read(cm_context *ctx, const char *path, cm_design_table **table);
CM_API void cm_design_table_destroy(cm_design_table **table);
CM_API size_t cm_design_table_n_parameters(const cm_design_table *table);
CM_API size_t cm_design_table_n_rows(const cm_design_table *table);
/* Name of parameter j (header order), NULL out of range. */
CM_API const char *cm_design_table_parameter(const cm_design_table *table, size_t j);
/* STEP path of row i (resolved against the table's directory), NULL out of range. */
CM_API const char *cm_design_table_path(const cm_design_table *table, size_t i);
/* Parameter values of row i (#parameters), NULL out of range. */
CM_API const double *cm_design_table_values(const cm_design_table *table, size_t i);
/* The line of row i in the file (1-based), 0 out of range. */
CM_API long cm_design_table_line(const cm_design_table *table, size_t i);
/* The row whose STEP file is path (the same file: device and inode), in *row; CM_ERR_MISMATCH
 * naming the table when no row is. */
CM_API cm_status cm_design_table_find(cm_context *ctx, const cm_design_table *table,
                                      const char *path, size_t *row);
/* 1 when the file's first non-blank line is a design table's header (first field "step"),
 * 0 otherwise (a plain list of STEP paths, an unreadable file). */
CM_API int cm_design_table_detect(const char *path);

typedef enum cm_design_scheme {
    CM_DESIGN_NONE = 0,     /* no row changes the parameter alone: skipped */
    CM_DESIGN_CENTRAL = 1,  /* rows on both sides: (X(plus) - X(minus)) / (dp_plus - dp_minus) */
    CM_DESIGN_FORWARD = 2,  /* only above: (X(plus) - X(base)) / dp_plus */
    CM_DESIGN_BACKWARD = 3  /* only below: (X(plus) - X(base)) / dp_plus, dp_plus < 0 */
} cm_design_scheme;

/* "none", "central", "forward", "backward". */
CM_API const char *cm_design_scheme_name(cm_design_scheme scheme);

/* How one parameter is differenced: rows of the table and their value minus the base's. */
typedef struct cm_design_difference {
    cm_design_scheme scheme;
    size_t plus, minus; /* rows: plus for every scheme but NONE (for BACKWARD the row below),
                           minus for CENTRAL only */
    double dp_plus, dp_minus; /* value - base value (dp_minus 0 unless CENTRAL) */
} cm_design_difference;

/* For each parameter the rows that change it alone relative to row base (values equal to
 * 1e-12 relative), the nearest on each side: both sides central differences, one side
 * one-sided. out: #parameters. Rows that change several parameters (or none) are ignored,
 * each with a CM_LOG_INFO note naming its line. A parameter no row changes alone is skipped
 * (scheme NONE): the return is CM_WARNING naming those parameters (a table may list
 * constants). CM_ERR_FORMAT when no parameter can be differenced. */
CM_API cm_status cm_design_plan(cm_context *ctx, const cm_design_table *table, size_t base,
                                cm_design_difference *out);

/* The design velocities of every parameter. */
typedef struct cm_design_velocities {
    size_t n_parameters;       /* of the table (skipped ones: scheme NONE, velocity 0) */
    size_t n_nodes;            /* of the morpher's mesh */
    size_t base;               /* the base row */
    int interior;              /* 1: v holds every node; 0: boundary nodes only (interior 0) */
    cm_design_difference *diff; /* n_parameters */
    double *v;                 /* n_parameters x n_nodes x 3: dX/dp_j, mesh unit per
                                  parameter unit */
    size_t surface_morphs;     /* rows morphed (each STEP read once) */
    double t_read, t_surface, t_warp; /* seconds: reading and matching the rows, their
                                         surface morphs, the differences and forward products */
} cm_design_velocities;

/* Design velocities of the mesh of mp for every parameter of table at row base: the rows of
 * cm_design_plan read once each (ro: the unit of the mesh coordinates, as the morph's; may
 * be NULL), numbered like g0 (cm_cad_match), their boundary positions made by
 * cm_morpher_boundary and differenced (cm_morpher_velocity); with interior the warp's
 * forward product carries them into the interior (cm_morpher_warp_forward_many with the
 * shared factorisation, up to 16 parameters per call: the RBF warps solve for them
 * together). g0: the geometry of row base, the one mp was created on (borrowed). The
 * velocity is that of the one-increment absolute morph with mp's method (morph.h).
 * Errors: cm_design_plan's, a row that cannot be read or does not correspond to g0 (its
 * path in the message), CM_ERR_UNSUPPORTED for a warp that is not linear (interior).
 * Returns CM_WARNING when parameters were skipped or face nodes left their trimmed face.
 * Progress: stage "design velocities", done/total = parameters. */
CM_API cm_status cm_design_velocity(cm_context *ctx, cm_morpher *mp, const cm_cad_model *g0,
                                    const cm_design_table *table, size_t base,
                                    const cm_cad_read_options *ro, int interior,
                                    cm_design_velocities **out);
CM_API void cm_design_velocities_destroy(cm_design_velocities **v);

/* dJdp (#parameters) = sum over nodes of sens . dX/dp_j. sens: #nodes x 3, dJ/dX.
 * boundary_only 0: sens at every node; computed as <J^T sens, V_b> with one reverse product
 * (cm_morpher_warp_transpose) for all parameters (every linear warp has one: the velocities
 * need a linear warp anyway); *reverse (may be NULL) is then 1, and 0 for boundary_only or
 * an error. boundary_only 1: sens is read at the
 * boundary nodes only (a surface sensitivity): sum_b sens_b . V_b, no warp product.
 * Skipped parameters get 0. */
CM_API cm_status cm_design_gradient(cm_context *ctx, cm_morpher *mp, const cm_design_velocities *v,
                                    const double *sens, int boundary_only, double *dJdp,
                                    int *reverse);

/* A sensitivity field dJ/dX of n_nodes nodes into sens (#nodes x 3, zeroed first): a CSV
 * `node,gx,gy,gz` (a path ending in .csv: 0-based node indices in the mesh's order; blank
 * lines and CRLF accepted; unlisted nodes 0) or a mesh file of the same nodes with a
 * 3-component point field "dJdX" (or, without one, its only 3-component point field).
 * listed (may be NULL): #nodes flags of the nodes the CSV lists (every node for a mesh).
 * Errors name path:line: CM_ERR_FORMAT for a bad header, column count or value;
 * CM_ERR_MISMATCH for a node out of range or twice, a mesh of another node count or without
 * such a field. */
CM_API cm_status cm_design_read_sensitivity(cm_context *ctx, const char *path, size_t n_nodes,
                                            double *sens, unsigned char *listed);

/* The outputs of `cadmorph sensitivity`, each through a temporary file (never partial).
 * m0: the morpher's mesh (cm_morpher_mesh); parameters with scheme NONE are left out.
 * velocity CSV: `node,x,y,z` (m0's coordinates) then `dx_d<p>,dy_d<p>,dz_d<p>` per parameter,
 * one row per node (0-based). velocity mesh: m0 with a 3-component point field `dX_d<p>` per
 * parameter, in any format cm_mesh_write takes (.vtu for ParaView). gradient CSV:
 * `parameter,dJdp,difference,dp_plus,dp_minus,step_plus,step_minus,product`: dJdp from
 * cm_design_gradient, difference central|forward|backward, dp_* the rows' values minus the
 * base's, step_* their STEP paths (step_minus the base row for one-sided differences),
 * product the way it was computed ("reverse", "forward" or "boundary"). */
CM_API cm_status cm_design_write_velocity_csv(cm_context *ctx, const cm_design_table *table,
                                              const cm_design_velocities *v, const cm_mesh *m0,
                                              const char *path);
CM_API cm_status cm_design_write_velocity_mesh(cm_context *ctx, const cm_design_table *table,
                                               const cm_design_velocities *v,
                                               const cm_mesh *m0, const char *path);
CM_API cm_status cm_design_write_gradient_csv(cm_context *ctx, const cm_design_table *table,
                                              const cm_design_velocities *v, const double *dJdp,
                                              const char *product, const char *path);

/* ---- sweeps of the built-in models (models.h): `cadmorph sweep` and `demo` ---- */

typedef struct cm_sweep_options {
    const char *model;   /* bore | pipe | bracket */
    const char *mesh;    /* "tet", "hex" or the path of a mesh of G(0) */
    double size;         /* tet: target edge (<= 0: 0.2); hex: cells of about this size
                            (<= 0: 0.1; resolution scales as 0.1 / size) */
    int modes;           /* CM_STUDY_ABSOLUTE | CM_STUDY_RELATIVE */
    int steps;           /* N >= 1: G(k / N), k = 1 .. N */
    const cm_study_method *methods; /* NULL: cm_study_default_methods */
    size_t n_methods;
    const char *out_dir; /* existing directory for G_<t>.step (removed unless write_step) and
                            the meshes at 50 and 100 % (<method>_<mode>_<pct>.vtu) */
    int write_step;      /* keep DIR/G_<t>.step */
    int write_meshes;    /* write the meshes at 50 % and 100 % */
    int adaptive;        /* 0: each morph is the plain one-step morph of the papers, inverted
                            cells kept (steps 1, allow_inverted: what the sweep measures);
                            1: adaptive steps (CM_MORPH_STEPS_AUTO, floor 0), a morph that
                            reaches no valid mesh a failed row (CM_ERR_REJECTED) */
    int optimize;        /* each morph with interior optimisation (cm_morph_options.optimize) */
} cm_sweep_options;

CM_API void cm_sweep_options_init(cm_sweep_options *opt);

/* Writes G(0) .. G(1) as STEP and reads them back (what a user's file goes through), meshes
 * G(0) and runs the study. Errors as cm_study_run, and the meshers'. */
CM_API cm_status cm_sweep_run(cm_context *ctx, const cm_sweep_options *opt, cm_study_result **result);

#ifdef __cplusplus
}
#endif
#endif
