// Linear-simplex warp (Staten et al. 2011, a generalisation of BMSWEEP; paper section 5):
// TetGen's Delaunay tetrahedralisation of M0's constrained nodes, each free node stored as
// the barycentric coordinates of the Delaunay tet that contains it, and after the boundary
// moves the same combination of the moved corners. Affine motions are reproduced exactly;
// a tet may span a concavity of the domain, which is the method's known weakness.
// Location: a kD-tree gives the constrained node nearest to the query, a stochastic visibility
// walk from one of its tets crosses faces with the query on their far side until all
// coordinates are >= 0. A query beyond a hull face is outside every tet; it gets
// the tet with the largest smallest coordinate, used with its (partly negative) coordinates:
// counted, logged (CM_LOG_DEBUG), cm_warp_fallback_nodes. Exceptions stop here (STYLE 8).
// Reverse product (docs/DESIGN.md, "Gradients"): a free node is a fixed combination of four
// constrained ones, so J^T v hands each free node's v back to its corners with the same
// barycentric weights (the fallback's negative ones included).
#include "cadmorph/kdtree.h"

extern "C" {
#include "warp_method.h"
}

#include <tetgen.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <exception>
#include <new>
#include <vector>

namespace
{

double orient(const double *a, const double *b, const double *c, const double *d)
{
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

struct delaunay {
    const double *xyz = nullptr;
    std::vector<int64_t> tet; // 4 per tet
    std::vector<int64_t> nbr; // 4 per tet: across the face opposite corner k, -1 on the hull

    void bary(int64_t t, const double *q, double l[4]) const
    {
        const double *p[4];
        for (int k = 0; k < 4; ++k)
            p[k] = xyz + 3 * tet[4 * t + k];
        const double v = orient(p[0], p[1], p[2], p[3]);
        l[0] = orient(q, p[1], p[2], p[3]) / v;
        l[1] = orient(p[0], q, p[2], p[3]) / v;
        l[2] = orient(p[0], p[1], q, p[3]) / v;
        l[3] = orient(p[0], p[1], p[2], q) / v;
    }
};

void build_neighbours(delaunay &d)
{
    const size_t nt = d.tet.size() / 4;
    std::vector<std::array<int64_t, 4>> faces(4 * nt); // sorted corners, then 4 t + k
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 4; ++k) {
            std::array<int64_t, 4> &f = faces[4 * t + k];
            int m = 0;
            for (int j = 0; j < 4; ++j)
                if (j != k) f[m++] = d.tet[4 * t + j];
            std::sort(f.begin(), f.begin() + 3);
            f[3] = (int64_t)(4 * t + k);
        }
    std::sort(faces.begin(), faces.end());
    d.nbr.assign(4 * nt, -1);
    for (size_t i = 0; i + 1 < faces.size(); ++i)
        if (std::equal(faces[i].begin(), faces[i].begin() + 3, faces[i + 1].begin())) {
            d.nbr[faces[i][3]] = faces[i + 1][3] / 4;
            d.nbr[faces[i + 1][3]] = faces[i][3] / 4;
            ++i;
        }
}

// The tet with the largest smallest coordinate (the containing one if there is one).
int64_t best_tet(const delaunay &d, const std::vector<unsigned char> &flat, const double *q,
                 double l[4])
{
    int64_t best = 0;
    double best_min = -1e300, lb[4];
    for (int64_t t = 0; t < (int64_t)(d.tet.size() / 4); ++t) {
        if (flat[t]) continue;
        d.bary(t, q, lb);
        const double m = std::min(std::min(lb[0], lb[1]), std::min(lb[2], lb[3]));
        if (m > best_min) best_min = m, best = t, std::memcpy(l, lb, sizeof lb);
    }
    return best;
}

const double inside_tol = 1e-12; // a coordinate this far below 0 is round-off on a face

cm_status locate(cm_context *ctx, const double *pts, size_t n_pts, const double *query,
                 size_t n_query, int64_t *corner, double *bary, size_t *n_outside)
{
    const char *fn = "cm_warp_create: simplex";
    *n_outside = 0;
    if (n_pts < 4)
        return cm_error(ctx, CM_ERR_NUMERIC, "%s: %zu constrained nodes, a tet needs 4", fn, n_pts);
    if (n_pts > (size_t)0x7fffffff)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: too many constrained nodes for TetGen", fn);
    // coplanar points: TetGen asserts (aborts) on a zero extent instead of throwing, so find
    // four points spanning a tet first (farthest from a point, a line, then a plane)
    {
        auto dist2 = [&](size_t i, size_t j) {
            double s2 = 0;
            for (int k = 0; k < 3; ++k)
                s2 += (pts[3 * i + k] - pts[3 * j + k]) * (pts[3 * i + k] - pts[3 * j + k]);
            return s2;
        };
        size_t a = 0, b = 0, c = 0;
        for (size_t i = 1; i < n_pts; ++i)
            if (dist2(0, i) > dist2(0, b)) b = i;
        const double *pa = pts, *pb = pts + 3 * b, l2 = dist2(0, b);
        double best = 0;
        for (size_t i = 0; i < n_pts; ++i) {
            const double *p = pts + 3 * i;
            double u[3] = {pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]},
                   v[3] = {p[0] - pa[0], p[1] - pa[1], p[2] - pa[2]};
            double w[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                           u[0] * v[1] - u[1] * v[0]};
            double a2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
            if (a2 > best) best = a2, c = i;
        }
        double vol = 0;
        for (size_t i = 0; i < n_pts; ++i)
            vol = std::max(vol, std::fabs(orient(pa, pb, pts + 3 * c, pts + 3 * i)));
        (void)a;
        if (!(l2 > 0) || !(vol > 1e-12 * l2 * std::sqrt(l2)))
            return cm_error(ctx, CM_ERR_NUMERIC,
                            "%s: the %zu constrained nodes are coplanar: no Delaunay tet", fn,
                            n_pts);
    }
    tetgenio in, out;
    in.firstnumber = 0;
    in.numberofpoints = (int)n_pts;
    in.pointlist = new REAL[3 * n_pts];
    std::copy(pts, pts + 3 * n_pts, in.pointlist);
    char sw[] = "QJ"; // Delaunay only, quiet, keep duplicate points: indices stay ours
    try {
        tetrahedralize(sw, &in, &out);
    } catch (int code) {
        return cm_error(ctx, code == 1 ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                        "%s: TetGen's Delaunay tetrahedralisation failed with code %d (coplanar "
                        "constrained nodes?)",
                        fn, code);
    }
    if (out.numberoftetrahedra <= 0 || out.numberofcorners != 4 || out.numberofpoints != (int)n_pts)
        return cm_error(ctx, CM_ERR_NUMERIC,
                        "%s: TetGen made %d tets on %d of %zu points (coplanar constrained nodes?)",
                        fn, out.numberoftetrahedra, out.numberofpoints, n_pts);
    delaunay d;
    d.xyz = pts;
    d.tet.assign(out.tetrahedronlist, out.tetrahedronlist + 4 * (size_t)out.numberoftetrahedra);
    build_neighbours(d);
    std::vector<int64_t> tet_of_point(n_pts, -1);
    for (size_t t = 0; t < d.tet.size() / 4; ++t)
        for (int k = 0; k < 4; ++k)
            tet_of_point[d.tet[4 * t + k]] = (int64_t)t;
    cm_log(ctx, CM_LOG_DEBUG, "simplex: Delaunay of %zu constrained nodes: %d tets", n_pts,
           out.numberoftetrahedra);
    if (n_query == 0) return CM_OK;

