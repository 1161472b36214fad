/* 2-D and axisymmetric meshes done exactly (docs/DESIGN.md, "Boundary motion by patch kind"):
 * recognising a one-cell-thick extruded mesh between two parallel empty planes, or a wedge
 * between two wedge planes through an axis; pairing each node with its image on the other
 * plane; a wedge's slab coordinates (r, z, w) in which it is morphed as a 2-D mesh. */
#include "motion_internal.h"

#include "cadmorph/kdtree.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* 1 when every node of a volume cell is a boundary node (the mesh is one cell thick). */
static int all_on_boundary(const cm_mesh *mesh, const cm_mesh_boundary *b,
                           const unsigned char *on_b)
{
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (b->cell_component[c] < 0) continue;
        const int64_t *p = mesh->conn + mesh->offset[c], *end = mesh->conn + mesh->offset[c + 1];
        if (mesh->type[c] == CM_CELL_POLYHEDRON) {
            int64_t nf = *p++;
            for (int64_t f = 0; f < nf && p < end; ++f) {
                int64_t k = *p++;
                for (int64_t j = 0; j < k; ++j)
                    if (!on_b[p[j]]) return 0;
                p += k;
            }
        } else
            for (; p < end; ++p)
                if (!on_b[*p]) return 0;
    }
    return 1;
}

/* Pairs the nodes of side A with those of side B whose coordinates q (#nodes x 3, the in-plane
 * part) agree to tol; 1 when every node of A and B has exactly one partner. */
static cm_status pair_sides(cm_context *ctx, size_t n, const double *q, const signed char *side,
                            double tol, int64_t *partner, int *ok)
{
    *ok = 0;
    size_t na = 0, nb = 0;
    for (size_t i = 0; i < n; ++i)
        na += side[i] == 1, nb += side[i] == -1;
    if (na == 0 || na != nb) return CM_OK;
    double *pb = malloc(3 * nb * sizeof *pb), *qa = malloc(3 * na * sizeof *qa);
    int64_t *ib = malloc(nb * sizeof *ib), *ia = malloc(na * sizeof *ia), *hit = malloc(na * sizeof *hit);
    double *d2 = malloc(na * sizeof *d2);
    cm_kdtree *tree = NULL;
    cm_status s = pb && qa && ib && ia && hit && d2
                      ? CM_OK
                      : cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
    for (size_t i = 0, ka = 0, kb = 0; s >= 0 && i < n; ++i) {
        if (side[i] == 1) memcpy(qa + 3 * ka, q + 3 * i, 3 * sizeof *qa), ia[ka++] = (int64_t)i;
        if (side[i] == -1) memcpy(pb + 3 * kb, q + 3 * i, 3 * sizeof *pb), ib[kb++] = (int64_t)i;
    }
    if (s >= 0) s = cm_kdtree_create(ctx, pb, nb, &tree);
    if (s >= 0) s = cm_kdtree_nearest(ctx, tree, qa, na, 1, hit, d2);
    if (s >= 0) {
        int good = 1;
        for (size_t i = 0; i < n; ++i)
            partner[i] = -1;
        for (size_t k = 0; good && k < na; ++k) {
            int64_t j = ib[hit[k]];
            if (!(d2[k] <= tol * tol) || partner[j] >= 0) good = 0;
            else partner[j] = ia[k], partner[ia[k]] = j;
        }
        *ok = good;
    }
    cm_kdtree_destroy(&tree);
    free(pb), free(qa), free(ib), free(ia), free(hit), free(d2);
    return s;
}

/* Marks the nodes of the faces of the listed groups. */
static void mark_groups(const cm_mesh *mesh, const int *groups, int ng, unsigned char *on,
                        unsigned char value)
{
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *ci = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!ci || ci->dim != 2) continue;
        for (int g = 0; g < ng; ++g)
            if (mesh->physical[c] == mesh->groups[groups[g]].tag)
                for (int64_t j = mesh->offset[c]; j < mesh->offset[c + 1]; ++j)
                    on[mesh->conn[j]] |= value;
    }
}

static int in_groups(const cm_mesh *mesh, int tag, const int *groups, int ng)
{
    for (int g = 0; g < ng; ++g)
        if (mesh->groups[groups[g]].tag == tag) return 1;
    return 0;
}

