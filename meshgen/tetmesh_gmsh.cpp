// gmsh as the second mesher: its C API (gmshc.h) in a forked child (child_process.h), since
// gmsh can crash or run long too. The child reads the STEP file with gmsh's OpenCASCADE
// kernel (the same OpenCASCADE 7.6 as cad/), meshes in 3D on one thread (no OpenMP pool after
// a fork) and sends nodes, tets and the boundary triangles with their gmsh surface tags. The
// parent maps each gmsh surface to the CAD face all its nodes lie on, so that the boundary
// triangles carry our face indices as the TetGen path's do, within the model's own tolerances
// (cm_cad_face_tolerances).
#include "tetmesh_gmsh.h"

#include "child_process.h"
#include "gmsh_child.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>
#include <map>
#include <string>

namespace {

const uint64_t record_magic = 0x636d676d73686d73ULL;  // "cmgmshms"

struct header {
    uint64_t magic;
    int64_t failed;  // 1: gmsh reported an error, message in msg; 2: the estimate is too large
    int64_t n_nodes, n_tets, n_tris;
    double bbox[6];
    double estimate;      // tets expected from gmsh's surface mesh (surface_layers)
    int64_t n_surface;    // its triangles
    char msg[400];
};

struct job {
    const char *path;
    const char *unit;  // cm_cad_unit's name of the model's unit
    double h;
    double volume, max_tets;  // the model's volume (ours), the bound on the estimate
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
    char msg[sizeof(header::msg)];
    if (cmvol::gmsh_start(&G, j.unit, msg, sizeof msg)) return send_failure(fd, msg);
    int ierr = 0;
    int *dt = nullptr;
    size_t ndt = 0;
    G.gmshModelOccImportShapes(j.path, &dt, &ndt, 0, "", &ierr);
    if (dt) G.gmshFree(dt);
    if (ierr) return send_error(G, fd, "cannot import the STEP file");
    G.gmshModelOccSynchronize(&ierr);
    if (ierr) return send_error(G, fd, "cannot synchronise the model");
    header hd = {};
    hd.magic = record_magic;
    G.gmshModelGetBoundingBox(-1, -1, &hd.bbox[0], &hd.bbox[1], &hd.bbox[2], &hd.bbox[3],
                            &hd.bbox[4], &hd.bbox[5], &ierr);
    G.gmshOptionSetNumber("Mesh.MeshSizeMax", j.h, &ierr);
    G.gmshOptionSetNumber("Mesh.MeshSizeMin", 0, &ierr);
    G.gmshOptionSetNumber("Mesh.MeshSizeFromCurvature", 12, &ierr);
    // the surface mesh first: the tets expected from it, refused before the volume mesh
    G.gmshModelMeshGenerate(2, &ierr);
    if (ierr) return send_error(G, fd, "meshing the surfaces failed");
    {
        size_t *tags = nullptr, ntags = 0, ncoord = 0, npar = 0;
        double *coord = nullptr, *par = nullptr;
        G.gmshModelMeshGetNodes(&tags, &ntags, &coord, &ncoord, &par, &npar, -1, -1, 1, 0, &ierr);
        if (ierr || ncoord != 3 * ntags) return send_error(G, fd, "cannot read the surface nodes");
        size_t max_tag = 0;
        for (size_t i = 0; i < ntags; ++i) max_tag = std::max(max_tag, tags[i]);
        std::vector<int64_t> index(max_tag + 1, -1);
        for (size_t i = 0; i < ntags; ++i) index[tags[i]] = (int64_t)i;
        size_t *etags = nullptr, netags = 0, *enodes = nullptr, nenodes = 0;
        G.gmshModelMeshGetElementsByType(2, &etags, &netags, &enodes, &nenodes, -1, 0, 1, &ierr);
        if (ierr || nenodes != 3 * netags) return send_error(G, fd, "cannot read the surface triangles");
        std::vector<int64_t> tri(nenodes);
        for (size_t i = 0; i < nenodes; ++i)
            tri[i] = enodes[i] <= max_tag ? index[enodes[i]] : -1;
        if (std::find(tri.begin(), tri.end(), -1) != tri.end())
            return send_error(G, fd, "a surface triangle has a node that is not in the mesh");
        const double vmax = j.h * j.h * j.h * std::sqrt(2.0) / 12.0;
        hd.n_surface = (int64_t)netags;
        hd.estimate = CM_EST_GMSH_VOLUME * j.volume / vmax +
                      CM_EST_GMSH_LAYER * cmvol::surface_layers(coord, tri.data(), netags, j.h);
        if (!(hd.estimate <= j.max_tets)) {
            hd.failed = 2;
            return cm_child_write(fd, &hd, sizeof hd) ? 3 : 0;
        }
    }
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

