// STEP reading and writing, the topology index (faces, edges, vertices numbered once by
// TopExp::MapShapes) and the correspondence check of G and G' (paper section 4: "the topology
// of G stays constant").
#include "cad_internal.hxx"
#include "step_scan.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GCPnts_AbscissaPoint.hxx>
#include <GProp_GProps.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>


#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

namespace cmcad {

cm_status check_face(cm_context *ctx, const cm_cad_model *m, int face, const char *fn)
{
    if (!m) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: model is NULL", fn);
    if (face < 0 || face >= m->faces.Extent())
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: face %d out of range (model has %d)", fn, face,
                        m->faces.Extent());
    return CM_OK;
}

cm_status check_edge(cm_context *ctx, const cm_cad_model *m, int edge, const char *fn)
{
    if (!m) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: model is NULL", fn);
    if (edge < 0 || edge >= m->edges.Extent())
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: edge %d out of range (model has %d)", fn, edge,
                        m->edges.Extent());
    return CM_OK;
}

}  // namespace cmcad

namespace {

// OpenCASCADE's translators use process-wide settings (Interface_Static) and the default
// messenger: set them under one lock, and remove the messenger's printers once so that the
// library never writes to stdout.
std::mutex xstep_lock;

void silence_opencascade()
{
    static std::once_flag once;
    std::call_once(once, [] {
        const Handle(Message_Messenger) &msg = Message::DefaultMessenger();
        msg->ChangePrinters().Clear();
    });
}

struct unit_name {
    const char *user, *occ;
};
const unit_name units[] = {{"mm", "MM"}, {"cm", "CM"}, {"m", "M"},   {"km", "KM"},
                           {"in", "INCH"}, {"ft", "FT"}, {"mi", "MI"}, {"um", "UM"}};

const char *occ_unit(const char *user)
{
    for (const unit_name &u : units)
        if (!strcmp(u.user, user)) return u.occ;
    return nullptr;
}

cm_cad_surface_type surface_type(GeomAbs_SurfaceType t)
{
    switch (t) {
    case GeomAbs_Plane: return CM_CAD_PLANE;
    case GeomAbs_Cylinder: return CM_CAD_CYLINDER;
    case GeomAbs_Cone: return CM_CAD_CONE;
    case GeomAbs_Sphere: return CM_CAD_SPHERE;
    case GeomAbs_Torus: return CM_CAD_TORUS;
    case GeomAbs_BezierSurface: return CM_CAD_BEZIER_SURFACE;
    case GeomAbs_BSplineSurface: return CM_CAD_BSPLINE_SURFACE;
    case GeomAbs_SurfaceOfRevolution: return CM_CAD_REVOLUTION;
    case GeomAbs_SurfaceOfExtrusion: return CM_CAD_EXTRUSION;
    case GeomAbs_OffsetSurface: return CM_CAD_OFFSET_SURFACE;
    default: return CM_CAD_OTHER_SURFACE;
    }
}

cm_cad_curve_type curve_type(GeomAbs_CurveType t)
{
    switch (t) {
    case GeomAbs_Line: return CM_CAD_LINE;
    case GeomAbs_Circle: return CM_CAD_CIRCLE;
    case GeomAbs_Ellipse: return CM_CAD_ELLIPSE;
    case GeomAbs_Hyperbola: return CM_CAD_HYPERBOLA;
    case GeomAbs_Parabola: return CM_CAD_PARABOLA;
    case GeomAbs_BezierCurve: return CM_CAD_BEZIER_CURVE;
    case GeomAbs_BSplineCurve: return CM_CAD_BSPLINE_CURVE;
    case GeomAbs_OffsetCurve: return CM_CAD_OFFSET_CURVE;
    default: return CM_CAD_OTHER_CURVE;
    }
}

void box_to(const Bnd_Box &b, double *out)
{
    if (b.IsVoid()) {
        std::fill(out, out + 6, 0.0);
        return;
    }
    b.Get(out[0], out[1], out[2], out[3], out[4], out[5]);
}

// Numbers faces, edges and vertices and fills everything the info calls return.
void index_topology(cm_cad_model *m)
{
    TopExp::MapShapes(m->shape, TopAbs_FACE, m->faces);
    TopExp::MapShapes(m->shape, TopAbs_EDGE, m->edges);
    TopExp::MapShapes(m->shape, TopAbs_VERTEX, m->vertices);
    TopTools_IndexedMapOfShape solids, shells;
    TopExp::MapShapes(m->shape, TopAbs_SOLID, solids);
    TopExp::MapShapes(m->shape, TopAbs_SHELL, shells);
    m->counts.solids = solids.Extent();
    m->counts.shells = shells.Extent();
    m->counts.faces = m->faces.Extent();
    m->counts.edges = m->edges.Extent();
    m->counts.vertices = m->vertices.Extent();

    m->vertex_xyz.resize(3 * (size_t)m->counts.vertices);
    for (int i = 0; i < m->counts.vertices; ++i) {
        gp_Pnt p = BRep_Tool::Pnt(TopoDS::Vertex(m->vertices(i + 1)));
        m->vertex_xyz[3 * i] = p.X(), m->vertex_xyz[3 * i + 1] = p.Y(),
                      m->vertex_xyz[3 * i + 2] = p.Z();
    }

    m->edge_info.resize(m->counts.edges);
    for (int i = 0; i < m->counts.edges; ++i) {
        TopoDS_Edge e = TopoDS::Edge(m->edge(i).Oriented(TopAbs_FORWARD));
        cm_cad_edge_info &info = m->edge_info[i];
        info = cm_cad_edge_info{};
        BRep_Tool::Range(e, info.t_range[0], info.t_range[1]);
        TopoDS_Vertex v1, v2;
        TopExp::Vertices(e, v1, v2);
        info.vertex[0] = v1.IsNull() ? -1 : m->vertices.FindIndex(v1) - 1;
        info.vertex[1] = v2.IsNull() ? -1 : m->vertices.FindIndex(v2) - 1;
        info.closed = !v1.IsNull() && v1.IsSame(v2);
        info.degenerate = BRep_Tool::Degenerated(e);
        info.type = CM_CAD_OTHER_CURVE;
        if (!info.degenerate && BRep_Tool::IsGeometric(e)) {
            BRepAdaptor_Curve c(e);
            info.type = curve_type(c.GetType());
            info.length = GCPnts_AbscissaPoint::Length(c);
        } else {
            info.degenerate = 1;
        }
        Bnd_Box b;
        BRepBndLib::AddOptimal(e, b, false, false);
        box_to(b, info.bbox);
    }

    TopTools_IndexedDataMapOfShapeListOfShape edge_faces;
    TopExp::MapShapesAndUniqueAncestors(m->shape, TopAbs_EDGE, TopAbs_FACE, edge_faces);
    m->edge_face_offset.assign(1, 0);
    for (int i = 0; i < m->counts.edges; ++i) {
        const TopTools_ListOfShape *l = edge_faces.Seek(m->edges(i + 1));
        if (l)
            for (const TopoDS_Shape &f : *l) m->edge_face.push_back(m->faces.FindIndex(f) - 1);
        m->edge_face_offset.push_back((int)m->edge_face.size());
    }

    m->face_info.resize(m->counts.faces);
    m->face_wire_offset.assign(1, 0);
    m->wire_offset.assign(1, 0);
    for (int i = 0; i < m->counts.faces; ++i) {
        TopoDS_Face f = m->face(i);
        cm_cad_face_info &info = m->face_info[i];
        info = cm_cad_face_info{};
        BRepAdaptor_Surface s(f, false);
        info.type = surface_type(s.GetType());
        BRepTools::UVBounds(f, info.uv_range[0], info.uv_range[1], info.uv_range[2],
                            info.uv_range[3]);
        info.periodic[0] = s.IsUPeriodic();
        info.periodic[1] = s.IsVPeriodic();
        info.period[0] = info.periodic[0] ? s.UPeriod() : 0.0;
        info.period[1] = info.periodic[1] ? s.VPeriod() : 0.0;
        info.reversed = f.Orientation() == TopAbs_REVERSED;
        GProp_GProps props;
        BRepGProp::SurfaceProperties(f, props);
        info.area = props.Mass();
        Bnd_Box b;
        BRepBndLib::AddOptimal(f, b, false, false);
        box_to(b, info.bbox);

        // The outer wire first, then the holes in the face's order.
        TopoDS_Wire outer = BRepTools::OuterWire(f);
        std::vector<TopoDS_Wire> wires;
        for (TopExp_Explorer w(f, TopAbs_WIRE); w.More(); w.Next()) {
            TopoDS_Wire wire = TopoDS::Wire(w.Current());
            if (!outer.IsNull() && wire.IsSame(outer))
                wires.insert(wires.begin(), wire);
            else
                wires.push_back(wire);
        }
        for (const TopoDS_Wire &wire : wires) {
            // Connected order (BRepTools_WireExplorer) when it covers the wire, else the
            // stored order: both are deterministic for a given file structure.
            std::vector<int> ed, rv;
            for (BRepTools_WireExplorer e(wire, f); e.More(); e.Next()) {
                ed.push_back(m->edges.FindIndex(e.Current()) - 1);
                rv.push_back(e.Current().Orientation() == TopAbs_REVERSED);
            }
            int stored = 0;
            for (TopExp_Explorer e(wire, TopAbs_EDGE); e.More(); e.Next()) ++stored;
            if ((int)ed.size() != stored) {
                ed.clear(), rv.clear();
                for (TopExp_Explorer e(wire, TopAbs_EDGE); e.More(); e.Next()) {
                    ed.push_back(m->edges.FindIndex(e.Current()) - 1);
                    rv.push_back(e.Current().Orientation() == TopAbs_REVERSED);
                }
            }
            m->wire_edge.insert(m->wire_edge.end(), ed.begin(), ed.end());
            m->wire_rev.insert(m->wire_rev.end(), rv.begin(), rv.end());
            m->wire_offset.push_back((int)m->wire_edge.size());
        }
        info.n_wires = (int)wires.size();
        m->face_wire_offset.push_back((int)m->wire_offset.size() - 1);
    }
    m->counts.wires = (int)m->wire_offset.size() - 1;

    Bnd_Box all;
    BRepBndLib::AddOptimal(m->shape, all, false, false);
    box_to(all, m->bbox);

}

const char *what_error(int err) { return strerror(err); }

}  // namespace

