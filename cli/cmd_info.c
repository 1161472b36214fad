/* `cadmorph info`: the topology summary of a STEP file (faces, edges, vertices, types, sizes)
 * and, with --compare, the verdict on whether a second file corresponds to it (the same
 * topology as a graph, in any numbering, DESIGN.md: G and G') and the correspondence found. */
#include "cli.h"
#include "options.h"

#include "cadmorph/cad.h"

#include <stdio.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph info G.step [--compare G2.step [--map OUT.csv]] [--cad-unit mm|cm|m|in|ft|...] "
    "[--faces] [--edges] [--verbose]";

static const char *other, *map_path;
static cm_cad_read_options opt;
static int faces, edges, verbose;

static int print_help(void);

static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "--compare", .kind = CLI_STRING, .dest = &other, .label = "--compare G2.step",
     .help = "check that G2 corresponds to G (the same solids, shells, faces,\n"
             "wires, edges, vertices and incidences in any numbering; surface\n"
             "and curve types may change); prints the correspondence, or the\n"
             "first differences"},
    {.name = "--map", .kind = CLI_STRING, .dest = &map_path, .label = "--map OUT.csv",
     .help = "with --compare: the correspondence as CSV (kind,index_in_G,\n"
             "index_in_G',orientation,type_G,type_G')"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &verbose,
     .label = "--verbose", .help = "debug messages on stderr (type changes, renumbering)"},
    {.name = "--cad-unit", .kind = CLI_STRING, .dest = &opt.unit, .label = "--cad-unit U",
     .help = "length unit of the coordinates (default mm): mm cm m km in ft mi um"},
    {.name = "--faces", .kind = CLI_FLAG, .dest = &faces, .label = "--faces",
     .help = "one line per face (type, area, wires, parameter range)"},
    {.name = "--edges", .kind = CLI_FLAG, .dest = &edges, .label = "--edges",
     .help = "one line per edge (type, length, vertices)"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf("Prints the topology of the STEP model G: counts, length units, bounding box, faces by\n"
           "surface type and edges by curve type. Faces, edges and vertices are numbered from 0\n"
           "in OpenCASCADE's order, the order cadmorph uses everywhere.\n\n"
           "options:\n");
    cli_print_options(stdout, options, 20);
    printf("\nexit codes: 0 done (and G2 corresponds), 1 usage, 2 bad input or G2 differs.\n");
    printf("With --compare, the correspondence: faces, edges and vertices of G2 numbered otherwise\n"
           "and edges that run the other way (cadmorph morph renumbers G2 the same way).\n");
    return CLI_EXIT_OK;
}

