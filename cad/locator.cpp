// Dense samples of the trimmed faces and a kD-tree on them (paper section 4): the nearest
// sample is the start value of the Newton projection, which makes projection onto complex
// trimmed faces fast and robust. Edges and vertices get their own trees.
#include "cad_internal.hxx"

#include "cadmorph/kdtree.h"

#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <gp_Pnt2d.hxx>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>

struct cm_cad_locator {
    const cm_cad_model *model = nullptr;
    double h = 0;
    std::vector<double> xyz, uv;  // face samples: #samples x 3, x 2
    std::vector<int> face;
    std::vector<double> exyz, et;  // edge samples
    std::vector<int> eedge;
    cm_kdtree *tree = nullptr, *etree = nullptr, *vtree = nullptr;
    ~cm_cad_locator()
    {
        cm_kdtree_destroy(&tree);
        cm_kdtree_destroy(&etree);
        cm_kdtree_destroy(&vtree);
    }
};

namespace {

const size_t default_cap = 20000000;

struct row {
    int face;
    double v;
    int nu;
    size_t offset;  // first candidate of this row
};

// Polyline length of the iso-line through 16 segments: the surface metric along u or v.
double iso_length(BRepAdaptor_Surface &S, bool along_u, double fixed, double a, double b)
{
    const int n = 16;
    double len = 0;
    gp_Pnt prev = along_u ? S.Value(a, fixed) : S.Value(fixed, a);
    for (int i = 1; i <= n; ++i) {
        double x = a + (b - a) * i / n;
        gp_Pnt p = along_u ? S.Value(x, fixed) : S.Value(fixed, x);
        len += p.Distance(prev);
        prev = p;
    }
    return len;
}

// Longest u and v iso-lines of each face (5 of each): the face's extent in the metric.
void face_extents(cmcad::adaptors &a, std::vector<double> &lu, std::vector<double> &lv)
{
    const cm_cad_model *m = a.model;
    lu.assign((size_t)m->counts.faces, 0);
    lv.assign((size_t)m->counts.faces, 0);
    for (int f = 0; f < m->counts.faces; ++f) {
        BRepAdaptor_Surface &S = a.surface(f);
        const double *r = m->face_info[f].uv_range;
        for (int i = 0; i <= 4; ++i) {
            lv[(size_t)f] = std::max(
                lv[(size_t)f], iso_length(S, false, r[0] + (r[1] - r[0]) * i / 4, r[2], r[3]));
            lu[(size_t)f] = std::max(
                lu[(size_t)f], iso_length(S, true, r[2] + (r[3] - r[2]) * i / 4, r[0], r[1]));
        }
    }
}

// Rows of the grid: the v step comes from the longest v iso-line, the u step of each row from
// that row's own u iso-line, so that the 3D spacing is close to h everywhere (a sphere gets
// fewer points per row near its poles). Returns the number of candidates.
size_t plan_rows(cmcad::adaptors &a, double h, const std::vector<double> &lvs,
                 std::vector<row> &rows)
{
    const cm_cad_model *m = a.model;
    rows.clear();
    size_t total = 0;
    for (int f = 0; f < m->counts.faces; ++f) {
        const cm_cad_face_info &fi = m->face_info[f];
        BRepAdaptor_Surface &S = a.surface(f);
        const double *r = fi.uv_range;
        long nv = std::max(1L, (long)std::ceil(lvs[(size_t)f] / h));
        for (long j = 0; j < nv; ++j) {
            double v = r[2] + (r[3] - r[2]) * (j + 0.5) / nv;
            double lu = iso_length(S, true, v, r[0], r[1]);
            int nu = (int)std::max(1.0, std::min(std::ceil(lu / h), 1e8));
            rows.push_back(row{f, v, nu, total});
            total += (size_t)nu;
        }
    }
    return total;
}

// Edge sample count per occurrence: about one per h along the edge, ends included.
int edge_count(const cm_cad_edge_info &ei, double h)
{
    return (int)std::max(2.0, std::min(std::ceil(ei.length / h) + 1, 1e8));
}

size_t count_edge_samples(const cm_cad_model *m, double h)
{
    size_t n = 0;
    for (size_t k = 0; k < m->wire_edge.size(); ++k) {
        const cm_cad_edge_info &ei = m->edge_info[m->wire_edge[k]];
        if (!ei.degenerate) n += (size_t)edge_count(ei, h);
    }
    return n;
}

cm_status build(cm_context *ctx, cm_cad_locator *L, const cm_cad_sample_options &o)
{
    const char *fn = "cm_cad_locator_create";
    const cm_cad_model *m = L->model;
    double diag = cm_bbox_diagonal(m->bbox);
    double h = o.h > 0 ? o.h : diag / 200;
    size_t cap = o.max_samples ? o.max_samples : default_cap;
    double clock0 = cm_wtime();
    cmcad::adaptors a(m);
    std::vector<row> rows;
    std::vector<double> lus, lvs;
    face_extents(a, lus, lvs);
    // The count h would give, from the faces' extents (the rows themselves cost an iso-line
    // each: a mesh whose shortest edge asks for 10^10 samples must not plan them first).
    double box = 0, edge_len = 0;
    for (size_t f = 0; f < lus.size(); ++f) box += lus[f] * lvs[f];
    for (size_t k = 0; k < m->wire_edge.size(); ++k) edge_len += m->edge_info[m->wire_edge[k]].length;
    const double h_asked = h;
    const double estimate = box / (h * h) + edge_len / h;
    if (estimate > 64 * (double)cap) {
        // solve box / h^2 + edge_len / h = cap for h: the estimate bounds the count from above
        // (the longest iso-lines), the loop below closes in on the cap
        double c = (double)cap;
        h = std::max(h, (edge_len + std::sqrt(edge_len * edge_len + 4 * c * box)) / (2 * c));
    }
    size_t total = plan_rows(a, h, lvs, rows) + count_edge_samples(m, h);
    const size_t total_asked = h == h_asked ? total : (size_t)std::min(estimate, 1e18);
    for (int it = 0; total > cap && it < 20; ++it) {
        h *= std::sqrt((double)total / (double)cap) * 1.02;
        total = plan_rows(a, h, lvs, rows) + count_edge_samples(m, h);
    }
    if (total > cap)
        return cm_error(ctx, CM_ERR_ARGUMENT, "%s: cannot meet the cap of %zu samples", fn, cap);
    L->h = h;

    // Two passes over the rows, in parallel, each row in its own slots so that the order is the
    // same for any thread count: which grid points lie inside their face (one byte per
    // candidate), then the points themselves, written straight into arrays of the exact size
    // (no candidate-sized buffers: trimmed faces keep a fraction of their parameter box).
    const size_t ncand = rows.empty() ? 0 : rows.back().offset + (size_t)rows.back().nu;
    std::vector<char> keep(ncand, 0);
    cmcad::region_error err;
    cm_status st = cm_progress(ctx, "sample", 0, (double)rows.size());
    if (st < 0) return st;
    // the caller asked to stop (seen by the calling thread, which reports): every thread skips
    // the rest of its rows
    int stop = 0;
    std::vector<cmcad::scanline> scan((size_t)m->counts.faces);
    for (int f = 0; f < m->counts.faces; ++f) cmcad::scanline_build(m, f, scan[(size_t)f]);
    const int nthreads = cm_context_threads_for(ctx, ncand, 4096);
#pragma omp parallel num_threads(nthreads) if (ncand > 4096)
    {
        cmcad::adaptors ta(m);
        const int nt = omp_get_num_threads();
        const bool master = omp_get_thread_num() == 0;
#pragma omp for schedule(static)
        for (long r = 0; r < (long)rows.size(); ++r) {
            int stopped;
#pragma omp atomic read
            stopped = stop;
            if (stopped) continue;
            // the calling thread reports: with a static schedule it owns the first 1/nt rows
            if (master && r % 64 == 0 &&
                cm_progress(ctx, "sample", std::min((double)r * nt / 2, (double)rows.size()),
                            (double)rows.size()) < 0) {
#pragma omp atomic write
                stop = 1;
                continue;
            }
            try {
                const row &rw = rows[r];
                const double *ur = m->face_info[rw.face].uv_range;
                cmcad::scanline_row(ta, rw.face, scan[(size_t)rw.face], rw.v, ur[0], ur[1], rw.nu,
                                    &keep[rw.offset]);
            } catch (...) {
                err.capture();
            }
        }
    }
    if (err.status != CM_OK) return err.report(ctx, fn);
    if (stop) return CM_ERR_INTERRUPTED;  // the message is cm_progress's
    // first kept sample of each row
    std::vector<size_t> first(rows.size() + 1, 0);
    for (size_t r = 0; r < rows.size(); ++r) {
        size_t k = 0;
        for (size_t c = rows[r].offset; c < rows[r].offset + (size_t)rows[r].nu; ++c)
            k += (size_t)keep[c];
        first[r + 1] = first[r] + k;
    }
    const size_t nkeep = first.back();

    // Edges: points on every occurrence of an edge in a face (uv from that face's pcurve, so
    // both copies of a seam), and once per edge for the edge tree.
    std::vector<double> fexyz, feuv;
    std::vector<int> feface;
    std::vector<char> edge_done(m->counts.edges, 0);
    for (int f = 0; f < m->counts.faces; ++f) {
        TopoDS_Face face = m->face(f);
        int k0 = m->wire_offset[m->face_wire_offset[f]];
        int k1 = m->wire_offset[m->face_wire_offset[f + 1]];
        for (int k = k0; k < k1; ++k) {
            int e = m->wire_edge[k];
            const cm_cad_edge_info &ei = m->edge_info[e];
            if (ei.degenerate) continue;
            TopoDS_Edge oe =
                TopoDS::Edge(m->edge(e).Oriented(m->wire_rev[k] ? TopAbs_REVERSED : TopAbs_FORWARD));
            double pf, pl;
            Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(oe, face, pf, pl);
            BRepAdaptor_Curve &C = a.curve(e);
            int ne = edge_count(ei, h);
            for (int i = 0; i < ne; ++i) {
                double t = ei.t_range[0] + (ei.t_range[1] - ei.t_range[0]) * i / (ne - 1);
                gp_Pnt p = C.Value(t);
                if (!pc.IsNull()) {
                    gp_Pnt2d q = pc->Value(t);
                    fexyz.insert(fexyz.end(), {p.X(), p.Y(), p.Z()});
                    feuv.insert(feuv.end(), {q.X(), q.Y()});
                    feface.push_back(f);
                }
                if (!edge_done[e]) {
                    L->exyz.insert(L->exyz.end(), {p.X(), p.Y(), p.Z()});
                    L->et.push_back(t);
                    L->eedge.push_back(e);
                }
            }
            edge_done[e] = 1;
        }
    }
    const size_t ns = nkeep + feface.size();
    L->xyz.resize(3 * ns);
    L->uv.resize(2 * ns);
    L->face.resize(ns);
    std::copy(fexyz.begin(), fexyz.end(), L->xyz.begin() + 3 * (std::ptrdiff_t)nkeep);
    std::copy(feuv.begin(), feuv.end(), L->uv.begin() + 2 * (std::ptrdiff_t)nkeep);
    std::copy(feface.begin(), feface.end(), L->face.begin() + (std::ptrdiff_t)nkeep);
    double *xyz = L->xyz.data(), *uvs = L->uv.data();
    int *fc = L->face.data();
#pragma omp parallel num_threads(nthreads) if (ncand > 4096)
    {
        cmcad::adaptors ta(m);
        const int nt = omp_get_num_threads();
        const bool master = omp_get_thread_num() == 0;
#pragma omp for schedule(static)
        for (long r = 0; r < (long)rows.size(); ++r) {
            int stopped;
#pragma omp atomic read
            stopped = stop;
            if (stopped) continue;
            if (master && r % 64 == 0 &&
                cm_progress(ctx, "sample",
                            std::min((double)rows.size() * 0.5 + (double)r * nt / 2,
                                     (double)rows.size()),
                            (double)rows.size()) < 0) {
#pragma omp atomic write
                stop = 1;
                continue;
            }
            try {
                const row &rw = rows[r];
                const double *ur = m->face_info[rw.face].uv_range;
                BRepAdaptor_Surface &S = ta.surface(rw.face);
                size_t j = first[(size_t)r];
                for (int i = 0; i < rw.nu; ++i) {
                    if (!keep[rw.offset + (size_t)i]) continue;
                    double u = ur[0] + (ur[1] - ur[0]) * (i + 0.5) / rw.nu;
                    gp_Pnt p = S.Value(u, rw.v);
                    xyz[3 * j] = p.X(), xyz[3 * j + 1] = p.Y(), xyz[3 * j + 2] = p.Z();
                    uvs[2 * j] = u, uvs[2 * j + 1] = rw.v;
                    fc[j++] = rw.face;
                }
            } catch (...) {
                err.capture();
            }
        }
    }
    if (err.status != CM_OK) return err.report(ctx, fn);
    if (stop) return CM_ERR_INTERRUPTED;
    if ((st = cm_progress(ctx, "sample", (double)rows.size(), (double)rows.size())) < 0) return st;
    std::vector<char>().swap(keep);
    double clock1 = cm_wtime();
    if (L->face.empty())
        return cm_error(ctx, CM_ERR_CAD, "%s: no sample inside any face", fn);
    double clock2 = cm_wtime();
    // the tree reads the locator's own samples (stored once: they live as long as the tree)
    st = cm_kdtree_create_borrowed(ctx, L->xyz.data(), L->face.size(), &L->tree);
    if (st == CM_OK) st = cm_progress(ctx, "sample", (double)rows.size(), (double)rows.size());
    if (st == CM_OK && !L->eedge.empty())
        st = cm_kdtree_create(ctx, L->exyz.data(), L->eedge.size(), &L->etree);
    if (st == CM_OK && m->counts.vertices > 0)
        st = cm_kdtree_create(ctx, m->vertex_xyz.data(), (size_t)m->counts.vertices, &L->vtree);
    if (st != CM_OK) return st;
    cm_log(ctx, CM_LOG_DEBUG,
           "sampling: %zu samples (%zu on edges) at h = %g; grid and edges %.3f s, "
           "kD-trees %.3f s",
           L->face.size(), L->eedge.size(), h, clock1 - clock0,
           cm_wtime() - clock2);
    if (h != h_asked)
        return cm_error(ctx, CM_WARNING,
                        "%s: h = %g would give about %.3g samples, over the cap of %zu: "
                        "h raised to %g (%zu samples)",
                        fn, h_asked, (double)total_asked, cap, h, L->face.size());
    return CM_OK;
}

}  // namespace