/* A circle is an ellipse with equal axes: tilting a cylindrical bore turns its circular rims
 * into ellipses while the topology stays the same, so the two types correspond. */
static bool same_curve_family(cm_cad_curve_type a, cm_cad_curve_type b)
{
    auto conic = [](cm_cad_curve_type t) { return t == CM_CAD_CIRCLE || t == CM_CAD_ELLIPSE; };
    return a == b || (conic(a) && conic(b));
}

extern "C" {

void cm_cad_read_options_init(cm_cad_read_options *opt)
{
    if (opt) opt->unit = "mm";
}

cm_status cm_cad_read(cm_context *ctx, const char *path, const cm_cad_read_options *opt,
                      cm_cad_model **model)
{
    const char *fn = "cm_cad_read";
    if (!model) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: model is NULL", fn);
    *model = nullptr;
    if (!path) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: path is NULL", fn);
    cm_cad_read_options o;
    cm_cad_read_options_init(&o);
    if (opt && opt->unit) o.unit = opt->unit;
    const char *occ = occ_unit(o.unit);
    if (!occ)
        return cm_error(ctx, CM_ERR_ARGUMENT,
                        "%s: unknown length unit '%s' (mm, cm, m, km, in, ft, mi, um)", fn, o.unit);
    // The bytes OpenCASCADE parses are the bytes we scanned: read once (cm_file_read refuses
    // FIFOs and devices before opening them), scan, then hand OpenCASCADE a stream.
    char *data = nullptr;
    size_t size = 0;
    cm_status st = cm_file_read(ctx, path, &data, &size);
    if (st != CM_OK) return st;
    st = cm_step_scan(ctx, path, data, size);
    if (st != CM_OK) {
        free(data);
        return st;
    }
    std::string text;
    st = cmcad::guard(ctx, fn, [&]() -> cm_status {
        text.assign(data, size);
        return CM_OK;
    });
    free(data);
    if (st != CM_OK) return st;

    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        silence_opencascade();
        std::unique_ptr<cm_cad_model> m(new cm_cad_model());
        {
            std::lock_guard<std::mutex> g(xstep_lock);
            STEPControl_Reader reader;
            Interface_Static::SetCVal("xstep.cascade.unit", occ);
            Interface_Static::SetIVal("read.step.product.mode", 1);
            std::istringstream stream(std::move(text));
            if (reader.ReadStream(path, stream) != IFSelect_RetDone)
                return cm_error(ctx, CM_ERR_FORMAT, "%s: OpenCASCADE cannot parse this STEP file",
                                path);
            TColStd_SequenceOfAsciiString lengths, angles, solid_angles;
            reader.FileUnits(lengths, angles, solid_angles);
            if (!lengths.IsEmpty()) m->file_unit = lengths.First().ToCString();
            if (reader.NbRootsForTransfer() == 0)
                return cm_error(ctx, CM_ERR_FORMAT, "%s: no shape to transfer in this STEP file",
                                path);
            if (reader.TransferRoots() == 0 || reader.NbShapes() == 0)
                return cm_error(ctx, CM_ERR_CAD, "%s: OpenCASCADE failed to transfer the shapes",
                                path);
            m->shape = reader.OneShape();
        }
        m->unit = o.unit;
        m->path = path;
        if (m->shape.IsNull())
            return cm_error(ctx, CM_ERR_CAD, "%s: OpenCASCADE failed to transfer the shapes", path);
        index_topology(m.get());
        if (m->counts.faces == 0)
            return cm_error(ctx, CM_ERR_FORMAT, "%s: no solid, shell or face in this STEP file",
                            path);
        *model = m.release();
        return CM_OK;
    });
}

