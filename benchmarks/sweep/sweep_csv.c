/* sweep.csv: one row per model x mesh x mode x method x step, written through a temporary
 * file (cm_outfile) like every output of cadmorph. */
#include "sweep.h"

#include <stdio.h>

cm_status cm_sweep_write_csv(cm_context *ctx, const cm_sweep_result *r, const char *path)
{
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s < 0) return s;
    fprintf(out.f, "model,mesh,mode,method,step,t,percent,min_scaled_jacobian,"
                   "mean_scaled_jacobian,inverted,cells,max_distance,max_distance_rel,outside,"
                   "nodes,boundary_nodes,threads,t_sample,t_classify,t_surface,t_volume_solve,"
                   "t_evaluation,t_quality,t_distance,t_write\n");
    for (size_t i = 0; i < r->n_rows; ++i) {
        const cm_sweep_row *w = &r->rows[i];
        fprintf(
            out.f,
            "%s,%s,%s,%s,%d,%.6g,%.4g,%.9g,%.9g,%zu,%zu,%.6g,%.6g,%zu,%zu,%zu,%d,%.6f,%.6f,%.6f,"
            "%.6f,%.6f,%.6f,%.6f,%.6f\n",
            r->model, r->mesh, cm_sweep_mode_name(w->mode), cm_sweep_method_name(w->method),
            w->step, w->t, 100 * w->t, w->min_sj, w->mean_sj, w->inverted, w->cells, w->max_dist,
            r->diagonal > 0 ? w->max_dist / r->diagonal : 0.0, w->outside, r->nodes,
            r->boundary_nodes, r->threads, w->t_sample, w->t_classify, w->t_surface,
            w->t_volume_solve, w->t_evaluation, w->t_quality, w->t_distance, w->t_write);
    }
    return cm_outfile_commit(ctx, &out);
}
