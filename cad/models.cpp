// The built-in models (models.h) as OpenCASCADE solids and their STEP export. Each model is built by
// the same sequence of operations for every t, so that the boolean and sweep algorithms
// produce the same topology in the same MapShapes order (checked by test_models).
#include "cadmorph/models.h"
#include "cad_internal.hxx"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepGProp.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <gp_Trsf.hxx>
#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRep_Tool.hxx>
#include <GC_MakeArcOfCircle.hxx>
#include <GProp_GProps.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Solid.hxx>
#include <gp_Ax1.hxx>
#include <gp_Ax2.hxx>
#include <gp_Circ.hxx>
#include <gp_Pln.hxx>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>

namespace {

const double deg = M_PI / 180.0;

// The single solid of a boolean result (which comes back as a compound).
TopoDS_Shape only_solid(const TopoDS_Shape &s, const char *what)
{
    TopExp_Explorer ex(s, TopAbs_SOLID);
    if (!ex.More()) throw std::runtime_error(std::string(what) + ": no solid");
    TopoDS_Shape solid = ex.Current();
    ex.Next();
    if (ex.More()) throw std::runtime_error(std::string(what) + ": more than one solid");
    return solid;
}

TopoDS_Shape cut(const TopoDS_Shape &a, const TopoDS_Shape &b, const char *what)
{
    BRepAlgoAPI_Cut op(a, b);
    if (!op.IsDone() || op.HasErrors()) throw std::runtime_error(std::string(what) + ": cut failed");
    return only_solid(op.Shape(), what);
}

TopoDS_Shape make_bore(double t)
{
    cm_model_bore p;
    cm_model_bore_at(t, &p);
    TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-2, -2, 0), gp_Pnt(2, 2, 2)).Shape();
    // axis through the block centre, +z rotated about +x; the seam side (x direction of the
    // cylinder) stays on +x, perpendicular to the tilt, so it never meets a box edge
    const double a = p.tilt_deg * deg;
    const gp_Dir dir(0, -std::sin(a), std::cos(a));
    const double half = 3.0;  // longer than the block at any tilt up to 25 degrees
    const gp_Pnt base(0 - half * dir.X(), 0 - half * dir.Y(), 1 - half * dir.Z());
    TopoDS_Shape cyl =
        BRepPrimAPI_MakeCylinder(gp_Ax2(base, dir, gp_Dir(1, 0, 0)), p.radius, 2 * half).Shape();
    return cut(box, cyl, "bore");
}

TopoDS_Shape make_pipe(double t)
{
    cm_model_pipe p;
    cm_model_pipe_at(t, &p);
    // The bend is a torus segment (BRepMesh triangulates a true torus well; a revolved disc
    // becomes a surface of revolution that it meshes with needle triangles). Every seam
    // lies on the outside of the bend (-y at the inlet), where the torus has its v = 0.
    const double a = p.bend_deg * deg;
    gp_Circ circle(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0), gp_Dir(0, -1, 0)), p.radius);
    TopoDS_Wire w = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire();
    TopoDS_Face disc = BRepBuilderAPI_MakeFace(w, true).Face();
    BRepPrimAPI_MakePrism inlet(disc, gp_Vec(p.inlet, 0, 0));
    TopoDS_Shape bend = BRepPrimAPI_MakeTorus(
        gp_Ax2(gp_Pnt(p.inlet, p.bend_radius, 0), gp_Dir(0, 0, 1), gp_Dir(0, -1, 0)),
        p.bend_radius, p.radius, a).Shape();
    // the outlet starts where the bend ends: the inlet's end disc turned by a about the bend axis
    gp_Trsf turn;
    turn.SetRotation(gp_Ax1(gp_Pnt(p.inlet, p.bend_radius, 0), gp_Dir(0, 0, 1)), a);
    TopoDS_Shape bend_end = BRepBuilderAPI_Transform(inlet.LastShape(), turn, true).Shape();
    BRepPrimAPI_MakePrism outlet(bend_end,
                                 gp_Vec(p.outlet * std::cos(a), p.outlet * std::sin(a), 0));

    TopTools_ListOfShape args, tools;
    args.Append(inlet.Shape());
    tools.Append(bend);
    tools.Append(outlet.Shape());
    BRepAlgoAPI_Fuse fuse;
    fuse.SetArguments(args);
    fuse.SetTools(tools);
    fuse.Build();
    if (!fuse.IsDone() || fuse.HasErrors()) throw std::runtime_error("pipe: fuse failed");
    return only_solid(fuse.Shape(), "pipe");
}

