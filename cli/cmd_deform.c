/* `cadmorph deform`: handle-based deformation of a surface or volume mesh (the handle
 * metaphor [CMLS §3]): handle nodes H move as given, fixed nodes F stay, the rest follows a
 * space deformation of deform.h's table (triharmonic RBF, constrained MLS, shell, DM-FFD). */
#include "cli.h"
#include "deform_constraints.h"
#include "deform_motion.h"

#include "cadmorph/deform.h"

#include "cadmorph/warp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph deform --mesh M --handles H.csv [--fixed F.csv | --fix-unlisted-boundary] "
    "[--method rbf|mls|dmffd|shell] -o M' [--stretch GS] [--bend GB] [--fix GF] [--samples K] "
    "[--cubature N] [--cover S] [--blend B] [--graded G] [--lattice N] [--clamp E] [--approximate-constraints] "
    "[--constraint TYPE:SET ...] [--slide P,...] [--fixed-patches P,...] [--no-slide] "
    "[--threads N] [--verbose]";

typedef struct deform_args {
    const char *mesh, *handles, *fixed, *out;
    int method, fix_boundary, exact, approximate, threads, verbose, lattice;
    double clamp;
    cm_mls_options mls;   /* stretch, bend, fix also weigh the shell */
    cli_constraints cons; /* --constraint and its options (deform_constraints.c) */
    cli_patch_motion patches; /* --slide, --fixed-patches, --no-slide (deform_motion.c) */
} deform_args;

static deform_args args;
static int print_help(void);

/* --method's names and values: deform.h's table, filled in by parse_args */
static const char *method_names[CM_DEFORM_N_METHODS + 1];
static int method_values[CM_DEFORM_N_METHODS];

static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "--mesh", .kind = CLI_STRING, .dest = &args.mesh, .label = "--mesh M",
     .help = "input mesh"},
    {.name = "--handles", .kind = CLI_STRING, .dest = &args.handles, .label = "--handles H.csv",
     .help = "the handle region and its displacement"},
    {.name = "--fixed", .kind = CLI_STRING, .dest = &args.fixed, .label = "--fixed F.csv",
     .help = "the fixed region"},
    {.name = "--fix-unlisted-boundary", .kind = CLI_FLAG, .dest = &args.fix_boundary,
     .label = "--fix-unlisted-boundary",
     .help = "fix every boundary node not in H.csv (volume: the\n"
             "boundary surface; surface: its border edges)"},
    {.name = "--method", .kind = CLI_ENUM, .dest = &args.method, .names = method_names,
     .values = method_values, .bad = "%.0sunknown method '%s' (rbf|mls|dmffd|shell)",
     .label = "--method M",
     .help = "rbf (triharmonic, exact at H and F), mls (constrained\n"
             "MLS, default; exact at H and F unless\n"
             "--approximate-constraints), dmffd (DM-FFD on a cubic\n"
             "B-spline lattice enclosing M, least squares: H and F keep\n"
             "their motion, the residual is the lattice's miss) or\n"
             "shell (surfaces: the mesh-based shell of the paper's eq. 10,\n"
             "the ground truth; weights per unit area, not normalised)"},
    CLI_MLS_OPTIONS(args.mls),
    {.name = "--fix", .kind = CLI_DOUBLE, .dest = &args.mls.fix, .lo = 0, .hi = NAN, .open = 1,
     .bad = "%s: '%s' is not a number > 0", .label = "--fix GF",
     .help = "mls / shell: constraint weight gamma_f (default 1000);\n"
             "--stretch and --bend weigh the shell's energies too"},
    {.name = "--approximate-constraints", .kind = CLI_FLAG, .dest = &args.approximate,
     .label = "--approximate-constraints",
     .help = "mls: H and F nodes get the field's value (the paper's\n"
             "weighted fit: they miss their motion by the residual)\n"
             "instead of their prescribed one (the default: exact, the\n"
             "field's miss carried into the free nodes around them)"},
    /* exactness is the default: kept so that scripts written before still run */
    {.name = "--exact-constraints", .kind = CLI_FLAG, .dest = &args.exact,
     .label = "--exact-constraints", .help = "mls: the default (accepted, does nothing)"},
    {.name = "--lattice", .kind = CLI_INT, .dest = &args.lattice, .lo = 4, .hi = 200,
     .bad = "%s: '%s' is not an integer in 4..200", .label = "--lattice N",
     .help = "dmffd: control points per axis (4..200, default 10)"},
    {.name = "--clamp", .kind = CLI_DOUBLE, .dest = &args.clamp, .lo = 0, .hi = 1, .open = 3,
     .bad = "%s: expected a number in (0, 1), got '%s'", .label = "--clamp E",
     .help = "dmffd: singular values <= E x the largest dropped\n(default 1e-10)"},
    CLI_CONSTRAINT_OPTIONS(args.cons),
    CLI_PATCH_MOTION_OPTIONS(args.patches),
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &args.out,
     .label = "-o, --output M'", .help = "output mesh (must not be an input)"},
    {.name = "--threads", .kind = CLI_THREADS, .dest = &args.threads, .label = "--threads N",
     .help = "threads (default: all)"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &args.verbose,
     .label = "--verbose", .help = "timings and debug messages on stderr"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf(
        "Deforms the mesh M (a surface mesh of triangles/quads, or a volume mesh;\n"
        "%s;\n"
        ".obj .off .stl are surfaces) by moving the handle nodes of H.csv, keeping the fixed nodes in place and\n"
        "letting every other node follow a space deformation. Writes M' with a per-node\n"
        "'displacement' field; surfaces also get 'mean_curvature' (H = |lap x|/2, cotangent\n"
        "Laplacian) and a mean-curvature summary, volume meshes the quality summary line.\n\n"
        "H.csv: header node,dx,dy,dz (0-based node index in M's file order).\n"
        "F.csv: header node, then one node index per line.\n\n"
        "--fix-unlisted-boundary of a volume mesh: %s\n"
        "options:\n",
        cm_mesh_format_list(), CLI_PATCH_MOTION_DEFAULTS);
    cli_print_options(stdout, options, 26);
    printf("\nexit codes: 0 done, 1 usage, 2 bad input.\n");
    return CLI_EXIT_OK;
}

