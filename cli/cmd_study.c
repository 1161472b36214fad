/* `cadmorph study`: a mesh M0 of G0 morphed onto every STEP file of a list (a design table
 * exported from a CAD program), by one or more methods, absolutely and/or relatively;
 * study.csv, study.svg and the meshes in the output directory, a summary on stdout. */
#include "cli.h"
#include "options.h"
#include "patch_motion.h"

#include "cadmorph/study.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph study --from G0.step --mesh M0 --variants LIST -o DIR "
    "[--mode absolute|relative|both] [--methods LIST] [--write-meshes none|all|failed] "
    "[--steps auto|K] [--allow-inverted] [--optimize] [--cad-unit U] "
    "[--off-cad refuse|fixed [--slide P,..] "
    "[--fixed-patches P,..] [--no-slide]] [--batch auto|K] [--solver S] [--rbf-tol T] "
    "[--threads N] "
    "[--verbose]";

enum { MAX_METHODS = 16 };

typedef struct study_args {
    const char *from, *mesh, *variants, *out, *unit, *methods;
    int modes, write_meshes, threads, verbose, steps, optimize, off_cad, allow_inverted;
    int batch;  /* cm_study_options.batch: 0 auto */
    int solver; /* the RBF warps' solver of every method (cm_rbf_solver) */
    double rbf_tol; /* and their iterative solvers' tolerance (0: the default) */
    cli_patch_motion patches; /* the motion of the nodes off G0 */
    int rank, ranks; /* under mpirun (cli_mpi_ranks) */
    cm_study_method list[MAX_METHODS];
    size_t n_methods;
} study_args;

static study_args args;


static int print_help(void);

/* --steps and --batch: K (1..1000) or auto (0: CM_MORPH_STEPS_AUTO, the automatic batch) */
static int parse_count(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    char *end;
    const long n = strtol(v, &end, 10);
    if (!strcmp(v, "auto"))
        *(int *)dest = 0;
    else if (end == v || *end || n < 1 || n > 1000)
        return cli_usage(p->cmd, p->usage, "%s: expected 1..1000 or auto, got '%s'", o->name, v);
    else
        *(int *)dest = (int)n;
    return 0;
}

static const char *method_help(void)
{
    static char methods[512];
    cm_study_method_help(methods, sizeof methods);
    return methods;
}

static const char *const write_names[] = {"none", "all", "failed", NULL};
static const int write_values[] = {CM_STUDY_WRITE_NONE, CM_STUDY_WRITE_ALL,
                                   CM_STUDY_WRITE_FAILED};

static const char *const off_cad_names[] = {"refuse", "fixed", NULL};
static const int off_cad_values[] = {CM_OFF_CAD_REFUSE, CM_OFF_CAD_FIXED};