static cm_status reduce_2d(cm_context *ctx, cm_boundary_motion *m, const cm_mesh *mesh,
                           const cm_mesh_boundary *b, const int *empty, int n_empty,
                           const unsigned char *on, double tol)
{
    size_t n = mesh->n_nodes;
    for (size_t i = 0; i < b->n_nodes; ++i)
        if (!(on[b->nodes[i]] & 1)) return CM_OK;
    /* one normal for the faces of every empty group: they are the two planes */
    double nrm[3] = {0, 0, 0};
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        const cm_cell_info *ci = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!ci || ci->dim != 2) continue;
        if (!in_groups(mesh, mesh->physical[c], empty, n_empty)) continue;
        const int64_t *nd = mesh->conn + mesh->offset[c];
        int64_t k = mesh->offset[c + 1] - mesh->offset[c];
        double f[3];
        cm_motion_face_normal(mesh->xyz, nd, k, f);
        double sgn = dot(nrm, f) < 0 ? -1 : 1;
        for (int q = 0; q < 3; ++q)
            nrm[q] += sgn * f[q];
    }
    if (!(dot(nrm, nrm) > 0)) return CM_OK;
    cm_motion_snap(nrm);
    double hmin = INFINITY, hmax = -INFINITY;
    for (size_t i = 0; i < b->n_nodes; ++i) {
        double h = dot(mesh->xyz + 3 * b->nodes[i], nrm);
        hmin = fmin(hmin, h), hmax = fmax(hmax, h);
    }
    if (!(hmax - hmin > 2 * tol)) return CM_OK;
    signed char *side = calloc(n ? n : 1, 1);
    double *q = malloc(3 * (n ? n : 1) * sizeof *q);
    int64_t *partner = malloc((n ? n : 1) * sizeof *partner);
    if (!side || !q || !partner) {
        free(side), free(q), free(partner);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
    }
    int ok = 1;
    for (size_t i = 0; i < b->n_nodes && ok; ++i) {
        size_t v = (size_t)b->nodes[i];
        const double *x = mesh->xyz + 3 * v;
        double h = dot(x, nrm);
        side[v] = fabs(h - hmax) <= tol ? 1 : fabs(h - hmin) <= tol ? -1 : 0;
        ok = side[v] != 0;
        for (int k = 0; k < 3; ++k)
            q[3 * v + k] = x[k] - h * nrm[k];
    }
    cm_status s = CM_OK;
    if (ok) s = pair_sides(ctx, n, q, side, tol, partner, &ok);
    free(side), free(q);
    if (s >= 0 && ok) {
        m->reduction = CM_MOTION_2D;
        m->partner = partner, partner = NULL;
        memset(m->axis, 0, 3 * sizeof *m->axis);
        memcpy(m->axis + 3, nrm, sizeof nrm);
        cm_log(ctx, CM_LOG_DEBUG, "motion: a 2-D mesh, normal (%g %g %g), thickness %g", nrm[0],
               nrm[1], nrm[2], hmax - hmin);
    }
    free(partner);
    return s;
}

