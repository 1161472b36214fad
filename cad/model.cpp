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

std::mutex &cmcad::xstep_lock()
{
    static std::mutex lock;
    return lock;
}

namespace {

// OpenCASCADE's translators use process-wide settings (Interface_Static, set under
// cmcad::xstep_lock) and the default messenger: remove its printers once so that the library
// never writes to stdout.

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
    m->shell_solid.assign(shells.Extent(), -1);
    for (int s = 1; s <= solids.Extent(); ++s)
        for (TopExp_Explorer x(solids(s), TopAbs_SHELL); x.More(); x.Next()) {
            int k = shells.FindIndex(x.Current());
            if (k > 0 && m->shell_solid[k - 1] < 0) m->shell_solid[k - 1] = s - 1;
        }
    m->face_shell.assign(m->faces.Extent(), -1);
    for (int s = 1; s <= shells.Extent(); ++s)
        for (TopExp_Explorer x(shells(s), TopAbs_FACE); x.More(); x.Next()) {
            int k = m->faces.FindIndex(x.Current());
            if (k > 0 && m->face_shell[k - 1] < 0) m->face_shell[k - 1] = s - 1;
        }
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
        gp_Pnt mid;
        if (!v1.IsNull()) mid = BRep_Tool::Pnt(v1);
        if (!info.degenerate && BRep_Tool::IsGeometric(e)) {
            BRepAdaptor_Curve c(e);
            info.type = curve_type(c.GetType());
            info.length = GCPnts_AbscissaPoint::Length(c);
            mid = c.Value(0.5 * (info.t_range[0] + info.t_range[1]));
        } else {
            info.degenerate = 1;
        }
        m->edge_mid.insert(m->edge_mid.end(), {mid.X(), mid.Y(), mid.Z()});
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
        gp_Pnt c = info.area > 0 ? props.CentreOfMass() : gp_Pnt();
        if (!(info.area > 0)) {
            Bnd_Box fb;
            BRepBndLib::Add(f, fb, false);
            if (!fb.IsVoid()) {
                double x0, y0, z0, x1, y1, z1;
                fb.Get(x0, y0, z0, x1, y1, z1);
                c.SetCoord(0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (z0 + z1));
            }
        }
        m->face_center.insert(m->face_center.end(), {c.X(), c.Y(), c.Z()});
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
            std::lock_guard<std::mutex> g(cmcad::xstep_lock());
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
        std::lock_guard<std::mutex> g(cmcad::xstep_lock());
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

}  // extern "C"
