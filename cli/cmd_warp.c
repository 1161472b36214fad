/* `cadmorph warp`: moves the interior nodes of a volume mesh by the RBF warp of boundary
 * displacements given in a CSV table, writes the moved mesh and reports its quality. */
#include "cli.h"
#include "options.h"
#include "patch_motion.h"

#include "cadmorph/warp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph warp --mesh M0 --displacements D.csv -o M1 [--method M] "
    "[--solver S] [--rbf-tol T] [--lattice N [--clamp E]] [--samples K --cubature N --cover S --stretch GS "
    "--bend GB --blend B] [--optimize] [--slide P,...] [--fixed-patches P,...] [--no-slide] "
    "[--threads N] [--verbose]";

typedef struct warp_args {
    const char *mesh, *csv, *out;
    cm_warp_method method;
    int threads, verbose, optimize, lattice, solver;
    double tolerance;
    double clamp;
    cm_mls_options mls;
    cli_patch_motion patches;
} warp_args;

static warp_args args;

static int print_help(void);



static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "--mesh", .kind = CLI_STRING, .dest = &args.mesh, .label = "--mesh M0",
     .help = "input volume mesh"},
    {.name = "--displacements", .kind = CLI_STRING, .dest = &args.csv,
     .label = "--displacements D", .help = "displacement table (CSV)"},
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &args.out,
     .label = "-o, --output M1", .help = "output mesh (must not be an input)"},
    {.name = "--method", .kind = CLI_CUSTOM, .takes_value = 1, .parse = cli_parse_warp_method,
     .dest = &args.method, .label = "--method M",
     .help = "interior warp: %s (default rbf: r^3)", .help_arg = cm_warp_method_list},
    {.name = "--kernel", .kind = CLI_ENUM, .dest = &args.method, .names = cli_kernel_names,
     .values = cli_kernel_methods, .bad = "%.0sunknown kernel '%s'", .label = "--kernel K",
     .help = "triharmonic (= --method rbf) or biharmonic (= rbf-biharmonic)"},
    {.name = "--optimize", .kind = CLI_FLAG, .dest = &args.optimize, .label = "--optimize",
     .help = "then optimise the other nodes (untangle, raise the worst cells;\n"
             "boundary and listed nodes stay where D.csv sends them)"},
    {CLI_SOLVER_OPTION, .dest = &args.solver},
    {CLI_RBF_TOL_OPTION, .dest = &args.tolerance},
    {.name = "--lattice", .kind = CLI_INT, .dest = &args.lattice, .lo = 4, .hi = 200,
     .bad = "%s: expected 4..200 control points per axis, got '%s'", .label = "--lattice N",
     .help = "dmffd: control points per axis of the B-spline lattice on the\n"
             "mesh's bounding box (paper: 5 10 15 25; default 10); DM-FFD\n"
             "is least squares: the boundary keeps its motion exactly, the\n"
             "interior follows a space map that misses it (--verbose)"},
    {.name = "--clamp", .kind = CLI_DOUBLE, .dest = &args.clamp, .lo = 0, .hi = 1, .open = 3,
     .bad = "%s: expected a number in (0, 1), got '%s'", .label = "--clamp E",
     .help = "dmffd: singular values <= E x the largest are dropped\n"
             "(default 1e-10; 1e-2 keeps coarse lattices usable)"},
    CLI_MLS_OPTIONS(args.mls),
    CLI_PATCH_MOTION_OPTIONS(args.patches),
    {.name = "--threads", .kind = CLI_THREADS, .dest = &args.threads, .label = "--threads N",
     .help = "threads for evaluation and quality (default: all)"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &args.verbose,
     .label = "--verbose", .help = "debug messages on stderr"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf(
        "Moves the nodes of the volume mesh M0 by the displacements of D.csv and carries the\n"
        "boundary motion into the interior with an RBF space warp (phi = r^3 by default, plus a\n"
        "linear polynomial), one per connected component of volume cells. Writes M1 (format by\n"
        "its name: %s)\n"
        "with per-node 'displacement' and per-cell\n"
        "'scaled_jacobian', then prints the quality summary line.\n\n"
        "D.csv: header node,dx,dy,dz; node is the 0-based index of the node in M0's file order.\n"
        "  Boundary nodes that are not listed stay where they are, or slide (below);\n"
        "  listed interior nodes are pinned to their displacement.\n\n"
        "%s\n"
        "options:\n",
        cm_mesh_format_list(), CLI_PATCH_MOTION_DEFAULTS);
    cli_print_options(stdout, options, 21);
    printf("\nexit codes: 0 done, 1 usage, 2 bad input (malformed file, degenerate boundary).\n");
    return CLI_EXIT_OK;
}

