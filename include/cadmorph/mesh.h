/* cadmorph mesh: mixed-cell volume meshes (plus the lower-dimensional elements that gmsh
 * files carry), file I/O chosen by extension, boundary extraction and scaled Jacobian.
 * Conventions: see core.h. Node indices are 0-based everywhere in this API.
 */
#ifndef CADMORPH_MESH_H
#define CADMORPH_MESH_H

#include "cadmorph/core.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Node order inside a cell is VTK's for every type (gmsh readers/writers permute). */
typedef enum cm_cell_type {
    CM_CELL_POINT = 0,
    CM_CELL_LINE2,
    CM_CELL_LINE3,
    CM_CELL_TRI3,
    CM_CELL_TRI6,
    CM_CELL_QUAD4,
    CM_CELL_QUAD8,
    CM_CELL_QUAD9,
    CM_CELL_TET4,
    CM_CELL_TET10,
    CM_CELL_HEX8,
    CM_CELL_HEX20,
    CM_CELL_HEX27,
    CM_CELL_WEDGE6,
    CM_CELL_WEDGE15,
    CM_CELL_WEDGE18,
    CM_CELL_PYR5,
    CM_CELL_PYR13,
    CM_CELL_PYR14,
    CM_CELL_POLYGON,    /* conn: the n nodes in order */
    CM_CELL_POLYHEDRON, /* conn: face stream  nf, n0, ids of face 0, n1, ids of face 1, ...;
                           faces oriented outward (right-hand rule), as VTK's */
    CM_CELL_TYPE_COUNT
} cm_cell_type;

typedef struct cm_cell_info {
    const char *name;    /* "tet4", "hex20", ... */
    int dim;             /* 0..3 */
    int nodes;           /* nodes per cell, -1 for polygon/polyhedron */
    int corners;         /* corner (linear) nodes: the first `corners` of the cell's nodes */
    cm_cell_type linear; /* the linear type with these corners */
    int vtk;             /* VTK cell type id */
    int gmsh;            /* gmsh element type id, 0 if gmsh has none */
} cm_cell_info;

/* Table entry of a type; NULL for an out-of-range value. */
CM_API const cm_cell_info *cm_cell_type_info(cm_cell_type type);
/* Type from VTK / gmsh id; returns CM_CELL_TYPE_COUNT for ids cadmorph does not know. */
CM_API cm_cell_type cm_cell_type_from_vtk(int vtk_id);
CM_API cm_cell_type cm_cell_type_from_gmsh(int gmsh_id);

typedef enum cm_field_location { CM_FIELD_NODE = 0, CM_FIELD_CELL = 1 } cm_field_location;

/* A named array of doubles attached to nodes or cells: #nodes|#cells x components. */
typedef struct cm_field {
    char *name;
    cm_field_location location;
    int components;
    double *data;
} cm_field;

/* What the file says of a boundary group that decides how its nodes may move in a morph
 * (docs/DESIGN.md, "Boundary motion by patch kind"). */
typedef enum cm_patch_kind {
    CM_PATCH_PLAIN = 0,     /* no rule from the file (OpenFOAM patch or wall, CGNS BCWall,
                               inflow, ..., and every group of a format without types) */
    CM_PATCH_SYMMETRY = 1,  /* OpenFOAM symmetryPlane and symmetry, CGNS BCSymmetryPlane */
    CM_PATCH_EMPTY = 2,     /* OpenFOAM empty: the front and back planes of a 2-D mesh */
    CM_PATCH_WEDGE = 3,     /* OpenFOAM wedge: the two sides of an axisymmetric mesh */
    CM_PATCH_CYCLIC = 4,    /* OpenFOAM cyclic, cyclicAMI, cyclicACMI, cyclicSlip */
    CM_PATCH_PROCESSOR = 5, /* OpenFOAM processor, processorCyclic: a cut of a decomposed case */
    CM_PATCH_N_KINDS
} cm_patch_kind;

/* Short name of a kind ("plain", "symmetry", "empty", "wedge", "cyclic", "processor"), NULL
 * out of range. */
CM_API const char *cm_patch_kind_name(cm_patch_kind kind);

