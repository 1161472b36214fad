/* `cadmorph sweep`: a Staten-style study of a benchmark model [SKM11]: M(0) morphed onto
 * G(t) for t = 1/N .. 1 by several methods, absolutely and/or relatively; sweep.csv, sweep.svg
 * and the meshes at 50 and 100 % in the output directory, a summary on stdout. */
#include "cli.h"
#include "options.h"

#include "cadmorph/study.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph sweep bore|pipe|bracket --mesh tet|hex|FILE --mode absolute|relative|both "
    "--steps N -o DIR [--size H] [--methods LIST] [--adaptive] [--optimize] [--write-step] "
    "[--threads N] [--verbose]";

enum { MAX_METHODS = 16 };

typedef struct sweep_args {
    cm_sweep_options opt;
    cm_study_method methods[MAX_METHODS];
    int threads, verbose;
} sweep_args;

static sweep_args args;

static int print_help(void);

/* The list in the sweeps' table order (rbf-s, project, rbf-s-biharmonic, then the others as
 * given), as the plot and summary have always shown them. */
static int parse_methods(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    (void)o;
    sweep_args *a = dest;
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return cli_usage(p->cmd, p->usage, "out of memory");
    size_t n = 0;
    cm_status s = cm_study_methods_parse(ctx, v, a->methods, MAX_METHODS, &n);
    if (s < 0) {
        cli_usage(p->cmd, p->usage, "--methods: %s", cm_context_message(ctx));
        cm_context_destroy(&ctx);
        return CLI_EXIT_USAGE;
    }
    cm_context_destroy(&ctx);
    for (size_t i = 1; i < n; ++i) /* insertion sort by slot: stable, n is tiny */
        for (size_t j = i; j > 0 && cm_study_method_slot(&a->methods[j], MAX_METHODS) <
                                        cm_study_method_slot(&a->methods[j - 1], MAX_METHODS);
             --j) {
            cm_study_method t = a->methods[j];
            a->methods[j] = a->methods[j - 1];
            a->methods[j - 1] = t;
        }
    a->opt.methods = a->methods;
    a->opt.n_methods = n;
    return 0;
}