extern "C" {

void cm_cad_sample_options_init(cm_cad_sample_options *opt)
{
    if (!opt) return;
    opt->h = 0;
    opt->max_samples = default_cap;
}

size_t cm_cad_sample_cap(size_t boundary_nodes, size_t max_cap)
{
    size_t cap = boundary_nodes > CM_CAD_MIN_SAMPLES / CM_CAD_SAMPLES_PER_NODE
                     ? boundary_nodes * CM_CAD_SAMPLES_PER_NODE
                     : CM_CAD_MIN_SAMPLES;
    if (boundary_nodes > SIZE_MAX / CM_CAD_SAMPLES_PER_NODE) cap = SIZE_MAX;
    return max_cap && cap > max_cap ? max_cap : cap;
}

cm_status cm_cad_locator_create(cm_context *ctx, const cm_cad_model *model,
                                const cm_cad_sample_options *opt, cm_cad_locator **locator)
{
    const char *fn = "cm_cad_locator_create";
    if (!locator) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: locator is NULL", fn);
    *locator = nullptr;
    if (!model) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: model is NULL", fn);
    cm_cad_sample_options o;
    cm_cad_sample_options_init(&o);
    if (opt) o = *opt;
    if (!std::isfinite(o.h)) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: h is not finite", fn);
    cm_cad_locator *L = nullptr;
    cm_status st = cmcad::guard(ctx, fn, [&]() -> cm_status {
        std::unique_ptr<cm_cad_locator> l(new cm_cad_locator());
        l->model = model;
        cm_status s = build(ctx, l.get(), o);
        if (s >= 0) L = l.release();
        return s;
    });
    *locator = L;
    return st;
}

void cm_cad_locator_destroy(cm_cad_locator **locator)
{
    if (!locator || !*locator) return;
    delete *locator;
    *locator = nullptr;
}

size_t cm_cad_locator_samples(const cm_cad_locator *L, const double **xyz, const int **face,
                              const double **uv)
{
    if (!L) return 0;
    if (xyz) *xyz = L->xyz.data();
    if (face) *face = L->face.data();
    if (uv) *uv = L->uv.data();
    return L->face.size();
}

double cm_cad_locator_h(const cm_cad_locator *L) { return L ? L->h : 0.0; }

cm_status cm_cad_locate_faces(cm_context *ctx, const cm_cad_locator *L, const double *xyz,
                              size_t n, int *face, double *uv, double *dist, double *foot)
{
    const char *fn = "cm_cad_locate_faces";
    if (!L || (n && !xyz)) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL locator or xyz", fn);
    if (n == 0) return CM_OK;
    const int k = (int)std::min<size_t>(6, L->face.size());
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        std::vector<int64_t> idx(n * (size_t)k);
        std::vector<double> d2(n * (size_t)k);
        cm_status st = cm_kdtree_nearest(ctx, L->tree, xyz, n, k, idx.data(), d2.data());
        if (st != CM_OK) return st;
        cmcad::region_error err;
        const double h = L->h;
#pragma omp parallel num_threads(cm_context_threads_for(ctx, n, 64)) if (n > 64)
        {
            cmcad::adaptors a(L->model);
#pragma omp for schedule(static)
            for (long i = 0; i < (long)n; ++i) {
                try {
                    gp_Pnt p(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
                    const int64_t *ix = &idx[(size_t)i * k];
                    const double *dd = &d2[(size_t)i * k];
                    // Faces of the nearest samples within h of the nearest: a face whose
                    // samples are all farther cannot hold a nearer foot point, since every
                    // point of a face is within about h / sqrt(2) of one of its samples.
                    double reach = std::sqrt(dd[0]) + h;
                    int tried[6], ntried = 0;
                    cmcad::foot best;
                    best.dist = std::numeric_limits<double>::infinity();
                    int best_face = -1;
                    for (int j = 0; j < k && ntried < 4; ++j) {
                        if (std::sqrt(dd[j]) > reach) break;
                        int f = L->face[ix[j]];
                        if (std::find(tried, tried + ntried, f) != tried + ntried) continue;
                        tried[ntried++] = f;
                        cmcad::foot r;
                        cmcad::project_on_face(a, f, p, L->uv[2 * ix[j]], L->uv[2 * ix[j] + 1], r);
                        if (r.dist < best.dist) best = r, best_face = f;
                    }
                    // A foot on a boundary edge may have a nearer twin on the face across
                    // that edge, whose samples need not be among the nearest few: try it, seeded
                    // by the edge's pcurve there.
                    if (best.edge >= 0) {
                        const cm_cad_model *m = L->model;
                        const int e = best.edge;
                        const double te = best.t;
                        for (int q = m->edge_face_offset[e]; q < m->edge_face_offset[e + 1]; ++q) {
                            int g = m->edge_face[q];
                            if (std::find(tried, tried + ntried, g) != tried + ntried) continue;
                            double pf, pl;
                            Handle(Geom2d_Curve) pc =
                                BRep_Tool::CurveOnSurface(m->edge(e), m->face(g), pf, pl);
                            if (pc.IsNull()) continue;
                            gp_Pnt2d s0 = pc->Value(te);
                            cmcad::foot r;
                            cmcad::project_on_face(a, g, p, s0.X(), s0.Y(), r);
                            if (r.dist < best.dist) best = r, best_face = g;
                        }
                    }
                    if (face) face[i] = best_face;
                    if (uv) uv[2 * i] = best.u, uv[2 * i + 1] = best.v;
                    if (dist) dist[i] = best.dist;
                    if (foot)
                        foot[3 * i] = best.p.X(), foot[3 * i + 1] = best.p.Y(),
                                 foot[3 * i + 2] = best.p.Z();
                } catch (...) {
                    err.capture();
                }
            }
        }
        return err.report(ctx, fn);
    });
}

