/* `cadmorph ffd`: moves every node of a mesh by a control-point FFD whose lattice comes from
 * a PyGeM parameter file (.prm), writes the mesh and reports how many nodes the lattice held
 * and the quality of the volume cells. */
#include "cli.h"
#include "options.h"

#include "cadmorph/deform.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph ffd --mesh M --lattice L.prm [--displacements C.csv] [--basis bspline|bernstein] "
    "-o M1 [--threads N] [--verbose]";

typedef struct ffd_args {
    const char *mesh, *lattice, *csv, *out;
    int basis; /* cm_ffd_basis */
    int threads, verbose;
} ffd_args;

static ffd_args args;

static int print_help(void);

static const char *const basis_names[] = {"bernstein", "bspline", NULL};
static const int basis_values[] = {CM_FFD_BERNSTEIN, CM_FFD_BSPLINE};

static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "--mesh", .kind = CLI_STRING, .dest = &args.mesh, .label = "--mesh M",
     .help = "input mesh (any cells: volume or surface)"},
    {.name = "--lattice", .kind = CLI_STRING, .dest = &args.lattice, .label = "--lattice L.prm",
     .help = "the lattice and, unless --displacements is given, its weights"},
    {.name = "--displacements", .kind = CLI_STRING, .dest = &args.csv,
     .label = "--displacements C",
     .help = "control displacements instead of the .prm weights: CSV with\n"
             "header i,j,k,dx,dy,dz, physical units in the world frame (not\n"
             "normalised); points not listed stay"},
    {.name = "--basis", .kind = CLI_ENUM, .dest = &args.basis, .names = basis_names,
     .values = basis_values, .bad = "%.0sunknown basis '%s' (bspline|bernstein)",
     .label = "--basis B",
     .help = "bernstein (default for .prm: PyGeM's Bernstein polynomials of\n"
             "degree n-1, global support) or bspline (uniform cubic B-splines\n"
             "on the box as their valid domain, the paper's; n >= 4 per axis;\n"
             "the control points then reach one spacing outside the box)"},
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &args.out,
     .label = "-o, --output M1", .help = "output mesh (must not be an input)"},
    {.name = "--threads", .kind = CLI_THREADS, .dest = &args.threads, .label = "--threads N",
     .help = "threads (default: all)"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &args.verbose,
     .label = "--verbose", .help = "debug messages on stderr"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf(
        "Free-form deformation: every node x of the mesh M inside the lattice moves by\n"
        "d(x) = sum_p dc_p N_p(u(x)); nodes outside it do not move (d = 0 exactly, counted).\n"
        "Writes M1 (%s)\n"
        "with per-node 'displacement' (and per-cell\n"
        "'scaled_jacobian'), prints the node counts, then the quality summary line.\n\n"
        "The lattice: a PyGeM parameter file (.prm) - [Box info] n control points, box length,\n"
        "box origin, rotation angle (degrees) per axis; [Parameters weights] lines 'i j k mu'.\n"
        "PyGeM's conventions, kept here:\n"
        "  - the box is origin + R diag(length) [0,1]^3 with R = Rx Ry Rz (right-handed, applied\n"
        "    to column vectors; PyGeM's angles2matrix(z, y, x)); the origin is control point\n"
        "    [0][0][0] and the centre of rotation;\n"
        "  - mu is normalised by the box lengths in the box's frame: the physical control\n"
        "    displacement is dc = R diag(length) mu;\n"
        "  - control point (i, j, k) is flat index (i ny + j) nz + k, as PyGeM's arrays.\n"
        "Differences from PyGeM:\n"
        "  - points within 1e-12 (in box units) of a face are inside and move; PyGeM's strict\n"
        "    test drops some points on the box faces (its bug #272);\n"
        "  - displacement form: zero weights leave every node bit for bit where it was (PyGeM's\n"
        "    two least-squares affine fits move them by ~1e-15);\n"
        "  - a missing .prm file is an error (PyGeM writes a default one there).\n\n"
        "options:\n",
        cm_mesh_format_list());
    cli_print_options(stdout, options, 21);
    printf("\nexit codes: 0 done, 1 usage, 2 bad input (malformed .prm or CSV, a number that is not\n"
           "finite, a box length of 0, a displacement - weight times box length - or a box beyond\n"
           "1e150, a lattice that is not invertible), 3 a result that is not finite (not written).\n");
    return CLI_EXIT_OK;
}

