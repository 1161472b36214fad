// Projection of points onto one face or one edge (paper section 4): Newton from a start value
// (the nearest dense sample), kept inside the trimmed domain, with the face's boundary edges
// as the fallback when the foot point falls outside the trimming.
#include "cad_internal.hxx"

#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <ShapeAnalysis_Curve.hxx>
#include <gp_Pnt2d.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <cmath>
#include <limits>

namespace cmcad {

// Nothing is allocated here: the constructor runs at the top of OpenMP regions, outside the
// try blocks of the loops; the tables grow on first use, inside them.
adaptors::adaptors(const cm_cad_model *m) noexcept : model(m) {}

adaptors::~adaptors()
{
    for (BRepAdaptor_Surface *x : s) delete x;
    for (BRepAdaptor_Curve *x : c) delete x;
    for (BRepTopAdaptor_FClass2d *x : k) delete x;
}

BRepAdaptor_Surface &adaptors::surface(int face)
{
    if (s.empty()) s.assign(model->faces.Extent(), nullptr);
    if (!s[face]) s[face] = new BRepAdaptor_Surface(model->face(face), true);
    return *s[face];
}

BRepAdaptor_Curve &adaptors::curve(int edge)
{
    if (c.empty()) c.assign(model->edges.Extent(), nullptr);
    if (!c[edge]) c[edge] = new BRepAdaptor_Curve(TopoDS::Edge(model->edge(edge).Oriented(TopAbs_FORWARD)));
    return *c[edge];
}

BRepTopAdaptor_FClass2d &adaptors::classifier(int face)
{
    if (k.empty()) k.assign(model->faces.Extent(), nullptr);
    if (!k[face]) {
        TopoDS_Face f = model->face(face);
        k[face] = new BRepTopAdaptor_FClass2d(f, BRep_Tool::Tolerance(f));
    }
    return *k[face];
}

// Periodic parameters are brought into the face's range here: Perform's own recentring
// builds a surface adaptor on every call, which made it the slowest step of a projection.
bool inside_face(adaptors &a, int face, double u, double v)
{
    const cm_cad_face_info &fi = a.model->face_info[face];
    for (int d = 0; d < 2; ++d) {
        double &x = d ? v : u, p = fi.period[d], lo = fi.uv_range[2 * d], hi = fi.uv_range[2 * d + 1];
        if (p <= 0 || !std::isfinite(x)) continue;
        const double tol = 1e-9 * p;
        if (x < lo - tol) x += p * std::ceil((lo - tol - x) / p);
        if (x > hi + tol) x -= p * std::ceil((x - hi - tol) / p);
    }
    return a.classifier(face).Perform(gp_Pnt2d(u, v), Standard_False) != TopAbs_OUT;
}

namespace {

double wrap(double x, double lo, double period)
{
    if (period <= 0) return x;
    double k = std::floor((x - lo) / period);
    double y = x - k * period;
    // keep a value that sits on the upper end of the range where it is
    if (y < lo) y += period;
    return y;
}

// Minimises |S(u,v) - p|^2 by Newton on the gradient (full Hessian when it is positive
// definite, Gauss-Newton otherwise) with a backtracking line search. Non-periodic parameters
// are clamped to the face's parameter box; clamped reports whether the result sits on it.
double newton_face(BRepAdaptor_Surface &S, const gp_Pnt &p, const double box[4],
                   const int periodic[2], double &u, double &v, bool &clamped)
{
    const double ur = box[1] - box[0], vr = box[3] - box[2];
    auto clamp = [&](double &a, double &b) {
        bool c = false;
        if (!periodic[0]) {
            if (a < box[0]) a = box[0], c = true;
            if (a > box[1]) a = box[1], c = true;
        }
        if (!periodic[1]) {
            if (b < box[2]) b = box[2], c = true;
            if (b > box[3]) b = box[3], c = true;
        }
        return c;
    };
    clamped = clamp(u, v);
    gp_Pnt q;
    gp_Vec su, sv, suu, svv, suv;
    S.D2(u, v, q, su, sv, suu, svv, suv);
    double f = q.SquareDistance(p);
    for (int it = 0; it < 60; ++it) {
        gp_Vec r(p, q);
        double g1 = r.Dot(su), g2 = r.Dot(sv);
        double a = su.Dot(su), b = su.Dot(sv), c = sv.Dot(sv);
        double h11 = a + r.Dot(suu), h12 = b + r.Dot(suv), h22 = c + r.Dot(svv);
        double det = h11 * h22 - h12 * h12;
        if (!(h11 > 0 && det > 1e-14 * (h11 * h22 + 1e-300))) {
            h11 = a, h12 = b, h22 = c;  // Gauss-Newton: positive semi-definite
        }
        // a tiny Levenberg term keeps degenerate points (sphere poles) solvable
        double lam = 1e-12 * (h11 + h22) + 1e-300;
        h11 += lam, h22 += lam;
        det = h11 * h22 - h12 * h12;
        if (!(det > 0)) break;
        double du = -(h22 * g1 - h12 * g2) / det, dv = -(h11 * g2 - h12 * g1) / det;
        // one Newton step never leaves a quarter of the parameter box (or of the period)
        double lu = 0.25 * (periodic[0] ? S.UPeriod() : std::max(ur, 1e-300));
        double lv = 0.25 * (periodic[1] ? S.VPeriod() : std::max(vr, 1e-300));
        double scale = std::max(std::fabs(du) / lu, std::fabs(dv) / lv);
        if (scale > 1) du /= scale, dv /= scale;
        // Close to the solution the squared distance no longer resolves the step (it is
        // quadratic in the tangential error): take small Newton steps as they are.
        const bool local = std::max(std::fabs(du) / lu, std::fabs(dv) / lv) < 1e-5;
        double step = 1.0, nu = u, nv = v, nf = f;
        gp_Pnt nq;
        gp_Vec nsu, nsv, nsuu, nsvv, nsuv;
        bool ok = false, nc = false;
        for (int ls = 0; ls < 40; ++ls, step *= 0.5) {
            nu = u + step * du, nv = v + step * dv;
            nc = clamp(nu, nv);
            S.D2(nu, nv, nq, nsu, nsv, nsuu, nsvv, nsuv);
            nf = nq.SquareDistance(p);
            if (local || nf <= f * (1 + 1e-15) + 1e-300) {
                ok = true;
                break;
            }
        }
        if (!ok) break;
        double moved = std::max(std::fabs(nu - u) / std::max(ur, 1e-300),
                                std::fabs(nv - v) / std::max(vr, 1e-300));
        u = nu, v = nv, f = nf, q = nq, su = nsu, sv = nsv, suu = nsuu, svv = nsvv, suv = nsuv;
        clamped = nc;
        if (moved < 1e-15) break;
    }
    return std::sqrt(f);
}

}  // namespace

double project_on_edge(adaptors &a, int edge, const gp_Pnt &p, double t0, double &t, gp_Pnt &q)
{
    BRepAdaptor_Curve &C = a.curve(edge);
    const double t1 = C.FirstParameter(), t2 = C.LastParameter();
    if (std::isnan(t0)) {
        ShapeAnalysis_Curve sac;
        sac.Project(C, p, 1e-12, q, t0, Standard_False);
    }
    t = std::min(std::max(t0, t1), t2);
    gp_Vec d1, d2;
    C.D2(t, q, d1, d2);
    double f = q.SquareDistance(p);
    // Newton on (C(t) - p) . C'(t) = 0, clamped to the edge's range, with backtracking.
    for (int it = 0; it < 60; ++it) {
        gp_Vec r(p, q);
        double g = r.Dot(d1), h = d1.Dot(d1) + r.Dot(d2);
        if (!(h > 0)) h = d1.Dot(d1);
        if (!(h > 0)) break;
        double dt = -g / h, lim = 0.25 * (t2 - t1);
        if (std::fabs(dt) > lim) dt = dt > 0 ? lim : -lim;
        double step = 1.0, nt = t, nf = f;
        gp_Pnt nq;
        gp_Vec n1, n2;
        bool ok = false;
        for (int ls = 0; ls < 40; ++ls, step *= 0.5) {
            nt = std::min(std::max(t + step * dt, t1), t2);
            C.D2(nt, nq, n1, n2);
            nf = nq.SquareDistance(p);
            if (nf <= f * (1 + 1e-15) + 1e-300) {
                ok = true;
                break;
            }
        }
        if (!ok) break;
        double moved = std::fabs(nt - t) / std::max(t2 - t1, 1e-300);
        t = nt, q = nq, d1 = n1, d2 = n2, f = nf;
        if (moved < 1e-15) break;
    }
    return std::sqrt(f);
}

void seed_on_face(adaptors &a, int face, const gp_Pnt &p, double &u, double &v)
{
    const cm_cad_face_info &fi = a.model->face_info[face];
    BRepAdaptor_Surface &S = a.surface(face);
    const int n = 24;
    double best = std::numeric_limits<double>::infinity(), bestin = best;
    double bu = fi.uv_range[0], bv = fi.uv_range[2], iu = bu, iv = bv;
    for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
            double uu = fi.uv_range[0] + (fi.uv_range[1] - fi.uv_range[0]) * i / n;
            double vv = fi.uv_range[2] + (fi.uv_range[3] - fi.uv_range[2]) * j / n;
            double d = S.Value(uu, vv).SquareDistance(p);
            if (d < best) best = d, bu = uu, bv = vv;
            if (d < bestin && inside_face(a, face, uu, vv)) bestin = d, iu = uu, iv = vv;
        }
    // prefer a start inside the trimming; the box corner may lie in a hole
    if (bestin < std::numeric_limits<double>::infinity())
        u = iu, v = iv;
    else
        u = bu, v = bv;
}