cm_status cm_cad_locate_edges(cm_context *ctx, const cm_cad_locator *L, const double *xyz,
                              size_t n, int *edge, double *t, double *dist)
{
    const char *fn = "cm_cad_locate_edges";
    if (!L || (n && !xyz)) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL locator or xyz", fn);
    if (n == 0) return CM_OK;
    if (!L->etree) return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: the model has no edges", fn);
    const int k = (int)std::min<size_t>(6, L->eedge.size());
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        std::vector<int64_t> idx(n * (size_t)k);
        std::vector<double> d2(n * (size_t)k);
        cm_status st = cm_kdtree_nearest(ctx, L->etree, xyz, n, k, idx.data(), d2.data());
        if (st != CM_OK) return st;
        cmcad::region_error err;
        const double h = L->h;
#pragma omp parallel num_threads(cm_context_threads_for(ctx, n, 64)) if (n > 64)
        {
            cmcad::adaptors a(L->model);
#pragma omp for schedule(static)
            for (long i = 0; i < (long)n; ++i) {
                try {
                    gp_Pnt p(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]), q;
                    const int64_t *ix = &idx[(size_t)i * k];
                    const double *dd = &d2[(size_t)i * k];
                    double reach = std::sqrt(dd[0]) + 2 * h;
                    int tried[4], ntried = 0, be = -1;
                    double bd = std::numeric_limits<double>::infinity(), bt = 0;
                    for (int j = 0; j < k && ntried < 4; ++j) {
                        if (std::sqrt(dd[j]) > reach) break;
                        int e = L->eedge[ix[j]];
                        if (std::find(tried, tried + ntried, e) != tried + ntried) continue;
                        tried[ntried++] = e;
                        double te;
                        double d = cmcad::project_on_edge(a, e, p, L->et[ix[j]], te, q);
                        if (d < bd) bd = d, bt = te, be = e;
                    }
                    if (edge) edge[i] = be;
                    if (t) t[i] = bt;
                    if (dist) dist[i] = bd;
                } catch (...) {
                    err.capture();
                }
            }
        }
        return err.report(ctx, fn);
    });
}

cm_status cm_cad_locate_vertices(cm_context *ctx, const cm_cad_locator *L, const double *xyz,
                                 size_t n, int *vertex, double *dist)
{
    const char *fn = "cm_cad_locate_vertices";
    if (!L || (n && !xyz)) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL locator or xyz", fn);
    if (n == 0) return CM_OK;
    if (!L->vtree) return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: the model has no vertices", fn);
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        std::vector<int64_t> idx(n);
        std::vector<double> d2(n);
        cm_status st = cm_kdtree_nearest(ctx, L->vtree, xyz, n, 1, idx.data(), d2.data());
        if (st != CM_OK) return st;
        for (size_t i = 0; i < n; ++i) {
            if (vertex) vertex[i] = (int)idx[i];
            if (dist) dist[i] = std::sqrt(d2[i]);
        }
        return CM_OK;
    });
}

}  // extern "C"
