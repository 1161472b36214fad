/* Placeholder until implemented. */
#include "cli.h"
#include <stdio.h>
int cli_cmd_sweep(int argc, char **argv) { (void)argc; (void)argv; fprintf(stderr, "cadmorph sweep: not implemented yet\n"); return CLI_EXIT_INTERNAL; }
