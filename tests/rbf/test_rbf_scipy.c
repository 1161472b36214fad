/* Writes random RBF problems and this library's solutions for the scipy cross-check
 * (rbf_scipy_check.py compares them with scipy.interpolate.RBFInterpolator).
 * usage: test_rbf_scipy DATA_DIR WORK_DIR -> WORK_DIR/rbf_scipy/<case>_{centres,values,
 * points,result}.txt */
#include "cadmorph/rbf.h"
#include "test_rng.h"
#include "test_util.h"

#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static uint64_t rng_state = 0x2545F4914F6CDD1DULL;

static double urand(void) { return test_rng_uniform(&rng_state); }

static int write_txt(const char *dir, const char *cs, const char *what, size_t rows, int cols,
                     const double *a)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s_%s.txt", dir, cs, what);
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    for (size_t i = 0; i < rows; ++i)
        for (int j = 0; j < cols; ++j)
            fprintf(f, "%.17g%c", a[i * (size_t)cols + (size_t)j], j + 1 < cols ? ' ' : '\n');
    return fclose(f);
}

static void run_case(cm_context *ctx, const char *dir, const char *name, cm_rbf_kernel kern,
                     size_t m, size_t n, int nc)
{
    const int dim = kern == CM_RBF_THIN_PLATE ? 2 : 3;
    static const double lo[3] = {-3.0, 2.0, 0.5}, len[3] = {6.0, 2.5, 1.5};
    double *c = malloc(m * dim * sizeof *c), *v = malloc(m * nc * sizeof *v);
    double *p = malloc(n * dim * sizeof *p), *out = malloc(n * nc * sizeof *out);
    for (size_t i = 0; i < m; ++i)
        for (int d = 0; d < dim; ++d) c[i * dim + d] = lo[d] + len[d] * urand();
    for (size_t i = 0; i < n; ++i)
        for (int d = 0; d < dim; ++d) p[i * dim + d] = lo[d] - 0.1 + (len[d] + 0.2) * urand();
    for (size_t i = 0; i < m; ++i)
        for (int r = 0; r < nc; ++r)
            v[i * nc + r] = sin(c[i * dim] + r) * cos(1.3 * c[i * dim + 1]) + 0.1 * urand();
    cm_rbf *rbf = NULL;
    cm_status st = cm_rbf_create(ctx, kern, dim, m, c, &rbf);
    if (st == CM_OK) st = cm_rbf_solve(ctx, rbf, nc, v);
    if (st == CM_OK) st = cm_rbf_evaluate(ctx, rbf, n, p, out);
    CHECK_MSG(st == CM_OK, "%s: %s", name, cm_context_message(ctx));
    CHECK(write_txt(dir, name, "centres", m, dim, c) == 0);
    CHECK(write_txt(dir, name, "values", m, nc, v) == 0);
    CHECK(write_txt(dir, name, "points", n, dim, p) == 0);
    CHECK(write_txt(dir, name, "result", n, nc, out) == 0);
    cm_rbf_destroy(&rbf);
    free(c), free(v), free(p), free(out);
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s DATA_DIR WORK_DIR\n", argv[0]);
        return 2;
    }
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/rbf_scipy", argv[2]);
    mkdir(dir, 0777);
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    run_case(ctx, dir, "cubic", CM_RBF_TRIHARMONIC, 400, 1000, 3);
    run_case(ctx, dir, "linear", CM_RBF_BIHARMONIC, 300, 800, 3);
    run_case(ctx, dir, "thin_plate_spline", CM_RBF_THIN_PLATE, 300, 1000, 2);
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
