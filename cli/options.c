/* The table-driven option parser of the subcommands (options.h). */
#include "options.h"

#include "cli.h"

#include "cadmorph/parallel.h"
#include "cadmorph/study.h"
#include "cadmorph/warp.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int takes_value(const cli_option *o)
{
    switch (o->kind) {
    case CLI_FLAG:
    case CLI_HELP:
    case CLI_NOTE:
        return 0;
    case CLI_CUSTOM:
        return o->takes_value;
    default:
        return 1;
    }
}

static int bad_value(const cli_parser *p, const cli_option *o, const char *opt, const char *v)
{
    return cli_usage(p->cmd, p->usage, o->bad ? o->bad : "%s: bad value '%s'", opt, v);
}

static int set_value(const cli_parser *p, const cli_option *o, const char *opt, const char *v)
{
    char *end = NULL;
    switch (o->kind) {
    case CLI_FLAG:
        *(int *)o->dest = 1;
        return 0;
    case CLI_STRING:
        *(const char **)o->dest = v;
        return 0;
    case CLI_THREADS:
        return cli_threads_parse(p->cmd, p->usage, v, (int *)o->dest) ? CLI_EXIT_USAGE : 0;
    case CLI_INT: {
        errno = 0;
        const long n = strtol(v, &end, 10);
        if (errno || end == v || *end || n < o->lo || n > o->hi) return bad_value(p, o, opt, v);
        *(int *)o->dest = (int)n;
        return 0;
    }
    case CLI_DOUBLE: {
        errno = 0;
        const double x = strtod(v, &end);
        int ok = !errno && end != v && !*end && isfinite(x);
        if (ok && !isnan(o->lo)) ok = (o->open & 1) ? x > o->lo : x >= o->lo;
        if (ok && !isnan(o->hi)) ok = (o->open & 2) ? x < o->hi : x <= o->hi;
        if (!ok) return bad_value(p, o, opt, v);
        *(double *)o->dest = x;
        return 0;
    }
    case CLI_ENUM:
        for (int k = 0; o->names[k]; ++k)
            if (!strcmp(v, o->names[k])) {
                *(int *)o->dest = o->values[k];
                return 0;
            }
        return bad_value(p, o, opt, v);
    case CLI_CUSTOM:
        return o->parse(p, o, v, o->dest);
    case CLI_HELP:
        return p->help();
    case CLI_NOTE:
        break;
    }
    return CLI_EXIT_INTERNAL;
}

int cli_parse(cli_parser *p, int argc, char **argv)
{
    p->n_pos = 0;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        const cli_option *o = p->options;
        if (a[0] == '-' && a[1] != '\0')
            while (o->name && (o->kind == CLI_NOTE ||
                               (strcmp(a, o->name) && !(o->alias && !strcmp(a, o->alias)))))
                ++o;
        if (a[0] == '-' && a[1] != '\0' && !o->name)
            return cli_usage(p->cmd, p->usage, p->unknown, a);
        if (a[0] != '-' || a[1] == '\0') { /* a positional argument ("-" is one too) */
            if (p->n_pos >= p->max_pos)
                return cli_usage(p->cmd, p->usage, p->max_pos ? p->extra : p->unknown, a);
            p->pos[p->n_pos++] = a;
            continue;
        }
        if (o->kind == CLI_HELP) return p->help();
        const char *v = NULL;
        if (takes_value(o)) {
            if (i + 1 >= argc) return cli_usage(p->cmd, p->usage, "option %s needs a value", a);
            v = argv[++i];
        }
        const int rc = set_value(p, o, a, v);
        if (rc) return rc;
    }
    return -1;
}

void cli_print_options(FILE *out, const cli_option *options, int width)
{
    for (const cli_option *o = options; o->name; ++o) {
        if (!o->label) continue;
        char text[2048];
        snprintf(text, sizeof text, o->help, o->help_arg ? o->help_arg() : "");
        fprintf(out, "  %-*s", width, o->label);
        for (const char *c = text; *c; ++c) /* continuation lines start under the column */
            if (*c == '\n')
                fprintf(out, "\n%*s", width + 2, "");
            else
                fputc(*c, out);
        fputc('\n', out);
    }
}

int cli_parse_warp_method(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    (void)o;
    const int m = cm_warp_method_from_name(v);
    if (m < 0)
        return cli_usage(p->cmd, p->usage, "unknown method '%s' (%s)", v, cm_warp_method_list());
    *(cm_warp_method *)dest = (cm_warp_method)m;
    return 0;
}

int cli_parse_size(const cli_parser *p, const cli_option *o, const char *v, void *dest)
{
    char *end = NULL;
    errno = 0;
    const long long n = strtoll(v, &end, 10);
    if (errno || end == v || *end || n < 1 || n > 100000000)
        return cli_usage(p->cmd, p->usage, "%s: expected an integer in 1..1e8, got '%s'", o->name, v);
    *(size_t *)dest = (size_t)n;
    return 0;
}

const char *const cli_kernel_names[] = {"triharmonic", "biharmonic", NULL};
const char *const cli_solver_names[] = {"auto", "dense", "iterative", "petsc", NULL};
const int cli_solver_values[] = {CM_RBF_SOLVER_AUTO, CM_RBF_SOLVER_DENSE, CM_RBF_SOLVER_ITERATIVE,
                                 CM_RBF_SOLVER_PETSC};

int cli_check_solver(const char *cmd, const char *usage, int solver)
{
    if (solver == CM_RBF_SOLVER_PETSC && !cm_parallel_available())
        return cli_usage(cmd, usage, "--solver petsc: this cadmorph was built without PETSc "
                         "(configure with -DCADMORPH_WITH_PETSC=ON)");
    return -1;
}

int cli_mpi_ranks(cm_context *ctx, const char *cmd, int *rank, int *ranks)
{
    *rank = 0;
    *ranks = 1;
    const char *v = getenv("OMPI_COMM_WORLD_SIZE");
    if (!v) v = getenv("PMI_SIZE");
    if (!v || atoi(v) <= 1) return 0;
    if (!cm_parallel_available()) {
        fprintf(stderr, "cadmorph %s: started by mpirun with %s ranks, but this cadmorph was "
                "built without PETSc/MPI (configure with -DCADMORPH_WITH_PETSC=ON)\n", cmd, v);
        return CLI_EXIT_USAGE;
    }
    cm_status s = cm_parallel_initialize(ctx);
    if (s < 0) return cli_fail(ctx, cmd, s);
    cm_parallel_rank(rank, ranks);
    return 0;
}

int cli_output_rank(void)
{
    int rank;
    cm_parallel_rank(&rank, NULL);
    return rank == 0;
}
const int cli_kernel_methods[] = {CM_WARP_RBF, CM_WARP_RBF_BIHARMONIC};
const char *const cli_study_mode_names[] = {"absolute", "relative", "both", NULL};
const int cli_study_mode_values[] = {CM_STUDY_ABSOLUTE, CM_STUDY_RELATIVE, CM_STUDY_BOTH};
