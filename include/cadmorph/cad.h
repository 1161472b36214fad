/* cadmorph cad: STEP models through OpenCASCADE — topology, correspondence of G and G',
 * evaluation, trimmed dense sampling with a kD-tree, projection (paper section 4).
 * Conventions: see core.h. Faces, edges and vertices are numbered once per model, 0-based,
 * in OpenCASCADE's TopExp::MapShapes order. G' may number its entities otherwise (a re-export
 * reorders faces and edges, renumbers the edges of seamed wires, reverses edges):
 * cm_cad_match finds the correspondence of the topologies as graphs and renumbers G' so that
 * entity i of G' is the counterpart of entity i of G; everything downstream indexes G' by G's
 * indices.
 * Lengths are in the model's target unit (cm_cad_read_options.unit, millimetre by default).
 * Parameters: faces (u, v), edges t, both in OpenCASCADE's parameterisation of the
 * underlying surface/curve; s in [0, 1] is the normalised arc length along an edge in its
 * own (forward) direction.
 */
#ifndef CADMORPH_CAD_H
#define CADMORPH_CAD_H

#include "cadmorph/core.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct cm_cad_model cm_cad_model;

/* ---- reading and writing ---- */

typedef struct cm_cad_read_options {
    /* Target length unit of the model coordinates: "mm" (default), "cm", "m", "km", "in",
     * "ft", "mi", "um". The file's own unit is converted to it. */
    const char *unit;
} cm_cad_read_options;

CM_API void cm_cad_read_options_init(cm_cad_read_options *opt);

/* Reads a STEP file (all roots transferred into one compound). Errors: CM_ERR_IO (missing,
 * unreadable), CM_ERR_FORMAT (not STEP, no face in it), CM_ERR_CAD (transfer failed).
 * opt may be NULL for defaults. */
CM_API cm_status cm_cad_read(cm_context *ctx, const char *path, const cm_cad_read_options *opt,
                      cm_cad_model **model);
/* Writes the model as STEP (AP214) in the model's target unit, via a temporary file. */
CM_API cm_status cm_cad_write(cm_context *ctx, const cm_cad_model *model, const char *path);
CM_API void cm_cad_destroy(cm_cad_model **model);

/* The length unit named in the file ("millimetre", "metre", "inch", ... as the file says;
 * "" if none) and the target unit of the coordinates ("mm", ...). Owned by the model. */
CM_API const char *cm_cad_file_unit(const cm_cad_model *model);
CM_API const char *cm_cad_unit(const cm_cad_model *model);

/* ---- topology ---- */

typedef struct cm_cad_counts {
    int solids, shells, faces, wires, edges, vertices;
} cm_cad_counts;

CM_API void cm_cad_get_counts(const cm_cad_model *model, cm_cad_counts *counts);

/* Surface and curve types follow OpenCASCADE's GeomAbs enumerations. */
typedef enum cm_cad_surface_type {
    CM_CAD_PLANE = 0, CM_CAD_CYLINDER, CM_CAD_CONE, CM_CAD_SPHERE, CM_CAD_TORUS,
    CM_CAD_BEZIER_SURFACE, CM_CAD_BSPLINE_SURFACE, CM_CAD_REVOLUTION, CM_CAD_EXTRUSION,
    CM_CAD_OFFSET_SURFACE, CM_CAD_OTHER_SURFACE
} cm_cad_surface_type;

typedef enum cm_cad_curve_type {
    CM_CAD_LINE = 0, CM_CAD_CIRCLE, CM_CAD_ELLIPSE, CM_CAD_HYPERBOLA, CM_CAD_PARABOLA,
    CM_CAD_BEZIER_CURVE, CM_CAD_BSPLINE_CURVE, CM_CAD_OFFSET_CURVE, CM_CAD_OTHER_CURVE
} cm_cad_curve_type;