cm_status cm_cad_write(cm_context *ctx, const cm_cad_model *model, const char *path)
{
    const char *fn = "cm_cad_write";
    if (!model || !path) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL model or path", fn);
    std::string tmp = std::string(path) + ".tmp";
    cm_status st = cmcad::guard(ctx, fn, [&]() -> cm_status {
        silence_opencascade();
        std::lock_guard<std::mutex> g(xstep_lock);
        const char *occ = occ_unit(model->unit.c_str());
        Interface_Static::SetCVal("xstep.cascade.unit", occ);
        Interface_Static::SetCVal("write.step.unit", occ);
        Interface_Static::SetCVal("write.step.schema", "AP214IS");
        STEPControl_Writer writer;
        if (writer.Transfer(model->shape, STEPControl_AsIs) != IFSelect_RetDone)
            return cm_error(ctx, CM_ERR_CAD, "%s: OpenCASCADE failed to translate the shape", path);
        if (writer.Write(tmp.c_str()) != IFSelect_RetDone)
            return cm_error(ctx, CM_ERR_IO, "%s: cannot write", tmp.c_str());
        return CM_OK;
    });
    if (st != CM_OK) {
        std::remove(tmp.c_str());
        return st;
    }
    if (std::rename(tmp.c_str(), path) != 0) {
        int err = errno;
        std::remove(tmp.c_str());
        return cm_error(ctx, CM_ERR_IO, "%s: cannot rename %s: %s", path, tmp.c_str(),
                        what_error(err));
    }
    return CM_OK;
}

