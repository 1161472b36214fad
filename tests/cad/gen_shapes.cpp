// Test generator: builds shapes with OpenCASCADE, writes them as STEP into the work dir, and
// writes points near each shape with their expected projection (built as P = S(u,v) + d N
// with N the outward normal, so the foot point, (u,v) and distance are known by construction).
// Also writes the bad inputs the CLI must refuse. The assertions live in the C tests.
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBuilderAPI_GTransform.hxx>
#include <BRepBuilderAPI_MakeSolid.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <Geom_Plane.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <gp_Circ.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRep_Tool.hxx>
#include <ShapeCustom.hxx>
#include <ShapeFix_Face.hxx>
#include <ShapeFix_Solid.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <GeomAPI_PointsToBSpline.hxx>
#include <Geom_BSplineCurve.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Vertex.hxx>
#include <gp_GTrsf.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <GeomAPI_PointsToBSplineSurface.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Shell.hxx>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

static bool write_step(const TopoDS_Shape &s, const std::string &path)
{
    STEPControl_Writer w;
    if (w.Transfer(s, STEPControl_AsIs) != IFSelect_RetDone) return false;
    return w.Write(path.c_str()) == IFSelect_RetDone;
}

// n points: random face (by area share ~ equal per face), random (u,v) inside its trimming,
// offset d in [0, dmax] along the outward normal (both signs if two_sided).
static bool write_points(const TopoDS_Shape &s, const std::string &path, int n, double dmax,
                         bool two_sided, unsigned seed)
{
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(s, TopAbs_FACE, faces);
    FILE *f = fopen(path.c_str(), "w");
    if (!f) return false;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    fprintf(f, "# x y z face u v dist fx fy fz\n");
    for (int i = 0; i < n;) {
        int k = (int)(U(rng) * faces.Extent());
        TopoDS_Face face = TopoDS::Face(faces(k + 1));
        double u0, u1, v0, v1;
        BRepTools::UVBounds(face, u0, u1, v0, v1);
        double u = u0 + (u1 - u0) * U(rng), v = v0 + (v1 - v0) * U(rng);
        BRepClass_FaceClassifier cl(face, gp_Pnt2d(u, v), 1e-9);
        if (cl.State() != TopAbs_IN) continue;
        BRepAdaptor_Surface S(face);
        gp_Pnt p;
        gp_Vec du, dv;
        S.D1(u, v, p, du, dv);
        gp_Vec nrm = du.Crossed(dv);
        if (nrm.Magnitude() < 1e-6) continue;  // near a pole the normal is ill-defined
        nrm.Normalize();
        if (face.Orientation() == TopAbs_REVERSED) nrm.Reverse();
        // a tenth of the points lie on the surface, as mesh nodes do
        double d = (i % 10 == 0) ? 0.0 : dmax * U(rng);
        if (two_sided && U(rng) < 0.5) d = -d;
        gp_Pnt q = p.Translated(nrm * d);
        fprintf(f, "%.17g %.17g %.17g %d %.17g %.17g %.17g %.17g %.17g %.17g\n", q.X(), q.Y(),
                q.Z(), k, u, v, std::fabs(d), p.X(), p.Y(), p.Z());
        ++i;
    }
    return fclose(f) == 0;
}

// The correspondence pairs (test_cad_correspond): a part with planes, a bore (cylinder) and a
// toroidal groove, then the same part after edits and re-exports that keep its topology.
static TopoDS_Shape grooved_part(bool extra_hole)
{
    TopoDS_Shape block = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 10, 8, 4).Shape();
    TopoDS_Shape bore =
        BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(5, 4, -1), gp_Dir(0, 0, 1)), 1.5, 6).Shape();
    TopoDS_Shape groove =
        BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(5, 4, 4), gp_Dir(0, 0, 1)), 2.7, 0.6).Shape();
    TopoDS_Shape part = BRepAlgoAPI_Cut(BRepAlgoAPI_Cut(block, bore).Shape(), groove).Shape();
    if (extra_hole) {
        TopoDS_Shape hole =
            BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1.5, 1.5, -1), gp_Dir(0, 0, 1)), 0.5, 6).Shape();
        part = BRepAlgoAPI_Cut(part, hole).Shape();
    }
    return part;
}

