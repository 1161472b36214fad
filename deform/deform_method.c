/* The point-set deformations behind one table (deform.h): rbf, mls, shell, dmffd. Each row
 * keeps its own state in cm_deform; create and apply make the same library calls, in the same
 * order and with the same arguments, as the callers made before they shared this table, so
 * their results stay bit-identical. */
#include "cadmorph/deform.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The DM-FFD lattice's margin around the bounding box, relative to its diagonal: every point
 * lies strictly inside the valid domain (not on its faces) and the lattice still hugs them. */
#define DEFORM_DMFFD_MARGIN 1e-3

struct cm_deform {
    const struct deform_row *row;
    cm_deform_options opt;
    size_t n, n_constrained, n_free;
    unsigned char *constrained; /* rbf, dmffd, shell: the caller's flags, copied */
    double *free_xyz;           /* rbf, dmffd: the free points, n_free x 3 */
    const cm_mesh *mesh;        /* shell: borrowed */
    cm_rbf *rbf;
    cm_ffd *ffd;
    cm_dmffd *dm;
    double *dc; /* dmffd: control displacements, #ctrl x 3 */
    cm_mls *mls;
    double residual, t_solve, t_evaluate;
    /* no free point, and the method gives the constrained points their prescribed values:
     * the result is known, nothing is built (cm_deform_stats.prescribed_only) */
    int prescribed_only;
};

typedef struct deform_row {
    const char *name;
    int needs_mesh;
    cm_status (*create)(cm_context *ctx, cm_deform *d, const double *xyz);
    cm_status (*apply)(cm_context *ctx, cm_deform *d, double *disp, double *residual);
    /* cm_deform_apply_transpose: out (n x 3) is zeroed by the dispatcher; the row adds J^T v
     * at the constrained points. NULL: no transpose (apply not linear, or not written). */
    cm_status (*apply_transpose)(cm_context *ctx, cm_deform *d, const double *v, double *out);
    /* cm_deform_apply_many: k blocks of n x 3 at once. NULL: the dispatcher loops over apply. */
    cm_status (*apply_many)(cm_context *ctx, cm_deform *d, size_t k, double *disp,
                            double *residual);
} deform_row;

/* ---- shared by rbf and dmffd: the points split into constrained and free ones ---- */

/* The constrained points (*c, n_constrained x 3, the caller frees) and the free ones
 * (d->free_xyz), each in point order. */
static cm_status split_points(cm_context *ctx, cm_deform *d, const double *xyz, double **c)
{
    size_t nc = d->n_constrained, nf = d->n_free;
    *c = malloc((nc ? nc : 1) * 3 * sizeof **c);
    d->free_xyz = malloc((nf ? nf : 1) * 3 * sizeof *d->free_xyz);
    if (!*c || !d->free_xyz) return cm_error(ctx, CM_ERR_NOMEM, "cm_deform_create: out of memory");
    for (size_t i = 0, a = 0, b = 0; i < d->n; ++i)
        if (d->constrained[i])
            memcpy(*c + 3 * a++, xyz + 3 * i, 3 * sizeof **c);
        else
            memcpy(d->free_xyz + 3 * b++, xyz + 3 * i, 3 * sizeof **c);
    return CM_OK;
}

/* Scratch for one apply: the constrained values (gathered from disp) and the free results. */
static cm_status apply_scratch(cm_context *ctx, const cm_deform *d, const double *disp,
                               double **v, double **out)
{
    size_t nc = d->n_constrained, nf = d->n_free;
    *v = malloc((nc ? nc : 1) * 3 * sizeof **v);
    *out = malloc((nf ? nf : 1) * 3 * sizeof **out);
    if (!*v || !*out) return cm_error(ctx, CM_ERR_NOMEM, "cm_deform_apply: out of memory");
    for (size_t i = 0, a = 0; i < d->n; ++i)
        if (d->constrained[i]) memcpy(*v + 3 * a++, disp + 3 * i, 3 * sizeof **v);
    return CM_OK;
}

static void scatter_free(const cm_deform *d, const double *out, double *disp)
{
    for (size_t i = 0, b = 0; i < d->n; ++i)
        if (!d->constrained[i]) memcpy(disp + 3 * i, out + 3 * b++, 3 * sizeof *disp);
}

/* ---- rbf: one interpolant through the constrained points, evaluated at the free ones ---- */

