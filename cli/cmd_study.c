/* `cadmorph study`: a mesh M0 of G0 morphed onto every STEP file of a list (a design table
 * exported from a CAD program), by one or more methods, absolutely and/or relatively;
 * study.csv, study.svg and the meshes in the output directory, a summary on stdout. */
#include "cli.h"

#include "cadmorph/study.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph study --from G0.step --mesh M0 --variants LIST -o DIR "
    "[--mode absolute|relative|both] [--methods LIST] [--write-meshes none|all|failed] "
    "[--steps K|auto] [--optimize] [--cad-unit U] [--threads N] [--verbose]";

static void print_help(void)
{
    char methods[512];
    cm_study_method_help(methods, sizeof methods);
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
        "options:\n"
        "  --from G0.step        the geometry M0 is a mesh of\n"
        "  --mesh M0             volume mesh of G0 (.msh .vtu .vtk .mesh)\n"
        "  --variants LIST       a text file of STEP paths, one per line ('#' comments; relative\n"
        "                        paths are relative to the list file), or a quoted glob pattern\n"
        "                        such as 'designs/*.step' (sorted)\n"
        "  -o, --output DIR      output directory (created if missing)\n"
        "  --mode M              absolute, relative or both (default absolute)\n"
        "  --methods LIST        comma-separated (default rbf-s): %s\n"
        "  --write-meshes W      none, all (default) or failed (results with inverted cells)\n"
        "  --steps K|auto        increments of each morph (default 1), or adaptive steps as\n"
        "                        in morph --steps auto (a variant without a valid step is a row\n"
        "                        with its error)\n"
        "  --optimize            interior optimisation after each morph step\n"
        "  --cad-unit U          unit of the mesh coordinates (mm default; cm m in ft um ...)\n"
        "  --threads N           threads (default: all)\n"
        "  --verbose             debug messages on stderr\n\n"
        "Progress (on a terminal): the variant count and an estimate of the time left.\n"
        "exit codes: 0 done (failed variants are warnings on stderr and rows in study.csv),\n"
        "1 usage, 2 bad input (G0, M0 or the list: one line naming the file), 4 internal "
        "error.\n",
        methods);
}

enum { MAX_METHODS = 16 };

typedef struct study_args {
    const char *from, *mesh, *variants, *out, *unit;
    int modes, write_meshes, threads, verbose, steps, optimize;
    cm_study_method methods[MAX_METHODS];
    size_t n_methods;
} study_args;

