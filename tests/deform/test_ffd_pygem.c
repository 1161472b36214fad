/* The PyGeM cross-check [PyGeM]: PyGeM's FFD (Bernstein, rotated box) against numbers PyGeM produced,
 * stored with the script that made them (tests/data/deform/make_pygem_fixture.py): the .prm
 * files are PyGeM's own write_parameters output, so the reader is checked on them too. At 4
 * control points per axis the clamped cubic B-spline is the cubic Bernstein basis: the same
 * numbers again. Also the reader's error paths. */
#include "test_util.h"

#include "cadmorph/deform.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static cm_context *ctx;
static const char *data_dir, *work_dir;

/* Reads x,y,z,xd,yd,zd rows. */
static size_t read_csv(const char *path, double **x, double **y)
{
    FILE *f = fopen(path, "r");
    if (!f) return 0;
    char line[1024];
    size_t n = 0, cap = 256;
    *x = malloc(cap * 3 * sizeof **x);
    *y = malloc(cap * 3 * sizeof **y);
    if (!fgets(line, sizeof line, f)) n = 0; /* header */
    double v[6];
    while (fgets(line, sizeof line, f) &&
           sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf", v, v + 1, v + 2, v + 3, v + 4, v + 5) == 6) {
        if (n == cap) {
            cap *= 2;
            *x = realloc(*x, cap * 3 * sizeof **x);
            *y = realloc(*y, cap * 3 * sizeof **y);
        }
        memcpy(*x + 3 * n, v, 3 * sizeof *v);
        memcpy(*y + 3 * n, v + 3, 3 * sizeof *v);
        ++n;
    }
    fclose(f);
    return n;
}

static void check_case(const char *name, int expect_n)
{
    char prm_path[1024], csv_path[1024];
    snprintf(prm_path, sizeof prm_path, "%s/deform/%s.prm", data_dir, name);
    snprintf(csv_path, sizeof csv_path, "%s/deform/%s.csv", data_dir, name);
    cm_ffd_prm prm;
    cm_status s = cm_ffd_prm_read(ctx, prm_path, &prm);
    CHECK_MSG(s == CM_OK, "%s: %s", name, cm_context_message(ctx));
    if (s != CM_OK) return;
    CHECK(prm.n[0] * prm.n[1] * prm.n[2] == expect_n);
    double *x = NULL, *y = NULL;
    size_t n = read_csv(csv_path, &x, &y);
    CHECK_MSG(n >= 100, "%s: %zu rows", csv_path, n);
    size_t nc = (size_t)prm.n[0] * prm.n[1] * prm.n[2];
    double *dc = malloc(nc * 3 * sizeof *dc), *d = malloc(n * 3 * sizeof *d);
    int rounds = prm.n[0] == 4 && prm.n[1] == 4 && prm.n[2] == 4 ? 2 : 1;
    for (int r = 0; r < rounds; ++r) {
        cm_ffd_desc desc;
        cm_ffd_prm_desc(&prm, CM_FFD_BERNSTEIN, &desc, dc);
        if (r == 1) { /* the clamped cubic B-spline on 4 points is the cubic Bernstein */
            desc.basis = CM_FFD_BSPLINE;
            desc.knots = CM_FFD_KNOTS_CLAMPED;
        }
        cm_ffd *f = NULL;
        CHECK(cm_ffd_create(ctx, &desc, &f) == CM_OK);
        cm_ffd_stats st;
        CHECK(cm_ffd_deform(ctx, f, dc, n, x, d, &st) == CM_OK);
        double worst = 0, dmax = 0;
        size_t moved_pygem = 0, unchanged_exact = 0, out = 0;
        for (size_t i = 0; i < n; ++i) {
            int pm = 0;
            for (int c = 0; c < 3; ++c) {
                double e = x[3 * i + c] + d[3 * i + c];
                worst = fmax(worst, fabs(e - y[3 * i + c]));
                dmax = fmax(dmax, fabs(y[3 * i + c] - x[3 * i + c]));
                pm |= y[3 * i + c] != x[3 * i + c];
            }
            moved_pygem += pm;
            if (!pm) {
                ++out;
                unchanged_exact += d[3 * i] == 0 && d[3 * i + 1] == 0 && d[3 * i + 2] == 0;
            }
        }
        printf("pygem %s (%s): %zu points, %zu moved by PyGeM, %zu inside here; max |ours - "
               "pygem| = %.3g (max |d| %.3g)\n",
               name, r ? "clamped B-spline" : "Bernstein", n, moved_pygem, st.inside, worst, dmax);
        CHECK_MSG(worst <= 1e-13, "%s: %g", name, worst);
        CHECK(st.inside == moved_pygem);
        CHECK(unchanged_exact == out && out > 0);
        cm_ffd_destroy(&f);
    }
    free(dc);
    free(d);
    free(x);
    free(y);
    cm_ffd_prm_free(&prm);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    fputs(text, f);
    fclose(f);
}