static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "--from", .kind = CLI_STRING, .dest = &args.from, .label = "--from G0.step",
     .help = "the geometry M0 is a mesh of"},
    {.name = "--mesh", .kind = CLI_STRING, .dest = &args.mesh, .label = "--mesh M0",
     .help = "volume mesh of G0: %s", .help_arg = cm_mesh_format_list},
    {.name = "--variants", .kind = CLI_STRING, .dest = &args.variants, .label = "--variants LIST",
     .help = "a text file of STEP paths, one per line ('#' comments; relative\n"
             "paths are relative to the list file), a quoted glob pattern\n"
             "such as 'designs/*.step' (sorted), or a design table: a CSV with\n"
             "the header step,<p1>,<p2>,... (as CAD programs export; G0 must be\n"
             "one of its rows, the others are the variants): study.csv gains\n"
             "a column per parameter, study.svg plots against the parameter\n"
             "when only one varies"},
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &args.out,
     .label = "-o, --output DIR", .help = "output directory (created if missing)"},
    {.name = "--mode", .kind = CLI_ENUM, .dest = &args.modes, .names = cli_study_mode_names,
     .values = cli_study_mode_values, .bad = "%.0sunknown mode '%s'", .label = "--mode M",
     .help = "absolute, relative or both (default absolute)"},
    {.name = "--methods", .kind = CLI_STRING, .dest = &args.methods, .label = "--methods LIST",
     .help = "comma-separated (default rbf-s): %s", .help_arg = method_help},
    {.name = "--write-meshes", .kind = CLI_ENUM, .dest = &args.write_meshes,
     .names = write_names, .values = write_values, .bad = "%s: none, all or failed, got '%s'",
     .label = "--write-meshes W",
     .help = "none, all (default) or failed (results with inverted cells:\n"
             "with --allow-inverted)"},
    {.name = "--steps", .kind = CLI_CUSTOM, .takes_value = 1, .parse = parse_count,
     .dest = &args.steps, .label = "--steps auto|K",
     .help = "each morph's steps, as in morph: adaptive (auto, the default)\n"
             "or K equal increments (1: the plain one-step morph); a variant\n"
             "whose morph reaches no valid mesh is a row with its error (status\n"
             "\"result rejected\"), its mesh not written"},
    {.name = "--allow-inverted", .kind = CLI_FLAG, .dest = &args.allow_inverted,
     .label = "--allow-inverted",
     .help = "keep results with inverted cells (rows with their count, meshes\n"
             "written), as morph --allow-inverted"},
    {.name = "--optimize", .kind = CLI_FLAG, .dest = &args.optimize, .label = "--optimize",
     .help = "interior optimisation after each morph step"},
    {.name = "--cad-unit", .kind = CLI_STRING, .dest = &args.unit, .label = "--cad-unit U",
     .help = "unit of the mesh coordinates (mm default; cm m in ft um ...)"},
    {.name = "--off-cad", .kind = CLI_ENUM, .dest = &args.off_cad, .names = off_cad_names,
     .values = off_cad_values, .bad = "%.0sexpected refuse or fixed, got '%s'",
     .label = "--off-cad P",
     .help = "boundary nodes not on G0: refuse (default) or fixed (kept, or\n"
             "sliding on their patch: see below), as in morph --off-cad"},
    CLI_PATCH_MOTION_OPTIONS(args.patches),
    {.name = "--batch", .kind = CLI_CUSTOM, .takes_value = 1, .parse = parse_count,
     .dest = &args.batch, .label = "--batch auto|K",
     .help = "absolute variants morphed together: their warps share one\n"
             "multi-column solve and evaluation (the same rows as one at a\n"
             "time, to the solver's tolerance); auto (default): all the\n"
             "variants, at most what half the free memory holds and 20,\n"
             "solved in 4 groups (each later group starts from the\n"
             "solutions before it) and evaluated in one pass; 1: one at a\n"
             "time"},
    {CLI_SOLVER_FIELDS, .dest = &args.solver,
     .help = "RBF warps: auto (default: a cost model that counts the variants,\n"
             "as they share one fit: dense to more boundary nodes than the\n"
             "~3,500 of one morph, iterative above), dense or iterative\n"
             "(FGMRES + Schwarz); petsc: use mpirun -n K instead"},
    {CLI_RBF_TOL_OPTION, .dest = &args.rbf_tol},
    {.name = "--threads", .kind = CLI_THREADS, .dest = &args.threads, .label = "--threads N",
     .help = "threads (default: all)"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &args.verbose,
     .label = "--verbose", .help = "debug messages on stderr"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf(
        "Morphs the mesh M0 of G0 onto every variant G of the list (same topology as G0, other\n"
        "dimensions) and compares methods. absolute: every variant from M0 (the classification\n"
        "of M0 and the warp factorisation are made once and shared by all variants); relative:\n"
        "variant i from the result of variant i-1, in list order. A variant that cannot be read\n"
        "or whose topology differs from G0 is a row with its error; the study goes on.\n\n"
        "Writes in DIR: study.csv (one row per variant x method x mode: min/mean scaled\n"
        "Jacobian, inverted cells, largest distance of the boundary to its G, stage times,\n"
        "status and message), study.svg (min scaled Jacobian per variant; solid absolute,\n"
        "dashed relative) and <method>_<mode>_<variant>.vtu (with 'scaled_jacobian' and\n"
        "'displacement'; <variant>: the STEP file's name without extension).\n\n"
        "Absolute variants run in batches (--batch): the warps of a batch share one solve\n"
        "and one evaluation with a column per variant and direction, so a study costs a\n"
        "fraction of its morphs; a variant whose one-step morph is not valid is morphed\n"
        "again alone (its adaptive steps), so the rows are those of one at a time.\n\n"
        "mpirun -n K cadmorph study ... (builds with -DCADMORPH_WITH_PETSC=ON): the absolute\n"
        "morph of variant i runs on rank i mod K (each rank in its own batches), the relative\n"
        "series of method m on rank m mod K (i and m counted from 0 in list order; a series is\n"
        "one chain: relative studies spread by method); each rank writes its rows' meshes into\n"
        "DIR, rank 0 study.csv and study.svg; an error on any rank ends the study. --threads is\n"
        "per rank (give K x N no more than the cores).\n\n"
        "options:\n");
    cli_print_options(stdout, options, 22);
    printf("\n" CLI_PATCH_MOTION_OFF_CAD
           "Every variant shares the factorisations of the two warp passes.\n");
    printf("\nProgress (on a terminal): variants done of all, the last batch's time per variant\n"
           "and an estimate of the time left.\n"
           "exit codes: 0 every row done, 1 usage, 2 bad input (G0, M0 or the list: one line\n"
           "naming the file), 3 some rows failed (a variant that cannot be read or does not\n"
           "match G0, a morph that reached no valid mesh): the study ran to the end, each\n"
           "failure a warning on stderr and a row with its status and message in study.csv,\n"
           "the other rows' meshes written; 4 internal error.\n");
    return CLI_EXIT_OK;
}

