/* checkMesh's checks, split by topic (not public): geometry of faces and cells
 * (quality_foam.c), topology and cell types (quality_foam_topology.c), directions, 2-D edge
 * alignment and wedges (quality_foam_2d.c), cyclic couplings (quality_foam_coupled.c). */
#ifndef CADMORPH_MESH_QUALITY_FOAM_INTERNAL_H
#define CADMORPH_MESH_QUALITY_FOAM_INTERNAL_H

#include "cadmorph/mesh.h"

#include "io/foam_internal.h"

#define FOAM_SMALL 1e-15
#define FOAM_ROOTSMALL 3.16227766016838e-08 /* sqrt(1e-15), OpenFOAM's ROOTSMALL */
#define FOAM_VSMALL 1e-300
#define FOAM_ROOTVSMALL 1e-150
#define FOAM_GREAT 1e15

/* OpenFOAM's face centres and areas (fc, fa: #faces x 3), cell centres and volumes (cc:
 * #cells x 3, vol: #cells), as primitiveMesh computes them. */
typedef struct cm_foam_geom {
    double *fc, *fa, *cc, *vol;
} cm_foam_geom;

cm_status cm_foam_geometry(cm_context *ctx, const cm_foam_poly *p, const double *xyz, cm_foam_geom *g);
void cm_foam_geometry_free(cm_foam_geom *g);

/* Per cell: 1 where checkMesh counts a negative volume or a face pyramid of the cell is
 * incorrectly oriented (bad: #cells, zeroed by the caller). */
void cm_foam_bad_cells(const cm_foam_poly *p, const cm_foam_geom *g, uint8_t *bad);

/* Topology checks and the cell-type table into q. */
cm_status cm_foam_check_topology(cm_context *ctx, const cm_foam_poly *p, cm_foam_quality *q);

/* Geometric and solution directions into q (needs face areas). */
void cm_foam_directions(const cm_foam_poly *p, const double *xyz, const double *fa, cm_foam_quality *q);

/* The 2-D edge alignment or the wedge checks into q; returns 1 when the check fails. */
cm_status cm_foam_check_alignment(cm_context *ctx, const cm_foam_poly *p, const double *xyz, const double *fa,
                                  cm_foam_quality *q, int *failed);

/* Cyclic couplings: nbr_cc (#boundary faces x 3) gets, for each face of a translational
 * cyclic patch, the centre of the cell across it moved next to this face; coupled
 * (#boundary faces) 1 for the owner side of a pair, 2 for the other side, 0 for faces of no
 * pair. Also checkMesh's coupled-point match into q. */
cm_status cm_foam_couplings(cm_context *ctx, const cm_foam_poly *p, const double *xyz, const cm_foam_geom *g,
                            double *nbr_cc, uint8_t *coupled, cm_foam_quality *q);

#endif
