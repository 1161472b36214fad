/* Exit codes, error lines, progress drawing and path checks shared by the subcommands. */
#include "cli.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

typedef struct cli_sink {
    int verbose;
    int tty;
    double last_draw;
    /* a study (stage "study", done/total = variants) under way: its start, and whether the
     * inner stages (a morph of each variant) should stay off the line */
    int in_study;
    double study_start, study_done, study_total;
    double study_mark, per_variant; /* the last report's time; seconds per variant since the
                                       one before (a batch reports once for its variants) */
    char inner[32];                 /* the inner stage last reported in a study, and its part
                                       done: a batch of variants is one long step of the study */
    double inner_part;
} cli_sink;

static cli_sink sink;

/* --threads above this many per online core is refused. */
#define CLI_THREADS_PER_CORE 4

static void log_to_stderr(void *user, cm_log_level level, const char *message)
{
    cli_sink *s = user;
    if (level == CM_LOG_DEBUG && !s->verbose) return;
    if (s->tty) fputs("\r\033[K", stderr);
    fprintf(stderr, "%s%s\n", level == CM_LOG_WARNING ? "warning: " : "", message);
}

/* "42 s", "3m05s", "2h10m" */
static void format_duration(double sec, char *buf, size_t size)
{
    long s = (long)(sec + 0.5);
    if (s < 60)
        snprintf(buf, size, "%ld s", s);
    else if (s < 3600)
        snprintf(buf, size, "%ldm%02lds", s / 60, s % 60);
    else
        snprintf(buf, size, "%ldh%02ldm", s / 3600, (s % 3600) / 60);
}

/* "study 3/20 variants, last 4.1 s per variant, about 1m20s left": the time left from the
 * mean time per variant so far (variants of one study cost about the same). Before the first
 * batch is done, the time it has run ("1m12s so far"): one batch may be the whole study. */
static void draw_study(cli_sink *s, double now)
{
    char left[64] = "estimating the time left", last[48] = "", d[24];
    const double run = now - s->study_start;
    if (s->study_done > 0) {
        format_duration(run / s->study_done * (s->study_total - s->study_done), d, sizeof d);
        snprintf(left, sizeof left, "about %s left", d);
    } else if (run >= 1.0) {
        format_duration(run, d, sizeof d);
        snprintf(left, sizeof left, "%s so far, estimating the time left", d);
    }
    if (s->per_variant > 0) {
        if (s->per_variant < 10)
            snprintf(d, sizeof d, "%.2g s", s->per_variant);
        else
            format_duration(s->per_variant, d, sizeof d);
        snprintf(last, sizeof last, "last %s per variant, ", d);
    }
    fprintf(stderr, "\r\033[Kstudy %.0f/%.0f variants, %s%s", s->study_done, s->study_total,
            last, left);
    if (s->inner[0]) fprintf(stderr, " (%s %.0f%%)", s->inner, 100.0 * s->inner_part);
}

static void progress_to_stderr(void *user, const char *stage, double done, double total)
{
    cli_sink *s = user;
    if (!s->tty) return;
    double now = cm_wtime();
    int finished = done >= total;
    if (!strcmp(stage, "study")) {
        if (!s->in_study || done < s->study_done) {
            s->study_start = s->study_mark = now;
            s->per_variant = 0;
        } else if (done > s->study_done) {
            s->per_variant = (now - s->study_mark) / (done - s->study_done);
            s->study_mark = now;
        }
        s->in_study = !finished;
        s->study_done = done;
        s->study_total = total;
        s->inner[0] = '\0';
    } else if (s->in_study) {
        snprintf(s->inner, sizeof s->inner, "%s", stage);
        s->inner_part = total > 0 ? fmin(done / total, 1.0) : 1.0;
        if (now - s->last_draw < 1.0) return; /* the estimate moves with the variants */
    }
    if (!finished && now - s->last_draw < 0.1) return;
    s->last_draw = now;
    if (s->in_study)
        draw_study(s, now);
    else
        fprintf(stderr, "\r\033[K%s %5.1f%%", stage, total > 0 ? 100.0 * done / total : 100.0);
    if (finished && !s->in_study) fputs("\r\033[K", stderr);
    fflush(stderr);
}

