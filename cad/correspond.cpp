// The correspondence of G and G' as graphs (paper section 4: "the topology of G stays
// constant", which a CAD system's re-export does not keep in its numbering): faces, wires,
// oriented edges and vertices are matched as two combinatorial maps. A dart is one use of an
// edge in a wire of a face; a matched pair of darts fixes the next darts of both wires and the
// darts on the other side of both edges, so one seed pair fixes a whole connected shell. The
// seed is the identity (a CAD edit keeps the numbering), else the candidate whose propagated
// match is geometrically closest (distance of vertices and face centres relative to the model
// size). Then G' can be renumbered in place so that everything downstream indexes it by G.
#include "cad_internal.hxx"

#include <algorithm>
#include <array>
#include <map>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numeric>
#include <string>
#include <vector>

namespace {

// One model as a combinatorial map. Edge direction and dart orientation are taken in the
// model's reference direction (OpenCASCADE's unless the edge is marked flipped).
struct topo {
    const cm_cad_model *m = nullptr;
    int nf = 0, ne = 0, nv = 0, nw = 0, nd = 0;
    std::vector<int> ev0, ev1;                        // edge -> first, last vertex
    std::vector<int> dface, dwire, dpos, dedge, drev;  // darts
    std::vector<int> wfirst, wlen, wface, wlocal;     // wires (global index)
    std::vector<int> eoff, edart;                     // edge -> its darts
    std::vector<int> fdarts;                          // darts per face

