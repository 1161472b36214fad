/* `cadmorph optimize MESH -o OUT`: interior node optimisation of any volume mesh (boundary
 * nodes never move): untangles inverted cells and raises the worst ones (optimize.h). */
#include "cli.h"
#include "options.h"

#include "cadmorph/optimize.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph optimize MESH -o OUT [--target-sj F] [--sweeps N] [--threads N] [--verbose]";

static const char *out;
static int threads, verbose;
static cm_optimize_options opt;

static int print_help(void);

static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &out,
     .label = "-o, --output OUT", .help = "output mesh (must not be the input)"},
    {.name = "--target-sj", .kind = CLI_DOUBLE, .dest = &opt.target_sj, .lo = -1, .hi = 1,
     .open = 1, .bad = "%s: expected a number in (-1, 1]%.0s", .label = "--target-sj F",
     .help = "work on the cells below this scaled Jacobian and their\n"
             "neighbours (default 0.3)"},
    {.name = "--sweeps", .kind = CLI_INT, .dest = &opt.sweeps, .lo = 1, .hi = 1000,
     .bad = "%s: expected 1..1000, got '%s'", .label = "--sweeps N",
     .help = "passes over those nodes (default 6)"},
    {.name = "--threads", .kind = CLI_THREADS, .dest = &threads, .label = "--threads N",
     .help = "threads (default: all); the result does not depend on it"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &verbose, .label = "--verbose",
     .help = "debug messages on stderr"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf("Moves the interior nodes of the volume mesh MESH to untangle inverted cells and raise\n"
           "the worst ones, node by node (Knupp's inverse mean ratio of the corner Jacobians,\n"
           "regularised so that inverted corners can recover); a move that would lower the\n"
           "worst cell around a node is not made. Boundary nodes, and the nodes of cells other\n"
           "than linear tets, hexes, wedges and pyramids, never move. Writes OUT\n"
           "(%s)\n"
           "with per-cell 'scaled_jacobian' and per-node 'displacement', prints the\n"
           "quality before and after and ends with the summary line of the result.\n\n"
           "options:\n",
           cm_mesh_format_list());
    cli_print_options(stdout, options, 21);
    printf("\nexit codes: 0 done, 1 usage, 2 bad input, 3 inverted cells remain.\n");
    return CLI_EXIT_OK;
}

/* Exit 3 says why on one line (README, "Exit codes"): how many cells stay inverted and the
 * worst of them (the lowest scaled Jacobian of a volume cell, NaN first). */
static int rejected(const cm_mesh *mesh, const double *sj, const cm_optimize_stats *st, const char *path)
{
    size_t worst = (size_t)-1;
    double wv = INFINITY;
    for (size_t c = 0; sj && c < mesh->n_cells; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!info || info->dim != 3) continue;
        const double v = isnan(sj[c]) ? -INFINITY : sj[c];
        if (worst == (size_t)-1 || v < wv) wv = v, worst = c;
    }
    if (worst == (size_t)-1)
        fprintf(stderr, "cadmorph optimize: %zu inverted cells remain; %s is written all the same\n",
                st->inverted_after, path);
    else
        fprintf(stderr,
                "cadmorph optimize: %zu inverted cell%s remain%s (the worst: cell %zu, 0-based, %s, scaled "
                "Jacobian %.6g); written all the same, no worse than the input: %s\n",
                st->inverted_after, st->inverted_after == 1 ? "" : "s", st->inverted_after == 1 ? "s" : "",
                worst, cm_cell_type_info((cm_cell_type)mesh->type[worst])->name, isnan(sj[worst]) ? NAN : sj[worst], path);
    return CLI_EXIT_REJECTED;
}

int cli_cmd_optimize(int argc, char **argv)
{
    static const char *cmd = "optimize";
    const char *in = NULL;
    cm_optimize_options_init(&opt);
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown argument '%s'", .pos = &in, .max_pos = 1,
                    .extra = "unexpected argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    if (parsed >= 0) return parsed;
    if (!in) return cli_usage(cmd, usage_line, "missing MESH");
    if (!out) return cli_usage(cmd, usage_line, "-o is required");
    if (cli_check_mesh_output(cmd, usage_line, out, &in, 1)) return CLI_EXIT_USAGE;

    cm_context *ctx = cli_context_create(cmd, verbose, threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_mesh *mesh = NULL;
    double *start = NULL, *sj = NULL;
    cm_optimize_stats st;
    cm_status s = cm_mesh_read(ctx, in, &mesh);
    if (s >= 0) {
        start = malloc(3 * (mesh->n_nodes ? mesh->n_nodes : 1) * sizeof *start);
        s = start ? CM_OK : cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    }
    if (s >= 0) {
        memcpy(start, mesh->xyz, 3 * mesh->n_nodes * sizeof *start);
        s = cm_mesh_optimize(ctx, mesh, NULL, &opt, &st);
        if (s < 0) s = cm_error_prefix(ctx, s, "%s", in);
    }
    if (s >= 0) { /* the nodes have moved: start becomes their displacement */
        for (size_t i = 0; i < 3 * mesh->n_nodes; ++i)
            start[i] = mesh->xyz[i] - start[i];
        s = cm_mesh_apply_displacement(ctx, mesh, start, CM_DISPLACEMENT_QUALITY, &sj);
    }
    if (s >= 0) {
        s = cm_mesh_write(ctx, mesh, out, NULL);
        if (s == CM_ERR_REJECTED) s = cm_error_prefix(ctx, s, "the optimisation of %s", in); /* non-finite */
    }
    int rc = CLI_EXIT_OK;
    if (s >= 0) {
        printf("optimize: %zu interior nodes worked on, %zu moves in %d passes; min scaled "
               "Jacobian %.6g -> %.6g, inverted %zu -> %zu\n",
               st.nodes_selected, st.moves, st.sweeps, st.min_sj_before, st.min_sj_after,
               st.inverted_before, st.inverted_after);
        s = cli_print_quality(ctx, mesh, sj, stdout, NULL);
    }
    if (s < 0)
        rc = cli_fail(ctx, cmd, s);
    else if (st.inverted_after > 0)
        rc = rejected(mesh, sj, &st, out); /* written all the same: it is better than the input */
    free(start);
    cm_mesh_destroy(&mesh);
    cm_context_destroy(&ctx);
    return rc;
}
