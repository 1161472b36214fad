/* `cadmorph morph`: morphs a volume mesh of G onto G' (surface morph on the CAD, then the
 * RBF warp of the interior), writes it, reports its quality and, on request, a CSV of stages. */
#include "cli.h"
#include "options.h"
#include "patch_motion.h"

#include "cadmorph/morph.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph morph --from G0.step --to G1.step --mesh M0 -o M1 [--steps auto|K] "
    "[--relative --via Ga.step,Gb.step,...] [--surface rbf|project] [--method M] [--solver S] [--rbf-tol T] "
    "[--lattice N [--clamp E]] [--samples K --cubature N --cover S --stretch GS --bend GB --blend B] "
    "[--min-sj F] [--min-step F] [--no-escalate] [--keep-partial | --allow-inverted] [--optimize] "
    "[--report R.csv] [--cad-unit U] [--cad-tol F [--keep-offset]] "
    "[--off-cad refuse|fixed [--slide P,..] [--fixed-patches P,..] [--no-slide]] "
    "[--threads N] [--verbose]";

#define MORPH_MAX_VIA 256

typedef struct morph_args {
    const char *from, *to, *mesh, *out, *report, *unit;
    cm_morph_options opt;
    int fail_on_inverted, allow_inverted, threads, verbose, relative, keep_partial, no_escalate;
    char via_list[8192]; /* --via, split in place at the commas */
    const char *via[MORPH_MAX_VIA];
    size_t n_via;
    cli_patch_motion patches; /* the motion of the nodes off G0 */
} morph_args;

static morph_args args;

/* Splits --via's value at commas into args.via. */
static int parse_via(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    morph_args *a = dest;
    (void)o;
    if (strlen(v) >= sizeof a->via_list)
        return cli_usage(p->cmd, p->usage, "--via: list longer than %zu characters",
                         sizeof a->via_list - 1);
    snprintf(a->via_list, sizeof a->via_list, "%s", v);
    a->n_via = 0;
    for (char *q = a->via_list; q;) {
        char *comma = strchr(q, ',');
        if (comma) *comma = 0;
        if (!*q) return cli_usage(p->cmd, p->usage, "--via: empty path in '%s'", v);
        if (a->n_via == MORPH_MAX_VIA)
            return cli_usage(p->cmd, p->usage, "--via: more than %d geometries", MORPH_MAX_VIA);
        a->via[a->n_via++] = q;
        q = comma ? comma + 1 : NULL;
    }
    return 0;
}

/* --steps K (1..4096) or --steps auto */
static int parse_steps(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    if (!strcmp(v, "auto")) {
        *(int *)dest = CM_MORPH_STEPS_AUTO;
        return 0;
    }
    char *end;
    long n = strtol(v, &end, 10);
    if (*end || n < 1 || n > 4096)
        return cli_usage(p->cmd, p->usage, "%s: expected a positive integer, got '%s'", o->name, v);
    *(int *)dest = (int)n;
    return 0;
}


static const char *const surface_names[] = {"rbf", "project", NULL};
static const int surface_methods[] = {CM_SURFACE_RBF, CM_SURFACE_PROJECT};

static const char *const off_cad_names[] = {"refuse", "fixed", NULL};
static const int off_cad_values[] = {CM_OFF_CAD_REFUSE, CM_OFF_CAD_FIXED};


static int print_help(void);