    explicit topo(const cm_cad_model *model) : m(model)
    {
        nf = m->counts.faces, ne = m->counts.edges, nv = m->counts.vertices;
        nw = (int)m->wire_offset.size() - 1;
        ev0.resize(ne), ev1.resize(ne);
        for (int e = 0; e < ne; ++e) {
            const cm_cad_edge_info &ei = m->edge_info[e];
            ev0[e] = ei.flipped ? ei.vertex[1] : ei.vertex[0];
            ev1[e] = ei.flipped ? ei.vertex[0] : ei.vertex[1];
        }
        fdarts.assign(nf, 0);
        for (int f = 0; f < nf; ++f)
            for (int w = m->face_wire_offset[f]; w < m->face_wire_offset[f + 1]; ++w) {
                wfirst.push_back((int)dface.size());
                wlen.push_back(m->wire_offset[w + 1] - m->wire_offset[w]);
                wface.push_back(f);
                wlocal.push_back(w - m->face_wire_offset[f]);
                for (int k = m->wire_offset[w]; k < m->wire_offset[w + 1]; ++k) {
                    int e = m->wire_edge[k];
                    dface.push_back(f), dwire.push_back(w), dpos.push_back(k - m->wire_offset[w]);
                    dedge.push_back(e);
                    drev.push_back(m->wire_rev[k] ^ m->edge_info[e].flipped);
                    ++fdarts[f];
                }
            }
        nd = (int)dface.size();
        eoff.assign(ne + 1, 0);
        for (int d = 0; d < nd; ++d) ++eoff[dedge[d] + 1];
        for (int e = 0; e < ne; ++e) eoff[e + 1] += eoff[e];
        edart.resize(nd);
        std::vector<int> fill(eoff.begin(), eoff.end() - 1);
        for (int d = 0; d < nd; ++d) edart[fill[dedge[d]]++] = d;
    }
    int next(int d) const { return wfirst[dwire[d]] + (dpos[d] + 1) % wlen[dwire[d]]; }
    int degree(int e) const { return eoff[e + 1] - eoff[e]; }
    int start(int d) const { return drev[d] ? ev1[dedge[d]] : ev0[dedge[d]]; }
    int end(int d) const { return drev[d] ? ev0[dedge[d]] : ev1[dedge[d]]; }
    bool degenerate(int e) const { return m->edge_info[e].degenerate != 0; }
    const double *fc(int f) const { return &m->face_center[3 * (size_t)f]; }
    const double *em(int e) const { return &m->edge_mid[3 * (size_t)e]; }
    const double *vx(int v) const { return &m->vertex_xyz[3 * (size_t)v]; }
};

double dist3(const double *a, const double *b)
{
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
}

// A (partial) correspondence G -> G' and its inverse for every kind; wrot: the rotation of a
// matched wire (position in G' = position in G + wrot, modulo the length).
struct state {
    std::vector<int> d, dinv, f, finv, e, einv, eflip, v, vinv, w, winv, wrot;
    double cost = 0;  // sum of distances of matched vertices and face centres
    long ncost = 0;
    state(const topo &A, const topo &B)
        : d(A.nd, -1), dinv(B.nd, -1), f(A.nf, -1), finv(B.nf, -1), e(A.ne, -1), einv(B.ne, -1),
          eflip(A.ne, 0), v(A.nv, -1), vinv(B.nv, -1), w(A.nw, -1), winv(B.nw, -1), wrot(A.nw, 0)
    {
    }
};

bool vertex_ok(const state &s, int x, int y)
{
    if (x < 0 || y < 0) return x < 0 && y < 0;
    return s.v[x] == y || (s.v[x] < 0 && s.vinv[y] < 0);
}

void set_vertex(const topo &A, const topo &B, state &s, int x, int y)
{
    if (x < 0 || s.v[x] >= 0) return;
    s.v[x] = y, s.vinv[y] = x;
    s.cost += dist3(A.vx(x), B.vx(y)), ++s.ncost;
}

// Propagates from the seed pair (a0, b0). Returns the number of darts matched; conflicts:
// pairs that the propagation proposed and the topology refused.
long propagate(const topo &A, const topo &B, state &s, int a0, int b0, long &conflicts)
{
    long matched = 0;
    std::vector<std::pair<int, int>> queue{{a0, b0}};
    while (!queue.empty()) {
        auto [a, b] = queue.back();
        queue.pop_back();
        if (s.d[a] == b) continue;
        if (s.d[a] >= 0 || s.dinv[b] >= 0) {
            ++conflicts;
            continue;
        }
        const int wa = A.dwire[a], wb = B.dwire[b], fa = A.dface[a], fb = B.dface[b];
        const int ea = A.dedge[a], eb = B.dedge[b], flip = A.drev[a] ^ B.drev[b];
        const int rot = ((B.dpos[b] - A.dpos[a]) % B.wlen[wb] + B.wlen[wb]) % B.wlen[wb];
        bool ok = A.wlen[wa] == B.wlen[wb] && A.degenerate(ea) == B.degenerate(eb) &&
                  A.degree(ea) == B.degree(eb);
        ok = ok && (s.f[fa] == fb || (s.f[fa] < 0 && s.finv[fb] < 0));
        ok = ok && (s.w[wa] == wb ? s.wrot[wa] == rot : s.w[wa] < 0 && s.winv[wb] < 0);
        ok = ok && (s.e[ea] == eb ? s.eflip[ea] == flip : s.e[ea] < 0 && s.einv[eb] < 0);
        const int sa = A.start(a), sb = B.start(b), ta = A.end(a), tb = B.end(b);
        ok = ok && vertex_ok(s, sa, sb) && vertex_ok(s, ta, tb) && ((sa == ta) == (sb == tb));
        if (!ok) {
            ++conflicts;
            continue;
        }
        s.d[a] = b, s.dinv[b] = a, ++matched;
        if (s.f[fa] < 0) {
            s.f[fa] = fb, s.finv[fb] = fa;
            s.cost += dist3(A.fc(fa), B.fc(fb)), ++s.ncost;
        }
        if (s.w[wa] < 0) s.w[wa] = wb, s.winv[wb] = wa, s.wrot[wa] = rot;
        if (s.e[ea] < 0) s.e[ea] = eb, s.einv[eb] = ea, s.eflip[ea] = flip;
        set_vertex(A, B, s, sa, sb);
        set_vertex(A, B, s, ta, tb);
        queue.push_back({A.next(a), B.next(b)});
        // The other uses of the edge: across a manifold edge (or a seam) the one other dart;
        // on a non-manifold edge each use goes to the use of the same orientation whose face
        // is matched to its face, else whose face centre is nearest.
        for (int i = A.eoff[ea]; i < A.eoff[ea + 1]; ++i) {
            int x = A.edart[i];
            if (x == a || s.d[x] >= 0) continue;
            int best = -1;
            double bd = 0;
            for (int j = B.eoff[eb]; j < B.eoff[eb + 1]; ++j) {
                int y = B.edart[j];
                if (y == b || s.dinv[y] >= 0 || (A.drev[x] ^ flip) != B.drev[y]) continue;
                int fx = A.dface[x], fy = B.dface[y];
                double dd = s.f[fx] == fy ? -1.0 : dist3(A.fc(fx), B.fc(fy));
                if (best < 0 || dd < bd) best = y, bd = dd;
            }
            if (best >= 0) queue.push_back({x, best});
        }
    }
    return matched;
}

// What a seed must share with its counterpart: wire length, the edge's degeneracy and number
// of uses (not the face's wire count: a hole added in G' changes it, and the seed must still
// find the face).
bool seed_compatible(const topo &A, const topo &B, int a, int b)
{
    return A.wlen[A.dwire[a]] == B.wlen[B.dwire[b]] &&
           A.degenerate(A.dedge[a]) == B.degenerate(B.dedge[b]) &&
           A.degree(A.dedge[a]) == B.degree(B.dedge[b]);
}

// Connected components of G's darts (next and the other uses of each edge).
std::vector<int> components(const topo &A, int &n)
{
    std::vector<int> comp(A.nd, -1);
    n = 0;
    for (int d0 = 0; d0 < A.nd; ++d0) {
        if (comp[d0] >= 0) continue;
        std::vector<int> stack{d0};
        comp[d0] = n;
        while (!stack.empty()) {
            int d = stack.back();
            stack.pop_back();
            int nx = A.next(d);
            if (comp[nx] < 0) comp[nx] = n, stack.push_back(nx);
            int e = A.dedge[d];
            for (int i = A.eoff[e]; i < A.eoff[e + 1]; ++i)
                if (comp[A.edart[i]] < 0) comp[A.edart[i]] = n, stack.push_back(A.edart[i]);
        }
        ++n;
    }
    return comp;
}

const int max_trials = 256;

// Matches the darts of every component of G, seed by seed.
void match_darts(const topo &A, const topo &B, state &s, double diag)
{
    int ncomp = 0;
    std::vector<int> comp = components(A, ncomp);
    std::vector<char> tried(A.nd, 0);
    for (int c = 0; c < ncomp; ++c) {
        for (int round = 0; round < 1000; ++round) {
            // the unmatched dart of the component whose kind is rarest among the unmatched
            // darts of G' (fewest trials)
            std::map<std::array<int, 3>, int> kinds;
            auto kind = [](const topo &T, int d) {
                return std::array<int, 3>{T.wlen[T.dwire[d]], (int)T.degenerate(T.dedge[d]),
                                          T.degree(T.dedge[d])};
            };
            for (int b = 0; b < B.nd; ++b)
                if (s.dinv[b] < 0) ++kinds[kind(B, b)];
            int a0 = -1, fewest = 0;
            for (int a = 0; a < A.nd; ++a) {
                if (comp[a] != c || s.d[a] >= 0 || tried[a]) continue;
                auto it = kinds.find(kind(A, a));
                if (it == kinds.end()) {
                    tried[a] = 1;
                    continue;
                }
                if (a0 < 0 || it->second < fewest) a0 = a, fewest = it->second;
                if (fewest == 1) break;
            }
            if (a0 < 0) break;
            std::vector<int> cand;
            for (int b = 0; b < B.nd; ++b)
                if (s.dinv[b] < 0 && seed_compatible(A, B, a0, b)) cand.push_back(b);
            tried[a0] = 1;
            long remaining = 0;
            for (int a = 0; a < A.nd; ++a) remaining += comp[a] == c && s.d[a] < 0;
            // identity first (same face, wire and position), then the nearest by geometry
            const int fa = A.dface[a0], ea = A.dedge[a0];
            auto is_identity = [&](int b) {
                return B.dface[b] == fa && B.dwire[b] == A.dwire[a0] && B.dpos[b] == A.dpos[a0];
            };
            auto geo = [&](int b) {
                return dist3(A.em(ea), B.em(B.dedge[b])) + dist3(A.fc(fa), B.fc(B.dface[b]));
            };
            std::vector<double> key(B.nd, 0);
            for (int b : cand) key[b] = is_identity(b) ? -1.0 : geo(b);
            std::stable_sort(cand.begin(), cand.end(),
                             [&](int x, int y) { return key[x] < key[y]; });
            if ((int)cand.size() > max_trials) cand.resize(max_trials);
            // The best trial: most darts matched (less conflicts), then the nearest. The
            // identity (a CAD edit keeps the numbering) wins unless another is clearly nearer.
            state best = s, ident = s;
            long best_score = -1, ident_score = -1;
            double best_cost = 0, ident_cost = 0;
            for (int b : cand) {
                state t = s;
                t.cost = 0, t.ncost = 0;
                long conflicts = 0;
                long matched = propagate(A, B, t, a0, b, conflicts);
                long score = matched - conflicts;
                double cost = t.ncost ? t.cost / (double)t.ncost / std::max(diag, 1e-300) : 0;
                const bool perfect = matched == remaining && conflicts == 0;
                if (key[b] < 0) {
                    ident_score = score, ident_cost = cost;
                    ident = t;
                }
                if (score > best_score || (score == best_score && cost < best_cost)) {
                    best_score = score, best_cost = cost;
                    best = std::move(t);
                }
                if (perfect && cost < 1e-9) break;  // the same geometry: nothing nearer
            }
            // How far the identity may be off: a parametric edit moves every entity (the ones
            // matched so far show by how much), a renumbered file of the same shape none. A
            // group that only geometry can place (a hole among equal holes) then follows the
            // numbering of an edit that moved the rest as far, and the geometry of a file that
            // moved nothing.
            const double moved = s.ncost ? s.cost / (double)s.ncost / std::max(diag, 1e-300) : 0;
            if (ident_score >= 0 && ident_score == best_score &&
                ident_cost <= 2 * best_cost + 2 * moved + 0.01)
                best = std::move(ident);
            double keep_cost = s.cost;
            long keep_n = s.ncost;
            s = std::move(best);
            s.cost += keep_cost, s.ncost += keep_n;
        }
    }
}

// Entities no dart reaches (faces without wires, edges in no face, isolated vertices): the
// nearest unmatched counterpart of the same kind.
void match_leftovers(const topo &A, const topo &B, state &s)
{
    for (int f = 0; f < A.nf; ++f) {
        if (s.f[f] >= 0 || A.fdarts[f]) continue;
        int best = -1;
        double bd = 0;
        for (int g = 0; g < B.nf; ++g) {
            if (s.finv[g] >= 0 || B.fdarts[g]) continue;
            double d = dist3(A.fc(f), B.fc(g));
            if (best < 0 || d < bd) best = g, bd = d;
        }
        if (best >= 0) s.f[f] = best, s.finv[best] = f;
    }
    for (int e = 0; e < A.ne; ++e) {
        if (s.e[e] >= 0 || A.degree(e)) continue;
        int best = -1;
        double bd = 0;
        for (int g = 0; g < B.ne; ++g) {
            if (s.einv[g] >= 0 || B.degree(g) || A.degenerate(e) != B.degenerate(g)) continue;
            double d = dist3(A.em(e), B.em(g));
            if (best < 0 || d < bd) best = g, bd = d;
        }
        if (best < 0) continue;
        // the direction: which way round puts the vertices nearer
        int a0 = A.ev0[e], a1 = A.ev1[e], b0 = B.ev0[best], b1 = B.ev1[best];
        int flip = 0;
        if (a0 >= 0 && a1 >= 0 && b0 >= 0 && b1 >= 0)
            flip = dist3(A.vx(a0), B.vx(b1)) + dist3(A.vx(a1), B.vx(b0)) <
                   dist3(A.vx(a0), B.vx(b0)) + dist3(A.vx(a1), B.vx(b1));
        int y0 = flip ? b1 : b0, y1 = flip ? b0 : b1;
        if (!vertex_ok(s, a0, y0) || !vertex_ok(s, a1, y1)) continue;
        s.e[e] = best, s.einv[best] = e, s.eflip[e] = flip;
        set_vertex(A, B, s, a0, y0);
        set_vertex(A, B, s, a1, y1);
    }
    for (int v = 0; v < A.nv; ++v) {
        if (s.v[v] >= 0) continue;
        int best = -1;
        double bd = 0;
        for (int g = 0; g < B.nv; ++g) {
            if (s.vinv[g] >= 0) continue;
            double d = dist3(A.vx(v), B.vx(g));
            if (best < 0 || d < bd) best = g, bd = d;
        }
        if (best >= 0) s.v[v] = best, s.vinv[best] = v;
    }
}

std::string face_words(const topo &T, int f)
{
    const cm_cad_face_info &fi = T.m->face_info[f];
    char b[128];
    int holes = fi.n_wires > 1 ? fi.n_wires - 1 : 0;
    snprintf(b, sizeof b, "%s, %d edge%s%s", cm_cad_surface_type_name(fi.type), T.fdarts[f],
             T.fdarts[f] == 1 ? "" : "s",
             holes == 0 ? "" : holes == 1 ? ", 1 hole" : (", " + std::to_string(holes) + " holes").c_str());
    return b;
}

std::string edge_words(const topo &T, int e)
{
    const cm_cad_edge_info &ei = T.m->edge_info[e];
    char b[96];
    snprintf(b, sizeof b, "%s, length %.4g",
             ei.degenerate ? "degenerate" : cm_cad_curve_type_name(ei.type), ei.length);
    return b;
}

// The differences that remain after matching, in words; empty if the topologies correspond.
std::vector<std::string> differences(const topo &A, const topo &B, const state &s)
{
    std::vector<std::string> out;
    char line[512];
    std::vector<char> g2_face_explained(B.nf, 0);
    for (int f = 0; f < A.nf; ++f) {
        int g = s.f[f];
        if (g < 0) {
            snprintf(line, sizeof line, "face %d (%s) has no counterpart in G'", f,
                     face_words(A, f).c_str());
            out.push_back(line);
            continue;
        }
        int wa = A.m->face_info[f].n_wires, wb = B.m->face_info[g].n_wires;
        // wires of f whose darts are not all matched to darts of g
        int bad_wire = -1;
        for (int w = A.m->face_wire_offset[f]; w < A.m->face_wire_offset[f + 1] && bad_wire < 0; ++w) {
            int b = s.w[w];
            if (b < 0 || B.wface[b] != g) bad_wire = w;
            for (int k = 0; k < A.wlen[w] && bad_wire < 0; ++k)
                if (s.d[A.wfirst[w] + k] < 0) bad_wire = w;
        }
        if (wb > wa) {
            // the faces of G' behind the extra wires: the hole's walls
            std::string walls;
            for (int w = B.m->face_wire_offset[g]; w < B.m->face_wire_offset[g + 1]; ++w) {
                if (s.winv[w] >= 0) continue;
                for (int k = 0; k < B.wlen[w]; ++k) {
                    int e = B.dedge[B.wfirst[w] + k];
                    for (int i = B.eoff[e]; i < B.eoff[e + 1]; ++i) {
                        int h = B.dface[B.edart[i]];
                        if (h == g || s.finv[h] >= 0 || g2_face_explained[h]) continue;
                        g2_face_explained[h] = 1;
                        walls += (walls.empty() ? "" : ", ") + std::to_string(h) + " (" +
                                 cm_cad_surface_type_name(B.m->face_info[h].type) + ")";
                    }
                }
            }
            snprintf(line, sizeof line, "face %d (%s) has no counterpart: G' has %s there%s%s%s", f,
                     face_words(A, f).c_str(),
                     wb - wa == 1 ? "a hole" : (std::to_string(wb - wa) + " holes").c_str(),
                     walls.empty() ? "" : " (face ", walls.c_str(), walls.empty() ? "" : " of G')");
            out.push_back(line);
        } else if (wb < wa) {
            snprintf(line, sizeof line,
                     "face %d (%s) has no counterpart: G' has %s there (face %d of G' has %d wire%s)",
                     f, face_words(A, f).c_str(),
                     wa - wb == 1 ? "no hole" : ("no " + std::to_string(wa - wb) + " holes").c_str(),
                     g, wb, wb == 1 ? "" : "s");
            out.push_back(line);
        } else if (bad_wire >= 0) {
            int b = s.w[bad_wire];
            std::string other = b >= 0 ? " (" + std::to_string(B.wlen[b]) + " edges there)" : "";
            snprintf(line, sizeof line,
                     "face %d (%s) has no counterpart: its %s wire (%d edges) differs in face %d of G'%s",
                     f, face_words(A, f).c_str(), A.wlocal[bad_wire] == 0 ? "outer" : "inner",
                     A.wlen[bad_wire], g, other.c_str());
            out.push_back(line);
        }
        if (A.m->face_shell[f] >= 0 && B.m->face_shell[g] < 0) {
            snprintf(line, sizeof line, "face %d (%s) lies in a shell in G, in none in G'", f,
                     face_words(A, f).c_str());
            out.push_back(line);
        }
    }
    for (int g = 0; g < B.nf; ++g)
        if (s.finv[g] < 0 && !g2_face_explained[g]) {
            snprintf(line, sizeof line, "face %d of G' (%s) has no counterpart in G", g,
                     face_words(B, g).c_str());
            out.push_back(line);
        }
    const bool faces_differ = !out.empty();
    // edges and vertices only when no face explains them
    if (!faces_differ) {
        for (int e = 0; e < A.ne; ++e)
            if (s.e[e] < 0) {
                snprintf(line, sizeof line, "edge %d (%s) has no counterpart in G'", e,
                         edge_words(A, e).c_str());
                out.push_back(line);
            } else {
                int g = s.e[e];
                int y0 = s.eflip[e] ? B.ev1[g] : B.ev0[g], y1 = s.eflip[e] ? B.ev0[g] : B.ev1[g];
                int a0 = A.ev0[e], a1 = A.ev1[e];
                bool ok = (a0 < 0 ? y0 < 0 : s.v[a0] == y0) && (a1 < 0 ? y1 < 0 : s.v[a1] == y1);
                if (!ok) {
                    snprintf(line, sizeof line, "edge %d (%s) joins other vertices in G' (edge %d)",
                             e, edge_words(A, e).c_str(), g);
                    out.push_back(line);
                }
            }
        for (int g = 0; g < B.ne; ++g)
            if (s.einv[g] < 0) {
                snprintf(line, sizeof line, "edge %d of G' (%s) has no counterpart in G", g,
                         edge_words(B, g).c_str());
                out.push_back(line);
            }
        for (int v = 0; v < A.nv; ++v)
            if (s.v[v] < 0) {
                snprintf(line, sizeof line, "vertex %d has no counterpart in G'", v);
                out.push_back(line);
            }
        for (int g = 0; g < B.nv; ++g)
            if (s.vinv[g] < 0) {
                snprintf(line, sizeof line, "vertex %d of G' has no counterpart in G", g);
                out.push_back(line);
            }
    }
    if (out.empty()) {
        // shells and solids: the faces of a shell of G lie in one shell of G', one to one
        const int ns = A.m->counts.shells, ns2 = B.m->counts.shells;
        std::vector<int> smap(ns, -2), sinv(ns2, -2);
        for (int f = 0; f < A.nf; ++f) {
            int a = A.m->face_shell[f], b = B.m->face_shell[s.f[f]];
            if (a < 0 || b < 0) continue;
            if (smap[a] == -2 && sinv[b] == -2) {
                smap[a] = b, sinv[b] = a;
            } else if (smap[a] != b) {
                snprintf(line, sizeof line,
                         "face %d (%s) lies in shell %d of G, whose other faces lie in another "
                         "shell of G'", f, face_words(A, f).c_str(), a);
                out.push_back(line);
                break;
            }
        }
        const int nsol = A.m->counts.solids, nsol2 = B.m->counts.solids;
        std::vector<int> somap(nsol, -2), soinv(nsol2, -2);
        for (int a = 0; a < ns && out.empty(); ++a) {
            if (smap[a] < 0) continue;
            int x = A.m->shell_solid[a], y = B.m->shell_solid[smap[a]];
            if ((x < 0) != (y < 0)) {
                snprintf(line, sizeof line, "shell %d bounds a solid in %s only", a,
                         x < 0 ? "G'" : "G");
                out.push_back(line);
            } else if (x >= 0) {
                if (somap[x] == -2 && soinv[y] == -2)
                    somap[x] = y, soinv[y] = x;
                else if (somap[x] != y) {
                    snprintf(line, sizeof line, "solid %d of G is split over several solids of G'",
                             x);
                    out.push_back(line);
                }
            }
        }
    }
    return out;
}

double diagonal(const double *b)
{
    return std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) +
                     (b[5] - b[2]) * (b[5] - b[2]));
}

