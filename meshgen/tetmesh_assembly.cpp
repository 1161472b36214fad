// Assemblies (tetmesh_assembly.h): solids that touch meshed as one conformal mesh. gmsh runs
// in a forked child as in tetmesh_gmsh.cpp, with one step more: its OpenCASCADE kernel
// fragments the imported solids (BooleanFragments), so that a face two solids share, or the
// part of a face they share, becomes one surface meshed once, and the tets on both sides use
// its nodes. The parent maps each gmsh volume to our solid (a point of one of its tets
// classified by OpenCASCADE) and each gmsh surface to the CAD faces it lies on, one per solid
// next to it: two for an interface, whose triangles are then written once for each.
#include "tetmesh_assembly.h"

#include "cadmorph/tetmesh.h"
#include "child_process.h"
#include "gmsh_child.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <string>

using cmvol::orient;

namespace {

const uint64_t record_magic = 0x636d61736d626c79ULL;  // "cmasmbly"

struct header {
    uint64_t magic;
    int64_t failed;  // 1: gmsh reported an error (or the fragments were not one per solid)
    int64_t n_nodes, n_tets, n_tris, n_solids;
    double bbox[6];
    char msg[400];
};

struct job {
    const char *path;
    const char *unit;
    double h;
};

int send_failure(int fd, const char *msg) { return cmvol::send_failure<header>(fd, record_magic, msg); }

int send_error(const cmvol::gmsh_api &G, int fd, const char *what)
{
    return cmvol::send_error<header>(G, fd, record_magic, what);
}

int child_work(void *arg, int fd)
{
    const job &j = *static_cast<const job *>(arg);
    cmvol::gmsh_api G;
    char msg0[sizeof(header::msg)];
    if (cmvol::gmsh_start(&G, j.unit, msg0, sizeof msg0)) return send_failure(fd, msg0);
    int ierr = 0;
    int *dt = nullptr;
    size_t ndt = 0;
    G.gmshModelOccImportShapes(j.path, &dt, &ndt, 1, "", &ierr);
    if (ierr) return send_error(G, fd, "cannot import the STEP file");
    std::vector<int> vols;  // (3, tag) pairs in import order: TopExp's order of the solids
    for (size_t i = 0; i + 1 < ndt; i += 2)
        if (dt[i] == 3) vols.insert(vols.end(), {3, dt[i + 1]});
    if (vols.size() < 4) return send_failure(fd, "fewer than two volumes imported");
    int *out = nullptr, **map = nullptr;
    size_t nout = 0, *nmap = nullptr, nnmap = 0;
    G.gmshModelOccFragment(vols.data(), vols.size(), nullptr, 0, &out, &nout, &map, &nmap, &nnmap,
                           -1, 1, 1, &ierr);
    if (ierr) return send_error(G, fd, "cannot fragment the solids");
    // each solid must come out as one volume of its own: more pieces or a piece in two
    // solids is an overlap the CAD check missed
    const size_t ns = vols.size() / 2;
    std::map<int, int> solid_of;  // gmsh volume tag after the fragment -> import index
    if (nnmap != ns) return send_failure(fd, "the fragments do not match the solids");
    for (size_t i = 0; i < ns; ++i) {
        int pieces = 0, tag = -1;
        for (size_t k = 0; k + 1 < nmap[i]; k += 2)
            if (map[i][k] == 3) ++pieces, tag = map[i][k + 1];
        if (pieces != 1 || solid_of.count(tag)) {
            char msg[200];
            std::snprintf(msg, sizeof msg, "solid %zu overlaps another: the fragments give it %d "
                          "volumes", i, pieces);
            return send_failure(fd, msg);
        }
        solid_of[tag] = (int)i;
    }
    G.gmshModelOccSynchronize(&ierr);
    if (ierr) return send_error(G, fd, "cannot synchronise the model");
    header hd = {};
    hd.magic = record_magic;
    hd.n_solids = (int64_t)ns;
    G.gmshModelGetBoundingBox(-1, -1, &hd.bbox[0], &hd.bbox[1], &hd.bbox[2], &hd.bbox[3],
                              &hd.bbox[4], &hd.bbox[5], &ierr);
    G.gmshOptionSetNumber("Mesh.MeshSizeMax", j.h, &ierr);
    // a floor far below any feature: gmsh 4.8's curvature sizing gives 0 on some degenerate
    // curves of real assemblies and then throws past its C API ("Wrong mesh element size
    // lc = 0"), which aborts the child
    G.gmshOptionSetNumber("Mesh.MeshSizeMin", 1e-3 * j.h, &ierr);
    G.gmshOptionSetNumber("Mesh.MeshSizeFromCurvature", 12, &ierr);
    G.gmshModelMeshGenerate(3, &ierr);
    if (ierr) return send_error(G, fd, "meshing failed");

    size_t *tags = nullptr, ntags = 0, ncoord = 0, npar = 0;
    double *coord = nullptr, *par = nullptr;
    G.gmshModelMeshGetNodes(&tags, &ntags, &coord, &ncoord, &par, &npar, -1, -1, 0, 0, &ierr);
    if (ierr || ncoord != 3 * ntags) return send_error(G, fd, "cannot read the nodes");
    size_t max_tag = 0;
    for (size_t i = 0; i < ntags; ++i) max_tag = std::max(max_tag, tags[i]);
    std::vector<int64_t> index(max_tag + 1, -1);
    for (size_t i = 0; i < ntags; ++i) index[tags[i]] = (int64_t)i;
    auto node = [&](size_t t) { return t <= max_tag ? index[t] : -1; };

    std::vector<int64_t> tets, tri;
    std::vector<int32_t> tet_solid, tri_tag;
    size_t *etags = nullptr, netags = 0, *enodes = nullptr, nenodes = 0;
    for (const auto &vs : solid_of) {
        G.gmshModelMeshGetElementsByType(4, &etags, &netags, &enodes, &nenodes, vs.first, 0, 1, &ierr);
        if (ierr || nenodes != 4 * netags) return send_error(G, fd, "cannot read the tets");
        for (size_t i = 0; i < nenodes; ++i) tets.push_back(node(enodes[i]));
        tet_solid.insert(tet_solid.end(), netags, vs.second);
        G.gmshFree(etags);
        G.gmshFree(enodes);
    }
    if (tets.empty()) return send_failure(fd, "no tets");
    int *surf = nullptr;
    size_t nsurf = 0;
    G.gmshModelGetEntities(&surf, &nsurf, 2, &ierr);
    for (size_t s = 0; s + 1 < nsurf; s += 2) {
        const int tag = surf[s + 1];
        G.gmshModelMeshGetElementsByType(2, &etags, &netags, &enodes, &nenodes, tag, 0, 1, &ierr);
        if (ierr || nenodes != 3 * netags) return send_error(G, fd, "cannot read the triangles");
        for (size_t i = 0; i < nenodes; ++i) tri.push_back(node(enodes[i]));
        tri_tag.insert(tri_tag.end(), netags, tag);
        G.gmshFree(etags);
        G.gmshFree(enodes);
    }
    hd.n_nodes = (int64_t)ntags;
    hd.n_tets = (int64_t)tet_solid.size();
    hd.n_tris = (int64_t)tri_tag.size();
    if (cm_child_write(fd, &hd, sizeof hd) || cm_child_write(fd, coord, 8 * ncoord) ||
        cm_child_write(fd, tets.data(), 8 * tets.size()) ||
        cm_child_write(fd, tet_solid.data(), 4 * tet_solid.size()) ||
        cm_child_write(fd, tri.data(), 8 * tri.size()) ||
        cm_child_write(fd, tri_tag.data(), 4 * tri_tag.size()))
        return 3;
    return 0;  // no gmshFinalize, no frees: the process ends here
}

struct mesh_guard {
    cm_mesh *m = nullptr;
    ~mesh_guard() { cm_mesh_destroy(&m); }
};

// What the child sent, nodes renumbered to those of tets.
struct raw {
    std::vector<double> xyz;
    std::vector<std::array<int64_t, 4>> tets;
    std::vector<int> tet_solid;  // gmsh's import index, then ours
    std::vector<int64_t> tri;
    std::vector<int> tri_tag;
    double bbox[6];
    size_t n_solids;
    double seconds;
};

cm_status run_child(cm_context *ctx, const cm_cad_model *model, double h, double time_limit, raw *r)
{
    const char *path = cm_cad_path(model);
    job j = {path, cm_cad_unit(model), h};
    char *data = nullptr;
    size_t size = 0;
    cm_child_outcome o;
    cm_status s = cm_child_run(ctx, "gmsh", "gmsh", child_work, &j, time_limit, &data, &size, &o);
    if (s < 0) return s;
    struct freer {
        char *p;
        ~freer() { std::free(p); }
    } f{data};
    if (o.timed_out || o.signal || o.exit_code != 0) {
        char how[700];
        cm_child_describe(&o, how, sizeof how);
        return cm_error(ctx, o.timed_out ? CM_ERR_UNSUPPORTED : CM_ERR_NUMERIC,
                        "%s: gmsh (assembly) %s%s", path, how,
                        o.timed_out ? " (raise the time limit, --time-limit)" : "");
    }
    header hd;
    if (size < sizeof hd || (std::memcpy(&hd, data, sizeof hd), hd.magic != record_magic))
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: gmsh's child sent no record (%zu bytes)", path, size);
    if (hd.failed) {
        hd.msg[sizeof hd.msg - 1] = '\0';
        return cm_error(ctx, CM_ERR_NUMERIC, "%s: gmsh (assembly): %s", path, hd.msg);
    }
    const size_t nn = (size_t)hd.n_nodes, nt = (size_t)hd.n_tets, nb = (size_t)hd.n_tris;
    const size_t need = sizeof hd + 8 * (3 * nn + 4 * nt + 3 * nb) + 4 * (nt + nb);
    if (hd.n_nodes < 0 || hd.n_tets < 0 || hd.n_tris < 0 || size != need)
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: gmsh's child sent %zu bytes, %zu expected",
                        path, size, need);
    const char *c = data + sizeof hd;
    std::vector<double> xyz((const double *)c, (const double *)c + 3 * nn);
    c += 8 * 3 * nn;
    std::vector<int64_t> tets((const int64_t *)c, (const int64_t *)c + 4 * nt);
    c += 8 * 4 * nt;
    r->tet_solid.assign((const int32_t *)c, (const int32_t *)c + nt);
    c += 4 * nt;
    r->tri.assign((const int64_t *)c, (const int64_t *)c + 3 * nb);
    c += 8 * 3 * nb;
    r->tri_tag.assign((const int32_t *)c, (const int32_t *)c + nb);
    std::copy(hd.bbox, hd.bbox + 6, r->bbox);
    r->n_solids = (size_t)hd.n_solids;
    r->seconds = o.seconds;
    for (int64_t v : tets)
        if (v < 0 || (size_t)v >= nn)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: a gmsh tet has a node that is not in the mesh", path);
    for (int64_t v : r->tri)
        if (v < 0 || (size_t)v >= nn)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: a gmsh triangle has a node that is not in the mesh", path);
    std::vector<int64_t> renum(nn, -1);
    size_t kept = 0;
    for (int64_t v : tets)
        if (renum[v] < 0) renum[v] = (int64_t)kept++;
    for (int64_t &v : r->tri) {
        if (renum[v] < 0)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: a gmsh boundary triangle is on no tet", path);
        v = renum[v];
    }
    r->xyz.assign(3 * kept, 0);
    for (size_t i = 0; i < nn; ++i)
        if (renum[i] >= 0) std::copy(&xyz[3 * i], &xyz[3 * i] + 3, &r->xyz[3 * renum[i]]);
    r->tets.resize(nt);
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 4; ++k) r->tets[t][k] = renum[tets[4 * t + k]];
    return CM_OK;
}