/* A named physical group (gmsh $PhysicalNames, Medit references, an OpenFOAM patch or zone, a
 * CGNS boundary condition, ...). */
typedef struct cm_mesh_group {
    int dim;
    int tag;
    char *name;
    cm_patch_kind kind; /* CM_PATCH_PLAIN unless the reader knows better (set after adding) */
} cm_mesh_group;

/* A gmsh 4 geometric entity, kept so that a .msh round trip keeps $Entities. */
typedef struct cm_mesh_entity {
    int dim;
    int tag;
    double bbox[6];     /* xmin ymin zmin xmax ymax zmax (points: x y z x y z) */
    int n_physical;
    int *physical;      /* physical tags of the entity */
    int n_bounding;
    int *bounding;      /* signed tags of bounding entities (dim-1) */
} cm_mesh_entity;

/* The mesh. Fields are public for reading; grow it only through the functions below. */
typedef struct cm_mesh {
    size_t n_nodes;
    double *xyz;         /* #nodes x 3 */
    int64_t *node_tag;   /* #nodes: the id the file gave each node; NULL means index + 1 */

    size_t n_cells;      /* all elements, any dimension, in file order */
    uint8_t *type;       /* #cells, cm_cell_type */
    int64_t *offset;     /* #cells + 1: cell c's nodes are conn[offset[c] .. offset[c+1]) */
    int64_t *conn;       /* 0-based node indices (polyhedra: face stream, see above) */
    int *physical;       /* #cells: physical group tag, 0 if none */
    int *entity;         /* #cells: geometric (elementary) entity tag, 0 if none */
    int64_t *cell_tag;   /* #cells: the id the file gave each element; NULL means index + 1 */

    size_t n_fields;
    cm_field *fields;
    size_t n_groups;
    cm_mesh_group *groups;
    size_t n_entities;
    cm_mesh_entity *entities;

    /* private: allocated lengths */
    size_t cap_nodes, cap_cells, cap_conn;
    /* private: what the file the mesh was read from holds beyond the mesh (an OpenFOAM
     * polyMesh's faces and patches, where a text file keeps its coordinates, ...), so that
     * writing the mesh back into that format changes only coordinates; shared by copies; NULL
     * for a mesh built in memory */
    struct cm_mesh_origin *origin;
} cm_mesh;

CM_API cm_status cm_mesh_create(cm_context *ctx, cm_mesh **mesh);
CM_API void cm_mesh_destroy(cm_mesh **mesh);

/* Sets the node count; xyz is (re)allocated and left uninitialised beyond the old count.
 * with_tags: also allocate node_tag (left for the caller to fill). */
CM_API cm_status cm_mesh_resize_nodes(cm_context *ctx, cm_mesh *mesh, size_t n_nodes,
                                      int with_tags);
/* Reserves room for more cells and connectivity entries (optional: add_cell grows). */
CM_API cm_status cm_mesh_reserve_cells(cm_context *ctx, cm_mesh *mesh, size_t n_cells,
                                       size_t n_conn);
/* Appends a cell. nodes: n entries, 0-based, VTK order (polyhedra: the face stream).
 * tag: the file's element id or 0 to use index + 1. */
CM_API cm_status cm_mesh_add_cell(cm_context *ctx, cm_mesh *mesh, cm_cell_type type,
                                  const int64_t *nodes, size_t n, int physical, int entity,
                                  int64_t tag);
/* Adds (or replaces) a field; *data points to its zeroed array, owned by the mesh. */
CM_API cm_status cm_mesh_add_field(cm_context *ctx, cm_mesh *mesh, const char *name,
                                   cm_field_location location, int components, double **data);
CM_API cm_field *cm_mesh_find_field(const cm_mesh *mesh, const char *name,
                                    cm_field_location location);
CM_API cm_status cm_mesh_add_group(cm_context *ctx, cm_mesh *mesh, int dim, int tag,
                                   const char *name);
/* Appends an entity; the arrays are copied. */
CM_API cm_status cm_mesh_add_entity(cm_context *ctx, cm_mesh *mesh, const cm_mesh_entity *entity);

