/* checkMesh and cyclic patches, written from the definitions of OpenFOAM v1912
 * (cyclicPolyPatch: face i of a patch faces face i of its neighbourPatch, the patch of the
 * lower index is the owner; polyMeshTools' non-orthogonality and skewness across the pair;
 * checkMesh's checkCoupledPoints). Translational pairs only: the cell across a face is moved
 * by the offset between the two face centres. A rotational pair (or a pair of unequal sizes,
 * as cyclicAMI) is left uncoupled and counted in uncoupled_patches. */
#define _POSIX_C_SOURCE 200809L
#include "quality_foam_internal.h"

#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The value of a one-word entry `key value;` of a patch dictionary, into buf ("" if none). */
static void dict_word(const char *dict, const char *key, char *buf, size_t cap)
{
    buf[0] = 0;
    if (!dict) return;
    const size_t kl = strlen(key);
    for (const char *s = dict; (s = strstr(s, key)) != NULL; s += kl) {
        if ((s > dict && !isspace((unsigned char)s[-1]) && s[-1] != ';' && s[-1] != '{') ||
            !isspace((unsigned char)s[kl]))
            continue;
        const char *v = s + kl;
        while (isspace((unsigned char)*v)) ++v;
        size_t n = 0;
        while (v[n] && v[n] != ';' && !isspace((unsigned char)v[n]) && n + 1 < cap) ++n;
        memcpy(buf, v, n);
        buf[n] = 0;
        return;
    }
}

static int is_cyclic(const cm_foam_patch *pt) { return pt->type && !strcmp(pt->type, "cyclic"); }

cm_status cm_foam_couplings(cm_context *ctx, const cm_foam_poly *p, const double *xyz, const cm_foam_geom *g,
                            double *nbr_cc, uint8_t *coupled, cm_foam_quality *q)
{
    (void)ctx;
    const int64_t ni = p->n_internal;
    double sum = 0;
    size_t npts = 0;
    for (size_t i = 0; i < p->n_patches; ++i) {
        const cm_foam_patch *pt = &p->patches[i];
        if (!is_cyclic(pt)) continue;
        char nb[256], tr[64];
        dict_word(pt->dict, "neighbourPatch", nb, sizeof nb);
        dict_word(pt->dict, "transform", tr, sizeof tr);
        size_t j = 0;
        while (j < p->n_patches && strcmp(p->patches[j].name, nb)) ++j;
        if (j == p->n_patches || j == i || p->patches[j].n != pt->n || !strcmp(tr, "rotational")) {
            ++q->uncoupled_patches;
            continue;
        }
        const cm_foam_patch *o = &p->patches[j];
        const int owner = i < j;
        for (int64_t k = 0; k < pt->n; ++k) {
            const int64_t f = pt->start + k, h = o->start + k;
            const double *c = g->cc + 3 * p->owner[h];
            for (int d = 0; d < 3; ++d) nbr_cc[3 * (f - ni) + d] = c[d] + g->fc[3 * f + d] - g->fc[3 * h + d];
            coupled[f - ni] = owner ? 1 : 2;
            if (!owner) continue;
            /* the partner's points, moved onto this face, in reverse order from the first:
             * each within a 1e-4 fraction of the face's size of its match */
            const int64_t *a = p->face_nodes + p->face_off[f], *b = p->face_nodes + p->face_off[h];
            const int64_t na = p->face_off[f + 1] - p->face_off[f], nb_ = p->face_off[h + 1] - p->face_off[h];
            ++q->coupled_faces;
            if (na != nb_) {
                ++q->coupled_point_errors;
                continue;
            }
            double rmax = 0;
            for (int64_t m = 0; m < na; ++m) {
                double r = 0;
                for (int d = 0; d < 3; ++d) {
                    const double e = xyz[3 * a[m] + d] - g->fc[3 * f + d];
                    r += e * e;
                }
                if (r > rmax) rmax = r;
            }
            const double tol = 1e-4 * sqrt(rmax);
            int64_t fp = 0;
            for (int64_t m = 0; m < na; ++m) {
                double r = 0;
                for (int d = 0; d < 3; ++d) {
                    const double e = xyz[3 * a[fp] + d] - (xyz[3 * b[m] + d] + g->fc[3 * f + d] - g->fc[3 * h + d]);
                    r += e * e;
                }
                r = sqrt(r);
                if (r > tol) {
                    ++q->coupled_point_errors;
                    break;
                }
                sum += r;
                ++npts;
                fp = (fp - 1 + na) % na;
            }
        }
    }
    q->coupled_avg_mismatch = npts ? sum / (double)npts : 0;
    return CM_OK;
}
