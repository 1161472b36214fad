/* Geometry shared by the boundary motion's files (motion_internal.h): face normals, unit
 * vectors snapped to the axes, the plane of a patch. */
#include "motion_internal.h"

#include <math.h>
#include <string.h>

static int is_face(const cm_mesh *mesh, size_t c)
{
    const cm_cell_info *ci = cm_cell_type_info((cm_cell_type)mesh->type[c]);
    return ci && ci->dim == 2;
}

static void normalize(double *v)
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0) v[0] /= l, v[1] /= l, v[2] /= l;
}

/* Components that are round-off are made 0, so that an axis-aligned plane's normal motion
 * is removed exactly (d - (d.n) n with n = (0, 0, 1) sets d_z to 0 bit for bit). */
void cm_motion_snap(double *v)
{
    normalize(v);
    for (int k = 0; k < 3; ++k)
        if (fabs(v[k]) < 1e-12) v[k] = 0;
    normalize(v);
    for (int k = 0; k < 3; ++k)
        if (fabs(fabs(v[k]) - 1) < 1e-15) v[k] = v[k] > 0 ? 1 : -1;
}

/* Area normal of a polygon (Newell). */
void cm_motion_face_normal(const double *xyz, const int64_t *nodes, int64_t k, double *n)
{
    n[0] = n[1] = n[2] = 0;
    for (int64_t j = 0; j < k; ++j) {
        const double *a = xyz + 3 * nodes[j], *b = xyz + 3 * nodes[(j + 1) % k];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
}

/* The normal of a group's faces (area weighted, signs aligned) and whether every face lies
 * in a plane of that normal to tol (the group may be several parallel planes, as a 2-D mesh's
 * frontAndBack). Returns 1 flat, 0 not (or no faces). */
int cm_motion_group_plane(const cm_mesh *mesh, const double *xyz, int tag, double tol, double *nrm)
{
    double sum[3] = {0, 0, 0};
    size_t faces = 0;
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (mesh->physical[c] != tag || !is_face(mesh, c)) continue;
        double f[3];
        cm_motion_face_normal(xyz, mesh->conn + mesh->offset[c], mesh->offset[c + 1] - mesh->offset[c], f);
        double sgn = sum[0] * f[0] + sum[1] * f[1] + sum[2] * f[2] < 0 ? -1 : 1;
        for (int k = 0; k < 3; ++k)
            sum[k] += sgn * f[k];
        ++faces;
    }
    if (!faces || !(sum[0] != 0 || sum[1] != 0 || sum[2] != 0)) return 0;
    memcpy(nrm, sum, sizeof sum);
    cm_motion_snap(nrm);
    for (size_t c = 0; c < mesh->n_cells; ++c) {
        if (mesh->physical[c] != tag || !is_face(mesh, c)) continue;
        const int64_t *nd = mesh->conn + mesh->offset[c];
        const double *p0 = xyz + 3 * nd[0];
        for (int64_t j = 1; j < mesh->offset[c + 1] - mesh->offset[c]; ++j) {
            const double *p = xyz + 3 * nd[j];
            double h = (p[0] - p0[0]) * nrm[0] + (p[1] - p0[1]) * nrm[1] + (p[2] - p0[2]) * nrm[2];
            if (fabs(h) > tol) return 0;
        }
    }
    return 1;
}

