/* `cadmorph morph`: morphs a volume mesh of G onto G' (surface morph on the CAD, then the
 * RBF warp of the interior), writes it, reports its quality and, on request, a CSV of stages. */
#include "cli.h"

#include "cadmorph/morph.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph morph --from G0.step --to G1.step --mesh M0 -o M1 [--steps K] "
    "[--relative --via Ga.step,Gb.step,...] [--surface rbf|project] [--method M] "
    "[--lattice N [--clamp E]] "
    "[--steps auto [--min-sj F] [--keep-partial]] [--optimize] [--report R.csv] "
    "[--fail-on-inverted] [--cad-unit U] [--threads N] [--verbose]";

static void print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf(
        "Moves the volume mesh M0 of the CAD model G0 onto G1 (same topology, other dimensions):\n"
        "boundary nodes on CAD vertices go to the matching vertex, nodes on edges keep their\n"
        "arc length, nodes on faces are moved in the face's (u,v) by a 2D thin-plate RBF fitted\n"
        "on the face boundaries; the interior follows by an RBF space warp per component.\n"
        "Writes M1 (.msh .vtu .vtk .mesh) with per-node 'displacement' and per-cell\n"
        "'scaled_jacobian', then prints the quality summary line.\n\n"
        "options:\n"
        "  --from G0.step       the geometry M0 was meshed from\n"
        "  --to G1.step         the edited geometry (same topology)\n"
        "  --mesh M0            input volume mesh\n"
        "  -o, --output M1      output mesh (must not be an input)\n"
        "  --steps K            split the boundary motion into K equal increments (default 1);\n"
        "                       each increment after the first refits the warp on the last mesh\n"
        "  --steps auto         adaptive steps: the whole motion first, halved on failure and\n"
        "                       refitted on the last valid mesh, doubled after easy steps,\n"
        "                       until every cell keeps a scaled Jacobian above --min-sj\n"
        "  --min-sj F           floor of --steps auto (default 0: no inverted cell)\n"
        "  --min-step F         smallest adaptive step, a fraction of the motion (default 1/256)\n"
        "  --keep-partial       when --steps auto finds no valid step, still write the last\n"
        "                       valid mesh (and the report) before exiting 3\n"
        "  --optimize           optimise the interior nodes after every step (boundary nodes\n"
        "                       stay on G1): untangles and raises the worst cells\n"
        "  --relative --via L   morph relatively through the intermediate geometries of the\n"
        "                       comma-separated list L (same topology): G0 -> Ga -> ... -> G1,\n"
        "                       each leg from the previous result (K increments per leg)\n"
        "  --surface S          rbf (parameter warp, default) or project (closest point)\n"
        "  --method M           interior warp: %s (default rbf)\n"
        "  --kernel K           triharmonic (= --method rbf) or biharmonic (= rbf-biharmonic)\n"
        "  --lattice N          dmffd: control points per axis of the B-spline lattice on the\n"
        "                       mesh's bounding box (paper: 5 10 15 25; default 10); DM-FFD\n"
        "                       is least squares: the boundary keeps its motion exactly, the\n"
        "                       interior follows a space map that misses it (residual)\n"
        "  --clamp E            dmffd: singular values <= E x the largest are dropped\n"
        "                       (default 1e-10; 1e-2 keeps coarse lattices usable)\n"
        "  --report R.csv       one row per step: quality, distance to G1, stage times\n"
        "  --fail-on-inverted   exit 3 without writing M1 if a cell is inverted\n"
        "  --cad-unit U         unit of the mesh coordinates: the STEP files are converted to\n"
        "                       it (mm default; cm m in ft um ...)\n"
        "  --threads N          threads (default: all)\n"
        "  --verbose            debug messages on stderr\n\n"
        "exit codes: 0 done, 1 usage, 2 bad input (unreadable file, G0 and G1 that do not\n"
        "correspond, a mesh that is not on G0), 3 inverted cells with --fail-on-inverted or no\n"
        "valid adaptive step (the message names the worst cells).\n",
        cm_warp_method_list());
}

#define MORPH_MAX_VIA 256

typedef struct morph_args {
    const char *from, *to, *mesh, *out, *report, *unit;
    cm_morph_options opt;
    int fail_on_inverted, threads, verbose, relative, keep_partial;
    char via_list[8192]; /* --via, split in place at the commas */
    const char *via[MORPH_MAX_VIA];
    size_t n_via;
} morph_args;

