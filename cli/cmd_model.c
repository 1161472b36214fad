/* `cadmorph model MODEL T [OUT.step] [--signature] [--hex-mesh MESH [--scale S]]`: the built-in
 * models of sweep and demo (include/cadmorph/models.h) for the user: G(T) as STEP, its
 * topology signature, the structured O-grid hex mesh of G(0). */
#include "cli.h"
#include "options.h"

#include "cadmorph/models.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage =
    "cadmorph model bore|pipe|bracket T [OUT.step] [--signature] "
    "[--hex-mesh MESH [--scale S]] [-h|--help]";

static const char *hex_out;
static double scale;
static int signature;

static const cli_option options[] = {
    {.name = "--signature", .kind = CLI_FLAG, .dest = &signature, .label = "--signature",
     .help = "print the topology signature of G(T) (counts, then each face's\n"
             "surface type and each edge's curve type and vertices, in\n"
             "OpenCASCADE's order) and the solid's volume"},
    {.name = "--hex-mesh", .kind = CLI_STRING, .dest = &hex_out, .label = "--hex-mesh MESH",
     .help = "write the structured O-grid hex mesh of G(0) (bore, pipe; T must\n"
             "be 0), with the cell field scaled_jacobian, and print its counts\n"
             "and the quality line"},
    {.name = "--scale", .kind = CLI_DOUBLE, .dest = &scale, .lo = 0, .hi = 8, .open = 1,
     .bad = "%s: expected a number in (0, 8], got '%s'", .label = "--scale S",
     .help = "with --hex-mesh: the cells per direction x S (default 1: about\n"
             "34k nodes for the bore, 20k for the pipe)"},
    {.name = "--help", .alias = "-h", .kind = CLI_HELP, .label = "-h, --help", .help = "this text"},
    {0}};

static int help(void)
{
    printf("usage: %s\n\n"
           "The parametric models G(T), T in [0, 1], of 'cadmorph sweep' and 'cadmorph demo':\n"
           "  bore     4 x 4 x 2 block with a through-bore: radius 0.6 -> 1.0, axis tilted\n"
           "           0 -> 25 degrees\n"
           "  pipe     rod of radius 0.5 with one bend: bend radius 2 -> 1.5, angle 90 -> 135\n"
           "           degrees, outlet 2 -> 4\n"
           "  bracket  L profile extruded 3, a fillet and two holes: fillet 0.5 -> 1.0, hole\n"
           "           radius 0.4 -> 0.6, one hole moves 3 -> 3.5\n"
           "Every T gives the same topology in the same face, edge and vertex order, so any two\n"
           "of them correspond ('cadmorph info G0.step --compare G1.step') and a mesh of one can\n"
           "be morphed onto another. Lengths are in millimetre. OUT.step gets G(T) as STEP\n"
           "(AP214); MESH gets the hex mesh of G(0), in the format of its extension:\n"
           "%s.\n\n"
           "options:\n",
           usage, cm_mesh_format_list());
    cli_print_options(stdout, options, 18);
    printf("\nexample:\n"
           "  cadmorph model bore 0 bore_0.step && cadmorph model bore 1 bore_1.step\n"
           "  cadmorph mesh bore_0.step -o bore_0.vtu\n"
           "  cadmorph morph --from bore_0.step --to bore_1.step --mesh bore_0.vtu -o bore_1.vtu\n"
           "\nexit codes: 0 done, 1 usage, 2 bad input (an output that cannot be written),\n"
           "4 internal error.\n");
    return CLI_EXIT_OK;
}

/* The O-grid of G(0) with the cell counts of cm_hexmesh_bore / cm_hexmesh_pipe times scale:
 * scale 1 is the mesh of the sweeps' hex runs. Prints its counts and the quality line. */
static cm_status write_hex_mesh(cm_context *ctx, const char *model, double s, const char *path)
{
    cm_mesh *m = NULL;
    cm_status st;
    if (!strcmp(model, "bore")) {
        const int nt = 8 * (int)(12 * s + 0.5);
        st = cm_hexmesh_bore(ctx, nt < 8 ? 8 : nt, (int)(20 * s + 0.5), (int)(16 * s + 0.5), 1.05,
                             &m);
    } else {
        st = cm_hexmesh_pipe(ctx, (int)(8 * s + 0.5), (int)(6 * s + 0.5), 0.1 / s, &m);
    }
    double *sj = NULL;
    cm_quality_stats all = {0};
    if (st >= 0) st = cm_mesh_add_field(ctx, m, "scaled_jacobian", CM_FIELD_CELL, 1, &sj);
    if (st >= 0) st = cm_mesh_quality(ctx, m, sj);
    if (st >= 0) st = cm_quality_summarize(ctx, m, sj, NULL, &all);
    if (st >= 0) st = cm_mesh_write(ctx, m, path, NULL);
    if (st >= 0) {
        printf("nodes=%zu hexes=%zu\n", m->n_nodes, m->n_cells);
        cli_print_quality_line(stdout, &all);
    }
    cm_mesh_destroy(&m);
    return st;
}

int cli_cmd_model(int argc, char **argv)
{
    const char *cmd = "model";
    const char *pos[3] = {NULL, NULL, NULL};
    hex_out = NULL;
    scale = 1;
    signature = 0;
    cli_parser p = {.cmd = cmd, .usage = usage, .options = options, .help = help,
                    .unknown = "unknown option '%s'", .pos = pos, .max_pos = 3,
                    .extra = "unexpected argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    if (parsed >= 0) return parsed;
    const char *model = pos[0], *step_out = pos[2];
    if (!model) return cli_usage(cmd, usage, "MODEL is required (%s)", cm_model_list());
    if (!cm_model_known(model))
        return cli_usage(cmd, usage, "unknown model '%s' (%s)", model, cm_model_list());
    if (!pos[1]) return cli_usage(cmd, usage, "T is required (a number in [0, 1])");
    char *end = NULL;
    errno = 0;
    const double t = strtod(pos[1], &end);
    if (errno || end == pos[1] || *end || !(t >= 0 && t <= 1))
        return cli_usage(cmd, usage, "T must be a number in [0, 1], got '%s'", pos[1]);
    if (!step_out && !signature && !hex_out)
        return cli_usage(cmd, usage, "nothing to do: give OUT.step, --signature or --hex-mesh");
    if (hex_out) {
        if (!strcmp(model, "bracket"))
            return cli_usage(cmd, usage, "no hex mesh of the bracket (bore, pipe only)");
        if (t != 0) return cli_usage(cmd, usage, "--hex-mesh is the mesh of G(0): T must be 0");
        if (cli_check_mesh_output(cmd, usage, hex_out, NULL, 0)) return CLI_EXIT_USAGE;
    }
    if (step_out && hex_out && cli_same_file(step_out, hex_out))
        return cli_usage(cmd, usage, "OUT.step and --hex-mesh name the same file");

    cm_context *ctx = cli_context_create(cmd, 0, 0);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_status s = CM_OK;
    if (step_out) s = cm_model_write_step(ctx, model, t, step_out);
    if (s >= 0 && signature) {
        static char buf[1 << 16];
        double volume = 0;
        s = cm_model_signature(ctx, model, t, buf, sizeof buf, &volume);
        if (s >= 0) printf("%svolume %.12g\n", buf, volume);
    }
    if (s >= 0 && hex_out) s = write_hex_mesh(ctx, model, scale, hex_out);
    const int rc = s < 0 ? cli_fail(ctx, cmd, s) : CLI_EXIT_OK;
    cm_context_destroy(&ctx);
    return rc;
}
