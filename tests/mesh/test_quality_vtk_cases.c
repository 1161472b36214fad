/* Writes random, distorted, inverted and degenerate tets, hexes and wedges with our scaled
 * Jacobian to WORK/quality_vtk_cases.txt; check_quality_vtk.py recomputes them with VTK's
 * vtkMeshQuality (Verdict) and fails on any difference above 1e-9. */
#include "cadmorph/mesh.h"
#include "test_rng.h"
#include "test_util.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static uint64_t rng_state = 0x2545F4914F6CDD1Dull;

static double uniform(void) { return test_rng_uniform(&rng_state); }

static double noise(double a) { return a * (2.0 * uniform() - 1.0); }

static void emit(FILE *f, cm_cell_type type, const char *name, int n, double (*p)[3])
{
    fprintf(f, "%s", name);
    for (int i = 0; i < n; ++i) fprintf(f, " %.17g %.17g %.17g", p[i][0], p[i][1], p[i][2]);
    fprintf(f, " %.17g\n", cm_quality_scaled_jacobian(type, &p[0][0]));
}

int main(int argc, char **argv)
{
    if (argc < 3) return 2;
    char path[4096];
    snprintf(path, sizeof path, "%s/quality_vtk_cases.txt", argv[2]);
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        return 2;
    }
    static const double cube[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                      {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    const double s3 = 1.7320508075688772;
    const double reg_tet[4][3] = {{0, 0, 0}, {1, 0, 0}, {0.5, s3 / 2, 0}, {0.5, s3 / 6, 0.816496580927726}};
    /* VTK-ordered right wedge (0-1-2 clockwise seen from 3-4-5) */
    const double reg_wedge[6][3] = {{0, 0, 0}, {0.5, s3 / 2, 0}, {1, 0, 0},
                                    {0, 0, 1}, {0.5, s3 / 2, 1}, {1, 0, 1}};
    int n_tet = 0, n_hex = 0, n_wedge = 0, n_neg = 0;
    for (int k = 0; k < 1500; ++k) {
        double p[4][3];
        const int kind = k % 5;
        for (int i = 0; i < 4; ++i)
            for (int d = 0; d < 3; ++d) {
                if (kind == 0) p[i][d] = noise(1.0);                              /* random */
                else if (kind == 1) p[i][d] = reg_tet[i][d] + noise(0.3);         /* distorted */
                else if (kind == 2) p[i][d] = 100.0 * reg_tet[i][d] + noise(45.0); /* large, wild */
                else if (kind == 3) p[i][d] = reg_tet[i][d] + noise(0.05);
                else p[i][d] = 1e-3 * (reg_tet[i][d] + noise(0.6)); /* mm-sized */
            }
        if (k % 7 == 0) { /* inverted copy */
            double t[3];
            memcpy(t, p[1], sizeof t);
            memcpy(p[1], p[2], sizeof t);
            memcpy(p[2], t, sizeof t);
        }
        if (k % 97 == 0) memcpy(p[3], p[0], sizeof p[3]); /* collapsed edge */
        if (k % 101 == 0) p[3][2] = p[0][2] = p[1][2] = p[2][2] = 0.25; /* flat */
        if (cm_quality_scaled_jacobian(CM_CELL_TET4, &p[0][0]) <= 0) ++n_neg;
        emit(f, CM_CELL_TET4, "tet", 4, p);
        ++n_tet;
    }
    for (int k = 0; k < 1500; ++k) {
        double p[8][3];
        const double amp = (k % 4 == 0) ? 0.6 : (k % 4 == 1) ? 0.25 : (k % 4 == 2) ? 0.05 : 1.2;
        const double sx = 0.5 + 3.0 * uniform(), sy = 0.5 + 3.0 * uniform(), sz = 0.5 + 3.0 * uniform();
        for (int i = 0; i < 8; ++i) {
            p[i][0] = sx * cube[i][0] + noise(amp);
            p[i][1] = sy * cube[i][1] + noise(amp);
            p[i][2] = sz * cube[i][2] + noise(amp);
        }
        if (k % 9 == 0) /* inverted: top and bottom swapped */
            for (int i = 0; i < 4; ++i)
                for (int d = 0; d < 3; ++d) {
                    double t = p[i][d];
                    p[i][d] = p[i + 4][d];
                    p[i + 4][d] = t;
                }
        if (k % 113 == 0) memcpy(p[6], p[5], sizeof p[6]); /* zero-length edge */
        if (cm_quality_scaled_jacobian(CM_CELL_HEX8, &p[0][0]) <= 0) ++n_neg;
        emit(f, CM_CELL_HEX8, "hex", 8, p);
        ++n_hex;
    }
    for (int k = 0; k < 1000; ++k) {
        double p[6][3];
        const double amp = (k % 3 == 0) ? 0.5 : (k % 3 == 1) ? 0.15 : 0.02;
        for (int i = 0; i < 6; ++i)
            for (int d = 0; d < 3; ++d) p[i][d] = reg_wedge[i][d] + noise(amp);
        if (k % 8 == 0) /* inverted: Verdict's (gmsh) numbering */
            for (int d = 0; d < 3; ++d) {
                double t = p[1][d];
                p[1][d] = p[2][d];
                p[2][d] = t;
                t = p[4][d];
                p[4][d] = p[5][d];
                p[5][d] = t;
            }
        if (cm_quality_scaled_jacobian(CM_CELL_WEDGE6, &p[0][0]) <= 0) ++n_neg;
        emit(f, CM_CELL_WEDGE6, "wedge", 6, p);
        ++n_wedge;
    }
    fclose(f);
    printf("wrote %d tets, %d hexes, %d wedges (%d with SJ <= 0) to %s\n", n_tet, n_hex, n_wedge,
           n_neg, path);
    CHECK(n_neg > 200); /* the comparison must cover inverted cells */
    return TEST_REPORT();
}