// A plate with a row of n equal holes, stretched by sx about its centre: in G' (sx = 2.5) the
// outer holes are nearer to other holes of G than to their own, and only the numbering
// (kept by the edit) places them.
static TopoDS_Shape hole_row(int n, double sx)
{
    TopoDS_Shape s = BRepPrimAPI_MakeBox(gp_Pnt(5.0 * n * (1 - sx), 0, 0), 10.0 * n * sx, 10, 4).Shape();
    for (int i = 0; i < n; ++i) {
        gp_Pnt c(5.0 * n + (5 + 10 * i - 5.0 * n) * sx, 5, -1);
        s = BRepAlgoAPI_Cut(s, BRepPrimAPI_MakeCylinder(gp_Ax2(c, gp_Dir(0, 0, 1)), 2, 6).Shape()).Shape();
    }
    return s;
}

// Non-uniform scale and shear (planes, cylinders and tori become B-splines).
static TopoDS_Shape gtransformed(const TopoDS_Shape &s)
{
    gp_GTrsf t;
    t.SetValue(1, 1, 1.3), t.SetValue(1, 2, 0.2), t.SetValue(1, 3, 0.1);
    t.SetValue(2, 1, 0.0), t.SetValue(2, 2, 0.8), t.SetValue(2, 3, 0.15);
    t.SetValue(3, 1, 0.05), t.SetValue(3, 2, 0.0), t.SetValue(3, 3, 1.1);
    t.SetTranslationPart(gp_XYZ(0.5, -0.3, 0.2));
    return BRepBuilderAPI_GTransform(s, t, true).Shape();
}

// The same solid with its faces in another order and its edges rebuilt by sewing: faces,
// edges and vertices are numbered otherwise, edges may run the other way.
static TopoDS_Shape renumbered(const TopoDS_Shape &s, unsigned seed)
{
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(s, TopAbs_FACE, faces);
    std::vector<int> order(faces.Extent());
    for (int i = 0; i < faces.Extent(); ++i) order[i] = i + 1;
    std::mt19937 rng(seed);
    std::shuffle(order.begin(), order.end(), rng);
    BRepBuilderAPI_Sewing sew(1e-6);
    for (int i : order) sew.Add(BRepBuilderAPI_Copy(faces(i)).Shape());
    sew.Perform();
    TopoDS_Shape shell = sew.SewedShape();
    TopoDS_Shell sh;
    for (TopExp_Explorer x(shell, TopAbs_SHELL); x.More(); x.Next()) sh = TopoDS::Shell(x.Current());
    BRepBuilderAPI_MakeSolid ms(sh);
    ShapeFix_Solid fix(ms.Solid());
    fix.Perform();
    return fix.Solid();
}

// A polyhedron rebuilt from its faces' corner points, polygon by polygon in a shuffled order
// and sewn: every edge is made anew along the first face that uses it, so some run against
// the original's.
static TopoDS_Shape rebuilt_polyhedron(const TopoDS_Shape &s, unsigned seed)
{
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(s, TopAbs_FACE, faces);
    std::vector<int> order(faces.Extent());
    for (int i = 0; i < faces.Extent(); ++i) order[i] = i + 1;
    std::mt19937 rng(seed);
    std::shuffle(order.begin(), order.end(), rng);
    BRepBuilderAPI_Sewing sew(1e-6);
    for (int i : order) {
        TopoDS_Face f = TopoDS::Face(faces(i));
        BRepBuilderAPI_MakePolygon poly;
        std::vector<gp_Pnt> pts;
        for (BRepTools_WireExplorer e(BRepTools::OuterWire(f), f); e.More(); e.Next())
            pts.push_back(BRep_Tool::Pnt(e.CurrentVertex()));
        // start the polygon elsewhere than the original wire
        std::rotate(pts.begin(), pts.begin() + (i % pts.size()), pts.end());
        for (const gp_Pnt &p : pts) poly.Add(p);
        poly.Close();
        sew.Add(BRepBuilderAPI_MakeFace(poly.Wire(), true).Face());
    }
    sew.Perform();
    TopoDS_Shell sh;
    for (TopExp_Explorer x(sew.SewedShape(), TopAbs_SHELL); x.More(); x.Next())
        sh = TopoDS::Shell(x.Current());
    ShapeFix_Solid fix(BRepBuilderAPI_MakeSolid(sh).Solid());
    fix.Perform();
    return fix.Solid();
}

