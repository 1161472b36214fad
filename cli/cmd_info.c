/* Placeholder until implemented. */
#include "cli.h"
#include <stdio.h>
int cli_cmd_info(int argc, char **argv) { (void)argc; (void)argv; fprintf(stderr, "cadmorph info: not implemented yet\n"); return CLI_EXIT_INTERNAL; }
