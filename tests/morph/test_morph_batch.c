/* cm_morpher_apply_batch against cm_morpher_apply_method per target on the built-in bore (its
 * STEP variants and hex O-grid), with the dense and the iterative RBF solver: the same
 * statuses, rows and coordinates (to rounding, to the iterative tolerance), a batch that
 * holds a target of another topology (a mismatch) and targets whose one-step morph is not
 * valid (morphed again alone: the same rejection or adaptive steps); configurations the batch
 * cannot serve (fixed steps > 1, a non-RBF warp) give one-at-a-time's results too.
 * usage: test_morph_batch DATA WORK */
#include "cadmorph/models.h"
#include "cadmorph/morph.h"
#include "test_util.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { K = 6 };

static int failures;

#define EXPECT(cond, ...)                                                                      \
    do {                                                                                       \
        if (!(cond)) {                                                                         \
            fprintf(stderr, "%s:%d: ", __FILE__, __LINE__);                                    \
            fprintf(stderr, __VA_ARGS__);                                                      \
            fputc('\n', stderr);                                                               \
            ++failures;                                                                        \
        }                                                                                      \
    } while (0)

/* One configuration: the batch of the targets against each alone; returns the items batched. */
static int compare(cm_context *ctx, const cm_cad_model *g0, const cm_mesh *m,
                   const cm_cad_model *const *targets, const cm_morph_options *mo,
                   const char *what, double *min_sj)
{
    const size_t n3 = 3 * m->n_nodes;
    double bb[6];
    cm_cad_bbox(g0, bb);
    const double diag = cm_bbox_diagonal(bb);
    const double tol = mo->method.warp.solver == CM_RBF_SOLVER_ITERATIVE ? 1e-7 : 1e-11;
    cm_morpher *a = NULL, *b = NULL;
    cm_status s = cm_morpher_create(ctx, g0, m, mo, &a);
    if (s >= 0) s = cm_morpher_create(ctx, g0, m, mo, &b);
    EXPECT(s >= 0, "%s: create: %s", what, cm_context_message(ctx));
    double *xyz[K], *one = malloc(n3 * sizeof *one);
    cm_morph_batch_item items[K];
    for (int j = 0; j < K; ++j)
        xyz[j] = malloc(n3 * sizeof *xyz[j]);
    int batched = 0;
    if (s >= 0) {
        s = cm_morpher_apply_batch(ctx, a, K, targets, &mo->method, xyz, items);
        EXPECT(s == CM_OK, "%s: batch: %d %s", what, s, cm_context_message(ctx));
    }
    for (int j = 0; j < K && s >= 0; ++j) {
        cm_morph_step row;
        memset(&row, 0, sizeof row);
        cm_status e = cm_morpher_apply_method(ctx, b, targets[j], &mo->method, one, &row);
        const cm_morph_batch_item *it = &items[j];
        batched += it->batched;
        if (min_sj) min_sj[j] = row.min_sj;
        EXPECT(it->status == e, "%s, target %d: status %s batched, %s alone (%s)", what, j,
               cm_status_name(it->status), cm_status_name(e), cm_context_message(ctx));
        if (e < 0) {
            EXPECT(!strcmp(it->message, cm_context_message(ctx)) || e == CM_ERR_REJECTED,
                   "%s, target %d: message '%s' vs '%s'", what, j, it->message,
                   cm_context_message(ctx));
            if (e != CM_ERR_REJECTED) continue;
        }
        EXPECT(it->row.step == row.step && it->row.inverted == row.inverted &&
                   it->row.cells == row.cells && it->row.outside == row.outside &&
                   it->row.accepted == row.accepted,
               "%s, target %d: row step %d/%d inverted %zu/%zu", what, j, it->row.step,
               row.step, it->row.inverted, row.inverted);
        EXPECT(fabs(it->row.min_sj - row.min_sj) <= 10 * tol &&
                   fabs(it->row.mean_sj - row.mean_sj) <= 10 * tol,
               "%s, target %d: min SJ %.15g vs %.15g, mean %.15g vs %.15g", what, j,
               it->row.min_sj, row.min_sj, it->row.mean_sj, row.mean_sj);
        EXPECT(fabs(it->row.residual - row.residual) <= tol * diag,
               "%s, target %d: residual %g vs %g", what, j, it->row.residual, row.residual);
        EXPECT(fabs(it->row.max_dist - row.max_dist) <= 1e-9 * diag,
               "%s, target %d: distance %g vs %g", what, j, it->row.max_dist, row.max_dist);
        double worst = 0;
        for (size_t i = 0; i < n3; ++i)
            worst = fmax(worst, fabs(xyz[j][i] - one[i]));
        EXPECT(worst <= tol * diag, "%s, target %d: coordinates differ by %g (diagonal %g)",
               what, j, worst, diag);
    }
    for (int j = 0; j < K; ++j)
        free(xyz[j]);
    free(one);
    cm_morpher_destroy(&a);
    cm_morpher_destroy(&b);
    printf("%s: %d of %d targets batched\n", what, batched, K);
    return batched;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: %s DATA WORK\n", argv[0]);
        return 2;
    }
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    cm_context_set_threads(ctx, 2);
    /* G0, five variants of the bore and a pipe (another topology) in the middle */
    const double t[K] = {0.2, 0.4, 0, 0.6, 0.8, 1.0};
    cm_cad_model *g[K + 1] = {0};
    char path[4096];
    cm_status s = CM_OK;
    for (int j = 0; j <= K && s >= 0; ++j) {
        snprintf(path, sizeof path, "%s/morph_batch_%d.step", argv[2], j);
        s = cm_model_write_step(ctx, j == 3 ? "pipe" : "bore", j ? t[j - 1] : 0, path);
        if (s >= 0) s = cm_cad_read(ctx, path, NULL, &g[j]);
    }
    cm_mesh *m = NULL;
    if (s >= 0) s = cm_hexmesh_bore(ctx, 16, 3, 3, 1.05, &m);
    CHECK_MSG(s >= 0, "%s", cm_context_message(ctx));
    const cm_cad_model *const *targets = (const cm_cad_model *const *)(g + 1);

    for (int it = 0; it < 2; ++it) {
        const cm_rbf_solver solver = it ? CM_RBF_SOLVER_ITERATIVE : CM_RBF_SOLVER_DENSE;
        const char *sn = it ? "iterative" : "dense";
        char what[128];
        /* the default morph: every target of the bore's topology batched */
        cm_morph_options mo;
        cm_morph_options_init(&mo);
        mo.method.warp.solver = solver;
        snprintf(what, sizeof what, "%s, rbf-s, steps auto", sn);
        double sj[K];
        EXPECT(compare(ctx, g[0], m, targets, &mo, what, sj) == K - 1, "%s: not all batched",
               what);
        /* closest-point surface, one step: the larger motions invert, the batch's
         * rejections are one-at-a-time's */
        mo.method.surface = CM_SURFACE_PROJECT;
        mo.steps = 1;
        snprintf(what, sizeof what, "%s, project, steps 1", sn);
        int n = compare(ctx, g[0], m, targets, &mo, what, NULL);
        EXPECT(n > 0 && n < K - 1, "%s: %d batched", what, n);
        /* adaptive steps with a floor that the larger motions miss in one step (between the
         * results' minimum scaled Jacobians): those are morphed again alone */
        mo.steps = CM_MORPH_STEPS_AUTO;
        mo.method.surface = CM_SURFACE_RBF;
        mo.min_sj = 0.5 * (sj[0] + sj[K - 1]);
        snprintf(what, sizeof what, "%s, rbf-s, floor %.3g", sn, mo.min_sj);
        n = compare(ctx, g[0], m, targets, &mo, what, NULL);
        EXPECT(n > 0 && n < K - 1, "%s: %d batched", what, n);
        /* what the batch cannot serve: fixed steps, a warp without a shared apply */
        cm_morph_options_init(&mo);
        mo.method.warp.solver = solver;
        mo.steps = 2;
        snprintf(what, sizeof what, "%s, steps 2", sn);
        EXPECT(compare(ctx, g[0], m, targets, &mo, what, NULL) == 0, "%s: batched", what);
    }
    cm_morph_options mo;
    cm_morph_options_init(&mo);
    mo.method.warp.method = CM_WARP_FEMWARP;
    EXPECT(compare(ctx, g[0], m, targets, &mo, "femwarp", NULL) == 0, "femwarp batched");

    /* an empty batch, NULL inputs */
    cm_morpher *mp = NULL;
    CHECK(cm_morpher_create(ctx, g[0], m, NULL, &mp) >= 0);
    cm_morph_method meth;
    cm_morph_method_init(&meth);
    CHECK(cm_morpher_apply_batch(ctx, mp, 0, NULL, &meth, NULL, NULL) == CM_OK);
    CHECK(cm_morpher_apply_batch(ctx, mp, 2, NULL, &meth, NULL, NULL) == CM_ERR_ARGUMENT);
    cm_morpher_destroy(&mp);

    for (int j = 0; j <= K; ++j)
        cm_cad_destroy(&g[j]);
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    if (failures) {
        fprintf(stderr, "%d failures\n", failures);
        return 1;
    }
    printf("ok\n");
    return 0;
}
