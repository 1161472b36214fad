/* `cadmorph detect`: planes, cylinders, spheres and cones of a surface mesh (or of a volume
 * mesh's boundary) by efficient RANSAC on face barycentres and normals (deform/ransac.c);
 * a CSV of the primitives and, optionally, a mesh whose faces carry their primitive's id. */
#include "cli.h"
#include "options.h"

#include "cadmorph/ransac.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const usage_line =
    "cadmorph detect MESH -o primitives.csv [--faces-out F.vtu] [--epsilon E] [--angle A] "
    "[--min-faces N] [--types LIST] [--seed S] [--threads N] [--verbose]";

typedef struct detect_args {
    const char *mesh, *out, *faces;
    double epsilon, angle;
    int min_faces, seed, threads, verbose;
    unsigned types;
} detect_args;

static detect_args args;

static int print_help(void);

static int parse_types(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    (void)o;
    unsigned m = 0;
    const char *s = v;
    while (*s) {
        size_t len = strcspn(s, ",");
        int found = 0;
        for (int t = CM_PRIMITIVE_PLANE; t <= CM_PRIMITIVE_CONE; ++t) {
            const char *name = cm_primitive_type_name((cm_primitive_type)t);
            if (strlen(name) == len && !strncmp(s, name, len)) m |= 1u << t, found = 1;
        }
        if (!found)
            return cli_usage(p->cmd, p->usage,
                             "--types: unknown primitive in '%s' (plane,cylinder,sphere,cone)", v);
        s += len;
        if (*s == ',') ++s;
    }
    if (!m) return cli_usage(p->cmd, p->usage, "--types: empty list");
    *(unsigned *)dest = m;
    return 0;
}

static const char *pos[1];

static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &args.out,
     .label = "-o, --output P.csv",
     .help = "the primitives: id,type,faces,nodes,area,rms,p0..p6 (see below)"},
    {.name = "--faces-out", .kind = CLI_STRING, .dest = &args.faces, .label = "--faces-out F",
     .help = "the faces (the surface cells; the boundary of a volume mesh)\n"
             "with a cell field 'primitive' (-1: none): colour by it in ParaView"},
    {.name = "--epsilon", .kind = CLI_DOUBLE, .dest = &args.epsilon, .label = "--epsilon E",
     .help = "distance tolerance relative to the bounding-box diagonal (0.005)", .lo = 0, .hi = 1,
     .open = 1, .bad = "%s: '%s' is not a number in (0, 1]"},
    {.name = "--angle", .kind = CLI_DOUBLE, .dest = &args.angle, .label = "--angle A",
     .help = "largest normal deviation in degrees (15)", .lo = 0, .hi = 90, .open = 3,
     .bad = "%s: '%s' is not a number in (0, 90)"},
    {.name = "--min-faces", .kind = CLI_INT, .dest = &args.min_faces, .label = "--min-faces N",
     .help = "smallest primitive (default 1 %% of the faces, at least 10)", .lo = 3, .hi = 1e9,
     .bad = "%s: '%s' is not an integer >= 3"},
    {.name = "--types", .kind = CLI_CUSTOM, .dest = &args.types, .parse = parse_types,
     .takes_value = 1, .label = "--types LIST",
     .help = "comma list of plane, cylinder, sphere, cone (all)"},
    {.name = "--seed", .kind = CLI_INT, .dest = &args.seed, .label = "--seed S",
     .help = "random seed (1): the result is the same for a seed", .lo = 0, .hi = 2147483647,
     .bad = "%s: '%s' is not an integer >= 0"},
    {.name = "--threads", .kind = CLI_THREADS, .dest = &args.threads, .label = "--threads N",
     .help = "threads (default: all)"},
    {.name = "--verbose", .alias = "-v", .kind = CLI_FLAG, .dest = &args.verbose,
     .label = "--verbose", .help = "debug messages on stderr"},
    {0}};

static int print_help(void)
{
    printf("usage: %s\n\n", usage_line);
    printf(
        "Detects planes, cylinders, spheres and cones in the faces of MESH (its 2D cells, or the\n"
        "boundary faces of a volume mesh) by the efficient RANSAC of Schnabel, Wahl and Klein\n"
        "on face barycentres and face normals, each candidate refined by a forward search. A\n"
        "primitive is assigned to all vertices of its faces (a vertex may have several): the\n"
        "node sets for `cadmorph deform --constraint` (write them with --faces-out and use\n"
        "the field as SET: primitive=ID).\n\n"
        "P.csv: id,type,faces,nodes,area,rms,p0,...,p6 with p = plane: point, normal;\n"
        "cylinder: axis point, axis, radius; sphere: centre, radius; cone: apex, axis, half\n"
        "angle (radians).\n\n"
        "options:\n");
    cli_print_options(stdout, options, 21);
    printf("\nexit codes: 0 done, 1 usage, 2 bad input.\n");
    return CLI_EXIT_OK;
}

