/* Placeholder until implemented. */
#include "cadmorph/mesh.h"
#include <math.h>

double cm_quality_scaled_jacobian(cm_cell_type type, const double *xyz) { (void)type; (void)xyz; return NAN; }
double cm_quality_polyhedron(const double *mesh_xyz, const int64_t *face_stream) { (void)mesh_xyz; (void)face_stream; return NAN; }
cm_status cm_mesh_quality(cm_context *ctx, const cm_mesh *mesh, double *sj) { (void)mesh; (void)sj; return cm_error(ctx, CM_ERR_UNSUPPORTED, "not implemented yet"); }
cm_status cm_quality_summarize(cm_context *ctx, const cm_mesh *mesh, const double *sj, cm_quality_stats *per_type, cm_quality_stats *all) { (void)mesh; (void)sj; (void)per_type; (void)all; return cm_error(ctx, CM_ERR_UNSUPPORTED, "not implemented yet"); }