static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "--from", .kind = CLI_STRING, .dest = &args.from, .label = "--from G0.step",
     .help = "the geometry M0 was meshed from"},
    {.name = "--to", .kind = CLI_STRING, .dest = &args.to, .label = "--to G1.step",
     .help = "the edited geometry (same topology)"},
    {.name = "--mesh", .kind = CLI_STRING, .dest = &args.mesh, .label = "--mesh M0",
     .help = "input volume mesh"},
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &args.out,
     .label = "-o, --output M1", .help = "output mesh (must not be an input)"},
    {.name = "--steps", .kind = CLI_CUSTOM, .takes_value = 1, .parse = parse_steps,
     .dest = &args.opt.steps, .label = "--steps auto",
     .help = "adaptive steps (the default): the whole motion first (a valid\n"
             "one-step morph costs what --steps 1 costs), halved on failure\n"
             "and refitted on the last valid mesh, doubled after easy steps,\n"
             "until the mesh is valid (no inverted cell, --min-sj)"},
    {.name = "--steps", .kind = CLI_NOTE, .label = "--steps K",
     .help = "split the boundary motion into K equal increments (--steps 1:\n"
             "the plain one-step morph of the papers); each increment after\n"
             "the first refits the warp on the last mesh; an increment that\n"
             "is not valid ends the morph (exit 3) unless --allow-inverted"},
    {.name = "--min-sj", .kind = CLI_DOUBLE, .dest = &args.opt.min_sj, .lo = -1, .hi = 1,
     .open = 2, .bad = "%s: expected a number in [-1, 1), got '%s'", .label = "--min-sj F",
     .help = "a valid mesh keeps every scaled Jacobian above F when F > 0\n"
             "(default 0: no inverted cell)"},
    {.name = "--min-step", .kind = CLI_DOUBLE, .dest = &args.opt.min_fraction, .lo = 0, .hi = 1,
     .open = 3, .bad = "%s: expected a number in (0, 1), got '%s'", .label = "--min-step F",
     .help = "smallest adaptive step, a fraction of the motion (default 1/256)"},
    {.name = "--keep-partial", .kind = CLI_FLAG, .dest = &args.keep_partial,
     .label = "--keep-partial",
     .help = "when no valid mesh is reached, still write the last valid\n"
             "mesh (and the report) before exiting 3"},
    {.name = "--optimize", .kind = CLI_FLAG, .dest = &args.opt.optimize, .label = "--optimize",
     .help = "optimise the interior nodes after every step (boundary nodes\n"
             "stay on G1): untangles and raises the worst cells"},
    {.name = "--no-escalate", .kind = CLI_FLAG, .dest = &args.no_escalate,
     .label = "--no-escalate",
     .help = "--steps auto without --optimize: exit 3 when no step is valid\n"
             "(default: the rest of the motion is retried with --optimize,\n"
             "with a warning)"},
    {.name = "--relative", .kind = CLI_FLAG, .dest = &args.relative},
    {.name = "--via", .kind = CLI_CUSTOM, .takes_value = 1, .parse = parse_via, .dest = &args,
     .label = "--relative --via L",
     .help = "morph relatively through the intermediate geometries of the\n"
             "comma-separated list L (same topology): G0 -> Ga -> ... -> G1,\n"
             "each leg from the previous result (K increments per leg)"},
    {.name = "--surface", .kind = CLI_ENUM, .dest = &args.opt.method.surface,
     .names = surface_names, .values = surface_methods, .bad = "%.0sunknown surface method '%s'",
     .label = "--surface S", .help = "rbf (parameter warp, default) or project (closest point)"},
    {.name = "--method", .kind = CLI_CUSTOM, .takes_value = 1, .parse = cli_parse_warp_method,
     .dest = &args.opt.method.warp.method, .label = "--method M",
     .help = "interior warp: %s (default rbf)", .help_arg = cm_warp_method_list},
    {.name = "--kernel", .kind = CLI_ENUM, .dest = &args.opt.method.warp.method,
     .names = cli_kernel_names, .values = cli_kernel_methods, .bad = "%.0sunknown kernel '%s'",
     .label = "--kernel K",
     .help = "triharmonic (= --method rbf) or biharmonic (= rbf-biharmonic)"},
    {CLI_SOLVER_OPTION, .dest = &args.opt.method.warp.solver},
    {CLI_RBF_TOL_OPTION, .dest = &args.opt.method.warp.tolerance},
    {.name = "--lattice", .kind = CLI_INT, .dest = &args.opt.method.warp.lattice, .lo = 4,
     .hi = 200, .bad = "%s: expected 4..200 control points per axis, got '%s'",
     .label = "--lattice N",
     .help = "dmffd: control points per axis of the B-spline lattice on the\n"
             "mesh's bounding box (paper: 5 10 15 25; default 10); DM-FFD\n"
             "is least squares: the boundary keeps its motion exactly, the\n"
             "interior follows a space map that misses it (residual)"},
    {.name = "--clamp", .kind = CLI_DOUBLE, .dest = &args.opt.method.warp.clamp, .lo = 0,
     .hi = 1, .open = 3, .bad = "%s: expected a number in (0, 1), got '%s'", .label = "--clamp E",
     .help = "dmffd: singular values <= E x the largest are dropped\n"
             "(default 1e-10; 1e-2 keeps coarse lattices usable)"},
    CLI_MLS_OPTIONS(args.opt.method.warp.mls),
    {.name = "--report", .kind = CLI_STRING, .dest = &args.report, .label = "--report R.csv",
     .help = "one row per step: quality, distance to G1, stage times"},
    {.name = "--allow-inverted", .kind = CLI_FLAG, .dest = &args.allow_inverted,
     .label = "--allow-inverted",
     .help = "write M1 even with inverted cells (exit 0, a warning naming\n"
             "them): --steps K runs to the end, --steps auto morphs the rest\n"
             "of the motion in one step when no step is valid"},
    {.name = "--fail-on-inverted", .kind = CLI_FLAG, .dest = &args.fail_on_inverted,
     .label = "--fail-on-inverted",
     .help = "the default (exit 3, M1 not written, when a cell is inverted);\n"
             "accepted for scripts that say so"},
    {.name = "--cad-unit", .kind = CLI_STRING, .dest = &args.unit, .label = "--cad-unit U",
     .help = "unit of the mesh coordinates: the STEP files are converted to\n"
             "it (mm default; cm m in ft um ...)"},
    {.name = "--cad-tol", .kind = CLI_DOUBLE, .dest = &args.opt.classify.rel_tol, .lo = 0,
     .hi = 1, .open = 1, .bad = "%s: expected a number in (0, 1], got '%s'", .label = "--cad-tol F",
     .help = "a boundary node is on G0 within F x its shortest boundary edge\n"
             "(default 1e-6; a snapped mesh, e.g. snappyHexMesh's, needs more)"},
    {.name = "--keep-offset", .kind = CLI_FLAG, .dest = &args.opt.keep_offset,
     .label = "--keep-offset",
     .help = "boundary nodes keep their offset from G0 (move as their point on\n"
             "G0 does) instead of landing on G1: for a mesh snapped near G0"},
    {.name = "--off-cad", .kind = CLI_ENUM, .dest = &args.opt.off_cad, .names = off_cad_names,
     .values = off_cad_values, .bad = "%.0sexpected refuse or fixed, got '%s'",
     .label = "--off-cad P",
     .help = "boundary nodes not on G0: refuse (default: not a mesh of G0) or\n"
             "fixed (kept where they are, e.g. a wind tunnel around the body,\n"
             "or sliding on their patch: see below; only whole boundary\n"
             "components off G0, or ones touching the body where the surface\n"
             "off G0 is flat; some node must be on G0)"},
    CLI_PATCH_MOTION_OPTIONS(args.patches),
    {.name = "--threads", .kind = CLI_THREADS, .dest = &args.threads,
     .bad = "%s: expected a positive integer, got '%s'", .label = "--threads N",
     .help = "threads (default: all)"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &args.verbose,
     .label = "--verbose", .help = "debug messages on stderr"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf(
        "Moves the volume mesh M0 of the CAD model G0 onto G1 (same topology, other dimensions):\n"
        "boundary nodes on CAD vertices go to the matching vertex, nodes on edges keep their\n"
        "arc length, nodes on faces are moved in the face's (u,v) by a 2D thin-plate RBF fitted\n"
        "on the face boundaries; the interior follows by an RBF space warp per component.\n"
        "Writes M1 with per-node 'displacement' and per-cell 'scaled_jacobian' (a polyMesh:\n"
        "its points only), then prints the quality summary line. Mesh formats (M0 and M1):\n"
        "  %s.\n\n"
        "options:\n",
        cm_mesh_format_list());
    cli_print_options(stdout, options, 21);
    printf("\n" CLI_PATCH_MOTION_OFF_CAD);
    printf("\nexit codes: 0 done (a valid M1, or one with inverted cells and --allow-inverted),\n"
           "1 usage, 2 bad input (unreadable file, G0 and G1 that do not correspond, a mesh that\n"
           "is not on G0), 3 no valid mesh reached (the message names the worst cells; M1 not\n"
           "written unless --keep-partial, the report written with the rejected rows).\n");
    return CLI_EXIT_OK;
}