// gmsh's import index -> our solid: the solid that holds the centroid of the volume's
// largest tet (strictly inside its solid, away from the faces)
cm_status map_solids(cm_context *ctx, const cm_cad_model *model, raw &r)
{
    const char *path = cm_cad_path(model);
    std::vector<double> best(r.n_solids, -1);
    std::vector<size_t> at(r.n_solids, 0);
    for (size_t t = 0; t < r.tets.size(); ++t) {
        const auto &c = r.tets[t];
        const double v = std::fabs(orient(&r.xyz[3 * c[0]], &r.xyz[3 * c[1]], &r.xyz[3 * c[2]],
                                          &r.xyz[3 * c[3]]));
        const int s = r.tet_solid[t];
        if (s < 0 || (size_t)s >= r.n_solids)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: a gmsh tet of no solid", path);
        if (v > best[s]) best[s] = v, at[s] = t;
    }
    std::vector<int> ours(r.n_solids, -1);
    std::set<int> used;
    for (size_t s = 0; s < r.n_solids; ++s) {
        if (best[s] < 0)
            return cm_error(ctx, CM_ERR_NUMERIC, "%s: gmsh made no tet in solid %zu", path, s);
        double p[3] = {0, 0, 0};
        for (int k = 0; k < 4; ++k)
            for (int d = 0; d < 3; ++d) p[d] += 0.25 * r.xyz[3 * r.tets[at[s]][k] + d];
        cm_status st = cm_cad_solid_at(ctx, model, p, &ours[s]);
        if (st < 0) return st;
        if (ours[s] < 0 || !used.insert(ours[s]).second)
            return cm_error(ctx, CM_ERR_MISMATCH,
                            "%s: gmsh's volume %zu is in %s of cadmorph's solids: gmsh's "
                            "geometry is not cadmorph's", path, s, ours[s] < 0 ? "none" : "two");
    }
    for (int &s : r.tet_solid) s = ours[s];
    return CM_OK;
}