static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "MODEL", .kind = CLI_NOTE, .label = "MODEL",
     .help = "bore, pipe or bracket (the built-in models)"},
    {.name = "--mesh", .kind = CLI_STRING, .dest = &args.opt.mesh, .label = "--mesh M",
     .help = "tet: TetGen mesh of G(0) at --size; hex: the O-grid hex mesh\n"
             "(bore, pipe); or a mesh file of G(0) (default tet)"},
    {.name = "--size", .kind = CLI_DOUBLE, .dest = &args.opt.size, .lo = 0, .hi = 1e6, .open = 1,
     .bad = "%s: expected a positive length, got '%s'", .label = "--size H",
     .help = "tet edge length (default 0.2); hex: cells of about H (default\n0.1)"},
    {.name = "--mode", .kind = CLI_ENUM, .dest = &args.opt.modes, .names = cli_study_mode_names,
     .values = cli_study_mode_values, .bad = "%.0sunknown mode '%s'", .label = "--mode M",
     .help = "absolute, relative or both (default both)"},
    {.name = "--steps", .kind = CLI_INT, .dest = &args.opt.steps, .lo = 1, .hi = 1000,
     .bad = "%s: expected 1..1000, got '%s'", .label = "--steps N",
     .help = "parameter steps (default 10)"},
    {.name = "--adaptive", .kind = CLI_FLAG, .dest = &args.opt.adaptive, .label = "--adaptive",
     .help = "each morph with adaptive steps (as morph --steps auto; a morph\n"
             "that reaches no valid mesh is a failed row); default: the plain\n"
             "one-step morph of the papers, inverted cells kept (as morph\n"
             "--steps 1 --allow-inverted): where they appear is what a sweep\n"
             "measures"},
    {.name = "--optimize", .kind = CLI_FLAG, .dest = &args.opt.optimize, .label = "--optimize",
     .help = "each morph with interior optimisation (as morph --optimize)"},
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &args.opt.out_dir,
     .label = "-o, --output DIR", .help = "output directory (created if missing)"},
    {.name = "--methods", .kind = CLI_CUSTOM, .takes_value = 1, .parse = parse_methods,
     .dest = &args, .label = "--methods LIST",
     .help = "comma-separated study methods (default the three above;\n"
             "see 'cadmorph study --help')"},
    {.name = "--write-step", .kind = CLI_FLAG, .dest = &args.opt.write_step,
     .label = "--write-step", .help = "keep G(t) as DIR/G_<t>.step"},
    {.name = "--threads", .kind = CLI_THREADS, .dest = &args.threads, .label = "--threads N",
     .help = "threads (default: all)"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &args.verbose,
     .label = "--verbose", .help = "debug messages on stderr"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf(
        "Morphs a mesh M(0) of the benchmark model G(0) onto G(t), t = 1/N, 2/N, ..., 1, and\n"
        "compares methods: rbf-s (CAD-aware surface morph + triharmonic warp), project (closest\n"
        "point on G(t) + triharmonic warp), rbf-s-biharmonic (surface morph + biharmonic warp).\n"
        "absolute: every M(t) from M(0) (classification and warp factorisation once, reused for\n"
        "every t); relative: M(t) from M(t - 1/N), classification and warp redone per step.\n\n"
        "Writes in DIR: sweep.csv (one row per mode x method x step: quality, largest distance\n"
        "of the boundary to G(t), stage times), sweep.svg (min scaled Jacobian against percent\n"
        "of parameter change; solid absolute, dashed relative) and <method>_<mode>_050.vtu /\n"
        "_100.vtu (the meshes at 50 and 100 %%, with 'scaled_jacobian' and 'displacement';\n"
        "for an odd N the middle one is the step just past 50 %%, named by its percent).\n\n"
        "options:\n");
    cli_print_options(stdout, options, 19);
    printf("\nexit codes: 0 done (a method that failed on the way is a warning on stderr), 1 "
           "usage,\n2 bad input, 4 internal error.\n");
    return CLI_EXIT_OK;
}

/* Returns -1 to go on, else the exit code. */
static int parse_args(int argc, char **argv, sweep_args *a)
{
    static const char *cmd = "sweep";
    memset(&args, 0, sizeof args);
    cm_sweep_options_init(&args.opt);
    args.opt.out_dir = NULL;
    const char *pos[2] = {NULL, NULL};
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown argument '%s'", .pos = pos, .max_pos = 2,
                    .extra = "one model only, got '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    *a = args;
    if (a->opt.methods == args.methods) a->opt.methods = a->methods; /* into the copy */
    if (parsed >= 0) return parsed;
    const char *model = pos[0];
    if (p.n_pos > 1)
        return cli_usage(cmd, usage_line, "one model only, got '%s' and '%s'", model, pos[1]);
    if (!model) return cli_usage(cmd, usage_line, "MODEL is required (bore, pipe, bracket)");
    if (strcmp(model, "bore") && strcmp(model, "pipe") && strcmp(model, "bracket"))
        return cli_usage(cmd, usage_line, "unknown model '%s' (bore, pipe, bracket)", model);
    if (!strcmp(a->opt.mesh, "hex") && !strcmp(model, "bracket"))
        return cli_usage(cmd, usage_line, "no hex mesh of the bracket (bore, pipe only)");
    if (!a->opt.out_dir) return cli_usage(cmd, usage_line, "-o DIR is required");
    a->opt.model = model;
    return -1;
}

