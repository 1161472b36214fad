// TetGen in a child process: Debian's TetGen 1.5.0 frees its memory pools twice when it gives
// up (terminatetetgen, then ~tetgenmesh), asserts on some valid surfaces and may run for an
// hour, none of which may take cadmorph down. The child builds the tetgenio, runs
// tetrahedralize and writes a record to the pipe: a header, then the arrays.
#include "tetgen_run.h"

#include "child_process.h"

#include <tetgen.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>

namespace {

const uint64_t record_magic = 0x636d74657467656eULL; // "cmtetgen"

struct header {
    uint64_t magic;
    int64_t code; // 0: meshed; TetGen's code when it threw and survived its own error path
    int64_t corners, n_points, n_tets, n_trifaces;
};

struct job {
    const cm_tetgen_plc *plc;
    const char *switches;
};

const char *tetgen_reason(int code)
{
    switch (code) {
    case 1: return "out of memory";
    case 2: return "internal error";
    case 3: return "the surface intersects itself";
    case 4: return "a very small input feature";
    case 5: return "two very close input facets";
    case 10: return "invalid input";
    default: return "unknown error";
    }
}

int write_result(int fd, const tetgenio &out)
{
    header h = {record_magic, 0, out.numberofcorners, out.numberofpoints,
                out.numberoftetrahedra, out.numberoftrifaces};
    if (cm_child_write(fd, &h, sizeof h)) return 3;
    if (h.n_points && cm_child_write(fd, out.pointlist, sizeof(double) * 3 * h.n_points)) return 3;
    // TetGen's int arrays are 32-bit: sent as they are
    static_assert(sizeof(int) == sizeof(int32_t), "TetGen's int is 32-bit");
    if (h.n_tets && cm_child_write(fd, out.tetrahedronlist, sizeof(int) * h.corners * h.n_tets))
        return 3;
    if (h.n_trifaces) {
        if (cm_child_write(fd, out.trifacelist, sizeof(int) * 3 * h.n_trifaces)) return 3;
        if (out.trifacemarkerlist) {
            if (cm_child_write(fd, out.trifacemarkerlist, sizeof(int) * h.n_trifaces)) return 3;
        } else {
            for (int64_t i = 0; i < h.n_trifaces; ++i) {
                const int z = 0;
                if (cm_child_write(fd, &z, sizeof z)) return 3;
            }
        }
    }
    return 0;
}

int child_work(void *arg, int fd)
{
    const job &j = *static_cast<const job *>(arg);
    const cm_tetgen_plc &p = *j.plc;
    try {
        tetgenio in, out;
        in.firstnumber = 0;
        in.numberofpoints = (int)p.n_points;
        in.pointlist = new REAL[3 * p.n_points];
        std::copy(p.xyz, p.xyz + 3 * p.n_points, in.pointlist);
        in.numberoffacets = (int)p.n_triangles;
        in.facetlist = new tetgenio::facet[p.n_triangles];
        in.facetmarkerlist = new int[p.n_triangles];
        for (size_t t = 0; t < p.n_triangles; ++t) {
            tetgenio::facet &f = in.facetlist[t];
            tetgenio::init(&f);
            f.numberofpolygons = 1;
            f.polygonlist = new tetgenio::polygon[1];
            tetgenio::init(&f.polygonlist[0]);
            f.polygonlist[0].numberofvertices = 3;
            f.polygonlist[0].vertexlist = new int[3];
            for (int k = 0; k < 3; ++k) f.polygonlist[0].vertexlist[k] = (int)p.tri[3 * t + k];
            in.facetmarkerlist[t] = p.marker[t];
        }
        std::string sw = j.switches;
        try {
            tetrahedralize(&sw[0], &in, &out);
        } catch (int code) {
            // reached only if TetGen's error path did not crash first
            header h = {record_magic, code, 0, 0, 0, 0};
            return cm_child_write(fd, &h, sizeof h) ? 3 : 0;
        }
        return write_result(fd, out);
    } catch (const std::bad_alloc &) {
        header h = {record_magic, 1, 0, 0, 0, 0};
        return cm_child_write(fd, &h, sizeof h) ? 3 : 0;
    } catch (...) {
        return 4;
    }
}

} // namespace

extern "C" void cm_tetgen_result_free(cm_tetgen_result *r)
{
    if (!r) return;
    std::free(r->xyz);
    std::free(r->tet);
    std::free(r->triface);
    std::free(r->trimarker);
    std::memset(r, 0, sizeof *r);
}

