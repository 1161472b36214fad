/* What every cadmorph subcommand shares: exit codes, how errors and progress reach the user,
 * and the checks on output paths. Only cli/ prints or exits. */
#ifndef CADMORPH_CLI_H
#define CADMORPH_CLI_H

#include "cadmorph/core.h"
#include "cadmorph/mesh.h"
#include "blas_reexec.h" /* cli_blas_setup, cli_blas_print_version */

#include <stdio.h>

enum {
    CLI_EXIT_OK = 0,
    CLI_EXIT_USAGE = 1,
    CLI_EXIT_BAD_INPUT = 2,
    CLI_EXIT_REJECTED = 3,
    CLI_EXIT_INTERNAL = 4,
    /* a library call stopped on request (CM_ERR_INTERRUPTED): the shell's code for a run
     * ended by SIGINT, which is what asks for it */
    CLI_EXIT_INTERRUPTED = 130
};

/* A context whose log goes to stderr (debug lines only when verbose), whose progress is drawn
 * on stderr when stderr is a terminal (during a study, stage "study": the variant count and
 * an estimate of the time left), with `threads` threads (0: all). NULL, after a line on
 * stderr naming cmd, when out of memory. */
cm_context *cli_context_create(const char *cmd, int verbose, int threads);

/* Prints "cadmorph <cmd>: <context message>" on one line to stderr, returns the exit code
 * for the status (2 for bad input, 4 for internal errors, 130 for an interrupted call). */
int cli_fail(cm_context *ctx, const char *cmd, cm_status s);

/* Prints "cadmorph <cmd>: <message>" and the usage hint to stderr; returns CLI_EXIT_USAGE. */
int cli_usage(const char *cmd, const char *usage, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* mkdir -p: the output directory and any missing parents. 0, or CLI_EXIT_BAD_INPUT after a
 * line on stderr naming cmd. */
int cli_make_dir(const char *cmd, const char *dir);

/* The output directory DIR of a command that writes several files (study, sweep; see
 * docs/DESIGN.md, "Command line contract"): the fixed output names (NULL-terminated list)
 * checked against the n inputs by device and inode, then a temporary directory to write into
 * (beside a new DIR, inside an existing one), od->tmp, made visible by cm_outdir_merge(ctx,
 * od, DIR, inputs, n) or removed by cm_outdir_abort. 0, or the exit code after one line on
 * stderr (1 when an output is an input). */
int cli_outdir_begin(cm_context *ctx, const char *cmd, const char *dir, const char *const *names,
                     const char *const *inputs, size_t n, cm_outdir *od);
/* Non-zero if the two paths name the same file (an existing output that is an input). */
int cli_same_file(const char *a, const char *b);
/* The checks of a mesh output before any work: a known mesh format, and none of the n inputs
 * (NULL entries skipped). 0, or CLI_EXIT_USAGE after a usage message. */
int cli_check_mesh_output(const char *cmd, const char *usage, const char *out,
                          const char *const *inputs, size_t n);

/* Argument helpers: the value after an option, or NULL (and a usage message) if missing. */
const char *cli_value(int argc, char **argv, int *i, const char *cmd, const char *usage);
/* The value of --threads (1 .. 4 x the online cores) into *threads: 0, or CLI_EXIT_USAGE after a usage message. */
int cli_threads_value(int argc, char **argv, int *i, const char *cmd, const char *usage,
                      int *threads);
/* The check behind it on the value v alone (also used by the option table). */
int cli_threads_parse(const char *cmd, const char *usage, const char *v, int *threads);

/* Quality report shared by quality, warp and morph. The line every mesh-producing command
 * ends with (DESIGN.md): "min_scaled_jacobian=<v> mean_scaled_jacobian=<v> inverted=<k>
 * cells=<n>" (%.6g; cells = volume cells). */
void cli_print_quality_line(FILE *out, const cm_quality_stats *all);
/* checkMesh's layout of the OpenFOAM metrics, then one line
 * max_aspect_ratio=.. max_non_orthogonality=.. avg_non_orthogonality=.. max_skewness=..
 * wrong_pyramids=.. negative_volumes=.. failed_checks=.. cells=.. (quality_foam_print.c) */
/* mesh: names the patches (its 2-D groups, tag = patch index + 1); may be NULL */
void cli_print_foam_quality(const cm_foam_quality *q, const cm_mesh *mesh, FILE *out);
/* One row per present (linear) cell type - type, cells, min, mean, 1st percentile, inverted -
 * then the line above. sj: #cells as from cm_mesh_quality; all (may be NULL) receives the
 * overall stats. */
cm_status cli_print_quality(cm_context *ctx, const cm_mesh *mesh, const double *sj, FILE *out,
                            cm_quality_stats *all);

/* When volume cells are inverted (scaled Jacobian <= 0, NaN, collapsed): one warning line on
 * stderr, "cadmorph <cmd>: warning: <k> inverted cells ...; the worst is cell <i> (0-based,
 * <type>, scaled Jacobian <v>) at (<x>, <y>, <z>)" - the summary line alone is easy to miss.
 * Returns k. */
size_t cli_warn_inverted(const char *cmd, const cm_mesh *mesh, const double *sj);


/* Subcommands: argv[0] is the subcommand name. */
int cli_cmd_quality(int argc, char **argv);
int cli_cmd_warp(int argc, char **argv);
int cli_cmd_deform(int argc, char **argv);
int cli_cmd_info(int argc, char **argv);
int cli_cmd_mesh(int argc, char **argv);
int cli_cmd_morph(int argc, char **argv);
int cli_cmd_sweep(int argc, char **argv);
int cli_cmd_study(int argc, char **argv);
int cli_cmd_demo(int argc, char **argv);
int cli_cmd_optimize(int argc, char **argv);
int cli_cmd_ffd(int argc, char **argv);
int cli_cmd_detect(int argc, char **argv);
int cli_cmd_model(int argc, char **argv);
int cli_cmd_sensitivity(int argc, char **argv);

#endif