static cm_status reduce_wedge(cm_context *ctx, cm_boundary_motion *m, const cm_mesh *mesh,
                              const cm_mesh_boundary *b, const int *wedge, unsigned char *on,
                              double tol)
{
    size_t n = mesh->n_nodes;
    double n1[3], n2[3], p1[3] = {0, 0, 0}, p2[3] = {0, 0, 0};
    if (!cm_motion_group_plane(mesh, mesh->xyz, mesh->groups[wedge[0]].tag, tol, n1) ||
        !cm_motion_group_plane(mesh, mesh->xyz, mesh->groups[wedge[1]].tag, tol, n2))
        return CM_OK;
    double c = dot(n1, n2);
    if (fabs(c) > 1 - 1e-9) return CM_OK;
    size_t c1 = 0, c2 = 0;
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            if (on[i] & 1) p1[k] += mesh->xyz[3 * i + k], c1 += k == 0;
            if (on[i] & 2) p2[k] += mesh->xyz[3 * i + k], c2 += k == 0;
        }
    if (!c1 || !c2) return CM_OK;
    for (int k = 0; k < 3; ++k)
        p1[k] /= (double)c1, p2[k] /= (double)c2;
    /* the axis: the point alpha n1 + beta n2 on both planes, along n1 x n2 */
    double d1 = dot(n1, p1), d2 = dot(n2, p2), ez[3], a[3];
    double al = (d1 - d2 * c) / (1 - c * c), be = (d2 - d1 * c) / (1 - c * c);
    cross(n1, n2, ez);
    cm_motion_snap(ez);
    for (int k = 0; k < 3; ++k)
        a[k] = al * n1[k] + be * n2[k];
    /* every boundary node on a wedge plane or on the axis */
    double er0[3] = {0, 0, 0}, rmax = 0;
    for (size_t i = 0; i < b->n_nodes; ++i) {
        const double *x = mesh->xyz + 3 * b->nodes[i];
        double v[3] = {x[0] - a[0], x[1] - a[1], x[2] - a[2]}, z = dot(v, ez);
        for (int k = 0; k < 3; ++k)
            v[k] -= z * ez[k];
        double r = sqrt(dot(v, v));
        if (!(on[b->nodes[i]] & 3) && r > tol) return CM_OK;
        for (int k = 0; k < 3; ++k)
            er0[k] += v[k];
        rmax = fmax(rmax, r);
    }
    for (int k = 0; k < 3; ++k)
        er0[k] -= dot(er0, ez) * ez[k];
    if (!(dot(er0, er0) > 0) || !(rmax > 0)) return CM_OK;
    cm_motion_snap(er0);
    double et0[3];
    cross(ez, er0, et0);
    double *slab = malloc(3 * (n ? n : 1) * sizeof *slab), *er = malloc(3 * (n ? n : 1) * sizeof *er);
    signed char *side = calloc(n ? n : 1, 1);
    int64_t *partner = malloc((n ? n : 1) * sizeof *partner);
    cm_status s = slab && er && side && partner
                      ? CM_OK
                      : cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
    double thmin = INFINITY, thmax = -INFINITY;
    for (size_t i = 0; s >= 0 && i < n; ++i) {
        const double *x = mesh->xyz + 3 * i;
        double v[3] = {x[0] - a[0], x[1] - a[1], x[2] - a[2]}, z = dot(v, ez);
        for (int k = 0; k < 3; ++k)
            v[k] -= z * ez[k];
        double r = sqrt(dot(v, v)), th = 0;
        if (r <= tol) {
            r = 0;
            memcpy(er + 3 * i, er0, sizeof er0);
        } else {
            th = atan2(dot(v, et0), dot(v, er0));
            for (int k = 0; k < 3; ++k)
                er[3 * i + k] = v[k] / r;
            if (on[i] & 3) thmin = fmin(thmin, th), thmax = fmax(thmax, th);
            side[i] = (on[i] & 3) == 1 ? 1 : (on[i] & 3) == 2 ? -1 : 0;
        }
        /* w in units of length: the angle times the largest radius */
        slab[3 * i] = r, slab[3 * i + 1] = z, slab[3 * i + 2] = th * rmax;
    }
    int ok = s >= 0;
    double *q = ok ? malloc(3 * (n ? n : 1) * sizeof *q) : NULL;
    if (ok && !q) s = cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
    for (size_t i = 0; s >= 0 && q && i < n; ++i)
        q[3 * i] = slab[3 * i], q[3 * i + 1] = slab[3 * i + 1], q[3 * i + 2] = 0;
    if (s >= 0 && q) s = pair_sides(ctx, n, q, side, tol, partner, &ok);
    free(q), free(side);
    if (s >= 0 && ok) {
        m->reduction = CM_MOTION_AXISYMMETRIC;
        m->slab = slab, m->er = er, m->partner = partner;
        slab = er = NULL, partner = NULL;
        memcpy(m->axis, a, sizeof a), memcpy(m->axis + 3, ez, sizeof ez);
        m->angle = thmax - thmin;
        cm_log(ctx, CM_LOG_DEBUG, "motion: a wedge of %g degrees about (%g %g %g) + t (%g %g %g)",
               m->angle * 180 / acos(-1.0), a[0], a[1], a[2], ez[0], ez[1], ez[2]);
    }
    free(slab), free(er), free(partner);
    return s;
}

cm_status cm_motion_reduce(cm_context *ctx, cm_boundary_motion *m, const cm_mesh *mesh,
                           const cm_mesh_boundary *b, const int *empty, int n_empty,
                           const int *wedge, int n_wedge, double flat_tol)
{
    size_t n = mesh->n_nodes;
    if (!(n_empty > 0 || n_wedge == 2) || !b->n_nodes) return CM_OK;
    unsigned char *on = calloc(n ? n : 1, 1);
    if (!on) return cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
    for (size_t i = 0; i < b->n_nodes; ++i)
        on[b->nodes[i]] = 8;
    cm_status s = CM_OK;
    if (all_on_boundary(mesh, b, on)) {
        memset(on, 0, n);
        if (n_wedge == 2) {
            mark_groups(mesh, wedge, 1, on, 1);
            mark_groups(mesh, wedge + 1, 1, on, 2);
            s = reduce_wedge(ctx, m, mesh, b, wedge, on, flat_tol);
        } else {
            mark_groups(mesh, empty, n_empty, on, 1);
            s = reduce_2d(ctx, m, mesh, b, empty, n_empty, on, flat_tol);
        }
    }
    free(on);
    return s;
}

