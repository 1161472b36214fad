/* checkMesh's default topology checks and its cell-type table, written from the definitions
 * of OpenFOAM v1912 (checkTopology: cell-to-face addressing, primitiveMesh::checkPoints,
 * checkUpperTriangular, checkFaceVertices, regionSplit, the empty-patch count; the cell models
 * hex, prism, wedge, pyr, tetWedge, tet of checkMesh's mesh stats). */
#define _POSIX_C_SOURCE 200809L
#include "quality_foam_internal.h"

#include <stdlib.h>
#include <string.h>

typedef struct nbr_rec {
    int64_t cell, face;
    size_t order; /* position in the cell's face list: keeps the sort stable */
} nbr_rec;

static int cmp_nbr(const void *x, const void *y)
{
    const nbr_rec *a = x, *b = y;
    if (a->cell != b->cell) return a->cell < b->cell ? -1 : 1;
    return a->order < b->order ? -1 : a->order > b->order;
}

static int64_t find_root(int64_t *up, int64_t i)
{
    while (up[i] != i) {
        up[i] = up[up[i]];
        i = up[i];
    }
    return i;
}

/* The cell type as OpenFOAM's cell models see it, from the counts of faces, their sizes and
 * the distinct points: each model has its own signature among closed cells (hex: 6 quads on
 * 8 points; prism: 2 triangles and 3 quads on 6; wedge - a hex with one edge collapsed - 2
 * triangles and 4 quads on 7; pyramid: 1 quad and 4 triangles on 5; tet wedge: 2 triangles
 * and 2 quads on 5; tet: 4 triangles on 4). */
static void count_type(cm_foam_quality *q, int nfaces, int ntri, int nquad, int nother, int64_t npoints)
{
    if (nother == 0) {
        if (nfaces == 6 && nquad == 6 && npoints == 8) return (void)++q->hexahedra;
        if (nfaces == 5 && ntri == 2 && nquad == 3 && npoints == 6) return (void)++q->prisms;
        if (nfaces == 6 && ntri == 2 && nquad == 4 && npoints == 7) return (void)++q->wedges;
        if (nfaces == 5 && ntri == 4 && nquad == 1 && npoints == 5) return (void)++q->pyramids;
        if (nfaces == 4 && ntri == 2 && nquad == 2 && npoints == 5) return (void)++q->tet_wedges;
        if (nfaces == 4 && ntri == 4 && npoints == 4) return (void)++q->tetrahedra;
    }
    ++q->polyhedra;
}