static int parse_args(int argc, char **argv, morph_args *a)
{
    static const char *cmd = "morph";
    memset(&args, 0, sizeof args);
    cm_morph_options_init(&args.opt);
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    if (args.unit) args.opt.cad_unit = args.unit;
    if (args.no_escalate) args.opt.escalate = 0;
    if (args.allow_inverted) args.opt.allow_inverted = 1;
    /* the names stay in the static args, so a's copy may point at them */
    cli_patch_motion_options(&args.patches, &args.opt.motion);
    *a = args;
    for (size_t k = 0; k < a->n_via; ++k) /* into a's own copy of the list */
        a->via[k] = a->via_list + (args.via[k] - args.via_list);
    if (parsed >= 0) return parsed;
    if (!a->from) return cli_usage(cmd, usage_line, "--from is required");
    if (!a->to) return cli_usage(cmd, usage_line, "--to is required");
    if (!a->mesh) return cli_usage(cmd, usage_line, "--mesh is required");
    if (!a->out) return cli_usage(cmd, usage_line, "-o is required");
    if (cli_check_solver(cmd, usage_line, a->opt.method.warp.solver) >= 0) return CLI_EXIT_USAGE;
    if (a->keep_partial && a->allow_inverted)
        return cli_usage(cmd, usage_line,
                         "--keep-partial (the last valid mesh) and --allow-inverted (the final "
                         "mesh, inverted cells and all): one or the other");
    if (a->fail_on_inverted && a->allow_inverted)
        return cli_usage(cmd, usage_line, "--fail-on-inverted and --allow-inverted contradict");
    if ((a->patches.n[0] || a->patches.n[1] || a->patches.all_fixed) &&
        a->opt.off_cad != CM_OFF_CAD_FIXED)
        return cli_usage(cmd, usage_line,
                         "--slide, --fixed-patches and --no-slide go with --off-cad fixed (the "
                         "nodes on G0 follow the CAD)");
    if (a->n_via && !a->relative)
        return cli_usage(cmd, usage_line, "--via needs --relative (a morph through them)");
    const char *inputs[3 + MORPH_MAX_VIA] = {a->from, a->to, a->mesh};
    for (size_t k = 0; k < a->n_via; ++k)
        inputs[3 + k] = a->via[k];
    if (cli_check_mesh_output(cmd, usage_line, a->out, inputs, 3 + a->n_via))
        return CLI_EXIT_USAGE;
    for (size_t k = 0; k < 3 + a->n_via; ++k) {
        if (a->report && cli_same_file(a->report, inputs[k]))
            return cli_usage(cmd, usage_line, "report %s is an input: refusing to overwrite it",
                             a->report);
    }
    if (a->report && cli_same_file(a->report, a->out))
        return cli_usage(cmd, usage_line, "--report and -o name the same file");
    return -1;
}