static cm_status rbf_create(cm_context *ctx, cm_deform *d, const double *xyz)
{
    double *c = NULL;
    cm_status s = split_points(ctx, d, xyz, &c);
    cm_rbf_options ro;
    cm_rbf_options_init(&ro);
    ro.solver = d->opt.solver;
    if (d->opt.tolerance > 0) ro.tolerance = d->opt.tolerance;
    if (d->opt.solves > 1) ro.solves = d->opt.solves;
    if (d->opt.warm_groups > 1) ro.warm_groups = d->opt.warm_groups;
    if (s >= 0) s = cm_rbf_create_opt(ctx, d->opt.kernel, 3, d->n_constrained, c, &ro, &d->rbf);
    free(c);
    return s;
}

/* k fields in one solve and one evaluation of 3k columns: the kernel passes serve every
 * column (cm_rbf_solve, cm_rbf_evaluate). Each block is scaled to a largest constrained value
 * in [1/2, 1) first, so that the iterative solver's tolerance (relative to the largest value
 * of all columns) and the check of merged duplicates (relative to the largest value) mean for
 * each block what they mean in its own apply (to a factor 2); the scaling is undone after the
 * evaluation. */
static cm_status rbf_apply_many(cm_context *ctx, cm_deform *d, size_t k, double *disp,
                                double *residual)
{
    const size_t nc = d->n_constrained, nf = d->n_free, w = 3 * k, n3 = 3 * d->n;
    *residual = 0;
    if (w > (size_t)(~0u >> 1))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_apply_many: %zu fields are too many", k);
    double *v = malloc((nc ? nc : 1) * w * sizeof *v);
    double *out = malloc((nf ? nf : 1) * w * sizeof *out);
    double *scale = malloc(k * sizeof *scale);
    cm_status s = v && out && scale
                      ? CM_OK
                      : cm_error(ctx, CM_ERR_NOMEM, "cm_deform_apply_many: out of memory for %zu "
                                 "fields of %zu points", k, d->n);
    for (size_t j = 0; s >= 0 && j < k; ++j) {
        const double *dj = disp + j * n3;
        double mx = 0;
        for (size_t i = 0; i < d->n; ++i)
            if (d->constrained[i])
                for (int c = 0; c < 3; ++c)
                    mx = fmax(mx, fabs(dj[3 * i + c]));
        /* a power of 2: exact, so a block's values reach the solver as in its own apply */
        int e = 0;
        if (mx > 0 && isfinite(mx)) frexp(mx, &e);
        scale[j] = ldexp(1.0, e);
        for (size_t i = 0, a = 0; i < d->n; ++i)
            if (d->constrained[i]) {
                for (int c = 0; c < 3; ++c)
                    v[a * w + 3 * j + c] = dj[3 * i + c] / scale[j];
                ++a;
            }
    }
    double t0 = cm_wtime();
    if (s >= 0) s = cm_rbf_solve(ctx, d->rbf, (int)w, v);
    double t1 = cm_wtime();
    if (s >= 0 && nf) s = cm_rbf_evaluate(ctx, d->rbf, nf, d->free_xyz, out);
    d->t_solve = t1 - t0;
    d->t_evaluate = cm_wtime() - t1;
    for (size_t j = 0; s >= 0 && j < k; ++j) {
        double *dj = disp + j * n3;
        for (size_t i = 0, b = 0; i < d->n; ++i)
            if (!d->constrained[i]) {
                for (int c = 0; c < 3; ++c)
                    dj[3 * i + c] = out[b * w + 3 * j + c] * scale[j];
                ++b;
            }
    }
    free(v);
    free(out);
    free(scale);
    return s;
}

/* One field: the same solve and evaluation as k fields (the scaling by a power of 2 changes
 * no bit). */
static cm_status rbf_apply(cm_context *ctx, cm_deform *d, double *disp, double *residual)
{
    return rbf_apply_many(ctx, d, 1, disp, residual);
}

/* J^T v: v at the constrained points plus the RBF's reverse product of the free ones. */
static cm_status rbf_apply_transpose(cm_context *ctx, cm_deform *d, const double *v, double *out)
{
    size_t nc = d->n_constrained, nf = d->n_free;
    double *vf = malloc((nf ? nf : 1) * 3 * sizeof *vf);
    double *oc = malloc((nc ? nc : 1) * 3 * sizeof *oc);
    cm_status s = vf && oc ? CM_OK
                           : cm_error(ctx, CM_ERR_NOMEM, "cm_deform_apply_transpose: out of memory");
    for (size_t i = 0, b = 0; s >= 0 && i < d->n; ++i)
        if (!d->constrained[i]) memcpy(vf + 3 * b++, v + 3 * i, 3 * sizeof *vf);
    double t0 = cm_wtime();
    if (s >= 0) s = cm_rbf_evaluate_transpose(ctx, d->rbf, nf, d->free_xyz, 3, vf, oc);
    d->t_solve = cm_wtime() - t0;
    d->t_evaluate = 0;
    for (size_t i = 0, a = 0; s >= 0 && i < d->n; ++i)
        if (d->constrained[i]) {
            for (int c = 0; c < 3; ++c) out[3 * i + c] += v[3 * i + c] + oc[3 * a + c];
            ++a;
        }
    free(vf);
    free(oc);
    return s;
}