// A B-spline face bounded by curves that lie 2e-5 off its surface, pcurves by projection (as
// OpenCASCADE builds them for industrial STEP files without pcurves): the face's boundary is
// only known to the edges' tolerance.
static TopoDS_Shape loose_bspline_face(const Handle(Geom_BSplineSurface) & bs)
{
    double u0, u1, v0, v1;
    bs->Bounds(u0, u1, v0, v1);
    const double du = 0.1 * (u1 - u0), dv = 0.1 * (v1 - v0);
    // a rectangle inside the surface's box, in uv, run counter-clockwise
    const double cu[5] = {u0 + du, u1 - du, u1 - du, u0 + du, u0 + du};
    const double cv[5] = {v0 + dv, v0 + dv, v1 - dv, v1 - dv, v0 + dv};
    BRepBuilderAPI_MakeWire mw;
    std::vector<TopoDS_Vertex> corner;
    for (int k = 0; k < 4; ++k)
        corner.push_back(BRepBuilderAPI_MakeVertex(bs->Value(cu[k], cv[k]).Translated(gp_Vec(0, 0, 2e-5))));
    for (int k = 0; k < 4; ++k) {
        TColgp_Array1OfPnt pts(1, 12);
        for (int i = 1; i <= 12; ++i) {
            double a = (i - 1) / 11.0;
            gp_Pnt p = bs->Value(cu[k] + a * (cu[k + 1] - cu[k]), cv[k] + a * (cv[k + 1] - cv[k]));
            pts(i) = p.Translated(gp_Vec(0, 0, 2e-5));
        }
        Handle(Geom_BSplineCurve) c = GeomAPI_PointsToBSpline(pts, 3, 8, GeomAbs_C2, 1e-9).Curve();
        mw.Add(BRepBuilderAPI_MakeEdge(c, corner[k], corner[(k + 1) % 4]).Edge());
    }
    TopoDS_Face f = BRepBuilderAPI_MakeFace(bs, mw.Wire(), true).Face();
    ShapeFix_Face fix(f);
    fix.Perform();
    TopoDS_Shell shell;
    BRep_Builder bb;
    bb.MakeShell(shell);
    bb.Add(shell, fix.Face());
    return shell;
}

// A spindle torus (minor radius 2 > major radius 1) closed by the plane z = -1.2: the
// apple-shaped outer part of the torus (v from -asin 0.6 to 2 pi / 3, where it meets the
// axis), sewn to a disc.
static TopoDS_Shape spindle_part()
{
    Handle(Geom_ToroidalSurface) t = new Geom_ToroidalSurface(gp_Ax3(gp::Origin(), gp::DZ()), 1.0, 2.0);
    TopoDS_Face side = BRepBuilderAPI_MakeFace(t, 0, 2 * M_PI, -std::asin(0.6), 2 * M_PI / 3, 1e-7).Face();
    Handle(Geom_Plane) pl = new Geom_Plane(gp_Ax3(gp_Pnt(0, 0, -1.2), gp::DZ()));
    TopoDS_Edge rim = BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, -1.2), gp::DZ()), 2.6)).Edge();
    TopoDS_Face disc = BRepBuilderAPI_MakeFace(pl, BRepBuilderAPI_MakeWire(rim).Wire()).Face();
    BRepBuilderAPI_Sewing sew(1e-6);
    sew.Add(side);
    sew.Add(disc);
    sew.Perform();
    TopoDS_Shell sh;
    for (TopExp_Explorer x(sew.SewedShape(), TopAbs_SHELL); x.More(); x.Next())
        sh = TopoDS::Shell(x.Current());
    ShapeFix_Solid fix(BRepBuilderAPI_MakeSolid(sh).Solid());
    fix.Perform();
    return fix.Solid();
}

