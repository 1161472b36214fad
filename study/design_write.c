/* The outputs of `cadmorph sensitivity` (study.h): the velocities as a CSV and as point
 * fields of M0 (ParaView), the gradient as a CSV; each written through a temporary file. */
#include "cadmorph/study.h"
#include "study_internal.h"

#include <stdio.h>
#include <string.h>

static int used(const cm_design_velocities *v, size_t j)
{
    return v->diff[j].scheme != CM_DESIGN_NONE;
}

static cm_status check(cm_context *ctx, const char *fn, const cm_design_table *t,
                       const cm_design_velocities *v, const char *path)
{
    return t && v && path ? CM_OK : cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL input", fn);
}

static cm_status check_mesh(cm_context *ctx, const char *fn, const cm_design_velocities *v,
                            const cm_mesh *m0)
{
    if (!m0) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL mesh", fn);
    if (m0->n_nodes != v->n_nodes)
        return cm_error(ctx, CM_ERR_MISMATCH, "%s: the mesh has %zu nodes, the velocities %zu",
                        fn, m0->n_nodes, v->n_nodes);
    return CM_OK;
}

/* ",<prefix><name>" as one CSV field */
static void prefixed(FILE *f, const char *prefix, const char *name)
{
    char buf[512];
    snprintf(buf, sizeof buf, "%s%s", prefix, name);
    fputc(',', f);
    cm_csv_field(f, buf);
}

cm_status cm_design_write_velocity_csv(cm_context *ctx, const cm_design_table *t,
                                       const cm_design_velocities *v, const cm_mesh *m,
                                       const char *path)
{
    const char *fn = "cm_design_write_velocity_csv";
    cm_status s = check(ctx, fn, t, v, path);
    if (s >= 0) s = check_mesh(ctx, fn, v, m);
    cm_outfile out;
    if (s >= 0) s = cm_outfile_open(ctx, path, &out);
    if (s < 0) return s;
    FILE *f = out.f;
    fputs("node,x,y,z", f);
    for (size_t j = 0; j < v->n_parameters; ++j) {
        if (!used(v, j)) continue;
        const char *name = cm_design_table_parameter(t, j);
        prefixed(f, "dx_d", name);
        prefixed(f, "dy_d", name);
        prefixed(f, "dz_d", name);
    }
    fputc('\n', f);
    for (size_t k = 0; k < m->n_nodes; ++k) {
        fprintf(f, "%zu,%.17g,%.17g,%.17g", k, m->xyz[3 * k], m->xyz[3 * k + 1], m->xyz[3 * k + 2]);
        for (size_t j = 0; j < v->n_parameters; ++j) {
            if (!used(v, j)) continue;
            const double *x = v->v + (j * v->n_nodes + k) * 3;
            fprintf(f, ",%.17g,%.17g,%.17g", x[0], x[1], x[2]);
        }
        fputc('\n', f);
    }
    return cm_outfile_commit(ctx, &out);
}

cm_status cm_design_write_velocity_mesh(cm_context *ctx, const cm_design_table *t,
                                        const cm_design_velocities *v, const cm_mesh *m0,
                                        const char *path)
{
    const char *fn = "cm_design_write_velocity_mesh";
    cm_status s = check(ctx, fn, t, v, path);
    if (s >= 0) s = check_mesh(ctx, fn, v, m0);
    cm_mesh *m = NULL;
    if (s >= 0) s = cm_mesh_copy(ctx, m0, &m);
    for (size_t j = 0; j < v->n_parameters && s >= 0; ++j) {
        if (!used(v, j)) continue;
        char name[512];
        snprintf(name, sizeof name, "dX_d%s", cm_design_table_parameter(t, j));
        double *data = NULL;
        s = cm_mesh_add_field(ctx, m, name, CM_FIELD_NODE, 3, &data);
        if (s >= 0) memcpy(data, v->v + j * v->n_nodes * 3, 3 * v->n_nodes * sizeof *data);
    }
    if (s >= 0) s = cm_mesh_write(ctx, m, path, NULL);
    cm_mesh_destroy(&m);
    return s;
}

cm_status cm_design_write_gradient_csv(cm_context *ctx, const cm_design_table *t,
                                       const cm_design_velocities *v, const double *g,
                                       const char *product, const char *path)
{
    cm_status s = check(ctx, "cm_design_write_gradient_csv", t, v, path);
    if (s >= 0 && (!g || !product))
        s = cm_error(ctx, CM_ERR_ARGUMENT, "cm_design_write_gradient_csv: NULL input");
    cm_outfile out;
    if (s >= 0) s = cm_outfile_open(ctx, path, &out);
    if (s < 0) return s;
    FILE *f = out.f;
    fputs("parameter,dJdp,difference,dp_plus,dp_minus,step_plus,step_minus,product\n", f);
    for (size_t j = 0; j < v->n_parameters; ++j) {
        const cm_design_difference *d = &v->diff[j];
        if (!used(v, j)) continue;
        cm_csv_field(f, cm_design_table_parameter(t, j));
        fprintf(f, ",%.17g,%s,%.17g,%.17g,", g[j], cm_design_scheme_name(d->scheme), d->dp_plus,
                d->dp_minus);
        cm_csv_field(f, cm_design_table_path(t, d->plus));
        fputc(',', f);
        cm_csv_field(f, cm_design_table_path(t, d->scheme == CM_DESIGN_CENTRAL ? d->minus : v->base));
        fprintf(f, ",%s\n", product);
    }
    return cm_outfile_commit(ctx, &out);
}