/* ---- dmffd: one lattice enclosing every point, DM-FFD through the constrained ones ---- */

static cm_status dmffd_create(cm_context *ctx, cm_deform *d, const double *xyz)
{
    int lattice = d->opt.lattice ? d->opt.lattice : 10;
    if (lattice < 4 || lattice > 200)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "cm_deform_create: dmffd lattice of %d control points per axis (4..200)",
                        lattice);
    if (d->n_constrained == 0)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_create: dmffd: no constrained point");
    d->opt.lattice = lattice;
    double bb[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < d->n; ++i)
        for (int a = 0; a < 3; ++a) {
            bb[a] = fmin(bb[a], xyz[3 * i + a]);
            bb[a + 3] = fmax(bb[a + 3], xyz[3 * i + a]);
        }
    double *c = NULL;
    cm_status s = split_points(ctx, d, xyz, &c);
    cm_ffd_desc desc;
    cm_ffd_desc_enclosing(&desc, bb, DEFORM_DMFFD_MARGIN, lattice);
    if (s >= 0) s = cm_ffd_create(ctx, &desc, &d->ffd);
    if (s >= 0 && !(d->dc = malloc(cm_ffd_control_count(d->ffd) * 3 * sizeof *d->dc)))
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_deform_create: out of memory");
    cm_dmffd_options o;
    cm_dmffd_options_init(&o);
    if (d->opt.clamp > 0) o.eps = d->opt.clamp;
    if (s >= 0) s = cm_dmffd_create(ctx, d->ffd, d->n_constrained, c, &o, &d->dm);
    free(c);
    return s;
}

static cm_status dmffd_apply(cm_context *ctx, cm_deform *d, double *disp, double *residual)
{
    double *h = NULL, *out = NULL;
    cm_status s = apply_scratch(ctx, d, disp, &h, &out);
    double t0 = cm_wtime();
    if (s >= 0) s = cm_dmffd_solve(ctx, d->dm, h, d->dc);
    double t1 = cm_wtime();
    /* a CM_WARNING (points Newton could not locate get 0) lets the result through */
    if (s >= 0 && d->n_free) s = cm_ffd_deform(ctx, d->ffd, d->dc, d->n_free, d->free_xyz, out, NULL);
    d->t_solve = t1 - t0;
    d->t_evaluate = cm_wtime() - t1;
    if (s >= 0) {
        scatter_free(d, out, disp);
        cm_dmffd_info info;
        cm_dmffd_get_info(d->dm, &info);
        *residual = info.residual_abs;
    }
    free(h);
    free(out);
    return s;
}

/* J^T v: the free points' v back through the evaluation (the FFD transposed) and the solve
 * (the pseudo-inverse transposed) onto the constrained points, which keep their own v. */
static cm_status dmffd_apply_transpose(cm_context *ctx, cm_deform *d, const double *v, double *out)
{
    size_t nc = d->n_constrained, nf = d->n_free, nctrl = cm_ffd_control_count(d->ffd);
    double *vf = malloc((nf ? nf : 1) * 3 * sizeof *vf);
    double *gdc = malloc(nctrl * 3 * sizeof *gdc), *gh = malloc(nc * 3 * sizeof *gh);
    cm_status s = vf && gdc && gh
                      ? CM_OK
                      : cm_error(ctx, CM_ERR_NOMEM, "cm_deform_apply_transpose: out of memory");
    if (s >= 0) {
        for (size_t i = 0, b = 0; i < d->n; ++i)
            if (!d->constrained[i]) memcpy(vf + 3 * b++, v + 3 * i, 3 * sizeof *vf);
        s = cm_ffd_deform_transpose(ctx, d->ffd, nf, d->free_xyz, vf, gdc, NULL);
    }
    if (s >= 0) {
        cm_status t = cm_dmffd_solve_transpose(ctx, d->dm, gdc, gh);
        if (t < 0) s = t; /* else a warning of the location stays */
    }
    if (s >= 0)
        for (size_t i = 0, a = 0; i < d->n; ++i)
            if (d->constrained[i]) {
                for (int k = 0; k < 3; ++k)
                    out[3 * i + k] += v[3 * i + k] + gh[3 * a + k];
                ++a;
            }
    free(vf);
    free(gdc);
    free(gh);
    return s;
}