/* "plane", "cylinder", ..., "line", "circle", ... */
CM_API const char *cm_cad_surface_type_name(cm_cad_surface_type type);
CM_API const char *cm_cad_curve_type_name(cm_cad_curve_type type);

typedef struct cm_cad_face_info {
    cm_cad_surface_type type;
    double uv_range[4];   /* umin umax vmin vmax of the trimmed face (BRepTools::UVBounds) */
    int periodic[2];      /* u, v periodic */
    double period[2];     /* periods (0 if not periodic) */
    int reversed;         /* face orientation opposite to the surface normal */
    int n_wires;          /* wire 0 is the outer wire */
    double area;
    double bbox[6];       /* xmin ymin zmin xmax ymax zmax */
} cm_cad_face_info;

typedef struct cm_cad_edge_info {
    cm_cad_curve_type type;   /* CM_CAD_OTHER_CURVE for degenerate edges */
    double t_range[2];
    int vertex[2];            /* first and last vertex (-1 if none) */
    int degenerate;           /* collapsed edge, e.g. at a sphere pole (no 3D curve) */
    int closed;               /* first vertex == last vertex */
    double length;
    double bbox[6];
    /* 1 in a G' renumbered by cm_cad_match where this edge runs against its counterpart in G:
     * s (arc length fraction, cm_cad_edge_t_to_s and _s_to_t, cm_cad_boundary.s) is then
     * measured in G's direction, from vertex[1] to vertex[0]; t, t_range, vertex and the
     * wires' reversed flags stay OpenCASCADE's. 0 otherwise. */
    int flipped;
} cm_cad_edge_info;

CM_API cm_status cm_cad_face_get_info(cm_context *ctx, const cm_cad_model *model, int face,
                               cm_cad_face_info *info);
CM_API cm_status cm_cad_edge_get_info(cm_context *ctx, const cm_cad_model *model, int edge,
                               cm_cad_edge_info *info);
/* xyz: 3 doubles. */
CM_API cm_status cm_cad_vertex_point(cm_context *ctx, const cm_cad_model *model, int vertex, double *xyz);
/* The path the model was read from ("" if none), for messages. */
CM_API const char *cm_cad_path(const cm_cad_model *model);
/* Bounding box of the whole model: 6 doubles. */
CM_API void cm_cad_bbox(const cm_cad_model *model, double *bbox);

/* Oriented edges of wire w of a face, in the wire's order. edges/reversed point into the
 * model (valid until it is destroyed): n entries, edge indices and 1 where the edge runs
 * against its own direction in this face. A seam edge of a periodic face appears twice,
 * once each way. */
CM_API cm_status cm_cad_face_wire(cm_context *ctx, const cm_cad_model *model, int face, int wire,
                           const int **edges, const int **reversed, int *n);

/* Faces adjacent to an edge (1 for a free edge, 2 for a manifold edge, 1 for a seam):
 * faces points into the model, n entries. */
CM_API cm_status cm_cad_edge_faces(cm_context *ctx, const cm_cad_model *model, int edge,
                            const int **faces, int *n);

/* How the model's solids meet (solids numbered 0-based in TopExp order, as in the groups
 * "solid_<k>" of an assembly mesh). Two solids closer than 1e-6 of the model's bounding-box
 * diagonal (or one inside the other) meet; OpenCASCADE's Boolean Common then tells whether
 * they overlap (a common volume above 1e-6 of the smaller solid's) or only touch (share a
 * face or part of one, as the parts of an assembly do).
 * Overlapping solids: CM_ERR_UNSUPPORTED naming the first such pair, whether one is inside
 * the other, and the way out (fuse them, or fragment them in the CAD). Touching solids: with
 * touching non-NULL, CM_OK and the first touching pair in touching[0..1] ({-1, -1} when all
 * solids are apart; a mesher meshes such a model as one conformal mesh, docs/DESIGN.md,
 * "Assemblies"); with touching NULL, CM_ERR_UNSUPPORTED naming the pair. CM_OK for one solid
 * or none. */