static int parse_args(int argc, char **argv, study_args *a)
{
    static const char *cmd = "study";
    memset(a, 0, sizeof *a);
    a->modes = CM_STUDY_ABSOLUTE;
    a->write_meshes = CM_STUDY_WRITE_ALL;
    a->steps = 1;
    const char *methods = "rbf-s";
    for (int i = 1; i < argc; ++i) {
        const char *o = argv[i], *v;
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            print_help();
            return CLI_EXIT_OK;
        } else if (!strcmp(o, "--verbose") || !strcmp(o, "-v")) {
            a->verbose = 1;
        } else if (!strcmp(o, "--from")) {
            if (!(a->from = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--mesh")) {
            if (!(a->mesh = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--variants")) {
            if (!(a->variants = cli_value(argc, argv, &i, cmd, usage_line)))
                return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "-o") || !strcmp(o, "--output")) {
            if (!(a->out = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--cad-unit")) {
            if (!(a->unit = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--mode")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            if (!strcmp(v, "absolute"))
                a->modes = CM_STUDY_ABSOLUTE;
            else if (!strcmp(v, "relative"))
                a->modes = CM_STUDY_RELATIVE;
            else if (!strcmp(v, "both"))
                a->modes = CM_STUDY_BOTH;
            else
                return cli_usage(cmd, usage_line, "unknown mode '%s'", v);
        } else if (!strcmp(o, "--methods")) {
            if (!(methods = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--optimize")) {
            a->optimize = 1;
        } else if (!strcmp(o, "--steps")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            char *end;
            long n = strtol(v, &end, 10);
            if (!strcmp(v, "auto"))
                a->steps = CM_MORPH_STEPS_AUTO;
            else if (end == v || *end || n < 1 || n > 1000)
                return cli_usage(cmd, usage_line, "--steps: expected 1..1000 or auto, got '%s'", v);
            else
                a->steps = (int)n;
        } else if (!strcmp(o, "--write-meshes")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            if (!strcmp(v, "none"))
                a->write_meshes = CM_STUDY_WRITE_NONE;
            else if (!strcmp(v, "all"))
                a->write_meshes = CM_STUDY_WRITE_ALL;
            else if (!strcmp(v, "failed"))
                a->write_meshes = CM_STUDY_WRITE_FAILED;
            else
                return cli_usage(cmd, usage_line, "--write-meshes: none, all or failed, got '%s'",
                                 v);
        } else if (!strcmp(o, "--threads")) {
            if (cli_threads_value(argc, argv, &i, cmd, usage_line, &a->threads))
                return CLI_EXIT_USAGE;
        } else {
            return cli_usage(cmd, usage_line, "unknown argument '%s'", o);
        }
    }
    if (!a->from || !a->mesh || !a->variants || !a->out)
        return cli_usage(cmd, usage_line, "--from, --mesh, --variants and -o are required");
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return cli_usage(cmd, usage_line, "out of memory");
    cm_status s = cm_study_methods_parse(ctx, methods, a->methods, MAX_METHODS, &a->n_methods);
    if (s < 0) cli_usage(cmd, usage_line, "--methods: %s", cm_context_message(ctx));
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
    cm_status s = cm_study_read_list(ctx, a->variants, &paths, &n);
    int rc = s < 0 ? cli_fail(ctx, "study", s) : cli_make_dir("study", a->out);
    if (rc == 0) {
        s = cm_cad_read(ctx, a->from, &ro, &g0);
        if (s >= 0) s = cm_mesh_read(ctx, a->mesh, &mesh);
        if (s >= 0) s = cm_study_family_files(ctx, (const char *const *)paths, n, &ro, &fam);
        if (s >= 0) {
            cm_study_options so;
            cm_study_options_init(&so);
            so.modes = a->modes;
            so.methods = a->methods;
            so.n_methods = a->n_methods;
            so.write_meshes = a->write_meshes;
            so.out_dir = a->out;
            const char *base = strrchr(a->from, '/'), *mbase = strrchr(a->mesh, '/');
            so.model = base ? base + 1 : a->from;
            so.mesh = mbase ? mbase + 1 : a->mesh;
            if (a->unit) so.morph.cad_unit = a->unit;
            so.morph.steps = a->steps;
            so.morph.optimize = a->optimize;
            s = cm_study_run(ctx, g0, mesh, &fam, &so, &r);
            if (s < 0) s = cm_error_prefix(ctx, s, "%s, %s", a->from, a->mesh);
        }
        if (s >= 0) {
            size_t len = strlen(a->out) + 16;
            char *path = malloc(len);
            if (!path) s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
            if (s >= 0) {
                snprintf(path, len, "%s/study.csv", a->out);
                s = cm_study_write_csv(ctx, r, path, CM_STUDY_CSV_FULL);
            }
            if (s >= 0) {
                snprintf(path, len, "%s/study.svg", a->out);
                s = cm_study_write_svg(ctx, r, path);
            }
            free(path);
        }
        rc = s < 0 ? cli_fail(ctx, "study", s) : CLI_EXIT_OK;
        if (rc == CLI_EXIT_OK) print_summary(r);
    }
    cm_study_result_destroy(&r);
    cm_study_family_release(&fam);
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&g0);
    cm_study_paths_free(&paths, n);
    return rc;
}

int cli_cmd_study(int argc, char **argv)
{
    study_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    cm_context *ctx = cli_context_create("study", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    rc = run(ctx, &a);
    cm_context_destroy(&ctx);
    return rc;
}