// Assemblies for cm_cad_check_solids_apart (separate solids in one compound, not fused):
// two unit boxes sharing the face x = 1 and a cylinder standing on part of the first box's
// top (touching), two boxes that cross (overlap), a box inside another (nested).
static bool write_assemblies(const std::string &dir)
{
    auto compound = [](std::initializer_list<TopoDS_Shape> parts) {
        TopoDS_Compound c;
        BRep_Builder b;
        b.MakeCompound(c);
        for (const TopoDS_Shape &p : parts) b.Add(c, p);
        return c;
    };
    const TopoDS_Shape a = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 1, 1, 1).Shape();
    const TopoDS_Shape b = BRepPrimAPI_MakeBox(gp_Pnt(1, 0, 0), 1, 1, 1).Shape();
    const TopoDS_Shape c =
        BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0.5, 0.5, 1), gp_Dir(0, 0, 1)), 0.3, 0.5).Shape();
    const TopoDS_Shape x = BRepPrimAPI_MakeBox(gp_Pnt(0.5, 0.2, 0.2), 1, 1, 1).Shape();
    const TopoDS_Shape big = BRepPrimAPI_MakeBox(gp_Pnt(-1, -1, -1), 3, 3, 3).Shape();
    return write_step(compound({a, b, c}), dir + "/asm_touch.step") &&
           write_step(compound({a, x}), dir + "/asm_overlap.step") &&
           write_step(compound({big, a}), dir + "/asm_nested.step");
}

