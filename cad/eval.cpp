// Evaluation of faces and edges for arrays of parameters, the trimming test, arc length on
// edges (GCPnts_AbscissaPoint) and the face boundaries sampled in (u,v) at equal arc-length
// fractions (paper section 4: the samples c_i, c'_i of the 2D parameter warp).
#include "cad_internal.hxx"

#include <BRep_Tool.hxx>
#include <GCPnts_AbscissaPoint.hxx>
#include <Geom2d_Curve.hxx>
#include <gp_Pnt2d.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace {

// Arc length from the first parameter to t, and its inverse, on a forward edge curve.
double length_to(BRepAdaptor_Curve &C, double t)
{
    double t1 = C.FirstParameter();
    if (t <= t1) return 0.0;
    return GCPnts_AbscissaPoint::Length(C, t1, std::min(t, C.LastParameter()), 1e-12);
}

double param_at(BRepAdaptor_Curve &C, double s, double length)
{
    double t1 = C.FirstParameter(), t2 = C.LastParameter();
    if (s <= 0) return t1;
    if (s >= 1) return t2;
    double guess = t1 + s * (t2 - t1);
    GCPnts_AbscissaPoint ap(1e-12 * std::max(length, 1e-300), C, s * length, t1);
    if (!ap.IsDone()) {
        GCPnts_AbscissaPoint ap2(C, s * length, t1, guess);
        return ap2.IsDone() ? ap2.Parameter() : guess;
    }
    return ap.Parameter();
}

template <class Body>
cm_status parallel_over(cm_context *ctx, const char *fn, const cm_cad_model *m, size_t n,
                        Body body)
{
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        cmcad::region_error err;
#pragma omp parallel num_threads(cm_context_threads_for(ctx, n, 256)) if (n > 256)
        {
            cmcad::adaptors a(m);
#pragma omp for schedule(static)
            for (long i = 0; i < (long)n; ++i) {
                try {
                    body(a, (size_t)i);
                } catch (...) {
                    err.capture();
                }
            }
        }
        return err.report(ctx, fn);
    });
}

}  // namespace

