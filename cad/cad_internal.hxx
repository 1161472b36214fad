// Shared by the C++ bridge files of cad/: the model behind the opaque cm_cad_model, and the
// guard that turns every C++/OpenCASCADE exception into a cm_status (STYLE rule 8).
#ifndef CADMORPH_CAD_INTERNAL_HXX
#define CADMORPH_CAD_INTERNAL_HXX

#include "cadmorph/cad.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <gp_Pnt.hxx>
#include <Standard_Failure.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <vector>

struct cm_cad_model {
    TopoDS_Shape shape;
    // OpenCASCADE's maps are 1-based; the API is 0-based: face i is faces(i + 1).
    TopTools_IndexedMapOfShape faces, edges, vertices;
    cm_cad_counts counts{};
    std::string file_unit, unit;
    std::string path;  // as given to cm_cad_read, for messages
    double bbox[6]{};
    std::vector<cm_cad_face_info> face_info;
    std::vector<cm_cad_edge_info> edge_info;
    std::vector<double> vertex_xyz;            // #vertices x 3
    std::vector<int> face_wire_offset;         // #faces + 1 into wire_offset
    std::vector<int> wire_offset;              // #wires + 1 into wire_edge / wire_rev
    std::vector<int> wire_edge, wire_rev;      // oriented edges of all wires
    std::vector<int> edge_face_offset, edge_face;  // edge -> adjacent faces
    // For the correspondence of G and G' (correspond.cpp): a point of each entity (face centre
    // of mass, edge mid-parameter point) and the shell of each face, the solid of each shell
    // (-1 if none).
    std::vector<double> face_center, edge_mid;     // #faces x 3, #edges x 3
    std::vector<int> face_shell, shell_solid;

    TopoDS_Face face(int i) const { return TopoDS::Face(faces(i + 1)); }
    TopoDS_Edge edge(int i) const { return TopoDS::Edge(edges(i + 1)); }
};

namespace cmcad {

// OpenCASCADE's STEP translators read process-wide settings (Interface_Static: the session's
// length unit, the unit written): every reader and writer sets the ones it uses under this
// lock, so that no call sees another's (a model written after a read in metres is not scaled).
std::mutex &xstep_lock();

// Runs body() and maps exceptions to a status with the function name in the message.
template <class F> cm_status guard(cm_context *ctx, const char *fn, F &&body) noexcept
{
    try {
        return body();
    } catch (const Standard_Failure &e) {
        return cm_error(ctx, CM_ERR_CAD, "%s: OpenCASCADE %s: %s", fn, e.DynamicType()->Name(),
                        e.GetMessageString());
    } catch (const std::bad_alloc &) {
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", fn);
    } catch (const std::exception &e) {
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: %s", fn, e.what());
    } catch (...) {
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: unknown exception", fn);
    }
}

// First error raised inside an OpenMP region (exceptions must not leave the region).
struct region_error {
    std::mutex lock;
    cm_status status = CM_OK;
    std::string message;
    void set(cm_status s, const std::string &m)
    {
        std::lock_guard<std::mutex> g(lock);
        if (status == CM_OK) status = s, message = m;
    }
    // Catches inside a loop body: use as  try { ... } catch (...) { err.capture(); }
    void capture() noexcept
    {
        try {
            throw;
        } catch (const Standard_Failure &e) {
            set(CM_ERR_CAD, std::string("OpenCASCADE: ") + e.GetMessageString());
        } catch (const std::bad_alloc &) {
            set(CM_ERR_NOMEM, "out of memory");
        } catch (const std::exception &e) {
            set(CM_ERR_INTERNAL, e.what());
        } catch (...) {
            set(CM_ERR_INTERNAL, "unknown exception");
        }
    }
    cm_status report(cm_context *ctx, const char *fn) const
    {
        if (status == CM_OK) return CM_OK;
        return cm_error(ctx, status, "%s: %s", fn, message.c_str());
    }
};

cm_status check_face(cm_context *ctx, const cm_cad_model *m, int face, const char *fn);
cm_status check_edge(cm_context *ctx, const cm_cad_model *m, int edge, const char *fn);

// Adaptors and trimming classifiers are not thread-safe (B-spline caches; concurrent
// BRepTopAdaptor_FClass2d::Perform calls crash in OCCT 7.6): each thread keeps its own, made
// lazily.
struct adaptors {
    explicit adaptors(const cm_cad_model *m) noexcept;
    ~adaptors();
    BRepAdaptor_Surface &surface(int face);
    BRepAdaptor_Curve &curve(int edge);  // not for degenerate edges
    BRepTopAdaptor_FClass2d &classifier(int face);
    const cm_cad_model *model;
    std::vector<BRepAdaptor_Surface *> s;
    std::vector<BRepAdaptor_Curve *> c;
    std::vector<BRepTopAdaptor_FClass2d *> k;
};

struct foot {
    double u = 0, v = 0, t = 0, dist = 0;
    gp_Pnt p;
    int edge = -1;  // face projection: the boundary edge the foot lies on, or -1
};

// Newton projection of p onto face's surface from (u0, v0), kept in the trimmed domain: a
// foot outside it (or on the border of the parameter box) is compared with the nearest
// point on the face's boundary edges.
void project_on_face(adaptors &a, int face, const gp_Pnt &p, double u0, double v0, foot &out);
// Projection onto an edge: Newton from t0, or a global search when t0 is NaN. Returns the
// distance; t and q receive parameter and foot.
double project_on_edge(adaptors &a, int edge, const gp_Pnt &p, double t0, double &t, gp_Pnt &q);
// A start value for a face without one: the best point of a coarse grid inside the face.
void seed_on_face(adaptors &a, int face, const gp_Pnt &p, double &u, double &v);
// 1 if (u, v) is in the trimmed domain of face (or on its boundary).
bool inside_face(adaptors &a, int face, double u, double v);

// Trimming test along a row of the sampling grid (cad/scanline.cpp): the pcurves of a face
// as a polyline, seg = x0 y0 x1 y1 per segment, within delta of the pcurves; ok = false
// when the face is classified point by point.
struct scanline {
    bool ok = false;
    double delta = 0;
    std::vector<double> seg;
};
void scanline_build(const cm_cad_model *m, int face, scanline &s);
// inside[i] for the candidates u_i = lo + (hi - lo) (i + 0.5) / nu on row v: as
// inside_face, which decides those within delta of the polyline.
void scanline_row(adaptors &a, int face, const scanline &s, double v, double lo, double hi,
                  int nu, char *inside);

}  // namespace cmcad

#endif
