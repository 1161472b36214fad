// TetGen bridge: the watertight OpenCASCADE triangulation of a solid's faces is the PLC that
// TetGen fills with quality tets (switches p, q, a; Y keeps the surface as it is). Nodes that
// TetGen adds on the surface lie on the flat triangles; they are projected onto their CAD
// face or edge so that every boundary node lies on the model. Exceptions stop here (STYLE 8);
// OpenCASCADE is reached only through cad's C API, which already maps Standard_Failure, so
// no OpenCASCADE header is seen here (DESIGN: OpenCASCADE only in cad/).
#include "cadmorph/kdtree.h"
#include "cadmorph/optimize.h"
#include "cadmorph/tetmesh.h"

#include "gmsh_child.h"
#include "tetgen_run.h"
#include "tetmesh_assembly.h"
#include "tetmesh_gmsh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <map>
#include <new>
#include <set>
#include <string>
#include <vector>

using cmvol::orient;

namespace {

struct cad_guard {
    cm_cad_triangulation *t = nullptr;
    ~cad_guard() { cm_cad_triangulation_destroy(&t); }
};

struct tetgen_result {
    cm_tetgen_result r = {};
    ~tetgen_result() { cm_tetgen_result_free(&r); }
};

struct mesh_guard {
    cm_mesh *m = nullptr;
    ~mesh_guard() { cm_mesh_destroy(&m); }
};

// Projects the boundary nodes TetGen added (index >= first) onto the CAD model: onto the face
// when all their boundary triangles lie on one face, else onto the nearest edge between
// those faces. flat_exact: the nodes on planes and lines are on them already (TetGen's, on
// our triangles); gmsh's are on its own reading of the file, off ours within the tolerances.
cm_status project_new_nodes(cm_context *ctx, const cm_cad_model *model,
                            const cm_cad_triangulation &surf, size_t first,
                            std::vector<double> &xyz, const std::vector<int64_t> &tri,
                            const std::vector<int> &tri_face, size_t *n_projected,
                            bool flat_exact = true)
{
    *n_projected = 0;
    const char *fn = "cm_tetmesh_create";
    std::map<int64_t, std::set<int>> faces_of;  // new boundary node -> its CAD faces
    for (size_t t = 0; t < tri_face.size(); ++t)
        for (int k = 0; k < 3; ++k)
            if ((size_t)tri[3 * t + k] >= first) faces_of[tri[3 * t + k]].insert(tri_face[t]);
    std::map<int, std::vector<int64_t>> on_face;
    std::vector<int64_t> on_edge;
    for (const auto &nf : faces_of)
        (nf.second.size() == 1 ? on_face[*nf.second.begin()] : on_edge).push_back(nf.first);

    for (const auto &fn_nodes : on_face) {
        const std::vector<int64_t> &nodes = fn_nodes.second;
        // TetGen's points on the triangles of a planar face are on the plane already
        cm_cad_face_info info;
        cm_status s = cm_cad_face_get_info(ctx, model, fn_nodes.first, &info);
        if (s < 0) return s;
        if (flat_exact && info.type == CM_CAD_PLANE) continue;
        *n_projected += nodes.size();
        std::vector<double> p(3 * nodes.size()), foot(3 * nodes.size());
        for (size_t i = 0; i < nodes.size(); ++i)
            for (int k = 0; k < 3; ++k) p[3 * i + k] = xyz[3 * nodes[i] + k];
        // seeds: (u, v) of the nearest corner of OpenCASCADE's triangles on this face
        // (unseeded, the projection searches a grid first: ten times slower)
        std::vector<double> cxyz, cuv, seed(2 * nodes.size());
        for (size_t t = 0; t < surf.n_triangles; ++t)
            if (surf.tri_face[t] == fn_nodes.first)
                for (int k = 0; k < 3; ++k) {
                    cxyz.insert(cxyz.end(), &surf.xyz[3 * surf.tri[3 * t + k]],
                                &surf.xyz[3 * surf.tri[3 * t + k]] + 3);
                    cuv.insert(cuv.end(), &surf.tri_uv[6 * t + 2 * k], &surf.tri_uv[6 * t + 2 * k] + 2);
                }
        cm_kdtree *tree = nullptr;
        if ((s = cm_kdtree_create(ctx, cxyz.data(), cxyz.size() / 3, &tree)) < 0) return s;
        std::vector<int64_t> near(nodes.size());
        s = cm_kdtree_nearest(ctx, tree, p.data(), nodes.size(), 1, near.data(), nullptr);
        cm_kdtree_destroy(&tree);
        if (s < 0) return s;
        for (size_t i = 0; i < nodes.size(); ++i)
            seed[2 * i] = cuv[2 * near[i]], seed[2 * i + 1] = cuv[2 * near[i] + 1];
        s = cm_cad_project_face(ctx, model, fn_nodes.first, p.data(), nodes.size(), seed.data(),
                                nullptr, nullptr, foot.data());
        if (s < 0) return s;
        for (size_t i = 0; i < nodes.size(); ++i)
            for (int k = 0; k < 3; ++k) xyz[3 * nodes[i] + k] = foot[3 * i + k];
    }
    if (on_edge.empty()) return CM_OK;

    cm_cad_counts counts;
    cm_cad_get_counts(model, &counts);
    std::map<std::pair<int, int>, std::vector<int>> edges_between;  // face pair -> edges
    for (int e = 0; e < counts.edges; ++e) {
        const int *ef = nullptr;
        int n = 0;
        cm_status s = cm_cad_edge_faces(ctx, model, e, &ef, &n);
        if (s < 0) return s;
        for (int i = 0; i < n; ++i)
            for (int j = i + 1; j < n; ++j)
                edges_between[{std::min(ef[i], ef[j]), std::max(ef[i], ef[j])}].push_back(e);
    }
    std::vector<cm_cad_edge_info> einfo(counts.edges);
    for (int e = 0; e < counts.edges; ++e) {
        cm_status s = cm_cad_edge_get_info(ctx, model, e, &einfo[e]);
        if (s < 0) return s;
    }
    for (int64_t node : on_edge) {
        const std::set<int> &fs = faces_of[node];
        std::set<int> cand;
        for (auto a = fs.begin(); a != fs.end(); ++a)
            for (auto b = std::next(a); b != fs.end(); ++b) {
                auto it = edges_between.find({*a, *b});
                if (it != edges_between.end()) cand.insert(it->second.begin(), it->second.end());
            }
        if (cand.empty())
            return cm_error(ctx, CM_ERR_INTERNAL,
                            "%s: TetGen put node %lld where faces meet that share no edge", fn,
                            (long long)node);
        double best = INFINITY, bt = 0;
        int be = -1;
        for (int e : cand) {
            double t = 0, d = 0;
            cm_status s = cm_cad_project_edge(ctx, model, e, &xyz[3 * node], 1, &t, &d);
            if (s < 0) return s;
            if (d < best) best = d, bt = t, be = e;
        }
        // a point TetGen put on a straight segment is on the line already
        if (flat_exact && einfo[be].type == CM_CAD_LINE) continue;
        ++*n_projected;
        cm_status s = cm_cad_edge_eval(ctx, model, be, &bt, 1, &xyz[3 * node]);
        if (s < 0) return s;
    }
    return CM_OK;
}

// The mesh from a mesher's nodes, tets and boundary triangles (each with its CAD face):
// tets positively oriented (VTK), boundary triangles outward, groups "solid" and "face_<k>".
cm_status assemble(cm_context *ctx, int n_faces, std::vector<double> &xyz,
                   std::vector<std::array<int64_t, 4>> &tets, std::vector<int64_t> &tri,
                   const std::vector<int> &tri_face, cm_mesh **out)
{
    const char *fn = "cm_tetmesh_create";
    cm_status s = CM_OK;
    const size_t nn = xyz.size() / 3, nt = tets.size(), nb = tri_face.size();
    // tets positively oriented; boundary triangles away from their tet's fourth node
    for (auto &c : tets)
        if (orient(&xyz[3 * c[0]], &xyz[3 * c[1]], &xyz[3 * c[2]], &xyz[3 * c[3]]) < 0)
            std::swap(c[2], c[3]);
    std::vector<std::array<int64_t, 4>> keys;  // sorted face, then (tet's other node | -1 - tri)
    keys.reserve(4 * nt + nb);
    for (size_t t = 0; t < nb; ++t) {
        std::array<int64_t, 4> k = {tri[3 * t], tri[3 * t + 1], tri[3 * t + 2], -1 - (int64_t)t};
        std::sort(k.begin(), k.begin() + 3);
        keys.push_back(k);
    }
    for (const auto &c : tets)
        for (int f = 0; f < 4; ++f) {
            std::array<int64_t, 4> k = {c[(f + 1) % 4], c[(f + 2) % 4], c[(f + 3) % 4], c[f]};
            std::sort(k.begin(), k.begin() + 3);
            keys.push_back(k);
        }
    std::sort(keys.begin(), keys.end());
    for (size_t i = 0; i < keys.size(); ++i) {
        if (keys[i][3] >= 0) continue;
        const size_t t = (size_t)(-1 - keys[i][3]);
        int64_t apex = -1;
        for (size_t j = i + 1; j < keys.size() && std::equal(keys[i].begin(), keys[i].begin() + 3,
                                                             keys[j].begin()); ++j)
            if (keys[j][3] >= 0) apex = keys[j][3];
        if (apex < 0)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: boundary triangle %zu is on no tet", fn, t);
        int64_t *f = &tri[3 * t];
        if (orient(&xyz[3 * f[0]], &xyz[3 * f[1]], &xyz[3 * f[2]], &xyz[3 * apex]) > 0)
            std::swap(f[1], f[2]);
    }

    mesh_guard m;
    if ((s = cm_mesh_create(ctx, &m.m)) < 0) return s;
    if ((s = cm_mesh_resize_nodes(ctx, m.m, nn, 0)) < 0) return s;
    std::copy(xyz.begin(), xyz.end(), m.m->xyz);
    if ((s = cm_mesh_reserve_cells(ctx, m.m, nt + nb, 4 * nt + 3 * nb)) < 0) return s;
    for (const auto &c : tets)
        if ((s = cm_mesh_add_cell(ctx, m.m, CM_CELL_TET4, c.data(), 4, 1, 1, 0)) < 0) return s;
    for (size_t t = 0; t < nb; ++t)
        if ((s = cm_mesh_add_cell(ctx, m.m, CM_CELL_TRI3, &tri[3 * t], 3, tri_face[t] + 1,
                                  tri_face[t] + 1, 0)) < 0)
            return s;
    if ((s = cm_mesh_add_group(ctx, m.m, 3, 1, "solid")) < 0) return s;
    std::vector<char> used(n_faces, 0);
    for (int f : tri_face) used[f] = 1;
    for (int f = 0; f < n_faces; ++f) {
        if (!used[f]) continue;
        const std::string name = "face_" + std::to_string(f);
        if ((s = cm_mesh_add_group(ctx, m.m, 2, f + 1, name.c_str())) < 0) return s;
    }
    *out = m.m;
    m.m = nullptr;
    return CM_OK;
}

// What the meshers share: the size, the bounds, OpenCASCADE's surface triangulation (TetGen's
// input, the estimate's and the projections' seeds) and the time budget.
struct plan {
    const char *path;
    cm_cad_counts counts;
    double h, q, vmax;
    double volume = 0, max_tets = 0;  // enclosed by the triangulation; the bound on the estimate
    double estimate = 0;              // TetGen's tets expected (estimate_tets)
    int touching[2] = {-1, -1};       // solids that touch: an assembly (tetmesh_assembly.h)
    cad_guard surf;
};

// The enclosed volume and the tets expected in TetGen's fill of triangulation T: the volume
// at a fraction of the bound vmax per tet (TetGen's tets average about a third of it:
// measured on the bore model, sizes 0.1-0.3: 2.4-2.9), plus the graded layer over the
// boundary triangles (cmvol::surface_layers; constants: benchmarks/RESULTS.md, Meshers).
double estimate_tets(const cm_cad_triangulation &T, double h, double vmax, double *volume,
                     double *layers)
{
    double v6 = 0;
    for (size_t t = 0; t < T.n_triangles; ++t) {
        const double *a = &T.xyz[3 * T.tri[3 * t]], *b = &T.xyz[3 * T.tri[3 * t + 1]],
                     *c = &T.xyz[3 * T.tri[3 * t + 2]];
        v6 += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
              a[2] * (b[0] * c[1] - b[1] * c[0]);
    }
    *volume = std::fabs(v6) / 6;
    *layers = cmvol::surface_layers(T.xyz, T.tri, T.n_triangles, h);
    return CM_EST_TETGEN_VOLUME * *volume / vmax + CM_EST_TETGEN_LAYER * *layers;
}

const char *mesher_name(int mesher) { return mesher == CM_MESHER_GMSH ? "gmsh" : "TetGen"; }

// The checks before any mesher runs, the triangulation and the estimate.
cm_status prepare(cm_context *ctx, const cm_cad_model *model, const cm_tetmesh_options &o,
                  plan *pl)
{
    const char *fn = "cm_tetmesh_create";
    cm_cad_get_counts(model, &pl->counts);
    pl->path = cm_cad_path(model);
    if (pl->counts.solids == 0)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "%s: the model has no solid (%d faces): a mesher fills solids (make the "
                        "closed shells solids in the CAD system)",
                        *pl->path ? pl->path : fn, pl->counts.faces);
    cm_status s = cm_cad_check_solids_apart(ctx, model, pl->touching);
    if (s < 0) return s;
    double bb[6];
    cm_cad_bbox(model, bb);
    const double h = pl->h = o.size > 0 ? o.size : cm_bbox_diagonal(bb) / 20;
    const double q = pl->q = o.quality > 0 ? o.quality : 1.4;
    if (!std::isfinite(h) || !std::isfinite(q) || q < 1.0)
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: size %g or quality %g out of range (quality >= 1)",
                        fn, h, q);
    /* TetGen's refinement need not end for dihedral bounds much above 18 degrees */
    if (!(o.min_dihedral >= 0 && o.min_dihedral <= 20))
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: minimum dihedral angle %g out of [0, 20] degrees",
                        fn, o.min_dihedral);
    if (o.mesher != CM_MESHER_TETGEN && o.mesher != CM_MESHER_GMSH)
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: unknown mesher %d", fn, o.mesher);
    pl->vmax = h * h * h * std::sqrt(2.0) / 12.0;  // regular tet of edge h
    const double t0 = cm_wtime();
    cm_cad_triangulate_options topt;
    cm_cad_triangulate_options_init(&topt);
    topt.size = h;
    if ((s = cm_cad_triangulate(ctx, model, &topt, &pl->surf.t)) < 0) return s;
    const cm_cad_triangulation &T = *pl->surf.t;
    double layers = 0;
    const double estimate = pl->estimate = estimate_tets(T, h, pl->vmax, &pl->volume, &layers);
    cm_log(ctx, CM_LOG_DEBUG, "tetmesh: surface %zu nodes, %zu triangles (%.3f s), volume %g "
           "(%.4g x the bound), layers %.4g: about %.3g tets expected from TetGen", T.n_nodes,
           T.n_triangles, cm_wtime() - t0, pl->volume, pl->volume / pl->vmax, layers, estimate);
    pl->max_tets = o.max_tets > 0 ? o.max_tets : CM_TETMESH_MAX_TETS;
    return CM_OK;
}