// Each gmsh surface -> the CAD faces it lies on, one per solid next to it (surface_solids):
// all of up to 24 of its nodes within tol of the face.
cm_status map_faces(cm_context *ctx, const cm_cad_model *model, const raw &r,
                    const std::map<int, std::set<int>> &surface_solids,
                    std::map<int, std::vector<int>> *faces_of)
{
    const char *path = cm_cad_path(model);
    cm_cad_counts counts;
    cm_cad_get_counts(model, &counts);
    double bb[6];
    cm_cad_bbox(model, bb);
    // gmsh's surface and OpenCASCADE's face: the same geometry read twice, the nodes on it
    // up to the meshers' projection (the single-solid path's bound, loosened tenfold for the
    // faces the fragment rebuilt)
    const double tol = 1e-6 * cm_bbox_diagonal(bb);
    std::vector<cm_cad_face_info> info(counts.faces);
    std::vector<int> solid(counts.faces);
    for (int f = 0; f < counts.faces; ++f) {
        cm_status s = cm_cad_face_get_info(ctx, model, f, &info[f]);
        if (s >= 0) s = cm_cad_face_solid(ctx, model, f, &solid[f]);
        if (s < 0) return s;
    }
    std::map<int, std::vector<int64_t>> nodes_of;
    for (size_t t = 0; t < r.tri_tag.size(); ++t)
        for (int k = 0; k < 3; ++k) nodes_of[r.tri_tag[t]].push_back(r.tri[3 * t + k]);
    for (auto &sn : nodes_of) {
        std::vector<int64_t> &v = sn.second;
        std::sort(v.begin(), v.end());
        v.erase(std::unique(v.begin(), v.end()), v.end());
        std::vector<double> p;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        const size_t step = std::max<size_t>(1, v.size() / 24);
        for (size_t i = 0; i < v.size(); i += step)
            for (int d = 0; d < 3; ++d) {
                const double x = r.xyz[3 * v[i] + d];
                p.push_back(x);
                lo[d] = std::min(lo[d], x), hi[d] = std::max(hi[d], x);
            }
        const size_t np = p.size() / 3;
        std::vector<double> dist(np);
        const std::set<int> &next_to = surface_solids.at(sn.first);
        std::map<int, std::pair<double, int>> closest;  // solid -> (distance, face)
        double best = INFINITY;
        for (int f = 0; f < counts.faces; ++f) {
            if (!next_to.count(solid[f]) && solid[f] >= 0) continue;
            bool inside = true;
            for (int d = 0; d < 3; ++d)
                inside = inside && lo[d] >= info[f].bbox[d] - tol && hi[d] <= info[f].bbox[d + 3] + tol;
            if (!inside) continue;
            cm_status s = cm_cad_project_face(ctx, model, f, p.data(), np, nullptr, nullptr,
                                              dist.data(), nullptr);
            if (s < 0) return s;
            const double worst = *std::max_element(dist.begin(), dist.end());
            best = std::min(best, worst);
            if (worst > tol) continue;
            auto it = closest.find(solid[f]);
            if (it == closest.end() || worst < it->second.first) closest[solid[f]] = {worst, f};
        }
        if (closest.empty())
            return cm_error(ctx, CM_ERR_MISMATCH,
                            "%s: gmsh's surface %d lies on no CAD face (closest: %.3g away, "
                            "tolerance %.3g): gmsh's geometry is not cadmorph's",
                            path, sn.first, best, tol);
        std::vector<int> &faces = (*faces_of)[sn.first];
        for (const auto &c : closest) faces.push_back(c.second.second);
    }
    return CM_OK;
}