CM_API cm_status cm_cad_check_solids_apart(cm_context *ctx, const cm_cad_model *model,
                                           int *touching);

/* The solid (0-based) whose shell holds the face; -1 for a face of no solid. A face shared
 * by two solids (a fragmented assembly) belongs to the first. */
CM_API cm_status cm_cad_face_solid(cm_context *ctx, const cm_cad_model *model, int face,
                                   int *solid);

/* The solid (0-based) the point xyz (3 doubles) is strictly inside, -1 when none (outside
 * every solid or on a face, to 1e-7 of the diagonal). */
CM_API cm_status cm_cad_solid_at(cm_context *ctx, const cm_cad_model *model, const double *xyz,
                                 int *solid);

/* The model's own tolerance around each face (BRep_Tool::Tolerance): tol[f], #faces doubles,
 * the largest of face f's tolerance and those of its edges and vertices, i.e. how far a point
 * of the face's boundary as one entity places it may be from the face's surface; *largest
 * (when not NULL) the largest over the model. In model units. */
CM_API cm_status cm_cad_face_tolerances(cm_context *ctx, const cm_cad_model *model, double *tol,
                                        double *largest);

/* ---- correspondence of G and G' ---- */

/* The correspondence of the topology of G and G' as graphs: solids, shells, faces, wires,
 * edges and vertices with their incidences and orientations. Adjacency decides first (a
 * matched face and an oriented edge of one of its wires fix the neighbours across every
 * edge); the distance of the entities' points relative to the model size decides between
 * candidates; the identity numbering is preferred when it is consistent. A change of surface
 * or curve type is allowed (logged at CM_LOG_DEBUG). Arrays are indexed by G's entities and
 * hold the index of the counterpart in G'. All arrays are owned by the struct. */
typedef struct cm_cad_correspondence {
    cm_cad_counts counts;     /* of G */
    int *face;                /* #faces */
    int *face_reversed;       /* #faces: 1 where the counterpart's surface normal runs
                                 against the face (cm_cad_face_info.reversed differs) */
    int *edge;                /* #edges */
    int *edge_flipped;        /* #edges: 1 where the counterpart runs the other way */
    int *vertex;              /* #vertices */
    int renumbered;           /* faces, edges, vertices or wire starts numbered otherwise, or
                                 edges flipped: cm_cad_match renumbers G' */
    int wires_restarted;      /* wires of G whose counterpart is another wire of the face or
                                 starts at another edge */
    int face_type_changes;    /* faces whose surface type differs (plane -> bspline, ...) */
    int edge_type_changes;    /* edges whose curve type differs */
} cm_cad_correspondence;

/* The correspondence of G and G' (both unchanged). CM_OK with *out if they correspond;
 * CM_ERR_MISMATCH and *out NULL if not, the message naming up to max_report differences in
 * words ("face 12 (plane, 4 edges) has no counterpart: G' has a hole there") and the counts
 * that differ ("faces: 9 in G, 10 in G'"). Refuses models whose sizes differ by 100x or more
 * (units); logs a warning when their file units differ. out may be NULL. */
CM_API cm_status cm_cad_correspond(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                                   int max_report, cm_cad_correspondence **out);
CM_API void cm_cad_correspondence_destroy(cm_cad_correspondence **c);

/* cm_cad_correspond, then G' is renumbered in place: its faces, edges, vertices take the
 * indices of their counterparts in G, the wires of each face G's order and start edge, and
 * edges that run the other way are marked flipped (cm_cad_edge_info.flipped). Call it before
 * anything indexes G' (a locator, a morpher): those keep indices. out may be NULL. */
CM_API cm_status cm_cad_match(cm_context *ctx, const cm_cad_model *g, cm_cad_model *g2,
                              int max_report, cm_cad_correspondence **out);

