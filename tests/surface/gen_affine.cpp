// Writes the STEP pairs G0, G1 = A G0 + b of the affine tests (test_affine.c) into OUT/affine:
// G0 = the built-in bore and bracket at t = 0 (cm_model_write_step), the gmsh-written hole_a
// and bore_a of DATA, the FreeCAD-written shaft_0 and OpenCASCADE's screw of DATA, and a
// turned part made here (a cylinder with a cone end and a cross bore: its vertices all lie in
// one plane, so they alone cannot determine a 3-D map); G1 = G0 transformed with OpenCASCADE, <part>_<map>.step. Also
// turned_bore.step: the turned part with a wider bore, an edit that is not affine.
//   gen_affine DATA OUT
// rigid and scale go through BRepBuilderAPI_Transform (surface types kept), general through
// BRepBuilderAPI_GTransform (non-uniform scale and shear: planes and cylinders become
// B-splines), as a user of OpenCASCADE would edit a part. The map is in affine_maps.h.
#include "affine_maps.h"
#include "cadmorph/models.h"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_GTransform.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <gp_GTrsf.hxx>
#include <gp_Mat.hxx>
#include <gp_Trsf.hxx>

#include <cstdio>
#include <cerrno>
#include <sys/stat.h>
#include <cstring>
#include <fstream>
#include <string>

static bool write_step(const TopoDS_Shape &s, const std::string &path)
{
    Interface_Static::SetCVal("write.step.unit", "MM");
    Interface_Static::SetCVal("write.step.schema", "AP214IS");
    STEPControl_Writer w;
    return w.Transfer(s, STEPControl_AsIs) == IFSelect_RetDone &&
           w.Write(path.c_str()) == IFSelect_RetDone;
}

// A turned part: a cylinder (radius 1.5, length 5 along z) with a truncated cone end (to
// radius 0.6 over 2) and a cross bore of radius bore_r along x at z = 2.5. Every seam and
// vertex lies in the plane y = 0: a revolved part whose vertices are coplanar.
static TopoDS_Shape turned_part(double bore_r)
{
    gp_Ax2 axis(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1));
    TopoDS_Shape body = BRepPrimAPI_MakeCylinder(axis, 1.5, 5.0).Shape();
    TopoDS_Shape cone =
        BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(0, 0, 5), gp_Dir(0, 0, 1)), 1.5, 0.6, 2.0).Shape();
    BRepAlgoAPI_Fuse fuse(body, cone);
    fuse.SimplifyResult();
    TopoDS_Shape bore =
        BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(-3, 0, 2.5), gp_Dir(1, 0, 0)), bore_r, 6.0).Shape();
    BRepAlgoAPI_Cut cut(fuse.Shape(), bore);
    cut.SimplifyResult();
    return cut.Shape();
}

static int transform(const char *in, const char *outpath, const char *kind)
{
    double m[3][4];
    if (!cm_affine_map(kind, m)) return 1;
    try {
        Message::DefaultMessenger()->ChangePrinters().Clear();
        Interface_Static::SetCVal("xstep.cascade.unit", "MM");
        STEPControl_Reader reader;
        if (reader.ReadFile(in) != IFSelect_RetDone || reader.TransferRoots() == 0) {
            fprintf(stderr, "gen_affine: cannot read %s\n", in);
            return 1;
        }
        TopoDS_Shape s = reader.OneShape(), out;
        if (kind[0] == 'g') {
            gp_GTrsf g;
            g.SetVectorialPart(gp_Mat(m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2],
                                      m[2][0], m[2][1], m[2][2]));
            g.SetTranslationPart(gp_XYZ(m[0][3], m[1][3], m[2][3]));
            BRepBuilderAPI_GTransform t(s, g, true);
            out = t.Shape();
        } else {
            gp_Trsf t;
            t.SetValues(m[0][0], m[0][1], m[0][2], m[0][3], m[1][0], m[1][1], m[1][2], m[1][3],
                        m[2][0], m[2][1], m[2][2], m[2][3]);
            BRepBuilderAPI_Transform bt(s, t, true);
            out = bt.Shape();
        }
        Interface_Static::SetCVal("write.step.unit", "MM");
        Interface_Static::SetCVal("write.step.schema", "AP214IS");
        STEPControl_Writer w;
        if (w.Transfer(out, STEPControl_AsIs) != IFSelect_RetDone ||
            w.Write(outpath) != IFSelect_RetDone) {
            fprintf(stderr, "gen_affine: cannot write %s\n", outpath);
            return 1;
        }
    } catch (const Standard_Failure &e) {
        fprintf(stderr, "gen_affine: OpenCASCADE: %s\n", e.GetMessageString());
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: gen_affine DATA OUT\n");
        return 1;
    }
    std::string data = argv[1], out = std::string(argv[2]) + "/affine";
    if (mkdir(out.c_str(), 0777) != 0 && errno != EEXIST) return 1;
    cm_context *ctx = nullptr;
    if (cm_context_create(&ctx) != CM_OK) return 1;
    int bad = 0;
    for (const char *model : {"bore", "bracket"}) {
        std::string p = out + "/" + model + ".step";
        if (cm_model_write_step(ctx, model, 0.0, p.c_str()) != CM_OK) {
            fprintf(stderr, "gen_affine: %s\n", cm_context_message(ctx));
            bad = 1;
        }
    }
    cm_context_destroy(&ctx);
    try {
        Message::DefaultMessenger()->ChangePrinters().Clear();
        if (!write_step(turned_part(0.5), out + "/turned.step") ||
            !write_step(turned_part(0.65), out + "/turned_bore.step")) {
            fprintf(stderr, "gen_affine: cannot write the turned part\n");
            bad = 1;
        }
    } catch (const Standard_Failure &e) {
        fprintf(stderr, "gen_affine: OpenCASCADE: %s\n", e.GetMessageString());
        bad = 1;
    }
    const std::string parts[7][2] = {{out + "/bore.step", "bore"},
                                     {out + "/bracket.step", "bracket"},
                                     {out + "/turned.step", "turned"},
                                     {data + "/surface/hole_a.step", "hole_a"},
                                     {data + "/cad/bore_a.step", "bore_a"},
                                     {data + "/freecad/shaft_0.step", "shaft"},
                                     {data + "/occt/screw.step", "screw"}};
    for (int i = 3; i < 7; ++i) { // the files written elsewhere next to their images
        std::ifstream in(parts[i][0], std::ios::binary);
        std::ofstream o(out + "/" + parts[i][1] + ".step", std::ios::binary);
        o << in.rdbuf();
        if (!in || !o) {
            fprintf(stderr, "gen_affine: cannot copy %s\n", parts[i][0].c_str());
            bad = 1;
        }
    }
    for (const auto &part : parts)
        for (const char *kind : {"rigid", "scale", "general"}) {
            std::string o = out + "/" + part[1] + "_" + kind + ".step";
            if (transform(part[0].c_str(), o.c_str(), kind) != 0) {
                fprintf(stderr, "gen_affine: %s %s failed\n", part[1].c_str(), kind);
                bad = 1;
            }
        }
    return bad;
}