/* Deep copy. */
CM_API cm_status cm_mesh_copy(cm_context *ctx, const cm_mesh *mesh, cm_mesh **copy);

/* Node indices in range, node counts match types, coordinates finite, polyhedron streams
 * consistent. what: a name for messages (usually the file path). */
CM_API cm_status cm_mesh_validate(cm_context *ctx, const cm_mesh *mesh, const char *what);

/* Number of cells of dimension dim. */
CM_API size_t cm_mesh_count_dim(const cm_mesh *mesh, int dim);

/* The distinct nodes of cell c, sorted, into out (a polyhedron's: those of its face stream):
 * their count, or -1 if more than cap (never more than the cell's connectivity entries). */
CM_API int cm_mesh_cell_nodes(const cm_mesh *mesh, size_t c, int64_t *out, int cap);

/* ---- the face stream of a polyhedron ----
 * One walk for every reader of CM_CELL_POLYHEDRON's stream (nf, n0, ids of face 0, n1, ...):
 *
 *   for (cm_polyhedron_face f = cm_polyhedron_begin(stream, len); cm_polyhedron_more(&f);
 *        cm_polyhedron_next(&f))
 *       ... f.n node ids at f.nodes (face f.face of f.n_faces) ...
 *
 * stream = mesh->conn + mesh->offset[c], len = its entry count, or -1 for a stream already
 * checked (cm_mesh_validate, which the readers run). A face with a negative count or one that
 * runs past len ends the walk with f.bad set; after a complete walk f.at is one past the last
 * face (so f.at < stream + len means trailing entries). */
typedef struct cm_polyhedron_face {
    int64_t face;         /* this face: 0 .. n_faces - 1 */
    int64_t n_faces;      /* the stream's face count (0 if negative) */
    int64_t n;            /* node count of this face */
    const int64_t *nodes; /* its n node ids */
    const int64_t *at;    /* this face's entry (its count) in the stream */
    const int64_t *end;   /* one past the stream, NULL for an unbounded walk */
    int bad;              /* stopped at a malformed face (f.face is that face) */
} cm_polyhedron_face;

static inline void cm_polyhedron_load(cm_polyhedron_face *f)
{
    if (f->face >= f->n_faces) return;
    if ((f->end && f->at >= f->end) || f->at[0] < 0 || (f->end && f->at[0] >= f->end - f->at)) {
        f->bad = 1;
        return;
    }
    f->n = f->at[0];
    f->nodes = f->at + 1;
}

static inline cm_polyhedron_face cm_polyhedron_begin(const int64_t *stream, int64_t len)
{
    cm_polyhedron_face f = {0, 0, 0, stream + 1, stream + 1, len >= 0 ? stream + len : NULL, 0};
    f.n_faces = len != 0 && stream[0] > 0 ? stream[0] : 0;
    cm_polyhedron_load(&f);
    return f;
}

static inline int cm_polyhedron_more(const cm_polyhedron_face *f)
{
    return !f->bad && f->face < f->n_faces;
}

static inline void cm_polyhedron_next(cm_polyhedron_face *f)
{
    f->at += 1 + f->n;
    ++f->face;
    f->n = 0;
    cm_polyhedron_load(f);
}

/* ---- files ----
 * Formats by name (cm_mesh_format_list; docs/DESIGN.md, "Mesh formats"): .msh (gmsh 2.2 / 4.1,
 * ASCII / binary little-endian), .vtu (VTK XML), .vtk (legacy UNSTRUCTURED_GRID), .mesh
 * (Medit); surface meshes also .obj, .off, .stl (corners merged into nodes when read); .cgns
 * (ADF / HDF5), .su2, Fluent .msh (told from gmsh's by its content) and .cas, Abaqus .inp,
 * Nastran .bdf / .nas / .dat, Exodus II .exo / .e / .ex2 / .g; and OpenFOAM polyMesh for a
 * path that is a directory, ends in '/', is named polyMesh or has no extension (a case
 * directory: its constant/polyMesh is read or written).
 * A mesh read from a file and written back to a path of the same format, with the nodes and
 * cells it was read with, changes the node coordinates only: every other byte of the file (of
 * the polyMesh's other files, of an included deck) stays as it was.
 * Readers report the file, the line (text), byte offset (binary) or node path (CGNS) and what
 * was expected. Writers write a temporary file beside the target and rename it: a failed
 * write leaves no partial file. */