static void test_reader_errors(void)
{
    cm_ffd_prm prm;
    char path[1024];
    snprintf(path, sizeof path, "%s/ffd_missing.prm", work_dir);
    remove(path);
    CHECK(cm_ffd_prm_read(ctx, path, &prm) == CM_ERR_IO);
    FILE *f = fopen(path, "r");
    CHECK(f == NULL); /* PyGeM would have written a default file here */
    if (f) fclose(f);

    const char *box = "[Box info]\nn control points x: 2\nn control points y: 2\n"
                      "n control points z: 2\nbox length x: 1\nbox length y: 1\nbox length z: 1\n"
                      "box origin x: 0\nbox origin y: 0\nbox origin z: 0\nrotation angle x: 0\n"
                      "rotation angle y: 0\nrotation angle z: 0\n";
    char text[4096];
    snprintf(path, sizeof path, "%s/ffd_bad.prm", work_dir);
    /* index out of range */
    snprintf(text, sizeof text,
             "%s[Parameters weights]\nparameter x: 0 0 0 0.5\n  2 0 0 1\nparameter y: 0 0 0 0\n"
             "parameter z: 0 0 0 0\n",
             box);
    write_file(path, text);
    CHECK(cm_ffd_prm_read(ctx, path, &prm) == CM_ERR_FORMAT);
    CHECK(strstr(cm_context_message(ctx), ":16:") != NULL);
    /* not a number */
    snprintf(text, sizeof text,
             "%s[Parameters weights]\nparameter x: 0 0 0 abc\nparameter y: 0 0 0 0\n"
             "parameter z: 0 0 0 0\n",
             box);
    write_file(path, text);
    CHECK(cm_ffd_prm_read(ctx, path, &prm) == CM_ERR_FORMAT);
    /* missing key */
    write_file(path, "[Box info]\nn control points x: 2\n");
    CHECK(cm_ffd_prm_read(ctx, path, &prm) == CM_ERR_FORMAT);
    CHECK(strstr(cm_context_message(ctx), "n control points y") != NULL);
    /* finite weights the lattice cannot apply: times the box length they overflow (1e308 x 2)
     * or leave coordinates whose cubes do (1e200): refused at their line */
    const char *huge[] = {"1e308", "-1e200", "1.7976931348623157e308"};
    for (int h = 0; h < 3; ++h) {
        char big_box[1024];
        snprintf(big_box, sizeof big_box, "%s", box);
        char *lx = strstr(big_box, "box length x: 1");
        if (lx) lx[14] = '2';
        snprintf(text, sizeof text,
                 "%s[Parameters weights]\nparameter x: 0 0 0 0\n  1 0 1 %s\nparameter y: 0 0 0 0\n"
                 "parameter z: 0 0 0 0\n",
                 big_box, huge[h]);
        write_file(path, text);
        CHECK(cm_ffd_prm_read(ctx, path, &prm) == CM_ERR_FORMAT);
        CHECK_MSG(strstr(cm_context_message(ctx), "ffd_bad.prm:16: weight") &&
                      strstr(cm_context_message(ctx), "control point (1, 0, 1) along x") &&
                      strstr(cm_context_message(ctx), "beyond any mesh"),
                  "%s", cm_context_message(ctx));
        CHECK(prm.mu == NULL);
    }
    /* a flat box (no lattice), a box no mesh fits in, a non-finite origin */
    const char *boxes[][2] = {{"box length y: 1", "box length y: 0"},
                              {"box length z: 1", "box length z: 1e151"},
                              {"box origin x: 0", "box origin x: nan"}};
    const char *why[] = {":6: 'box length y' is 0", ":7: 'box length z' is 1e+151, beyond any mesh",
                         ":8: 'box origin x' is not a number"};
    for (int b = 0; b < 3; ++b) {
        char bad_box[1024];
        const char *at = strstr(box, boxes[b][0]);
        snprintf(bad_box, sizeof bad_box, "%.*s%s%s", (int)(at - box), box, boxes[b][1],
                 at + strlen(boxes[b][0]));
        snprintf(text, sizeof text,
                 "%s[Parameters weights]\nparameter x: 0 0 0 0.5\nparameter y: 0 0 0 0\n"
                 "parameter z: 0 0 0 0\n",
                 bad_box);
        write_file(path, text);
        CHECK(cm_ffd_prm_read(ctx, path, &prm) == CM_ERR_FORMAT);
        CHECK_MSG(strstr(cm_context_message(ctx), why[b]) != NULL, "%s", cm_context_message(ctx));
    }
    /* the bound itself and a negative (mirrored) box are fine */
    snprintf(text, sizeof text,
             "%s[Parameters weights]\nparameter x: 0 0 0 1e150\nparameter y: 0 0 0 -1e150\n"
             "parameter z: 0 0 0 0\n",
             box);
    write_file(path, text);
    CHECK(cm_ffd_prm_read(ctx, path, &prm) == CM_OK);
    cm_ffd_prm_free(&prm);
    /* good, with '=' and upper case keys and a continuation line */
    snprintf(text, sizeof text,
             "%s[Parameters weights]\nParameter X = 0 0 0 0.5\n   1 1 1 -0.25\n"
             "parameter y: 0 0 0 0\nparameter z: 1 0 1 0.125\n",
             box);
    write_file(path, text);
    CHECK(cm_ffd_prm_read(ctx, path, &prm) == CM_OK);
    if (prm.mu) {
        CHECK(prm.mu[0] == 0.5 && prm.mu[3 * 7] == -0.25 && prm.mu[3 * 5 + 2] == 0.125);
        cm_ffd_prm_free(&prm);
    }
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    data_dir = argv[1];
    work_dir = argv[2];
    cm_context_create(&ctx);
    check_case("bern444_rot", 64);
    check_case("bern333_rot", 27);
    check_case("bern222", 8);
    check_case("bern534_rot", 60);
    test_reader_errors();
    cm_context_destroy(&ctx);
    return TEST_REPORT();
}