/* ---- mls: the constrained MLS over the mesh's cells ---- */

static cm_status mls_create(cm_context *ctx, cm_deform *d, const double *xyz)
{
    (void)xyz;
    return cm_mls_create(ctx, d->mesh, d->constrained, &d->opt.mls, &d->mls);
}

static cm_status mls_apply(cm_context *ctx, cm_deform *d, double *disp, double *residual)
{
    double t0 = cm_wtime();
    cm_status s = cm_mls_apply(ctx, d->mls, disp, residual);
    d->t_solve = cm_wtime() - t0;
    return s;
}

static cm_status mls_apply_transpose(cm_context *ctx, cm_deform *d, const double *v, double *out)
{
    return cm_mls_apply_transpose(ctx, d->mls, v, out);
}

/* ---- shell: nothing to precompute; each apply solves the shell's system ---- */

static cm_status shell_create(cm_context *ctx, cm_deform *d, const double *xyz)
{
    (void)ctx, (void)d, (void)xyz;
    return CM_OK;
}

static cm_status shell_apply(cm_context *ctx, cm_deform *d, double *disp, double *residual)
{
    double t0 = cm_wtime();
    cm_status s = cm_mls_shell(ctx, d->mesh, d->constrained, d->opt.mls.stretch, d->opt.mls.bend,
                               d->opt.mls.fix, disp);
    d->t_solve = cm_wtime() - t0;
    *residual = 0;
    return s;
}

/* One row per cm_deform_method, in enum order. */
/* apply_transpose: NULL for shell, which assembles and solves its system anew in each apply
 * (nothing kept to transpose). */
static const deform_row rows[CM_DEFORM_N_METHODS] = {
    [CM_DEFORM_RBF] = {"rbf", 0, rbf_create, rbf_apply, rbf_apply_transpose, rbf_apply_many},
    [CM_DEFORM_MLS] = {"mls", 1, mls_create, mls_apply, mls_apply_transpose, NULL},
    [CM_DEFORM_SHELL] = {"shell", 1, shell_create, shell_apply, NULL, NULL},
    [CM_DEFORM_DMFFD] = {"dmffd", 0, dmffd_create, dmffd_apply, dmffd_apply_transpose, NULL},
};

const char *cm_deform_method_name(cm_deform_method method)
{
    return (int)method >= 0 && method < CM_DEFORM_N_METHODS ? rows[method].name : NULL;
}

int cm_deform_method_from_name(const char *name)
{
    for (int m = 0; name && m < CM_DEFORM_N_METHODS; ++m)
        if (!strcmp(name, rows[m].name)) return m;
    return -1;
}

void cm_deform_options_init(cm_deform_options *opt)
{
    if (!opt) return;
    memset(opt, 0, sizeof *opt);
    opt->method = CM_DEFORM_RBF;
    opt->kernel = CM_RBF_TRIHARMONIC;
    opt->solver = CM_RBF_SOLVER_AUTO;
    cm_mls_options_init(&opt->mls);
}

void cm_deform_destroy(cm_deform **def)
{
    if (!def || !*def) return;
    cm_deform *d = *def;
    cm_rbf_destroy(&d->rbf);
    cm_dmffd_destroy(&d->dm);
    cm_ffd_destroy(&d->ffd);
    cm_mls_destroy(&d->mls);
    free(d->constrained);
    free(d->free_xyz);
    free(d->dc);
    free(d);
    *def = NULL;
}