void refine_on_surface(adaptors &a, int face, const gp_Pnt &p, double tol, foot &out);

void project_on_face(adaptors &a, int face, const gp_Pnt &p, double u0, double v0, foot &out)
{
    const cm_cad_model *m = a.model;
    const cm_cad_face_info &fi = m->face_info[face];
    BRepAdaptor_Surface &S = a.surface(face);
    double u = u0, v = v0;
    bool clamped = false;
    double d = newton_face(S, p, fi.uv_range, fi.periodic, u, v, clamped);
    {
        // At a degenerate point (sphere or cone apex: one derivative vanishes) Newton cannot
        // turn the other parameter; restart from a few values of it, slightly inside.
        gp_Pnt q;
        gp_Vec su, sv;
        S.D1(u, v, q, su, sv);
        double scale = std::max(su.Magnitude(), sv.Magnitude());
        if (scale > 0 && std::min(su.Magnitude(), sv.Magnitude()) < 1e-7 * scale) {
            bool u_degenerate = su.Magnitude() < sv.Magnitude();
            for (int k = 0; k < 8; ++k) {
                double uu = u, vv = v;
                if (u_degenerate) {
                    uu = fi.uv_range[0] + (fi.uv_range[1] - fi.uv_range[0]) * (k + 0.5) / 8;
                    vv = v + (v > 0.5 * (fi.uv_range[2] + fi.uv_range[3]) ? -1 : 1) * 1e-3 *
                                 (fi.uv_range[3] - fi.uv_range[2]);
                } else {
                    vv = fi.uv_range[2] + (fi.uv_range[3] - fi.uv_range[2]) * (k + 0.5) / 8;
                    uu = u + (u > 0.5 * (fi.uv_range[0] + fi.uv_range[1]) ? -1 : 1) * 1e-3 *
                                 (fi.uv_range[1] - fi.uv_range[0]);
                }
                bool c2 = false;
                double d2 = newton_face(S, p, fi.uv_range, fi.periodic, uu, vv, c2);
                if (d2 < d * (1 - 1e-15)) d = d2, u = uu, v = vv, clamped = c2;
            }
        }
    }
    u = wrap(u, fi.uv_range[0] - 1e-9 * fi.period[0], fi.period[0]);
    v = wrap(v, fi.uv_range[2] - 1e-9 * fi.period[1], fi.period[1]);
    bool in = inside_face(a, face, u, v);
    out.edge = -1;
    if (in && !clamped) {
        out.u = u, out.v = v, out.dist = d, out.p = S.Value(u, v);
        return;
    }
    double best = in ? d : std::numeric_limits<double>::infinity();
    if (in) out.u = u, out.v = v, out.dist = d, out.p = S.Value(u, v);
    double tol = BRep_Tool::Tolerance(m->face(face));
    // The nearest point of the trimmed face lies on its boundary: try every boundary edge.
    int w0 = m->face_wire_offset[face], w1 = m->face_wire_offset[face + 1];
    for (int k = m->wire_offset[w0]; k < m->wire_offset[w1]; ++k) {
        int e = m->wire_edge[k];
        if (m->edge_info[e].degenerate) continue;
        tol = std::max(tol, BRep_Tool::Tolerance(m->edge(e)));
        double t;
        gp_Pnt q;
        double de = project_on_edge(a, e, p, std::numeric_limits<double>::quiet_NaN(), t, q);
        if (de < best) {
            TopoDS_Edge oe = TopoDS::Edge(m->edge(e).Oriented(m->wire_rev[k] ? TopAbs_REVERSED
                                                                               : TopAbs_FORWARD));
            double f, l;
            Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(oe, m->face(face), f, l);
            if (pc.IsNull()) continue;
            gp_Pnt2d uv = pc->Value(t);
            best = de, out.u = uv.X(), out.v = uv.Y(), out.dist = de, out.p = q, out.edge = e,
            out.t = t;
        }
    }
    if (best == std::numeric_limits<double>::infinity()) {
        // no edge with a pcurve: keep the Newton result rather than nothing
        out.u = u, out.v = v, out.dist = d, out.p = S.Value(u, v);
        return;
    }
    // the foot is on the trimming (an edge's 3D curve, or the parameter box it clamped to)
    refine_on_surface(a, face, p, tol, out);
}

