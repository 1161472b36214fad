/* `cadmorph demo`: the embedded example, end to end: the bore benchmark model, a tet mesh of
 * G(0) by OpenCASCADE + TetGen, and an absolute 10-step sweep to the full parameter change
 * with the three methods compared. It is `cadmorph sweep` with fixed arguments, printed first
 * so that a user can vary them. */
#include "cli.h"
#include "options.h"

#include <stdio.h>
#include <string.h>

static const char *const usage_line = "cadmorph demo [-o DIR]";

static const char *dir;

static int help(void)
{
    printf("usage: %s\n\nThe bore model (4 x 4 x 2 block, bore radius 0.6 -> 1.0, axis tilted\n"
           "0 -> 25 degrees), a tet mesh of G(0), and an absolute 10-step sweep to 100 %%\n"
           "comparing rbf-s, project and rbf-s-biharmonic. Writes DIR/sweep.csv,\n"
           "DIR/sweep.svg and the meshes at 50 and 100 %% (default DIR: cadmorph-demo).\n",
           usage_line);
    return CLI_EXIT_OK;
}

static const cli_option options[] = {
    {.name = "--help", .alias = "-h", .kind = CLI_HELP},
    {.name = "-o", .alias = "--output", .kind = CLI_STRING, .dest = &dir},
    {0}};

int cli_cmd_demo(int argc, char **argv)
{
    dir = "cadmorph-demo";
    cli_parser p = {.cmd = "demo", .usage = usage_line, .options = options, .help = help,
                    .unknown = "unexpected argument '%s'"};
    const int parsed = cli_parse(&p, argc, argv);
    if (parsed >= 0) return parsed;
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