// The whole correspondence with its verdict. On success fills s; diffs empty.
struct result {
    std::vector<std::string> diffs, counts;
    bool renumbered = false;
};

void find(const cm_cad_model *g, const cm_cad_model *g2, state &s, const topo &A, const topo &B,
          result &r)
{
    const cm_cad_counts &a = g->counts, &b = g2->counts;
    const struct {
        const char *name;
        int x, y;
    } counts[] = {{"solids", a.solids, b.solids}, {"shells", a.shells, b.shells},
                  {"faces", a.faces, b.faces},    {"wires", a.wires, b.wires},
                  {"edges", a.edges, b.edges},    {"vertices", a.vertices, b.vertices}};
    char line[128];
    for (const auto &c : counts)
        if (c.x != c.y) {
            snprintf(line, sizeof line, "%s: %d in G, %d in G'", c.name, c.x, c.y);
            r.counts.push_back(line);
        }
    match_darts(A, B, s, diagonal(g->bbox));
    match_leftovers(A, B, s);
    r.diffs = differences(A, B, s);
    if (!r.diffs.empty() || !r.counts.empty()) return;
    for (int f = 0; f < A.nf && !r.renumbered; ++f) r.renumbered = s.f[f] != f;
    for (int e = 0; e < A.ne && !r.renumbered; ++e) r.renumbered = s.e[e] != e || s.eflip[e];
    for (int v = 0; v < A.nv && !r.renumbered; ++v) r.renumbered = s.v[v] != v;
    for (int w = 0; w < A.nw && !r.renumbered; ++w) r.renumbered = s.w[w] != w || s.wrot[w];
}

