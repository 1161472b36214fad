/* Placeholder until implemented. */
#include "cli.h"
#include <stdio.h>
int cli_cmd_quality(int argc, char **argv) { (void)argc; (void)argv; fprintf(stderr, "cadmorph quality: not implemented yet\n"); return CLI_EXIT_INTERNAL; }