/* The CSV report into its open temporary file (committed with the mesh). */
static void fill_report(FILE *f, const cm_morph_result *r)
{
    fprintf(f, "step,min_scaled_jacobian,mean_scaled_jacobian,inverted,max_distance_to_g1,"
               "t_read,t_sample,t_classify,t_surface_morph,t_volume_solve,t_evaluation,"
               "t_write,fraction,accepted,optimized_moves,note\n");
    for (int k = 0; k < r->n_steps; ++k) {
        const cm_morph_step *st = &r->steps[k];
        /* the note names cells and positions: quoted, with its own quotes doubled */
        char note[2 * sizeof st->note + 3];
        size_t n = 0;
        note[n++] = '"';
        for (const char *c = st->note; *c && n < sizeof note - 2; ++c) {
            if (*c == '"') note[n++] = '"';
            note[n++] = *c;
        }
        note[n++] = '"';
        note[n] = 0;
        fprintf(f, "%d,%.9g,%.9g,%zu,%.6g,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.9g,%d,%zu,%s\n",
                st->step, st->min_sj, st->mean_sj, st->inverted, st->max_dist, st->t_read,
                st->t_sample, st->t_classify, st->t_surface, st->t_volume_solve, st->t_evaluation,
                st->t_write, st->fraction, st->accepted, st->optimized_moves, note);
    }
}

