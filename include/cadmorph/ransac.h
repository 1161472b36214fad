/* cadmorph primitive detection on a surface mesh (MLS paper section 6.3): the efficient
 * RANSAC of Schnabel, Wahl, Klein ("Efficient RANSAC for point-cloud shape detection", 2007)
 * on face barycentres and face normals (not vertex normals: at a sharp edge those belong to
 * no primitive, the paper's Figure 7), planes, cylinders, spheres and cones, each candidate
 * refined by a forward search (grow through face neighbours compatible with the refitted
 * primitive, refit, repeat); at the end a face on a primitive's border moves to a
 * neighbouring primitive it fits closer (tangent blends). A primitive is assigned to every vertex of its faces, so a
 * vertex may belong to several. Conventions: see core.h. */
#ifndef CADMORPH_RANSAC_H
#define CADMORPH_RANSAC_H

#include "cadmorph/core.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum cm_primitive_type {
    CM_PRIMITIVE_PLANE = 0,
    CM_PRIMITIVE_CYLINDER,
    CM_PRIMITIVE_SPHERE,
    CM_PRIMITIVE_CONE
} cm_primitive_type;

/* "plane", "cylinder", "sphere", "cone" */
CM_API const char *cm_primitive_type_name(cm_primitive_type t);

typedef struct cm_primitive {
    cm_primitive_type type;
    /* plane: point[3], unit normal[3]; cylinder: point on the axis[3], unit axis[3], radius;
     * sphere: centre[3], radius; cone: apex[3], unit axis[3] (into the cone), half-angle (rad) */
    double p[7];
    size_t n_faces;
    double area;
    double rms; /* root mean square distance of its faces' barycentres */
} cm_primitive;

typedef struct cm_ransac_options {
    double epsilon;      /* distance tolerance, relative to the bounding-box diagonal (0.005) */
    double normal_angle; /* largest deviation of a face normal from the primitive's, degrees (15) */
    size_t min_faces;    /* tau: smallest primitive (0: 1 % of the faces, at least 10) */
    double probability;  /* p_t: the chance of having overlooked a better candidate (0.99) */
    unsigned types;      /* bit mask of 1 << cm_primitive_type (all four) */
    uint64_t seed;       /* random sampling (1) */
} cm_ransac_options;

CM_API void cm_ransac_options_init(cm_ransac_options *opt);

typedef struct cm_ransac_result {
    size_t n_primitives;
    cm_primitive *primitives;
    int32_t *face_primitive; /* #faces: the primitive of each face, -1 for none */
    int64_t *node_offset;    /* n_primitives + 1 into nodes */
    int64_t *nodes;          /* the vertices of each primitive's faces, ascending */
    size_t candidates;       /* minimal sets drawn */
} cm_ransac_result;

/* Faces: n_faces polygons (face_offset: n_faces + 1 into face_nodes, 0-based node ids into
 * xyz: #nodes x 3), e.g. the 2D cells of a surface mesh or the boundary of a volume mesh.
 * Deterministic for a seed. */
CM_API cm_status cm_ransac_detect(cm_context *ctx, size_t n_nodes, const double *xyz,
                                  size_t n_faces, const int64_t *face_offset,
                                  const int64_t *face_nodes, const cm_ransac_options *opt,
                                  cm_ransac_result **result);
CM_API void cm_ransac_result_destroy(cm_ransac_result **result);

#ifdef __cplusplus
}
#endif
#endif