typedef enum cm_mesh_format {
    CM_FORMAT_UNKNOWN = 0,
    CM_FORMAT_MSH,
    CM_FORMAT_VTU,
    CM_FORMAT_VTK,
    CM_FORMAT_MEDIT,
    CM_FORMAT_OBJ, /* surface formats: faces (and, in .obj, lines) only */
    CM_FORMAT_OFF,
    CM_FORMAT_STL,
    CM_FORMAT_FOAM,    /* OpenFOAM polyMesh: a case directory or its constant/polyMesh */
    CM_FORMAT_CGNS,    /* CGNS (ADF or HDF5) */
    CM_FORMAT_SU2,     /* SU2 native, ASCII */
    CM_FORMAT_FLUENT,  /* Fluent mesh or case (.msh shared with gmsh: told apart by content) */
    CM_FORMAT_ABAQUS,  /* Abaqus input deck */
    CM_FORMAT_NASTRAN, /* Nastran bulk data */
    CM_FORMAT_EXODUS   /* Exodus II */
} cm_mesh_format;

CM_API cm_mesh_format cm_mesh_format_from_path(const char *path);
/* The extensions cm_mesh_read and cm_mesh_write know, for messages:
 * ".msh .vtu .vtk .mesh .obj .off .stl, or an OpenFOAM case directory". */
CM_API const char *cm_mesh_format_list(void);

typedef struct cm_mesh_write_options {
    int msh_version; /* 22 or 41 (default 41) */
    int binary;      /* msh, vtk, stl: binary; vtu: base64 data (appended raw if also `appended`) */
    int compress;    /* vtu: zlib compression (default on) */
    int appended;    /* vtu: appended raw data section */
} cm_mesh_write_options;

CM_API void cm_mesh_write_options_init(cm_mesh_write_options *opt);

CM_API cm_status cm_mesh_read(cm_context *ctx, const char *path, cm_mesh **mesh);
/* opt may be NULL for defaults. */
CM_API cm_status cm_mesh_write(cm_context *ctx, const cm_mesh *mesh, const char *path,
                               const cm_mesh_write_options *opt);

/* A node list (the fixed region of `cadmorph deform`, a constraint set): the header `node`,
 * then one 0-based node index per line; blank lines, trailing blanks and CRLF accepted. Sets
 * mark[i] = 1 for every listed node i < n_nodes (mark is not cleared first). Errors name the
 * file and line: a missing header, a token that is not an index, an index out of range. */
CM_API cm_status cm_mesh_read_node_list(cm_context *ctx, const char *path, size_t n_nodes,
                                        unsigned char *mark);

/* ---- boundary and components (volume cells only: dim 3) ---- */

typedef struct cm_mesh_boundary {
    size_t n_faces;         /* faces used by exactly one volume cell */
    int64_t *face_offset;   /* #faces + 1 into face_nodes */
    int64_t *face_nodes;    /* corner nodes of each face, oriented outward */
    int64_t *face_cell;     /* #faces: the cell the face belongs to */
    size_t n_nodes;         /* boundary nodes (corner and higher-order nodes of boundary faces) */
    int64_t *nodes;         /* sorted ascending */
    size_t n_components;    /* connected components of volume cells (sharing a face) */
    int *cell_component;    /* #cells: component of each volume cell, -1 for other cells */
    size_t n_nonmanifold;   /* faces shared by three or more cells */
    size_t n_duplicate;     /* volume cells with exactly the node set of another cell */
} cm_mesh_boundary;

/* Returns CM_WARNING (with counts in the message) for non-manifold faces or duplicates. */
CM_API cm_status cm_mesh_boundary_create(cm_context *ctx, const cm_mesh *mesh,
                                         cm_mesh_boundary **b);
CM_API void cm_mesh_boundary_destroy(cm_mesh_boundary **b);

/* ---- quality: Verdict's scaled Jacobian ---- */