cm_context *cli_context_create(const char *cmd, int verbose, int threads)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) {
        fprintf(stderr, "cadmorph %s: out of memory\n", cmd);
        return NULL;
    }
    cm_context_set_threads(ctx, threads);
    sink.verbose = verbose;
    sink.tty = isatty(fileno(stderr));
    cm_context_set_log(ctx, log_to_stderr, &sink);
    cm_context_set_progress(ctx, progress_to_stderr, &sink);
    return ctx;
}

int cli_fail(cm_context *ctx, const char *cmd, cm_status s)
{
    const char *msg = cm_context_message(ctx);
    fprintf(stderr, "cadmorph %s: %s\n", cmd, msg && *msg ? msg : cm_status_name(s));
    if (s == CM_ERR_ARGUMENT) return CLI_EXIT_USAGE;
    if (s == CM_ERR_REJECTED) return CLI_EXIT_REJECTED;
    if (s == CM_ERR_INTERRUPTED) return CLI_EXIT_INTERRUPTED;
    return cm_status_is_input_error(s) ? CLI_EXIT_BAD_INPUT : CLI_EXIT_INTERNAL;
}

int cli_usage(const char *cmd, const char *usage, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "cadmorph %s: ", cmd);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\nusage: %s\n", usage);
    return CLI_EXIT_USAGE;
}

int cli_make_dir(const char *cmd, const char *dir)
{
    char path[4096];
    if (snprintf(path, sizeof path, "%s", dir) >= (int)sizeof path) {
        fprintf(stderr, "cadmorph %s: output directory name too long\n", cmd);
        return CLI_EXIT_BAD_INPUT;
    }
    for (char *p = path + 1;; ++p) {
        if (*p != '/' && *p) continue;
        char c = *p;
        *p = 0;
        struct stat st;
        if (stat(path, &st) != 0) {
            if (mkdir(path, 0777) != 0 && errno != EEXIST) {
                fprintf(stderr, "cadmorph %s: cannot create %s: %s\n", cmd, path, strerror(errno));
                return CLI_EXIT_BAD_INPUT;
            }
        } else if (!S_ISDIR(st.st_mode)) {
            fprintf(stderr, "cadmorph %s: %s exists and is not a directory\n", cmd, path);
            return CLI_EXIT_BAD_INPUT;
        }
        *p = c;
        if (!c) return 0;
    }
}

int cli_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0) return strcmp(a, b) == 0;
    return cm_same_file(a, b);
}

int cli_outdir_begin(cm_context *ctx, const char *cmd, const char *dir, const char *const *names,
                     const char *const *inputs, size_t n, cm_outdir *od)
{
    memset(od, 0, sizeof *od);
    for (size_t k = 0; names && names[k]; ++k) {
        char path[4200];
        if (snprintf(path, sizeof path, "%s/%s", dir, names[k]) >= (int)sizeof path) {
            fprintf(stderr, "cadmorph %s: output directory name too long\n", cmd);
            return CLI_EXIT_BAD_INPUT;
        }
        for (size_t j = 0; j < n; ++j)
            if (inputs[j] && cm_same_file(path, inputs[j])) {
                fprintf(stderr, "cadmorph %s: output %s is the input %s: refusing to overwrite it\n",
                        cmd, path, inputs[j]);
                return CLI_EXIT_USAGE;
            }
    }
    struct stat st;
    cm_status s;
    if (stat(dir, &st) == 0 && S_ISDIR(st.st_mode)) {
        /* an existing DIR: the temporary inside it (one file system for the renames) */
        char inside[4200];
        snprintf(inside, sizeof inside, "%s/.cm", dir);
        s = cm_outdir_open(ctx, inside, od);
    } else {
        s = cm_outdir_open(ctx, dir, od);
    }
    return s < 0 ? cli_fail(ctx, cmd, s) : 0;
}

