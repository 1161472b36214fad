/* OpenFOAM checkMesh's geometry checks, written from the definitions of OpenFOAM v1912
 * (primitiveMeshFaceCentresAndAreas, primitiveMeshCellCentresAndVols, primitiveMeshTools:
 * faceOrthogonality, faceSkewness, boundaryFaceSkewness, facePyramidVolume, cellClosedness;
 * polyMesh::checkFaceOrthogonality statistics over internal faces). The summation orders
 * follow OpenFOAM's so that the printed values agree to checkMesh's 6 digits. */
#define _POSIX_C_SOURCE 200809L
#include "quality_foam_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double mag(const double *a) { return sqrt(dot(a, a)); }

static void face_geometry(const cm_foam_poly *p, const double *xyz, int64_t f, double *fc, double *fa)
{
    const int64_t *n = p->face_nodes + p->face_off[f];
    const int64_t np = p->face_off[f + 1] - p->face_off[f];
    if (np == 3) {
        const double *a = xyz + 3 * n[0], *b = xyz + 3 * n[1], *c = xyz + 3 * n[2];
        double u[3], v[3];
        for (int k = 0; k < 3; ++k) {
            fc[k] = (1.0 / 3.0) * (a[k] + b[k] + c[k]);
            u[k] = b[k] - a[k];
            v[k] = c[k] - a[k];
        }
        fa[0] = 0.5 * (u[1] * v[2] - u[2] * v[1]);
        fa[1] = 0.5 * (u[2] * v[0] - u[0] * v[2]);
        fa[2] = 0.5 * (u[0] * v[1] - u[1] * v[0]);
        return;
    }
    double cen[3] = {0, 0, 0};
    for (int64_t i = 0; i < np; ++i)
        for (int k = 0; k < 3; ++k) cen[k] += xyz[3 * n[i] + k];
    for (int k = 0; k < 3; ++k) cen[k] /= (double)np;
    double sn[3] = {0, 0, 0}, sac[3] = {0, 0, 0}, sa = 0;
    for (int64_t i = 0; i < np; ++i) {
        const double *x = xyz + 3 * n[i], *y = xyz + 3 * n[(i + 1) % np];
        double c[3], u[3], v[3], t[3];
        for (int k = 0; k < 3; ++k) {
            c[k] = x[k] + y[k] + cen[k];
            u[k] = y[k] - x[k];
            v[k] = cen[k] - x[k];
        }
        t[0] = u[1] * v[2] - u[2] * v[1];
        t[1] = u[2] * v[0] - u[0] * v[2];
        t[2] = u[0] * v[1] - u[1] * v[0];
        double a = mag(t);
        for (int k = 0; k < 3; ++k) {
            sn[k] += t[k];
            sac[k] += a * c[k];
        }
        sa += a;
    }
    if (sa < FOAM_ROOTVSMALL) {
        memcpy(fc, cen, sizeof cen);
        fa[0] = fa[1] = fa[2] = 0;
    } else {
        for (int k = 0; k < 3; ++k) {
            fc[k] = (1.0 / 3.0) * sac[k] / sa;
            fa[k] = 0.5 * sn[k];
        }
    }
}

static double clamp1(double x) { return x < -1 ? -1 : x > 1 ? 1 : x; }
static double deg(double r) { return r * 180.0 / M_PI; }

void cm_foam_geometry_free(cm_foam_geom *g)
{
    free(g->fc);
    free(g->fa);
    free(g->cc);
    free(g->vol);
    memset(g, 0, sizeof *g);
}

