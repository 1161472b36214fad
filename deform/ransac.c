/* Primitive detection (MLS paper section 6.3) by the efficient RANSAC of Schnabel, Wahl and
 * Klein (2007), on face barycentres and normals: minimal sets drawn locally (the other faces
 * from the first one's cell of a grid of random level, so that small primitives are found as
 * readily as large ones), candidates scored by the largest connected set of compatible faces
 * (distance < epsilon, normal within alpha, connected through shared edges instead of the
 * paper's parameter-space bitmap: a mesh has the connectivity), the best candidate extracted
 * once the chance of having missed a better one, 1 - (1 - n / (N L 2^(k-1)))^t, is below
 * 1 - p_t, and the search stopped when a primitive of tau faces would have been found by now.
 * An extracted candidate is refined by a forward search: refit on its faces, grow through
 * neighbours compatible with the refit, repeat until nothing is added. */
#include "cadmorph/ransac.h"
#include "cadmorph/shapeup.h"
#include "shape_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LEVELS 5     /* grid levels: cells of diag / 2^(l+1) */
#define BATCH 40     /* minimal sets drawn between extraction checks */
#define MAX_DRAWS 400000
#define PI 3.14159265358979323846

typedef struct cand {
    cm_primitive_type type;
    double p[7];
    size_t score;
} cand;

typedef struct rs {
    size_t nf, n_rem;
    double *c, *n, *area;
    int64_t *adj_off;
    int32_t *adj;
    double diag, eps, cosa;
    unsigned char *assigned, *ok;
    int32_t *queue, *best_list;
    int32_t *order[LEVELS];    /* faces sorted by cell */
    int32_t *cell_lo[LEVELS];  /* per face: its cell's range in order */
    int32_t *cell_hi[LEVELS];
    uint64_t rng;
    unsigned types;
} rs;

const char *cm_primitive_type_name(cm_primitive_type t)
{
    switch (t) {
    case CM_PRIMITIVE_PLANE: return "plane";
    case CM_PRIMITIVE_CYLINDER: return "cylinder";
    case CM_PRIMITIVE_SPHERE: return "sphere";
    case CM_PRIMITIVE_CONE: return "cone";
    }
    return "unknown";
}

void cm_ransac_options_init(cm_ransac_options *opt)
{
    if (!opt) return;
    opt->epsilon = 0.005;
    opt->normal_angle = 15;
    opt->min_faces = 0;
    opt->probability = 0.99;
    opt->types = 0xF;
    opt->seed = 1;
}

void cm_ransac_result_destroy(cm_ransac_result **r)
{
    if (!r || !*r) return;
    free((*r)->primitives), free((*r)->face_primitive), free((*r)->node_offset), free((*r)->nodes);
    free(*r);
    *r = NULL;
}