void cm_cad_destroy(cm_cad_model **model)
{
    if (!model || !*model) return;
    try {
        delete *model;
    } catch (...) {
        // destructors of OpenCASCADE handles do not throw; nothing to report to here
    }
    *model = nullptr;
}

const char *cm_cad_file_unit(const cm_cad_model *model)
{
    return model ? model->file_unit.c_str() : "";
}

const char *cm_cad_path(const cm_cad_model *model) { return model ? model->path.c_str() : ""; }

const char *cm_cad_unit(const cm_cad_model *model) { return model ? model->unit.c_str() : ""; }

void cm_cad_get_counts(const cm_cad_model *model, cm_cad_counts *counts)
{
    if (!counts) return;
    *counts = model ? model->counts : cm_cad_counts{};
}

const char *cm_cad_surface_type_name(cm_cad_surface_type type)
{
    static const char *names[] = {"plane",     "cylinder",   "cone",      "sphere",
                                  "torus",     "bezier",     "bspline",   "revolution",
                                  "extrusion", "offset",     "other"};
    return (unsigned)type <= CM_CAD_OTHER_SURFACE ? names[type] : "?";
}

const char *cm_cad_curve_type_name(cm_cad_curve_type type)
{
    static const char *names[] = {"line",   "circle",  "ellipse", "hyperbola", "parabola",
                                  "bezier", "bspline", "offset",  "other"};
    return (unsigned)type <= CM_CAD_OTHER_CURVE ? names[type] : "?";
}

