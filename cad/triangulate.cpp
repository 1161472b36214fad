// Watertight surface triangulation of a CAD model (BRepMesh) and the volume of its solids.
// BRepMesh discretises each edge once and every face on it reuses that discretisation
// (Poly_PolygonOnTriangulation: indices into the face's triangulation), so mapping polygon
// nodes of all faces to one node per edge point glues the faces without a tolerance merge.
#include "cad_internal.hxx"
#include "cadmorph/cad.h"

#include <BRepGProp.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <IMeshTools_Parameters.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <Poly_PolygonOnTriangulation.hxx>
#include <Poly_Triangulation.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Vertex.hxx>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <tuple>

namespace {

struct builder {
    std::vector<double> xyz;
    std::vector<int> dim, entity;
    int64_t add(const gp_Pnt &p, int d, int e)
    {
        xyz.push_back(p.X());
        xyz.push_back(p.Y());
        xyz.push_back(p.Z());
        dim.push_back(d);
        entity.push_back(e);
        return (int64_t)dim.size() - 1;
    }
    gp_Pnt at(int64_t i) const { return gp_Pnt(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]); }
};

template <class T> T *copy_out(const std::vector<T> &v)
{
    T *p = (T *)std::malloc((v.empty() ? 1 : v.size()) * sizeof(T));
    if (!p) throw std::bad_alloc();
    if (!v.empty()) std::memcpy(p, v.data(), v.size() * sizeof(T));
    return p;
}

// Edges of the triangles not matched by exactly one opposite edge.
size_t open_edges(const std::vector<int64_t> &tri)
{
    std::vector<std::array<int64_t, 3>> e;  // (min, max, +1 forward / -1 backward)
    e.reserve(tri.size());
    for (size_t t = 0; t < tri.size() / 3; ++t)
        for (int k = 0; k < 3; ++k) {
            int64_t a = tri[3 * t + k], b = tri[3 * t + (k + 1) % 3];
            e.push_back(a < b ? std::array<int64_t, 3>{a, b, 1} : std::array<int64_t, 3>{b, a, -1});
        }
    std::sort(e.begin(), e.end());
    size_t bad = 0;
    for (size_t i = 0; i < e.size();) {
        size_t j = i;
        while (j < e.size() && e[j][0] == e[i][0] && e[j][1] == e[i][1]) ++j;
        if (!(j - i == 2 && e[i][2] != e[i + 1][2])) ++bad;
        i = j;
    }
    return bad;
}

}  // namespace

extern "C" void cm_cad_triangulate_options_init(cm_cad_triangulate_options *opt)
{
    if (!opt) return;
    opt->size = 0;
    opt->linear_deflection = 0;
    opt->angular_deflection = 0;
    opt->min_size = 0;
}

extern "C" void cm_cad_triangulation_destroy(cm_cad_triangulation **t)
{
    if (!t || !*t) return;
    std::free((*t)->xyz);
    std::free((*t)->node_dim);
    std::free((*t)->node_entity);
    std::free((*t)->tri);
    std::free((*t)->tri_face);
    std::free((*t)->tri_uv);
    std::free(*t);
    *t = nullptr;
}