/* Per method and mode: the quality at 100 % and the first step with an inverted cell. */
static void print_summary(const cm_study_result *r)
{
    printf("%s %s mesh: %zu nodes, %zu cells, %zu boundary nodes; M(0) min scaled Jacobian "
           "%.4g\n",
           r->model, r->mesh, r->nodes, r->cells, r->boundary_nodes, r->min_sj0);
    printf("%-18s %-9s %6s %10s %10s %9s %14s %12s\n", "method", "mode", "steps", "min_sj",
           "mean_sj", "inverted", "first_inverted", "max_dist/diag");
    for (int mode = CM_STUDY_ABSOLUTE; mode <= CM_STUDY_RELATIVE; ++mode)
        for (size_t m = 0; m < r->n_methods; ++m) {
            const cm_study_row *last = NULL;
            int first_inv = 0, n = 0;
            double worst = 0;
            for (size_t i = 0; i < r->n_rows; ++i) {
                const cm_study_row *w = &r->rows[i];
                if (w->mode != mode || w->method != m || w->status < 0) continue;
                last = w;
                ++n;
                if (w->inverted && !first_inv) first_inv = (int)w->variant + 1;
                if (w->max_dist > worst) worst = w->max_dist;
            }
            if (!last) continue;
            char inv[32] = "-";
            if (first_inv) snprintf(inv, sizeof inv, "step %d", first_inv);
            printf("%-18s %-9s %6d %10.4g %10.4g %9zu %14s %12.3g\n", r->methods[m].name,
                   cm_study_mode_name(mode), n, last->min_sj, last->mean_sj, last->inverted, inv,
                   r->diagonal > 0 ? worst / r->diagonal : 0.0);
        }
}

int cli_cmd_sweep(int argc, char **argv)
{
    sweep_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    cm_context *ctx = cli_context_create("sweep", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    /* the results go to a temporary directory made visible at the end (docs/DESIGN.md,
     * "Command line contract"); a mesh FILE is the one input the outputs are checked against */
    const int file_mesh = strcmp(a.opt.mesh, "tet") && strcmp(a.opt.mesh, "hex");
    const char *inputs[1] = {file_mesh ? a.opt.mesh : NULL};
    static const char *const names[] = {"sweep.csv", "sweep.svg", NULL};
    const char *out = a.opt.out_dir;
    cm_outdir od;
    if ((rc = cli_outdir_begin(ctx, "sweep", out, names, inputs, 1, &od)) != 0) {
        cm_context_destroy(&ctx);
        return rc;
    }
    a.opt.out_dir = od.tmp;
    cm_study_result *r = NULL;
    cm_status s = cm_sweep_run(ctx, &a.opt, &r);
    if (s < 0) {
        rc = cli_fail(ctx, "sweep", s);
        cm_outdir_abort(&od);
        cm_context_destroy(&ctx);
        return rc;
    }
    /* a stopped series was logged as a warning when it happened */
    size_t n = strlen(a.opt.out_dir) + 16;
    char *path = malloc(n);
    if (!path) {
        cm_outdir_abort(&od);
        cm_study_result_destroy(&r);
        cm_context_destroy(&ctx);
        fprintf(stderr, "cadmorph sweep: out of memory\n");
        return CLI_EXIT_INTERNAL;
    }
    snprintf(path, n, "%s/sweep.csv", a.opt.out_dir);
    s = cm_study_write_csv(ctx, r, path, CM_STUDY_CSV_SWEEP);
    if (s >= 0) {
        snprintf(path, n, "%s/sweep.svg", a.opt.out_dir);
        s = cm_study_write_svg(ctx, r, path);
    }
    if (s >= 0) s = cm_outdir_merge(ctx, &od, out, inputs, 1);
    cm_outdir_abort(&od);
    rc = s < 0 ? cli_fail(ctx, "sweep", s) : CLI_EXIT_OK;
    if (rc == CLI_EXIT_OK) print_summary(r);
    free(path);
    cm_study_result_destroy(&r);
    cm_context_destroy(&ctx);
    return rc;
}