cm_status build_mesh(cm_context *ctx, const cm_cad_model *model, raw &r, cm_mesh **out)
{
    const char *path = cm_cad_path(model);
    cm_cad_counts counts;
    cm_cad_get_counts(model, &counts);
    const size_t nt = r.tets.size(), nb = r.tri_tag.size();
    for (auto &c : r.tets)
        if (orient(&r.xyz[3 * c[0]], &r.xyz[3 * c[1]], &r.xyz[3 * c[2]], &r.xyz[3 * c[3]]) < 0)
            std::swap(c[2], c[3]);
    // the tets on each triangle (one on the boundary, two on an interface): sorted faces
    std::vector<std::array<int64_t, 4>> keys;  // sorted face, then tet (>= 0) or -1 - triangle
    keys.reserve(4 * nt + nb);
    for (size_t t = 0; t < nb; ++t) {
        std::array<int64_t, 4> k = {r.tri[3 * t], r.tri[3 * t + 1], r.tri[3 * t + 2], -1 - (int64_t)t};
        std::sort(k.begin(), k.begin() + 3);
        keys.push_back(k);
    }
    for (size_t c = 0; c < nt; ++c)
        for (int f = 0; f < 4; ++f) {
            std::array<int64_t, 4> k = {r.tets[c][(f + 1) % 4], r.tets[c][(f + 2) % 4],
                                        r.tets[c][(f + 3) % 4], (int64_t)c};
            std::sort(k.begin(), k.begin() + 3);
            keys.push_back(k);
        }
    std::sort(keys.begin(), keys.end());
    std::vector<std::array<int64_t, 2>> tri_tets(nb, {-1, -1});
    for (size_t i = 0; i < keys.size();) {
        size_t j = i;
        std::vector<int64_t> tris, tets;
        for (; j < keys.size() && std::equal(keys[i].begin(), keys[i].begin() + 3, keys[j].begin()); ++j)
            (keys[j][3] < 0 ? tris : tets).push_back(keys[j][3] < 0 ? -1 - keys[j][3] : keys[j][3]);
        for (int64_t t : tris)
            for (size_t k = 0; k < tets.size() && k < 2; ++k) tri_tets[t][k] = tets[k];
        i = j;
    }
    std::map<int, std::set<int>> surface_solids;
    for (size_t t = 0; t < nb; ++t) {
        if (tri_tets[t][0] < 0)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: boundary triangle %zu is on no tet", path, t);
        for (int64_t c : tri_tets[t])
            if (c >= 0) surface_solids[r.tri_tag[t]].insert(r.tet_solid[c]);
    }
    std::map<int, std::vector<int>> faces_of;
    cm_status s = map_faces(ctx, model, r, surface_solids, &faces_of);
    if (s < 0) return s;

    mesh_guard m;
    const size_t nn = r.xyz.size() / 3;
    if ((s = cm_mesh_create(ctx, &m.m)) < 0) return s;
    if ((s = cm_mesh_resize_nodes(ctx, m.m, nn, 0)) < 0) return s;
    std::copy(r.xyz.begin(), r.xyz.end(), m.m->xyz);
    if ((s = cm_mesh_reserve_cells(ctx, m.m, nt + 2 * nb, 4 * nt + 6 * nb)) < 0) return s;
    std::vector<char> solid_used(counts.solids, 0), face_used(counts.faces, 0);
    for (size_t c = 0; c < nt; ++c) {
        const int k = r.tet_solid[c];
        solid_used[k] = 1;
        if ((s = cm_mesh_add_cell(ctx, m.m, CM_CELL_TET4, r.tets[c].data(), 4, k + 1, k + 1, 0)) < 0)
            return s;
    }
    for (size_t t = 0; t < nb; ++t)
        for (int f : faces_of[r.tri_tag[t]]) {
            int fs = -1;
            if ((s = cm_cad_face_solid(ctx, model, f, &fs)) < 0) return s;
            // outward from the face's own solid: its tet on this triangle (the first for a
            // face of no solid or one shared by both)
            int64_t tet = tri_tets[t][0];
            if (tri_tets[t][1] >= 0 && r.tet_solid[tri_tets[t][1]] == fs) tet = tri_tets[t][1];
            int64_t v[3] = {r.tri[3 * t], r.tri[3 * t + 1], r.tri[3 * t + 2]};
            int64_t apex = -1;
            for (int k = 0; k < 4; ++k)
                if (r.tets[tet][k] != v[0] && r.tets[tet][k] != v[1] && r.tets[tet][k] != v[2])
                    apex = r.tets[tet][k];
            if (orient(&r.xyz[3 * v[0]], &r.xyz[3 * v[1]], &r.xyz[3 * v[2]], &r.xyz[3 * apex]) > 0)
                std::swap(v[1], v[2]);
            face_used[f] = 1;
            if ((s = cm_mesh_add_cell(ctx, m.m, CM_CELL_TRI3, v, 3, f + 1, f + 1, 0)) < 0) return s;
        }
    for (int k = 0; k < counts.solids; ++k) {
        if (!solid_used[k]) continue;
        const std::string name = "solid_" + std::to_string(k);
        if ((s = cm_mesh_add_group(ctx, m.m, 3, k + 1, name.c_str())) < 0) return s;
    }
    for (int f = 0; f < counts.faces; ++f) {
        if (!face_used[f]) continue;
        const std::string name = "face_" + std::to_string(f);
        if ((s = cm_mesh_add_group(ctx, m.m, 2, f + 1, name.c_str())) < 0) return s;
    }
    size_t interface = 0;
    for (const auto &sf : faces_of) interface += sf.second.size() > 1;
    cm_log(ctx, CM_LOG_DEBUG, "tetmesh: gmsh assembly: %zu solids, %zu nodes, %zu tets, %zu "
           "surfaces (%zu interfaces) (%.3f s)", r.n_solids, nn, nt, faces_of.size(), interface,
           r.seconds);
    *out = m.m;
    m.m = nullptr;
    return CM_OK;
}

}  // namespace

