/* Benchmark of the CAD layer: dense sampling + kD-tree build at about 1M samples,
 * nearest-sample queries, and projection of 100k points near the surface (nearest sample +
 * Newton). Usage: bench_cad MODEL.step [samples=1e6] [points=1e5] [threads=2] */
#include "cadmorph/cad.h"
#include "cadmorph/kdtree.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static void log_line(void *user, cm_log_level level, const char *msg)
{
    (void)user, (void)level;
    printf("  [%s]\n", msg);
}

/* Process CPU time: on a shared machine the wall clock includes other people's jobs. */
static double cpu(void) { return (double)clock() / CLOCKS_PER_SEC; }

static double rnd(uint64_t *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_cad MODEL.step [samples] [points] [threads]\n");
        return 1;
    }
    double want = argc > 2 ? atof(argv[2]) : 1e6;
    size_t npts = argc > 3 ? (size_t)atof(argv[3]) : 100000;
    int threads = argc > 4 ? atoi(argv[4]) : 2;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_context_set_threads(ctx, threads);
    cm_context_set_log(ctx, log_line, NULL);
    cm_cad_model *m = NULL;
    double t0 = cm_wtime();
    if (cm_cad_read(ctx, argv[1], NULL, &m) != CM_OK) {
        fprintf(stderr, "%s\n", cm_context_message(ctx));
        return 2;
    }
    double t_read = cm_wtime() - t0;
    cm_cad_counts c;
    cm_cad_get_counts(m, &c);
    double area = 0;
    for (int f = 0; f < c.faces; ++f) {
        cm_cad_face_info fi;
        cm_cad_face_get_info(ctx, m, f, &fi);
        area += fi.area;
    }
    cm_cad_sample_options o;
    cm_cad_sample_options_init(&o);
    o.h = sqrt(area / want);
    cm_cad_locator *loc = NULL;
    t0 = cm_wtime();
    double c0 = cpu();
    cm_status st = cm_cad_locator_create(ctx, m, &o, &loc);
    double t_sample = cm_wtime() - t0, c_sample = cpu() - c0;
    if (st < 0) {
        fprintf(stderr, "%s\n", cm_context_message(ctx));
        return 2;
    }
    const double *xyz, *uv;
    const int *face;
    size_t ns = cm_cad_locator_samples(loc, &xyz, &face, &uv);
    /* the kD-tree alone, on the same samples */
    cm_kdtree *tree = NULL;
    t0 = cm_wtime();
    cm_kdtree_create(ctx, xyz, ns, &tree);
    double t_tree = cm_wtime() - t0;

    /* points near the surface: samples moved by up to h in each direction */
    uint64_t seed = 7;
    double *q = malloc(3 * npts * sizeof *q), *d = malloc(npts * sizeof *d),
           *puv = malloc(2 * npts * sizeof *puv);
    int *pf = malloc(npts * sizeof *pf);
    int64_t *idx = malloc(npts * sizeof *idx);
    double h = cm_cad_locator_h(loc);
    for (size_t i = 0; i < npts; ++i) {
        size_t j = (size_t)(rnd(&seed) * ns);
        for (int k = 0; k < 3; ++k) q[3 * i + k] = xyz[3 * j + k] + (2 * rnd(&seed) - 1) * h;
    }
    t0 = cm_wtime();
    c0 = cpu();
    cm_kdtree_nearest(ctx, tree, q, npts, 1, idx, d);
    double t_nn = cm_wtime() - t0, c_nn = cpu() - c0;
    t0 = cm_wtime();
    c0 = cpu();
    st = cm_cad_locate_faces(ctx, loc, q, npts, pf, puv, d, NULL);
    double t_proj = cm_wtime() - t0, c_proj = cpu() - c0;
    if (st < 0) fprintf(stderr, "%s\n", cm_context_message(ctx));
    double dmax = 0;
    for (size_t i = 0; i < npts; ++i) dmax = fmax(dmax, d[i]);

    printf("model %s: %d faces, %d edges, read %.3f s\n", argv[1], c.faces, c.edges, t_read);
    printf("threads %d\n", threads);
    printf("samples %zu (h %.4g): sampling + kD-trees %.3f s wall, %.3f s cpu; "
           "kD-tree alone %.3f s\n",
           ns, h, t_sample, c_sample, t_tree);
    printf("nearest sample: %zu queries %.3f s wall = %.2f us/query; cpu %.2f us/query\n", npts,
           t_nn, 1e6 * t_nn / npts, 1e6 * c_nn / npts);
    printf("projection (nearest sample + Newton): %zu points %.3f s wall = %.2f us/point, "
           "%.3f s cpu (max distance %.3g)\n",
           npts, t_proj, 1e6 * t_proj / npts, c_proj, dmax);
    cm_kdtree_destroy(&tree);
    cm_cad_locator_destroy(&loc);
    cm_cad_destroy(&m);
    free(q), free(d), free(puv), free(pf), free(idx);
    cm_context_destroy(&ctx);
    return 0;
}