// The volume's share of gmsh's estimate alone, checked before gmsh meshes any surface (which
// at a size far too small would take longer than any limit).
cm_status check_gmsh_volume(cm_context *ctx, const plan &pl)
{
    const double lower = CM_EST_GMSH_VOLUME * pl.volume / pl.vmax;
    if (!(lower <= pl.max_tets))
        return cm_error(ctx, CM_ERR_NOMEM,
                        "%s: size %g would make at least %.2g tets in gmsh (volume %g), more than "
                        "the limit of %.3g: use a larger size or lift the limit (cadmorph mesh "
                        "--force)", pl.path, pl.h, lower, pl.volume, pl.max_tets);
    return CM_OK;
}

// gmsh's mesh of the model's file, its boundary nodes then projected onto our faces and edges.
cm_status run_gmsh(cm_context *ctx, const cm_cad_model *model, const plan &pl, double limit,
                   cmvol::raw_mesh *r)
{
    cm_status s = check_gmsh_volume(ctx, pl);
    if (s < 0) return s;
    s = cmvol::gmsh_mesh(ctx, model, pl.h, limit, pl.volume, pl.max_tets, r);
    if (s < 0) return s;
    // gmsh's nodes lie on gmsh's reading of the file, which differs from ours within the
    // model's tolerances: put every boundary node on our faces (edges where faces meet)
    const double t0 = cm_wtime();
    size_t n_projected = 0;
    if ((s = project_new_nodes(ctx, model, *pl.surf.t, 0, r->xyz, r->tri, r->tri_face,
                               &n_projected, false)) < 0)
        return s;
    cm_log(ctx, CM_LOG_DEBUG, "tetmesh: %zu gmsh boundary nodes projected onto the faces and "
           "edges (%.3f s)", n_projected, cm_wtime() - t0);
    return CM_OK;
}

