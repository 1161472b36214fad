/* checkMesh's layout for cm_foam_quality (the "Mesh stats", "Checking topology..." and
 * "Checking geometry..." blocks of OpenFOAM v1912's checkMesh, numbers with its 6 significant digits) and
 * cadmorph's one-line summary. */
#include "cli.h"

static void vec(FILE *out, const double *v)
{
    fprintf(out, "(%g %g %g)", v[0], v[1], v[2]);
}

/* The name of patch k (0-based): the mesh's 2-D group of tag k + 1. */
static const char *patch_name(const cm_mesh *mesh, int64_t k, char *buf, size_t cap)
{
    for (size_t i = 0; mesh && i < mesh->n_groups; ++i)
        if (mesh->groups[i].dim == 2 && mesh->groups[i].tag == k + 1 && mesh->groups[i].name)
            return mesh->groups[i].name;
    snprintf(buf, cap, "patch%lld", (long long)k);
    return buf;
}

void cli_print_foam_quality(const cm_foam_quality *q, const cm_mesh *mesh, FILE *out)
{
    char nbuf[32];
    fprintf(out,
            "Mesh stats\n"
            "    points:           %zu\n"
            "    faces:            %zu\n"
            "    internal faces:   %zu\n"
            "    cells:            %zu\n"
            "    faces per cell:   %g\n"
            "    boundary patches: %zu\n\n",
            q->points, q->faces, q->internal_faces, q->cells,
            q->cells ? (double)(2 * q->internal_faces + (q->faces - q->internal_faces)) / (double)q->cells : 0.0,
            q->patches);
    fprintf(out,
            "Overall number of cells of each type:\n"
            "    hexahedra:     %zu\n"
            "    prisms:        %zu\n"
            "    wedges:        %zu\n"
            "    pyramids:      %zu\n"
            "    tet wedges:    %zu\n"
            "    tetrahedra:    %zu\n"
            "    polyhedra:     %zu\n\n",
            q->hexahedra, q->prisms, q->wedges, q->pyramids, q->tet_wedges, q->tetrahedra, q->polyhedra);
    /* the patches of a mesh cadmorph reads are contiguous and cover the boundary faces */
    fprintf(out, "Checking topology...\n    Boundary definition OK.\n");
    if (q->empty_not_2d)
        fprintf(out, " ***Total number of faces on empty patches is not divisible by the number of cells in "
                     "the mesh. Hence this mesh is not 1D or 2D.\n");
    if (q->illegal_cells)
        fprintf(out, "    Illegal cells (less than 4 faces or out of range faces) found,  number of cells: %zu\n",
                q->illegal_cells);
    else
        fprintf(out, "    Cell to face addressing OK.\n");
    if (q->unused_points_faces || q->unused_points_cells)
        fprintf(out, " ***Unused points found in the mesh, number unused by faces: %zu number unused by cells: %zu\n",
                q->unused_points_faces, q->unused_points_cells);
    else
        fprintf(out, "    Point usage OK.\n");
    if (q->multiple_face_cells)
        fprintf(out, "  <<Found %zu neighbouring cells with multiple inbetween faces.\n", q->multiple_face_cells);
    fprintf(out, q->upper_triangular_error ? " ***Faces not in upper triangular order.\n"
                                           : "    Upper triangular ordering OK.\n");
    if (q->bad_vertex_faces)
        fprintf(out, "    Faces with invalid vertex labels found,  number of faces: %zu\n", q->bad_vertex_faces);
    else
        fprintf(out, "    Face vertices OK.\n");
    if (q->regions <= 1)
        fprintf(out, "    Number of regions: %zu (OK).\n", q->regions);
    else
        fprintf(out, "   *Number of regions: %zu\n    The mesh has multiple regions which are not connected by "
                     "any face.\n", q->regions);
    int nd = 0, ns = 0;
    for (int k = 0; k < 3; ++k) {
        nd += q->directions[k] == 1;
        ns += q->solution_directions[k] == 1;
    }
    fprintf(out, "\nChecking geometry...\n    Overall domain bounding box ");
    vec(out, q->bbox);
    fputc(' ', out);
    vec(out, q->bbox + 3);
    fprintf(out, "\n    Mesh has %d geometric (non-empty/wedge) directions (%d %d %d)\n", nd,
            q->directions[0] == 1, q->directions[1] == 1, q->directions[2] == 1);
    fprintf(out, "    Mesh has %d solution (non-empty) directions (%d %d %d)\n", ns,
            q->solution_directions[0] == 1, q->solution_directions[1] == 1, q->solution_directions[2] == 1);
    if (q->alignment_checked == 2 && q->wedge_error == 0)
        fprintf(out, "    Wedge angle %g degrees\n", q->wedge_angle);
    if (q->wedge_error == 1)
        fprintf(out, " ***Cannot find opposite wedge for wedge %s\n", patch_name(mesh, q->wedge_patch, nbuf, sizeof nbuf));
    else if (q->wedge_error == 3)
        fprintf(out, " ***Wedge patch %s not planar. A point is not in patch plane by %g metre.\n",
                patch_name(mesh, q->wedge_patch, nbuf, sizeof nbuf), q->wedge_off_plane);
    else if (q->alignment_checked && q->non_aligned_edges)
        fprintf(out, " ***Number of edges not aligned with or perpendicular to non-empty directions: %zu\n",
                q->non_aligned_edges);
    else if (q->alignment_checked)
        fprintf(out, "    All edges aligned with or perpendicular to non-empty directions.\n");
    if (q->boundary_open) {
        fprintf(out, " ***Boundary openness ");
        vec(out, q->boundary_openness);
        fprintf(out, " possible hole in boundary description.\n");
    } else {
        fprintf(out, "    Boundary openness ");
        vec(out, q->boundary_openness);
        fprintf(out, " OK.\n");
    }
    if (q->open_cells)
        fprintf(out, " ***Open cells found, max cell openness: %g, number of open cells %zu\n", q->max_cell_openness,
                q->open_cells);
    else if (q->high_aspect_cells)
        fprintf(out, " ***High aspect ratio cells found, Max aspect ratio: %g, number of cells %zu\n",
                q->max_aspect_ratio, q->high_aspect_cells);
    else
        fprintf(out, "    Max cell openness = %g OK.\n    Max aspect ratio = %g OK.\n", q->max_cell_openness,
                q->max_aspect_ratio);
    if (q->min_face_area < 1e-300)
        fprintf(out, " ***Zero or negative face area detected.  Minimum area: %g\n", q->min_face_area);
    else
        fprintf(out, "    Minimum face area = %g. Maximum face area = %g.  Face area magnitudes OK.\n", q->min_face_area,
                q->max_face_area);
    if (q->min_volume < 1e-300)
        fprintf(out, " ***Zero or negative cell volume detected.  Minimum negative volume: %g, Number of negative volume cells: %zu\n",
                q->min_volume, q->negative_volume_cells);
    else
        fprintf(out, "    Min volume = %g. Max volume = %g.  Total volume = %g.  Cell volumes OK.\n", q->min_volume,
                q->max_volume, q->total_volume);
    if (q->internal_faces)
        fprintf(out, "    Mesh non-orthogonality Max: %g average: %g\n", q->max_non_orthogonality,
                q->avg_non_orthogonality);
    if (q->severe_non_orthogonal_faces)
        fprintf(out, "   *Number of severely non-orthogonal (> 70 degrees) faces: %zu.\n", q->severe_non_orthogonal_faces);
    if (q->non_orthogonality_errors)
        fprintf(out, " ***Number of non-orthogonality errors: %zu.\n", q->non_orthogonality_errors);
    else
        fprintf(out, "    Non-orthogonality check OK.\n");
    if (q->wrong_pyramids)
        fprintf(out, " ***Error in face pyramids: %zu faces are incorrectly oriented.\n", q->wrong_pyramids);
    else
        fprintf(out, "    Face pyramids OK.\n");
    if (q->high_skew_faces)
        fprintf(out, " ***Max skewness = %g, %zu highly skew faces detected which may impair the quality of the results\n",
                q->max_skewness, q->high_skew_faces);
    else
        fprintf(out, "    Max skewness = %g OK.\n", q->max_skewness);
    if (q->coupled_point_errors)
        fprintf(out, "  **Error in coupled point location: %zu faces have their 0th or consecutive vertex not "
                     "opposite their coupled equivalent. Average mismatch %g.\n",
                q->coupled_point_errors, q->coupled_avg_mismatch);
    else
        fprintf(out, "    Coupled point location match (average %g) OK.\n", q->coupled_avg_mismatch);
    if (q->failed_checks) fprintf(out, "\nFailed %zu mesh checks.\n\n", q->failed_checks);
    else fprintf(out, "\nMesh OK.\n\n");
    fprintf(out,
            "max_aspect_ratio=%.9g max_non_orthogonality=%.9g avg_non_orthogonality=%.9g max_skewness=%.9g "
            "wrong_pyramids=%zu negative_volumes=%zu failed_checks=%zu cells=%zu\n",
            q->max_aspect_ratio, q->max_non_orthogonality, q->avg_non_orthogonality, q->max_skewness,
            q->wrong_pyramids, q->negative_volume_cells, q->failed_checks, q->cells);
}
