/* `cadmorph mesh G.step -o M [--size H] [--quality Q] [--preserve-surface]`: tet mesh of a STEP
 * solid (OpenCASCADE surface triangulation, TetGen volume), written with its quality field,
 * then the node/cell counts and the quality report. */
#include "cli.h"
#include "options.h"

#include "cadmorph/cad.h"
#include "cadmorph/tetmesh.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage =
    "cadmorph mesh G.step -o MESH [--size H] [--quality Q] [--preserve-surface] "
    "[--min-dihedral D] [--no-optimize] [--min-sj F] [--force] [--mesher tetgen|gmsh] "
    "[--time-limit S] "
    "[--cad-unit U] [--threads N] [-v] [-h|--help]";

static const char *out, *unit;
static cm_tetmesh_options opt;
static int threads, verbose, preserve_surface, no_optimize, force;
static const char *const mesher_names[] = {"tetgen", "gmsh", NULL};
static const int mesher_values[] = {CM_MESHER_TETGEN, CM_MESHER_GMSH};

static const cli_option options[] = {
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &out, .label = "-o MESH",
     .help = "output mesh (required)"},
    {.name = "--size", .kind = CLI_DOUBLE, .dest = &opt.size, .lo = 0, .hi = NAN, .open = 1,
     .bad = "%s needs a number > 0, got '%s'", .label = "--size H",
     .help = "target edge length in model units (default: bbox diagonal / 20)"},
    {.name = "--quality", .kind = CLI_DOUBLE, .dest = &opt.quality, .lo = 1, .hi = NAN,
     .bad = "%s needs a number >= 1, got '%s'", .label = "--quality Q",
     .help = "bound on the tets' radius-edge ratio, >= 1 (default 1.4)"},
    {.name = "--preserve-surface", .kind = CLI_FLAG, .dest = &preserve_surface,
     .label = "--preserve-surface",
     .help = "keep OpenCASCADE's surface triangulation as it is (TetGen -Y);\n"
             "by default TetGen refines it and its new boundary nodes are\n"
             "projected onto the CAD faces and edges"},
    {.name = "--min-dihedral", .kind = CLI_DOUBLE, .dest = &opt.min_dihedral, .lo = 0, .hi = 20,
     .bad = "%s needs degrees in [0, 20], got '%s'", .label = "--min-dihedral D",
     .help = "lower bound on the tets' dihedral angles, degrees in [0, 20]\n"
             "(default 12; 0: TetGen's own): fewer slivers, more tets"},
    {.name = "--no-optimize", .kind = CLI_FLAG, .dest = &no_optimize, .label = "--no-optimize",
     .help = "keep the mesher's interior nodes; by default they are optimised\n"
             "to lift slivers (boundary nodes never move)"},
    {.name = "--min-sj", .kind = CLI_DOUBLE, .dest = &opt.min_sj, .lo = -1, .hi = 1,
     .open = 2, .bad = "%s: expected a number in [-1, 1), got '%s'", .label = "--min-sj F",
     .help = "floor of the tets' scaled Jacobian after the optimisation, as\n"
             "morph's (default 0: no inverted tet, nor a flat one, below 1e-6);\n"
             "a mesh below it is not written (exit 3; -1 accepts any mesh)"},
    {.name = "--force", .kind = CLI_FLAG, .dest = &force, .label = "--force",
     .help = "mesh even when the estimated tet count exceeds 1e7 (refused\n"
             "otherwise, exit code 4, with the estimate; estimated from the\n"
             "surface triangulation, within 3x on the measured parts)"},
    {.name = "--mesher", .kind = CLI_ENUM, .dest = &opt.mesher, .names = mesher_names,
     .values = mesher_values, .bad = "%.0sunknown mesher '%s' (tetgen|gmsh)",
     .label = "--mesher M",
     .help = "gmsh (default; gmsh's library meshes the same STEP file, --size\n"
             "is its largest element size) or tetgen (OpenCASCADE's surface\n"
             "triangulation filled by TetGen; the default when --quality,\n"
             "--min-dihedral or --preserve-surface is given: TetGen's options).\n"
             "Without --mesher, when the first mesher fails (or its mesh is\n"
             "below --min-sj) the other is tried, with a warning; an explicit\n"
             "--mesher means that mesher only"},
    {.name = "--time-limit", .kind = CLI_DOUBLE, .dest = &opt.time_limit, .lo = 0, .hi = NAN,
     .open = 1, .bad = "%s needs seconds > 0, got '%s'", .label = "--time-limit S",
     .help = "seconds the meshing may take (default 600); the mesher runs in\n"
             "a child process, so its crash or hang is an error message. With\n"
             "the fallback the first mesher gets half, the other the rest"},
    {.name = "--cad-unit", .kind = CLI_STRING, .dest = &unit, .label = "--cad-unit U",
     .help = "length unit of the coordinates (default mm)"},
    {.name = "--threads", .kind = CLI_THREADS, .dest = &threads, .label = "--threads N",
     .help = "threads for the quality computation (default: all)"},
    {.name = "-v", .alias = "--verbose", .kind = CLI_FLAG, .dest = &verbose,
     .label = "-v, --verbose", .help = "stage timings on stderr"},
    {.name = "--help", .alias = "-h", .kind = CLI_HELP, .label = "-h, --help", .help = "this text"},
    {0}};