// OpenCASCADE's triangulation filled by TetGen, with its retries; the nodes TetGen adds on
// the surface projected onto the CAD faces and edges.
cm_status run_tetgen(cm_context *ctx, const cm_cad_model *model, const cm_tetmesh_options &o,
                     const plan &pl, double limit, cmvol::raw_mesh *r)
{
    const char *fn = "cm_tetmesh_create", *path = pl.path;
    const cm_cad_triangulation &T = *pl.surf.t;
    const cm_cad_counts &counts = pl.counts;
    const double h = pl.h, q = pl.q, vmax = pl.vmax;
    // refused before TetGen runs (gmsh's estimate comes from its own surface mesh)
    if (!(pl.estimate <= pl.max_tets))
        return cm_error(ctx, CM_ERR_NOMEM,
                        "%s: size %g would make about %.2g tets in TetGen (%zu surface triangles, "
                        "volume %g), more than the limit of %.3g: use a larger size or lift the "
                        "limit (cadmorph mesh --force)",
                        path, h, pl.estimate, T.n_triangles, pl.volume, pl.max_tets);
    if (T.n_open_edges)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "%s: the faces do not close a solid (%zu open or non-manifold edges)", fn,
                        T.n_open_edges);
    const double t1 = cm_wtime();
    cm_status s = cm_progress(ctx, "tetgen", 0, 1);
    if (s < 0) return s;

    const cm_tetgen_plc plc = {T.n_nodes, T.n_triangles, T.xyz, T.tri, nullptr};
    std::vector<int> marker(T.n_triangles);
    for (size_t t = 0; t < T.n_triangles; ++t) marker[t] = T.tri_face[t] + 1;  // 0: no marker
    cm_tetgen_plc in = plc;
    in.marker = marker.data();
    // TetGen's -d reports the triangles that intersect (what two touching solids or a bad
    // triangulation give) in words a user can act on; TetGen's error path crashes (now in the
    // child), which says less
    {
        const double td = cm_wtime();
        tetgen_result diag;
        int failure = 0;
        s = cm_tetgen_run(ctx, path, &in, "pdQ", limit, &diag.r, &failure);
        if (s < 0 && failure == 0) return s;
        if (s < 0) {
            // a crash or a timeout of the check itself: the meshing below says what happens
            cm_log(ctx, CM_LOG_DEBUG, "tetmesh: TetGen -d: %s", cm_context_message(ctx));
            if (failure == 3)
                return cm_error(ctx, s, "%s: TetGen's intersection check did not finish in %.3g s "
                                "(nothing more tried: raise the time limit, --time-limit)", path, limit);
        } else if (diag.r.n_trifaces > 0) {
            std::set<int> faces;
            for (size_t t = 0; t < diag.r.n_trifaces; ++t) faces.insert(diag.r.trimarker[t] - 1);
            std::string list;
            int shown = 0;
            for (int f : faces) {
                if (shown++ == 8) {
                    list += ", ...";
                    break;
                }
                list += (list.empty() ? "" : ", ") + std::to_string(f);
            }
            return cm_error(ctx, CM_ERR_UNSUPPORTED,
                            "%s: the surface triangulation intersects itself (%zu triangles on "
                            "CAD faces %s): TetGen cannot mesh it",
                            path, diag.r.n_trifaces, list.c_str());
        } else {
            cm_log(ctx, CM_LOG_DEBUG, "tetmesh: TetGen -d: no intersecting triangles (%.3f s)",
                   cm_wtime() - td);
        }
    }

    // What helps when TetGen crashes, asserts or gives up on a valid surface: keeping the
    // surface (-Y: no Steiner points on it, where fillcavity's assertion was met), a looser
    // quality bound (less refinement near degenerate spots), a surface moved off its exact
    // cocircular and coplanar configurations (its nodes put back afterwards)
    struct attempt {
        const char *label;
        bool keep_surface;
        double q, dihedral;
        bool perturb;
    };
    std::vector<attempt> attempts = {{"the switches asked for", o.preserve_surface != 0, q,
                                      o.min_dihedral, false}};
    if (!o.preserve_surface) attempts.push_back({"-Y (surface kept)", true, q, o.min_dihedral, false});
    if (q < 2 || o.min_dihedral > 0)
        attempts.push_back({"quality q2 without a dihedral bound", o.preserve_surface != 0,
                            std::max(q, 2.0), 0, false});
    attempts.push_back({"a surface perturbed by 1e-6 x size", o.preserve_surface != 0, q,
                        o.min_dihedral, true});
    tetgen_result tv;
    std::string tried;
    bool preserved = o.preserve_surface != 0;
    char sw[128] = "";
    std::vector<double> perturbed;
    size_t chosen = attempts.size();
    for (size_t a = 0; a < attempts.size(); ++a) {
        const attempt &at = attempts[a];
        /* the dihedral bound (after the radius-edge ratio) is what removes most slivers:
         * TetGen's -O optimisation levels changed no measured quality (benchmarks/RESULTS.md,
         * quality guarantee: tet meshes) */
        char dihedral[32] = "";
        if (at.dihedral > 0) std::snprintf(dihedral, sizeof dihedral, "/%.6g", at.dihedral);
        std::snprintf(sw, sizeof sw, "pzq%.6g%sa%.6g%sQ", at.q, dihedral, vmax,
                      at.keep_surface ? "Y" : "");
        in.xyz = T.xyz;
        if (at.perturb) {
            // a fixed sequence: the same model gives the same mesh
            perturbed.assign(T.xyz, T.xyz + 3 * T.n_nodes);
            uint64_t state = 0x9e3779b97f4a7c15ULL;
            for (double &x : perturbed) {
                state = state * 6364136223846793005ULL + 1442695040888963407ULL;
                x += 1e-6 * h * ((double)(state >> 11) / 9007199254740992.0 - 0.5);
            }
            in.xyz = perturbed.data();
        }
        int failure = 0;
        s = cm_tetgen_run(ctx, path, &in, sw, limit, &tv.r, &failure);
        if (s == CM_ERR_INTERRUPTED) return s;  // the caller's stop: no further attempt
        if (s >= 0 && (tv.r.n_tets == 0 || tv.r.corners != 4)) {
            cm_tetgen_result_free(&tv.r);
            s = cm_error(ctx, CM_ERR_NUMERIC, "%s: TetGen made no linear tets (switches %s)", path, sw);
        }
        if (s >= 0 && at.perturb) {
            // the input nodes go back onto the CAD model: refused if that inverts a tet
            size_t flipped = 0;
            std::vector<double> back(tv.r.xyz, tv.r.xyz + 3 * tv.r.n_points);
            std::copy(T.xyz, T.xyz + 3 * T.n_nodes, back.begin());
            for (size_t t = 0; t < tv.r.n_tets; ++t) {
                const int32_t *c = &tv.r.tet[4 * t];
                const double before = orient(&tv.r.xyz[3 * c[0]], &tv.r.xyz[3 * c[1]],
                                             &tv.r.xyz[3 * c[2]], &tv.r.xyz[3 * c[3]]);
                const double after = orient(&back[3 * c[0]], &back[3 * c[1]], &back[3 * c[2]],
                                            &back[3 * c[3]]);
                if ((before > 0) != (after > 0) || after == 0) ++flipped;
            }
            if (flipped) {
                cm_tetgen_result_free(&tv.r);
                s = cm_error(ctx, CM_ERR_NUMERIC, "%s: TetGen meshed the perturbed surface, but "
                             "putting its nodes back inverts %zu tets", path, flipped);
            } else {
                std::copy(back.begin(), back.end(), tv.r.xyz);
            }
        }
        if (s >= 0) {
            chosen = a;
            preserved = at.keep_surface;
            break;
        }
        std::string why = cm_context_message(ctx);
        const std::string prefix = std::string(path) + ": ";
        if (why.compare(0, prefix.size(), prefix) == 0) why.erase(0, prefix.size());
        tried += std::string(tried.empty() ? "" : "; ") + at.label + ": " + why;
        if (failure == 3) break;  // a hang is not retried: each would take the whole limit
    }
    if (chosen == attempts.size()) {
        const bool hung = tried.find("did not finish") != std::string::npos;
        return cm_error(ctx, s < 0 ? s : CM_ERR_NUMERIC, "%s: TetGen could not mesh it. Tried %s%s",
                        path, tried.c_str(),
                        hung ? " (nothing more: raise the time limit, --time-limit)" : "");
    }
    if (chosen > 0)
        cm_log(ctx, CM_LOG_WARNING, "%s: TetGen meshed with %s (switches %s) after: %s", path,
               attempts[chosen].label, sw, tried.c_str());

    if (tv.r.trimarker == nullptr && tv.r.n_trifaces)
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: TetGen gave no face markers", fn);
    const size_t nn = tv.r.n_points, nt = tv.r.n_tets, nb = tv.r.n_trifaces;
    std::vector<double> &xyz = r->xyz;
    std::vector<int64_t> &tri = r->tri;
    std::vector<int> &tri_face = r->tri_face;
    xyz.assign(tv.r.xyz, tv.r.xyz + 3 * nn);
    tri.resize(nb * 3);
    tri_face.resize(nb);
    for (size_t t = 0; t < nb; ++t) {
        for (int k = 0; k < 3; ++k) tri[3 * t + k] = tv.r.triface[3 * t + k];
        tri_face[t] = tv.r.trimarker[t] - 1;
        if (tri_face[t] < 0 || tri_face[t] >= counts.faces)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: boundary triangle %zu without a CAD face", fn, t);
    }
    const double t2 = cm_wtime();
    cm_log(ctx, CM_LOG_DEBUG, "tetmesh: TetGen -%s: %zu nodes, %zu tets (%.3f s)", sw, nn, nt, t2 - t1);
    // TetGen keeps the input points first and in order; the others are its Steiner points
    size_t n_projected = 0;
    if (!preserved &&
        (s = project_new_nodes(ctx, model, T, T.n_nodes, xyz, tri, tri_face, &n_projected)) < 0)
        return s;
    cm_log(ctx, CM_LOG_DEBUG, "tetmesh: %zu new boundary nodes projected onto curved faces and edges (%.3f s)",
           n_projected, cm_wtime() - t2);

    r->tets.resize(nt);
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 4; ++k) r->tets[t][k] = tv.r.tet[4 * t + k];
    return CM_OK;
}

