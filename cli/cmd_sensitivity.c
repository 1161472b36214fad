/* `cadmorph sensitivity`: design velocities dX/dp of a mesh for the parameters of a design
 * table and, given a sensitivity dJ/dX, the gradient dJ/dp (docs/DESIGN.md, "Gradients"). */
#include "cli.h"
#include "options.h"

#include "cadmorph/study.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *const usage_line =
    "cadmorph sensitivity --from G0.step --mesh M0 --design-table T.csv -o DIR "
    "[--dJdX S | --dJdXs S] [--surface rbf|project] [--method M] [--solver S] [--cad-unit U] "
    "[--threads N] [--verbose]";

typedef struct sens_args {
    const char *from, *mesh, *table, *out, *dJdX, *dJdXs, *unit;
    int threads, verbose;
    cm_morph_options opt;
} sens_args;

static sens_args args;

static int print_help(void);

static const char *const surface_names[] = {"rbf", "project", NULL};
static const int surface_methods[] = {CM_SURFACE_RBF, CM_SURFACE_PROJECT};
static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "--from", .kind = CLI_STRING, .dest = &args.from, .label = "--from G0.step",
     .help = "the base geometry: a row of the design table, the one M0 lies on"},
    {.name = "--mesh", .kind = CLI_STRING, .dest = &args.mesh, .label = "--mesh M0",
     .help = "volume mesh of G0: %s", .help_arg = cm_mesh_format_list},
    {.name = "--design-table", .kind = CLI_STRING, .dest = &args.table,
     .label = "--design-table T.csv",
     .help = "CSV exported by the CAD program: header step,<p1>,<p2>,...,\n"
             "one row per STEP file (paths relative to T.csv) with its values"},
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &args.out,
     .label = "-o, --output DIR", .help = "output directory (created if missing)"},
    {.name = "--dJdX", .kind = CLI_STRING, .dest = &args.dJdX, .label = "--dJdX S",
     .help = "sensitivity dJ/dX of every node: a CSV node,gx,gy,gz (0-based\n"
             "nodes of M0; unlisted nodes 0) or a mesh of M0's nodes with the\n"
             "3-component point field dJdX; writes DIR/gradient.csv"},
    {.name = "--dJdXs", .kind = CLI_STRING, .dest = &args.dJdXs, .label = "--dJdXs S",
     .help = "the same on the boundary only (a surface sensitivity map):\n"
             "dJ/dp = sum over boundary nodes of S . dX/dp, values given at\n"
             "interior nodes are ignored"},
    {.name = "--surface", .kind = CLI_ENUM, .dest = &args.opt.method.surface,
     .names = surface_names, .values = surface_methods, .bad = "%.0sunknown surface method '%s'",
     .label = "--surface S", .help = "rbf (default: parameter-space warp) or project"},
    {.name = "--method", .kind = CLI_CUSTOM, .takes_value = 1, .parse = cli_parse_warp_method,
     .dest = &args.opt.method.warp.method, .label = "--method M",
     .help = "interior warp: %s (default rbf)", .help_arg = cm_warp_method_list},
    {CLI_SOLVER_OPTION, .dest = &args.opt.method.warp.solver},
    {CLI_RBF_TOL_OPTION, .dest = &args.opt.method.warp.tolerance},
    {.name = "--cad-unit", .kind = CLI_STRING, .dest = &args.unit, .label = "--cad-unit U",
     .help = "unit of the mesh coordinates (mm default; cm m in ft um ...)"},
    {.name = "--threads", .kind = CLI_THREADS, .dest = &args.threads, .label = "--threads N",
     .help = "threads (default: all)"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &args.verbose,
     .label = "--verbose", .help = "debug messages on stderr"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf(
        "Design velocities of the mesh M0 of G0 for every parameter p of a design table:\n"
        "dX/dp, how each node moves per unit of p when the mesh is morphed onto the edited\n"
        "CAD (cadmorph morph, one step). For each parameter the rows that change it alone\n"
        "relative to G0's row are used: rows on both sides give central differences, one\n"
        "side a forward or backward difference (said on stdout and in gradient.csv); rows\n"
        "that change several parameters are ignored with a note; a parameter no row changes\n"
        "alone is skipped with a warning. The boundary part is the difference of the surface\n"
        "morphs onto those rows (no volume morph is differenced), the interior part the\n"
        "warp's forward product of it with the factorisation a morph of M0 makes.\n\n"
        "Writes in DIR:\n"
        "  velocity.vtu   M0 with one point field dX_d<p> per parameter: dX/dp, in mesh unit\n"
        "                 per unit of p (e.g. mm/mm, mm/degree); open it in ParaView\n"
        "  velocity.csv   node,x,y,z (M0's coordinates), then dx_d<p>,dy_d<p>,dz_d<p> per\n"
        "                 parameter: the same velocities, one row per node (0-based)\n"
        "  gradient.csv   with --dJdX or --dJdXs: parameter,dJdp,difference,dp_plus,dp_minus,\n"
        "                 step_plus,step_minus,product: dJ/dp = sum over nodes of\n"
        "                 S . dX/dp, in the unit of J per unit of p (S in J per mesh unit);\n"
        "                 difference central|forward|backward, dp_* the rows' values minus\n"
        "                 G0's, product reverse (J^T S, one solve for all parameters) or\n"
        "                 boundary (--dJdXs: no warp product)\n\n"
        "options:\n");
    cli_print_options(stdout, options, 24);
    printf("\nexit codes: 0 done, 1 usage, 2 bad input (G0, M0, the table or S: one line\n"
           "naming the file and line), 4 internal error, 130 interrupted. Nothing is written\n"
           "to DIR unless every output is complete.\n");
    return CLI_EXIT_OK;
}

