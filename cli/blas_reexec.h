/* OpenBLAS set-up at program start, shared by cadmorph and the benchmark programs (a timing
 * on OpenBLAS's Prescott kernels, which it picks on Sapphire-Rapids-class Xeons, says nothing
 * about the tool: benchmarks/RESULTS.md). */
#ifndef CADMORPH_CLI_BLAS_REEXEC_H
#define CADMORPH_CLI_BLAS_REEXEC_H

#include <stdio.h>

/* First thing in main: may execute the program again with OPENBLAS_CORETYPE and
 * OPENBLAS_NUM_THREADS set (blas.h); says so under --verbose. */
void cli_blas_setup(int argc, char **argv);
/* The BLAS lines of --version: library, core (and who chose it), threads. */
void cli_blas_print_version(FILE *out);

#endif