cm_status cm_foam_check_topology(cm_context *ctx, const cm_foam_poly *p, cm_foam_quality *q)
{
    const int64_t nf = p->n_faces, ni = p->n_internal, nc = p->n_cells, np = p->n_points;
    cm_status s = CM_OK;
    /* the cells' face lists as primitiveMesh builds them: owned faces, then neighboured ones */
    int64_t *coff = calloc((size_t)nc + 1, sizeof *coff);
    int64_t *cfaces = malloc((size_t)(ni + nf ? ni + nf : 1) * sizeof *cfaces);
    int64_t *fill = malloc((size_t)(nc ? nc : 1) * sizeof *fill);
    uint8_t *used = calloc((size_t)(np ? np : 1), 1);
    int64_t *mark = malloc((size_t)(np ? np : 1) * sizeof *mark);
    int64_t *up = malloc((size_t)(nc ? nc : 1) * sizeof *up);
    nbr_rec *nbr = NULL;
    size_t nbr_cap = 0;
    if (!coff || !cfaces || !fill || !used || !mark || !up) goto nomem;
    for (int64_t f = 0; f < nf; ++f) ++coff[p->owner[f] + 1];
    for (int64_t f = 0; f < ni; ++f) ++coff[p->neighbour[f] + 1];
    for (int64_t c = 0; c < nc; ++c) coff[c + 1] += coff[c];
    memcpy(fill, coff, (size_t)nc * sizeof *fill);
    for (int64_t f = 0; f < nf; ++f) cfaces[fill[p->owner[f]]++] = f;
    for (int64_t f = 0; f < ni; ++f) cfaces[fill[p->neighbour[f]]++] = f;

    /* cells of fewer than 4 faces (the face labels are in range by construction) */
    for (int64_t c = 0; c < nc; ++c)
        if (coff[c + 1] - coff[c] <= 3) ++q->illegal_cells;

    /* face vertices out of range or repeated within the face; points no face uses (every
     * face has an owner cell, so a point of no cell is a point of no face) */
    for (int64_t i = 0; i < np; ++i) mark[i] = -1;
    for (int64_t f = 0; f < nf; ++f) {
        int out = 0;
        for (int64_t k = p->face_off[f]; k < p->face_off[f + 1]; ++k) {
            const int64_t v = p->face_nodes[k];
            if (v < 0 || v >= np) {
                out = 1;
                continue;
            }
            used[v] = 1;
            if (mark[v] == f) ++q->bad_vertex_faces;
            mark[v] = f;
        }
        q->bad_vertex_faces += (size_t)out;
    }
    for (int64_t i = 0; i < np; ++i)
        if (!used[i]) ++q->unused_points_faces, ++q->unused_points_cells;

    /* upper-triangular order: owner < neighbour, and for each cell the faces to its
     * higher-numbered neighbours numbered in the order of those neighbours */
    for (int64_t f = 0; f < ni; ++f)
        if (p->owner[f] >= p->neighbour[f]) q->upper_triangular_error = 1;
    for (int64_t c = 0; c < nc; ++c) {
        const size_t n = (size_t)(coff[c + 1] - coff[c]);
        if (n > nbr_cap) {
            nbr_rec *t = realloc(nbr, 2 * n * sizeof *nbr);
            if (!t) goto nomem;
            nbr = t;
            nbr_cap = 2 * n;
        }
        size_t m = 0;
        for (size_t i = 0; i < n; ++i) {
            const int64_t f = cfaces[coff[c] + (int64_t)i];
            if (f >= ni) continue;
            const int64_t other = p->neighbour[f] == c ? p->owner[f] : p->neighbour[f];
            if (c < other) nbr[m++] = (nbr_rec){other, f, i};
        }
        qsort(nbr, m, sizeof *nbr, cmp_nbr);
        int multiple = 0;
        for (size_t i = 1; i < m; ++i) {
            if (nbr[i].cell == nbr[i - 1].cell) multiple = 1;
            else if (nbr[i].face < nbr[i - 1].face) q->upper_triangular_error = 1;
        }
        q->multiple_face_cells += (size_t)multiple;
    }

    /* regions: cells connected through internal faces */
    for (int64_t c = 0; c < nc; ++c) up[c] = c;
    for (int64_t f = 0; f < ni; ++f) {
        int64_t a = find_root(up, p->owner[f]), b = find_root(up, p->neighbour[f]);
        if (a != b) up[a > b ? a : b] = a < b ? a : b;
    }
    for (int64_t c = 0; c < nc; ++c)
        if (find_root(up, c) == c) ++q->regions;

    /* empty patches: a 1-D or 2-D mesh has a multiple of its cells on them */
    {
        int64_t n_empty = 0;
        for (size_t i = 0; i < p->n_patches; ++i)
            if (p->patches[i].type && !strcmp(p->patches[i].type, "empty")) n_empty += p->patches[i].n;
        q->empty_not_2d = nc && n_empty % nc;
    }

    /* cell types */
    for (int64_t i = 0; i < np; ++i) mark[i] = -1;
    for (int64_t c = 0; c < nc; ++c) {
        int ntri = 0, nquad = 0, nother = 0;
        int64_t npts = 0;
        for (int64_t i = coff[c]; i < coff[c + 1]; ++i) {
            const int64_t f = cfaces[i], k = p->face_off[f + 1] - p->face_off[f];
            if (k == 3) ++ntri;
            else if (k == 4) ++nquad;
            else ++nother;
            for (int64_t j = p->face_off[f]; j < p->face_off[f + 1]; ++j) {
                const int64_t v = p->face_nodes[j];
                if (v < 0 || v >= np || mark[v] == c) continue;
                mark[v] = c;
                ++npts;
            }
        }
        count_type(q, (int)(coff[c + 1] - coff[c]), ntri, nquad, nother, npts);
    }
    goto done;
nomem:
    s = cm_error(ctx, CM_ERR_NOMEM, "out of memory for the topology checks of %lld cells", (long long)nc);
done:
    free(coff);
    free(cfaces);
    free(fill);
    free(used);
    free(mark);
    free(up);
    free(nbr);
    return s;
}