/* Returns -1 to go on, else the exit code. */
static int parse_args(int argc, char **argv, deform_args *a)
{
    static const char *cmd = "deform";
    memset(&args, 0, sizeof args);
    for (int m = 0; m < CM_DEFORM_N_METHODS; ++m)
        method_names[m] = cm_deform_method_name(m), method_values[m] = m;
    args.method = CM_DEFORM_MLS, args.lattice = 10;
    cm_mls_options_init(&args.mls);
    cli_constraints_init(&args.cons);
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    *a = args;
    if (parsed >= 0) return parsed;
    if (a->approximate) a->mls.keep_constrained = 0; /* else the library's default: exact */
    if (a->approximate && a->exact)
        return cli_usage(cmd, usage_line,
                         "--approximate-constraints and --exact-constraints exclude each other");
    if (!a->mesh) return cli_usage(cmd, usage_line, "--mesh is required");
    if (!a->handles) return cli_usage(cmd, usage_line, "--handles is required");
    if (!a->out) return cli_usage(cmd, usage_line, "-o is required");
    if (a->fixed && a->fix_boundary)
        return cli_usage(cmd, usage_line, "--fixed and --fix-unlisted-boundary exclude each other");
    if ((a->method == CM_DEFORM_MLS || a->method == CM_DEFORM_SHELL) && a->mls.stretch + a->mls.bend <= 0)
        return cli_usage(cmd, usage_line, "--stretch + --bend must be > 0");
    if (cli_constraints_any(&a->cons) && a->method != CM_DEFORM_MLS)
        return cli_usage(cmd, usage_line, "--constraint needs --method mls");
    const char *inputs[] = {a->mesh, a->handles, a->fixed, a->cons.cad};
    return cli_check_mesh_output(cmd, usage_line, a->out, inputs, 4) ? CLI_EXIT_USAGE : -1;
}

/* The mesh moved by the method; a non-finite result (refused by cm_mesh_write) names the
 * method that made it. */
static cm_status write_result(cm_context *ctx, const cm_mesh *mesh, const deform_args *a)
{
    cm_status s = cm_mesh_write(ctx, mesh, a->out, NULL);
    if (s == CM_ERR_REJECTED)
        s = cm_error_prefix(ctx, s, "the %s deformation of %s", cm_deform_method_name(a->method), a->handles);
    return s;
}

