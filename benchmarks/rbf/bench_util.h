/* What the RBF benchmarks share: CPU seconds and peak RSS of the process (getrusage), a
 * seeded uniform generator, and raw float64 files (the data sets of
 * bench_rbf_iterative_data.py / bench_rbf_surface_data.py). Header-only: each benchmark is one
 * executable. */
#ifndef CADMORPH_BENCH_UTIL_H
#define CADMORPH_BENCH_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>

/* CPU seconds of the process (user + system): on a shared machine the figure that the other
 * jobs disturb least. */
static inline double bench_cpu_seconds(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
           (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

static inline double bench_peak_rss_mb(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / 1024.0;
}

/* xorshift64 in [0, 1), the same sequence in every run */
static unsigned long long bench_rng = 0x9E3779B97F4A7C15ULL;
static inline double bench_urand(void)
{
    bench_rng ^= bench_rng << 13;
    bench_rng ^= bench_rng >> 7;
    bench_rng ^= bench_rng << 17;
    return (double)(bench_rng >> 11) * (1.0 / 9007199254740992.0);
}

/* The whole file at path (malloc'd, 8 bytes of slack), its size in *bytes; NULL if it cannot
 * be read. */
static inline double *bench_read_raw(const char *path, size_t *bytes)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    double *x = n >= 0 ? malloc((size_t)n + 8) : NULL;
    size_t got = x ? fread(x, 1, (size_t)n, f) : 0;
    fclose(f);
    if (!x || got != (size_t)n) {
        free(x);
        return NULL;
    }
    *bytes = (size_t)n;
    return x;
}

/* The set file PREFIX.ext as n x 3 doubles (*n: the rows); NULL if it cannot be read. */
static inline double *bench_read_xyz(const char *prefix, const char *ext, size_t *n)
{
    char path[4096];
    size_t bytes = 0;
    snprintf(path, sizeof path, "%s.%s", prefix, ext);
    double *x = bench_read_raw(path, &bytes);
    *n = bytes / (3 * sizeof(double));
    return x;
}

#endif