extern "C" cm_status cm_cad_triangulate(cm_context *ctx, const cm_cad_model *model,
                                        const cm_cad_triangulate_options *opt,
                                        cm_cad_triangulation **out)
{
    const char *fn = "cm_cad_triangulate";
    if (out) *out = nullptr;
    if (!model || !out) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL model or output", fn);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        const int nf = model->faces.Extent();
        if (nf == 0) return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: the model has no faces", fn);
        cm_cad_triangulate_options o;
        cm_cad_triangulate_options_init(&o);
        if (opt) o = *opt;
        const double diag = cm_bbox_diagonal(model->bbox);
        const double h = o.size > 0 ? o.size : diag / 20;
        const double lin = o.linear_deflection > 0 ? o.linear_deflection : h / 10;
        const double ang = o.angular_deflection > 0 ? o.angular_deflection : 0.3;
        if (!(h > 0) || !std::isfinite(h))
            return cm_error(ctx, CM_ERR_ARGUMENT, "%s: size %g is not a positive length", fn, h);

        // A finer triangulation left by an earlier call would be kept by BRepMesh: drop it.
        TopoDS_Shape shape = model->shape;
        BRepTools::Clean(shape);
        // MinSize: without it BRepMesh may crowd points a few thousandths apart (seen on a
        // surface of revolution), and a tet mesher keeps those as tiny slivers
        IMeshTools_Parameters par;
        par.Deflection = lin;
        par.Angle = ang;
        par.MinSize = o.min_size > 0 ? o.min_size : h / 4;
        par.InParallel = Standard_False;
        par.Relative = Standard_False;
        BRepMesh_IncrementalMesh mesher(shape, par);
        if (!mesher.IsDone()) return cm_error(ctx, CM_ERR_CAD, "%s: BRepMesh failed", fn);

        builder b;
        const int nv = model->vertices.Extent();
        for (int v = 0; v < nv; ++v)
            b.add(BRep_Tool::Pnt(TopoDS::Vertex(model->vertices(v + 1))), 0, v);
        std::vector<std::vector<int64_t>> edge_nodes(model->edges.Extent());
        std::vector<int64_t> tri;
        std::vector<int> tri_face;
        std::vector<double> tri_uv;

        for (int f = 0; f < nf; ++f) {
            const TopoDS_Face face = model->face(f);
            TopLoc_Location loc;
            const Handle(Poly_Triangulation) &pt = BRep_Tool::Triangulation(face, loc);
            if (pt.IsNull() || pt->NbTriangles() == 0)
                return cm_error(ctx, CM_ERR_CAD, "%s: face %d: BRepMesh made no triangles", fn, f);
            if (!pt->HasUVNodes())
                return cm_error(ctx, CM_ERR_CAD, "%s: face %d: triangulation without (u, v)", fn, f);
            const gp_Trsf &trsf = loc.Transformation();
            std::vector<int64_t> l2g(pt->NbNodes() + 1, -1);
            for (TopExp_Explorer ex(face, TopAbs_EDGE); ex.More(); ex.Next()) {
                const TopoDS_Edge edge = TopoDS::Edge(ex.Current());
                const int e = model->edges.FindIndex(edge) - 1;
                const Handle(Poly_PolygonOnTriangulation) &poly =
                    BRep_Tool::PolygonOnTriangulation(edge, pt, loc);
                if (poly.IsNull())
                    return cm_error(ctx, CM_ERR_CAD, "%s: face %d: edge %d has no discretisation", fn,
                                    f, e);
                const TColStd_Array1OfInteger &idx = poly->Nodes();
                const int n = idx.Length();
                TopoDS_Vertex v0, v1;
                TopExp::Vertices(edge, v0, v1);
                const int64_t g0 = v0.IsNull() ? -1 : model->vertices.FindIndex(v0) - 1;
                const int64_t g1 = v1.IsNull() ? -1 : model->vertices.FindIndex(v1) - 1;
                auto point = [&](int j) { return pt->Node(idx(idx.Lower() + j)).Transformed(trsf); };
                if (BRep_Tool::Degenerated(edge)) {
                    for (int j = 0; j < n; ++j) l2g[idx(idx.Lower() + j)] = g0;
                    continue;
                }
                std::vector<int64_t> &en = edge_nodes[e];
                if (en.empty()) {
                    // the ends are the edge's vertices (whichever lies nearer: the polygon
                    // runs in the curve's direction, the vertex pair in the edge's)
                    const gp_Pnt p0 = point(0);
                    const bool swap = g0 >= 0 && g1 >= 0 &&
                                      p0.SquareDistance(b.at(g1)) < p0.SquareDistance(b.at(g0));
                    en.resize(n);
                    en[0] = swap ? g1 : g0;
                    en[n - 1] = swap ? g0 : g1;
                    for (int j = 1; j < n - 1; ++j) en[j] = b.add(point(j), 1, e);
                } else if ((int)en.size() != n) {
                    return cm_error(ctx, CM_ERR_CAD,
                                    "%s: edge %d: %d points in face %d, %zu in an earlier face", fn,
                                    e, n, f, en.size());
                }
                // same points, possibly listed from the other end
                // (an interior point decides: both ends of a closed edge are one vertex)
                const int j = n > 2 ? 1 : 0;
                const bool rev = n > 1 && point(j).SquareDistance(b.at(en[n - 1 - j])) <
                                              point(j).SquareDistance(b.at(en[j]));
                for (int j = 0; j < n; ++j) l2g[idx(idx.Lower() + j)] = en[rev ? n - 1 - j : j];
            }
            for (int i = 1; i <= pt->NbNodes(); ++i)
                if (l2g[i] < 0) l2g[i] = b.add(pt->Node(i).Transformed(trsf), 2, f);
            const bool flip = face.Orientation() == TopAbs_REVERSED;
            for (int k = 1; k <= pt->NbTriangles(); ++k) {
                int a, c, d;
                pt->Triangle(k).Get(a, c, d);
                if (flip) std::swap(c, d);
                const int64_t ga = l2g[a], gc = l2g[c], gd = l2g[d];
                if (ga < 0 || gc < 0 || gd < 0)
                    return cm_error(ctx, CM_ERR_CAD, "%s: face %d: a triangle on a missing node", fn, f);
                if (ga == gc || gc == gd || gd == ga) continue;  // collapsed at a degenerate edge
                tri.insert(tri.end(), {ga, gc, gd});
                tri_face.push_back(f);
                for (int corner : {a, c, d}) {
                    const gp_Pnt2d uv = pt->UVNode(corner);
                    tri_uv.push_back(uv.X());
                    tri_uv.push_back(uv.Y());
                }
            }
        }

        auto *t = (cm_cad_triangulation *)std::calloc(1, sizeof(cm_cad_triangulation));
        if (!t) throw std::bad_alloc();
        try {
            t->n_nodes = b.dim.size();
            t->xyz = copy_out(b.xyz);
            t->node_dim = copy_out(b.dim);
            t->node_entity = copy_out(b.entity);
            t->n_triangles = tri_face.size();
            t->tri = copy_out(tri);
            t->tri_face = copy_out(tri_face);
            t->tri_uv = copy_out(tri_uv);
            t->n_open_edges = open_edges(tri);
        } catch (...) {
            cm_cad_triangulation_destroy(&t);
            throw;
        }
        *out = t;
        return CM_OK;
    });
}

extern "C" cm_status cm_cad_volume(cm_context *ctx, const cm_cad_model *model, double *volume)
{
    const char *fn = "cm_cad_volume";
    if (!model || !volume) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL model or output", fn);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        if (model->counts.solids == 0)
            return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: the model has no solid", fn);
        GProp_GProps props;
        BRepGProp::VolumeProperties(model->shape, props);
        *volume = props.Mass();
        return CM_OK;
    });
}
