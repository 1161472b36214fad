/* cadmorph surface: classification of the boundary nodes of a volume mesh against the CAD
 * model G (vertex | edge | face) and the CAD-aware surface morph G -> G' (paper section 4):
 * vertices go to the matching vertex, edge nodes keep their normalised arc length, face
 * nodes are moved in parameter space by a 2D thin-plate RBF fitted on the face's boundary
 * samples and evaluated on the matching face of G'; an affine edit is reproduced exactly.
 * Conventions: see core.h. Node indices are 0-based mesh node indices.
 */
#ifndef CADMORPH_SURFACE_H
#define CADMORPH_SURFACE_H

#include "cadmorph/cad.h"
#include "cadmorph/mesh.h"
#include "cadmorph/rbf.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- classification ---- */

typedef enum cm_surface_kind {
    CM_SURFACE_ON_VERTEX = 0,
    CM_SURFACE_ON_EDGE = 1,
    CM_SURFACE_ON_FACE = 2
} cm_surface_kind;

typedef struct cm_classify_options {
    /* A node lies on an entity when its distance is at most
     *   rel_tol x (shortest boundary edge at the node) + abs_tol x (model bbox diagonal).
     * Defaults 1e-6 and 1e-9. */
    double rel_tol, abs_tol;
    /* 0 (default): a node off G is an error. 1: nodes off G are left out of the result and
     * listed in its `off` (a mesh whose boundary is partly not on G, e.g. a wind tunnel
     * around a body); it is still an error when no node is on G. */
    int keep_off;
} cm_classify_options;

CM_API void cm_classify_options_init(cm_classify_options *opt);

/* The boundary nodes of a mesh, each on one entity of G. Arrays owned by the struct. */
typedef struct cm_surface_nodes {
    size_t n;            /* boundary nodes */
    int64_t *node;       /* n: mesh node index (ascending, as cm_mesh_boundary.nodes) */
    double *xyz;         /* n x 3: position when classified */
    unsigned char *kind; /* n: cm_surface_kind */
    int *entity;         /* n: vertex, edge or face of G (0-based) */
    double *param;       /* n x 2: face (u, v); edge (t, s); vertex (0, 0) */
    double *dist;        /* n: distance to the entity */
    double *h;           /* n: shortest boundary edge at the node */
    size_t count[3];     /* nodes per kind */
    double max_dist;     /* largest dist */
    size_t n_off;        /* with keep_off: boundary nodes off G (not among the n above) */
    int64_t *off;        /* n_off: their mesh node indices, ascending */
    double *off_dist;    /* n_off: their distance to G */
} cm_surface_nodes;

/* Shortest boundary-face edge at each boundary node: h_node (b->n_nodes, in the order of
 * b->nodes), and the shortest over all, *h_min (either may be NULL). Edges of zero length
 * are ignored (a node with only such edges gets the global minimum). */
CM_API cm_status cm_surface_edge_lengths(cm_context *ctx, const cm_mesh *mesh,
                                         const cm_mesh_boundary *b, double *h_node, double *h_min);

/* Classifies the boundary nodes of b: vertex if within tolerance of a CAD vertex, else edge
 * if within tolerance of an edge (t from the projection, s its arc length), else face (u,v);
 * with opt->keep_off the nodes off G are set aside in (n_off, off) instead of failing.
 * locator: built on g (its h about a quarter of the shortest boundary edge). A node farther
 * than the tolerance from every face is CM_ERR_MISMATCH; the message gives their count, the
 * worst distance and node, and suggests a unit mismatch when the mesh and model sizes differ
 * by a unit factor (10, 100, 1000, 25.4, 304.8). opt may be NULL for defaults. */
CM_API cm_status cm_surface_classify(cm_context *ctx, const cm_cad_model *g,
                                     const cm_cad_locator *locator, const cm_mesh *mesh,
                                     const cm_mesh_boundary *b, const cm_classify_options *opt,
                                     cm_surface_nodes **nodes);
CM_API void cm_surface_nodes_destroy(cm_surface_nodes **nodes);

/* ---- morph ---- */

typedef enum cm_surface_method {
    CM_SURFACE_RBF = 0,    /* parameter-space thin-plate warp per face (the method) */
    CM_SURFACE_PROJECT = 1 /* baseline: closest point on the matching entity of G' */
} cm_surface_method;

typedef struct cm_surface_morph_options {
    cm_surface_method method;
    /* Boundary samples per edge for the parameter warp: about length / spacing, clamped to
     * [min_per_edge, max_per_edge]. spacing <= 0: the median of the nodes' h, else
     * bbox diagonal / 100. Defaults: 0, 8, 200. */
    double spacing;
    int min_per_edge, max_per_edge;
    /* Affine edits (G' = A G + b) reproduced exactly: A, b are fitted on the vertices, or,
     * when the vertices cannot determine them (fewer than 4, coplanar), on the volume
     * moments and points over every edge and face (docs/DESIGN.md, "Affine edits"). When
     * they reproduce every vertex (and those points) within affine_tol x the bbox diagonal
     * of G', each edge and face that they map onto G' (points spread over it land within
     * that tolerance) sends its nodes to the images of their feet on G instead of equal arc
     * length and the parameter warp. Default 1e-9; 0 turns it off. RBF method only. */
    double affine_tol;
} cm_surface_morph_options;

CM_API void cm_surface_morph_options_init(cm_surface_morph_options *opt);