    cm_kdtree *tree = nullptr;
    cm_status s = cm_kdtree_create(ctx, pts, n_pts, &tree);
    if (s < 0) return s;
    std::vector<int64_t> near(n_query);
    s = cm_kdtree_nearest(ctx, tree, query, n_query, 1, near.data(), nullptr);
    cm_kdtree_destroy(&tree);
    if (s < 0) return s;

    // TetGen's Delaunay tetrahedralisation of coplanar boundary nodes (planar faces, the
    // O-grids' symmetry planes) contains flat tets, whose coordinates are noise (1e14): the
    // walk never stops in one and leaves it through a random other face
    std::vector<unsigned char> flat(d.tet.size() / 4);
    for (size_t t = 0; t < flat.size(); ++t) {
        const double *p[4];
        double e2 = 0;
        for (int k = 0; k < 4; ++k)
            p[k] = pts + 3 * d.tet[4 * t + k];
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b) {
                double s2 = 0;
                for (int k = 0; k < 3; ++k)
                    s2 += (p[a][k] - p[b][k]) * (p[a][k] - p[b][k]);
                e2 = std::max(e2, s2);
            }
        flat[t] = std::fabs(orient(p[0], p[1], p[2], p[3])) <= 1e-10 * e2 * std::sqrt(e2);
    }
    // a stochastic visibility walk (it ends in a Delaunay mesh; Devillers, Pion, Teillaud
    // 2002): cross a random face, other than the entry face, with q on its far side; walks
    // longer than this are cycling and search every tet instead
    const int64_t max_steps = std::min<int64_t>((int64_t)(d.tet.size() / 4) + 16, 100000);
    size_t n_searched = 0;
    unsigned long long rng = 0x9E3779B97F4A7C15ULL;
    for (size_t i = 0; i < n_query; ++i) {
        const double *q = query + 3 * i;
        int64_t t = tet_of_point[near[i]] >= 0 ? tet_of_point[near[i]] : 0, from = -1;
        double l[4] = {0, 0, 0, 0};
        bool found = false;
        for (int64_t step = 0; step < max_steps; ++step) {
            int cand[4], nc = 0;
            bool negative = false;
            if (flat[t]) {
                negative = true;
                for (int j = 0; j < 4; ++j)
                    if (d.nbr[4 * t + j] >= 0 && d.nbr[4 * t + j] != from) cand[nc++] = j;
            } else {
                d.bary(t, q, l);
                for (int j = 0; j < 4; ++j)
                    if (!(l[j] >= -inside_tol)) {
                        negative = true;
                        if (d.nbr[4 * t + j] >= 0 && d.nbr[4 * t + j] != from) cand[nc++] = j;
                    }
            }
            if (!negative) {
                found = true;
                break;
            }
            if (nc == 0 && from >= 0) { // only the way back is open: take it
                for (int j = 0; j < 4; ++j)
                    if (d.nbr[4 * t + j] == from) cand[nc++] = j;
            }
            if (nc == 0) break; // only hull faces separate q from this tet: outside the hull
            rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
            from = t;
            t = d.nbr[4 * t + cand[(rng >> 33) % (unsigned)nc]];
        }
        if (!found) {
            // outside, or a walk that did not end: search every tet
            ++n_searched;
            t = best_tet(d, flat, q, l);
            const double m = std::min(std::min(l[0], l[1]), std::min(l[2], l[3]));
            if (m < -inside_tol) ++*n_outside;
        }
        for (int k = 0; k < 4; ++k) {
            corner[4 * i + k] = d.tet[4 * t + k];
            bary[4 * i + k] = l[k];
        }
    }
    cm_log(ctx, CM_LOG_DEBUG,
           "simplex: %zu of %zu walks ended outside the hull or did not end; "
           "every tet searched for them",
           n_searched, n_query);
    return CM_OK;
}