cm_status cm_cad_face_get_info(cm_context *ctx, const cm_cad_model *model, int face,
                               cm_cad_face_info *info)
{
    cm_status st = cmcad::check_face(ctx, model, face, "cm_cad_face_get_info");
    if (st != CM_OK) return st;
    if (!info) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_cad_face_get_info: info is NULL");
    *info = model->face_info[face];
    return CM_OK;
}

cm_status cm_cad_edge_get_info(cm_context *ctx, const cm_cad_model *model, int edge,
                               cm_cad_edge_info *info)
{
    cm_status st = cmcad::check_edge(ctx, model, edge, "cm_cad_edge_get_info");
    if (st != CM_OK) return st;
    if (!info) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_cad_edge_get_info: info is NULL");
    *info = model->edge_info[edge];
    return CM_OK;
}

cm_status cm_cad_vertex_point(cm_context *ctx, const cm_cad_model *model, int vertex, double *xyz)
{
    if (!model || !xyz) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_cad_vertex_point: NULL argument");
    if (vertex < 0 || vertex >= model->counts.vertices)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_cad_vertex_point: vertex %d out of range (%d)",
                        vertex, model->counts.vertices);
    std::copy(&model->vertex_xyz[3 * (size_t)vertex], &model->vertex_xyz[3 * (size_t)vertex] + 3,
              xyz);
    return CM_OK;
}

void cm_cad_bbox(const cm_cad_model *model, double *bbox)
{
    if (!bbox) return;
    if (model)
        std::copy(model->bbox, model->bbox + 6, bbox);
    else
        std::fill(bbox, bbox + 6, 0.0);
}

cm_status cm_cad_face_wire(cm_context *ctx, const cm_cad_model *model, int face, int wire,
                           const int **edges, const int **reversed, int *n)
{
    cm_status st = cmcad::check_face(ctx, model, face, "cm_cad_face_wire");
    if (st != CM_OK) return st;
    int nw = model->face_info[face].n_wires;
    if (wire < 0 || wire >= nw)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_cad_face_wire: face %d has %d wires, asked %d",
                        face, nw, wire);
    int w = model->face_wire_offset[face] + wire;
    int b = model->wire_offset[w], e = model->wire_offset[w + 1];
    if (edges) *edges = model->wire_edge.data() + b;
    if (reversed) *reversed = model->wire_rev.data() + b;
    if (n) *n = e - b;
    return CM_OK;
}

cm_status cm_cad_edge_faces(cm_context *ctx, const cm_cad_model *model, int edge,
                            const int **faces, int *n)
{
    cm_status st = cmcad::check_edge(ctx, model, edge, "cm_cad_edge_faces");
    if (st != CM_OK) return st;
    int b = model->edge_face_offset[edge], e = model->edge_face_offset[edge + 1];
    if (faces) *faces = model->edge_face.data() + b;
    if (n) *n = e - b;
    return CM_OK;
}

