/* Boundary motion by patch kind (motion.h): the kind of every node from its patches' kinds and
 * the user's choice, and the projection of a displacement field onto the constraints
 * (docs/DESIGN.md, "Boundary motion by patch kind"). The 2-D and wedge recognition is in
 * motion_reduce.c, curved slides in motion_surface.c. */
#include "motion_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Patches whose file type says they are planes (symmetry, empty, wedge, cyclic) are taken
 * as flat to this fraction of the mesh diagonal: an ASCII case written at 6 digits puts the
 * points of a wedge plane 1e-7 off it. A plain patch the user slides must be flat to
 * round-off (1e-9) to slide on a plane; otherwise it slides on its own surface. */
#define FLAT_TYPED 1e-5
#define FLAT_PLAIN 1e-9
/* two unit normals are one plane's when |n1 . n2| exceeds this */
#define PARALLEL (1 - 1e-9)

static const char *const kind_names[CM_MOTION_N_KINDS] = {"free",  "fixed", "prescribed",
                                                          "plane", "line",  "surface"};

const char *cm_motion_kind_name(cm_motion_kind kind)
{
    return (int)kind >= 0 && kind < CM_MOTION_N_KINDS ? kind_names[kind] : NULL;
}

void cm_motion_options_init(cm_motion_options *opt)
{
    if (opt) memset(opt, 0, sizeof *opt);
}

enum role { ROLE_NONE = 0, ROLE_FIXED, ROLE_SLIDE, ROLE_IGNORE };

static int is_face(const cm_mesh *mesh, size_t c)
{
    const cm_cell_info *ci = cm_cell_type_info((cm_cell_type)mesh->type[c]);
    return ci && ci->dim == 2;
}

/* The dim-2 group of a physical tag, -1 if none (groups are few: a linear search with the
 * last answer cached). */
static int group_of(const cm_mesh *mesh, int tag, int *last)
{
    if (*last >= 0 && mesh->groups[*last].tag == tag) return *last;
    for (size_t g = 0; g < mesh->n_groups; ++g)
        if (mesh->groups[g].dim == 2 && mesh->groups[g].tag == tag) return *last = (int)g;
    return -1;
}

static cm_status name_error(cm_context *ctx, const cm_mesh *mesh, const char *what,
                            const char *name)
{
    char list[1024] = "";
    size_t len = 0;
    for (size_t g = 0; g < mesh->n_groups && len + 2 < sizeof list; ++g)
        if (mesh->groups[g].dim == 2)
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", len ? ", " : "",
                                    mesh->groups[g].name ? mesh->groups[g].name : "?");
    if (len >= sizeof list) len = sizeof list - 1;
    return cm_error(ctx, CM_ERR_ARGUMENT, "%s '%s': the mesh has no such patch (it has: %s)",
                    what, name, len ? list : "no patches");
}

static int find_group(const cm_mesh *mesh, const char *name)
{
    for (size_t g = 0; g < mesh->n_groups; ++g)
        if (mesh->groups[g].dim == 2 && mesh->groups[g].name && !strcmp(mesh->groups[g].name, name))
            return (int)g;
    return -1;
}

/* Per node: up to three distinct slide plane normals. */
typedef struct node_planes {
    double *n;      /* #nodes x 9 */
    uint8_t *count; /* #nodes, 3 means "three or more" */
} node_planes;

static void add_plane(node_planes *np, size_t i, const double *nrm)
{
    double *ni = np->n + 9 * i;
    for (int k = 0; k < np->count[i] && k < 3; ++k)
        if (fabs(ni[3 * k] * nrm[0] + ni[3 * k + 1] * nrm[1] + ni[3 * k + 2] * nrm[2]) > PARALLEL)
            return;
    if (np->count[i] < 3) memcpy(ni + 3 * np->count[i], nrm, 3 * sizeof *nrm), ++np->count[i];
}

void cm_boundary_motion_destroy(cm_boundary_motion **motion)
{
    if (!motion || !*motion) return;
    cm_boundary_motion *m = *motion;
    for (size_t k = 0; k < m->n_surfaces; ++k)
        cm_motion_surface_destroy(m->surfaces[k]);
    free(m->surfaces), free(m->surface);
    free(m->kind), free(m->dir), free(m->partner), free(m->copy), free(m->slab), free(m->er);
    if (m->xyz0 != m->slab) free(m->xyz0);
    free(m);
    *motion = NULL;
}

