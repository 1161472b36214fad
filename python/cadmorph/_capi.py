"""The C API of libcadmorph as cffi sees it (ABI mode: no compiler at install time).

The declarations below copy those of include/cadmorph/core.h and mesh.h that the package
uses, struct layouts included (cm_mesh is read field by field); a change of those headers is
a change here (tests/python/test_layout.py compares the layouts with the compiler's). The
library is CADMORPH_LIBRARY if set, else the one CMake recorded in _libpath.py (the build
tree's, or the installed one relative to this package), else the soname through the dynamic
loader. cffi releases the GIL around every call into the library.
"""
import os

import cffi

CDEF = r"""
typedef enum cm_status {
    CM_OK = 0, CM_WARNING = 1, CM_ERR_NOMEM = -1, CM_ERR_ARGUMENT = -2, CM_ERR_IO = -3,
    CM_ERR_FORMAT = -4, CM_ERR_UNSUPPORTED = -5, CM_ERR_MISMATCH = -6, CM_ERR_NUMERIC = -7,
    CM_ERR_CAD = -8, CM_ERR_INTERNAL = -9, CM_ERR_REJECTED = -10
} cm_status;
const char *cm_status_name(cm_status s);
int cm_status_is_input_error(cm_status s);
typedef struct cm_context cm_context;
cm_status cm_context_create(cm_context **ctx);
void cm_context_destroy(cm_context **ctx);
const char *cm_context_message(const cm_context *ctx);
void cm_context_set_threads(cm_context *ctx, int threads);
const char *cm_version(void);

typedef enum cm_cell_type {
    CM_CELL_POINT = 0, CM_CELL_LINE2, CM_CELL_LINE3, CM_CELL_TRI3, CM_CELL_TRI6, CM_CELL_QUAD4,
    CM_CELL_QUAD8, CM_CELL_QUAD9, CM_CELL_TET4, CM_CELL_TET10, CM_CELL_HEX8, CM_CELL_HEX20,
    CM_CELL_HEX27, CM_CELL_WEDGE6, CM_CELL_WEDGE15, CM_CELL_WEDGE18, CM_CELL_PYR5,
    CM_CELL_PYR13, CM_CELL_PYR14, CM_CELL_POLYGON, CM_CELL_POLYHEDRON, CM_CELL_TYPE_COUNT
} cm_cell_type;
typedef struct cm_cell_info {
    const char *name; int dim; int nodes; int corners; cm_cell_type linear; int vtk; int gmsh;
} cm_cell_info;
const cm_cell_info *cm_cell_type_info(cm_cell_type type);

typedef enum cm_field_location { CM_FIELD_NODE = 0, CM_FIELD_CELL = 1 } cm_field_location;
typedef struct cm_field {
    char *name; cm_field_location location; int components; double *data;
} cm_field;
typedef struct cm_mesh_group { int dim; int tag; char *name; } cm_mesh_group;
typedef struct cm_mesh_entity {
    int dim; int tag; double bbox[6]; int n_physical; int *physical; int n_bounding;
    int *bounding;
} cm_mesh_entity;
struct cm_foam_poly;
typedef struct cm_mesh {
    size_t n_nodes; double *xyz; int64_t *node_tag;
    size_t n_cells; uint8_t *type; int64_t *offset; int64_t *conn; int *physical; int *entity;
    int64_t *cell_tag;
    size_t n_fields; cm_field *fields; size_t n_groups; cm_mesh_group *groups;
    size_t n_entities; cm_mesh_entity *entities;
    size_t cap_nodes, cap_cells, cap_conn;
    struct cm_foam_poly *foam;
} cm_mesh;
void cm_mesh_destroy(cm_mesh **mesh);
size_t cm_mesh_count_dim(const cm_mesh *mesh, int dim);
const char *cm_mesh_format_list(void);
typedef struct cm_mesh_write_options {
    int msh_version; int binary; int compress; int appended;
} cm_mesh_write_options;
void cm_mesh_write_options_init(cm_mesh_write_options *opt);
cm_status cm_mesh_read(cm_context *ctx, const char *path, cm_mesh **mesh);
cm_status cm_mesh_write(cm_context *ctx, const cm_mesh *mesh, const char *path,
                        const cm_mesh_write_options *opt);
cm_status cm_mesh_quality(cm_context *ctx, const cm_mesh *mesh, double *sj);
typedef struct cm_quality_stats {
    size_t count; double min, mean, p01; size_t inverted;
} cm_quality_stats;
cm_status cm_quality_summarize(cm_context *ctx, const cm_mesh *mesh, const double *sj,
                               cm_quality_stats *per_type, cm_quality_stats *all);
"""

# the soname of libcadmorph 0.x when CMake did not record it: the minor version is part of
# it (cmake/library.cmake)
SONAME = "libcadmorph.so.0.1"

ffi = cffi.FFI()
ffi.cdef(CDEF)


def _candidates():
    """CADMORPH_LIBRARY if set, the library CMake recorded, then the soname."""
    try:
        from . import _libpath
    except ImportError:  # a copy of the sources that CMake did not configure
        _libpath = None
    if os.environ.get("CADMORPH_LIBRARY"):
        yield os.environ["CADMORPH_LIBRARY"]
    if getattr(_libpath, "LIBRARY", None):
        yield _libpath.LIBRARY
    yield getattr(_libpath, "SONAME", SONAME)


def _load():
    """The first library that loads, and its path; ImportError naming every attempt."""
    errors = []
    for path in _candidates():
        if os.sep in path and not os.path.exists(path):
            errors.append("%s: no such file" % path)
            continue
        try:
            return ffi.dlopen(path), path
        except OSError as e:
            errors.append(str(e))
    raise ImportError("cadmorph: cannot load libcadmorph (%s)" % "; ".join(errors))


lib, LIBRARY_PATH = _load()