static int parse_args(int argc, char **argv, detect_args *a)
{
    static const char *cmd = "detect";
    memset(&args, 0, sizeof args);
    cm_ransac_options o;
    cm_ransac_options_init(&o);
    args.epsilon = o.epsilon, args.angle = o.normal_angle, args.seed = (int)o.seed;
    args.types = o.types;
    cli_parser p = {.cmd = cmd, .usage = usage_line, .options = options, .help = print_help,
                    .unknown = "unknown argument '%s'", .pos = pos, .max_pos = 1,
                    .extra = "unexpected argument '%s' (one MESH)"};
    const int parsed = cli_parse(&p, argc, argv);
    *a = args;
    a->mesh = pos[0];
    if (parsed >= 0) return parsed;
    if (p.n_pos < 1 || !a->mesh) return cli_usage(cmd, usage_line, "MESH is required");
    if (!a->out) return cli_usage(cmd, usage_line, "-o is required");
    const char *inputs[] = {a->mesh};
    if (a->faces && cli_check_mesh_output(cmd, usage_line, a->faces, inputs, 1)) return CLI_EXIT_USAGE;
    if (cli_same_file(a->out, a->mesh))
        return cli_usage(cmd, usage_line, "output %s is an input: refusing to overwrite it", a->out);
    return -1;
}

/* The faces to detect on: corner nodes of the 2D cells (surface mesh; cell ids kept), else
 * the boundary of the volume cells. */
static cm_status gather_faces(cm_context *ctx, const cm_mesh *m, size_t *nf, int64_t **off,
                              int64_t **nodes, int64_t **cell)
{
    size_t n2 = cm_mesh_count_dim(m, 2);
    if (n2 > 0) {
        size_t total = 0;
        for (size_t c = 0; c < m->n_cells; ++c) {
            const cm_cell_info *inf = cm_cell_type_info((cm_cell_type)m->type[c]);
            if (inf && inf->dim == 2)
                total += inf->corners > 0 ? (size_t)inf->corners : (size_t)(m->offset[c + 1] - m->offset[c]);
        }
        *off = malloc((n2 + 1) * sizeof **off);
        *nodes = malloc((total ? total : 1) * sizeof **nodes);
        *cell = malloc(n2 * sizeof **cell);
        if (!*off || !*nodes || !*cell) return cm_error(ctx, CM_ERR_NOMEM, "out of memory");
        size_t f = 0, q = 0;
        (*off)[0] = 0;
        for (size_t c = 0; c < m->n_cells; ++c) {
            const cm_cell_info *inf = cm_cell_type_info((cm_cell_type)m->type[c]);
            if (!inf || inf->dim != 2) continue;
            int64_t k = inf->corners > 0 ? inf->corners : m->offset[c + 1] - m->offset[c];
            for (int64_t i = 0; i < k; ++i)
                (*nodes)[q++] = m->conn[m->offset[c] + i];
            (*cell)[f] = (int64_t)c;
            (*off)[++f] = (int64_t)q;
        }
        *nf = f;
        return CM_OK;
    }
    cm_mesh_boundary *b = NULL;
    cm_status s = cm_mesh_boundary_create(ctx, m, &b);
    if (s < 0) return s;
    if (b->n_faces == 0) {
        cm_mesh_boundary_destroy(&b);
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "the mesh has neither faces nor volume cells");
    }
    size_t total = (size_t)b->face_offset[b->n_faces];
    *off = malloc((b->n_faces + 1) * sizeof **off);
    *nodes = malloc(total * sizeof **nodes);
    *cell = NULL;
    if (!*off || !*nodes) {
        cm_mesh_boundary_destroy(&b);
        return cm_error(ctx, CM_ERR_NOMEM, "out of memory");
    }
    memcpy(*off, b->face_offset, (b->n_faces + 1) * sizeof **off);
    memcpy(*nodes, b->face_nodes, total * sizeof **nodes);
    *nf = b->n_faces;
    cm_mesh_boundary_destroy(&b);
    return CM_OK;
}

