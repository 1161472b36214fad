/* Placeholder until implemented. */
#include "cli.h"
#include <stdio.h>
int cli_cmd_warp(int argc, char **argv) { (void)argc; (void)argv; fprintf(stderr, "cadmorph warp: not implemented yet\n"); return CLI_EXIT_INTERNAL; }