// A new mesh optimised, and its quality judgement: CM_ERR_REJECTED naming the worst tet when
// it stays below the floor. On success *out takes the mesh.
cm_status judge(cm_context *ctx, const plan &pl, const cm_tetmesh_options &o, int mesher,
                mesh_guard &m, cm_mesh **out)
{
    cm_status s = CM_OK;
    /* the meshers' radius-edge bounds leave slivers: move the interior nodes to lift them;
     * an assembly's interfaces are inside the mesh, on CAD faces: held too */
    if (o.optimize) {
        const std::vector<unsigned char> fixed = cmvol::assembly_fixed_nodes(m.m);
        s = cm_mesh_optimize(ctx, m.m, fixed.empty() ? nullptr : fixed.data(), nullptr, nullptr);
        if (s < 0) return s;
    }
    if (o.min_sj >= -1) {
        std::vector<double> sj(m.m->n_cells);
        if ((s = cm_mesh_quality(ctx, m.m, sj.data())) < 0) return s;
        size_t worst = SIZE_MAX, flat = 0, below = 0;
        for (size_t c = 0; c < m.m->n_cells; ++c) {
            if (m.m->type[c] != CM_CELL_TET4) continue;
            if (worst == SIZE_MAX || !(sj[c] >= sj[worst])) worst = c;
            below += !(sj[c] > o.min_sj);
            flat += o.min_sj >= 0 && !(sj[c] >= CM_TETMESH_FLAT_SJ);
        }
        if (worst != SIZE_MAX && (below || flat)) {
            const int64_t *nodes = &m.m->conn[m.m->offset[worst]];
            double c[3] = {0, 0, 0};
            for (int k = 0; k < 4; ++k)
                for (int d = 0; d < 3; ++d) c[d] += 0.25 * m.m->xyz[3 * nodes[k] + d];
            return cm_error(ctx, CM_ERR_REJECTED,
                            "%s: %s's mesh has %zu tet%s at or below the scaled-Jacobian floor %g%s "
                            "after the optimisation; the worst, tet %zu at (%.6g, %.6g, %.6g), "
                            "has %.3g",
                            pl.path, mesher_name(mesher), std::max(below, flat), std::max(below, flat) == 1 ? "" : "s", o.min_sj,
                            o.min_sj >= 0 ? " or flat" : "", worst, c[0], c[1], c[2], sj[worst]);
        }
    }
    *out = m.m;
    m.m = nullptr;
    return CM_OK;
}

