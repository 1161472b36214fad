/* `cadmorph quality MESH [--csv OUT.csv] [--threads N]`: Verdict scaled Jacobian of every
 * volume cell, a per-type table and the summary line; optionally one CSV row per volume cell. */
#include "cli.h"
#include "options.h"

#include <stdlib.h>
#include <string.h>

static const char *const usage = "cadmorph quality MESH [--csv OUT.csv] [--foam] [--threads N] [-h|--help]";

static const char *csv;
static int threads, foam;

static const cli_option options[] = {
    {.name = "--csv", .kind = CLI_STRING, .dest = &csv, .label = "--csv OUT.csv",
     .help = "write cell,type,scaled_jacobian for every volume cell (cell: 0-based\n"
             "index among all elements of the file)"},
    {.name = "--foam", .kind = CLI_FLAG, .dest = &foam, .label = "--foam",
     .help = "first what OpenFOAM checkMesh runs by default (v1912 definitions: cell types,\n"
             "topology, directions, 2-D edge alignment and wedge checks, openness, aspect\n"
             "ratio, non-orthogonality, skewness, face pyramids, volumes, cyclic point\n"
             "match) with its verdict (\"Mesh OK.\" or \"Failed N mesh checks.\") in its layout and\n"
             "the line max_aspect_ratio=.. max_non_orthogonality=.. avg_non_orthogonality=..\n"
             "max_skewness=.. wrong_pyramids=.. negative_volumes=.. failed_checks=.. cells=..;\n"
             "on a polyMesh its own faces, on other meshes the faces of the volume cells"},
    {.name = "--threads", .kind = CLI_THREADS, .dest = &threads, .label = "--threads N",
     .help = "threads for the computation (default: all)"},
    {.name = "--help", .alias = "-h", .kind = CLI_HELP, .label = "-h, --help", .help = "this text"},
    {0}};

static int help(void)
{
    printf("usage: %s\n\n"
           "Scaled Jacobian (as Verdict / VTK's vtkMeshQuality define it) of every volume cell of\n"
           "MESH (%s). Prints one row\n"
           "per cell type - cells, minimum, mean, 1st percentile, inverted - and ends with the line\n"
           "  min_scaled_jacobian=<v> mean_scaled_jacobian=<v> inverted=<k> cells=<n>\n"
           "Inverted counts the cells a solver rejects: on an OpenFOAM polyMesh and for every\n"
           "polyhedron, what checkMesh calls a negative volume or an incorrectly oriented face\n"
           "(its face-pyramid test); for other cells a scaled Jacobian <= 0. The scaled Jacobian\n"
           "of a polyhedron (the minimum over its tet decomposition) is a quality measure only.\n\n"
           "options:\n",
           usage, cm_mesh_format_list());
    cli_print_options(stdout, options, 16);
    return CLI_EXIT_OK;
}

static cm_status write_csv(cm_context *ctx, const cm_mesh *mesh, const double *sj, const char *path)
{
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    fputs("cell,type,scaled_jacobian\n", out.f);
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!info || info->dim < 3) continue;
        fprintf(out.f, "%zu,%s,%.17g\n", c, info->name, sj[c]);
    }
    return cm_outfile_commit(ctx, &out);
}

int cli_cmd_quality(int argc, char **argv)
{
    const char *cmd = "quality", *mesh_path = NULL;
    cli_parser p = {.cmd = cmd, .usage = usage, .options = options, .help = help,
                    .unknown = "unknown option '%s'", .pos = &mesh_path, .max_pos = 1,
                    .extra = "unexpected argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    if (parsed >= 0) return parsed;
    if (!mesh_path) return cli_usage(cmd, usage, "missing MESH");
    if (csv && cli_same_file(csv, mesh_path))
        return cli_usage(cmd, usage, "--csv %s is the input mesh; refusing to overwrite it", csv);

    cm_context *ctx = cli_context_create(cmd, 0, threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    int rc = CLI_EXIT_OK;
    cm_mesh *mesh = NULL;
    double *sj = NULL;
    cm_status s = cm_mesh_read(ctx, mesh_path, &mesh);
    if (s < 0) {
        rc = cli_fail(ctx, cmd, s);
        goto done;
    }
    if (s > 0) fprintf(stderr, "cadmorph %s: warning: %s\n", cmd, cm_context_message(ctx));
    if (cm_mesh_count_dim(mesh, 3) == 0) {
        fprintf(stderr, "cadmorph %s: %s: no volume cells (tet, hex, wedge, pyramid, polyhedron)\n", cmd,
                mesh_path);
        rc = CLI_EXIT_BAD_INPUT;
        goto done;
    }
    if (foam) {
        cm_foam_quality fq;
        if ((s = cm_mesh_quality_foam(ctx, mesh, &fq)) < 0) {
            rc = cli_fail(ctx, cmd, s);
            goto done;
        }
        cli_print_foam_quality(&fq, mesh, stdout);
    }
    sj = malloc((mesh->n_cells ? mesh->n_cells : 1) * sizeof *sj);
    if (!sj) {
        fprintf(stderr, "cadmorph %s: out of memory (%zu cells)\n", cmd, mesh->n_cells);
        rc = CLI_EXIT_INTERNAL;
        goto done;
    }
    if ((s = cm_mesh_quality(ctx, mesh, sj)) < 0) {
        rc = cli_fail(ctx, cmd, s);
        goto done;
    }
    /* the CSV first: the summary line then reports a run whose outputs all exist */
    if (csv && (s = write_csv(ctx, mesh, sj, csv)) < 0) {
        rc = cli_fail(ctx, cmd, s);
        goto done;
    }
    if ((s = cli_print_quality(ctx, mesh, sj, stdout, NULL)) < 0) rc = cli_fail(ctx, cmd, s);
done:
    free(sj);
    cm_mesh_destroy(&mesh);
    cm_context_destroy(&ctx);
    return rc;
}
