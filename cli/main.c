/* The cadmorph program: picks the subcommand; each lives in its own cmd_<name>.c. */
#include "cli.h"

#include "cadmorph/parallel.h"
#include "cadmorph/version.h"

#include <signal.h>
#include <stdio.h>
#include <string.h>

typedef struct cli_command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} cli_command;

static const cli_command commands[] = {
    {"morph", cli_cmd_morph, "morph a mesh of G0.step onto G1.step (surface on the CAD, interior by RBF)"},
    {"study", cli_cmd_study, "morph a mesh onto every STEP file of a list (a design table), compare methods"},
    {"sensitivity", cli_cmd_sensitivity, "design velocities dX/dp of a mesh for a CAD design table, gradients dJ/dp"},
    {"sweep", cli_cmd_sweep, "Staten-style study: morph a benchmark model over its parameter change"},
    {"demo", cli_cmd_demo, "the embedded example: bore model, tet mesh, 10-step absolute sweep"},
    {"quality", cli_cmd_quality, "scaled Jacobian report of a mesh; --foam: OpenFOAM checkMesh's metrics"},
    {"deform", cli_cmd_deform, "handle-based deformation of a surface or volume mesh (RBF, MLS, DM-FFD, shell)"},
    {"warp", cli_cmd_warp, "move interior nodes by a warp of boundary displacements (RBF, FEMWARP, DM-FFD, ...)"},
    {"ffd", cli_cmd_ffd, "free-form deformation of a mesh by a control lattice (PyGeM .prm accepted)"},
    {"detect", cli_cmd_detect, "planes, cylinders, spheres, cones of a surface mesh (efficient RANSAC)"},
    {"mesh", cli_cmd_mesh, "tet mesh of a STEP solid (gmsh by default, or TetGen)"},
    {"optimize", cli_cmd_optimize, "move interior nodes to untangle and raise the worst cells"},
    {"info", cli_cmd_info, "topology summary of a STEP file, correspondence with another"},
    {"model", cli_cmd_model, "a built-in model (bore, pipe, bracket) at parameter T as STEP, its hex mesh"},
};

static int usage(FILE *out)
{
    fprintf(out, "usage: cadmorph <command> [options]\n\ncommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof *commands; ++i)
        fprintf(out, "  %-10s %s\n", commands[i].name, commands[i].summary);
    fprintf(out, "\n'cadmorph <command> --help' describes a command.\n");
    return out == stdout ? 0 : 1;
}

/* An interrupted write must not leave its temporary file behind: remove the live temporaries,
 * then die of the same signal (default action) so that the caller sees how we ended. */
static void on_signal(int sig)
{
    if (cm_output_signal(sig)) return; /* raised again when the renames under way are done */
    cm_outfile_unlink_all();
    signal(sig, SIG_DFL);
    raise(sig);
}

static void install_signal_handlers(void)
{
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    for (size_t i = 0; i < sizeof sigs / sizeof *sigs; ++i) {
        struct sigaction sa, old;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigemptyset(&sa.sa_mask);
        /* a signal the caller chose to ignore (nohup) stays ignored */
        if (sigaction(sigs[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN) continue;
        sigaction(sigs[i], &sa, NULL);
    }
}

int main(int argc, char **argv)
{
    cli_blas_setup(argc, argv);
    install_signal_handlers();
    if (argc < 2) return usage(stderr);
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "help"))
        return usage(stdout);
    if (!strcmp(argv[1], "--version")) {
        printf("cadmorph %s\n", cm_version());
        cli_blas_print_version(stdout);
        return 0;
    }
    for (size_t i = 0; i < sizeof commands / sizeof *commands; ++i)
        if (!strcmp(argv[1], commands[i].name)) {
            int rc = commands[i].run(argc - 1, argv + 1);
            cm_parallel_finalize(); /* MPI must end before the process does (--solver petsc) */
            return rc;
        }
    fprintf(stderr, "cadmorph: unknown command '%s'\n", argv[1]);
    return usage(stderr);
}