cm_status cm_deform_create(cm_context *ctx, const cm_deform_options *opt, size_t n,
                           const double *xyz, const unsigned char *constrained,
                           const cm_mesh *mesh, cm_deform **def)
{
    if (!def) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_create: def is NULL");
    *def = NULL;
    cm_deform_options defaults;
    cm_deform_options_init(&defaults);
    if (!opt) opt = &defaults;
    if ((int)opt->method < 0 || opt->method >= CM_DEFORM_N_METHODS)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_create: unknown method %d",
                        (int)opt->method);
    const deform_row *row = &rows[opt->method];
    if (row->needs_mesh && (!mesh || mesh->n_nodes != n))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_create: %s needs the mesh of the %zu points",
                        row->name, n);
    if (row->needs_mesh) xyz = mesh->xyz;
    if (!constrained || (n && !xyz))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_create: NULL input");
    cm_deform *d = calloc(1, sizeof *d);
    if (d) d->constrained = malloc(n ? n : 1);
    if (!d || !d->constrained) {
        free(d);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_deform_create: out of memory");
    }
    memcpy(d->constrained, constrained, n);
    d->row = row;
    d->opt = *opt;
    d->n = n;
    d->mesh = row->needs_mesh ? mesh : NULL;
    for (size_t i = 0; i < n; ++i)
        d->n_constrained += constrained[i] != 0;
    d->n_free = n - d->n_constrained;
    /* Every point constrained (a 2-D mesh whose nodes all lie on boundary patches, with the
     * unlisted boundary fixed): rbf and dmffd write only free points, mls with
     * keep_constrained gives the constrained ones their prescribed values, so apply would
     * return disp as it came in. Building the interpolant (a dense or iterative RBF over
     * every point, the lattice's SVD, the MLS factor) would cost time and memory for no
     * change. The shell and the approximate mls write the field's values: they are built. */
    d->prescribed_only = n > 0 && d->n_free == 0 &&
                         (opt->method == CM_DEFORM_RBF || opt->method == CM_DEFORM_DMFFD ||
                          (opt->method == CM_DEFORM_MLS && opt->mls.keep_constrained));
    if (d->prescribed_only) {
        cm_log(ctx, CM_LOG_INFO,
               "cm_deform_create: %s: all %zu points are constrained: the result is the "
               "prescribed motion, nothing to build or solve",
               row->name, n);
        *def = d;
        return CM_OK;
    }
    cm_status s = row->create(ctx, d, xyz);
    if (s < 0) {
        cm_deform_destroy(&d);
        return s;
    }
    *def = d;
    return s;
}

cm_status cm_deform_apply(cm_context *ctx, cm_deform *def, double *disp, double *residual)
{
    if (!def || !disp)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_apply: def or disp is NULL");
    double r = 0;
    cm_status s = def->prescribed_only ? CM_OK : def->row->apply(ctx, def, disp, &r);
    def->residual = r;
    if (residual) *residual = r;
    return s;
}

cm_status cm_deform_apply_many(cm_context *ctx, cm_deform *def, size_t k, double *disp,
                               double *residual)
{
    if (!def || (k && !disp))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_apply_many: def or disp is NULL");
    if (residual) *residual = 0;
    if (k == 0) return CM_OK;
    double r = 0;
    cm_status s = CM_OK, warn = CM_OK;
    if (def->prescribed_only) {
        /* every block stays as it came in */
    } else if (def->row->apply_many) {
        s = def->row->apply_many(ctx, def, k, disp, &r);
    } else {
        /* the largest residual of the blocks; a warning of one block lets the others run */
        for (size_t j = 0; j < k && s >= 0; ++j) {
            double rj = 0;
            s = def->row->apply(ctx, def, disp + j * 3 * def->n, &rj);
            if (s == CM_WARNING) warn = s;
            if (rj > r || rj != rj) r = rj;
        }
    }
    def->residual = r;
    if (residual) *residual = r;
    return s < 0 ? s : s == CM_WARNING ? s : warn;
}

cm_status cm_deform_apply_transpose(cm_context *ctx, cm_deform *def, const double *v,
                                    double *out)
{
    if (!def || !v || !out)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_apply_transpose: def, v or out is NULL");
    if (!def->row->apply_transpose)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_deform_apply_transpose: method %s has no transpose", def->row->name);
    size_t n3 = 3 * def->n;
    if (n3 && v < out + n3 && out < v + n3)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_deform_apply_transpose: v and out overlap");
    if (def->prescribed_only) {
        /* apply is the identity on the constrained values */
        memcpy(out, v, n3 * sizeof *out);
        return CM_OK;
    }
    memset(out, 0, n3 * sizeof *out);
    return def->row->apply_transpose(ctx, def, v, out);
}

void cm_deform_get_stats(const cm_deform *def, cm_deform_stats *stats)
{
    if (!stats) return;
    memset(stats, 0, sizeof *stats);
    if (!def) return;
    stats->method = def->opt.method;
    stats->constrained = def->n_constrained;
    stats->free = def->n_free;
    stats->residual = def->residual;
    stats->t_solve = def->t_solve;
    stats->t_evaluate = def->t_evaluate;
    stats->prescribed_only = def->prescribed_only;
    if (def->rbf) cm_rbf_get_stats(def->rbf, &stats->rbf);
    if (def->dm) {
        cm_dmffd_get_info(def->dm, &stats->dmffd);
        stats->lattice = def->opt.lattice;
        stats->control_points = cm_ffd_control_count(def->ffd);
    }
    if (def->mls) cm_mls_get_stats(def->mls, &stats->mls);
}

cm_mls *cm_deform_get_mls(cm_deform *def) { return def ? def->mls : NULL; }