cm_status cm_foam_geometry(cm_context *ctx, const cm_foam_poly *p, const double *xyz, cm_foam_geom *g)
{
    const int64_t nf = p->n_faces, ni = p->n_internal, nc = p->n_cells;
    memset(g, 0, sizeof *g);
    g->fc = malloc((size_t)(nf ? nf : 1) * 3 * sizeof *g->fc);
    g->fa = malloc((size_t)(nf ? nf : 1) * 3 * sizeof *g->fa);
    g->cc = calloc((size_t)(nc ? nc : 1) * 3, sizeof *g->cc);
    g->vol = calloc((size_t)(nc ? nc : 1), sizeof *g->vol);
    double *cest = calloc((size_t)(nc ? nc : 1) * 3, sizeof *cest);
    int64_t *ncf = calloc((size_t)(nc ? nc : 1), sizeof *ncf);
    if (!g->fc || !g->fa || !g->cc || !g->vol || !cest || !ncf) {
        free(cest);
        free(ncf);
        cm_foam_geometry_free(g);
        return cm_error(ctx, CM_ERR_NOMEM, "out of memory for %lld cells", (long long)nc);
    }
    double *fc = g->fc, *fa = g->fa, *cc = g->cc, *vol = g->vol;
#pragma omp parallel for schedule(static) if (nf > 20000)
    for (int64_t f = 0; f < nf; ++f) face_geometry(p, xyz, f, fc + 3 * f, fa + 3 * f);

    /* cell centres and volumes: pyramids on each face about the average of face centres */
    for (int64_t f = 0; f < nf; ++f) {
        int64_t o = p->owner[f];
        for (int k = 0; k < 3; ++k) cest[3 * o + k] += fc[3 * f + k];
        ++ncf[o];
    }
    for (int64_t f = 0; f < ni; ++f) {
        int64_t o = p->neighbour[f];
        for (int k = 0; k < 3; ++k) cest[3 * o + k] += fc[3 * f + k];
        ++ncf[o];
    }
    for (int64_t c = 0; c < nc; ++c)
        for (int k = 0; k < 3; ++k) cest[3 * c + k] /= (double)(ncf[c] ? ncf[c] : 1);
    for (int pass = 0; pass < 2; ++pass) {
        const int64_t n = pass ? ni : nf;
        const int64_t *cell = pass ? p->neighbour : p->owner;
        for (int64_t f = 0; f < n; ++f) {
            const int64_t c = cell[f];
            double d[3];
            for (int k = 0; k < 3; ++k) d[k] = pass ? cest[3 * c + k] - fc[3 * f + k] : fc[3 * f + k] - cest[3 * c + k];
            double pyr3 = dot(fa + 3 * f, d);
            for (int k = 0; k < 3; ++k) cc[3 * c + k] += pyr3 * ((3.0 / 4.0) * fc[3 * f + k] + (1.0 / 4.0) * cest[3 * c + k]);
            vol[c] += pyr3;
        }
    }
    for (int64_t c = 0; c < nc; ++c) {
        if (fabs(vol[c]) > FOAM_VSMALL)
            for (int k = 0; k < 3; ++k) cc[3 * c + k] /= vol[c];
        else
            memcpy(cc + 3 * c, cest + 3 * c, 3 * sizeof *cc);
        vol[c] *= 1.0 / 3.0;
    }
    free(cest);
    free(ncf);
    return CM_OK;
}

/* checkMesh's face-pyramid test of a face for its owner (side 0) or neighbour (side 1). */
static int wrong_pyramid(const cm_foam_geom *g, int64_t f, int64_t cell, int side)
{
    const double *c = g->cc + 3 * cell, *fc = g->fc + 3 * f;
    double h[3] = {c[0] - fc[0], c[1] - fc[1], c[2] - fc[2]};
    const double v = (1.0 / 3.0) * dot(g->fa + 3 * f, h);
    return (side ? v : -v) < -FOAM_SMALL;
}

void cm_foam_bad_cells(const cm_foam_poly *p, const cm_foam_geom *g, uint8_t *bad)
{
    for (int64_t c = 0; c < p->n_cells; ++c)
        if (g->vol[c] < FOAM_VSMALL) bad[c] = 1;
    for (int64_t f = 0; f < p->n_faces; ++f) {
        if (wrong_pyramid(g, f, p->owner[f], 0)) bad[p->owner[f]] = 1;
        if (f < p->n_internal && wrong_pyramid(g, f, p->neighbour[f], 1)) bad[p->neighbour[f]] = 1;
    }
}