TopoDS_Shape make_bracket(double t)
{
    cm_model_bracket p;
    cm_model_bracket_at(t, &p);
    const double L = p.leg, w = p.width, r = p.fillet;
    // the L profile, counter-clockwise from the outer corner; the fillet is an arc of the
    // profile (the same surface BRepFilletAPI would put on the inner vertical edge)
    gp_Pnt q[6] = {gp_Pnt(0, 0, 0), gp_Pnt(L, 0, 0), gp_Pnt(L, w, 0),
                   gp_Pnt(w + r, w, 0), gp_Pnt(w, w + r, 0), gp_Pnt(w, L, 0)};
    const double c = std::sqrt(0.5);
    gp_Pnt mid(w + r - r * c, w + r - r * c, 0);
    BRepBuilderAPI_MakeWire wire;
    wire.Add(BRepBuilderAPI_MakeEdge(q[0], q[1]).Edge());
    wire.Add(BRepBuilderAPI_MakeEdge(q[1], q[2]).Edge());
    wire.Add(BRepBuilderAPI_MakeEdge(q[2], q[3]).Edge());
    wire.Add(BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(q[3], mid, q[4]).Value()).Edge());
    wire.Add(BRepBuilderAPI_MakeEdge(q[4], q[5]).Edge());
    wire.Add(BRepBuilderAPI_MakeEdge(q[5], gp_Pnt(0, L, 0)).Edge());
    wire.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(0, L, 0), q[0]).Edge());
    if (!wire.IsDone()) throw std::runtime_error("bracket: profile wire failed");
    TopoDS_Face face = BRepBuilderAPI_MakeFace(wire.Wire(), true).Face();
    TopoDS_Shape body = BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, p.height)).Shape();

    const double zc = 0.5 * p.height;
    TopoDS_Shape hole1 = BRepPrimAPI_MakeCylinder(
        gp_Ax2(gp_Pnt(p.hole1_x, -1, zc), gp_Dir(0, 1, 0), gp_Dir(0, 0, 1)), p.hole_radius, w + 2).Shape();
    TopoDS_Shape hole2 = BRepPrimAPI_MakeCylinder(
        gp_Ax2(gp_Pnt(-1, p.hole2_y, zc), gp_Dir(1, 0, 0), gp_Dir(0, 0, 1)), p.hole_radius, w + 2).Shape();
    return cut(cut(body, hole1, "bracket hole 1"), hole2, "bracket hole 2");
}

// CM_ERR_ARGUMENT for what the caller got wrong, before any OpenCASCADE work.
cm_status check(cm_context *ctx, const char *fn, const char *model, double t)
{
    if (!model) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL model", fn);
    if (!cm_model_known(model))
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: unknown model '%s' (%s)", fn, model,
                        cm_model_list());
    if (!(t >= 0 && t <= 1))
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: t must lie in [0, 1], got %g", fn, t);
    return CM_OK;
}

TopoDS_Shape make(const char *model, double t)
{
    if (!std::strcmp(model, "bore")) return make_bore(t);
    if (!std::strcmp(model, "pipe")) return make_pipe(t);
    return make_bracket(t);
}

void quiet_occ()
{
    // STEP writing talks to the default messenger's stdout printer
    Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
}

}  // namespace