/* G and G' correspond in G's numbering (as after cm_cad_match): CM_OK if so; CM_ERR_MISMATCH
 * with the differences (as cm_cad_correspond) if not, or saying that G' needs renumbering by
 * cm_cad_match when they correspond only with another numbering. */
CM_API cm_status cm_cad_compare(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                         int max_report);

/* ---- evaluation (arrays; OpenMP with one adaptor per thread) ---- */

/* uv: n x 2; xyz: n x 3 output; normal: n x 3 unit normals oriented as the face (outward for
 * the faces of a solid), may be NULL. */
CM_API cm_status cm_cad_face_eval(cm_context *ctx, const cm_cad_model *model, int face, const double *uv,
                           size_t n, double *xyz, double *normal);
/* t: n; xyz: n x 3 output. */
CM_API cm_status cm_cad_edge_eval(cm_context *ctx, const cm_cad_model *model, int edge, const double *t,
                           size_t n, double *xyz);
/* Trimming: inside[i] = 1 if uv[i] (n x 2) lies in the face's trimmed domain or on its
 * boundary, 0 outside. Periodic parameters are taken modulo the period. */
CM_API cm_status cm_cad_face_inside(cm_context *ctx, const cm_cad_model *model, int face,
                             const double *uv, size_t n, int *inside);

/* Arc length: s = length(t_first .. t) / length(edge) and its inverse (GCPnts_AbscissaPoint).
 * Degenerate edges map linearly between t and s. t, s: n entries. */
CM_API cm_status cm_cad_edge_t_to_s(cm_context *ctx, const cm_cad_model *model, int edge, const double *t,
                             size_t n, double *s);
CM_API cm_status cm_cad_edge_s_to_t(cm_context *ctx, const cm_cad_model *model, int edge, const double *s,
                             size_t n, double *t);

/* ---- face boundaries in parameter space ---- */

/* Samples of the (u,v) boundary of a face: for each wire, each oriented edge, per_edge[e]
 * points at equal arc-length fractions i / per_edge[e], i = 0 .. per_edge[e]-1, taken along
 * the edge's orientation in the face (so sample i of an edge of G corresponds to sample i of
 * the same edge of G'). Degenerate edges are sampled uniformly in t. A seam edge gives both
 * copies (one per pcurve).  All arrays are owned by the struct. */
typedef struct cm_cad_boundary {
    size_t n;
    double *uv;   /* n x 2 */
    double *xyz;  /* n x 3 (the 3D point of the edge) */
    int *edge;    /* n */
    double *s;    /* n: normalised arc length in the edge's own direction */
    int *wire;    /* n */
} cm_cad_boundary;

/* per_edge: #edges counts (indexed by edge; at least 1 each), or NULL to use `count` for
 * every edge. */
CM_API cm_status cm_cad_face_boundary(cm_context *ctx, const cm_cad_model *model, int face,
                               const int *per_edge, int count, cm_cad_boundary **boundary);
/* The same samples at other points of the edges: t (n entries, n and layout as
 * cm_cad_face_boundary gives them) is the edge parameter of each sample, NaN for the
 * arc-length one. For corresponding samples that do not sit at equal arc-length fractions
 * (the images of G's samples under an affine edit). Degenerate edges keep
 * their uniform samples; s keeps the nominal fraction. */
CM_API cm_status cm_cad_face_boundary_at(cm_context *ctx, const cm_cad_model *model, int face,
                                         const int *per_edge, int count, const double *t,
                                         cm_cad_boundary **boundary);
CM_API void cm_cad_boundary_destroy(cm_cad_boundary **boundary);

/* ---- projection ---- */

/* Onto one face, seeded: uv0 (n x 2, may be NULL: a coarse grid search seeds), Newton on the
 * surface, kept inside the trimmed domain (a foot point outside the trimming is replaced by
 * the nearest point on the face's boundary edges). xyz: n x 3. Outputs uv: n x 2, dist: n,
 * foot: n x 3; each may be NULL. */