/* The mesh and the report as one output (docs/DESIGN.md, "Command line contract"): the
 * report's temporary is created first (a report that cannot be written leaves no mesh); a
 * mesh file is written into a temporary directory beside -o and renamed together with the
 * report; an OpenFOAM case (a directory with its own atomic scheme) and an Abaqus or Nastran
 * deck (with its included files) are written before the report is committed. Returns the exit code (rc when all went well). */
static int write_outputs(cm_context *ctx, const morph_args *a, cm_morph_result *r, int want_mesh,
                         int want_report, int rc)
{
    cm_outfile rep = {0};
    cm_outdir od = {0};
    char *staged = NULL;
    cm_status s = CM_OK;
    if (want_report) s = cm_outfile_open(ctx, a->report, &rep);
    if (s >= 0 && want_mesh) {
        double t = cm_wtime();
        /* an Abaqus or Nastran deck writes its included files beside it: not staged */
        const cm_mesh_format fmt = cm_mesh_format_from_path(a->out);
        if (want_report && fmt != CM_FORMAT_FOAM && fmt != CM_FORMAT_ABAQUS && fmt != CM_FORMAT_NASTRAN) {
            /* the temporary directory beside -o: "<dir of -o>/.cm-XXXXXX" */
            const char *base = strrchr(a->out, '/');
            base = base ? base + 1 : a->out;
            char beside[4200];
            snprintf(beside, sizeof beside, "%.*s.cm", (int)(base - a->out), a->out);
            s = cm_outdir_open(ctx, beside, &od);
            size_t len = s >= 0 ? strlen(od.tmp) + strlen(base) + 2 : 0;
            if (s >= 0 && !(staged = malloc(len))) s = cm_error(ctx, CM_ERR_NOMEM, "out of memory");
            if (s >= 0) {
                snprintf(staged, len, "%s/%s", od.tmp, base);
                s = cm_mesh_write(ctx, r->mesh, staged, NULL);
            }
        } else {
            s = cm_mesh_write(ctx, r->mesh, a->out, NULL);
        }
        r->steps[r->n_steps - 1].t_write = cm_wtime() - t;
    }
    if (s >= 0 && want_report) {
        fill_report(rep.f, r);
        s = cm_outfile_commit_all(ctx, &rep, 1, staged, a->out);
    }
    cm_outfile_abort(&rep);
    cm_outdir_abort(&od);
    free(staged);
    return s < 0 ? cli_fail(ctx, "morph", s) : rc;
}