int cli_cmd_deform(int argc, char **argv)
{
    deform_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    cm_context *ctx = cli_context_create("deform", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_mesh *mesh = NULL;
    cm_mesh_boundary *b = NULL;
    double *disp = NULL, *H = NULL, *field = NULL, *sj = NULL;
    unsigned char *con = NULL, *fixed = NULL, *border = NULL;
    cm_status s = cm_mesh_read(ctx, a.mesh, &mesh);
    size_t n = s >= 0 ? mesh->n_nodes : 0;
    int volume = s >= 0 && cm_mesh_count_dim(mesh, 3) > 0;
    if (s >= 0 && !volume && cm_mesh_count_dim(mesh, 2) == 0)
        s = cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: neither faces nor volume cells", a.mesh);
    if (s >= 0) {
        disp = malloc((n ? n : 1) * 3 * sizeof *disp);
        con = calloc(n ? n : 1, 1);
        fixed = calloc(n ? n : 1, 1);
        border = calloc(n ? n : 1, 1);
        H = malloc((n ? n : 1) * sizeof *H);
        if (!disp || !con || !fixed || !border || !H) s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    }
    if (s >= 0) s = cm_warp_read_displacements(ctx, a.handles, n, disp, con);
    if (s >= 0 && a.fixed) s = cm_mesh_read_node_list(ctx, a.fixed, n, fixed);
    if (s >= 0 && !volume) s = cm_mls_mean_curvature(ctx, mesh, H, border);
    if (s >= 0 && volume && a.fix_boundary) {
        s = cm_mesh_boundary_create(ctx, mesh, &b);
        if (s >= 0) {
            s = CM_OK;
            for (size_t i = 0; i < b->n_nodes; ++i)
                border[b->nodes[i]] = 1;
        }
    }
    cli_deform_motion dm = {0}; /* sliding patches are not fixed (deform_motion.c) */
    if (s >= 0 && volume && a.fix_boundary)
        s = cli_deform_motion_begin(ctx, mesh, b, &a.patches, disp, con, border, &dm);
    size_t nh = 0, nf = 0;
    for (size_t i = 0; s >= 0 && i < n; ++i) {
        if (con[i] && fixed[i]) {
            s = cm_error(ctx, CM_ERR_MISMATCH, "node %zu is both a handle and fixed", i);
            break;
        }
        if (a.fix_boundary && border[i] && !con[i]) fixed[i] = 1;
        nh += con[i] != 0;
        nf += fixed[i] != 0;
        if (fixed[i]) con[i] = 1, disp[3 * i] = disp[3 * i + 1] = disp[3 * i + 2] = 0;
        else if (con[i]) con[i] = 2; /* the MLS weighs handle and fixed groups apart */
    }
    /* every listed node is a handle (one listed as fixed too is refused above): none is a
     * table without rows, bad input like any other malformed file */
    if (s >= 0 && nh == 0) s = cm_error(ctx, CM_ERR_FORMAT, "%s: no rows after the header", a.handles);
    double residual = 0, t0 = cm_wtime();
    if (s >= 0 && a.method == CM_DEFORM_SHELL && volume)
        s = cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: --method shell deforms surface meshes only", a.mesh);
    cm_deform *def = NULL;
    cm_deform_options dopt;
    cm_deform_options_init(&dopt);
    dopt.method = (cm_deform_method)a.method;
    dopt.lattice = a.lattice, dopt.clamp = a.clamp, dopt.mls = a.mls;
    cm_shape_set sets[CLI_MAX_CONSTRAINTS];
    const int shaped = s >= 0 && a.method == CM_DEFORM_MLS; /* the sets to resolve and free */
    if (shaped) s = cli_constraints_resolve(ctx, mesh, &a.cons, sets);
    if (s >= 0) s = cm_deform_create(ctx, &dopt, n, mesh->xyz, con, mesh, &def);
    /* no free node: nothing was built (cm_deform_stats.prescribed_only), and shape
     * constraints have no node to move */
    if (s >= 0 && cli_constraints_any(&a.cons) && cm_deform_get_mls(def))
        s = cli_constraints_run(ctx, cm_deform_get_mls(def), mesh, &a.cons, sets, disp, &residual);
    else if (s >= 0) {
        s = cm_deform_apply(ctx, def, disp, &residual);
        /* the shell refuses a degenerate face of the surface it was given: say which file */
        if (s == CM_ERR_FORMAT && a.method == CM_DEFORM_SHELL) s = cm_error_prefix(ctx, s, "%s", a.mesh);
    }
    if (shaped) cli_constraints_free(&a.cons, sets);
    cm_deform_stats st;
    cm_deform_get_stats(def, &st);
    if (s >= 0 && st.prescribed_only)
        printf("deform: no free node: every node is a handle or fixed, so the result is the "
               "prescribed motion (no %s built or solved)\n",
               a.method == CM_DEFORM_MLS ? "MLS" : a.method == CM_DEFORM_DMFFD ? "lattice" : "RBF");
    if (s >= 0 && a.method == CM_DEFORM_MLS && !st.prescribed_only)
        cm_log(ctx, CM_LOG_DEBUG,
               "deform mls: %zu samples (%zu surface), %zu cubature points, %zu constrained; "
               "sample %.3f s, basis %.3f s, factor %.3f s (%zu entries), apply %.3f s; CPU s "
               "%.3f, %.3f, %.3f, %.3f",
               st.mls.samples, st.mls.surface_samples, st.mls.cubature, st.mls.constrained,
               st.mls.t_sample, st.mls.t_basis, st.mls.t_factor, st.mls.factor_nonzeros,
               st.mls.t_apply, st.mls.c_sample, st.mls.c_basis, st.mls.c_factor, st.mls.c_apply);
    if (s >= 0 && a.method == CM_DEFORM_DMFFD && !st.prescribed_only)
        cm_log(ctx, CM_LOG_DEBUG,
               "deform dmffd-%d: %zu handles, %zu of %zu control points active, rank %zu (%zu "
               "clamped)",
               st.lattice, st.dmffd.handles, st.dmffd.active, st.control_points, st.dmffd.rank,
               st.dmffd.clamped);
    cm_deform_destroy(&def);
    if (s >= 0) s = cli_deform_motion_end(ctx, mesh, &dm, disp);
    cli_deform_motion_free(&dm);
    double t1 = cm_wtime();
    /* volume meshes get the quality; surfaces their mean curvature, below */
    if (s >= 0)
        s = cm_mesh_apply_displacement(ctx, mesh, disp,
                                       CM_DISPLACEMENT_MOVE | (volume ? CM_DISPLACEMENT_QUALITY : 0),
                                       &sj);
    double h_before[3] = {0, 0, 0}; /* min, mean, max over interior vertices */
    if (s >= 0 && !volume) {
        for (int pass = 0; pass < 2 && s >= 0; ++pass) {
            if (pass == 1) s = cm_mls_mean_curvature(ctx, mesh, H, border);
            double mn = INFINITY, mx = 0, sum = 0;
            size_t cnt = 0;
            for (size_t i = 0; s >= 0 && i < n; ++i)
                if (!border[i]) mn = fmin(mn, H[i]), mx = fmax(mx, H[i]), sum += H[i], ++cnt;
            if (pass == 0) {
                h_before[0] = cnt ? mn : 0, h_before[1] = cnt ? sum / (double)cnt : 0, h_before[2] = mx;
                /* H of the input was computed before the move */
                continue;
            }
            if (s >= 0) s = cm_mesh_add_field(ctx, mesh, "mean_curvature", CM_FIELD_NODE, 1, &field);
            if (s >= 0) memcpy(field, H, n * sizeof *field);
            if (s >= 0) s = write_result(ctx, mesh, &a);
            if (s >= 0) {
                printf("deform: %s, %zu handle nodes, %zu fixed, %zu free, %.3f s, residual %.6g\n",
                       cm_deform_method_name(a.method), nh, nf, n - nh - nf, t1 - t0, residual);
                printf("mean_curvature (interior vertices): before min=%.6g mean=%.6g max=%.6g; "
                       "after min=%.6g mean=%.6g max=%.6g\n",
                       h_before[0], h_before[1], h_before[2], cnt ? mn : 0,
                       cnt ? sum / (double)cnt : 0, mx);
            }
        }
    }
    if (s >= 0 && volume) {
        s = write_result(ctx, mesh, &a);
        if (s >= 0) {
            printf("deform: %s, %zu handle nodes, %zu fixed, %zu free, %.3f s, residual %.6g\n",
                   cm_deform_method_name(a.method), nh, nf, n - nh - nf, t1 - t0, residual);
            s = cli_print_quality(ctx, mesh, sj, stdout, NULL);
        }
    }
    rc = s < 0 ? cli_fail(ctx, "deform", s) : CLI_EXIT_OK;
    free(disp), free(con), free(fixed), free(border), free(H);
    cm_mesh_boundary_destroy(&b);
    cm_mesh_destroy(&mesh);
    cm_context_destroy(&ctx);
    return rc;
}