typedef struct cm_surface_morph_stats {
    size_t faces_warped;        /* faces with nodes, one 2D RBF each (RBF method) */
    size_t faces_skipped;       /* faces without interior nodes */
    size_t outside;             /* face nodes whose (u',v') left the trimmed domain of f'_k;
                                   they are put on the closest point of f'_k instead */
    int64_t worst_outside_node; /* mesh node, -1 if none */
    double worst_outside_dist;  /* how far f'_k(u',v') was from the trimmed face */
    size_t edges_affine;        /* edges and faces (with nodes) moved as affine images */
    size_t faces_affine;
    int affine;                 /* 1 if G moved by one affine map (docs/DESIGN.md) */
    double affine_residual;     /* largest miss of that map at the vertices, or at the vertex,
                                   edge and face points when the vertices alone cannot
                                   determine it (INFINITY: no fit) */
} cm_surface_morph_stats;

/* Morphs the classified nodes from G to G' (models that correspond: cm_cad_compare).
 * xyz: nodes->n x 3 output, the new positions in the order of nodes->node. Returns
 * CM_WARNING (message with count and worst node) when face nodes left their trimmed domain.
 * opt and stats may be NULL. */
CM_API cm_status cm_surface_morph(cm_context *ctx, const cm_cad_model *g, const cm_cad_model *g2,
                                  const cm_surface_nodes *nodes,
                                  const cm_surface_morph_options *opt, double *xyz,
                                  cm_surface_morph_stats *stats);

/* What the surface morph computes from G and the nodes alone, kept across targets: the
 * boundary samples of every face of G, the factorised thin-plate system of its parameter warp
 * (only the right-hand side depends on G': each target is one solve with the factor) and the
 * nodes grouped by entity (docs/DESIGN.md, "Surface morph across targets"). Filled on first
 * use; a call with another G, other nodes or other sampling options empties it first. G and
 * the nodes are identified by address: empty it (cm_surface_morph_cache_clear) before they
 * are freed or changed in place. Not for concurrent calls. */
typedef struct cm_surface_morph_cache cm_surface_morph_cache;

CM_API cm_status cm_surface_morph_cache_create(cm_context *ctx, cm_surface_morph_cache **cache);
CM_API void cm_surface_morph_cache_clear(cm_surface_morph_cache *cache);
CM_API void cm_surface_morph_cache_destroy(cm_surface_morph_cache **cache);

/* cm_surface_morph with a cache (NULL: none, as cm_surface_morph): the same positions, bit
 * for bit, whatever the cache held before. */
CM_API cm_status cm_surface_morph_cached(cm_context *ctx, cm_surface_morph_cache *cache,
                                         const cm_cad_model *g, const cm_cad_model *g2,
                                         const cm_surface_nodes *nodes,
                                         const cm_surface_morph_options *opt, double *xyz,
                                         cm_surface_morph_stats *stats);

/* Distance of points (n x 3) to the model of the locator: the largest, and the index of the
 * point where it occurs (either may be NULL). */
CM_API cm_status cm_surface_max_distance(cm_context *ctx, const cm_cad_locator *locator,
                                         const double *xyz, size_t n, double *max_dist,
                                         size_t *worst);

/* ---- constraint sets the CAD model knows (deformations with shape constraints) ---- */

typedef enum cm_surface_set_type {
    CM_SURFACE_SET_PLANE = 0,    /* the nodes of a planar face */
    CM_SURFACE_SET_CYLINDER = 1, /* the nodes of a cylindrical face */
    CM_SURFACE_SET_CIRCLE = 2,   /* the nodes of a circular edge */
    CM_SURFACE_SET_CONE = 3      /* the nodes of a conical face */
} cm_surface_set_type;

/* Which entities become sets: every face/edge of a type whose flag is set, plus the listed
 * ids (0-based) whatever the flags say. */
typedef struct cm_surface_set_filter {
    int plane, cylinder, circle, cone;
    int n_faces, n_edges;
    const int *faces, *edges;
} cm_surface_set_filter;

typedef struct cm_surface_set {
    cm_surface_set_type type;
    int entity;     /* the face (plane, cylinder, cone) or edge (circle) of G */
    size_t n;       /* nodes, ascending */
    int64_t *nodes; /* owned by the cm_surface_sets */
} cm_surface_set;

typedef struct cm_surface_sets {
    size_t n;
    cm_surface_set *set; /* faces first (ascending id), then edges */
} cm_surface_sets;

/* The constraint sets of a volume mesh lying on G: the boundary nodes are classified on G
 * (cm_surface_classify, a locator of h = shortest boundary edge / 4); a planar, cylindrical
 * or conical face's set holds the nodes on the face, on the edges of its wires and on
 * their vertices; a circular edge's set the nodes on the edge and its end vertices, so a
 * node may be in several sets. Sets with fewer nodes than their fit needs (3; cylinders 5)
 * are left out (cones 6). filter NULL: all planes, cylinders, cones and circles. A listed
 * face that is no plane, cylinder or cone, or edge that is no circle, is CM_ERR_UNSUPPORTED; an id out of range
 * CM_ERR_MISMATCH; a mesh without volume cells CM_ERR_UNSUPPORTED. */
CM_API cm_status cm_surface_cad_sets(cm_context *ctx, const cm_cad_model *g, const cm_mesh *mesh,
                                     const cm_surface_set_filter *filter, cm_surface_sets **sets);
CM_API void cm_surface_sets_destroy(cm_surface_sets **sets);

#ifdef __cplusplus
}
#endif
#endif