static void print_model(const char *path, const cm_cad_model *m, int faces, int edges)
{
    cm_cad_counts c;
    cm_cad_get_counts(m, &c);
    double bb[6];
    cm_cad_bbox(m, bb);
    const char *fu = cm_cad_file_unit(m);
    printf("file: %s\n", path);
    printf("unit: %s (file: %s)\n", cm_cad_unit(m), *fu ? fu : "not given");
    printf("solids %d  shells %d  faces %d  wires %d  edges %d  vertices %d\n", c.solids, c.shells,
           c.faces, c.wires, c.edges, c.vertices);
    printf("bbox: [%g, %g] x [%g, %g] x [%g, %g]\n", bb[0], bb[3], bb[1], bb[4], bb[2], bb[5]);

    int stype[CM_CAD_OTHER_SURFACE + 1] = {0}, ctype[CM_CAD_OTHER_CURVE + 1] = {0}, degenerate = 0;
    double area = 0, length = 0;
    for (int f = 0; f < c.faces; ++f) {
        cm_cad_face_info fi;
        if (cm_cad_face_get_info(NULL, m, f, &fi) != CM_OK) continue;
        ++stype[fi.type];
        area += fi.area;
    }
    for (int e = 0; e < c.edges; ++e) {
        cm_cad_edge_info ei;
        if (cm_cad_edge_get_info(NULL, m, e, &ei) != CM_OK) continue;
        if (ei.degenerate)
            ++degenerate;
        else
            ++ctype[ei.type];
        length += ei.length;
    }
    printf("faces by type:");
    for (int t = 0; t <= CM_CAD_OTHER_SURFACE; ++t)
        if (stype[t]) printf(" %s %d", cm_cad_surface_type_name((cm_cad_surface_type)t), stype[t]);
    printf("  (total area %g)\n", area);
    printf("edges by type:");
    for (int t = 0; t <= CM_CAD_OTHER_CURVE; ++t)
        if (ctype[t]) printf(" %s %d", cm_cad_curve_type_name((cm_cad_curve_type)t), ctype[t]);
    if (degenerate) printf(" degenerate %d", degenerate);
    printf("  (total length %g)\n", length);

    if (faces)
        for (int f = 0; f < c.faces; ++f) {
            cm_cad_face_info fi;
            if (cm_cad_face_get_info(NULL, m, f, &fi) != CM_OK) continue;
            int n_edges = 0;
            for (int w = 0; w < fi.n_wires; ++w) {
                int n = 0;
                if (cm_cad_face_wire(NULL, m, f, w, NULL, NULL, &n) == CM_OK) n_edges += n;
            }
            printf("face %d: %s area %g wires %d edges %d u [%g, %g] v [%g, %g]%s\n", f,
                   cm_cad_surface_type_name(fi.type), fi.area, fi.n_wires, n_edges, fi.uv_range[0],
                   fi.uv_range[1], fi.uv_range[2], fi.uv_range[3], fi.reversed ? " reversed" : "");
        }
    if (edges)
        for (int e = 0; e < c.edges; ++e) {
            cm_cad_edge_info ei;
            if (cm_cad_edge_get_info(NULL, m, e, &ei) != CM_OK) continue;
            printf("edge %d: %s length %g vertices (%d,%d) t [%g, %g]\n", e,
                   ei.degenerate ? "degenerate" : cm_cad_curve_type_name(ei.type), ei.length,
                   ei.vertex[0], ei.vertex[1], ei.t_range[0], ei.t_range[1]);
        }
}

static const char *edge_type(const cm_cad_model *m, int e)
{
    cm_cad_edge_info ei;
    if (cm_cad_edge_get_info(NULL, m, e, &ei) != CM_OK) return "?";
    return ei.degenerate ? "degenerate" : cm_cad_curve_type_name(ei.type);
}

static const char *face_type(const cm_cad_model *m, int f)
{
    cm_cad_face_info fi;
    if (cm_cad_face_get_info(NULL, m, f, &fi) != CM_OK) return "?";
    return cm_cad_surface_type_name(fi.type);
}

/* The summary of the correspondence on stdout: what is renumbered, flipped, of another type. */
static void print_correspondence(const cm_cad_model *g, const cm_cad_model *g2,
                                 const cm_cad_correspondence *c)
{
    int fmoved = 0, emoved = 0, eflip = 0, vmoved = 0, frev = 0;
    for (int f = 0; f < c->counts.faces; ++f) fmoved += c->face[f] != f, frev += c->face_reversed[f];
    for (int e = 0; e < c->counts.edges; ++e) emoved += c->edge[e] != e, eflip += c->edge_flipped[e];
    for (int v = 0; v < c->counts.vertices; ++v) vmoved += c->vertex[v] != v;
    printf("correspondence: %d of %d faces, %d of %d edges, %d of %d vertices numbered otherwise "
           "in G'; %d edges run the other way, %d of %d wires start elsewhere, %d faces have the "
           "opposite surface normal\n",
           fmoved, c->counts.faces, emoved, c->counts.edges, vmoved, c->counts.vertices, eflip,
           c->wires_restarted, c->counts.wires, frev);
    printf("type changes: %d faces, %d edges\n", c->face_type_changes, c->edge_type_changes);
    int shown = 0;
    for (int f = 0; f < c->counts.faces && shown < 20; ++f)
        if (c->face[f] != f || strcmp(face_type(g, f), face_type(g2, c->face[f]))) {
            printf("  face %d -> %d (%s -> %s)\n", f, c->face[f], face_type(g, f),
                   face_type(g2, c->face[f]));
            ++shown;
        }
    for (int e = 0; e < c->counts.edges && shown < 40; ++e)
        if (c->edge[e] != e || c->edge_flipped[e] || strcmp(edge_type(g, e), edge_type(g2, c->edge[e]))) {
            printf("  edge %d -> %d%s (%s -> %s)\n", e, c->edge[e],
                   c->edge_flipped[e] ? " reversed" : "", edge_type(g, e), edge_type(g2, c->edge[e]));
            ++shown;
        }
    if (shown >= 20) printf("  ... (--map OUT.csv lists all)\n");
}