// An edge's 3D curve lies within the edge's tolerance of the surface, not on it (industrial
// B-spline faces: up to 1e-4), and the parameter box of the face comes from the pcurves: so
// the distance to a foot on the trimming is not the distance to the face, a point of the
// surface just beyond the trimming curve would report the gap (or its distance to the box).
// The final answer is a Newton projection onto the surface from the foot's (u,v), in a
// parameter box widened by the tolerance tol (of the face and its edges), kept when its foot
// stays within tol of the foot on the trimming (a point truly beyond the boundary slides
// farther along the surface and keeps that foot).
void refine_on_surface(adaptors &a, int face, const gp_Pnt &p, double tol, foot &out)
{
    const cm_cad_face_info &fi = a.model->face_info[face];
    BRepAdaptor_Surface &S = a.surface(face);
    gp_Pnt q;
    gp_Vec su, sv;
    S.D1(out.u, out.v, q, su, sv);
    double box[4];
    std::copy(fi.uv_range, fi.uv_range + 4, box);
    const double gu = su.Magnitude(), gv = sv.Magnitude();
    const double mu = gu > 0 ? std::min(4 * tol / gu, 0.01 * (box[1] - box[0])) : 0;
    const double mv = gv > 0 ? std::min(4 * tol / gv, 0.01 * (box[3] - box[2])) : 0;
    box[0] -= mu, box[1] += mu, box[2] -= mv, box[3] += mv;
    double u = out.u, v = out.v;
    bool clamped = false;
    double d = newton_face(S, p, box, fi.periodic, u, v, clamped);
    gp_Pnt f = S.Value(u, v);
    if (d < out.dist && f.Distance(out.p) <= 2 * tol + 1e-12 * (1 + p.XYZ().Modulus())) {
        u = wrap(u, fi.uv_range[0] - 1e-9 * fi.period[0], fi.period[0]);
        v = wrap(v, fi.uv_range[2] - 1e-9 * fi.period[1], fi.period[1]);
        out.u = u, out.v = v, out.dist = d, out.p = f;
    }
}

}  // namespace cmcad