CM_API cm_status cm_cad_project_face(cm_context *ctx, const cm_cad_model *model, int face,
                              const double *xyz, size_t n, const double *uv0, double *uv,
                              double *dist, double *foot);
/* Onto one edge (global search on the curve, then Newton): t, dist: n. */
CM_API cm_status cm_cad_project_edge(cm_context *ctx, const cm_cad_model *model, int edge,
                              const double *xyz, size_t n, double *t, double *dist);

/* Each point onto its own entity in one pass: kind[i] 1 an edge, 2 a face (the values of
 * cm_surface_kind; any other kind is skipped and its dist[i] left as it was), entity[i] its
 * index; uv0 (n x 2, may be NULL: grid seeds) the face points' seeds; dist: n. The distances
 * are those of cm_cad_project_edge and cm_cad_project_face called entity by entity, bit for
 * bit, but all points share one team of threads: a check over many small entities does not
 * start one per entity. */
CM_API cm_status cm_cad_project_each(cm_context *ctx, const cm_cad_model *model, size_t n,
                                     const int *kind, const int *entity, const double *xyz,
                                     const double *uv0, double *dist);

/* Dense samples of the trimmed faces plus a kD-tree on them, for projections of many points. */
typedef struct cm_cad_locator cm_cad_locator;

typedef struct cm_cad_sample_options {
    /* Target 3D spacing; <= 0: bbox diagonal / 200. For projecting a mesh, pass a quarter of
     * its smallest boundary edge (the CAD layer knows no mesh). */
    double h;
    size_t max_samples;  /* cap; 0: 20,000,000. If h would exceed it, h grows and the
                            create call returns CM_WARNING saying so. */
} cm_cad_sample_options;

CM_API void cm_cad_sample_options_init(cm_cad_sample_options *opt);

/* The samples worth their memory for projecting the boundary nodes of a mesh: they only
 * start the Newton projections and name the candidate faces, so a few dozen per boundary node
 * suffice (CM_CAD_SAMPLES_PER_NODE, at least CM_CAD_MIN_SAMPLES), at most max_cap (0: no
 * upper bound). A sample costs about 60 bytes. */
#define CM_CAD_SAMPLES_PER_NODE 64
#define CM_CAD_MIN_SAMPLES ((size_t)250000)
CM_API size_t cm_cad_sample_cap(size_t boundary_nodes, size_t max_cap);

/* Samples every face inside its trimmed domain on a grid whose step adapts to the surface
 * metric (3D spacing close to h) plus points on every edge (each with the uv of its pcurve in
 * each adjacent face), then builds the kD-trees. The model must outlive the locator. */
CM_API cm_status cm_cad_locator_create(cm_context *ctx, const cm_cad_model *model,
                                const cm_cad_sample_options *opt, cm_cad_locator **locator);
CM_API void cm_cad_locator_destroy(cm_cad_locator **locator);

/* The samples: n, and borrowed arrays xyz (n x 3), face (n), uv (n x 2); h actually used. */
CM_API size_t cm_cad_locator_samples(const cm_cad_locator *locator, const double **xyz,
                              const int **face, const double **uv);
CM_API double cm_cad_locator_h(const cm_cad_locator *locator);

/* Nearest face of each point (paper section 4): the nearest sample is the start value of a
 * Newton projection onto its face; the faces of the next nearest samples (up to 4 samples,
 * within h of the nearest) are projected onto too, and the closest foot point wins. The foot
 * stays in the trimmed domain (outside it, the nearest point of the face's boundary edges is
 * taken). Periodic u, v are returned in the face's range. face: n (0-based), uv: n x 2,
 * dist: n, foot: n x 3; each output may be NULL. */
