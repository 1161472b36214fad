/* `cadmorph sweep`: a Staten-style study of a benchmark model (issue 6): M(0) morphed onto
 * G(t) for t = 1/N .. 1 by several methods, absolutely and/or relatively; sweep.csv, sweep.svg
 * and the meshes at 50 and 100 % in the output directory, a summary on stdout. */
#include "cli.h"

#include "cadmorph/study.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph sweep bore|pipe|bracket --mesh tet|hex|FILE --mode absolute|relative|both "
    "--steps N -o DIR [--size H] [--methods LIST] [--adaptive] [--optimize] [--write-step] "
    "[--threads N] [--verbose]";

static void print_help(void)
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
        "options:\n"
        "  MODEL              bore, pipe or bracket (the built-in models)\n"
        "  --mesh M           tet: TetGen mesh of G(0) at --size; hex: the O-grid hex mesh\n"
        "                     (bore, pipe); or a mesh file of G(0) (default tet)\n"
        "  --size H           tet edge length (default 0.2); hex: cells of about H (default\n"
        "                     0.1)\n"
        "  --mode M           absolute, relative or both (default both)\n"
        "  --steps N          parameter steps (default 10)\n"
        "  --adaptive         each morph with adaptive steps (as morph --steps auto)\n"
        "  --optimize         each morph with interior optimisation (as morph --optimize)\n"
        "  -o, --output DIR   output directory (created if missing)\n"
        "  --methods LIST     comma-separated study methods (default the three above;\n"
        "                     see 'cadmorph study --help')\n"
        "  --write-step       keep G(t) as DIR/G_<t>.step\n"
        "  --threads N        threads (default: all)\n"
        "  --verbose          debug messages on stderr\n\n"
        "exit codes: 0 done (a method that failed on the way is a warning on stderr), 1 usage,\n"
        "2 bad input, 4 internal error.\n");
}

enum { MAX_METHODS = 16 };

typedef struct sweep_args {
    cm_sweep_options opt;
    cm_study_method methods[MAX_METHODS];
    int threads, verbose;
} sweep_args;

/* The list in the sweeps' table order (rbf-s, project, rbf-s-biharmonic, then the others as
 * given), as the plot and summary have always shown them. */
static int parse_methods(const char *v, sweep_args *a)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return cli_usage("sweep", usage_line, "out of memory");
    size_t n = 0;
    cm_status s = cm_study_methods_parse(ctx, v, a->methods, MAX_METHODS, &n);
    if (s < 0) {
        cli_usage("sweep", usage_line, "--methods: %s", cm_context_message(ctx));
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

static int parse_args(int argc, char **argv, sweep_args *a)
{
    static const char *cmd = "sweep";
    memset(a, 0, sizeof *a);
    cm_sweep_options_init(&a->opt);
    a->opt.out_dir = NULL;
    const char *model = NULL;
    for (int i = 1; i < argc; ++i) {
        const char *o = argv[i], *v;
        char *end;
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            print_help();
            return CLI_EXIT_OK;
        } else if (!strcmp(o, "--verbose") || !strcmp(o, "-v")) {
            a->verbose = 1;
        } else if (!strcmp(o, "--write-step")) {
            a->opt.write_step = 1;
        } else if (!strcmp(o, "--mesh")) {
            if (!(a->opt.mesh = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "-o") || !strcmp(o, "--output")) {
            if (!(a->opt.out_dir = cli_value(argc, argv, &i, cmd, usage_line)))
                return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--mode")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            if (!strcmp(v, "absolute"))
                a->opt.modes = CM_STUDY_ABSOLUTE;
            else if (!strcmp(v, "relative"))
                a->opt.modes = CM_STUDY_RELATIVE;
            else if (!strcmp(v, "both"))
                a->opt.modes = CM_STUDY_BOTH;
            else
                return cli_usage(cmd, usage_line, "unknown mode '%s'", v);
        } else if (!strcmp(o, "--methods")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            if (parse_methods(v, a)) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--adaptive")) {
            a->opt.adaptive = 1;
        } else if (!strcmp(o, "--optimize")) {
            a->opt.optimize = 1;
        } else if (!strcmp(o, "--steps")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            long n = strtol(v, &end, 10);
            if (end == v || *end || n < 1 || n > 1000)
                return cli_usage(cmd, usage_line, "--steps: expected 1..1000, got '%s'", v);
            a->opt.steps = (int)n;
        } else if (!strcmp(o, "--size")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            double h = strtod(v, &end);
            if (end == v || *end || !(h > 0) || h > 1e6)
                return cli_usage(cmd, usage_line, "--size: expected a positive length, got '%s'",
                                 v);
            a->opt.size = h;
        } else if (!strcmp(o, "--threads")) {
            if (cli_threads_value(argc, argv, &i, cmd, usage_line, &a->threads))
                return CLI_EXIT_USAGE;
        } else if (o[0] == '-') {
            return cli_usage(cmd, usage_line, "unknown argument '%s'", o);
        } else if (model) {
            return cli_usage(cmd, usage_line, "one model only, got '%s' and '%s'", model, o);
        } else {
            model = o;
        }
    }
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
    if ((rc = cli_make_dir("sweep", a.opt.out_dir)) != 0) return rc;
    cm_context *ctx = cli_context_create("sweep", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_study_result *r = NULL;
    cm_status s = cm_sweep_run(ctx, &a.opt, &r);
    if (s < 0) {
        rc = cli_fail(ctx, "sweep", s);
        cm_context_destroy(&ctx);
        return rc;
    }
    /* a stopped series was logged as a warning when it happened */
    size_t n = strlen(a.opt.out_dir) + 16;
    char *path = malloc(n);
    if (!path) {
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
    rc = s < 0 ? cli_fail(ctx, "sweep", s) : CLI_EXIT_OK;
    if (rc == CLI_EXIT_OK) print_summary(r);
    free(path);
    cm_study_result_destroy(&r);
    cm_context_destroy(&ctx);
    return rc;
}