// The size check of G and G' (kept from the index comparison): a file in mm against the same
// numbers declared in m morphs to a x1000 result.
cm_status check_sizes(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2)
{
    const double d1 = diagonal(g->bbox), d2 = diagonal(g2->bbox);
    const double ratio = d1 > 0 && d2 > 0 ? std::max(d1 / d2, d2 / d1) : 1.0;
    if (ratio >= 100)
        return cm_error(ctx, CM_ERR_MISMATCH,
                        "%s and %s: G and G' differ in size by %.3gx (bounding-box diagonals %g and %g "
                        "%s; file units %s and %s): check the units of the STEP files",
                        g->path.c_str(), g2->path.c_str(), ratio, d1, d2, g->unit.c_str(),
                        g->file_unit.c_str(), g2->file_unit.c_str());
    if (g->file_unit != g2->file_unit)
        cm_log(ctx, CM_LOG_WARNING,
               "G is in %s, G' in %s (both read as %s): check that this is intended",
               g->file_unit.c_str(), g2->file_unit.c_str(), g->unit.c_str());
    return CM_OK;
}

cm_status report(cm_context *ctx, const result &r, int max_report)
{
    size_t total = r.diffs.size() + r.counts.size();
    std::string msg = "topology of G and G' differs (" + std::to_string(total) +
                      (total == 1 ? " difference): " : " differences): ");
    size_t shown = 0;
    for (size_t i = 0; i < r.diffs.size() && (int)i < max_report; ++i, ++shown)
        msg += (shown ? "; " : "") + r.diffs[i];
    if (r.diffs.size() > (size_t)max_report) msg += "; ...", ++shown;
    for (const std::string &c : r.counts) msg += (shown++ ? "; " : "") + c;
    return cm_error(ctx, CM_ERR_MISMATCH, "%s", msg.c_str());
}