CM_API cm_status cm_cad_locate_faces(cm_context *ctx, const cm_cad_locator *locator, const double *xyz,
                              size_t n, int *face, double *uv, double *dist, double *foot);
/* Nearest edge of each point (a kD-tree on edge samples, then Newton on the curves of the
 * nearest samples' edges): edge (0-based), t, dist: n. s follows from cm_cad_edge_t_to_s. */
CM_API cm_status cm_cad_locate_edges(cm_context *ctx, const cm_cad_locator *locator, const double *xyz,
                              size_t n, int *edge, double *t, double *dist);
/* Nearest vertex of each point: vertex, dist: n. */
CM_API cm_status cm_cad_locate_vertices(cm_context *ctx, const cm_cad_locator *locator,
                                 const double *xyz, size_t n, int *vertex, double *dist);

/* ---- surface triangulation (for tet meshing) and volume ---- */

typedef struct cm_cad_triangulate_options {
    double size;        /* target edge length; <= 0: bbox diagonal / 20 */
    /* BRepMesh's chord (linear) and angular deflection; <= 0: size / 10 and 0.3 rad (about
     * 17 degrees, so that a circle of radius r gets edges of about 0.3 r). */
    double linear_deflection;
    double angular_deflection;
    double min_size;    /* BRepMesh's smallest edge (MinSize); <= 0: size / 4 */
} cm_cad_triangulate_options;

CM_API void cm_cad_triangulate_options_init(cm_cad_triangulate_options *opt);

/* One node per CAD vertex, per interior point of an edge's discretisation (shared by the
 * faces on both sides) and per interior point of a face: the triangulation is watertight
 * wherever the model is. All arrays are owned by the struct. */
typedef struct cm_cad_triangulation {
    size_t n_nodes;
    double *xyz;        /* #nodes x 3 */
    int *node_dim;      /* #nodes: 0 on a CAD vertex, 1 inside an edge, 2 inside a face */
    int *node_entity;   /* #nodes: the vertex, edge or face index */
    size_t n_triangles;
    int64_t *tri;       /* #triangles x 3, 0-based, oriented by the face's orientation in its
                           solid (outward normal by the right-hand rule) */
    int *tri_face;      /* #triangles: the face */
    double *tri_uv;     /* #triangles x 6: (u, v) of each corner on the triangle's face (seeds
                           for projections onto the face) */
    size_t n_open_edges;   /* triangle edges not shared by exactly two triangles with
                              opposite directions: 0 for the boundary of a closed solid */
} cm_cad_triangulation;

/* Meshes every face of the model (BRepMesh_IncrementalMesh; a triangulation left on the
 * shape by an earlier call is discarded first, so do not call it concurrently on the same
 * model). Errors: CM_ERR_UNSUPPORTED for a model without faces, CM_ERR_CAD when BRepMesh
 * fails or leaves a face without triangles (message names the face). */
CM_API cm_status cm_cad_triangulate(cm_context *ctx, const cm_cad_model *model,
                             const cm_cad_triangulate_options *opt, cm_cad_triangulation **out);
CM_API void cm_cad_triangulation_destroy(cm_cad_triangulation **t);

/* Total volume of the model's solids (BRepGProp); CM_ERR_UNSUPPORTED if it has no solid. */
CM_API cm_status cm_cad_volume(cm_context *ctx, const cm_cad_model *model, double *volume);
/* Volume moments of the model's solids (BRepGProp, adaptive): volume (> 0), centroid (3) and
 * the centred second moments per unit volume, second (3 x 3 row-major) = int (x - c)(x - c)^T
 * dV / volume. An affine map x -> A x + b maps them to |det A| volume, A c + b, A second A^T.
 * CM_ERR_UNSUPPORTED if the model has no solid. */
CM_API cm_status cm_cad_volume_moments(cm_context *ctx, const cm_cad_model *model,
                                       double *volume, double *centroid, double *second);

#ifdef __cplusplus
}
#endif
#endif