struct simplex_warp {
    cm_warp_nodes *nodes = nullptr;
    std::vector<int64_t> corner; // 4 per free node: node ids
    std::vector<double> bary;
    size_t n_outside = 0;
    ~simplex_warp() { cm_warp_nodes_destroy(&nodes); }
};

cm_status create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                 const unsigned char *constrained, simplex_warp *w)
{
    cm_status s = cm_warp_nodes_create(ctx, mesh, b, constrained, &w->nodes);
    if (s < 0) return s;
    const cm_warp_nodes &n = *w->nodes;
    if (n.n_free == 0) return CM_OK;
    std::vector<double> pts(3 * n.n_fixed), q(3 * n.n_free);
    for (size_t j = 0; j < n.n_fixed; ++j)
        std::memcpy(&pts[3 * j], mesh->xyz + 3 * n.fixed_nodes[j], 3 * sizeof(double));
    for (size_t i = 0; i < n.n_free; ++i)
        std::memcpy(&q[3 * i], mesh->xyz + 3 * n.free_nodes[i], 3 * sizeof(double));
    w->corner.resize(4 * n.n_free);
    w->bary.resize(4 * n.n_free);
    s = locate(ctx, pts.data(), n.n_fixed, q.data(), n.n_free, w->corner.data(), w->bary.data(),
               &w->n_outside);
    if (s < 0) return s;
    for (int64_t &c : w->corner)
        c = n.fixed_nodes[c]; // fixed index -> node id
    cm_log(ctx, CM_LOG_DEBUG,
           "simplex: %zu of %zu free nodes outside every Delaunay tet (extrapolated from the "
           "nearest)",
           w->n_outside, n.n_free);
    return CM_OK;
}

} // namespace