cm_status cm_mesh_quality_foam(cm_context *ctx, const cm_mesh *mesh, cm_foam_quality *q)
{
    if (!mesh || !q) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_quality_foam: NULL argument");
    memset(q, 0, sizeof *q);
    cm_foam_poly *p = NULL;
    cm_status s = cm_foam_of_mesh(ctx, mesh, &p);
    if (s != CM_OK) return cm_error_prefix(ctx, s, "cm_mesh_quality_foam");
    const double *xyz = mesh->xyz;
    const int64_t nf = p->n_faces, ni = p->n_internal, nc = p->n_cells, nb = nf - ni;
    cm_foam_geom g = {0};
    double *smag = calloc((size_t)(nc ? nc : 1) * 3, sizeof *smag);
    double *sclosed = calloc((size_t)(nc ? nc : 1) * 3, sizeof *sclosed);
    double *nbr_cc = calloc((size_t)(nb ? nb : 1) * 3, sizeof *nbr_cc);
    uint8_t *coupled = calloc((size_t)(nb ? nb : 1), 1);
    if (!smag || !sclosed || !nbr_cc || !coupled) {
        s = cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_quality_foam: out of memory for %lld cells", (long long)nc);
        goto done;
    }
    q->points = (size_t)p->n_points;
    q->faces = (size_t)nf;
    q->internal_faces = (size_t)ni;
    q->cells = (size_t)nc;
    q->patches = p->n_patches;
    q->wedge_patch = -1;
    if ((s = cm_foam_check_topology(ctx, p, q)) < 0) goto fail;
    for (int k = 0; k < 3; ++k) {
        q->bbox[k] = mesh->n_nodes ? xyz[k] : 0;
        q->bbox[3 + k] = mesh->n_nodes ? xyz[k] : 0;
    }
    for (size_t i = 0; i < mesh->n_nodes; ++i)
        for (int k = 0; k < 3; ++k) {
            double x = xyz[3 * i + k];
            if (x < q->bbox[k]) q->bbox[k] = x;
            if (x > q->bbox[3 + k]) q->bbox[3 + k] = x;
        }
    if ((s = cm_foam_geometry(ctx, p, xyz, &g)) < 0) goto fail;
    const double *fc = g.fc, *fa = g.fa, *cc = g.cc, *vol = g.vol;

    /* directions: empty patches take theirs away, wedge patches the geometric one */
    cm_foam_directions(p, xyz, fa, q);
    int ndims = (q->directions[0] == 1) + (q->directions[1] == 1) + (q->directions[2] == 1);
    int align_failed = 0;
    if (ndims < 3 && (s = cm_foam_check_alignment(ctx, p, xyz, fa, q, &align_failed)) < 0) goto fail;
    if ((s = cm_foam_couplings(ctx, p, xyz, &g, nbr_cc, coupled, q)) < 0) goto fail;

    /* boundary openness */
    {
        double sum[3] = {0, 0, 0}, summag = 0;
        for (int64_t f = ni; f < nf; ++f) {
            for (int k = 0; k < 3; ++k) sum[k] += fa[3 * f + k];
            summag += mag(fa + 3 * f);
        }
        double worst = 0;
        for (int k = 0; k < 3; ++k) {
            q->boundary_openness[k] = sum[k] / (summag + FOAM_VSMALL);
            if (fabs(q->boundary_openness[k]) > worst) worst = fabs(q->boundary_openness[k]);
        }
        q->boundary_open = worst > 1e-6;
    }

    /* cell openness and aspect ratio (over the geometric directions) */
    for (int pass = 0; pass < 2; ++pass) {
        const int64_t n = pass ? ni : nf;
        const int64_t *cell = pass ? p->neighbour : p->owner;
        for (int64_t f = 0; f < n; ++f) {
            const int64_t c = cell[f];
            for (int k = 0; k < 3; ++k) {
                sclosed[3 * c + k] += pass ? -fa[3 * f + k] : fa[3 * f + k];
                smag[3 * c + k] += fabs(fa[3 * f + k]);
            }
        }
    }
    q->worst_aspect_cell = -1;
    for (int64_t c = 0; c < nc; ++c) {
        double open = 0, lo = 1e300, hi = -1e300;
        for (int k = 0; k < 3; ++k) {
            double o = fabs(sclosed[3 * c + k]) / (smag[3 * c + k] + FOAM_ROOTVSMALL);
            if (o > open) open = o;
            if (q->directions[k] == 1) {
                if (smag[3 * c + k] < lo) lo = smag[3 * c + k];
                if (smag[3 * c + k] > hi) hi = smag[3 * c + k];
            }
        }
        double ar = hi / (lo + FOAM_ROOTVSMALL);
        if (ndims == 3) {
            double v = vol[c] > FOAM_ROOTVSMALL ? vol[c] : FOAM_ROOTVSMALL;
            double a2 = (1.0 / 6.0) * (smag[3 * c] + smag[3 * c + 1] + smag[3 * c + 2]) / pow(v, 2.0 / 3.0);
            if (a2 > ar) ar = a2;
        }
        if (open > q->max_cell_openness) q->max_cell_openness = open;
        if (open > 1e-6) ++q->open_cells;
        if (c == 0 || ar > q->max_aspect_ratio) {
            q->max_aspect_ratio = ar;
            q->worst_aspect_cell = c;
        }
        if (ar > 1000) ++q->high_aspect_cells;
    }

    /* face areas and cell volumes */
    q->min_face_area = FOAM_GREAT;
    q->max_face_area = -FOAM_GREAT;
    for (int64_t f = 0; f < nf; ++f) {
        double a = mag(fa + 3 * f);
        if (a < FOAM_VSMALL) ++q->zero_area_faces;
        if (a < q->min_face_area) q->min_face_area = a;
        if (a > q->max_face_area) q->max_face_area = a;
    }
    q->min_volume = FOAM_GREAT;
    q->max_volume = -FOAM_GREAT;
    for (int64_t c = 0; c < nc; ++c) {
        if (vol[c] < FOAM_VSMALL) ++q->negative_volume_cells;
        if (vol[c] < q->min_volume) q->min_volume = vol[c];
        if (vol[c] > q->max_volume) q->max_volume = vol[c];
        q->total_volume += vol[c];
    }

    /* non-orthogonality: internal faces and both sides of cyclic pairs count towards the
     * thresholds, internal and the owner side of cyclic pairs towards max and average (as
     * polyMesh::checkFaceOrthogonality) */
    {
        const double severe = cos(70.0 * M_PI / 180.0);
        double mind = FOAM_GREAT, sum = 0;
        int64_t nsum = 0;
        q->worst_non_orthogonal_face = -1;
        for (int64_t f = 0; f < nf; ++f) {
            const int is_coupled = f >= ni && coupled[f - ni];
            if (f >= ni && !is_coupled) continue;
            const double *a = cc + 3 * p->owner[f], *b = f < ni ? cc + 3 * p->neighbour[f] : nbr_cc + 3 * (f - ni);
            double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            double o = dot(d, fa + 3 * f) / (mag(d) * mag(fa + 3 * f) + FOAM_ROOTVSMALL);
            if (o < severe) {
                if (o > FOAM_SMALL) ++q->severe_non_orthogonal_faces;
                else ++q->non_orthogonality_errors;
            }
            if (f >= ni && coupled[f - ni] != 1) continue;
            if (o < mind) {
                mind = o;
                q->worst_non_orthogonal_face = f;
            }
            sum += o;
            ++nsum;
        }
        if (nsum > 0) {
            q->max_non_orthogonality = deg(acos(clamp1(mind)));
            q->avg_non_orthogonality = deg(acos(clamp1(sum / (double)nsum)));
        }
    }

    /* face pyramids */
    for (int64_t f = 0; f < nf; ++f) {
        q->wrong_pyramids += (size_t)wrong_pyramid(&g, f, p->owner[f], 0);
        if (f < ni) q->wrong_pyramids += (size_t)wrong_pyramid(&g, f, p->neighbour[f], 1);
    }

    /* skewness: internal and cyclic faces against the line between the cell centres,
     * other boundary faces against their mirror cell; the far side of a cyclic pair counts
     * towards the maximum only */
    q->max_skewness = -FOAM_GREAT;
    q->worst_skew_face = -1;
    for (int64_t f = 0; f < nf; ++f) {
        const double *own = cc + 3 * p->owner[f], *A = fa + 3 * f, *F = fc + 3 * f;
        double cpf[3] = {F[0] - own[0], F[1] - own[1], F[2] - own[2]}, d[3];
        double scale;
        const int cpl = f >= ni ? coupled[f - ni] : 0;
        if (f < ni || cpl) {
            const double *nb = f < ni ? cc + 3 * p->neighbour[f] : nbr_cc + 3 * (f - ni);
            for (int k = 0; k < 3; ++k) d[k] = nb[k] - own[k];
            scale = 0.2;
        } else {
            double nrm[3], m = mag(A) + FOAM_ROOTVSMALL;
            for (int k = 0; k < 3; ++k) nrm[k] = A[k] / m;
            double t = dot(nrm, cpf);
            for (int k = 0; k < 3; ++k) d[k] = nrm[k] * t;
            scale = 0.4;
        }
        double r = dot(A, cpf) / (dot(A, d) + FOAM_ROOTVSMALL), sv[3];
        for (int k = 0; k < 3; ++k) sv[k] = cpf[k] - r * d[k];
        double msv = mag(sv), hat[3];
        for (int k = 0; k < 3; ++k) hat[k] = sv[k] / (msv + FOAM_ROOTVSMALL);
        double fd = scale * mag(d) + FOAM_ROOTVSMALL;
        for (int64_t k = p->face_off[f]; k < p->face_off[f + 1]; ++k) {
            const double *x = xyz + 3 * p->face_nodes[k];
            double e[3] = {x[0] - F[0], x[1] - F[1], x[2] - F[2]};
            double t = fabs(dot(hat, e));
            if (t > fd) fd = t;
        }
        double sk = msv / fd;
        if (sk > q->max_skewness) {
            q->max_skewness = sk;
            q->worst_skew_face = f;
        }
        if (sk > 4 && cpl != 2) ++q->high_skew_faces;
    }

    q->failed_checks = (size_t)(q->illegal_cells > 0) + (q->unused_points_faces || q->unused_points_cells) +
                       (size_t)q->upper_triangular_error + (q->bad_vertex_faces > 0) + (size_t)align_failed +
                       (size_t)q->boundary_open + (q->open_cells || q->high_aspect_cells) +
                       (q->min_face_area < FOAM_VSMALL) + (q->min_volume < FOAM_VSMALL) +
                       (q->non_orthogonality_errors > 0) + (q->wrong_pyramids > 0) + (q->high_skew_faces > 0) +
                       (q->coupled_point_errors > 0);
    goto done;
fail:
    s = cm_error_prefix(ctx, s, "cm_mesh_quality_foam");
done:
    cm_foam_geometry_free(&g);
    free(smag);
    free(sclosed);
    free(nbr_cc);
    free(coupled);
    cm_foam_poly_release(&p);
    return s;
}