extern "C" cm_status cm_model_write_step(cm_context *ctx, const char *model, double t,
                                         const char *path)
{
    static const char *fn = "cm_model_write_step";
    cm_status st = check(ctx, fn, model, t);
    if (st < 0) return st;
    if (!path) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL path", fn);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        TopoDS_Shape s;
        try {
            s = make(model, t);
        } catch (const std::runtime_error &e) { // a boolean that did not give one solid
            return cm_error(ctx, CM_ERR_CAD, "%s: %s at t = %g: %s", fn, model, t, e.what());
        }
        std::lock_guard<std::mutex> g(cmcad::xstep_lock());
        quiet_occ();
        // the shape is in mm whatever unit the last read or write left as the session's
        Interface_Static::SetCVal("xstep.cascade.unit", "MM");
        Interface_Static::SetCVal("write.step.unit", "MM");
        STEPControl_Writer writer;
        if (writer.Transfer(s, STEPControl_AsIs) != IFSelect_RetDone)
            return cm_error(ctx, CM_ERR_CAD, "%s: %s at t = %g: STEP transfer failed", fn, model, t);
        if (writer.Write(path) != IFSelect_RetDone)
            return cm_error(ctx, CM_ERR_IO, "%s: cannot write %s", fn, path);
        return CM_OK;
    });
}

extern "C" cm_status cm_model_signature(cm_context *ctx, const char *model, double t, char *buf,
                                        size_t size, double *volume)
{
    static const char *fn = "cm_model_signature";
    cm_status st = check(ctx, fn, model, t);
    if (st < 0) return st;
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        TopoDS_Shape s;
        try {
            s = make(model, t);
        } catch (const std::runtime_error &e) {
            return cm_error(ctx, CM_ERR_CAD, "%s: %s at t = %g: %s", fn, model, t, e.what());
        }
        TopTools_IndexedMapOfShape solids, faces, edges, vertices;
        TopExp::MapShapes(s, TopAbs_SOLID, solids);
        TopExp::MapShapes(s, TopAbs_FACE, faces);
        TopExp::MapShapes(s, TopAbs_EDGE, edges);
        TopExp::MapShapes(s, TopAbs_VERTEX, vertices);
        std::string out = "solids " + std::to_string(solids.Extent()) + " faces " +
                          std::to_string(faces.Extent()) + " edges " + std::to_string(edges.Extent()) +
                          " vertices " + std::to_string(vertices.Extent()) + "\n";
        for (int i = 1; i <= faces.Extent(); ++i) {
            const TopoDS_Face &f = TopoDS::Face(faces(i));
            out += "face " + std::to_string(i - 1) + " " +
                   std::to_string((int)BRepAdaptor_Surface(f).GetType()) + " " +
                   (f.Orientation() == TopAbs_REVERSED ? "R" : "F") + ":";
            for (TopExp_Explorer ex(f, TopAbs_EDGE); ex.More(); ex.Next())
                out += " " + std::to_string(edges.FindIndex(ex.Current()) - 1) +
                       (ex.Current().Orientation() == TopAbs_REVERSED ? "r" : "f");
            out += "\n";
        }
        for (int i = 1; i <= edges.Extent(); ++i) {
            const TopoDS_Edge &e = TopoDS::Edge(edges(i));
            const int type = BRep_Tool::Degenerated(e) ? -1 : (int)BRepAdaptor_Curve(e).GetType();
            out += "edge " + std::to_string(i - 1) + " " + std::to_string(type) + ": " +
                   std::to_string(vertices.FindIndex(TopExp::FirstVertex(e)) - 1) + " " +
                   std::to_string(vertices.FindIndex(TopExp::LastVertex(e)) - 1) + "\n";
        }
        if (volume) {
            GProp_GProps props;
            BRepGProp::VolumeProperties(s, props);
            *volume = props.Mass();
        }
        if (buf && size > 0) std::snprintf(buf, size, "%s", out.c_str());
        return CM_OK;
    });
}
