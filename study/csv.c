/* study.csv / sweep.csv: one row per variant x method x mode, written through a temporary
 * file (cm_outfile) like every output of cadmorph. */
#include "cadmorph/study.h"
#include "study_internal.h"

#include <stdio.h>
#include <string.h>

void cm_csv_field(FILE *f, const char *s)
{
    if (!strpbrk(s, ",\"\r\n")) {
        fputs(s, f);
        return;
    }
    fputc('"', f);
    for (; *s; ++s) {
        if (*s == '"') fputc('"', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

cm_status cm_study_write_csv(cm_context *ctx, const cm_study_result *r, const char *path,
                             int format)
{
    if (!r || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_study_write_csv: NULL input");
    int full = format != CM_STUDY_CSV_SWEEP;
    cm_outfile out;
    cm_status s = cm_outfile_open(ctx, path, &out);
    if (s < 0) return s;
    FILE *f = out.f;
    fprintf(f, "model,mesh,mode,method,step,t,percent,min_scaled_jacobian,"
               "mean_scaled_jacobian,inverted,cells,max_distance,max_distance_rel,outside,"
               "nodes,boundary_nodes,threads,t_sample,t_classify,t_surface,t_volume_solve,"
               "t_evaluation,t_quality,t_distance,t_write%s",
            full ? ",variant,status,message" : "");
    for (size_t k = 0; full && k < r->n_values; ++k) {
        fputc(',', f);
        cm_csv_field(f, r->value_names[k]);
    }
    fputc('\n', f);
    for (size_t i = 0; i < r->n_rows; ++i) {
        const cm_study_row *w = &r->rows[i];
        if (!full && w->status < 0) continue; /* the sweep's series end where they fail */
        cm_csv_field(f, r->model);
        fputc(',', f);
        cm_csv_field(f, r->mesh);
        fprintf(f, ",%s,", cm_study_mode_name(w->mode));
        cm_csv_field(f, r->methods[w->method].name);
        fprintf(f,
                ",%zu,%.6g,%.4g,%.9g,%.9g,%zu,%zu,%.6g,%.6g,%zu,%zu,%zu,%d,%.6f,%.6f,%.6f,%.6f,"
                "%.6f,%.6f,%.6f,%.6f",
                w->variant + 1, w->t, 100 * w->t, w->min_sj, w->mean_sj, w->inverted, w->cells,
                w->max_dist, r->diagonal > 0 ? w->max_dist / r->diagonal : 0.0, w->outside,
                r->nodes, r->boundary_nodes, r->threads, w->t_sample, w->t_classify,
                w->t_surface, w->t_volume_solve, w->t_evaluation, w->t_quality, w->t_distance,
                w->t_write);
        if (full) {
            fputc(',', f);
            cm_csv_field(f, w->label);
            fprintf(f, ",%s,", cm_status_name(w->status));
            cm_csv_field(f, w->message);
            for (size_t k = 0; k < r->n_values; ++k)
                fprintf(f, ",%.17g", r->values[w->variant * r->n_values + k]);
        }
        fputc('\n', f);
    }
    return cm_outfile_commit(ctx, &out);
}