/* The case directory an OpenFOAM path names: "X/", "X/constant/polyMesh" and the pieces
 * "X/processor*" all name X. 0, or -1 if it does not fit. */
static int foam_case_root(const char *path, char *out, size_t cap)
{
    size_t len = strlen(path);
    if (len >= cap) return -1;
    memcpy(out, path, len + 1);
    static const char *const tails[] = {"/", "/processor*", "/polyMesh", "/constant"};
    for (int t = 0; t < 4; ++t) {
        const size_t k = strlen(tails[t]);
        while (len > k && memcmp(out + len - k, tails[t], k) == 0)
            out[len -= k] = '\0';
    }
    return 0;
}

/* 1 when out and in name the same OpenFOAM case: writing there replaces its points in place,
 * the way OpenFOAM's own moveMesh does (docs/DESIGN.md, "Command line contract"). */
static int same_foam_case(const char *out, const char *in)
{
    char a[4096], b[4096];
    return cm_mesh_format_from_path(out) == CM_FORMAT_FOAM &&
           cm_mesh_format_from_path(in) == CM_FORMAT_FOAM && foam_case_root(out, a, sizeof a) == 0 &&
           foam_case_root(in, b, sizeof b) == 0 && cli_same_file(a, b);
}

int cli_check_mesh_output(const char *cmd, const char *usage, const char *out,
                          const char *const *inputs, size_t n)
{
    if (cm_mesh_format_from_path(out) == CM_FORMAT_UNKNOWN)
        return cli_usage(cmd, usage, "%s: unknown mesh extension (%s)", out,
                         cm_mesh_format_list());
    for (size_t k = 0; k < n; ++k)
        if (inputs[k] && !same_foam_case(out, inputs[k]) && cli_same_file(out, inputs[k]))
            return cli_usage(cmd, usage, "output %s is an input: refusing to overwrite it", out);
    return 0;
}

int cli_threads_value(int argc, char **argv, int *i, const char *cmd, const char *usage,
                      int *threads)
{
    const char *v = cli_value(argc, argv, i, cmd, usage);
    if (!v) return CLI_EXIT_USAGE;
    return cli_threads_parse(cmd, usage, v, threads);
}

int cli_threads_parse(const char *cmd, const char *usage, const char *v, int *threads)
{
    char *end = NULL;
    errno = 0;
    long t = strtol(v, &end, 10);
    if (errno || end == v || *end || t < 1)
        return cli_usage(cmd, usage, "--threads needs a positive integer, got '%s'", v);
    /* libgomp aborts the process when it cannot create a thread (512 did on 2 cores); more
     * than a few threads per core only costs, so refuse them here with a message */
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    if (cores < 1) cores = 1;
    if (t > CLI_THREADS_PER_CORE * cores)
        return cli_usage(cmd, usage, "--threads %ld is more than %d per core (%ld cores: at most %ld)",
                         t, CLI_THREADS_PER_CORE, cores, CLI_THREADS_PER_CORE * cores);
    *threads = (int)t;
    return 0;
}

const char *cli_value(int argc, char **argv, int *i, const char *cmd, const char *usage)
{
    if (*i + 1 >= argc) {
        cli_usage(cmd, usage, "option %s needs a value", argv[*i]);
        return NULL;
    }
    return argv[++*i];
}

void cli_print_quality_line(FILE *out, const cm_quality_stats *all)
{
    fprintf(out, "min_scaled_jacobian=%.6g mean_scaled_jacobian=%.6g inverted=%zu cells=%zu\n", all->min,
            all->mean, all->inverted, all->count);
}