// Type changes, one debug line each (shown under --verbose), and their counts.
void log_type_changes(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                      const state &s, cm_cad_correspondence *c)
{
    for (int f = 0; f < g->counts.faces; ++f) {
        cm_cad_surface_type x = g->face_info[f].type, y = g2->face_info[s.f[f]].type;
        if (x == y) continue;
        ++c->face_type_changes;
        cm_log(ctx, CM_LOG_DEBUG, "correspondence: face %d: %s in G, %s in G' (face %d)", f,
               cm_cad_surface_type_name(x), cm_cad_surface_type_name(y), s.f[f]);
    }
    for (int e = 0; e < g->counts.edges; ++e) {
        const cm_cad_edge_info &x = g->edge_info[e], &y = g2->edge_info[s.e[e]];
        if (x.type == y.type) continue;
        ++c->edge_type_changes;
        cm_log(ctx, CM_LOG_DEBUG, "correspondence: edge %d: %s in G, %s in G' (edge %d)", e,
               x.degenerate ? "degenerate" : cm_cad_curve_type_name(x.type),
               y.degenerate ? "degenerate" : cm_cad_curve_type_name(y.type), s.e[e]);
    }
    if (c->face_type_changes || c->edge_type_changes)
        cm_log(ctx, CM_LOG_DEBUG,
               "correspondence: %d faces and %d edges change their surface or curve type",
               c->face_type_changes, c->edge_type_changes);
}