static double bbox_diag(const cm_mesh *mesh)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < mesh->n_nodes; ++i)
        for (int k = 0; k < 3; ++k)
            lo[k] = fmin(lo[k], mesh->xyz[3 * i + k]), hi[k] = fmax(hi[k], mesh->xyz[3 * i + k]);
    double d = 0;
    for (int k = 0; mesh->n_nodes && k < 3; ++k)
        d += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    return sqrt(d);
}

/* Roles of the dim-2 groups (indexed like mesh->groups) from kinds and options. */
static cm_status group_roles(cm_context *ctx, const cm_mesh *mesh, const cm_motion_options *opt,
                             uint8_t *role)
{
    for (size_t g = 0; g < mesh->n_groups; ++g) {
        const cm_mesh_group *gr = &mesh->groups[g];
        role[g] = ROLE_NONE;
        if (gr->dim != 2) continue;
        if (gr->kind == CM_PATCH_PROCESSOR) role[g] = ROLE_IGNORE;
        else if (opt->all_fixed || gr->kind == CM_PATCH_PLAIN) role[g] = ROLE_FIXED;
        else role[g] = ROLE_SLIDE;
    }
    for (size_t k = 0; k < opt->n_slide; ++k) {
        int g = find_group(mesh, opt->slide[k]);
        if (g < 0) return name_error(ctx, mesh, "--slide", opt->slide[k]);
        for (size_t j = 0; j < opt->n_fixed; ++j)
            if (!strcmp(opt->fixed[j], opt->slide[k]))
                return cm_error(ctx, CM_ERR_ARGUMENT,
                                "patch '%s' is both sliding and fixed", opt->slide[k]);
        if (mesh->groups[g].kind != CM_PATCH_PROCESSOR) role[g] = ROLE_SLIDE;
    }
    for (size_t k = 0; k < opt->n_fixed; ++k) {
        int g = find_group(mesh, opt->fixed[k]);
        if (g < 0) return name_error(ctx, mesh, "--fixed-patches", opt->fixed[k]);
        role[g] = ROLE_FIXED;
    }
    return CM_OK;
}

/* Plane normals of the sliding groups in work coordinates; a curved one becomes a surface
 * (or, if that fails, fixed with a warning). geom: 1 plane, 2 surface. */
static cm_status slide_geometry(cm_context *ctx, cm_boundary_motion *m, const cm_mesh *mesh,
                                const double *X, uint8_t *role, double *gn, int *gsurf,
                                int *warned)
{
    cm_status s = CM_OK;
    for (size_t g = 0; g < mesh->n_groups && s >= 0; ++g) {
        gsurf[g] = -1;
        if (role[g] != ROLE_SLIDE) continue;
        const cm_mesh_group *gr = &mesh->groups[g];
        if (m->reduction == CM_MOTION_AXISYMMETRIC && gr->kind == CM_PATCH_WEDGE) {
            /* the planes w = +-c of the slab (their faces at the axis touch w = 0) */
            gn[3 * g] = gn[3 * g + 1] = 0, gn[3 * g + 2] = 1;
            continue;
        }
        double tol = (gr->kind == CM_PATCH_PLAIN ? FLAT_PLAIN : FLAT_TYPED) * m->diag;
        if (cm_motion_group_plane(mesh, X, gr->tag, tol, gn + 3 * g)) continue;
        cm_motion_surface *sf = NULL;
        cm_motion_surface **grown = realloc(m->surfaces, (m->n_surfaces + 1) * sizeof *grown);
        if (!grown) return cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
        m->surfaces = grown;
        s = cm_motion_surface_create(ctx, mesh, X, gr->tag, &sf);
        if (s == CM_ERR_NOMEM) return s;
        if (!sf && s >= 0) continue; /* no faces (a wedge's axis patch): nothing to move */
        if (s < 0) {
            cm_log(ctx, CM_LOG_WARNING, "patch '%s' slides on no surface (%s): fixed",
                   gr->name ? gr->name : "?", cm_context_message(ctx));
            role[g] = ROLE_FIXED, s = CM_OK, *warned = 1;
            continue;
        }
        gsurf[g] = (int)m->n_surfaces;
        m->surfaces[m->n_surfaces++] = sf;
    }
    return s;
}