    size_t *etags = nullptr, netags = 0, *enodes = nullptr, nenodes = 0;
    G.gmshModelMeshGetElementsByType(4, &etags, &netags, &enodes, &nenodes, -1, 0, 1, &ierr);
    if (ierr || nenodes != 4 * netags) return send_error(G, fd, "cannot read the tets");
    if (netags == 0) return send_error(G, fd, "no tets (is there a volume?)");
    std::vector<int64_t> tets(nenodes);
    for (size_t i = 0; i < nenodes; ++i)
        tets[i] = enodes[i] <= max_tag ? index[enodes[i]] : -1;
    G.gmshFree(etags);
    G.gmshFree(enodes);

    int *surf = nullptr;
    size_t nsurf = 0;
    G.gmshModelGetEntities(&surf, &nsurf, 2, &ierr);
    std::vector<int64_t> tri;
    std::vector<int32_t> tri_tag;
    for (size_t s = 0; s + 1 < nsurf; s += 2) {
        const int tag = surf[s + 1];
        G.gmshModelMeshGetElementsByType(2, &etags, &netags, &enodes, &nenodes, tag, 0, 1, &ierr);
        if (ierr || nenodes != 3 * netags) return send_error(G, fd, "cannot read the triangles");
        for (size_t i = 0; i < nenodes; ++i)
            tri.push_back(enodes[i] <= max_tag ? index[enodes[i]] : -1);
        tri_tag.insert(tri_tag.end(), netags, tag);
        G.gmshFree(etags);
        G.gmshFree(enodes);
    }
    if (surf) G.gmshFree(surf);
    hd.n_nodes = (int64_t)ntags;
    hd.n_tets = (int64_t)tets.size() / 4;
    hd.n_tris = (int64_t)tri_tag.size();
    if (cm_child_write(fd, &hd, sizeof hd) || cm_child_write(fd, coord, 8 * ncoord) ||
        cm_child_write(fd, tets.data(), 8 * tets.size()) ||
        cm_child_write(fd, tri.data(), 8 * tri.size()) ||
        cm_child_write(fd, tri_tag.data(), 4 * tri_tag.size()))
        return 3;
    // no gmshFinalize, no frees: the process ends here
    return 0;
}

}  // namespace

double cmvol::surface_layers(const double *xyz, const int64_t *tri, size_t n_tri, double h)
{
    double layer = 0;
    for (size_t t = 0; t < n_tri; ++t) {
        const double *a = &xyz[3 * tri[3 * t]], *b = &xyz[3 * tri[3 * t + 1]], *c = &xyz[3 * tri[3 * t + 2]];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                             u[0] * w[1] - u[1] * w[0]};
        const double area = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        const double l = std::sqrt(area * 4 / std::sqrt(3.0));  // equilateral of that area
        layer += l < h && l > 0 ? std::log2(h / l) + 1 : 1;
    }
    return layer;
}