// The mesh of one mesher's result, optimised and judged.
cm_status finish(cm_context *ctx, const plan &pl, const cm_tetmesh_options &o, int mesher,
                 cmvol::raw_mesh &r, cm_mesh **out)
{
    mesh_guard m;
    cm_status s = assemble(ctx, pl.counts.faces, r.xyz, r.tets, r.tri, r.tri_face, &m.m);
    return s < 0 ? s : judge(ctx, pl, o, mesher, m, out);
}

// The message of the last error without the model's path in front (it opens the final one).
std::string reason(cm_context *ctx, const char *path)
{
    std::string why = cm_context_message(ctx);
    const std::string prefix = std::string(path) + ": ";
    if (why.compare(0, prefix.size(), prefix) == 0) why.erase(0, prefix.size());
    return why;
}

cm_status run_one(cm_context *ctx, const cm_cad_model *model, const cm_tetmesh_options &o,
                  const plan &pl, int mesher, double limit, cm_mesh **out)
{
    const char *stage = mesher == CM_MESHER_GMSH ? "gmsh" : "tetgen";
    cm_status s = cm_progress(ctx, stage, 0, 1);
    if (s < 0) return s;
    cmvol::raw_mesh r;
    s = mesher == CM_MESHER_GMSH ? run_gmsh(ctx, model, pl, limit, &r)
                                 : run_tetgen(ctx, model, o, pl, limit, &r);
    if (s >= 0) s = finish(ctx, pl, o, mesher, r, out);
    // the nodes TetGen adds on curved faces, projected onto them, can flatten the tets under
    // them beyond what moving interior nodes lifts; the surface kept as triangulated (-Y)
    // has no such nodes (OpenCASCADE data/occ/bottle: 162 flat tets refined, none kept)
    if (s == CM_ERR_REJECTED && mesher == CM_MESHER_TETGEN && !o.preserve_surface) {
        const std::string why = reason(ctx, pl.path);
        cm_tetmesh_options kept = o;
        kept.preserve_surface = 1;
        cmvol::raw_mesh ry;
        s = run_tetgen(ctx, model, kept, pl, limit, &ry);
        if (s >= 0) s = finish(ctx, pl, kept, mesher, ry, out);
        if (s >= 0)
            cm_log(ctx, CM_LOG_WARNING, "%s: %s; meshed with the surface kept (TetGen -Y)",
                   pl.path, why.c_str());
        else if (s != CM_ERR_INTERRUPTED)
            s = cm_error(ctx, s, "%s: %s; with the surface kept (-Y): %s", pl.path, why.c_str(),
                         reason(ctx, pl.path).c_str());
    }
    if (s >= 0 && (s = cm_progress(ctx, stage, 1, 1)) < 0) cm_mesh_destroy(out);
    return s;
}