/* The kind of every node from its patches (work coordinates X). */
static cm_status node_kinds(cm_context *ctx, cm_boundary_motion *m, const cm_mesh *mesh,
                            const cm_mesh_boundary *b, const unsigned char *prescribed,
                            const uint8_t *role, const double *gn, const int *gsurf)
{
    size_t n = m->n;
    node_planes np = {malloc(9 * (n ? n : 1) * sizeof(double)), calloc(n ? n : 1, 1)};
    /* bit 1: on the boundary, 2: on a fixed patch, 4: on a patch (any), 8: two surfaces */
    uint8_t *flag = calloc(n ? n : 1, 1);
    int32_t *surf = malloc((n ? n : 1) * sizeof *surf);
    if (!np.n || !np.count || !flag || !surf) {
        free(np.n), free(np.count), free(flag), free(surf);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
    }
    for (size_t i = 0; i < n; ++i)
        surf[i] = -1;
    for (size_t i = 0; i < b->n_nodes; ++i)
        flag[b->nodes[i]] |= 1;
    int last = -1;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (!is_face(mesh, c)) continue;
        int g = group_of(mesh, mesh->physical[c], &last);
        if (g < 0 || role[g] == ROLE_NONE) continue;
        for (int64_t j = mesh->offset[c]; j < mesh->offset[c + 1]; ++j) {
            size_t i = (size_t)mesh->conn[j];
            if (!(flag[i] & 1)) continue; /* a face inside the mesh is no boundary */
            if (role[g] == ROLE_IGNORE) continue;
            flag[i] |= 4;
            if (role[g] == ROLE_FIXED) flag[i] |= 2;
            else if (gsurf[g] >= 0) {
                if (surf[i] >= 0 && surf[i] != gsurf[g]) flag[i] |= 8;
                surf[i] = gsurf[g];
            } else
                add_plane(&np, i, gn + 3 * g);
        }
    }
    /* a wedge's axis: the line r = 0 of the slab, w = 0 */
    if (m->reduction == CM_MOTION_AXISYMMETRIC)
        for (size_t i = 0; i < n; ++i)
            if ((flag[i] & 1) && m->slab[3 * i] == 0) {
                static const double ex[3] = {1, 0, 0}, ew[3] = {0, 0, 1};
                add_plane(&np, i, ex), add_plane(&np, i, ew);
                flag[i] |= 4;
            }
    int any_surface = 0;
    for (size_t i = 0; i < n; ++i) {
        cm_motion_kind k;
        double *d = m->dir + 3 * i;
        d[0] = d[1] = d[2] = 0;
        if (prescribed && prescribed[i]) k = CM_MOTION_PRESCRIBED;
        else if (!(flag[i] & 1)) k = CM_MOTION_FREE;
        else if (!(flag[i] & 4)) k = b && (flag[i] & 1) ? CM_MOTION_FIXED : CM_MOTION_FREE;
        else if (flag[i] & 2) k = CM_MOTION_FIXED;
        else if (surf[i] >= 0)
            k = np.count[i] || (flag[i] & 8) ? CM_MOTION_FIXED : CM_MOTION_SLIDE_SURFACE;
        else if (np.count[i] == 1) k = CM_MOTION_SLIDE_PLANE, memcpy(d, np.n + 9 * i, 3 * sizeof *d);
        else if (np.count[i] == 2) {
            const double *a = np.n + 9 * i, *c = a + 3;
            d[0] = a[1] * c[2] - a[2] * c[1];
            d[1] = a[2] * c[0] - a[0] * c[2];
            d[2] = a[0] * c[1] - a[1] * c[0];
            cm_motion_snap(d);
            k = CM_MOTION_SLIDE_LINE;
        } else if (np.count[i] >= 3) k = CM_MOTION_FIXED;
        else k = CM_MOTION_FREE; /* only on processor patches: inside the whole mesh */
        m->kind[i] = (uint8_t)k;
        any_surface |= k == CM_MOTION_SLIDE_SURFACE;
    }
    free(np.n), free(np.count), free(flag);
    if (any_surface) m->surface = surf;
    else free(surf);
    return CM_OK;
}