/* Splits --via's value at commas into a->via. */
static int parse_via(const char *cmd, morph_args *a, const char *v)
{
    if (strlen(v) >= sizeof a->via_list)
        return cli_usage(cmd, usage_line, "--via: list longer than %zu characters",
                         sizeof a->via_list - 1);
    snprintf(a->via_list, sizeof a->via_list, "%s", v);
    a->n_via = 0;
    for (char *p = a->via_list; p;) {
        char *comma = strchr(p, ',');
        if (comma) *comma = 0;
        if (!*p) return cli_usage(cmd, usage_line, "--via: empty path in '%s'", v);
        if (a->n_via == MORPH_MAX_VIA)
            return cli_usage(cmd, usage_line, "--via: more than %d geometries", MORPH_MAX_VIA);
        a->via[a->n_via++] = p;
        p = comma ? comma + 1 : NULL;
    }
    return -1;
}

static int parse_args(int argc, char **argv, morph_args *a)
{
    static const char *cmd = "morph";
    memset(a, 0, sizeof *a);
    cm_morph_options_init(&a->opt);
    for (int i = 1; i < argc; ++i) {
        const char *o = argv[i], *v;
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            print_help();
            return CLI_EXIT_OK;
        } else if (!strcmp(o, "--verbose") || !strcmp(o, "-v")) {
            a->verbose = 1;
        } else if (!strcmp(o, "--fail-on-inverted")) {
            a->fail_on_inverted = 1;
        } else if (!strcmp(o, "--from")) {
            if (!(a->from = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--to")) {
            if (!(a->to = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--mesh")) {
            if (!(a->mesh = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "-o") || !strcmp(o, "--output")) {
            if (!(a->out = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--report")) {
            if (!(a->report = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
        } else if (!strcmp(o, "--cad-unit")) {
            if (!(a->unit = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            a->opt.cad_unit = a->unit;
        } else if (!strcmp(o, "--surface")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            if (!strcmp(v, "rbf"))
                a->opt.method.surface = CM_SURFACE_RBF;
            else if (!strcmp(v, "project"))
                a->opt.method.surface = CM_SURFACE_PROJECT;
            else
                return cli_usage(cmd, usage_line, "unknown surface method '%s'", v);
        } else if (!strcmp(o, "--kernel")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            if (!strcmp(v, "triharmonic"))
                a->opt.method.warp.method = CM_WARP_RBF;
            else if (!strcmp(v, "biharmonic"))
                a->opt.method.warp.method = CM_WARP_RBF_BIHARMONIC;
            else
                return cli_usage(cmd, usage_line, "unknown kernel '%s'", v);
        } else if (!strcmp(o, "--clamp")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            char *end;
            double e = strtod(v, &end);
            if (end == v || *end || !(e > 0 && e < 1))
                return cli_usage(cmd, usage_line, "--clamp: expected a number in (0, 1), got '%s'",
                                 v);
            a->opt.method.warp.clamp = e;
        } else if (!strcmp(o, "--lattice")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            char *end;
            long n = strtol(v, &end, 10);
            if (end == v || *end || n < 4 || n > 200)
                return cli_usage(cmd, usage_line,
                                 "--lattice: expected 4..200 control points per axis, got '%s'", v);
            a->opt.method.warp.lattice = (int)n;
        } else if (!strcmp(o, "--method")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            int m = cm_warp_method_from_name(v);
            if (m < 0)
                return cli_usage(cmd, usage_line, "unknown method '%s' (%s)", v,
                                 cm_warp_method_list());
            a->opt.method.warp.method = (cm_warp_method)m;
        } else if (!strcmp(o, "--relative")) {
            a->relative = 1;
        } else if (!strcmp(o, "--via")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            int rc = parse_via(cmd, a, v);
            if (rc >= 0) return rc;
        } else if (!strcmp(o, "--optimize")) {
            a->opt.optimize = 1;
        } else if (!strcmp(o, "--keep-partial")) {
            a->keep_partial = 1;
        } else if (!strcmp(o, "--min-sj") || !strcmp(o, "--min-step")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            char *end;
            double x = strtod(v, &end);
            int step = !strcmp(o, "--min-step");
            if (*end || !(x >= -1 && x < 1) || (step && !(x > 0)))
                return cli_usage(cmd, usage_line, "%s: expected a number in %s, got '%s'", o,
                                 step ? "(0, 1)" : "[-1, 1)", v);
            if (step)
                a->opt.min_fraction = x;
            else
                a->opt.min_sj = x;
        } else if (!strcmp(o, "--steps") && i + 1 < argc && !strcmp(argv[i + 1], "auto")) {
            a->opt.steps = CM_MORPH_STEPS_AUTO;
            ++i;
        } else if (!strcmp(o, "--steps") || !strcmp(o, "--threads")) {
            if (!(v = cli_value(argc, argv, &i, cmd, usage_line))) return CLI_EXIT_USAGE;
            char *end;
            long n = strtol(v, &end, 10);
            if (*end || n < 1 || n > 4096)
                return cli_usage(cmd, usage_line, "%s: expected a positive integer, got '%s'", o,
                                 v);
            if (!strcmp(o, "--steps"))
                a->opt.steps = (int)n;
            else
                a->threads = (int)n;
        } else {
            return cli_usage(cmd, usage_line, "unknown argument '%s'", o);
        }
    }
    if (!a->from) return cli_usage(cmd, usage_line, "--from is required");
    if (!a->to) return cli_usage(cmd, usage_line, "--to is required");
    if (!a->mesh) return cli_usage(cmd, usage_line, "--mesh is required");
    if (!a->out) return cli_usage(cmd, usage_line, "-o is required");
    if (a->keep_partial && a->opt.steps != CM_MORPH_STEPS_AUTO)
        return cli_usage(cmd, usage_line, "--keep-partial goes with --steps auto");
    if (a->n_via && !a->relative)
        return cli_usage(cmd, usage_line, "--via needs --relative (a morph through them)");
    if (cm_mesh_format_from_path(a->out) == CM_FORMAT_UNKNOWN)
        return cli_usage(cmd, usage_line, "%s: unknown mesh extension (.msh .vtu .vtk .mesh)",
                         a->out);
    const char *inputs[3 + MORPH_MAX_VIA] = {a->from, a->to, a->mesh};
    for (size_t k = 0; k < a->n_via; ++k)
        inputs[3 + k] = a->via[k];
    for (size_t k = 0; k < 3 + a->n_via; ++k) {
        if (cli_same_file(a->out, inputs[k]))
            return cli_usage(cmd, usage_line, "output %s is an input: refusing to overwrite it",
                             a->out);
        if (a->report && cli_same_file(a->report, inputs[k]))
            return cli_usage(cmd, usage_line, "report %s is an input: refusing to overwrite it",
                             a->report);
    }
    if (a->report && cli_same_file(a->report, a->out))
        return cli_usage(cmd, usage_line, "--report and -o name the same file");
    return -1;
}

/* The CSV report, written through a temporary file like the meshes. */
static cm_status write_report(cm_context *ctx, const char *path, const cm_morph_result *r)
{
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s < 0) return s;
    fprintf(out.f, "step,min_scaled_jacobian,mean_scaled_jacobian,inverted,max_distance_to_g1,"
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
        fprintf(out.f, "%d,%.9g,%.9g,%zu,%.6g,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.9g,%d,%zu,%s\n",
                st->step, st->min_sj, st->mean_sj, st->inverted, st->max_dist, st->t_read,
                st->t_sample, st->t_classify, st->t_surface, st->t_volume_solve, st->t_evaluation,
                st->t_write, st->fraction, st->accepted, st->optimized_moves, note);
    }
    return cm_outfile_commit(ctx, &out);
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
    /* a rejected adaptive morph: the report, and with --keep-partial the last valid mesh */
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
    if (!partial && a.fail_on_inverted && last->inverted > 0) {
        fprintf(stderr,
                "cadmorph morph: %zu inverted cells (min scaled Jacobian %.6g); %s not written\n",
                last->inverted, last->min_sj, a.out);
        rc = CLI_EXIT_REJECTED;
    }
    if (rc == CLI_EXIT_OK || (partial && a.keep_partial)) {
        double t = cm_wtime();
        s = cm_mesh_write(ctx, r->mesh, a.out, NULL);
        r->steps[r->n_steps - 1].t_write = cm_wtime() - t;
        if (s < 0) rc = cli_fail(ctx, "morph", s);
    }
    if (a.report && (rc == CLI_EXIT_OK || rc == CLI_EXIT_REJECTED)) {
        s = write_report(ctx, a.report, r);
        if (s < 0) rc = cli_fail(ctx, "morph", s);
    }
    if (rc == CLI_EXIT_OK || rc == CLI_EXIT_REJECTED) {
        printf("boundary nodes: %zu on vertices, %zu on edges, %zu on faces; "
               "largest distance to G1: %.3g (%.3g x diagonal)\n",
               r->counts[0], r->counts[1], r->counts[2], r->max_dist,
               r->diagonal > 0 ? r->max_dist / r->diagonal : 0.0);
        s = cli_print_quality(ctx, r->mesh, r->sj, stdout, NULL);
        if (s < 0 && rc == CLI_EXIT_OK) rc = cli_fail(ctx, "morph", s);
    }
    cm_morph_result_destroy(&r);
    cm_context_destroy(&ctx);
    return rc;
}