static cm_status write_csv(cm_context *ctx, const char *path, const cm_ransac_result *r)
{
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s < 0) return s;
    fprintf(out.f, "id,type,faces,nodes,area,rms,p0,p1,p2,p3,p4,p5,p6\n");
    for (size_t i = 0; i < r->n_primitives; ++i) {
        const cm_primitive *p = r->primitives + i;
        fprintf(out.f, "%zu,%s,%zu,%lld,%.10g,%.6g", i, cm_primitive_type_name(p->type), p->n_faces,
                (long long)(r->node_offset[i + 1] - r->node_offset[i]), p->area, p->rms);
        int np = p->type == CM_PRIMITIVE_PLANE ? 6 : p->type == CM_PRIMITIVE_SPHERE ? 4 : 7;
        for (int k = 0; k < 7; ++k)
            k < np ? fprintf(out.f, ",%.12g", p->p[k]) : fprintf(out.f, ",");
        fprintf(out.f, "\n");
    }
    return cm_outfile_commit(ctx, &out);
}

/* The faces as a mesh with the cell field 'primitive'. */
static cm_status write_faces(cm_context *ctx, const char *path, const cm_mesh *m, size_t nf,
                             const int64_t *off, const int64_t *nodes, const int64_t *cell,
                             const cm_ransac_result *r)
{
    cm_mesh *f = NULL;
    cm_status s = cm_mesh_create(ctx, &f);
    if (s >= 0) s = cm_mesh_resize_nodes(ctx, f, m->n_nodes, 0);
    if (s >= 0) memcpy(f->xyz, m->xyz, m->n_nodes * 3 * sizeof *f->xyz);
    for (size_t i = 0; s >= 0 && i < nf; ++i) {
        int64_t k = off[i + 1] - off[i];
        cm_cell_type t = k == 3 ? CM_CELL_TRI3 : k == 4 ? CM_CELL_QUAD4 : CM_CELL_POLYGON;
        if (cell) t = (cm_cell_type)m->type[cell[i]], k = m->offset[cell[i] + 1] - m->offset[cell[i]];
        s = cm_mesh_add_cell(ctx, f, t, cell ? m->conn + m->offset[cell[i]] : nodes + off[i], (size_t)k,
                             0, 0, 0);
    }
    double *field = NULL;
    if (s >= 0) s = cm_mesh_add_field(ctx, f, "primitive", CM_FIELD_CELL, 1, &field);
    if (s >= 0)
        for (size_t i = 0; i < nf; ++i)
            field[i] = r->face_primitive[i];
    if (s >= 0) s = cm_mesh_write(ctx, f, path, NULL);
    cm_mesh_destroy(&f);
    return s;
}

int cli_cmd_detect(int argc, char **argv)
{
    detect_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc >= 0) return rc;
    cm_context *ctx = cli_context_create("detect", a.verbose, a.threads);
    if (!ctx) return CLI_EXIT_INTERNAL;
    cm_mesh *mesh = NULL;
    cm_ransac_result *r = NULL;
    int64_t *off = NULL, *nodes = NULL, *cell = NULL;
    size_t nf = 0;
    cm_status s = cm_mesh_read(ctx, a.mesh, &mesh);
    if (s >= 0) s = gather_faces(ctx, mesh, &nf, &off, &nodes, &cell);
    double t0 = cm_wtime();
    if (s >= 0) {
        cm_ransac_options o;
        cm_ransac_options_init(&o);
        o.epsilon = a.epsilon, o.normal_angle = a.angle, o.seed = (uint64_t)a.seed;
        o.min_faces = (size_t)a.min_faces, o.types = a.types;
        s = cm_ransac_detect(ctx, mesh->n_nodes, mesh->xyz, nf, off, nodes, &o, &r);
    }
    double t1 = cm_wtime();
    if (s >= 0) s = write_csv(ctx, a.out, r);
    if (s >= 0 && a.faces) s = write_faces(ctx, a.faces, mesh, nf, off, nodes, cell, r);
    if (s >= 0) {
        size_t count[4] = {0, 0, 0, 0}, covered = 0;
        for (size_t i = 0; i < r->n_primitives; ++i)
            ++count[r->primitives[i].type], covered += r->primitives[i].n_faces;
        printf("detect: %zu faces, %zu primitives (%zu planes, %zu cylinders, %zu spheres, %zu "
               "cones) on %zu faces, %zu left; %zu minimal sets, %.3f s\n",
               nf, r->n_primitives, count[0], count[1], count[2], count[3], covered, nf - covered,
               r->candidates, t1 - t0);
    }
    rc = s < 0 ? cli_fail(ctx, "detect", s) : CLI_EXIT_OK;
    free(off), free(nodes), free(cell);
    cm_ransac_result_destroy(&r);
    cm_mesh_destroy(&mesh);
    cm_context_destroy(&ctx);
    return rc;
}