/* Returns -1 to go on, else the exit code. */
static int parse_args(int argc, char **argv, study_args *a)
{
    static const char *cmd = "study";
    memset(&args, 0, sizeof args);
    args.modes = CM_STUDY_ABSOLUTE;
    args.write_meshes = CM_STUDY_WRITE_ALL;
    args.steps = CM_MORPH_STEPS_AUTO;
    args.methods = "rbf-s";
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    /* the names stay in the static args, so a's copy may point at them */
    *a = args;
    if (parsed >= 0) return parsed;
    if ((a->patches.n[0] || a->patches.n[1] || a->patches.all_fixed) &&
        a->off_cad != CM_OFF_CAD_FIXED)
        return cli_usage(cmd, usage_line,
                         "--slide, --fixed-patches and --no-slide go with --off-cad fixed (the "
                         "nodes on G0 follow the CAD)");
    if (a->solver == CM_RBF_SOLVER_PETSC)
        return cli_usage(cmd, usage_line,
                         "--solver petsc: a study spreads its variants over the MPI ranks "
                         "(mpirun -n K cadmorph study), each rank solving its own");
    if (!a->from || !a->mesh || !a->variants || !a->out)
        return cli_usage(cmd, usage_line, "--from, --mesh, --variants and -o are required");
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return cli_usage(cmd, usage_line, "out of memory");
    cm_status s = cm_study_methods_parse(ctx, a->methods, a->list, MAX_METHODS, &a->n_methods);
    if (s < 0) cli_usage(cmd, usage_line, "--methods: %s", cm_context_message(ctx));
    for (size_t k = 0; k < a->n_methods; ++k) {
        a->list[k].method.warp.solver = (cm_rbf_solver)a->solver;
        a->list[k].method.warp.tolerance = a->rbf_tol;
    }
    cm_context_destroy(&ctx);
    return s < 0 ? CLI_EXIT_USAGE : -1;
}

/* One line per row: what a user checks before opening the CSV. */
static void print_summary(const cm_study_result *r)
{
    printf("%zu variants; mesh %zu nodes, %zu cells, %zu boundary nodes; M0 min scaled "
           "Jacobian %.4g; %.1f s\n",
           r->n_variants, r->nodes, r->cells, r->boundary_nodes, r->min_sj0, r->t_total);
    printf("%-24s %-18s %-9s %10s %10s %9s %13s  %s\n", "variant", "method", "mode", "min_sj",
           "mean_sj", "inverted", "max_dist/diag", "status");
    for (size_t i = 0; i < r->n_rows; ++i) {
        const cm_study_row *w = &r->rows[i];
        if (w->status < 0) {
            printf("%-24s %-18s %-9s %10s %10s %9s %13s  %s\n", w->label,
                   r->methods[w->method].name, cm_study_mode_name(w->mode), "-", "-", "-", "-",
                   cm_status_name(w->status));
            continue;
        }
        printf("%-24s %-18s %-9s %10.4g %10.4g %9zu %13.3g  %s\n", w->label,
               r->methods[w->method].name, cm_study_mode_name(w->mode), w->min_sj, w->mean_sj,
               w->inverted, r->diagonal > 0 ? w->max_dist / r->diagonal : 0.0,
               cm_status_name(w->status));
    }
}

