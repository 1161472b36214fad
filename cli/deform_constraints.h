/* `cadmorph deform --constraint TYPE:SET`: the specs, their node sets and the Shape-Up run
 * (cli/deform_constraints.c). */
#ifndef CADMORPH_CLI_DEFORM_CONSTRAINTS_H
#define CADMORPH_CLI_DEFORM_CONSTRAINTS_H

#include "options.h"

#include "cadmorph/shapeup.h"

#include <math.h>

#define CLI_MAX_CONSTRAINTS 256

typedef struct cli_constraints {
    int n;
    cm_shape_type type[CLI_MAX_CONSTRAINTS];
    const char *set[CLI_MAX_CONSTRAINTS]; /* the SET part of argv, or a CAD set's label */
    char *owned[CLI_MAX_CONSTRAINTS];     /* the labels allocated here */
    const char *cad, *cad_filter;         /* --constraints-from-cad G.step, --cad-constraints */
    cm_shapeup_options opt;
} cli_constraints;

void cli_constraints_init(cli_constraints *c);

/* The values of --constraint TYPE:SET (appended to the cli_constraints dest) and of
 * --dense-constraints (no value), as CLI_CUSTOM parsers. */
int cli_parse_constraint(const cli_parser *p, const cli_option *o, const char *v, void *dest);
int cli_parse_dense_constraints(const cli_parser *p, const cli_option *o, const char *v, void *dest);

/* The constraint options of deform's option table (c: a cli_constraints lvalue, set by
 * cli_constraints_init before parsing). */
#define CLI_CONSTRAINT_OPTIONS(c)                                                                 \
    {.name = "--constraint", .kind = CLI_CUSTOM, .takes_value = 1, .parse = cli_parse_constraint, \
     .dest = &(c), .label = "--constraint TYPE:SET",                                              \
     .help = "MLS only, repeatable: keep the nodes of SET on a shape of\n"                       \
             "TYPE while deforming (Shape-Up, the MLS paper's section 6):\n"                     \
             "plane, circle, cylinder, cone, line (similar copy:\n"                              \
             "translation, rotation, uniform scale) or rigid. SET: a\n"                          \
             "node-list file (header node), else a physical group of the\n"                      \
             "mesh (gmsh; an OpenFOAM patch or cellZone), else a field\n"                        \
             "NAME or NAME=VALUE (nodes where the node field, or of the\n"                       \
             "cells where the cell field, is nonzero / equals VALUE)"},                          \
    {.name = "--constraint-weight", .kind = CLI_DOUBLE, .dest = &(c).opt.weight, .lo = 0,         \
     .hi = NAN, .open = 1, .bad = "%s: '%s' is not a number > 0", .label = "--constraint-weight GC", \
     .help = "gamma_c (default 10)"},                                                             \
    {.name = "--constraint-iterations", .kind = CLI_INT, .dest = &(c).opt.max_iterations,         \
     .lo = 0, .hi = 1e9, .bad = "%s: '%s' is not an integer in 0..1e9",                           \
     .label = "--constraint-iterations N", .help = "cap on the alternations (default 10000)"},   \
    {.name = "--constraint-tolerance", .kind = CLI_DOUBLE, .dest = &(c).opt.tolerance, .lo = 0,   \
     .hi = NAN, .bad = "%s: '%s' is not a number >= 0", .label = "--constraint-tolerance T",     \
     .help = "stop when no constrained node moves more than T x the\n"                           \
             "bounding-box diagonal in one alternation (default 1e-9)"},                          \
    {.name = "--dense-constraints", .kind = CLI_CUSTOM, .parse = cli_parse_dense_constraints,     \
     .dest = &(c), .label = "--dense-constraints",                                                \
     .help = "mean-centred C (dense per set) instead of subtracting one\n"                       \
             "point (section 6.1, the default)"},                                                 \
    {.name = "--constraint-anderson", .kind = CLI_INT, .dest = &(c).opt.anderson, .lo = 1,        \
     .hi = 64, .bad = "%s: '%s' is not an integer in 1..64", .label = "--constraint-anderson M",  \
     .help = "Anderson acceleration over the last M iterates (1..64;\n"                          \
             "default off: the paper's plain alternation)"},                                      \
    {.name = "--constraint-snap", .kind = CLI_FLAG, .dest = &(c).opt.snap,                        \
     .label = "--constraint-snap",                                                                \
     .help = "after the alternation, put the constrained nodes on their\n"                       \
             "projections (the shapes then hold to rounding)"},                                   \
    {.name = "--constraints-from-cad", .kind = CLI_STRING, .dest = &(c).cad,                      \
     .label = "--constraints-from-cad G",                                                         \
     .help = "volume meshes: constraints from the STEP model G of the\n"                         \
             "mesh: the nodes of each planar face (with its edges and\n"                         \
             "vertices) a plane set, of each cylindrical (conical) face\n"                       \
             "a cylinder (cone) set, of each circular edge a circle set"},                       \
    {.name = "--cad-constraints", .kind = CLI_STRING, .dest = &(c).cad_filter,                    \
     .label = "--cad-constraints LIST",                                                           \
     .help = "which of them: plane, cylinder, cone, circle, face:N,\n"                           \
             "edge:N (0-based ids as `cadmorph info` lists; default all\n"                       \
             "types)"}

/* 1 if any constraint was asked for. */
int cli_constraints_any(const cli_constraints *c);

/* The node sets of the specs: SET is a node-list file (header `node`), else a physical group
 * of the mesh by name, else a field NAME or NAME=VALUE (nodes of the node field, or of the
 * cells of the cell field, that are nonzero / equal VALUE); then the sets of the CAD model
 * (appended to c). sets: CLI_MAX_CONSTRAINTS entries, c->n of them filled, to be freed with
 * cli_constraints_free. */
cm_status cli_constraints_resolve(cm_context *ctx, const cm_mesh *mesh, cli_constraints *c,
                                  cm_shape_set *sets);
void cli_constraints_free(cli_constraints *c, cm_shape_set *sets);

/* The sets of --constraints-from-cad (deform_cad_constraints.c), appended to c and sets. */
cm_status cli_cad_constraints(cm_context *ctx, const cm_mesh *mesh, cli_constraints *c,
                              cm_shape_set *sets);

/* Shape-Up on an MLS deformation: disp as cm_mls_apply; prints one line per set and a
 * summary; adds the node field 'constraint_set' (the last set of each node, -1: none). */
cm_status cli_constraints_run(cm_context *ctx, cm_mls *mls, cm_mesh *mesh,
                              const cli_constraints *c, const cm_shape_set *sets, double *disp,
                              double *fix_residual);

#endif