/* splitmix64: small, seedable, the same on every platform */
static uint64_t next_u64(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

static size_t rand_below(uint64_t *s, size_t n)
{
    return n ? (size_t)(next_u64(s) % n) : 0;
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static int normalize(double *v)
{
    double l = sqrt(dot3(v, v));
    if (!(l > 0) || !isfinite(l)) return 0;
    v[0] /= l, v[1] /= l, v[2] /= l;
    return 1;
}

/* distance of x from the primitive and the primitive's unit normal there */
static double prim_distance(const cand *k, const double *x, double nrm[3])
{
    const double *p = k->p;
    double v[3] = {x[0] - p[0], x[1] - p[1], x[2] - p[2]};
    switch (k->type) {
    case CM_PRIMITIVE_PLANE:
        memcpy(nrm, p + 3, 3 * sizeof *nrm);
        return fabs(dot3(v, p + 3));
    case CM_PRIMITIVE_SPHERE: {
        double l = sqrt(dot3(v, v));
        if (l > 0) nrm[0] = v[0] / l, nrm[1] = v[1] / l, nrm[2] = v[2] / l;
        else nrm[0] = 1, nrm[1] = nrm[2] = 0;
        return fabs(l - p[3]);
    }
    case CM_PRIMITIVE_CYLINDER: {
        double h = dot3(v, p + 3), q[3] = {v[0] - h * p[3], v[1] - h * p[4], v[2] - h * p[5]};
        double l = sqrt(dot3(q, q));
        if (l > 0) nrm[0] = q[0] / l, nrm[1] = q[1] / l, nrm[2] = q[2] / l;
        else nrm[0] = 1, nrm[1] = nrm[2] = 0;
        return fabs(l - p[6]);
    }
    case CM_PRIMITIVE_CONE: {
        double h = dot3(v, p + 3), q[3] = {v[0] - h * p[3], v[1] - h * p[4], v[2] - h * p[5]};
        double rho = sqrt(dot3(q, q)), len = sqrt(dot3(v, v)), th = p[6];
        double r[3] = {1, 0, 0};
        if (rho > 0) r[0] = q[0] / rho, r[1] = q[1] / rho, r[2] = q[2] / rho;
        for (int a = 0; a < 3; ++a)
            nrm[a] = cos(th) * r[a] - sin(th) * p[3 + a];
        double phi = atan2(rho, h);
        if (phi - th >= PI / 2) return len; /* behind the apex */
        return fabs(len * sin(phi - th));
    }
    }
    return INFINITY;
}

static int compatible(const rs *s, const cand *k, size_t f)
{
    double nrm[3];
    double d = prim_distance(k, s->c + 3 * f, nrm);
    return d < s->eps && fabs(dot3(nrm, s->n + 3 * f)) >= s->cosa;
}

/* The largest connected set of unassigned compatible faces (through shared edges); its
 * faces into s->best_list when keep. seed >= 0: only the component of that face. */
static size_t score(rs *s, const cand *k, int keep, int64_t seed)
{
    size_t nf = s->nf, best = 0;
    for (size_t f = 0; f < nf; ++f)
        s->ok[f] = !s->assigned[f] && compatible(s, k, f);
    for (size_t f0 = seed >= 0 ? (size_t)seed : 0; f0 < nf; ++f0) {
        if (s->ok[f0] != 1) {
            if (seed >= 0) break;
            continue;
        }
        size_t head = 0, tail = 0;
        s->queue[tail++] = (int32_t)f0;
        s->ok[f0] = 2;
        while (head < tail) {
            int32_t f = s->queue[head++];
            for (int64_t a = s->adj_off[f]; a < s->adj_off[f + 1]; ++a) {
                int32_t g = s->adj[a];
                if (s->ok[g] == 1) s->ok[g] = 2, s->queue[tail++] = g;
            }
        }
        if (tail > best) {
            best = tail;
            if (keep) memcpy(s->best_list, s->queue, tail * sizeof *s->queue);
        }
        if (seed >= 0) break;
    }
    return best;
}

/* ---- candidates from minimal sets ---- */

static int verify(const rs *s, const cand *k, const size_t *f, int m)
{
    for (int i = 0; i < m; ++i)
        if (!compatible(s, k, f[i])) return 0;
    return 1;
}

static int make_plane(const rs *s, const size_t f[3], cand *k)
{
    const double *a = s->c + 3 * f[0], *b = s->c + 3 * f[1], *c = s->c + 3 * f[2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    k->type = CM_PRIMITIVE_PLANE;
    memcpy(k->p, a, 3 * sizeof *a);
    cross3(u, v, k->p + 3);
    return normalize(k->p + 3) && verify(s, k, f, 3);
}

/* the point nearest to both lines p + t n and q + u m: their midpoint */
static int nearest_lines(const double *p, const double *n, const double *q, const double *m,
                         double out[3])
{
    double w[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
    double a = dot3(n, n), b = dot3(n, m), c = dot3(m, m), d = dot3(n, w), e = dot3(m, w);
    double den = a * c - b * b;
    if (!(fabs(den) > 1e-12)) return 0;
    double t = (b * e - c * d) / den, u = (a * e - b * d) / den;
    for (int i = 0; i < 3; ++i)
        out[i] = 0.5 * (p[i] + t * n[i] + q[i] + u * m[i]);
    return 1;
}

static int make_sphere(const rs *s, const size_t f[3], cand *k)
{
    const double *p = s->c + 3 * f[0], *q = s->c + 3 * f[1];
    k->type = CM_PRIMITIVE_SPHERE;
    if (!nearest_lines(p, s->n + 3 * f[0], q, s->n + 3 * f[1], k->p)) return 0;
    double r1 = sqrt((p[0] - k->p[0]) * (p[0] - k->p[0]) + (p[1] - k->p[1]) * (p[1] - k->p[1]) +
                     (p[2] - k->p[2]) * (p[2] - k->p[2]));
    double r2 = sqrt((q[0] - k->p[0]) * (q[0] - k->p[0]) + (q[1] - k->p[1]) * (q[1] - k->p[1]) +
                     (q[2] - k->p[2]) * (q[2] - k->p[2]));
    k->p[3] = 0.5 * (r1 + r2);
    /* huge spheres are planes */
    return k->p[3] < s->diag && verify(s, k, f, 3);
}

static int make_cylinder(const rs *s, const size_t f[3], cand *k)
{
    const double *p = s->c + 3 * f[0], *q = s->c + 3 * f[1];
    const double *n1 = s->n + 3 * f[0], *n2 = s->n + 3 * f[1];
    double a[3];
    cross3(n1, n2, a);
    if (!normalize(a)) return 0;
    /* both normal lines projected onto the plane normal to the axis meet on the axis */
    double pp[3], qq[3], m1[3], m2[3];
    double hp = dot3(p, a), hq = dot3(q, a), h1 = dot3(n1, a), h2 = dot3(n2, a);
    for (int i = 0; i < 3; ++i)
        pp[i] = p[i] - hp * a[i], qq[i] = q[i] - hq * a[i], m1[i] = n1[i] - h1 * a[i],
        m2[i] = n2[i] - h2 * a[i];
    k->type = CM_PRIMITIVE_CYLINDER;
    if (!nearest_lines(pp, m1, qq, m2, k->p)) return 0;
    memcpy(k->p + 3, a, sizeof a);
    double d1[3] = {pp[0] - k->p[0], pp[1] - k->p[1], pp[2] - k->p[2]};
    double d2[3] = {qq[0] - k->p[0], qq[1] - k->p[1], qq[2] - k->p[2]};
    k->p[6] = 0.5 * (sqrt(dot3(d1, d1)) + sqrt(dot3(d2, d2)));
    return k->p[6] < s->diag && verify(s, k, f, 3);
}

static int make_cone(const rs *s, const size_t f[3], cand *k)
{
    /* the apex: the common point of the three tangent planes */
    double m[9], rhs[3];
    for (int i = 0; i < 3; ++i) {
        memcpy(m + 3 * i, s->n + 3 * f[i], 3 * sizeof *m);
        rhs[i] = dot3(s->n + 3 * f[i], s->c + 3 * f[i]);
    }
    double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                 m[2] * (m[3] * m[7] - m[4] * m[6]);
    if (!(fabs(det) > 1e-6)) return 0;
    double apex[3];
    for (int i = 0; i < 3; ++i) {
        double mm[9];
        memcpy(mm, m, sizeof mm);
        for (int r = 0; r < 3; ++r)
            mm[3 * r + i] = rhs[r];
        apex[i] = (mm[0] * (mm[4] * mm[8] - mm[5] * mm[7]) - mm[1] * (mm[3] * mm[8] - mm[5] * mm[6]) +
                   mm[2] * (mm[3] * mm[7] - mm[4] * mm[6])) / det;
    }
    double u[3][3];
    for (int i = 0; i < 3; ++i) {
        for (int a = 0; a < 3; ++a)
            u[i][a] = s->c[3 * f[i] + a] - apex[a];
        if (!normalize(u[i])) return 0;
    }
    /* the axis: normal of the plane through the three unit directions' tips */
    double e1[3] = {u[1][0] - u[0][0], u[1][1] - u[0][1], u[1][2] - u[0][2]};
    double e2[3] = {u[2][0] - u[0][0], u[2][1] - u[0][1], u[2][2] - u[0][2]}, ax[3];
    cross3(e1, e2, ax);
    if (!normalize(ax)) return 0;
    if (dot3(ax, u[0]) < 0) ax[0] = -ax[0], ax[1] = -ax[1], ax[2] = -ax[2];
    double th = 0;
    for (int i = 0; i < 3; ++i)
        th += acos(fmax(-1, fmin(1, dot3(ax, u[i])))) / 3;
    /* nearly flat or nearly cylindrical cones are the other primitives */
    if (th < 3 * PI / 180 || th > 80 * PI / 180 || !isfinite(th)) return 0;
    double far = 0;
    for (int a = 0; a < 3; ++a)
        far = fmax(far, fabs(apex[a]));
    k->type = CM_PRIMITIVE_CONE;
    memcpy(k->p, apex, sizeof apex);
    memcpy(k->p + 3, ax, sizeof ax);
    k->p[6] = th;
    return verify(s, k, f, 3);
}

/* ---- refits (the forward search's fits) ---- */

static int refit(cm_context *ctx, rs *s, cand *k, size_t m, const int32_t *list, double *buf,
                 double *tmp)
{
    for (size_t i = 0; i < m; ++i)
        memcpy(buf + 3 * i, s->c + 3 * list[i], 3 * sizeof *buf);
    double fit[7];
    switch (k->type) {
    case CM_PRIMITIVE_PLANE:
        if (m < 3 || cm_shape_project_plane(ctx, m, buf, tmp, fit) < 0) return 0;
        memcpy(k->p, fit, 6 * sizeof *fit);
        return 1;
    case CM_PRIMITIVE_CYLINDER:
        if (m < 5 || cm_shape_project_cylinder(ctx, m, buf, k->p, tmp, fit) < 0) return 0;
        memcpy(k->p, fit, 7 * sizeof *fit);
        return k->p[6] < s->diag;
    case CM_PRIMITIVE_SPHERE: {
        /* algebraic: |x|^2 + D.x + E = 0, in coordinates about the old centre */
        if (m < 4) return 0;
        double a[16] = {0}, b[4] = {0};
        for (size_t i = 0; i < m; ++i) {
            double y[3] = {buf[3 * i] - k->p[0], buf[3 * i + 1] - k->p[1], buf[3 * i + 2] - k->p[2]};
            double row[4] = {y[0], y[1], y[2], 1}, z = -dot3(y, y);
            for (int p = 0; p < 4; ++p) {
                b[p] += row[p] * z;
                for (int q = 0; q < 4; ++q)
                    a[4 * p + q] += row[p] * row[q];
            }
        }
        if (!cm_shape_solve_small(4, a, b)) return 0;
        double cen[3] = {-b[0] / 2, -b[1] / 2, -b[2] / 2}, r2 = dot3(cen, cen) - b[3];
        if (!(r2 > 0) || !isfinite(r2)) return 0;
        for (int i = 0; i < 3; ++i)
            k->p[i] += cen[i];
        k->p[3] = sqrt(r2);
        return k->p[3] < s->diag;
    }
    case CM_PRIMITIVE_CONE:
        /* nearly flat or nearly cylindrical cones are the other primitives */
        if (m < 7 || cm_shape_project_cone(ctx, m, buf, k->p, tmp, fit) < 0) return 0;
        if (!(fit[6] > 0.01 && fit[6] < 1.5)) return 0;
        memcpy(k->p, fit, 7 * sizeof *fit);
        return 1;
    }
    return 0;
}

/* A simpler primitive that fits the faces of a curved candidate as well (a plane for a huge
 * cylinder or sphere, a cylinder for a slender cone) replaces it. */
static void prefer_simple(cm_context *ctx, rs *s, cand *k, size_t m, const int32_t *list,
                          double *buf, double *tmp)
{
    if (k->type == CM_PRIMITIVE_PLANE) return;
    cand alt[2];
    int na = 0;
    alt[na] = *k, alt[na++].type = CM_PRIMITIVE_PLANE;
    if (k->type == CM_PRIMITIVE_CONE) {
        alt[na] = *k, alt[na].type = CM_PRIMITIVE_CYLINDER;
        /* the start: the cone's axis (through its apex), the mean distance from it */
        memcpy(alt[na].p, k->p, 3 * sizeof(double));
        double r = 0;
        for (size_t i = 0; i < m; ++i) {
            double nrm[3];
            cand c0 = alt[na];
            c0.p[6] = 0;
            r += prim_distance(&c0, s->c + 3 * list[i], nrm) / (double)m;
        }
        alt[na].p[6] = r;
        ++na;
    }
    for (int i = 0; i < na; ++i) {
        if (!refit(ctx, s, &alt[i], m, list, buf, tmp)) continue;
        size_t good = 0;
        for (size_t j = 0; j < m; ++j)
            good += (size_t)compatible(s, &alt[i], (size_t)list[j]);
        if (good == m) {
            *k = alt[i];
            return;
        }
    }
}

/* The grids of localized sampling: per level, faces sorted by the integer cell of their
 * barycentre, and each face's cell range. */
static int cmp_key(const void *a, const void *b)
{
    const uint64_t *x = a, *y = b;
    return (x[0] > y[0]) - (x[0] < y[0]) ? (x[0] > y[0]) - (x[0] < y[0]) : (x[1] > y[1]) - (x[1] < y[1]);
}

static cm_status build_levels(cm_context *ctx, rs *s, const double lo[3])
{
    uint64_t *kv = malloc(s->nf * 2 * sizeof *kv);
    if (!kv) return cm_error(ctx, CM_ERR_NOMEM, "cm_ransac_detect: out of memory");
    for (int l = 0; l < LEVELS; ++l) {
        double h = s->diag / (double)(2u << l);
        s->order[l] = malloc(s->nf * sizeof(int32_t));
        s->cell_lo[l] = malloc(s->nf * sizeof(int32_t));
        s->cell_hi[l] = malloc(s->nf * sizeof(int32_t));
        if (!s->order[l] || !s->cell_lo[l] || !s->cell_hi[l]) {
            free(kv);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_ransac_detect: out of memory");
        }
        for (size_t f = 0; f < s->nf; ++f) {
            uint64_t key = 0;
            for (int a = 0; a < 3; ++a)
                key = key * 2097152u + (uint64_t)((s->c[3 * f + a] - lo[a]) / h);
            kv[2 * f] = key, kv[2 * f + 1] = f;
        }
        qsort(kv, s->nf, 2 * sizeof *kv, cmp_key);
        for (size_t i = 0; i < s->nf;) {
            size_t j = i;
            while (j < s->nf && kv[2 * j] == kv[2 * i])
                ++j;
            for (size_t q = i; q < j; ++q) {
                int32_t f = (int32_t)kv[2 * q + 1];
                s->order[l][q] = f;
                s->cell_lo[l][f] = (int32_t)i, s->cell_hi[l][f] = (int32_t)j;
            }
            i = j;
        }
    }
    free(kv);
    return CM_OK;
}

/* faces sharing an edge (corner nodes consecutive in each polygon) */
static int cmp_edge(const void *a, const void *b)
{
    const int64_t *x = a, *y = b;
    for (int i = 0; i < 2; ++i)
        if (x[i] != y[i]) return x[i] < y[i] ? -1 : 1;
    return 0;
}

static cm_status build_adjacency(cm_context *ctx, rs *s, const int64_t *off, const int64_t *nodes)
{
    size_t ne = (size_t)(off[s->nf] - off[0]);
    int64_t *e = malloc((ne ? ne : 1) * 3 * sizeof *e);
    int64_t *cnt = calloc(s->nf + 1, sizeof *cnt);
    if (!e || !cnt) {
        free(e), free(cnt);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_ransac_detect: out of memory");
    }
    size_t q = 0;
    for (size_t f = 0; f < s->nf; ++f) {
        int64_t m = off[f + 1] - off[f];
        for (int64_t i = 0; i < m; ++i) {
            int64_t a = nodes[off[f] + i], b = nodes[off[f] + (i + 1) % m];
            e[3 * q] = a < b ? a : b, e[3 * q + 1] = a < b ? b : a, e[3 * q + 2] = (int64_t)f;
            ++q;
        }
    }
    qsort(e, q, 3 * sizeof *e, cmp_edge);
    for (int pass = 0; pass < 2; ++pass) {
        for (size_t i = 0; i < q;) {
            size_t j = i;
            while (j < q && e[3 * j] == e[3 * i] && e[3 * j + 1] == e[3 * i + 1])
                ++j;
            for (size_t x = i; x < j; ++x)
                for (size_t y = i; y < j; ++y)
                    if (x != y && e[3 * x + 2] != e[3 * y + 2]) {
                        int64_t f = e[3 * x + 2];
                        if (pass == 0)
                            ++cnt[f + 1];
                        else
                            s->adj[cnt[f]++] = (int32_t)e[3 * y + 2];
                    }
            i = j;
        }
        if (pass == 0) {
            for (size_t f = 0; f < s->nf; ++f)
                cnt[f + 1] += cnt[f];
            s->adj_off = malloc((s->nf + 1) * sizeof *s->adj_off);
            s->adj = malloc(((size_t)cnt[s->nf] ? (size_t)cnt[s->nf] : 1) * sizeof *s->adj);
            if (!s->adj_off || !s->adj) {
                free(e), free(cnt);
                return cm_error(ctx, CM_ERR_NOMEM, "cm_ransac_detect: out of memory");
            }
            memcpy(s->adj_off, cnt, (s->nf + 1) * sizeof *cnt);
        }
    }
    free(e), free(cnt);
    return CM_OK;
}

static void rs_free(rs *s)
{
    free(s->c), free(s->n), free(s->area), free(s->adj_off), free(s->adj), free(s->assigned);
    free(s->ok), free(s->queue), free(s->best_list);
    for (int l = 0; l < LEVELS; ++l)
        free(s->order[l]), free(s->cell_lo[l]), free(s->cell_hi[l]);
}

/* A random unassigned face (rejection from all faces, then a scan when few remain). */
static int64_t random_face(rs *s)
{
    for (int t = 0; t < 64; ++t) {
        size_t f = rand_below(&s->rng, s->nf);
        if (!s->assigned[f]) return (int64_t)f;
    }
    size_t k = rand_below(&s->rng, s->n_rem);
    for (size_t f = 0; f < s->nf; ++f)
        if (!s->assigned[f] && k-- == 0) return (int64_t)f;
    return -1;
}

/* Two more unassigned faces from the cell of f[0] at a random level. */
static int local_sample(rs *s, size_t f[3])
{
    int l = (int)rand_below(&s->rng, LEVELS);
    int32_t lo = s->cell_lo[l][f[0]], hi = s->cell_hi[l][f[0]];
    for (int i = 1; i < 3; ++i) {
        int found = 0;
        for (int t = 0; t < 16 && !found; ++t) {
            int32_t g = s->order[l][lo + (int32_t)rand_below(&s->rng, (size_t)(hi - lo))];
            if (s->assigned[g] || (size_t)g == f[0] || (i == 2 && (size_t)g == f[1])) continue;
            f[i] = (size_t)g, found = 1;
        }
        if (!found) return 0;
    }
    return 1;
}

cm_status cm_ransac_detect(cm_context *ctx, size_t n_nodes, const double *xyz, size_t n_faces,
                           const int64_t *off, const int64_t *fnodes, const cm_ransac_options *opt,
                           cm_ransac_result **out)
{
    const char *who = "cm_ransac_detect";
    if (!out) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: out is NULL", who);
    *out = NULL;
    if (!xyz || !off || !fnodes) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL argument", who);
    if (n_faces > (size_t)INT32_MAX) return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: too many faces", who);
    cm_ransac_options o;
    if (opt)
        o = *opt;
    else
        cm_ransac_options_init(&o);
    if (!(o.epsilon > 0) || !(o.normal_angle > 0 && o.normal_angle < 90) ||
        !(o.probability > 0 && o.probability < 1))
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "%s: epsilon %g, normal angle %g, probability %g: need epsilon > 0, 0 < angle "
                        "< 90, 0 < probability < 1",
                        who, o.epsilon, o.normal_angle, o.probability);
    rs s;
    memset(&s, 0, sizeof s);
    s.nf = s.n_rem = n_faces;
    s.rng = o.seed;
    s.types = o.types & 0xF;
    cm_status st = CM_OK;
    cm_ransac_result *r = calloc(1, sizeof *r);
    size_t cap_prim = 16, n_cand = 0, cap_cand = 1024;
    cand *pool = malloc(cap_cand * sizeof *pool);
    double *buf = malloc((n_faces ? n_faces : 1) * 3 * sizeof *buf);
    double *tmp = malloc((n_faces ? n_faces : 1) * 3 * sizeof *tmp);
    s.c = malloc((n_faces ? n_faces : 1) * 3 * sizeof *s.c);
    s.n = malloc((n_faces ? n_faces : 1) * 3 * sizeof *s.n);
    s.area = malloc((n_faces ? n_faces : 1) * sizeof *s.area);
    s.assigned = calloc(n_faces ? n_faces : 1, 1);
    s.ok = malloc(n_faces ? n_faces : 1);
    s.queue = malloc((n_faces ? n_faces : 1) * sizeof *s.queue);
    s.best_list = malloc((n_faces ? n_faces : 1) * sizeof *s.best_list);
    if (r) {
        r->primitives = malloc(cap_prim * sizeof *r->primitives);
        r->face_primitive = malloc((n_faces ? n_faces : 1) * sizeof *r->face_primitive);
    }
    if (!r || !pool || !buf || !tmp || !s.c || !s.n || !s.area || !s.assigned || !s.ok || !s.queue ||
        !s.best_list || !r->primitives || !r->face_primitive) {
        st = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
        goto done;
    }
    /* barycentres, Newell normals, areas; the bounding box */
    double lo[3] = {DBL_MAX, DBL_MAX, DBL_MAX}, hi[3] = {-DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (size_t f = 0; f < n_faces; ++f) {
        int64_t m = off[f + 1] - off[f];
        double c[3] = {0, 0, 0}, nn[3] = {0, 0, 0};
        if (m < 3) {
            st = cm_error(ctx, CM_ERR_ARGUMENT, "%s: face %zu has %lld nodes", who, f, (long long)m);
            goto done;
        }
        for (int64_t i = 0; i < m; ++i) {
            int64_t a = fnodes[off[f] + i], b = fnodes[off[f] + (i + 1) % m];
            /* both ends of the edge are read below: check both before using either */
            if (a < 0 || (size_t)a >= n_nodes || b < 0 || (size_t)b >= n_nodes) {
                const int64_t bad = a < 0 || (size_t)a >= n_nodes ? a : b;
                st = cm_error(ctx, CM_ERR_ARGUMENT, "%s: face %zu: node %lld of %zu", who, f,
                              (long long)bad, n_nodes);
                goto done;
            }
            const double *p = xyz + 3 * a, *q = xyz + 3 * b;
            for (int d = 0; d < 3; ++d)
                c[d] += p[d] / (double)m, lo[d] = fmin(lo[d], p[d]), hi[d] = fmax(hi[d], p[d]);
            nn[0] += (p[1] - q[1]) * (p[2] + q[2]);
            nn[1] += (p[2] - q[2]) * (p[0] + q[0]);
            nn[2] += (p[0] - q[0]) * (p[1] + q[1]);
        }
        double len = sqrt(dot3(nn, nn));
        s.area[f] = len / 2;
        if (len > 0) nn[0] /= len, nn[1] /= len, nn[2] /= len;
        memcpy(s.c + 3 * f, c, sizeof c);
        memcpy(s.n + 3 * f, nn, sizeof nn);
    }
    for (size_t f = 0; f < n_faces; ++f)
        r->face_primitive[f] = -1;
    if (n_faces == 0) goto nodes;
    s.diag = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                  (hi[2] - lo[2]) * (hi[2] - lo[2]));
    s.eps = o.epsilon * s.diag;
    s.cosa = cos(o.normal_angle * PI / 180);
    size_t tau = o.min_faces ? o.min_faces : (n_faces / 100 > 10 ? n_faces / 100 : 10);
    st = build_adjacency(ctx, &s, off, fnodes);
    if (st >= 0) st = build_levels(ctx, &s, lo);
    if (st < 0) goto done;
    /* degenerate faces take part in nothing */
    for (size_t f = 0; f < n_faces; ++f)
        if (!(s.area[f] > 0)) s.assigned[f] = 1, --s.n_rem;
    size_t draws = 0;
    const double denom = (double)LEVELS * 4; /* L 2^(k-1), k = 3 */
    while (s.n_rem >= tau && draws < MAX_DRAWS) {
        for (int b = 0; b < BATCH; ++b) {
            size_t f[3];
            int64_t f0 = random_face(&s);
            if (f0 < 0) break;
            f[0] = (size_t)f0;
            ++draws;
            if (!local_sample(&s, f)) continue;
            for (int t = 0; t < 4; ++t) {
                if (!(s.types & (1u << t))) continue;
                cand k;
                int okc = t == CM_PRIMITIVE_PLANE      ? make_plane(&s, f, &k)
                          : t == CM_PRIMITIVE_CYLINDER ? make_cylinder(&s, f, &k)
                          : t == CM_PRIMITIVE_SPHERE   ? make_sphere(&s, f, &k)
                                                       : make_cone(&s, f, &k);
                if (!okc) continue;
                k.score = score(&s, &k, 0, -1);
                if (k.score < 3) continue;
                if (n_cand == cap_cand) {
                    cand *p2 = realloc(pool, 2 * cap_cand * sizeof *pool);
                    if (!p2) {
                        st = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
                        goto done;
                    }
                    pool = p2, cap_cand *= 2;
                }
                pool[n_cand++] = k;
            }
        }
        size_t bi = 0, best = 0;
        for (size_t i = 0; i < n_cand; ++i)
            if (pool[i].score > best || (pool[i].score == best && best && pool[i].type < pool[bi].type))
                best = pool[i].score, bi = i;
        double nr = (double)s.n_rem;
        double p_best = 1 - pow(1 - fmin(1, (double)best / (nr * denom)), (double)draws);
        if (best >= tau && p_best > o.probability) {
            /* extract: forward search from the candidate's component */
            cand k = pool[bi];
            size_t m = score(&s, &k, 1, -1);
            for (int it = 0; it < 20 && m >= 3; ++it) {
                cand k2 = k;
                if (!refit(ctx, &s, &k2, m, s.best_list, buf, tmp)) break;
                /* grow from the first face of the current set under the refit */
                int32_t seed = s.best_list[0];
                size_t m2 = compatible(&s, &k2, (size_t)seed) ? score(&s, &k2, 0, seed) : 0;
                if (m2 < m) break; /* the refit lost faces: keep the previous fit */
                k = k2;
                m = score(&s, &k, 1, seed);
                if (m2 == m && it > 0) break;
            }
            m = score(&s, &k, 1, -1);
            prefer_simple(ctx, &s, &k, m, s.best_list, buf, tmp);
            m = score(&s, &k, 1, -1);
            if (m < tau) {
                pool[bi].score = 0; /* lost its faces to the refit: drop it */
                continue;
            }
            if (r->n_primitives == cap_prim) {
                cm_primitive *p2 = realloc(r->primitives, 2 * cap_prim * sizeof *p2);
                if (!p2) {
                    st = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
                    goto done;
                }
                r->primitives = p2, cap_prim *= 2;
            }
            cm_primitive *pr = r->primitives + r->n_primitives;
            memset(pr, 0, sizeof *pr);
            pr->type = k.type;
            memcpy(pr->p, k.p, sizeof k.p);
            double ss = 0;
            for (size_t i = 0; i < m; ++i) {
                int32_t g = s.best_list[i];
                double nv[3], d = prim_distance(&k, s.c + 3 * g, nv);
                ss += d * d;
                pr->area += s.area[g];
                s.assigned[g] = 1;
                r->face_primitive[g] = (int32_t)r->n_primitives;
            }
            pr->n_faces = m;
            pr->rms = sqrt(ss / (double)m);
            ++r->n_primitives;
            s.n_rem -= m;
            /* rescore the pool on what is left */
            size_t keep = 0;
            for (size_t i = 0; i < n_cand; ++i) {
                pool[i].score = score(&s, pool + i, 0, -1);
                if (pool[i].score >= tau) pool[keep++] = pool[i];
            }
            n_cand = keep;
            continue;
        }
        double p_tau = 1 - pow(1 - fmin(1, (double)tau / (nr * denom)), (double)draws);
        if (best < tau && p_tau > o.probability) break;
    }
    r->candidates = draws;
    /* Boundary refinement: a face on the border of its primitive moves to a neighbouring
     * primitive it fits better (the border rows of a blend tangent to an earlier-extracted
     * plane belong to the blend); unassigned faces join a compatible neighbour. Then the
     * counts, areas and rms are those of the final faces. */
    for (int pass = 0; pass < 10; ++pass) {
        size_t changed = 0;
        for (size_t f = 0; f < n_faces; ++f) {
            if (!(s.area[f] > 0)) continue;
            int32_t cur = r->face_primitive[f], best = cur;
            double nv[3], bd = INFINITY;
            if (cur >= 0) {
                cand kc = {r->primitives[cur].type, {0}, 0};
                memcpy(kc.p, r->primitives[cur].p, sizeof kc.p);
                bd = prim_distance(&kc, s.c + 3 * f, nv);
            }
            for (int64_t a = s.adj_off[f]; a < s.adj_off[f + 1]; ++a) {
                int32_t q = r->face_primitive[s.adj[a]];
                if (q < 0 || q == best) continue;
                cand kq = {r->primitives[q].type, {0}, 0};
                memcpy(kq.p, r->primitives[q].p, sizeof kq.p);
                double d = prim_distance(&kq, s.c + 3 * f, nv);
                if (d < bd && compatible(&s, &kq, f)) bd = d, best = q;
            }
            if (best != cur) r->face_primitive[f] = best, ++changed;
        }
        if (!changed) break;
    }
    for (size_t i = 0; i < r->n_primitives; ++i)
        r->primitives[i].n_faces = 0, r->primitives[i].area = 0, r->primitives[i].rms = 0;
    for (size_t f = 0; f < n_faces; ++f) {
        int32_t q = r->face_primitive[f];
        if (q < 0) continue;
        cm_primitive *pr = r->primitives + q;
        cand kq = {pr->type, {0}, 0};
        memcpy(kq.p, pr->p, sizeof kq.p);
        double nv[3], d = prim_distance(&kq, s.c + 3 * f, nv);
        ++pr->n_faces, pr->area += s.area[f], pr->rms += d * d;
    }
    for (size_t i = 0; i < r->n_primitives; ++i)
        if (r->primitives[i].n_faces)
            r->primitives[i].rms = sqrt(r->primitives[i].rms / (double)r->primitives[i].n_faces);
nodes:
    /* the vertices of each primitive's faces */
    {
        size_t np = r->n_primitives;
        r->node_offset = calloc(np + 1, sizeof *r->node_offset);
        unsigned char *mark = calloc(n_nodes ? n_nodes : 1, 1);
        size_t total = 0;
        if (!r->node_offset || !mark) {
            free(mark);
            st = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
            goto done;
        }
        for (int pass = 0; pass < 2; ++pass) {
            size_t q = 0;
            for (size_t pi = 0; pi < np; ++pi) {
                memset(mark, 0, n_nodes ? n_nodes : 1);
                for (size_t f = 0; f < n_faces; ++f)
                    if (r->face_primitive[f] == (int32_t)pi)
                        for (int64_t i = off[f]; i < off[f + 1]; ++i)
                            mark[fnodes[i]] = 1;
                for (size_t v = 0; v < n_nodes; ++v)
                    if (mark[v]) {
                        if (pass) r->nodes[q] = (int64_t)v;
                        ++q;
                    }
                if (pass) r->node_offset[pi + 1] = (int64_t)q;
            }
            if (pass == 0) {
                total = q;
                r->nodes = malloc((total ? total : 1) * sizeof *r->nodes);
                if (!r->nodes) {
                    free(mark);
                    st = cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", who);
                    goto done;
                }
            }
        }
        free(mark);
    }
done:
    rs_free(&s);
    free(pool), free(buf), free(tmp);
    if (st < 0)
        cm_ransac_result_destroy(&r);
    else
        *out = r;
    return st;
}