extern "C" {

cm_status cm_cad_face_eval(cm_context *ctx, const cm_cad_model *model, int face, const double *uv,
                           size_t n, double *xyz, double *normal)
{
    const char *fn = "cm_cad_face_eval";
    cm_status st = cmcad::check_face(ctx, model, face, fn);
    if (st != CM_OK) return st;
    if (n && (!uv || !xyz)) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL uv or xyz", fn);
    const bool rev = model->face_info[face].reversed;
    return parallel_over(ctx, fn, model, n, [&](cmcad::adaptors &a, size_t i) {
        gp_Pnt p;
        gp_Vec du, dv;
        a.surface(face).D1(uv[2 * i], uv[2 * i + 1], p, du, dv);
        xyz[3 * i] = p.X(), xyz[3 * i + 1] = p.Y(), xyz[3 * i + 2] = p.Z();
        if (normal) {
            gp_Vec nv = du.Crossed(dv);
            double len = nv.Magnitude();
            if (len > 0) nv /= len;
            if (rev) nv.Reverse();
            normal[3 * i] = nv.X(), normal[3 * i + 1] = nv.Y(), normal[3 * i + 2] = nv.Z();
        }
    });
}

cm_status cm_cad_edge_eval(cm_context *ctx, const cm_cad_model *model, int edge, const double *t,
                           size_t n, double *xyz)
{
    const char *fn = "cm_cad_edge_eval";
    cm_status st = cmcad::check_edge(ctx, model, edge, fn);
    if (st != CM_OK) return st;
    if (n && (!t || !xyz)) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL t or xyz", fn);
    const cm_cad_edge_info &ei = model->edge_info[edge];
    if (ei.degenerate) {
        // a collapsed edge is its vertex for every t
        const double *v = &model->vertex_xyz[3 * (size_t)std::max(ei.vertex[0], 0)];
        for (size_t i = 0; i < n; ++i) std::copy(v, v + 3, xyz + 3 * i);
        return CM_OK;
    }
    return parallel_over(ctx, fn, model, n, [&](cmcad::adaptors &a, size_t i) {
        gp_Pnt p = a.curve(edge).Value(t[i]);
        xyz[3 * i] = p.X(), xyz[3 * i + 1] = p.Y(), xyz[3 * i + 2] = p.Z();
    });
}

cm_status cm_cad_face_inside(cm_context *ctx, const cm_cad_model *model, int face,
                             const double *uv, size_t n, int *inside)
{
    const char *fn = "cm_cad_face_inside";
    cm_status st = cmcad::check_face(ctx, model, face, fn);
    if (st != CM_OK) return st;
    if (n && (!uv || !inside)) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL uv or inside", fn);
    return parallel_over(ctx, fn, model, n, [&](cmcad::adaptors &a, size_t i) {
        inside[i] = cmcad::inside_face(a, face, uv[2 * i], uv[2 * i + 1]);
    });
}

cm_status cm_cad_edge_t_to_s(cm_context *ctx, const cm_cad_model *model, int edge, const double *t,
                             size_t n, double *s)
{
    const char *fn = "cm_cad_edge_t_to_s";
    cm_status st = cmcad::check_edge(ctx, model, edge, fn);
    if (st != CM_OK) return st;
    if (n && (!t || !s)) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL t or s", fn);
    const cm_cad_edge_info &ei = model->edge_info[edge];
    const double t1 = ei.t_range[0], t2 = ei.t_range[1];
    // a flipped edge (cm_cad_match) measures s in its counterpart's direction
    const bool flip = ei.flipped;
    if (ei.degenerate || !(ei.length > 0)) {
        for (size_t i = 0; i < n; ++i) {
            s[i] = std::min(std::max((t[i] - t1) / (t2 - t1), 0.0), 1.0);
            if (flip) s[i] = 1.0 - s[i];
        }
        return CM_OK;
    }
    return parallel_over(ctx, fn, model, n, [&](cmcad::adaptors &a, size_t i) {
        s[i] = std::min(std::max(length_to(a.curve(edge), t[i]) / ei.length, 0.0), 1.0);
        if (flip) s[i] = 1.0 - s[i];
    });
}

cm_status cm_cad_edge_s_to_t(cm_context *ctx, const cm_cad_model *model, int edge, const double *s,
                             size_t n, double *t)
{
    const char *fn = "cm_cad_edge_s_to_t";
    cm_status st = cmcad::check_edge(ctx, model, edge, fn);
    if (st != CM_OK) return st;
    if (n && (!t || !s)) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL t or s", fn);
    const cm_cad_edge_info &ei = model->edge_info[edge];
    const double t1 = ei.t_range[0], t2 = ei.t_range[1];
    const bool flip = ei.flipped;
    if (ei.degenerate || !(ei.length > 0)) {
        for (size_t i = 0; i < n; ++i)
            t[i] = t1 + std::min(std::max(flip ? 1.0 - s[i] : s[i], 0.0), 1.0) * (t2 - t1);
        return CM_OK;
    }
    return parallel_over(ctx, fn, model, n, [&](cmcad::adaptors &a, size_t i) {
        t[i] = param_at(a.curve(edge), flip ? 1.0 - s[i] : s[i], ei.length);
    });
}

void cm_cad_boundary_destroy(cm_cad_boundary **boundary)
{
    if (!boundary || !*boundary) return;
    cm_cad_boundary *b = *boundary;
    free(b->uv), free(b->xyz), free(b->edge), free(b->s), free(b->wire);
    free(b);
    *boundary = nullptr;
}

}  // extern "C"

