/* `cadmorph sweep`: a Staten-style study of a benchmark model (issue 6): M(0) morphed onto
 * G(t) for t = 1/N .. 1 by several methods, absolutely and/or relatively; sweep.csv, sweep.svg
 * and the meshes at 50 and 100 % in the output directory, a summary on stdout. */
#include "cli.h"

#include "sweep.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char *const usage_line =
    "cadmorph sweep bore|pipe|bracket --mesh tet|hex|FILE --mode absolute|relative|both "
    "--steps N -o DIR [--size H] [--methods rbf-s,project,rbf-s-biharmonic] [--write-step] "
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
        "  MODEL              bore, pipe or bracket (benchmarks/models)\n"
        "  --mesh M           tet: TetGen mesh of G(0) at --size; hex: the O-grid hex mesh\n"
        "                     (bore, pipe); or a mesh file of G(0) (default tet)\n"
        "  --size H           tet edge length (default 0.2); hex: cells of about H (default\n"
        "                     0.1)\n"
        "  --mode M           absolute, relative or both (default both)\n"
        "  --steps N          parameter steps (default 10)\n"
        "  -o, --output DIR   output directory (created if missing)\n"
        "  --methods LIST     comma-separated subset (default all three)\n"
        "  --write-step       keep G(t) as DIR/G_<t>.step\n"
        "  --threads N        threads (default: all)\n"
        "  --verbose          debug messages on stderr\n\n"
        "exit codes: 0 done (a method that failed on the way is a warning on stderr), 1 usage,\n"
        "2 bad input, 4 internal error.\n");
}

typedef struct sweep_args {
    cm_sweep_options opt;
    int threads, verbose;
} sweep_args;

static int parse_methods(const char *v, unsigned *methods)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", v);
    *methods = 0;
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok;
         tok = strtok_r(NULL, ",", &save)) {
        int m = cm_sweep_method_from_name(tok);
        if (m < 0) return cli_usage("sweep", usage_line, "unknown method '%s'", tok);
        *methods |= 1u << m;
    }
    if (!*methods) return cli_usage("sweep", usage_line, "--methods: empty list");
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
                a->opt.modes = CM_SWEEP_ABSOLUTE;
            else if (!strcmp(v, "relative"))
                a->opt.modes = CM_SWEEP_RELATIVE;
            else if (!strcmp(v, "both"))
                a->opt.modes = CM_SWEEP_ABSOLUTE | CM_SWEEP_RELATIVE;
            else
                return cli_usage(cmd, usage_line, "unknown mode '%s'", v);
        } else if (!strcmp(o, "--methods")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            if (parse_methods(v, &a->opt.methods)) return CLI_EXIT_USAGE;
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

/* mkdir -p: the output directory and any missing parents. */
static int make_dir(const char *dir)
{
    char path[4096];
    if (snprintf(path, sizeof path, "%s", dir) >= (int)sizeof path) {
        fprintf(stderr, "cadmorph sweep: output directory name too long\n");
        return CLI_EXIT_BAD_INPUT;
    }
    for (char *p = path + 1;; ++p) {
        if (*p != '/' && *p) continue;
        char c = *p;
        *p = 0;
        struct stat st;
        if (stat(path, &st) != 0) {
            if (mkdir(path, 0777) != 0 && errno != EEXIST) {
                fprintf(stderr, "cadmorph sweep: cannot create %s: %s\n", path, strerror(errno));
                return CLI_EXIT_BAD_INPUT;
            }
        } else if (!S_ISDIR(st.st_mode)) {
            fprintf(stderr, "cadmorph sweep: %s exists and is not a directory\n", path);
            return CLI_EXIT_BAD_INPUT;
        }
        *p = c;
        if (!c) return 0;
    }
}

/* Per method and mode: the quality at 100 % and the first step with an inverted cell. */
static void print_summary(const cm_sweep_result *r)
{
    printf("%s %s mesh: %zu nodes, %zu cells, %zu boundary nodes; M(0) min scaled Jacobian "
           "%.4g\n",
           r->model, r->mesh, r->nodes, r->cells, r->boundary_nodes, r->min_sj0);
    printf("%-18s %-9s %6s %10s %10s %9s %14s %12s\n", "method", "mode", "steps", "min_sj",
           "mean_sj", "inverted", "first_inverted", "max_dist/diag");
    for (int mode = CM_SWEEP_ABSOLUTE; mode <= CM_SWEEP_RELATIVE; ++mode)
        for (int m = 0; m < CM_SWEEP_N_METHODS; ++m) {
            const cm_sweep_row *last = NULL;
            int first_inv = 0, n = 0;
            double worst = 0;
            for (size_t i = 0; i < r->n_rows; ++i) {
                const cm_sweep_row *w = &r->rows[i];
                if (w->mode != mode || w->method != m) continue;
                last = w;
                ++n;
                if (w->inverted && !first_inv) first_inv = w->step;
                if (w->max_dist > worst) worst = w->max_dist;
            }
            if (!last) continue;
            char inv[32] = "-";
            if (first_inv) snprintf(inv, sizeof inv, "step %d", first_inv);
            printf("%-18s %-9s %6d %10.4g %10.4g %9zu %14s %12.3g\n", cm_sweep_method_name(m),
                   cm_sweep_mode_name(mode), n, last->min_sj, last->mean_sj, last->inverted, inv,
                   r->diagonal > 0 ? worst / r->diagonal : 0.0);
        }
}

int cli_cmd_sweep(int argc, char **argv)
{
    sweep_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    if ((rc = make_dir(a.opt.out_dir)) != 0) return rc;
    cm_context *ctx = cli_context_create("sweep", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_sweep_result *r = NULL;
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
        cm_sweep_result_destroy(&r);
        cm_context_destroy(&ctx);
        fprintf(stderr, "cadmorph sweep: out of memory\n");
        return CLI_EXIT_INTERNAL;
    }
    snprintf(path, n, "%s/sweep.csv", a.opt.out_dir);
    s = cm_sweep_write_csv(ctx, r, path);
    if (s >= 0) {
        snprintf(path, n, "%s/sweep.svg", a.opt.out_dir);
        s = cm_sweep_write_svg(ctx, r, path);
    }
    rc = s < 0 ? cli_fail(ctx, "sweep", s) : CLI_EXIT_OK;
    if (rc == CLI_EXIT_OK) print_summary(r);
    free(path);
    cm_sweep_result_destroy(&r);
    cm_context_destroy(&ctx);
    return rc;
}