cm_status cm_boundary_motion_create(cm_context *ctx, const cm_mesh *mesh,
                                    const cm_mesh_boundary *b, const unsigned char *prescribed,
                                    const cm_motion_options *opt, cm_boundary_motion **motion)
{
    if (!motion) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_boundary_motion_create: motion is NULL");
    *motion = NULL;
    if (!mesh || !b)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_boundary_motion_create: mesh or boundary is NULL");
    cm_motion_options defaults;
    cm_motion_options_init(&defaults);
    if (!opt) opt = &defaults;
    size_t n = mesh->n_nodes, ng = mesh->n_groups;
    cm_boundary_motion *m = calloc(1, sizeof *m);
    uint8_t *role = calloc(ng ? ng : 1, 1);
    double *gn = calloc(3 * (ng ? ng : 1), sizeof *gn);
    int *gsurf = calloc(ng ? ng : 1, sizeof *gsurf);
    int *rgroups = malloc(2 * (ng ? ng : 1) * sizeof *rgroups);
    cm_status s = CM_OK;
    if (!m || !role || !gn || !gsurf || !rgroups ||
        !(m->kind = calloc(n ? n : 1, 1)) || !(m->dir = malloc(3 * (n ? n : 1) * sizeof *m->dir)))
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
    if (s >= 0) {
        m->n = n;
        m->diag = bbox_diag(mesh);
        s = group_roles(ctx, mesh, opt, role);
    }
    /* the 2-D and wedge reduction: empty and wedge patches that still slide */
    if (s >= 0 && !opt->all_fixed && !opt->no_reduction) {
        int n_empty = 0, n_wedge = 0;
        for (size_t g = 0; g < ng; ++g)
            if (mesh->groups[g].dim == 2 && role[g] == ROLE_SLIDE) {
                if (mesh->groups[g].kind == CM_PATCH_EMPTY) rgroups[n_empty++] = (int)g;
                if (mesh->groups[g].kind == CM_PATCH_WEDGE) rgroups[ng + n_wedge++] = (int)g;
            }
        s = cm_motion_reduce(ctx, m, mesh, b, rgroups, n_empty, rgroups + ng, n_wedge,
                             FLAT_TYPED * m->diag);
    }
    if (s >= 0 && !opt->all_fixed && !m->partner) {
        int n_cyclic = 0;
        for (size_t g = 0; g < ng; ++g)
            if (mesh->groups[g].dim == 2 && role[g] == ROLE_SLIDE &&
                mesh->groups[g].kind == CM_PATCH_CYCLIC)
                rgroups[n_cyclic++] = (int)g;
        s = cm_motion_pair_cyclic(ctx, m, mesh, rgroups, n_cyclic, FLAT_TYPED * m->diag);
    }
    const double *X = m && m->slab ? m->slab : mesh->xyz;
    int warned = 0;
    if (s >= 0) s = slide_geometry(ctx, m, mesh, X, role, gn, gsurf, &warned);
    if (s >= 0) s = node_kinds(ctx, m, mesh, b, prescribed, role, gn, gsurf);
    if (s >= 0 && m->partner) {
        /* a pair moves as one: the partner of a prescribed node takes its motion */
        m->copy = calloc(n ? n : 1, 1);
        if (!m->copy) s = cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
        for (size_t i = 0; s >= 0 && i < n; ++i) {
            int64_t j = m->partner[i];
            if (j >= 0 && m->kind[j] == CM_MOTION_PRESCRIBED && m->kind[i] != CM_MOTION_PRESCRIBED &&
                !(prescribed && prescribed[i]))
                m->copy[i] = 1;
        }
        for (size_t i = 0; s >= 0 && i < n; ++i)
            if (m->copy[i]) m->kind[i] = CM_MOTION_PRESCRIBED;
    }
    if (s >= 0 && m->surface) {
        m->xyz0 = m->slab ? m->slab : malloc(3 * (n ? n : 1) * sizeof *m->xyz0);
        if (!m->xyz0) s = cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
        else if (m->xyz0 != m->slab) memcpy(m->xyz0, mesh->xyz, 3 * n * sizeof *m->xyz0);
    }
    for (size_t i = 0; s >= 0 && i < n; ++i)
        ++m->count[m->kind[i]];
    free(role), free(gn), free(gsurf), free(rgroups);
    if (s < 0) {
        cm_boundary_motion_destroy(&m);
        return s;
    }
    *motion = m;
    (void)warned; /* logged where it happened */
    return CM_OK;
}

cm_motion_kind cm_boundary_motion_kind(const cm_boundary_motion *m, size_t node)
{
    return m && node < m->n ? (cm_motion_kind)m->kind[node] : CM_MOTION_FREE;
}

size_t cm_boundary_motion_count(const cm_boundary_motion *m, cm_motion_kind kind)
{
    return m && (int)kind >= 0 && kind < CM_MOTION_N_KINDS ? m->count[kind] : 0;
}

cm_motion_reduction cm_boundary_motion_reduction(const cm_boundary_motion *m, double *axis,
                                                 double *angle)
{
    if (axis) memcpy(axis, m ? m->axis : (const double[6]){0}, 6 * sizeof *axis);
    if (angle) *angle = m ? m->angle : 0;
    return m ? m->reduction : CM_MOTION_3D;
}