cm_status cm_motion_pair_cyclic(cm_context *ctx, cm_boundary_motion *m, const cm_mesh *mesh,
                                const int *cyclic, int n_cyclic, double flat_tol)
{
    size_t n = mesh->n_nodes;
    if (n_cyclic < 2 || m->partner) return CM_OK;
    signed char *side = calloc(n ? n : 1, 1);
    unsigned char *on = calloc(n ? n : 1, 1);
    double *q = malloc(3 * (n ? n : 1) * sizeof *q);
    int64_t *partner = malloc((n ? n : 1) * sizeof *partner), *pair = malloc((n ? n : 1) * sizeof *pair);
    cm_status s = side && on && q && partner && pair
                      ? CM_OK
                      : cm_error(ctx, CM_ERR_NOMEM, "cm_boundary_motion_create: out of memory");
    for (size_t i = 0; s >= 0 && i < n; ++i)
        partner[i] = -1;
    size_t pairs = 0;
    /* each two parallel flat cyclic patches whose nodes match along their normal: a
     * translational pair, whose sides get one motion */
    for (int a = 0; s >= 0 && a < n_cyclic; ++a)
        for (int c = a + 1; s >= 0 && c < n_cyclic; ++c) {
            double na[3], nc[3];
            if (!cm_motion_group_plane(mesh, mesh->xyz, mesh->groups[cyclic[a]].tag, flat_tol, na) ||
                !cm_motion_group_plane(mesh, mesh->xyz, mesh->groups[cyclic[c]].tag, flat_tol, nc) ||
                fabs(dot(na, nc)) < 1 - 1e-9)
                continue;
            memset(on, 0, n);
            mark_groups(mesh, cyclic + a, 1, on, 1);
            mark_groups(mesh, cyclic + c, 1, on, 2);
            int ok = 1;
            for (size_t i = 0; i < n && ok; ++i) {
                ok = on[i] != 3 && (on[i] == 0 || partner[i] < 0);
                side[i] = on[i] == 1 ? 1 : on[i] == 2 ? -1 : 0;
                double h = dot(mesh->xyz + 3 * i, na);
                for (int k = 0; k < 3; ++k)
                    q[3 * i + k] = mesh->xyz[3 * i + k] - h * na[k];
            }
            if (ok) s = pair_sides(ctx, n, q, side, flat_tol, pair, &ok);
            for (size_t i = 0; s >= 0 && ok && i < n; ++i)
                if (pair[i] >= 0) partner[i] = pair[i], ++pairs;
        }
    if (s >= 0 && pairs) {
        m->partner = partner, partner = NULL;
        cm_log(ctx, CM_LOG_DEBUG, "motion: %zu nodes of cyclic patches paired", pairs);
    }
    free(side), free(on), free(q), free(partner), free(pair);
    return s;
}

double cm_motion_to_work(const cm_boundary_motion *m, const double *disp, double *work,
                         size_t *worst)
{
    *worst = 0;
    if (!m->slab) {
        if (work != disp) memcpy(work, disp, 3 * m->n * sizeof *work);
        return 0;
    }
    const double *ez = m->axis + 3;
    double dropped = 0;
    for (size_t i = 0; i < m->n; ++i) {
        const double *d = disp + 3 * i, *er = m->er + 3 * i;
        double dz = dot(d, ez), dr = m->slab[3 * i] == 0 ? 0 : dot(d, er);
        if (m->kind[i] == CM_MOTION_PRESCRIBED) {
            double o[3], l;
            for (int k = 0; k < 3; ++k)
                o[k] = d[k] - dz * ez[k] - dr * er[k];
            l = sqrt(dot(o, o));
            if (l > dropped) dropped = l, *worst = i;
        }
        work[3 * i] = dr, work[3 * i + 1] = dz, work[3 * i + 2] = 0;
    }
    return dropped;
}

void cm_motion_from_work(const cm_boundary_motion *m, const double *work, double *disp)
{
    if (!m->slab) {
        if (work != disp) memcpy(disp, work, 3 * m->n * sizeof *disp);
        return;
    }
    const double *ez = m->axis + 3;
    for (size_t i = 0; i < m->n; ++i) {
        const double *er = m->er + 3 * i;
        double dr = m->slab[3 * i] == 0 ? 0 : work[3 * i], dz = work[3 * i + 1];
        for (int k = 0; k < 3; ++k)
            disp[3 * i + k] = dr * er[k] + dz * ez[k];
    }
}