cm_status cmvol::gmsh_mesh(cm_context *ctx, const cm_cad_model *model, double h,
                           double time_limit, double volume, double max_tets, raw_mesh *out)
{
    const char *path = cm_cad_path(model);
    job j = {path, cm_cad_unit(model), h, volume, max_tets};
    char *data = nullptr;
    size_t size = 0;
    cm_child_outcome o;
    cm_status s = cm_child_run(ctx, "gmsh", "gmsh", child_work, &j, time_limit, &data, &size, &o);
    if (s < 0) return s;
    if (o.timed_out || o.signal || o.exit_code != 0) {
        std::free(data);
        char how[700];
        cm_child_describe(&o, how, sizeof how);
        return cm_error(ctx, o.timed_out ? CM_ERR_UNSUPPORTED : CM_ERR_NUMERIC, "%s: gmsh %s%s",
                        path, how, o.timed_out ? " (raise the time limit, --time-limit)" : "");
    }
    header hd;
    if (size < sizeof hd || (std::memcpy(&hd, data, sizeof hd), hd.magic != record_magic)) {
        std::free(data);
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: gmsh's child sent no record (%zu bytes)", path, size);
    }
    if (hd.failed == 2) {
        std::free(data);
        return cm_error(ctx, CM_ERR_NOMEM,
                        "%s: size %g would make about %.2g tets in gmsh (its surface mesh: %lld "
                        "triangles), more than the limit of %.3g: use a larger size or lift the "
                        "limit (cadmorph mesh --force)",
                        path, h, hd.estimate, (long long)hd.n_surface, max_tets);
    }
    if (hd.failed) {
        std::free(data);
        hd.msg[sizeof hd.msg - 1] = '\0';
        return cm_error(ctx, CM_ERR_NUMERIC, "%s: gmsh: %s", path, hd.msg);
    }
    const size_t nn = (size_t)hd.n_nodes, nt = (size_t)hd.n_tets, nb = (size_t)hd.n_tris;
    const size_t need = sizeof hd + 8 * (3 * nn + 4 * nt + 3 * nb) + 4 * nb;
    if (hd.n_nodes < 0 || hd.n_tets < 0 || hd.n_tris < 0 || size != need) {
        std::free(data);
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: gmsh's child sent %zu bytes, %zu expected",
                        path, size, need);
    }
    const char *c = data + sizeof hd;
    out->xyz.assign((const double *)c, (const double *)c + 3 * nn);
    c += 8 * 3 * nn;
    std::vector<int64_t> tets((const int64_t *)c, (const int64_t *)c + 4 * nt);
    c += 8 * 4 * nt;
    out->tri.assign((const int64_t *)c, (const int64_t *)c + 3 * nb);
    c += 8 * 3 * nb;
    std::vector<int32_t> tri_tag((const int32_t *)c, (const int32_t *)c + nb);
    std::free(data);
    for (int64_t v : tets)
        if (v < 0 || (size_t)v >= nn)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: a gmsh tet has a node that is not in the mesh", path);
    for (int64_t v : out->tri)
        if (v < 0 || (size_t)v >= nn)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: a gmsh triangle has a node that is not in the mesh", path);
    // only the nodes of tets (gmsh keeps the nodes of every entity it meshed)
    std::vector<int64_t> renum(nn, -1);
    size_t kept = 0;
    for (int64_t v : tets)
        if (renum[v] < 0) renum[v] = (int64_t)kept++;
    for (int64_t v : out->tri)
        if (renum[v] < 0)
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: a gmsh boundary triangle is on no tet", path);
    std::vector<double> xyz(3 * kept);
    for (size_t i = 0; i < nn; ++i)
        if (renum[i] >= 0) std::copy(&out->xyz[3 * i], &out->xyz[3 * i] + 3, &xyz[3 * renum[i]]);
    out->xyz.swap(xyz);
    for (int64_t &v : out->tri) v = renum[v];
    out->tets.resize(nt);
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 4; ++k) out->tets[t][k] = renum[tets[4 * t + k]];

    // gmsh surface -> CAD face: the face all of the surface's nodes lie on, within the model's
    // own tolerance there (gmsh binds faces in OpenCASCADE's order, so face tag - 1 is tried
    // first; a renumbering costs only time). A point of an edge may be its tolerance away from
    // the faces that meet there: a file's tolerances of 1e-4 x its size are common (CAD
    // systems' own), and gmsh places its nodes on the edge curves.
    double bb[6];
    cm_cad_bbox(model, bb);
    const double diag = cm_bbox_diagonal(bb), gdiag = cm_bbox_diagonal(hd.bbox);
    cm_cad_counts counts;
    cm_cad_get_counts(model, &counts);
    std::vector<double> face_tol(counts.faces);
    double largest_tol = 0;
    if ((s = cm_cad_face_tolerances(ctx, model, face_tol.data(), &largest_tol)) < 0) return s;
    const double floor_tol = 1e-7 * diag;
    std::map<int, std::vector<int64_t>> nodes_of;
    for (size_t t = 0; t < nb; ++t)
        for (int k = 0; k < 3; ++k) nodes_of[tri_tag[t]].push_back(out->tri[3 * t + k]);
    std::map<int, int> face_of;
    std::vector<int> taken(counts.faces, 0);
    double worst_ok = 0;
    for (auto &sn : nodes_of) {
        std::vector<int64_t> &v = sn.second;
        std::sort(v.begin(), v.end());
        v.erase(std::unique(v.begin(), v.end()), v.end());
        // up to 24 nodes spread over the surface's list
        std::vector<double> p;
        const size_t step = std::max<size_t>(1, v.size() / 24);
        for (size_t i = 0; i < v.size(); i += step)
            p.insert(p.end(), &out->xyz[3 * v[i]], &out->xyz[3 * v[i]] + 3);
        const size_t np = p.size() / 3;
        std::vector<double> dist(np);
        int found = -1, best_face = -1;
        double best = INFINITY;
        for (int k = -1; k < counts.faces && found < 0; ++k) {
            const int f = k < 0 ? sn.first - 1 : k;
            if (f < 0 || f >= counts.faces || (k >= 0 && f == sn.first - 1) || taken[f]) continue;
            s = cm_cad_project_face(ctx, model, f, p.data(), np, nullptr, nullptr, dist.data(), nullptr);
            if (s < 0) return s;
            const double worst = *std::max_element(dist.begin(), dist.end());
            if (worst < best) best = worst, best_face = f;
            if (worst <= std::max(floor_tol, 4 * face_tol[f])) found = f;
        }
        if (found < 0) {
            // the boxes tell a unit apart (factors of 10 and more) from a geometry that differs
            char unit[160] = "";
            if (gdiag > 2 * diag || gdiag < 0.5 * diag)
                std::snprintf(unit, sizeof unit, " (its size %g, ours %g: another unit?)", gdiag, diag);
            return cm_error(ctx, CM_ERR_MISMATCH,
                            "%s: gmsh's surface %d lies on no CAD face (closest: face %d, %.3g "
                            "away, beyond 4 x the model's tolerance there, %.3g): gmsh's "
                            "geometry is not cadmorph's%s",
                            path, sn.first, best_face, best,
                            best_face >= 0 ? std::max(floor_tol / 4, face_tol[best_face]) : 0.0, unit);
        }
        worst_ok = std::max(worst_ok, best);
        taken[found] = 1;
        face_of[sn.first] = found;
    }
    cm_log(ctx, CM_LOG_DEBUG, "tetmesh: gmsh's surfaces on the CAD faces within %.3g (largest "
           "tolerance of the model %.3g)", worst_ok, largest_tol);
    out->tri_face.resize(nb);
    for (size_t t = 0; t < nb; ++t) out->tri_face[t] = face_of[tri_tag[t]];
    cm_log(ctx, CM_LOG_DEBUG, "tetmesh: gmsh: %zu nodes, %zu tets (about %.3g expected from its "
           "%lld surface triangles), %zu boundary triangles on %zu faces (%.3f s)", nn, nt,
           hd.estimate, (long long)hd.n_surface, nb, nodes_of.size(), o.seconds);
    return CM_OK;
}