int64_t cm_boundary_motion_partner(const cm_boundary_motion *m, size_t node)
{
    return m && m->partner && node < m->n ? m->partner[node] : -1;
}

/* Which node of a pair whose kinds differ gives the pair its motion: the stronger. */
static int rank_of(uint8_t kind)
{
    return kind == CM_MOTION_PRESCRIBED ? 3 : kind == CM_MOTION_FIXED ? 2 : kind != CM_MOTION_FREE;
}

void cm_motion_project_work(const cm_boundary_motion *m, double *w, double *dropped,
                            size_t *worst)
{
    *dropped = 0, *worst = 0;
    const int planar = m->reduction != CM_MOTION_3D; /* the 2-D plane's normal is axis + 3 */
    const double *pn = m->reduction == CM_MOTION_2D ? m->axis + 3 : (const double[3]){0, 0, 1};
    for (size_t i = 0; i < m->n; ++i) {
        double *d = w + 3 * i;
        const double *u = m->dir + 3 * i;
        switch ((cm_motion_kind)m->kind[i]) {
        case CM_MOTION_FIXED:
            d[0] = d[1] = d[2] = 0;
            break;
        case CM_MOTION_PRESCRIBED:
            if (m->copy && m->copy[i]) memcpy(d, w + 3 * m->partner[i], 3 * sizeof *d);
            if (planar) {
                double dn = d[0] * pn[0] + d[1] * pn[1] + d[2] * pn[2];
                if (fabs(dn) > *dropped) *dropped = fabs(dn), *worst = i;
                for (int k = 0; k < 3; ++k)
                    d[k] -= dn * pn[k];
            }
            break;
        case CM_MOTION_SLIDE_PLANE: {
            double dn = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
            for (int k = 0; k < 3; ++k)
                d[k] -= dn * u[k];
            break;
        }
        case CM_MOTION_SLIDE_LINE: {
            double dt = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
            for (int k = 0; k < 3; ++k)
                d[k] = dt * u[k];
            break;
        }
        case CM_MOTION_SLIDE_SURFACE: {
            const double *x = m->xyz0 + 3 * i;
            double p[3] = {x[0] + d[0], x[1] + d[1], x[2] + d[2]}, q[3];
            cm_motion_surface_closest(m->surfaces[m->surface[i]], p, q);
            for (int k = 0; k < 3; ++k)
                d[k] = q[k] - x[k];
            break;
        }
        default:
            break;
        }
    }
    /* one motion per pair (exactly the same bits on both nodes): the mean, or the motion of
     * the node whose kind is stronger (prescribed, fixed, slide) */
    for (size_t i = 0; m->partner && i < m->n; ++i) {
        int64_t j = m->partner[i];
        if (j <= (int64_t)i) continue;
        int ri = rank_of(m->kind[i]), rj = rank_of(m->kind[j]);
        for (int k = 0; k < 3; ++k) {
            double v = ri == rj ? 0.5 * (w[3 * i + k] + w[3 * j + k])
                       : ri > rj ? w[3 * i + k] : w[3 * j + k];
            w[3 * i + k] = w[3 * j + k] = v;
        }
    }
}

cm_status cm_boundary_motion_project(cm_context *ctx, const cm_boundary_motion *m, double *disp)
{
    if (!m || !disp)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_boundary_motion_project: NULL argument");
    double *w = disp;
    if (m->slab && !(w = malloc(3 * (m->n ? m->n : 1) * sizeof *w)))
        return cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_project: out of memory");
    size_t worst0 = 0, worst1 = 0;
    double dropped0 = w != disp ? cm_motion_to_work(m, disp, w, &worst0) : 0, dropped1 = 0;
    cm_motion_project_work(m, w, &dropped1, &worst1);
    if (w != disp) {
        cm_motion_from_work(m, w, disp);
        free(w);
    }
    double dropped = fmax(dropped0, dropped1);
    if (dropped > 1e-12 * m->diag) {
        cm_log(ctx, CM_LOG_WARNING,
               "%s mesh: prescribed motion out of its plane dropped (largest %.3g, at node %zu)",
               m->reduction == CM_MOTION_2D ? "2-D" : "axisymmetric", dropped,
               dropped0 >= dropped1 ? worst0 : worst1);
        return CM_WARNING;
    }
    return CM_OK;
}