extern "C" cm_status cm_tetgen_run(cm_context *ctx, const char *what, const cm_tetgen_plc *plc,
                                   const char *switches, double time_limit,
                                   cm_tetgen_result *res, int *failure)
{
    std::memset(res, 0, sizeof *res);
    if (failure) *failure = 0;
    if (plc->n_points > INT32_MAX / 3 || plc->n_triangles > INT32_MAX)
        return cm_error(ctx, CM_ERR_UNSUPPORTED, "%s: %zu points, %zu triangles: beyond TetGen's "
                        "32-bit indices", what, plc->n_points, plc->n_triangles);
    job j = {plc, switches};
    char *data = nullptr;
    size_t size = 0;
    cm_child_outcome o;
    cm_status s = cm_child_run(ctx, "TetGen", "tetgen", child_work, &j, time_limit, &data, &size, &o);
    if (s < 0) return s;
    if (o.timed_out || o.signal || o.exit_code != 0) {
        std::free(data);
        char how[700];
        cm_child_describe(&o, how, sizeof how);
        if (failure) *failure = o.timed_out ? 3 : 2;
        return cm_error(ctx, o.timed_out ? CM_ERR_UNSUPPORTED : CM_ERR_NUMERIC,
                        "%s: TetGen %s, switches %s", what, how, switches);
    }
    header h;
    if (size < sizeof h) {
        std::free(data);
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: TetGen's child sent %zu bytes", what, size);
    }
    std::memcpy(&h, data, sizeof h);
    if (h.magic != record_magic) {
        std::free(data);
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: TetGen's child sent no record", what);
    }
    if (h.code != 0) {
        std::free(data);
        if (failure) *failure = 1;
        return cm_error(ctx, h.code == 1 ? CM_ERR_NOMEM : CM_ERR_NUMERIC,
                        "%s: TetGen failed with code %d (%s), switches %s", what, (int)h.code,
                        tetgen_reason((int)h.code), switches);
    }
    const size_t np = (size_t)h.n_points, nt = (size_t)h.n_tets, nf = (size_t)h.n_trifaces,
                 nc = (size_t)h.corners;
    const size_t need = sizeof h + 8 * 3 * np + 4 * nc * nt + 4 * 4 * nf;
    if (h.n_points < 0 || h.n_tets < 0 || h.n_trifaces < 0 || h.corners < 0 || size != need) {
        std::free(data);
        return cm_error(ctx, CM_ERR_INTERNAL, "%s: TetGen's child sent %zu bytes, %zu expected",
                        what, size, need);
    }
    res->n_points = np;
    res->n_tets = nt;
    res->n_trifaces = nf;
    res->corners = (int)nc;
    res->xyz = (double *)std::malloc(8 * 3 * np + 8);
    res->tet = (int32_t *)std::malloc(4 * nc * nt + 4);
    res->triface = (int32_t *)std::malloc(4 * 3 * nf + 4);
    res->trimarker = (int32_t *)std::malloc(4 * nf + 4);
    if (!res->xyz || !res->tet || !res->triface || !res->trimarker) {
        std::free(data);
        cm_tetgen_result_free(res);
        return cm_error(ctx, CM_ERR_NOMEM, "%s: out of memory for TetGen's %zu tets", what, nt);
    }
    const char *c = data + sizeof h;
    std::memcpy(res->xyz, c, 8 * 3 * np);
    c += 8 * 3 * np;
    std::memcpy(res->tet, c, 4 * nc * nt);
    c += 4 * nc * nt;
    std::memcpy(res->triface, c, 4 * 3 * nf);
    c += 4 * 3 * nf;
    std::memcpy(res->trimarker, c, 4 * nf);
    std::free(data);
    // indices from another process are checked before anything uses them
    for (size_t i = 0; i < nc * nt; ++i)
        if (res->tet[i] < 0 || (size_t)res->tet[i] >= np) {
            cm_tetgen_result_free(res);
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: TetGen's tet node %zu out of range", what, i);
        }
    for (size_t i = 0; i < 3 * nf; ++i)
        if (res->triface[i] < 0 || (size_t)res->triface[i] >= np) {
            cm_tetgen_result_free(res);
            return cm_error(ctx, CM_ERR_INTERNAL, "%s: TetGen's triangle node out of range", what);
        }
    return CM_OK;
}