/* Scaled Jacobian of one cell from its corner coordinates (VTK order, corners x 3).
 * Types: tet, hex, wedge, pyramid (higher-order types use their corners).
 * Returns NaN for types without a definition (use cm_quality_polyhedron for polyhedra). */
CM_API double cm_quality_scaled_jacobian(cm_cell_type type, const double *xyz);

/* Polyhedron: decomposed into tets (cell centre, face centre, edge) - minimum of their
 * scaled Jacobians. face_stream as in CM_CELL_POLYHEDRON; coordinates from mesh xyz. */
CM_API double cm_quality_polyhedron(const double *mesh_xyz, const int64_t *face_stream);

/* sj: #cells output; NaN for cells of dimension < 3. OpenMP over cells. */
CM_API cm_status cm_mesh_quality(cm_context *ctx, const cm_mesh *mesh, double *sj);

typedef struct cm_quality_stats {
    size_t count;
    double min, mean, p01; /* p01: 1st percentile */
    size_t inverted;       /* cells a solver rejects (cm_mesh_invalid_cells): on a polyMesh and
                              for polyhedra checkMesh's negative volume or wrongly oriented
                              face, else scaled Jacobian <= 0 (collapsed, NaN included) */
} cm_quality_stats;

/* Stats over volume cells: per_type[CM_CELL_TYPE_COUNT] (by linear type) and all. Either
 * output may be NULL. sj as from cm_mesh_quality. */
CM_API cm_status cm_quality_summarize(cm_context *ctx, const cm_mesh *mesh, const double *sj,
                                      cm_quality_stats *per_type, cm_quality_stats *all);

/* ---- OpenFOAM checkMesh's default checks (as OpenFOAM v1912 defines them) ----
 * What checkMesh runs without options, on one (serial) mesh:
 *  - topology: cell-to-face addressing (cells of fewer than 4 faces), point usage, upper-
 *    triangular face order, face vertices (out of range or repeated), the number of
 *    regions (a warning), empty-patch faces a multiple of the cells (a warning);
 *  - geometry: geometric directions (empty and wedge patches take theirs away) and solution
 *    directions (empty only); on a mesh with fewer than 3 geometric directions the 2-D edge
 *    alignment (no wedge) or the wedge checks (opposite wedge, common axis, planar wedges,
 *    edge alignment); boundary openness; cell openness and aspect ratio (over the geometric
 *    directions); face areas; cell volumes; non-orthogonality; face pyramids; skewness;
 *    coupled point match of translational cyclic patches.
 * Face centres and areas by the triangle fan about the face's point average, cell centres
 * and volumes by face pyramids about the face-centre average; non-orthogonality over internal
 * and cyclic faces (degrees), skewness over all faces (boundary faces against their mirror),
 * aspect ratio from the cell's summed |area| components, face pyramids of owner and neighbour.
 * Thresholds are checkMesh's: aspect ratio 1000, non-orthogonality 70 degrees (error past
 * 90), skewness 4, cell openness 1e-6. Uses the polyMesh's own faces when the mesh was read
 * from one, else the faces of its volume cells (matched between cells). Cell types by
 * OpenFOAM's cell models (hex, prism, wedge, pyramid, tetWedge, tet; anything else is a
 * polyhedron). */