/* Returns -1 to go on, else the exit code. */
static int parse_args(int argc, char **argv, warp_args *a)
{
    static const char *cmd = "warp";
    memset(&args, 0, sizeof args);
    args.method = CM_WARP_RBF;
    cm_mls_options_init(&args.mls);
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    *a = args;
    if (parsed >= 0) return parsed;
    if (!a->mesh) return cli_usage(cmd, usage_line, "--mesh is required");
    if (!a->csv) return cli_usage(cmd, usage_line, "--displacements is required");
    if (!a->out) return cli_usage(cmd, usage_line, "-o is required");
    if (cli_check_solver(cmd, usage_line, a->solver) >= 0) return CLI_EXIT_USAGE;
    const char *inputs[] = {a->mesh, a->csv};
    return cli_check_mesh_output(cmd, usage_line, a->out, inputs, 2) ? CLI_EXIT_USAGE : -1;
}

/* The boundary motion of the mesh with the listed nodes prescribed (a warning is shown and
 * the warp goes on). */
static cm_status warp_motion_create(cm_context *ctx, const cm_mesh *mesh,
                                    const unsigned char *listed, const cli_patch_motion *pm,
                                    cm_boundary_motion **motion)
{
    cm_mesh_boundary *b = NULL;
    cm_motion_options mo;
    cli_patch_motion_options(pm, &mo);
    cm_status s = cm_mesh_boundary_create(ctx, mesh, &b);
    if (s >= 0) s = cm_boundary_motion_create(ctx, mesh, b, listed, &mo, motion);
    if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
    cm_mesh_boundary_destroy(&b);
    if (s >= 0 && *motion) {
        double axis[6], angle;
        cm_motion_reduction r = cm_boundary_motion_reduction(*motion, axis, &angle);
        cm_log(ctx, CM_LOG_DEBUG,
               "warp: boundary motion: %zu fixed, %zu prescribed, %zu sliding on planes, %zu on "
               "lines, %zu on surfaces%s",
               cm_boundary_motion_count(*motion, CM_MOTION_FIXED),
               cm_boundary_motion_count(*motion, CM_MOTION_PRESCRIBED),
               cm_boundary_motion_count(*motion, CM_MOTION_SLIDE_PLANE),
               cm_boundary_motion_count(*motion, CM_MOTION_SLIDE_LINE),
               cm_boundary_motion_count(*motion, CM_MOTION_SLIDE_SURFACE),
               r == CM_MOTION_2D ? "; a 2-D mesh" : r == CM_MOTION_AXISYMMETRIC ? "; a wedge" : "");
    }
    return s < 0 ? s : CM_OK;
}

int cli_cmd_warp(int argc, char **argv)
{
    warp_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    cm_context *ctx = cli_context_create("warp", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_mesh *mesh = NULL;
    double *disp = NULL;
    unsigned char *listed = NULL;
    double *sj = NULL;
    cm_status s = cm_mesh_read(ctx, a.mesh, &mesh);
    if (s >= 0) {
        disp = malloc((mesh->n_nodes ? mesh->n_nodes : 1) * 3 * sizeof *disp);
        listed = malloc(mesh->n_nodes ? mesh->n_nodes : 1);
        s = disp && listed ? cm_warp_read_displacements(ctx, a.csv, mesh->n_nodes, disp, listed)
                           : cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    }
    cm_warp_options opt;
    cm_warp_options_init(&opt);
    opt.method = a.method;
    opt.lattice = a.lattice;
    opt.solver = (cm_rbf_solver)a.solver;
    opt.tolerance = a.tolerance;
    opt.clamp = a.clamp;
    opt.mls = a.mls;
    cm_warp_mesh_stats st;
    cm_boundary_motion *motion = NULL;
    if (s >= 0) s = warp_motion_create(ctx, mesh, listed, &a.patches, &motion);
    if (s >= 0) {
        cm_optimize_options oo;
        cm_optimize_options_init(&oo);
        s = cm_warp_mesh(ctx, mesh, disp, listed, motion, &opt, a.optimize ? &oo : NULL, &sj, &st);
        if (s < 0) s = cm_error_prefix(ctx, s, "%s", a.mesh);
    }
    cm_boundary_motion_destroy(&motion);
    if (s >= 0)
        cm_log(ctx, CM_LOG_DEBUG,
               "warp: %s, %zu nodes, %zu boundary nodes, %zu components: create %.3f s, "
               "apply %.3f s, residual at the constrained nodes %.3g",
               cm_warp_method_name(a.method), mesh->n_nodes, st.boundary_nodes, st.components,
               st.t_create, st.t_apply, st.residual);
    /* under mpirun (--solver petsc) every rank has the result; rank 0 writes it */
    const int writer = cli_output_rank();
    if (s >= 0 && writer) s = cm_mesh_write(ctx, mesh, a.out, NULL);
    /* the report only once the mesh is written: its last line is what scripts parse */
    if (s >= 0 && writer) s = cli_print_quality(ctx, mesh, sj, stdout, NULL);
    if (s >= 0 && writer) cli_warn_inverted("warp", mesh, sj);
    rc = s < 0 ? cli_fail(ctx, "warp", s) : CLI_EXIT_OK;
    free(disp);
    free(listed);
    cm_mesh_destroy(&mesh);
    cm_context_destroy(&ctx);
    return rc;
}