static int parse_args(int argc, char **argv, sens_args *a)
{
    static const char *cmd = "sensitivity";
    memset(&args, 0, sizeof args);
    cm_morph_options_init(&args.opt);
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    if (args.unit) args.opt.cad_unit = args.unit;
    *a = args;
    if (parsed >= 0) return parsed;
    if (!a->from || !a->mesh || !a->table || !a->out)
        return cli_usage(cmd, usage_line, "--from, --mesh, --design-table and -o are required");
    if (a->dJdX && a->dJdXs)
        return cli_usage(cmd, usage_line, "--dJdX and --dJdXs: give one sensitivity");
    if (cli_check_solver(cmd, usage_line, a->opt.method.warp.solver) >= 0) return CLI_EXIT_USAGE;
    return -1;
}

static void print_summary(const cm_design_table *t, const cm_design_velocities *v,
                          const double *g, const char *product, double seconds)
{
    printf("%zu parameters, %zu rows; %zu nodes; %zu surface morphs; %.2f s (read %.2f, surface "
           "%.2f, warp %.2f)\n",
           v->n_parameters, cm_design_table_n_rows(t), v->n_nodes, v->surface_morphs, seconds,
           v->t_read, v->t_surface, v->t_warp);
    printf("%-20s %-9s %12s %12s %14s%s\n", "parameter", "difference", "dp_plus", "dp_minus",
           "max|dX/dp|", g ? "           dJ/dp" : "");
    for (size_t j = 0; j < v->n_parameters; ++j) {
        const cm_design_difference *d = &v->diff[j];
        if (d->scheme == CM_DESIGN_NONE) {
            printf("%-20s %-9s (skipped: no row changes it alone)\n",
                   cm_design_table_parameter(t, j), "none");
            continue;
        }
        double vmax = 0;
        const double *x = v->v + j * v->n_nodes * 3;
        for (size_t k = 0; k < v->n_nodes; ++k)
            vmax = fmax(vmax, sqrt(x[3 * k] * x[3 * k] + x[3 * k + 1] * x[3 * k + 1] +
                                   x[3 * k + 2] * x[3 * k + 2]));
        printf("%-20s %-9s %12.6g %12.6g %14.6g", cm_design_table_parameter(t, j),
               cm_design_scheme_name(d->scheme), d->dp_plus, d->dp_minus, vmax);
        if (g) printf(" %16.9g", g[j]);
        printf("\n");
    }
    if (g) printf("gradient by %s products\n", product);
}

