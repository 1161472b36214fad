/* `cadmorph deform --constraint TYPE:SET`: the specs, their node sets and the Shape-Up run
 * (cli/deform_constraints.c). */
#ifndef CADMORPH_CLI_DEFORM_CONSTRAINTS_H
#define CADMORPH_CLI_DEFORM_CONSTRAINTS_H

#include "cadmorph/shapeup.h"

#define CLI_MAX_CONSTRAINTS 64

typedef struct cli_constraints {
    int n;
    cm_shape_type type[CLI_MAX_CONSTRAINTS];
    const char *set[CLI_MAX_CONSTRAINTS]; /* the SET part of argv (borrowed) */
    cm_shapeup_options opt;
} cli_constraints;

void cli_constraints_init(cli_constraints *c);

/* Handles argv[*i] if it is one of the constraint options (--constraint TYPE:SET,
 * --constraint-weight, --constraint-iterations, --constraint-tolerance, --dense-constraints):
 * returns 1 and advances *i, 0 if it is not one, -1 after a usage message (exit 1). */
int cli_constraints_option(int argc, char **argv, int *i, const char *cmd, const char *usage,
                           cli_constraints *c);

/* Help text lines of the options. */
void cli_constraints_help(void);

/* The node sets of the specs: SET is a node-list file (header `node`), else a physical group
 * of the mesh by name, else a field NAME or NAME=VALUE (nodes of the node field, or of the
 * cells of the cell field, that are nonzero / equal VALUE). sets: c->n entries, their
 * nodes to be freed with cli_constraints_free. */
cm_status cli_constraints_resolve(cm_context *ctx, const cm_mesh *mesh, const cli_constraints *c,
                                  cm_shape_set *sets);
void cli_constraints_free(int n, cm_shape_set *sets);

/* Shape-Up on an MLS deformation: disp as cm_mls_apply; prints one line per set and a
 * summary. */
cm_status cli_constraints_run(cm_context *ctx, cm_mls *mls, const cm_mesh *mesh,
                              const cli_constraints *c, const cm_shape_set *sets, double *disp,
                              double *fix_residual);

#endif