/* Returns -1 to go on, else the exit code. */
static int parse_args(int argc, char **argv, ffd_args *a)
{
    static const char *cmd = "ffd";
    memset(&args, 0, sizeof args);
    args.basis = CM_FFD_BERNSTEIN;
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    *a = args;
    if (parsed >= 0) return parsed;
    if (!a->mesh) return cli_usage(cmd, usage_line, "--mesh is required");
    if (!a->lattice) return cli_usage(cmd, usage_line, "--lattice is required");
    if (!a->out) return cli_usage(cmd, usage_line, "-o is required");
    const char *inputs[] = {a->mesh, a->lattice, a->csv};
    return cli_check_mesh_output(cmd, usage_line, a->out, inputs, 3) ? CLI_EXIT_USAGE : -1;
}

/* The lattice and control displacements of the .prm (and the CSV). */
static cm_status load_lattice(cm_context *ctx, const ffd_args *a, cm_ffd **ffd, double **dc)
{
    cm_ffd_prm prm;
    cm_status s = cm_ffd_prm_read(ctx, a->lattice, &prm);
    if (s < 0) return s;
    size_t nc = (size_t)prm.n[0] * prm.n[1] * prm.n[2];
    *dc = malloc(nc * 3 * sizeof **dc);
    if (!*dc) s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    cm_ffd_desc desc;
    if (s >= 0) {
        cm_ffd_prm_desc(&prm, a->basis, &desc, *dc);
        if (a->csv) s = cm_ffd_read_displacements(ctx, a->csv, prm.n, *dc, NULL);
    }
    if (s >= 0) {
        s = cm_ffd_create(ctx, &desc, ffd);
        /* the lattice came from the file: a lattice the library refuses is bad input */
        if (s == CM_ERR_ARGUMENT) s = CM_ERR_FORMAT;
        if (s < 0) s = cm_error_prefix(ctx, s, "%s", a->lattice);
    }
    cm_ffd_prm_free(&prm);
    return s;
}

int cli_cmd_ffd(int argc, char **argv)
{
    ffd_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    cm_context *ctx = cli_context_create("ffd", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_mesh *mesh = NULL;
    cm_ffd *ffd = NULL;
    double *dc = NULL, *disp = NULL, *sj = NULL;
    cm_ffd_stats st;
    memset(&st, 0, sizeof st);
    cm_status s = load_lattice(ctx, &a, &ffd, &dc);
    if (s >= 0) s = cm_mesh_read(ctx, a.mesh, &mesh);
    if (s >= 0 && !(disp = malloc(3 * (mesh->n_nodes ? mesh->n_nodes : 1) * sizeof *disp)))
        s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    if (s >= 0) {
        double t0 = cm_wtime();
        s = cm_ffd_deform(ctx, ffd, dc, mesh->n_nodes, mesh->xyz, disp, &st);
        if (s == CM_WARNING) cm_log(ctx, CM_LOG_WARNING, "%s", cm_context_message(ctx));
        cm_log(ctx, CM_LOG_DEBUG, "ffd: %zu nodes in %.3f s", mesh->n_nodes, cm_wtime() - t0);
    }
    if (s >= 0)
        s = cm_mesh_apply_displacement(ctx, mesh, disp, CM_DISPLACEMENT_MOVE | CM_DISPLACEMENT_QUALITY,
                                       &sj);
    if (s >= 0) {
        s = cm_mesh_write(ctx, mesh, a.out, NULL);
        /* a non-finite result: what made it */
        if (s == CM_ERR_REJECTED) s = cm_error_prefix(ctx, s, "the motion of %s", a.csv ? a.csv : a.lattice);
    }
    if (s >= 0) {
        printf("ffd: %zu nodes: %zu inside the lattice, %zu outside (not moved), %zu not "
               "inverted by Newton\n",
               mesh->n_nodes, st.inside, st.outside, st.failed);
        s = cli_print_quality(ctx, mesh, sj, stdout, NULL);
    }
    rc = s < 0 ? cli_fail(ctx, "ffd", s) : CLI_EXIT_OK;
    free(dc), free(disp);
    cm_ffd_destroy(&ffd);
    cm_mesh_destroy(&mesh);
    cm_context_destroy(&ctx);
    return rc;
}