// The driver: the mesher asked for, then (o.fallback) the other one, each judged the same way.
cm_status build(cm_context *ctx, const cm_cad_model *model, const cm_tetmesh_options &o,
                cm_mesh **out)
{
    plan pl;
    cm_status s = prepare(ctx, model, o, &pl);
    if (s < 0) return s;
    const double limit = o.time_limit > 0 ? o.time_limit : CM_TETMESH_TIME_LIMIT;
    if (pl.touching[0] >= 0) {
        // solids that touch: only gmsh meshes them (docs/DESIGN.md, Assemblies), so the
        // fallback goes there at once; an explicit TetGen is refused by assembly_mesh
        const int mesher = o.fallback ? CM_MESHER_GMSH : o.mesher;
        mesh_guard m;
        if ((s = check_gmsh_volume(ctx, pl)) < 0 ||
            (s = cmvol::assembly_mesh(ctx, model, mesher, pl.h, limit, pl.touching, &m.m)) < 0)
            return s;
        return judge(ctx, pl, o, mesher, m, out);
    }
    const int first = o.mesher, second = first == CM_MESHER_GMSH ? CM_MESHER_TETGEN : CM_MESHER_GMSH;
    const double t0 = cm_wtime();
    // half each: a mesher that hangs (gmsh on a 313-face plate: more than 600 s) leaves the
    // other time enough (TetGen -Y: seconds; benchmarks/RESULTS.md, Meshers)
    const double first_limit = o.fallback ? CM_TETMESH_FIRST_SHARE * limit : limit;
    s = run_one(ctx, model, o, pl, first, first_limit, out);
    // a size beyond the tet limit is the size's fault, not the mesher's: the other mesher
    // would refuse it too
    if (s >= 0 || s == CM_ERR_INTERRUPTED || s == CM_ERR_NOMEM) return s;
    const std::string why1 = reason(ctx, pl.path);
    if (!o.fallback)
        return cm_error(ctx, s, "%s: %s (the other mesher: --mesher %s)", pl.path, why1.c_str(),
                        first == CM_MESHER_GMSH ? "tetgen" : "gmsh");
    const cm_status s1 = s;
    const double left = std::isfinite(limit) ? std::max(limit - (cm_wtime() - t0), 0.05 * limit)
                                             : limit;
    s = run_one(ctx, model, o, pl, second, left, out);
    if (s >= 0) {
        cm_log(ctx, CM_LOG_WARNING, "%s: %s could not mesh it (%s); meshed with %s", pl.path,
               mesher_name(first), why1.c_str(), mesher_name(second));
        return s;
    }
    if (s == CM_ERR_INTERRUPTED) return s;
    const std::string why2 = reason(ctx, pl.path);
    // the status of the mesher asked for, unless the other one's says more (memory, quality)
    const cm_status worst = s1 == CM_ERR_REJECTED || s == CM_ERR_REJECTED ? CM_ERR_REJECTED : s1;
    return cm_error(ctx, worst, "%s: no mesh: %s: %s; %s: %s (try another --size, a longer "
                    "--time-limit, or repair the model)", pl.path, mesher_name(first),
                    why1.c_str(), mesher_name(second), why2.c_str());
}

}  // namespace

extern "C" void cm_tetmesh_options_init(cm_tetmesh_options *opt)
{
    if (!opt) return;
    opt->size = 0;
    opt->quality = 1.4;
    opt->preserve_surface = 0;
    opt->optimize = 1;
    opt->min_dihedral = 12;
    opt->max_tets = 0;
    opt->time_limit = 0;
    opt->mesher = CM_MESHER_TETGEN;
    opt->fallback = 1;
    opt->min_sj = 0;
}

extern "C" cm_status cm_tetmesh_create(cm_context *ctx, const cm_cad_model *model,
                                       const cm_tetmesh_options *opt, cm_mesh **mesh)
{
    const char *fn = "cm_tetmesh_create";
    if (mesh) *mesh = nullptr;
    if (!model || !mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL model or output", fn);
    cm_tetmesh_options o;
    cm_tetmesh_options_init(&o);
    if (opt) o = *opt;
    try {
        return build(ctx, model, o, mesh);
    } catch (const std::bad_alloc &) {
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", fn);
    } catch (const std::exception &e) {
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: %s", fn, e.what());
    } catch (...) {
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: unknown exception", fn);
    }
}