cm_status cm_cad_compare(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                         int max_report)
{
    if (!g || !g2) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_cad_compare: NULL model");
    if (max_report < 1) max_report = 1;
    return cmcad::guard(ctx, "cm_cad_compare", [&]() -> cm_status {
        std::vector<std::string> diff;
        size_t total = 0;
        char line[256];
        auto add = [&](const char *s) {
            if ((int)diff.size() < max_report) diff.push_back(s);
            ++total;
        };
        const cm_cad_counts &a = g->counts, &b = g2->counts;
        const struct {
            const char *name;
            int x, y;
        } counts[] = {{"solids", a.solids, b.solids}, {"shells", a.shells, b.shells},
                      {"faces", a.faces, b.faces},    {"wires", a.wires, b.wires},
                      {"edges", a.edges, b.edges},    {"vertices", a.vertices, b.vertices}};
        for (const auto &c : counts)
            if (c.x != c.y) {
                snprintf(line, sizeof line, "%s: %d in G, %d in G'", c.name, c.x, c.y);
                add(line);
            }
        int nf = std::min(a.faces, b.faces), ne = std::min(a.edges, b.edges);
        for (int i = 0; i < nf; ++i) {
            const cm_cad_face_info &p = g->face_info[i], &q = g2->face_info[i];
            if (p.type != q.type) {
                snprintf(line, sizeof line, "face %d: %s in G, %s in G'", i,
                         cm_cad_surface_type_name(p.type), cm_cad_surface_type_name(q.type));
                add(line);
                continue;
            }
            if (p.n_wires != q.n_wires) {
                snprintf(line, sizeof line, "face %d: %d wires in G, %d in G'", i, p.n_wires,
                         q.n_wires);
                add(line);
                continue;
            }
            for (int w = 0; w < p.n_wires; ++w) {
                int wa = g->face_wire_offset[i] + w, wb = g2->face_wire_offset[i] + w;
                int ba = g->wire_offset[wa], ea = g->wire_offset[wa + 1];
                int bb = g2->wire_offset[wb], eb = g2->wire_offset[wb + 1];
                bool same = ea - ba == eb - bb;
                for (int k = 0; same && k < ea - ba; ++k)
                    same = g->wire_edge[ba + k] == g2->wire_edge[bb + k] &&
                           g->wire_rev[ba + k] == g2->wire_rev[bb + k];
                if (!same) {
                    snprintf(line, sizeof line,
                             "face %d wire %d: %d edges starting %s%d in G, %d starting %s%d in G'",
                             i, w, ea - ba, ea > ba && g->wire_rev[ba] ? "-" : "",
                             ea > ba ? g->wire_edge[ba] : -1, eb - bb,
                             eb > bb && g2->wire_rev[bb] ? "-" : "",
                             eb > bb ? g2->wire_edge[bb] : -1);
                    add(line);
                    break;
                }
            }
        }
        for (int i = 0; i < ne; ++i) {
            const cm_cad_edge_info &p = g->edge_info[i], &q = g2->edge_info[i];
            if (!same_curve_family(p.type, q.type) || p.degenerate != q.degenerate) {
                snprintf(line, sizeof line, "edge %d: %s in G, %s in G'", i,
                         p.degenerate ? "degenerate" : cm_cad_curve_type_name(p.type),
                         q.degenerate ? "degenerate" : cm_cad_curve_type_name(q.type));
                add(line);
            } else if (p.vertex[0] != q.vertex[0] || p.vertex[1] != q.vertex[1]) {
                snprintf(line, sizeof line, "edge %d: vertices (%d,%d) in G, (%d,%d) in G'", i,
                         p.vertex[0], p.vertex[1], q.vertex[0], q.vertex[1]);
                add(line);
            }
        }
        if (total == 0) {
            // Same topology but another scale: a file in mm against the same numbers declared
            // in m morphs to a x1000 result. Orders of magnitude are an error, another unit
            // name alone (converted to the same unit) a warning.
            auto diag = [](const double *b) {
                return std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) +
                                 (b[5] - b[2]) * (b[5] - b[2]));
            };
            const double d1 = diag(g->bbox), d2 = diag(g2->bbox);
            const double ratio = d1 > 0 && d2 > 0 ? std::max(d1 / d2, d2 / d1) : 1.0;
            const bool units_differ = g->file_unit != g2->file_unit;
            if (ratio >= 100)
                return cm_error(ctx, CM_ERR_MISMATCH,
                                "%s and %s: G and G' differ in size by %.3gx (bounding-box diagonals %g and %g "
                                "%s; file units %s and %s): check the units of the STEP files",
                                g->path.c_str(), g2->path.c_str(), ratio, d1, d2, g->unit.c_str(), g->file_unit.c_str(),
                                g2->file_unit.c_str());
            if (units_differ)
                cm_log(ctx, CM_LOG_WARNING,
                       "G is in %s, G' in %s (both read as %s): check that this is intended",
                       g->file_unit.c_str(), g2->file_unit.c_str(), g->unit.c_str());
            return CM_OK;
        }
        std::string msg = "topology of G and G' differs (" + std::to_string(total) +
                          (total == 1 ? " difference): " : " differences): ");
        for (size_t i = 0; i < diff.size(); ++i) msg += (i ? "; " : "") + diff[i];
        if (total > diff.size()) msg += "; ...";
        return cm_error(ctx, CM_ERR_MISMATCH, "%s", msg.c_str());
    });
}

}  // extern "C"