// A box whose vertices sit 3e-4 to 5e-4 off the corners where its edge lines meet, edges and
// vertices of tolerance 1e-3 (as a CAD system's export leaves them; the STEP reader sets the
// tolerances back from the gaps): a mesher that reads the file by itself (gmsh) puts its corner
// nodes on the vertex points, off our faces by up to the model's tolerance.
static TopoDS_Shape loose_box()
{
    TopoDS_Shape box = BRepBuilderAPI_Copy(BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 3, 4, 2).Shape()).Shape();
    BRep_Builder b;
    TopTools_IndexedMapOfShape vs, es;
    TopExp::MapShapes(box, TopAbs_VERTEX, vs);
    TopExp::MapShapes(box, TopAbs_EDGE, es);
    for (int i = 1; i <= es.Extent(); ++i) b.UpdateEdge(TopoDS::Edge(es(i)), 1e-3);
    for (int i = 1; i <= vs.Extent(); ++i) {
        const TopoDS_Vertex &v = TopoDS::Vertex(vs(i));
        const gp_Pnt p = BRep_Tool::Pnt(v);
        const double d = 3e-4;
        b.UpdateVertex(v, gp_Pnt(p.X() + (i % 2 ? d : -d), p.Y() + (i % 3 ? d : -d), p.Z() + d * ((i % 5) - 2) / 2), 1e-3);
    }
    return box;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: gen_shapes OUTDIR\n");
        return 1;
    }
    Message::DefaultMessenger()->ChangePrinters().Clear();
    Interface_Static::SetCVal("write.step.schema", "AP214IS");
    std::string dir = argv[1];
    try {
        const int n = 10000;
        TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(-1, -2, -0.5), 3, 4, 2).Shape();
        TopoDS_Shape cyl =
            BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(1, 2, 3), gp_Dir(0, 0, 1)), 2, 5).Shape();
        TopoDS_Shape sph = BRepPrimAPI_MakeSphere(gp_Pnt(0.5, -1, 2), 3).Shape();
        TopoDS_Shape tor =
            BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(1, 1, 1), gp_Dir(0, 0, 1)), 5, 1.5).Shape();
        TopoDS_Shape block = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), 10, 8, 4).Shape();
        TopoDS_Shape bore =
            BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(5, 4, -1), gp_Dir(0, 0, 1)), 2, 6).Shape();
        TopoDS_Shape holed = BRepAlgoAPI_Cut(block, bore).Shape();

        TColgp_Array2OfPnt pts(1, 8, 1, 8);
        for (int i = 1; i <= 8; ++i)
            for (int j = 1; j <= 8; ++j) {
                double x = 4.0 * (i - 1) / 7, y = 3.0 * (j - 1) / 7;
                pts(i, j) = gp_Pnt(x, y, 0.3 * std::sin(x) * std::cos(1.3 * y));
            }
        Handle(Geom_BSplineSurface) bs = GeomAPI_PointsToBSplineSurface(pts).Surface();
        TopoDS_Face bface = BRepBuilderAPI_MakeFace(bs, 1e-7).Face();
        TopoDS_Shell shell;
        BRep_Builder bb;
        bb.MakeShell(shell);
        bb.Add(shell, bface);

        struct {
            const char *name;
            TopoDS_Shape s;
            double dmax;
            bool two;
        } shapes[] = {{"box", box, 0.3, false},   {"cylinder", cyl, 0.2, false},
                      {"sphere", sph, 0.3, false}, {"torus", tor, 0.15, false},
                      {"holed", holed, 0.2, false}, {"bspline", shell, 0.05, true}};
        unsigned seed = 1;
        for (auto &s : shapes) {
            std::string base = dir + "/" + s.name;
            if (!write_step(s.s, base + ".step") ||
                !write_points(s.s, base + ".pts", n, s.dmax, s.two, seed++)) {
                fprintf(stderr, "gen_shapes: cannot write %s\n", base.c_str());
                return 1;
            }
        }
        TopoDS_Shape part = grooved_part(false);
        const struct {
            const char *name;
            TopoDS_Shape s;
        } pairs[] = {{"part", part},
                     {"part_hole", grooved_part(true)},
                     {"part_gtrsf", gtransformed(part)},
                     {"part_nurbs", BRepBuilderAPI_NurbsConvert(part, true).Shape()},
                     {"part_renumbered", renumbered(part, 7)},
                     {"part_revolution", ShapeCustom::ConvertToRevolution(part)},
                     {"block", block},
                     {"block_rebuilt", rebuilt_polyhedron(block, 3)},
                     {"spindle", spindle_part()},
                     {"loose_bspline", loose_bspline_face(bs)},
                     {"row_a", hole_row(6, 1.0)},
                     {"row_b", hole_row(6, 2.5)},
                     {"loose_box", loose_box()}};
        for (auto &p : pairs)
            if (!write_step(p.s, dir + "/" + p.name + ".step")) {
                fprintf(stderr, "gen_shapes: cannot write %s\n", p.name);
                return 1;
            }
        if (!write_assemblies(dir)) {
            fprintf(stderr, "gen_shapes: cannot write the assemblies\n");
            return 1;
        }
        // bad inputs: a STEP with only an edge (no solid, shell or face), a text file
        TopoDS_Shape edge = BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(1, 2, 3)).Shape();
        if (!write_step(edge, dir + "/edge_only.step")) return 1;
        FILE *t = fopen((dir + "/not_step.step").c_str(), "w");
        if (!t) return 1;
        fprintf(t, "This is a text file, not a STEP file.\nsolid box\nendsolid\n");
        fclose(t);
    } catch (const Standard_Failure &e) {
        fprintf(stderr, "gen_shapes: OpenCASCADE: %s\n", e.GetMessageString());
        return 1;
    }
    return 0;
}
