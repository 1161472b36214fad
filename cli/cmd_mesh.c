/* `cadmorph mesh G.step -o M [--size H] [--quality Q] [--preserve-surface]`: tet mesh of a STEP
 * solid (OpenCASCADE surface triangulation, TetGen volume), written with its quality field,
 * then the node/cell counts and the quality report. */
#include "cli.h"

#include "cadmorph/cad.h"
#include "cadmorph/tetmesh.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage =
    "cadmorph mesh G.step -o MESH [--size H] [--quality Q] [--preserve-surface] "
    "[--min-dihedral D] [--no-optimize] [--force] [--cad-unit U] [--threads N] [-v] [-h|--help]";

static int help(void)
{
    printf("usage: %s\n\n"
           "Tet mesh of the solid in G.step: OpenCASCADE triangulates the faces (watertight across\n"
           "face borders), TetGen fills the solid with tets of bounded radius-edge ratio. Every\n"
           "boundary node lies on the CAD model. MESH (.msh, .vtu, .vtk, .mesh) gets the tets and\n"
           "the boundary triangles, each tagged with its CAD face (face index + 1, as in\n"
           "'cadmorph info'), and the cell field scaled_jacobian. Prints the counts, then the\n"
           "quality report ending with\n"
           "  min_scaled_jacobian=<v> mean_scaled_jacobian=<v> inverted=<k> cells=<n>\n\n"
           "options:\n"
           "  -o MESH             output mesh (required)\n"
           "  --size H            target edge length in model units (default: bbox diagonal / 20)\n"
           "  --quality Q         bound on the tets' radius-edge ratio, >= 1 (default 1.4)\n"
           "  --preserve-surface  keep OpenCASCADE's surface triangulation as it is (TetGen -Y);\n"
           "                      by default TetGen refines it and its new boundary nodes are\n"
           "                      projected onto the CAD faces and edges\n"
           "  --min-dihedral D    lower bound on the tets' dihedral angles, degrees in [0, 20]\n"
           "                      (default 12; 0: TetGen's own): fewer slivers, more tets\n"
           "  --no-optimize       keep TetGen's interior nodes; by default they are optimised\n"
           "                      to lift slivers (boundary nodes never move)\n"
           "  --force             mesh even when the estimated tet count exceeds 1e7 (refused\n"
           "                      otherwise, exit code 4, with the estimate)\n"
           "  --cad-unit U        length unit of the coordinates (default mm)\n"
           "  --threads N         threads for the quality computation (default: all)\n"
           "  -v, --verbose       stage timings on stderr\n"
           "  -h, --help          this text\n\n"
           "exit codes: 0 done, 1 usage, 2 bad input (unreadable STEP, no closed solid, TetGen\n"
           "failure, touching solids), 4 out of memory or beyond the tet limit, internal error.\n",
           usage);
    return CLI_EXIT_OK;
}

static int parse_double(const char *cmd, const char *opt, const char *v, double lo, double *out)
{
    char *end = NULL;
    errno = 0;
    const double x = strtod(v, &end);
    if (errno || *end || !isfinite(x) || !(x >= lo) || (lo == 0 && x == 0))
        return cli_usage(cmd, usage, "%s needs a number %s %g, got '%s'", opt, lo == 0 ? ">" : ">=",
                         lo, v);
    *out = x;
    return 0;
}

int cli_cmd_mesh(int argc, char **argv)
{
    const char *cmd = "mesh", *in = NULL, *out = NULL, *unit = NULL;
    cm_tetmesh_options opt;
    cm_tetmesh_options_init(&opt);
    int threads = 0, verbose = 0;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = NULL;
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) return help();
        if (!strcmp(a, "-v") || !strcmp(a, "--verbose")) {
            verbose = 1;
        } else if (!strcmp(a, "--no-optimize")) {
            opt.optimize = 0;
        } else if (!strcmp(a, "--preserve-surface")) {
            opt.preserve_surface = 1;
        } else if (!strcmp(a, "--force")) {
            opt.max_tets = INFINITY;
        } else if (!strcmp(a, "-o") || !strcmp(a, "--output")) {
            if (!(out = cli_value(argc, argv, &i, cmd, usage))) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--cad-unit")) {
            if (!(unit = cli_value(argc, argv, &i, cmd, usage))) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--size")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage))) return CLI_EXIT_USAGE;
            if (parse_double(cmd, a, v, 0, &opt.size)) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--quality")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage))) return CLI_EXIT_USAGE;
            if (parse_double(cmd, a, v, 1, &opt.quality)) return CLI_EXIT_USAGE;
        } else if (!strcmp(a, "--min-dihedral")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage))) return CLI_EXIT_USAGE;
            char *end = NULL;
            opt.min_dihedral = strtod(v, &end);
            if (*end || !(opt.min_dihedral >= 0 && opt.min_dihedral <= 20))
                return cli_usage(cmd, usage, "--min-dihedral needs degrees in [0, 20], got '%s'", v);
        } else if (!strcmp(a, "--threads")) {
            if (cli_threads_value(argc, argv, &i, cmd, usage, &threads)) return CLI_EXIT_USAGE;
        } else if (a[0] == '-' && a[1] != '\0') {
            return cli_usage(cmd, usage, "unknown option '%s'", a);
        } else if (in) {
            return cli_usage(cmd, usage, "unexpected argument '%s'", a);
        } else {
            in = a;
        }
    }
    if (!in) return cli_usage(cmd, usage, "missing G.step");
    if (!out) return cli_usage(cmd, usage, "missing -o MESH");
    if (cm_mesh_format_from_path(out) == CM_FORMAT_UNKNOWN)
        return cli_usage(cmd, usage, "%s: unknown mesh format (.msh, .vtu, .vtk, .mesh)", out);
    if (cli_same_file(out, in))
        return cli_usage(cmd, usage, "output %s is the input: refusing to overwrite it", out);

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