namespace {

// The samples of cm_cad_face_boundary; at_t (NULL: arc-length fractions) gives the edge
// parameter of each sample instead (NaN: the arc-length one).
cm_status face_boundary(cm_context *ctx, const cm_cad_model *model, int face, const int *per_edge,
                        int count, const double *at_t, cm_cad_boundary **boundary, const char *fn)
{
    if (!boundary) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: boundary is NULL", fn);
    *boundary = nullptr;
    cm_status st = cmcad::check_face(ctx, model, face, fn);
    if (st != CM_OK) return st;
    const int w0 = model->face_wire_offset[face], w1 = model->face_wire_offset[face + 1];
    const int k0 = model->wire_offset[w0], k1 = model->wire_offset[w1];
    size_t n = 0;
    for (int k = k0; k < k1; ++k) {
        int c = per_edge ? per_edge[model->wire_edge[k]] : count;
        if (c < 1)
            return cm_error(ctx, CM_ERR_ARGUMENT, "%s: edge %d: %d samples (need at least 1)", fn,
                            model->wire_edge[k], c);
        n += (size_t)c;
    }
    cm_cad_boundary *b = (cm_cad_boundary *)calloc(1, sizeof *b);
    if (!b) return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory", fn);
    b->n = n;
    b->uv = (double *)malloc(2 * n * sizeof(double) + 1);
    b->xyz = (double *)malloc(3 * n * sizeof(double) + 1);
    b->edge = (int *)malloc(n * sizeof(int) + 1);
    b->s = (double *)malloc(n * sizeof(double) + 1);
    b->wire = (int *)malloc(n * sizeof(int) + 1);
    if (!b->uv || !b->xyz || !b->edge || !b->s || !b->wire) {
        cm_cad_boundary_destroy(&b);
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory for %zu samples", fn, n);
    }
    st = cmcad::guard(ctx, fn, [&]() -> cm_status {
        cmcad::adaptors a(model);
        TopoDS_Face f = model->face(face);
        size_t j = 0;
        for (int w = w0; w < w1; ++w) {
            for (int k = model->wire_offset[w]; k < model->wire_offset[w + 1]; ++k) {
                const int e = model->wire_edge[k];
                const bool rev = model->wire_rev[k];
                const int c = per_edge ? per_edge[e] : count;
                const cm_cad_edge_info &ei = model->edge_info[e];
                TopoDS_Edge oe =
                    TopoDS::Edge(model->edge(e).Oriented(rev ? TopAbs_REVERSED : TopAbs_FORWARD));
                double pf, pl;
                Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(oe, f, pf, pl);
                if (pc.IsNull())
                    return cm_error(ctx, CM_ERR_CAD, "%s: face %d: edge %d has no pcurve", fn,
                                    face, e);
                for (int i = 0; i < c; ++i, ++j) {
                    // fraction along the edge as the wire runs, s in the edge's own direction
                    double frac = (double)i / c, s = rev ? 1.0 - frac : frac, t;
                    gp_Pnt p;
                    if (ei.degenerate || !(ei.length > 0)) {
                        t = pf + s * (pl - pf);
                        const double *v = &model->vertex_xyz[3 * (size_t)std::max(ei.vertex[0], 0)];
                        p.SetCoord(v[0], v[1], v[2]);
                    } else {
                        t = at_t && !std::isnan(at_t[j]) ? at_t[j]
                                                         : param_at(a.curve(e), s, ei.length);
                        p = a.curve(e).Value(t);
                    }
                    gp_Pnt2d q = pc->Value(t);
                    b->uv[2 * j] = q.X(), b->uv[2 * j + 1] = q.Y();
                    b->xyz[3 * j] = p.X(), b->xyz[3 * j + 1] = p.Y(), b->xyz[3 * j + 2] = p.Z();
                    b->edge[j] = e, b->s[j] = ei.flipped ? 1.0 - s : s, b->wire[j] = w - w0;
                }
            }
        }
        return CM_OK;
    });
    if (st != CM_OK) {
        cm_cad_boundary_destroy(&b);
        return st;
    }
    *boundary = b;
    return CM_OK;
}

}  // namespace

extern "C" {

cm_status cm_cad_face_boundary(cm_context *ctx, const cm_cad_model *model, int face,
                               const int *per_edge, int count, cm_cad_boundary **boundary)
{
    return face_boundary(ctx, model, face, per_edge, count, nullptr, boundary,
                         "cm_cad_face_boundary");
}

cm_status cm_cad_face_boundary_at(cm_context *ctx, const cm_cad_model *model, int face,
                                  const int *per_edge, int count, const double *t,
                                  cm_cad_boundary **boundary)
{
    if (!t) {
        if (boundary) *boundary = nullptr;
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_cad_face_boundary_at: t is NULL");
    }
    return face_boundary(ctx, model, face, per_edge, count, t, boundary,
                         "cm_cad_face_boundary_at");
}

}  // extern "C"