/* Reads G0, M0 and the list, runs the study, writes study.csv and study.svg. */
static int run(cm_context *ctx, const study_args *a)
{
    char **paths = NULL;
    size_t n = 0;
    cm_cad_model *g0 = NULL;
    cm_mesh *mesh = NULL;
    cm_study_family fam = {0};
    cm_study_result *r = NULL;
    cm_cad_read_options ro;
    cm_cad_read_options_init(&ro);
    if (a->unit) ro.unit = a->unit;
    /* a design table (header step,<p1>,...) or a plain list of STEP paths */
    cm_design_table *table = NULL;
    size_t base = 0;
    const int design = cm_design_table_detect(a->variants);
    cm_status s = design ? cm_design_table_read(ctx, a->variants, &table)
                         : cm_study_read_list(ctx, a->variants, &paths, &n);
    if (s >= 0 && design) s = cm_design_table_find(ctx, table, a->from, &base);
    /* every input, against which every output is checked (device and inode) */
    const char **inputs = s >= 0 ? malloc((n + 3) * sizeof *inputs) : NULL;
    if (s >= 0 && !inputs) s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    size_t n_in = 0;
    if (inputs) {
        inputs[n_in++] = a->from;
        inputs[n_in++] = a->mesh;
        inputs[n_in++] = a->variants;
        for (size_t k = 0; k < n; ++k)
            inputs[n_in++] = paths[k];
    }
    /* the results go to a temporary directory made visible at the end (docs/DESIGN.md,
     * "Command line contract"); under mpirun the ranks write into DIR itself */
    static const char *const names[] = {"study.csv", "study.svg", NULL};
    cm_outdir od = {0};
    int rc = s < 0 ? cli_fail(ctx, "study", s)
             : a->ranks > 1 ? cli_make_dir("study", a->out)
                            : cli_outdir_begin(ctx, "study", a->out, names, inputs, n_in, &od);
    const char *out_dir = od.tmp ? od.tmp : a->out;
    if (rc == 0) {
        s = cm_cad_read(ctx, a->from, &ro, &g0);
        if (s >= 0) s = cm_mesh_read(ctx, a->mesh, &mesh);
        if (s >= 0)
            s = design ? cm_study_family_design(ctx, table, base, &ro, &fam)
                       : cm_study_family_files(ctx, (const char *const *)paths, n, &ro, &fam);
        if (s >= 0) {
            cm_study_options so;
            cm_study_options_init(&so);
            so.modes = a->modes;
            so.methods = a->list;
            so.n_methods = a->n_methods;
            so.write_meshes = a->write_meshes;
            so.out_dir = out_dir;
            const char *base = strrchr(a->from, '/'), *mbase = strrchr(a->mesh, '/');
            so.model = base ? base + 1 : a->from;
            so.mesh = mbase ? mbase + 1 : a->mesh;
            if (a->unit) so.morph.cad_unit = a->unit;
            so.morph.steps = a->steps;
            so.morph.optimize = a->optimize;
            so.morph.allow_inverted = a->allow_inverted;
            so.morph.off_cad = (cm_off_cad)a->off_cad;
            cli_patch_motion_options(&args.patches, &so.morph.motion);
            so.batch = a->batch;
            so.rank = a->rank;
            so.ranks = a->ranks;
            s = cm_study_run(ctx, g0, mesh, &fam, &so, &r);
            if (s < 0) s = cm_error_prefix(ctx, s, "%s, %s", a->from, a->mesh);
        }
        if (s >= 0 && a->rank == 0) { /* under mpirun: every rank has all rows, rank 0 writes */
            size_t len = strlen(out_dir) + 16;
            char *path = malloc(len);
            if (!path) s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
            if (s >= 0) {
                snprintf(path, len, "%s/study.csv", out_dir);
                s = cm_study_write_csv(ctx, r, path, CM_STUDY_CSV_FULL);
            }
            if (s >= 0) {
                snprintf(path, len, "%s/study.svg", out_dir);
                s = cm_study_write_svg(ctx, r, path);
            }
            free(path);
        }
        if (s >= 0 && od.tmp) s = cm_outdir_merge(ctx, &od, a->out, inputs, n_in);
        rc = s < 0 ? cli_fail(ctx, "study", s) : CLI_EXIT_OK;
        if (rc == CLI_EXIT_OK && a->rank == 0) print_summary(r);
        /* failed rows were warnings as they happened: the exit code says so at the end */
        if (rc == CLI_EXIT_OK && r->n_failed) {
            if (a->rank == 0)
                fprintf(stderr, "cadmorph study: %zu of %zu rows failed (status and message in "
                        "%s/study.csv)\n", r->n_failed, r->n_rows, a->out);
            rc = CLI_EXIT_REJECTED;
        }
    }
    cm_outdir_abort(&od);
    free(inputs);
    cm_study_result_destroy(&r);
    cm_study_family_release(&fam);
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&g0);
    cm_study_paths_free(&paths, n);
    cm_design_table_destroy(&table);
    return rc;
}

int cli_cmd_study(int argc, char **argv)
{
    study_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    cm_context *ctx = cli_context_create("study", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    /* mpirun -n K cadmorph study: the absolute variants and the relative series over the K
     * ranks (cm_study_options.rank) */
    rc = cli_mpi_ranks(ctx, "study", &a.rank, &a.ranks);
    if (rc == 0) rc = run(ctx, &a);
    cm_context_destroy(&ctx);
    return rc;
}
