/* `cadmorph demo`: the embedded example, end to end: the bore benchmark model, a tet mesh of
 * G(0) by OpenCASCADE + TetGen, and an absolute 10-step sweep to the full parameter change
 * with the three methods compared. It is `cadmorph sweep` with fixed arguments, printed first
 * so that a user can vary them. */
#include "cli.h"

#include <stdio.h>
#include <string.h>

static const char *const usage_line = "cadmorph demo [-o DIR]";

int cli_cmd_demo(int argc, char **argv)
{
    const char *dir = "cadmorph-demo";
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            printf("usage: %s\n\nThe bore model (4 x 4 x 2 block, bore radius 0.6 -> 1.0, axis tilted\n"
                   "0 -> 25 degrees), a tet mesh of G(0), and an absolute 10-step sweep to 100 %%\n"
                   "comparing rbf-s, project and rbf-s-biharmonic. Writes DIR/sweep.csv,\n"
                   "DIR/sweep.svg and the meshes at 50 and 100 %% (default DIR: cadmorph-demo).\n",
                   usage_line);
            return CLI_EXIT_OK;
        } else if (!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) {
            if (!(dir = cli_value(argc, argv, &i, "demo", usage_line))) return CLI_EXIT_USAGE;
        } else {
            return cli_usage("demo", usage_line, "unexpected argument '%s'", argv[i]);
        }
    }
    char *sweep[] = {"sweep", "bore", "--mesh", "tet", "--size", "0.3", "--mode", "absolute",
                     "--steps", "10", "-o", (char *)dir, NULL};
    const int n = (int)(sizeof sweep / sizeof *sweep) - 1;
    printf("cadmorph demo: running");
    for (int i = 0; i < n; ++i) printf(" %s", sweep[i]);
    printf("\n");
    fflush(stdout);
    int rc = cli_cmd_sweep(n, sweep);
    if (rc == CLI_EXIT_OK)
        printf("\nWritten to %s/: sweep.csv (quality per step and method), sweep.svg (the plot),\n"
               "<method>_absolute_050.vtu and _100.vtu (open in ParaView, colour by scaled_jacobian).\n",
               dir);
    return rc;
}
