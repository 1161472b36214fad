// Writes the STEP pairs G0, G1 = A G0 + b of the affine tests (test_affine.c) into OUT/affine:
// G0 = the built-in bore and bracket at t = 0 (cm_model_write_step) and the gmsh-written
// hole_a and bore_a of DATA; G1 = G0 transformed with OpenCASCADE, <part>_<map>.step.
//   gen_affine DATA OUT
// rigid and scale go through BRepBuilderAPI_Transform (surface types kept), general through
// BRepBuilderAPI_GTransform (non-uniform scale and shear: planes and cylinders become
// B-splines), as a user of OpenCASCADE would edit a part. The map is in affine_maps.h.
#include "affine_maps.h"
#include "cadmorph/models.h"

#include <BRepBuilderAPI_GTransform.hxx>
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
    const std::string parts[4][2] = {{out + "/bore.step", "bore"},
                                     {out + "/bracket.step", "bracket"},
                                     {data + "/surface/hole_a.step", "hole_a"},
                                     {data + "/cad/bore_a.step", "bore_a"}};
    for (int i = 2; i < 4; ++i) { // the gmsh-written G0 next to its images
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