// Renumbers g2 in place by the state (G -> G').
void renumber(const topo &A, const topo &B, const state &s, cm_cad_model *g2)
{
    const cm_cad_model *g = A.m;
    const int nf = A.nf, ne = A.ne, nv = A.nv;
    TopTools_IndexedMapOfShape faces, edges, vertices;
    for (int f = 0; f < nf; ++f) faces.Add(g2->faces(s.f[f] + 1));
    for (int e = 0; e < ne; ++e) edges.Add(g2->edges(s.e[e] + 1));
    for (int v = 0; v < nv; ++v) vertices.Add(g2->vertices(s.v[v] + 1));
    std::vector<cm_cad_face_info> face_info(nf);
    std::vector<double> face_center(3 * (size_t)nf), edge_mid(3 * (size_t)ne),
        vertex_xyz(3 * (size_t)nv);
    std::vector<int> face_shell(nf);
    for (int f = 0; f < nf; ++f) {
        face_info[f] = g2->face_info[s.f[f]];
        face_shell[f] = g2->face_shell[s.f[f]];
        std::copy_n(&g2->face_center[3 * (size_t)s.f[f]], 3, &face_center[3 * (size_t)f]);
    }
    std::vector<cm_cad_edge_info> edge_info(ne);
    for (int e = 0; e < ne; ++e) {
        cm_cad_edge_info ei = g2->edge_info[s.e[e]];
        for (int k = 0; k < 2; ++k) ei.vertex[k] = ei.vertex[k] < 0 ? -1 : s.vinv[ei.vertex[k]];
        ei.flipped = ei.flipped ^ s.eflip[e];
        edge_info[e] = ei;
        std::copy_n(&g2->edge_mid[3 * (size_t)s.e[e]], 3, &edge_mid[3 * (size_t)e]);
    }
    for (int v = 0; v < nv; ++v)
        std::copy_n(&g2->vertex_xyz[3 * (size_t)s.v[v]], 3, &vertex_xyz[3 * (size_t)v]);
    // wires in G's order, each from the counterpart of G's first dart; reversed flags stay
    // OpenCASCADE's (they pick the pcurve of a seam)
    std::vector<int> face_wire_offset{0}, wire_offset{0}, wire_edge, wire_rev;
    for (int f = 0; f < nf; ++f) {
        for (int w = g->face_wire_offset[f]; w < g->face_wire_offset[f + 1]; ++w) {
            int b = s.w[w], len = B.wlen[b];
            for (int k = 0; k < len; ++k) {
                int pos = (k + s.wrot[w]) % len;
                int kk = g2->wire_offset[b] + pos;
                wire_edge.push_back(s.einv[g2->wire_edge[kk]]);
                wire_rev.push_back(g2->wire_rev[kk]);
            }
            wire_offset.push_back((int)wire_edge.size());
        }
        face_wire_offset.push_back((int)wire_offset.size() - 1);
    }
    std::vector<int> edge_face_offset{0}, edge_face;
    for (int e = 0; e < ne; ++e) {
        int o = s.e[e];
        for (int i = g2->edge_face_offset[o]; i < g2->edge_face_offset[o + 1]; ++i)
            edge_face.push_back(s.finv[g2->edge_face[i]]);
        edge_face_offset.push_back((int)edge_face.size());
    }
    g2->faces = std::move(faces);
    g2->edges = std::move(edges);
    g2->vertices = std::move(vertices);
    g2->face_info = std::move(face_info);
    g2->edge_info = std::move(edge_info);
    g2->vertex_xyz = std::move(vertex_xyz);
    g2->face_center = std::move(face_center);
    g2->edge_mid = std::move(edge_mid);
    g2->face_shell = std::move(face_shell);
    g2->face_wire_offset = std::move(face_wire_offset);
    g2->wire_offset = std::move(wire_offset);
    g2->wire_edge = std::move(wire_edge);
    g2->wire_rev = std::move(wire_rev);
    g2->edge_face_offset = std::move(edge_face_offset);
    g2->edge_face = std::move(edge_face);
}

