// Row-wise trimming test for the locator's sampling grid (cad/locator.cpp): one exact
// classification (BRepTopAdaptor_FClass2d, a point-in-polygon test over the whole boundary
// polygon) per grid candidate made B-spline-heavy parts with long boundaries cost tens of
// seconds to sample (benchmarks/RESULTS.md, CAD layer). A row v = const meets the face's boundary in a few
// crossings: with the pcurves as a polyline, the even-odd count of crossings left of a
// candidate decides it, and only candidates within delta of the polyline (delta bounds how
// far it is from the pcurves: the sampled chord deviation, with a margin, and any gap
// between consecutive pcurves) are left to the exact classifier. A face whose polyline is
// too far from its pcurves (or has none) is classified exactly throughout.
#include "cad_internal.hxx"

#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <gp_Pnt2d.hxx>

#include <algorithm>
#include <cmath>
#include <utility>

namespace cmcad {

void scanline_build(const cm_cad_model *m, int face, scanline &s)
{
    s.ok = false;
    s.seg.clear();
    const cm_cad_face_info &fi = m->face_info[face];
    const double ext = std::max(fi.uv_range[1] - fi.uv_range[0], fi.uv_range[3] - fi.uv_range[2]);
    if (!(ext > 0) || !std::isfinite(ext)) return;
    const TopoDS_Face f = m->face(face);
    const int n = 64;  // segments per edge occurrence
    double dev = 0;
    for (int w = m->face_wire_offset[face]; w < m->face_wire_offset[face + 1]; ++w) {
        gp_Pnt2d first, prev;
        bool have = false;
        for (int k = m->wire_offset[w]; k < m->wire_offset[w + 1]; ++k) {
            const bool rev = m->wire_rev[k];
            TopoDS_Edge oe = TopoDS::Edge(
                m->edge(m->wire_edge[k]).Oriented(rev ? TopAbs_REVERSED : TopAbs_FORWARD));
            double pf, pl;
            Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(oe, f, pf, pl);
            if (pc.IsNull() || !std::isfinite(pf) || !std::isfinite(pl)) return;
            const double a = rev ? pl : pf, b = rev ? pf : pl;
            gp_Pnt2d p = pc->Value(a);
            if (have) {  // a gap between pcurves is a segment too, and bounds delta
                s.seg.insert(s.seg.end(), {prev.X(), prev.Y(), p.X(), p.Y()});
                dev = std::max(dev, prev.Distance(p));
            } else {
                first = p, have = true;
            }
            for (int i = 1; i <= n; ++i) {
                gp_Pnt2d q = pc->Value(a + (b - a) * i / n);
                gp_Pnt2d mid = pc->Value(a + (b - a) * (i - 0.5) / n);
                dev = std::max(dev, mid.Distance(gp_Pnt2d((p.X() + q.X()) / 2, (p.Y() + q.Y()) / 2)));
                s.seg.insert(s.seg.end(), {p.X(), p.Y(), q.X(), q.Y()});
                p = q;
            }
            prev = p;
        }
        if (have) {
            s.seg.insert(s.seg.end(), {prev.X(), prev.Y(), first.X(), first.Y()});
            dev = std::max(dev, prev.Distance(first));
        }
    }
    // the midpoint deviation estimates the chord error; 4x covers the quarter points of a
    // segment whose curvature varies, and FClass2d's own tolerance near the boundary
    s.delta = 4 * dev + 1e-9 * ext;
    s.ok = !s.seg.empty() && s.delta < 0.05 * ext;
}

void scanline_row(adaptors &a, int face, const scanline &s, double v, double lo, double hi,
                  int nu, char *inside)
{
    auto u_at = [&](int i) { return lo + (hi - lo) * (i + 0.5) / nu; };
    if (!s.ok) {
        for (int i = 0; i < nu; ++i) inside[i] = inside_face(a, face, u_at(i), v);
        return;
    }
    std::vector<double> xs;
    std::vector<std::pair<double, double>> band;
    const double d = s.delta;
    for (size_t k = 0; k + 3 < s.seg.size(); k += 4) {
        const double x0 = s.seg[k], y0 = s.seg[k + 1], x1 = s.seg[k + 2], y1 = s.seg[k + 3];
        if ((y0 > v) != (y1 > v)) xs.push_back(x0 + (v - y0) * (x1 - x0) / (y1 - y0));
        if (std::max(y0, y1) < v - d || std::min(y0, y1) > v + d) continue;
        // the part of the segment inside the band |y - v| <= d, widened by d: a superset of
        // the row's points within d of the segment
        double t0 = 0, t1 = 1;
        if (y1 != y0) {
            double ta = (v - d - y0) / (y1 - y0), tb = (v + d - y0) / (y1 - y0);
            t0 = std::max(0.0, std::min(ta, tb)), t1 = std::min(1.0, std::max(ta, tb));
        }
        double xa = x0 + t0 * (x1 - x0), xb = x0 + t1 * (x1 - x0);
        band.emplace_back(std::min(xa, xb) - d, std::max(xa, xb) + d);
    }
    std::sort(xs.begin(), xs.end());
    std::sort(band.begin(), band.end());
    size_t ix = 0, ib = 0;
    double reach = -INFINITY;  // right end of the bands started left of u
    for (int i = 0; i < nu; ++i) {
        const double u = u_at(i);
        while (ix < xs.size() && xs[ix] < u) ++ix;
        while (ib < band.size() && band[ib].first <= u) reach = std::max(reach, band[ib++].second);
        inside[i] = u <= reach ? inside_face(a, face, u, v) : (ix % 2 == 1);
    }
}

}  // namespace cmcad