static int help(void)
{
    printf("usage: %s\n\n"
           "Tet mesh of the solid in G.step, by gmsh (its OpenCASCADE kernel reads the same file)\n"
           "or by TetGen (OpenCASCADE triangulates the faces, watertight across face borders,\n"
           "TetGen fills the solid with tets of bounded radius-edge ratio). The mesher runs in a\n"
           "child process under a time limit: its crash or hang is an error message; when\n"
           "TetGen fails, -Y, a looser quality bound and a perturbed surface are tried; when\n"
           "one mesher fails, the other is tried (one warning line says so) unless --mesher\n"
           "is given. gmsh's surface must lie on the CAD faces within the model's own\n"
           "tolerances; every boundary node is then put on the CAD model. The mesh is\n"
           "optimised and judged as a morph's (--min-sj). MESH gets the tets and the boundary\n"
           "triangles, each tagged with its CAD face (face index + 1, as in 'cadmorph info'),\n"
           "and the cell field scaled_jacobian, in the format of its extension:\n"
           "%s.\n"
           "Prints the counts, then the quality report ending with\n"
           "  min_scaled_jacobian=<v> mean_scaled_jacobian=<v> inverted=<k> cells=<n>\n\n"
           "options:\n",
           usage, cm_mesh_format_list());
    cli_print_options(stdout, options, 20);
    printf("\nexit codes: 0 done, 1 usage, 2 bad input (unreadable STEP, no closed solid, touching\n"
           "solids, the meshers failed, crashed or ran out of time: the message says what was\n"
           "tried), 3 the mesh stays below --min-sj (the worst tet named, nothing written),\n"
           "4 out of memory or beyond the tet limit, internal error.\n");
    return CLI_EXIT_OK;
}

int cli_cmd_mesh(int argc, char **argv)
{
    const char *cmd = "mesh", *in = NULL;
    cm_tetmesh_options_init(&opt);
    /* "not given" marks: TetGen's own options select TetGen when --mesher is not given */
    const double quality0 = opt.quality, dihedral0 = opt.min_dihedral;
    opt.quality = opt.min_dihedral = NAN;
    opt.mesher = -1;
    cli_parser p = {.cmd = cmd, .usage = usage, .options = options, .help = help,
                    .unknown = "unknown option '%s'", .pos = &in, .max_pos = 1,
                    .extra = "unexpected argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    if (parsed >= 0) return parsed;
    const int tetgen_options = !isnan(opt.quality) || !isnan(opt.min_dihedral) || preserve_surface;
    if (isnan(opt.quality)) opt.quality = quality0;
    if (isnan(opt.min_dihedral)) opt.min_dihedral = dihedral0;
    if (opt.mesher == CM_MESHER_GMSH && tetgen_options)
        return cli_usage(cmd, usage, "--quality, --min-dihedral and --preserve-surface are "
                         "TetGen's: not with --mesher gmsh");
    /* gmsh by default: better tets than TetGen's at the same size or tet count
     * (benchmarks/RESULTS.md, Meshers) and no crash on its error paths */
    /* an explicit --mesher is that mesher only: a user who chose it wants its result or why not */
    if (opt.mesher >= 0) opt.fallback = 0;
    if (opt.mesher < 0) opt.mesher = tetgen_options ? CM_MESHER_TETGEN : CM_MESHER_GMSH;
    if (preserve_surface) opt.preserve_surface = 1;
    if (no_optimize) opt.optimize = 0;
    if (force) opt.max_tets = INFINITY;
    if (!in) return cli_usage(cmd, usage, "missing G.step");
    if (!out) return cli_usage(cmd, usage, "missing -o MESH");
    if (cli_check_mesh_output(cmd, usage, out, &in, 1)) return CLI_EXIT_USAGE;

    cm_context *ctx = cli_context_create(cmd, verbose, threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_cad_read_options ro;
    cm_cad_read_options_init(&ro);
    if (unit) ro.unit = unit;
    cm_cad_model *model = NULL;
    cm_mesh *mesh = NULL;
    double *sj = NULL;
    const double t0 = cm_wtime();
    cm_status s = cm_cad_read(ctx, in, &ro, &model);
    const double t1 = cm_wtime();
    if (s >= 0) s = cm_tetmesh_create(ctx, model, &opt, &mesh);
    const double t2 = cm_wtime();
    if (s >= 0) s = cm_mesh_add_field(ctx, mesh, "scaled_jacobian", CM_FIELD_CELL, 1, &sj);
    if (s >= 0) s = cm_mesh_quality(ctx, mesh, sj);
    if (s >= 0) s = cm_mesh_write(ctx, mesh, out, NULL);
    if (s >= 0) {
        printf("nodes=%zu tets=%zu boundary_triangles=%zu read_s=%.3f mesh_s=%.3f\n", mesh->n_nodes,
               cm_mesh_count_dim(mesh, 3), cm_mesh_count_dim(mesh, 2), t1 - t0, t2 - t1);
        /* the report only once the mesh is written: its last line is what scripts parse */
        s = cli_print_quality(ctx, mesh, sj, stdout, NULL);
    }
    const int rc = s < 0 ? cli_fail(ctx, cmd, s) : CLI_EXIT_OK;
    cm_mesh_destroy(&mesh);
    cm_cad_destroy(&model);
    cm_context_destroy(&ctx);
    return rc;
}
