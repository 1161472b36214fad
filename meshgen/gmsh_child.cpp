// gmsh's start in a mesher's child and the helpers both gmsh paths use (gmsh_child.h).
#include "gmsh_child.h"

#include <dlfcn.h>

#include <cstdio>
#include <cstring>

#ifndef CM_GMSH_SONAME
#define CM_GMSH_SONAME "libgmsh.so"
#endif

namespace cmvol {

namespace {

int load_gmsh(gmsh_api *g, char *err, size_t n)
{
    void *lib = dlopen(CM_GMSH_SONAME, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        std::snprintf(err, n, "cannot load gmsh's library (Debian package libgmsh4.8): %s", dlerror());
        return 1;
    }
#define CM_GMSH_LOAD(f)                                                                            \
    if (!(g->f = reinterpret_cast<decltype(&::f)>(dlsym(lib, #f)))) {                              \
        std::snprintf(err, n, "%s has no %s", CM_GMSH_SONAME, #f);                                 \
        return 1;                                                                                  \
    }
    CM_GMSH_FUNCTIONS(CM_GMSH_LOAD)
#undef CM_GMSH_LOAD
    return 0;
}

// OpenCASCADE's name of a unit (Geometry.OCCTargetUnit) for ours
const char *occ_unit(const char *u)
{
    static const char *const map[][2] = {{"mm", "MM"}, {"cm", "CM"}, {"m", "M"},   {"km", "KM"},
                                         {"in", "INCH"}, {"ft", "FT"}, {"mi", "MI"}, {"um", "UM"}};
    for (const auto &m : map)
        if (u && !std::strcmp(u, m[0])) return m[1];
    return "MM";
}

}  // namespace

int gmsh_start(gmsh_api *g, const char *unit, char *msg, size_t n)
{
    if (load_gmsh(g, msg, n)) return 1;
    int ierr = 0;
    g->gmshInitialize(0, nullptr, 0, &ierr);
    if (ierr) {
        gmsh_error_text(*g, "initialisation failed", msg, n);
        return 1;
    }
    // quiet (errors still reach the logger), one thread
    g->gmshOptionSetNumber("General.Terminal", 0, &ierr);
    g->gmshOptionSetNumber("General.NumThreads", 1, &ierr);
    g->gmshOptionSetNumber("Mesh.MaxNumThreads1D", 1, &ierr);
    g->gmshOptionSetNumber("Mesh.MaxNumThreads2D", 1, &ierr);
    g->gmshOptionSetNumber("Mesh.MaxNumThreads3D", 1, &ierr);
    g->gmshOptionSetString("Geometry.OCCTargetUnit", occ_unit(unit), &ierr);
    return 0;
}

void gmsh_error_text(const gmsh_api &g, const char *what, char *msg, size_t n)
{
    char *err = nullptr;
    int ierr = 0;
    g.gmshLoggerGetLastError(&err, &ierr);
    std::snprintf(msg, n, "%s%s%s", what, err && *err ? ": " : "", err ? err : "");
    if (err) g.gmshFree(err);
}

double orient(const double *a, const double *b, const double *c, const double *d)
{
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

}  // namespace cmvol