int cli_cmd_morph(int argc, char **argv)
{
    morph_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    cm_context *ctx = cli_context_create("morph", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_morph_result *r = NULL;
    cm_status s = cm_morph_run(ctx, a.from, a.to, a.mesh, a.via, a.n_via, &a.opt, &r);
    if (s < 0 && !r) {
        rc = cli_fail(ctx, "morph", s);
        cm_context_destroy(&ctx);
        return rc;
    }
    /* no valid mesh reached: the report, and with --keep-partial the last valid mesh */
    int partial = s == CM_ERR_REJECTED;
    if (partial) rc = cli_fail(ctx, "morph", s);
    /* warnings were logged as they happened; the mesh is that of the last accepted step */
    int k_last = r->n_steps - 1;
    while (k_last > 0 && !r->steps[k_last].accepted)
        --k_last;
    const cm_morph_step *last = &r->steps[k_last];
    cm_log(ctx, CM_LOG_DEBUG,
           "morph: boundary nodes on vertices %zu, edges %zu, faces %zu; largest distance to "
           "G1 %.3g (%.3g x diagonal)",
           r->counts[0], r->counts[1], r->counts[2], r->max_dist,
           r->diagonal > 0 ? r->max_dist / r->diagonal : 0.0);
    if (!partial) rc = CLI_EXIT_OK;
    /* the library's guard returns valid meshes only; this is the writer's own check */
    if (!partial && !a.allow_inverted && last->inverted > 0) {
        fprintf(stderr,
                "cadmorph morph: %zu inverted cells (min scaled Jacobian %.6g); %s not written\n",
                last->inverted, last->min_sj, a.out);
        rc = CLI_EXIT_REJECTED;
    }
    /* under mpirun (--solver petsc) every rank has the result; rank 0 writes it */
    const int writer = cli_output_rank();
    int keep = partial && a.keep_partial;
    if (keep && writer) {
        /* the last valid mesh is M0 itself when the first step failed: not valid when M0 is not */
        cm_quality_stats q;
        if (cm_quality_summarize(ctx, r->mesh, r->sj, NULL, &q) >= 0 && q.inverted > 0) {
            fprintf(stderr, "cadmorph morph: --keep-partial: the last valid mesh would be %s "
                    "itself, which has %zu inverted cells; %s not written\n", a.mesh,
                    q.inverted, a.out);
            keep = 0;
        }
    }
    const int want_mesh = writer && (rc == CLI_EXIT_OK || keep);
    const int want_report = writer && a.report && (rc == CLI_EXIT_OK || rc == CLI_EXIT_REJECTED);
    if (want_mesh || want_report) rc = write_outputs(ctx, &a, r, want_mesh, want_report, rc);
    if (writer && (rc == CLI_EXIT_OK || rc == CLI_EXIT_REJECTED)) {
        printf("boundary nodes: %zu on vertices, %zu on edges, %zu on faces; ", r->counts[0],
               r->counts[1], r->counts[2]);
        if (r->off_cad_nodes)
            printf(r->off_cad_slide ? "%zu off G0 (%zu boundary components; %zu of them slide, "
                                      "the rest kept fixed); "
                                    : "%zu off G0 kept fixed (%zu boundary components); ",
                   r->off_cad_nodes, r->off_cad_components, r->off_cad_slide);
        printf("largest distance to G1: %.3g (%.3g x diagonal)\n", r->max_dist,
               r->diagonal > 0 ? r->max_dist / r->diagonal : 0.0);
        s = cli_print_quality(ctx, r->mesh, r->sj, stdout, NULL);
        if (s < 0 && rc == CLI_EXIT_OK) rc = cli_fail(ctx, "morph", s);
        /* a rejected result said so already */
        if (s >= 0 && rc == CLI_EXIT_OK) cli_warn_inverted("morph", r->mesh, r->sj);
    }
    cm_morph_result_destroy(&r);
    cm_context_destroy(&ctx);
    return rc;
}