size_t cli_warn_inverted(const char *cmd, const cm_mesh *mesh, const double *sj)
{
    /* the cells a solver rejects (cm_mesh_invalid_cells, docs/DESIGN.md): on a polyMesh and
     * for polyhedra checkMesh's negative volume or wrongly oriented face, not the scaled
     * Jacobian of our tet decomposition */
    uint8_t *flag = malloc(mesh->n_cells ? mesh->n_cells : 1);
    cm_context *ctx = NULL;
    size_t n = 0, worst = (size_t)-1;
    if (!flag || cm_context_create(&ctx) != CM_OK || cm_mesh_invalid_cells(ctx, mesh, sj, flag, &n) < 0) {
        fprintf(stderr, "cadmorph %s: warning: could not count the inverted cells (out of memory)\n", cmd);
        free(flag);
        cm_context_destroy(&ctx);
        return 0;
    }
    cm_context_destroy(&ctx);
    double wv = INFINITY;
    size_t by_faces = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (!flag[c]) continue;
        by_faces += flag[c] == 2;
        /* the worst: the lowest scaled Jacobian among them (NaN, undefined, first) */
        const double v = isnan(sj[c]) ? -INFINITY : fabs(sj[c]) >= 1e30 ? 0.0 : sj[c];
        if (worst == (size_t)-1 || v < wv) wv = v, worst = c;
    }
    free(flag);
    if (n == 0) return 0;
    double centre[3] = {0, 0, 0};
    const cm_cell_type type = (cm_cell_type)mesh->type[worst];
    if (type == CM_CELL_POLYHEDRON) {
        /* the average of its face streams' nodes */
        const int64_t *st = mesh->conn + mesh->offset[worst];
        int64_t nf = st[0], k = 1, cnt = 0;
        for (int64_t f = 0; f < nf; ++f) {
            const int64_t m = st[k++];
            for (int64_t i = 0; i < m; ++i, ++cnt)
                for (int d = 0; d < 3; ++d) centre[d] += mesh->xyz[3 * st[k + i] + d];
            k += m;
        }
        for (int d = 0; d < 3; ++d) centre[d] /= (double)(cnt ? cnt : 1);
    } else {
        const int64_t *nodes = mesh->conn + mesh->offset[worst];
        const int64_t k = mesh->offset[worst + 1] - mesh->offset[worst];
        for (int64_t i = 0; i < k; ++i)
            for (int d = 0; d < 3; ++d) centre[d] += mesh->xyz[3 * nodes[i] + d] / (double)k;
    }
    /* the rule that made them inverted: docs/DESIGN.md, "What counts as an inverted cell" */
    char why[200];
    if (by_faces == 0)
        snprintf(why, sizeof why, "scaled Jacobian <= 0");
    else if (by_faces == n)
        snprintf(why, sizeof why, "a negative volume or a wrongly oriented face, as checkMesh finds them");
    else
        snprintf(why, sizeof why,
                 "%zu with a negative volume or a wrongly oriented face as checkMesh finds them, %zu with "
                 "scaled Jacobian <= 0",
                 by_faces, n - by_faces);
    fprintf(stderr,
            "cadmorph %s: warning: %zu inverted cell%s (%s); the worst is cell %zu (0-based, %s, scaled "
            "Jacobian %.6g) at (%.6g, %.6g, %.6g); inverted: cells a solver rejects\n",
            cmd, n, n == 1 ? "" : "s", why, worst, cm_cell_type_info(type)->name, isnan(sj[worst]) ? NAN : wv,
            centre[0], centre[1], centre[2]);
    return n;
}

cm_status cli_print_quality(cm_context *ctx, const cm_mesh *mesh, const double *sj, FILE *out,
                            cm_quality_stats *all_out)
{
    cm_quality_stats per[CM_CELL_TYPE_COUNT], all;
    cm_status s = cm_quality_summarize(ctx, mesh, sj, per, &all);
    if (s < 0) return s;
    fprintf(out, "%-12s %10s %12s %12s %12s %10s\n", "type", "cells", "min_sj", "mean_sj", "p01_sj",
            "inverted");
    for (int t = 0; t < CM_CELL_TYPE_COUNT; ++t) {
        if (per[t].count == 0) continue;
        fprintf(out, "%-12s %10zu %12.6g %12.6g %12.6g %10zu\n", cm_cell_type_info((cm_cell_type)t)->name,
                per[t].count, per[t].min, per[t].mean, per[t].p01, per[t].inverted);
    }
    cli_print_quality_line(out, &all);
    if (all_out) *all_out = all;
    return s;
}
