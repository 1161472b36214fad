/* One option parser for every subcommand: a table of options (name, alias, kind, where the
 * value goes, help text) instead of a strcmp chain per command. The messages are those the
 * commands printed before (tests check them): "option X needs a value", "unknown option 'X'",
 * and each option's own message for a bad value. */
#ifndef CADMORPH_CLI_OPTIONS_H
#define CADMORPH_CLI_OPTIONS_H

#include "cadmorph/core.h"

#include <stdio.h>

typedef enum cli_kind {
    CLI_FLAG,    /* int *dest = 1 */
    CLI_STRING,  /* const char **dest = the value */
    CLI_INT,     /* int *dest, min..max */
    CLI_DOUBLE,  /* double *dest, in the range of lo, hi, open */
    CLI_ENUM,    /* int *dest = values[k] for the value names[k] */
    CLI_THREADS, /* int *dest, 1..4096 */
    CLI_CUSTOM,  /* parse(value, dest) decides */
    CLI_HELP,    /* prints the command's help, exit 0 */
    CLI_NOTE     /* a line of the help only (another form of an option), never parsed */
} cli_kind;

typedef struct cli_option cli_option;
typedef struct cli_parser cli_parser;

/* What a CLI_CUSTOM option does with its value (NULL for an option without value, see
 * takes_value): 0 done, or the exit code after a usage message (cli_usage with p's cmd and
 * usage). */
typedef int (*cli_parse_fn)(const cli_parser *p, const cli_option *o, const char *value,
                            void *dest);

struct cli_option {
    const char *name;  /* "--size" */
    const char *alias; /* "-o", or NULL */
    cli_kind kind;
    void *dest;
    const char *label; /* left column of the help ("--size H"); NULL: not in the help */
    /* right column: printf format of one %s (help_arg); a newline in it starts a continuation
     * line under the column */
    const char *help;
    const char *(*help_arg)(void); /* the %s of help (e.g. the list of warp methods), or NULL */
    /* CLI_INT: min, max; CLI_DOUBLE: lo, hi (NAN: no bound), open: bit 1 lo open, bit 2 hi
     * open */
    double lo, hi;
    int open;
    /* bad value: printf format of two %s, the option name and the value (%.0s skips one) */
    const char *bad;
    const char *const *names; /* CLI_ENUM: NULL-terminated names and their values */
    const int *values;
    cli_parse_fn parse; /* CLI_CUSTOM */
    int takes_value;    /* CLI_CUSTOM: 1 if it reads a value */
};

/* A command's parser: its options (ended by an entry with name NULL), its positional
 * arguments (up to max_pos into pos), and its messages. */
struct cli_parser {
    const char *cmd;   /* "mesh" */
    const char *usage; /* the usage line */
    const cli_option *options;
    int (*help)(void);   /* prints the help; its return value is the exit code */
    const char *unknown; /* "unknown option '%s'" or "unknown argument '%s'" */
    const char **pos;    /* positional arguments; max_pos 0: none accepted */
    int max_pos;
    const char *extra; /* format of one %s for a positional beyond max_pos */
    int n_pos;         /* out: how many were given */
};

/* Values shared by several commands: --method M of the warp method table (dest: a
 * cm_warp_method), and --kernel triharmonic|biharmonic (a CLI_ENUM onto the same field). */
int cli_parse_warp_method(const cli_parser *p, const cli_option *o, const char *value, void *dest);
extern const char *const cli_kernel_names[];
/* --solver of the RBF warps: auto, dense, iterative (cm_rbf_solver). */
extern const char *const cli_solver_names[];
extern const int cli_solver_values[];
/* The fields of --solver and --rbf-tol that warp and morph share (each adds its .dest), so
 * that the help's figures (the AUTO crossover) are written once. */
#define CLI_SOLVER_FIELDS                                                                      \
    .name = "--solver", .kind = CLI_ENUM, .names = cli_solver_names,                           \
    .values = cli_solver_values,                                                               \
    .bad = "%.0sunknown solver '%s' (auto, dense, iterative, petsc)", .label = "--solver S"
#define CLI_SOLVER_OPTION                                                                      \
    CLI_SOLVER_FIELDS,                                                                         \
    .help = "RBF warps: auto (default: dense below ~3,500 boundary nodes,\n"                   \
            "iterative above), dense, iterative (FGMRES + Schwarz) or petsc\n"                 \
            "(the same distributed over MPI ranks: mpirun -n K; builds\n"                      \
            "with -DCADMORPH_WITH_PETSC=ON)"