static int run(cm_context *ctx, const sens_args *a)
{
    double t0 = cm_wtime();
    cm_design_table *t = NULL;
    cm_cad_model *g0 = NULL;
    cm_mesh *mesh = NULL;
    cm_morpher *mp = NULL;
    cm_design_velocities *v = NULL;
    double *sens = NULL, *grad = NULL;
    char *paths[3] = {NULL, NULL, NULL};
    int written = 0;
    const char *product = a->dJdXs ? "boundary" : "reverse";
    cm_cad_read_options ro;
    cm_cad_read_options_init(&ro);
    if (a->unit) ro.unit = a->unit;
    size_t base = 0;
    cm_status s = cm_design_table_read(ctx, a->table, &t);
    if (s >= 0) s = cm_design_table_find(ctx, t, a->from, &base);
    if (s >= 0) s = cm_cad_read(ctx, a->from, &ro, &g0);
    if (s >= 0) s = cm_mesh_read(ctx, a->mesh, &mesh);
    if (s >= 0) {
        s = cm_morpher_create(ctx, g0, mesh, &a->opt, &mp);
        if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
        if (s < 0) s = cm_error_prefix(ctx, s, "%s, %s", a->from, a->mesh);
    }
    if (s >= 0) s = cm_design_velocity(ctx, mp, g0, t, base, &ro, 1, &v);
    const char *spath = a->dJdX ? a->dJdX : a->dJdXs;
    if (s >= 0 && spath) {
        sens = malloc(3 * (mesh->n_nodes ? mesh->n_nodes : 1) * sizeof *sens);
        grad = calloc(v->n_parameters ? v->n_parameters : 1, sizeof *grad);
        s = sens && grad ? cm_design_read_sensitivity(ctx, spath, mesh->n_nodes, sens, NULL)
                         : cm_error(ctx, CM_ERR_NOMEM, "out of memory");
        if (s >= 0) s = cm_design_gradient(ctx, mp, v, sens, a->dJdXs != NULL, grad, NULL);
    }
    /* every result is made: now the outputs, each through a temporary file; a failed one
     * removes those written before it */
    int rc = s < 0 ? cli_fail(ctx, "sensitivity", s) : cli_make_dir("sensitivity", a->out);
    static const char *const names[3] = {"velocity.vtu", "velocity.csv", "gradient.csv"};
    for (int k = 0; k < 3 && rc == 0; ++k) {
        size_t len = strlen(a->out) + 32;
        if (!(paths[k] = malloc(len))) {
            s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
            break;
        }
        snprintf(paths[k], len, "%s/%s", a->out, names[k]);
    }
    if (rc == 0 && s >= 0) {
        s = cm_design_write_velocity_mesh(ctx, t, v, mesh, paths[0]);
        if (s >= 0) ++written, s = cm_design_write_velocity_csv(ctx, t, v, mesh, paths[1]);
        if (s >= 0 && grad)
            ++written, s = cm_design_write_gradient_csv(ctx, t, v, grad, product, paths[2]);
        if (s >= 0 && grad) ++written;
        if (s < 0)
            for (int k = 0; k < written; ++k)
                unlink(paths[k]);
        rc = s < 0 ? cli_fail(ctx, "sensitivity", s) : CLI_EXIT_OK;
    } else if (rc == 0) {
        rc = cli_fail(ctx, "sensitivity", s);
    }
    if (rc == CLI_EXIT_OK) print_summary(t, v, grad, product, cm_wtime() - t0);
    for (int k = 0; k < 3; ++k)
        free(paths[k]);
    free(sens);
    free(grad);
    cm_design_velocities_destroy(&v);
    cm_morpher_destroy(&mp);
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&g0);
    cm_design_table_destroy(&t);
    return rc;
}

int cli_cmd_sensitivity(int argc, char **argv)
{
    sens_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    cm_context *ctx = cli_context_create("sensitivity", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    rc = run(ctx, &a);
    cm_context_destroy(&ctx);
    return rc;
}