cm_status cmvol::assembly_mesh(cm_context *ctx, const cm_cad_model *model, int mesher, double h,
                               double time_limit, const int touching[2], cm_mesh **out)
{
    const char *path = cm_cad_path(model);
    cm_cad_counts counts;
    cm_cad_get_counts(model, &counts);
    if (mesher != CM_MESHER_GMSH)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "%s: solids %d and %d (of %d) touch (share a face): TetGen cannot mesh "
                        "an assembly; mesh it with --mesher gmsh (one conformal mesh, a group per "
                        "solid)", path, touching[0], touching[1], counts.solids);
    cm_status s = cm_progress(ctx, "gmsh", 0, 1);
    if (s < 0) return s;
    raw r;
    if ((s = run_child(ctx, model, h, time_limit, &r)) < 0) return s;
    if (r.n_solids != (size_t)counts.solids)
        return cm_error(ctx, CM_ERR_MISMATCH, "%s: gmsh read %zu solids, cadmorph %d: gmsh's "
                        "geometry is not cadmorph's", path, r.n_solids, counts.solids);
    double bb[6];
    cm_cad_bbox(model, bb);
    const double diag = cm_bbox_diagonal(bb), gdiag = cm_bbox_diagonal(r.bbox);
    bool holds = gdiag >= 0.5 * diag && gdiag <= 2 * diag;
    for (int k = 0; k < 3; ++k)
        holds = holds && r.bbox[k] <= bb[k] + 1e-4 * diag && r.bbox[k + 3] >= bb[k + 3] - 1e-4 * diag;
    if (!holds)
        return cm_error(ctx, CM_ERR_MISMATCH,
                        "%s: gmsh read another geometry: its bounding box [%g %g %g, %g %g %g] "
                        "does not fit cadmorph's [%g %g %g, %g %g %g]",
                        path, r.bbox[0], r.bbox[1], r.bbox[2], r.bbox[3], r.bbox[4], r.bbox[5],
                        bb[0], bb[1], bb[2], bb[3], bb[4], bb[5]);
    if ((s = map_solids(ctx, model, r)) < 0) return s;
    if ((s = build_mesh(ctx, model, r, out)) < 0) return s;
    s = cm_progress(ctx, "gmsh", 1, 1);
    if (s < 0) cm_mesh_destroy(out);
    return s;
}

std::vector<unsigned char> cmvol::assembly_fixed_nodes(const cm_mesh *mesh)
{
    std::vector<unsigned char> fixed;
    std::set<int> solids;
    for (size_t c = 0; c < mesh->n_cells && solids.size() < 2; ++c)
        if (mesh->type[c] == CM_CELL_TET4) solids.insert(mesh->physical[c]);
    if (solids.size() < 2) return fixed;
    fixed.assign(mesh->n_nodes, 0);
    // the nodes of the surface triangles: every boundary node (each boundary face carries
    // one) and the interfaces' nodes, which must stay on their CAD faces
    for (size_t c = 0; c < mesh->n_cells; ++c)
        if (mesh->type[c] == CM_CELL_TRI3)
            for (int64_t k = mesh->offset[c]; k < mesh->offset[c + 1]; ++k) fixed[mesh->conn[k]] = 1;
    return fixed;
}