extern "C" {

cm_status cm_cad_project_face(cm_context *ctx, const cm_cad_model *model, int face,
                              const double *xyz, size_t n, const double *uv0, double *uv,
                              double *dist, double *foot)
{
    const char *fn = "cm_cad_project_face";
    cm_status st = cmcad::check_face(ctx, model, face, fn);
    if (st != CM_OK) return st;
    if (n && !xyz) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: xyz is NULL", fn);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        cmcad::region_error err;
#pragma omp parallel num_threads(cm_context_threads_for(ctx, n, 64)) if (n > 64)
        {
            cmcad::adaptors a(model);
#pragma omp for schedule(static)
            for (long i = 0; i < (long)n; ++i) {
                try {
                    gp_Pnt p(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
                    double u, v;
                    if (uv0)
                        u = uv0[2 * i], v = uv0[2 * i + 1];
                    else
                        cmcad::seed_on_face(a, face, p, u, v);
                    cmcad::foot r;
                    cmcad::project_on_face(a, face, p, u, v, r);
                    if (uv) uv[2 * i] = r.u, uv[2 * i + 1] = r.v;
                    if (dist) dist[i] = r.dist;
                    if (foot) foot[3 * i] = r.p.X(), foot[3 * i + 1] = r.p.Y(), foot[3 * i + 2] = r.p.Z();
                } catch (...) {
                    err.capture();
                }
            }
        }
        return err.report(ctx, fn);
    });
}