cm_cad_correspondence *make_result(const cm_cad_model *g, const cm_cad_model *g2, const state &s,
                                   bool renumbered)
{
    cm_cad_correspondence *c = (cm_cad_correspondence *)calloc(1, sizeof *c);
    if (!c) throw std::bad_alloc();
    c->counts = g->counts;
    const size_t nf = (size_t)g->counts.faces, ne = (size_t)g->counts.edges,
                 nv = (size_t)g->counts.vertices;
    c->face = (int *)malloc(nf * sizeof(int) + 1);
    c->face_reversed = (int *)malloc(nf * sizeof(int) + 1);
    c->edge = (int *)malloc(ne * sizeof(int) + 1);
    c->edge_flipped = (int *)malloc(ne * sizeof(int) + 1);
    c->vertex = (int *)malloc(nv * sizeof(int) + 1);
    if (!c->face || !c->face_reversed || !c->edge || !c->edge_flipped || !c->vertex) {
        cm_cad_correspondence_destroy(&c);
        throw std::bad_alloc();
    }
    for (size_t f = 0; f < nf; ++f) {
        c->face[f] = s.f[f];
        c->face_reversed[f] = g->face_info[f].reversed != g2->face_info[s.f[f]].reversed;
    }
    for (size_t e = 0; e < ne; ++e) c->edge[e] = s.e[e], c->edge_flipped[e] = s.eflip[e];
    for (size_t v = 0; v < nv; ++v) c->vertex[v] = s.v[v];
    c->renumbered = renumbered;
    for (size_t w = 0; w < s.w.size(); ++w) c->wires_restarted += s.w[w] != (int)w || s.wrot[w] != 0;
    return c;
}