static cm_status write_map(cm_context *ctx, const char *path, const cm_cad_model *g,
                           const cm_cad_model *g2, const cm_cad_correspondence *c)
{
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s != CM_OK) return s;
    fprintf(out.f, "kind,index_in_G,index_in_G',orientation,type_G,type_G'\n");
    for (int f = 0; f < c->counts.faces; ++f)
        fprintf(out.f, "face,%d,%d,%s,%s,%s\n", f, c->face[f],
                c->face_reversed[f] ? "reversed" : "same", face_type(g, f),
                face_type(g2, c->face[f]));
    for (int e = 0; e < c->counts.edges; ++e)
        fprintf(out.f, "edge,%d,%d,%s,%s,%s\n", e, c->edge[e],
                c->edge_flipped[e] ? "reversed" : "same", edge_type(g, e), edge_type(g2, c->edge[e]));
    for (int v = 0; v < c->counts.vertices; ++v)
        fprintf(out.f, "vertex,%d,%d,same,vertex,vertex\n", v, c->vertex[v]);
    return cm_outfile_commit(ctx, &out);
}

int cli_cmd_info(int argc, char **argv)
{
    static const char *cmd = "info";
    const char *path = NULL;
    cm_cad_read_options_init(&opt);
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown option '%s'", .pos = &path, .max_pos = 1,
                    .extra = "one STEP file expected, got '%s' too"};
    const int parsed = cli_parse(&p, argc, argv);
    if (parsed >= 0) return parsed;
    if (!path) return cli_usage(cmd, usage_line, "no STEP file given");
    if (map_path && !other) return cli_usage(cmd, usage_line, "--map needs --compare G2.step");
    if (map_path && (cli_same_file(map_path, path) || cli_same_file(map_path, other)))
        return cli_usage(cmd, usage_line, "--map %s would overwrite an input", map_path);

    cm_context *ctx = cli_context_create("info", verbose, 0);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_cad_model *g = NULL, *g2 = NULL;
    cm_cad_correspondence *corr = NULL;
    int rc = CLI_EXIT_OK;
    cm_status st = cm_cad_read(ctx, path, &opt, &g);
    if (st == CM_ERR_ARGUMENT) {
        rc = cli_usage(cmd, usage_line, "%s", cm_context_message(ctx));
        goto done;
    }
    if (st < 0) {
        rc = cli_fail(ctx, cmd, st);
        goto done;
    }
    if (other) {
        st = cm_cad_read(ctx, other, &opt, &g2);
        if (st < 0) {
            rc = cli_fail(ctx, cmd, st);
            goto done;
        }
        st = cm_cad_correspond(ctx, g, g2, 5, &corr);
        if (st < 0) {
            rc = cli_fail(ctx, cmd, st);
            goto done;
        }
        if (map_path) {
            st = write_map(ctx, map_path, g, g2, corr);
            if (st < 0) {
                rc = cli_fail(ctx, cmd, st);
                goto done;
            }
        }
    }
    print_model(path, g, faces, edges);
    if (g2) {
        cm_cad_counts c;
        cm_cad_get_counts(g, &c);
        printf("%s corresponds to %s: %d faces, %d edges, %d vertices%s\n", other, path, c.faces,
               c.edges, c.vertices, corr->renumbered ? " (numbered otherwise)" : " in the same order");
        print_correspondence(g, g2, corr);
    }
done:
    cm_cad_correspondence_destroy(&corr);
    cm_cad_destroy(&g);
    cm_cad_destroy(&g2);
    cm_context_destroy(&ctx);
    return rc;
}