#define CLI_RBF_TOL_OPTION                                                                     \
    .name = "--rbf-tol", .kind = CLI_DOUBLE, .lo = 0, .hi = 0.5,                               \
    .bad = "%s: expected a tolerance in 0..0.5, got '%s'", .label = "--rbf-tol T",             \
    .help = "RBF warps, iterative solvers: stop at a miss at the centres of T x the\n"         \
            "largest displacement. The boundary is set exactly anyway; the interior\n"         \
            "moves by about T x the motion. Default: from the mesh, 1e-3 x the\n"              \
            "shortest wall-to-interior spacing of a cell over the boundary's diagonal,\n"      \
            "within [1e-10, 1e-6] (-v names it)"
/* -1 if the --solver value can run in this build, else the usage exit code after saying why
 * (petsc without PETSc). */
int cli_check_solver(const char *cmd, const char *usage, int solver);
/* 1 on the rank that writes outputs and prints reports: rank 0 under mpirun with --solver
 * petsc (the other ranks compute the same result), and always without MPI. */
int cli_output_rank(void);
/* Under mpirun (OMPI_COMM_WORLD_SIZE or PMI_SIZE > 1): initialises MPI (PETSc builds) and
 * returns this process's rank and the rank count; 1 rank otherwise. 0, or the exit code after
 * a message (a build without PETSc). */
int cli_mpi_ranks(cm_context *ctx, const char *cmd, int *rank, int *ranks);
extern const int cli_kernel_methods[];
/* --mode of study and sweep: absolute, relative, both (CM_STUDY_*). */
extern const char *const cli_study_mode_names[];
extern const int cli_study_mode_values[];

/* A count (1 .. 1e8) into a size_t (dest), e.g. --samples. */
int cli_parse_size(const cli_parser *p, const cli_option *o, const char *value, void *dest);

/* The MLS options of warp, morph and deform (m: a cm_mls_options lvalue, set to its defaults
 * before parsing): --samples K, --cubature N, --cover S, --stretch GS, --bend GB, --blend B,
 * --graded G. */
#define CLI_MLS_OPTIONS(m)                                                                        \
    {.name = "--samples", .kind = CLI_CUSTOM, .takes_value = 1, .parse = cli_parse_size,          \
     .dest = &(m).samples, .label = "--samples K",                                                \
     .help = "mls: samples k (default 2%% of the nodes, at least 500)"},                          \
    {.name = "--cubature", .kind = CLI_CUSTOM, .takes_value = 1, .parse = cli_parse_size,         \
     .dest = &(m).cubature, .label = "--cubature N", .help = "mls: cubature points (default 4 k)"}, \
    {.name = "--cover", .kind = CLI_INT, .dest = &(m).cover, .lo = 1, .hi = 64,                   \
     .bad = "%s: expected 1..64 samples covering every point, got '%s'", .label = "--cover S",    \
     .help = "mls: samples covering every point (default 5)"},                                    \
    {.name = "--stretch", .kind = CLI_DOUBLE, .dest = &(m).stretch, .lo = 0, .hi = NAN,           \
     .bad = "%s: '%s' is not a number >= 0", .label = "--stretch GS",                            \
     .help = "mls: stretching weight gamma_s (default 1)"},                                       \
    {.name = "--bend", .kind = CLI_DOUBLE, .dest = &(m).bend, .lo = 0, .hi = NAN,                 \
     .bad = "%s: '%s' is not a number >= 0", .label = "--bend GB",                               \
     .help = "mls: bending weight gamma_b (default 1)"},                                       \
    {.name = "--blend", .kind = CLI_DOUBLE, .dest = &(m).blend, .lo = 0, .hi = NAN,               \
     .bad = "%s: '%s' is not a number >= 0", .label = "--blend B",                               \
     .help = "mls: the field's miss at the boundary decays into the interior over\n"             \
             "B x the mean support radius (default 1.5; 0: the first cell layer takes it)"},      \
    {.name = "--graded", .kind = CLI_DOUBLE, .dest = &(m).graded, .lo = 0, .hi = 1,               \
     .bad = "%s: '%s' is not a number in 0..1", .label = "--graded G",                           \
     .help = "mls: samples follow the mesh's resolution: 0 uniform by\n"                        \
             "volume and area (default), 1 each cell alike (a CFD mesh\n"                      \
             "refined around a body: the 1M-cell car case needs it)"}

/* Parses argv[1..argc). Returns -1 when the command should run, or the exit code: 0 after
 * --help, CLI_EXIT_USAGE after a message on stderr. */
int cli_parse(cli_parser *p, int argc, char **argv);

/* The options block of a help text: "  <label><help>" per labelled option, the label
 * column width wide, continuation lines indented to the help column. */
void cli_print_options(FILE *out, const cli_option *options, int width);

#endif
