/* `cadmorph deform --constraint TYPE:SET`: the specs, their node sets and the Shape-Up run
 * (cli/deform_constraints.c). */
#ifndef CADMORPH_CLI_DEFORM_CONSTRAINTS_H
#define CADMORPH_CLI_DEFORM_CONSTRAINTS_H

#include "cadmorph/shapeup.h"

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

/* Handles argv[*i] if it is one of the constraint options (--constraint TYPE:SET,
 * --constraint-weight, --constraint-iterations, --constraint-tolerance, --dense-constraints,
 * --constraint-snap, --constraints-from-cad, --cad-constraints):
 * returns 1 and advances *i, 0 if it is not one, -1 after a usage message (exit 1). */
int cli_constraints_option(int argc, char **argv, int *i, const char *cmd, const char *usage,
                           cli_constraints *c);

/* Help text lines of the options. */
void cli_constraints_help(void);

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