// cm_cad_correspond and cm_cad_match: g2_out non-NULL renumbers it.
cm_status correspond(cm_context *ctx, const char *fn, const cm_cad_model *g,
                     const cm_cad_model *g2, cm_cad_model *g2_out, int max_report,
                     cm_cad_correspondence **out, bool need_identity)
{
    if (out) *out = nullptr;
    if (!g || !g2) return cm_error(ctx, CM_ERR_ARGUMENT, "%s: NULL model", fn);
    if (max_report < 1) max_report = 1;
    return cmcad::guard(ctx, fn, [&]() -> cm_status {
        topo A(g), B(g2);
        state s(A, B);
        result r;
        find(g, g2, s, A, B, r);
        if (!r.diffs.empty() || !r.counts.empty()) return report(ctx, r, max_report);
        cm_status st = check_sizes(ctx, g, g2);
        if (st != CM_OK) return st;
        if (need_identity && r.renumbered) {
            int nf = 0, ne = 0;
            for (int f = 0; f < A.nf; ++f) nf += s.f[f] != f;
            for (int e = 0; e < A.ne; ++e) ne += s.e[e] != e || s.eflip[e];
            return cm_error(ctx, CM_ERR_MISMATCH,
                            "G' corresponds to G only with another numbering (%d faces, %d edges "
                            "renumbered or reversed): renumber it with cm_cad_match first",
                            nf, ne);
        }
        std::unique_ptr<cm_cad_correspondence, void (*)(cm_cad_correspondence *)> c(
            make_result(g, g2, s, r.renumbered),
            [](cm_cad_correspondence *p) { cm_cad_correspondence_destroy(&p); });
        log_type_changes(ctx, g, g2, s, c.get());
        if (r.renumbered)
            cm_log(ctx, CM_LOG_DEBUG, "correspondence: G' is numbered otherwise than G%s",
                   g2_out ? ": renumbered" : "");
        if (g2_out && r.renumbered) renumber(A, B, s, g2_out);
        if (out) *out = c.release();
        return CM_OK;
    });
}

}  // namespace

extern "C" {

cm_status cm_cad_correspond(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                            int max_report, cm_cad_correspondence **out)
{
    return correspond(ctx, "cm_cad_correspond", g, g2, nullptr, max_report, out, false);
}

cm_status cm_cad_match(cm_context *ctx, const cm_cad_model *g, cm_cad_model *g2, int max_report,
                       cm_cad_correspondence **out)
{
    if (g == g2 && g) {
        // a model against itself: the identity, nothing to renumber
        return correspond(ctx, "cm_cad_match", g, g2, nullptr, max_report, out, false);
    }
    return correspond(ctx, "cm_cad_match", g, g2, g2, max_report, out, false);
}

cm_status cm_cad_compare(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                         int max_report)
{
    return correspond(ctx, "cm_cad_compare", g, g2, nullptr, max_report, nullptr, true);
}

void cm_cad_correspondence_destroy(cm_cad_correspondence **c)
{
    if (!c || !*c) return;
    free((*c)->face), free((*c)->face_reversed), free((*c)->edge), free((*c)->edge_flipped),
        free((*c)->vertex);
    free(*c);
    *c = nullptr;
}

}  // extern "C"
