// What both gmsh children share (tetmesh_gmsh.cpp: one solid; tetmesh_assembly.cpp: solids
// that touch): gmsh's C API opened by dlopen in the child only, its start with cadmorph's
// settings, its last error as text; and the orientation of a tet. C++, private to meshgen/.
#ifndef CADMORPH_MESHGEN_GMSH_CHILD_H
#define CADMORPH_MESHGEN_GMSH_CHILD_H

// gmshc.h declares C functions without extern "C" of its own
extern "C" {
#include <gmshc.h>
}

#include "child_process.h"

#include <cstddef>
#include <cstdint>
#include <cstdio>

namespace cmvol {

// gmsh's library is opened in the child only: linked into cadmorph it would load 60 more
// shared libraries (FLTK, OpenGL, X11, ...) into every command, 0.15 s CPU each start.
// The prototypes are gmshc.h's own.
#define CM_GMSH_FUNCTIONS(X)                                                                       \
    X(gmshInitialize) X(gmshFree) X(gmshLoggerGetLastError) X(gmshOptionSetNumber)                \
    X(gmshOptionSetString) X(gmshModelOccImportShapes) X(gmshModelOccFragment)                    \
    X(gmshModelOccSynchronize) X(gmshModelGetBoundingBox) X(gmshModelMeshGenerate)                \
    X(gmshModelMeshGetNodes) X(gmshModelMeshGetElementsByType) X(gmshModelGetEntities)

struct gmsh_api {
#define CM_GMSH_MEMBER(f) decltype(&::f) f = nullptr;
    CM_GMSH_FUNCTIONS(CM_GMSH_MEMBER)
#undef CM_GMSH_MEMBER
};

// Opens gmsh's library into *g and initialises it quiet, on one thread (the fork left no
// OpenMP pool behind), with OpenCASCADE's target unit for our unit name (cm_cad_unit: "mm",
// "m", "in", ...). 0 on success, else 1 with the reason in msg.
int gmsh_start(gmsh_api *g, const char *unit, char *msg, size_t n);

// msg = "what: gmsh's last error" (or what alone when gmsh logged none).
void gmsh_error_text(const gmsh_api &g, const char *what, char *msg, size_t n);

// Sends a child's failure record: a header H (a record type with magic, failed and a char
// msg[]) with failed = 1 and msg; the exit status for cm_child_run (3: the pipe failed).
template <class H> int send_failure(int fd, uint64_t magic, const char *msg)
{
    H hd = {};
    hd.magic = magic;
    hd.failed = 1;
    std::snprintf(hd.msg, sizeof hd.msg, "%s", msg);
    return cm_child_write(fd, &hd, sizeof hd) ? 3 : 0;
}

// The failure record of `what` with gmsh's last error (gmsh_error_text).
template <class H> int send_error(const gmsh_api &g, int fd, uint64_t magic, const char *what)
{
    char msg[sizeof(H::msg)];
    gmsh_error_text(g, what, msg, sizeof msg);
    return send_failure<H>(fd, magic, msg);
}

// Six times the signed volume of tet abcd (> 0: positively oriented, as VTK's).
double orient(const double *a, const double *b, const double *c, const double *d);

}  // namespace cmvol
#endif