cm_status cm_cad_project_edge(cm_context *ctx, const cm_cad_model *model, int edge,
                              const double *xyz, size_t n, double *t, double *dist)
{
    const char *fn = "cm_cad_project_edge";
    cm_status st = cmcad::check_edge(ctx, model, edge, fn);
    if (st != CM_OK) return st;
    if (n && !xyz) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: xyz is NULL", fn);
    if (model->edge_info[edge].degenerate)
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: edge %d is degenerate (a point)", fn, edge);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        cmcad::region_error err;
#pragma omp parallel num_threads(cm_context_threads_for(ctx, n, 64)) if (n > 64)
        {
            cmcad::adaptors a(model);
#pragma omp for schedule(static)
            for (long i = 0; i < (long)n; ++i) {
                try {
                    gp_Pnt p(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]), q;
                    double ti;
                    double d = cmcad::project_on_edge(a, edge, p,
                                                      std::numeric_limits<double>::quiet_NaN(), ti, q);
                    if (t) t[i] = ti;
                    if (dist) dist[i] = d;
                } catch (...) {
                    err.capture();
                }
            }
        }
        return err.report(ctx, fn);
    });
}

cm_status cm_cad_project_each(cm_context *ctx, const cm_cad_model *model, size_t n,
                              const int *kind, const int *entity, const double *xyz,
                              const double *uv0, double *dist)
{
    const char *fn = "cm_cad_project_each";
    if (!model) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: model is NULL", fn);
    if (n && (!kind || !entity || !xyz || !dist))
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL kind, entity, xyz or dist", fn);
    for (size_t i = 0; i < n; ++i) {
        cm_status st = CM_OK;
        if (kind[i] == 1) {
            st = cmcad::check_edge(ctx, model, entity[i], fn);
            if (st == CM_OK && model->edge_info[entity[i]].degenerate)
                st = cm_error(ctx, CM_ERR_ARGUMENT, "%s: edge %d is degenerate (a point)", fn,
                              entity[i]);
        } else if (kind[i] == 2) {
            st = cmcad::check_face(ctx, model, entity[i], fn);
        }
        if (st != CM_OK) return st;
    }
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        cmcad::region_error err;
        // dynamic: the points of one entity are contiguous in the callers' order, and the
        // cost of a point varies by entity (an edge's global search, a face's Newton)
#pragma omp parallel num_threads(cm_context_threads_for(ctx, n, 64)) if (n > 64)
        {
            cmcad::adaptors a(model);
#pragma omp for schedule(dynamic, 64)
            for (long i = 0; i < (long)n; ++i) {
                try {
                    gp_Pnt p(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
                    if (kind[i] == 1) {
                        gp_Pnt q;
                        double ti;
                        dist[i] = cmcad::project_on_edge(a, entity[i], p,
                                                         std::numeric_limits<double>::quiet_NaN(),
                                                         ti, q);
                    } else if (kind[i] == 2) {
                        double u, v;
                        if (uv0)
                            u = uv0[2 * i], v = uv0[2 * i + 1];
                        else
                            cmcad::seed_on_face(a, entity[i], p, u, v);
                        cmcad::foot r;
                        cmcad::project_on_face(a, entity[i], p, u, v, r);
                        dist[i] = r.dist;
                    }
                } catch (...) {
                    err.capture();
                }
            }
        }
        return err.report(ctx, fn);
    });
}

}  // extern "C"
