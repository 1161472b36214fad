/* The MLS deformation at scale ([CMLS §7.1, §7.3]): set-up (sampling, shape
 * functions, factorisation) once, then R deformations of the same handles with different
 * displacements (a design loop), each one CHOLMOD solve and one sparse product. Prints wall
 * and CPU seconds per phase and the peak resident set.
 * usage: bench_mls MESH H.csv F.csv SAMPLES CUBATURE [REPEATS] */
#define _POSIX_C_SOURCE 200809L
#include "cadmorph/mls.h"
#include "cadmorph/warp.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

static int read_fixed(const char *path, size_t n, unsigned char *con)
{
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    char line[64];
    if (!fgets(line, sizeof line, f)) {
        fclose(f);
        return -1;
    }
    long long v;
    while (fscanf(f, "%lld", &v) == 1)
        if (v >= 0 && (size_t)v < n) con[v] = 1;
    fclose(f);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 6) {
        fprintf(stderr, "usage: bench_mls MESH H.csv F.csv SAMPLES CUBATURE [REPEATS]\n");
        return 1;
    }
    int repeats = argc > 6 ? atoi(argv[6]) : 5;
    cm_context *ctx = NULL;
    cm_context_create(&ctx);
    cm_mesh *mesh = NULL;
    double t0 = cm_wtime();
    if (cm_mesh_read(ctx, argv[1], &mesh) < 0) {
        fprintf(stderr, "%s\n", cm_context_message(ctx));
        return 2;
    }
    double t_read = cm_wtime() - t0;
    size_t n = mesh->n_nodes;
    double *disp = calloc(3 * n, sizeof *disp), *h = calloc(3 * n, sizeof *h);
    unsigned char *handle = calloc(n, 1), *con = calloc(n, 1);
    if (cm_warp_read_displacements(ctx, argv[2], n, h, handle) < 0 || read_fixed(argv[3], n, con)) {
        fprintf(stderr, "tables: %s\n", cm_context_message(ctx));
        return 2;
    }
    size_t nh = 0, nf = 0;
    for (size_t i = 0; i < n; ++i) {
        if (handle[i]) con[i] = 2, ++nh;
        else if (con[i]) con[i] = 1, ++nf;
    }
    cm_mls_options o;
    cm_mls_options_init(&o);
    o.samples = (size_t)atol(argv[4]);
    o.cubature = (size_t)atol(argv[5]);
    o.keep_constrained = 0;
    cm_mls *mls = NULL;
    if (cm_mls_create(ctx, mesh, con, &o, &mls) < 0) {
        fprintf(stderr, "%s\n", cm_context_message(ctx));
        return 3;
    }
    cm_mls_stats st;
    cm_mls_get_stats(mls, &st);
    printf("nodes %zu, handle %zu, fixed %zu; samples %zu (%zu surface), cubature %zu; read %.2f s\n", n, nh, nf,
           st.samples, st.surface_samples, st.cubature, t_read);
    printf("set-up: sample %.2f s (CPU %.2f), basis %.2f s (CPU %.2f), factor %.2f s (CPU %.2f, %zu entries), "
           "Phi %zu entries\n",
           st.t_sample, st.c_sample, st.t_basis, st.c_basis, st.t_factor, st.c_factor, st.factor_nonzeros,
           st.phi_nonzeros);
    double wsum = 0, csum = 0, res = 0;
    for (int r = 0; r < repeats; ++r) {
        /* the handle's motion scaled and turned a little each time: a new right-hand side */
        double s = 0.5 + 0.5 * (r + 1) / repeats, c = 0.1 * r;
        for (size_t i = 0; i < n; ++i) {
            disp[3 * i] = s * h[3 * i] - c * h[3 * i + 1];
            disp[3 * i + 1] = s * h[3 * i + 1] + c * h[3 * i];
            disp[3 * i + 2] = s * h[3 * i + 2];
            if (con[i] == 1) disp[3 * i] = disp[3 * i + 1] = disp[3 * i + 2] = 0;
        }
        if (cm_mls_apply(ctx, mls, disp, &res) < 0) {
            fprintf(stderr, "%s\n", cm_context_message(ctx));
            return 3;
        }
        cm_mls_get_stats(mls, &st);
        wsum += st.t_apply, csum += st.c_apply;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("per deformation (mean of %d): %.3f s (CPU %.3f), residual %.3g; peak RSS %.0f MB\n", repeats,
           wsum / repeats, csum / repeats, res, (double)ru.ru_maxrss / 1024.0);
    cm_mls_destroy(&mls);
    cm_mesh_destroy(&mesh);
    free(disp), free(h), free(handle), free(con);
    cm_context_destroy(&ctx);
    return 0;
}