typedef struct cm_foam_quality {
    size_t points, faces, internal_faces, cells, patches;
    size_t hexahedra, prisms, wedges, pyramids, tet_wedges, tetrahedra, polyhedra;
    double bbox[6];
    int directions[3];              /* geometric: 1 a direction, -1 taken by empty or wedge */
    int solution_directions[3];     /* solution: 1 a direction, -1 taken by empty */
    /* topology */
    size_t illegal_cells;           /* fewer than 4 faces */
    size_t unused_points_faces, unused_points_cells; /* points of no face / of no cell */
    int upper_triangular_error;     /* internal faces not in upper-triangular order */
    size_t multiple_face_cells;     /* cells with two faces to one neighbour (a note) */
    size_t bad_vertex_faces;        /* faces with out-of-range or repeated vertices */
    size_t regions;                 /* face-connected regions (more than 1: a warning) */
    int empty_not_2d;               /* empty faces not a multiple of the cells (a warning) */
    /* 2-D and wedge (checked when a geometric direction is taken) */
    int alignment_checked;          /* 1 edge alignment, 2 wedge checks */
    size_t non_aligned_edges;
    int wedge_error;                /* 0 none, 1 no opposite wedge, 2 different axes, 3 a
                                       wedge patch not planar */
    double wedge_angle;             /* degrees, of the first wedge patch */
    double wedge_off_plane;         /* wedge_error 3: the distance of the point off its plane */
    int64_t wedge_patch;            /* the patch (0-based) wedge_error is about, -1 if none */
    double boundary_openness[3];
    double max_cell_openness;
    size_t open_cells;
    double max_aspect_ratio;
    size_t high_aspect_cells;       /* aspect ratio > 1000 */
    int64_t worst_aspect_cell;
    double min_face_area, max_face_area;
    size_t zero_area_faces;
    double min_volume, max_volume, total_volume;
    size_t negative_volume_cells;   /* volume < 1e-300 */
    double max_non_orthogonality, avg_non_orthogonality; /* degrees */
    size_t severe_non_orthogonal_faces, non_orthogonality_errors;
    int64_t worst_non_orthogonal_face;
    size_t wrong_pyramids;          /* faces with a pyramid volume < -1e-15 (owner and neighbour) */
    double max_skewness;
    size_t high_skew_faces;         /* skewness > 4 */
    int64_t worst_skew_face;
    int boundary_open;              /* boundary openness > 1e-6 */
    size_t coupled_faces;           /* faces of cyclic patches checked for their match */
    size_t coupled_point_errors;    /* of them, faces whose points miss their partner's */
    double coupled_avg_mismatch;
    size_t uncoupled_patches;       /* cyclic patches not checked (rotational, unmatched) */
    size_t failed_checks;           /* as checkMesh counts them ("Failed N mesh checks.") */
} cm_foam_quality;

CM_API cm_status cm_mesh_quality_foam(cm_context *ctx, const cm_mesh *mesh, cm_foam_quality *q);

/* ---- what counts as an inverted cell (docs/DESIGN.md) ----
 * The cells a solver rejects: on a mesh read from an OpenFOAM polyMesh and for every
 * polyhedron, a cell checkMesh calls a negative volume (volume < 1e-300) or one with an
 * incorrectly oriented face (a face pyramid of volume < -1e-15 to its centre); any other
 * volume cell (tet, hex, wedge, pyramid of a mesh from another format) when its scaled
 * Jacobian is <= 0 (or undefined). sj: as from cm_mesh_quality. invalid (may be NULL):
 * #cells, set to 0 for a cell that is not inverted, 1 for one inverted by its scaled
 * Jacobian, 2 for one inverted by checkMesh's tests. *count: how many are inverted. */
CM_API cm_status cm_mesh_invalid_cells(cm_context *ctx, const cm_mesh *mesh, const double *sj,
                                       uint8_t *invalid, size_t *count);

/* ---- a moved mesh and its record ---- */

typedef enum cm_displacement_flags {
    CM_DISPLACEMENT_MOVE = 1,   /* add disp to mesh->xyz; without it the nodes already stand
                                   where disp brought them */
    CM_DISPLACEMENT_QUALITY = 2 /* then add the per-cell "scaled_jacobian" field: the quality
                                   of the moved mesh (cm_mesh_quality) */
} cm_displacement_flags;

/* What every program that moves a mesh writes with it: moves the nodes by disp (#nodes x 3)
 * when flags has CM_DISPLACEMENT_MOVE, stores disp as the per-node "displacement" field and,
 * with CM_DISPLACEMENT_QUALITY, adds the "scaled_jacobian" field after it (fields the mesh
 * already has are replaced where they stand, so the order of the fields is kept; disp must
 * not be the data of the mesh's own "displacement" field). sj (may be NULL): the quality
 * field's data, NULL without CM_DISPLACEMENT_QUALITY. */
CM_API cm_status cm_mesh_apply_displacement(cm_context *ctx, cm_mesh *mesh, const double *disp,
                                            unsigned flags, double **sj);

#ifdef __cplusplus
}
#endif
#endif