extern "C" cm_status cm_simplex_locate(cm_context *ctx, const double *pts, size_t n_pts,
                                       const double *query, size_t n_query, int64_t *corner,
                                       double *bary, size_t *n_outside)
{
    try {
        return locate(ctx, pts, n_pts, query, n_query, corner, bary, n_outside);
    } catch (const std::bad_alloc &) {
        return cm_error(ctx, CM_ERR_NOMEM, "cm_simplex_locate: out of memory");
    } catch (const std::exception &e) {
        return cm_error(ctx, CM_ERR_INTERNAL, "cm_simplex_locate: %s", e.what());
    } catch (int code) {
        return cm_error(ctx, CM_ERR_NUMERIC, "cm_simplex_locate: TetGen failed with code %d", code);
    } catch (...) {
        return cm_error(ctx, CM_ERR_INTERNAL, "cm_simplex_locate: unknown exception");
    }
}

namespace
{

void simplex_destroy(void *state)
{
    delete static_cast<simplex_warp *>(state);
}

size_t simplex_fallback_nodes(const void *state)
{
    return state ? static_cast<const simplex_warp *>(state)->n_outside : 0;
}

cm_status simplex_create(cm_context *ctx, const cm_mesh *mesh, const cm_mesh_boundary *b,
                         const unsigned char *constrained, const cm_warp_options *, void **state)
{
    simplex_warp *w = nullptr;
    try {
        w = new simplex_warp;
        cm_status s = create(ctx, mesh, b, constrained, w);
        if (s < 0) {
            delete w;
            return s;
        }
        *state = w;
        return s;
    } catch (const std::bad_alloc &) {
        delete w;
        return cm_error(ctx, CM_ERR_NOMEM, "cm_warp_create: simplex: out of memory");
    } catch (const std::exception &e) {
        delete w;
        return cm_error(ctx, CM_ERR_INTERNAL, "cm_warp_create: simplex: %s", e.what());
    } catch (int code) {
        delete w;
        return cm_error(ctx, CM_ERR_NUMERIC, "cm_warp_create: simplex: TetGen failed with code %d",
                        code);
    } catch (...) {
        delete w;
        return cm_error(ctx, CM_ERR_INTERNAL, "cm_warp_create: simplex: unknown exception");
    }
}

cm_status simplex_apply(cm_context *, void *state, double *disp, double *residual)
{
    const simplex_warp *w = static_cast<const simplex_warp *>(state);
    *residual = 0;
    const cm_warp_nodes &n = *w->nodes;
    for (size_t i = 0; i < n.n_free; ++i) {
        double v[3] = {0, 0, 0};
        for (int k = 0; k < 4; ++k) {
            const double *dc = disp + 3 * w->corner[4 * i + k];
            for (int j = 0; j < 3; ++j)
                v[j] += w->bary[4 * i + k] * dc[j];
        }
        std::memcpy(disp + 3 * n.free_nodes[i], v, sizeof v);
    }
    return CM_OK;
}

// Nothing here allocates or throws: no try block is needed at this boundary.
cm_status simplex_apply_transpose(cm_context *, void *state, const double *v, double *out)
{
    const simplex_warp *w = static_cast<const simplex_warp *>(state);
    const cm_warp_nodes &n = *w->nodes;
    cm_warp_nodes_add_identity(&n, v, out);
    for (size_t i = 0; i < n.n_free; ++i) {
        const double *vi = v + 3 * n.free_nodes[i];
        for (int k = 0; k < 4; ++k) {
            double *oc = out + 3 * w->corner[4 * i + k];
            for (int j = 0; j < 3; ++j)
                oc[j] += w->bary[4 * i + k] * vi[j];
        }
    }
    return CM_OK;
}

} // namespace

extern "C" const cm_warp_method_ops cm_warp_simplex = {
    "simplex",       simplex_create,         simplex_apply,
    simplex_destroy, simplex_fallback_nodes, simplex_apply_transpose,
    NULL, NULL};
