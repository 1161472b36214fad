/* checkMesh's layout for cm_foam_quality (the "Mesh stats" and "Checking geometry..."
 * blocks of OpenFOAM v1912's checkMesh, numbers with its 6 significant digits) and
 * cadmorph's one-line summary. */
#include "cli.h"

static void vec(FILE *out, const double *v)
{
    fprintf(out, "(%g %g %g)", v[0], v[1], v[2]);
}

void cli_print_foam_quality(const cm_foam_quality *q, FILE *out)
{
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
            "    pyramids:      %zu\n"
            "    tetrahedra:    %zu\n"
            "    polyhedra:     %zu\n\n",
            q->hexahedra, q->prisms, q->pyramids, q->tetrahedra, q->polyhedra);
    int nd = 0;
    for (int k = 0; k < 3; ++k) nd += q->directions[k] == 1;
    fprintf(out, "Checking geometry...\n    Overall domain bounding box ");
    vec(out, q->bbox);
    fputc(' ', out);
    vec(out, q->bbox + 3);
    fprintf(out, "\n    Mesh has %d geometric (non-empty/wedge) directions (%d %d %d)\n", nd, q->directions[0],
            q->directions[1], q->directions[2]);
    fprintf(out, "    Mesh has %d solution (non-empty) directions (%d %d %d)\n", nd, q->directions[0],
            q->directions[1], q->directions[2]);
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
    if (q->failed_checks) fprintf(out, "\nFailed %zu mesh checks.\n\n", q->failed_checks);
    else fprintf(out, "\nMesh OK.\n\n");
    fprintf(out,
            "max_aspect_ratio=%.9g max_non_orthogonality=%.9g avg_non_orthogonality=%.9g max_skewness=%.9g "
            "wrong_pyramids=%zu negative_volumes=%zu failed_checks=%zu cells=%zu\n",
            q->max_aspect_ratio, q->max_non_orthogonality, q->avg_non_orthogonality, q->max_skewness,
            q->wrong_pyramids, q->negative_volume_cells, q->failed_checks, q->cells);
}
