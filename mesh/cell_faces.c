/* Local face tables of volume cells in VTK order (the same faces, in the same order and
 * orientation, as vtkTetra/vtkHexahedron/vtkWedge/vtkPyramid::GetFace - outward for a cell of
 * positive volume), and where the higher-order nodes of each type sit. */
#include "cell_faces.h"


static const cm_face_table tet_faces = {4, {3, 3, 3, 3}, {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 2, 1}}};
static const cm_face_table hex_faces = {6,
                                     {4, 4, 4, 4, 4, 4},
                                     {{0, 4, 7, 3},
                                      {1, 2, 6, 5},
                                      {0, 1, 5, 4},
                                      {3, 7, 6, 2},
                                      {0, 3, 2, 1},
                                      {4, 5, 6, 7}}};
static const cm_face_table wedge_faces = {
    5, {3, 3, 4, 4, 4}, {{0, 1, 2}, {3, 5, 4}, {0, 3, 4, 1}, {1, 4, 5, 2}, {2, 5, 3, 0}}};
static const cm_face_table pyramid_faces = {
    5, {4, 3, 3, 3, 3}, {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}}};

/* Higher-order nodes: node corners + i sits on edge i of this list (VTK's numbering), and the
 * mid-face nodes that follow sit on the face with the listed corners; both were checked
 * against the parametric coordinates of vtkQuadraticTetra, vtkQuadraticHexahedron,
 * vtkTriQuadraticHexahedron, vtkQuadraticWedge, vtkBiQuadraticQuadraticWedge and
 * vtkQuadraticPyramid. A node lies on a face when all its defining corners do. */
typedef struct ho_table {
    int n_edges;
    int edge[12][2];
    int n_face_nodes; /* mid-face nodes, numbered after the mid-edge nodes */
    int face_nodes[6][4];
    int face_size[6];
} ho_table;

static const ho_table tet_ho = {6, {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}, 0, {{0}}, {0}};
static const ho_table hex_ho = {12,
                                {{0, 1},
                                 {1, 2},
                                 {2, 3},
                                 {3, 0},
                                 {4, 5},
                                 {5, 6},
                                 {6, 7},
                                 {7, 4},
                                 {0, 4},
                                 {1, 5},
                                 {2, 6},
                                 {3, 7}},
                                6,
                                {{0, 3, 7, 4}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 2, 6, 7}, {0, 1, 2, 3}, {4, 5, 6, 7}},
                                {4, 4, 4, 4, 4, 4}};
static const ho_table wedge_ho = {9,
                                  {{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}},
                                  3,
                                  {{0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}},
                                  {4, 4, 4}};
static const ho_table pyramid_ho = {8,
                                    {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}},
                                    1,
                                    {{0, 1, 2, 3}},
                                    {4}};

static const cm_face_table *faces_of(cm_cell_type linear);

const cm_face_table *cm_cell_face_table(cm_cell_type type)
{
    const cm_cell_info *info = cm_cell_type_info(type);
    return info && info->dim == 3 ? faces_of(info->linear) : NULL;
}

static const cm_face_table *faces_of(cm_cell_type linear)
{
    switch (linear) {
    case CM_CELL_TET4: return &tet_faces;
    case CM_CELL_HEX8: return &hex_faces;
    case CM_CELL_WEDGE6: return &wedge_faces;
    case CM_CELL_PYR5: return &pyramid_faces;
    default: return NULL;
    }
}

static const ho_table *ho_of(cm_cell_type linear)
{
    switch (linear) {
    case CM_CELL_TET4: return &tet_ho;
    case CM_CELL_HEX8: return &hex_ho;
    case CM_CELL_WEDGE6: return &wedge_ho;
    case CM_CELL_PYR5: return &pyramid_ho;
    default: return NULL;
    }
}

int cm_cell_face_count(const cm_mesh *mesh, size_t c)
{
    const cm_cell_type type = (cm_cell_type)mesh->type[c];
    if (type == CM_CELL_POLYHEDRON) {
        const int64_t nf = mesh->conn[mesh->offset[c]];
        return nf > 0 && nf < (1 << 30) ? (int)nf : 0;
    }
    const cm_cell_info *info = cm_cell_type_info(type);
    if (!info || info->dim < 3) return 0;
    const cm_face_table *t = faces_of(info->linear);
    return t ? t->n_faces : 0;
}

int cm_cell_face_nodes(const cm_mesh *mesh, size_t c, int f, int64_t *nodes, int cap)
{
    const cm_cell_type type = (cm_cell_type)mesh->type[c];
    const int64_t *conn = mesh->conn + mesh->offset[c];
    if (type == CM_CELL_POLYHEDRON) {
        cm_polyhedron_face p = cm_polyhedron_begin(conn, mesh->offset[c + 1] - mesh->offset[c]);
        if (f < 0 || f >= p.n_faces) return -1;
        while (cm_polyhedron_more(&p) && p.face < f)
            cm_polyhedron_next(&p);
        if (!cm_polyhedron_more(&p) || p.n > cap) return -1;
        for (int64_t i = 0; i < p.n; ++i) nodes[i] = p.nodes[i];
        return (int)p.n;
    }
    const cm_cell_info *info = cm_cell_type_info(type);
    const cm_face_table *t = info ? faces_of(info->linear) : NULL;
    if (!t || f < 0 || f >= t->n_faces || t->size[f] > cap) return -1;
    for (int i = 0; i < t->size[f]; ++i) nodes[i] = conn[t->node[f][i]];
    return t->size[f];
}

int cm_cell_face_extra_nodes(const cm_mesh *mesh, size_t c, int f, int64_t nodes[5])
{
    const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
    if (!info || info->dim < 3 || info->nodes <= info->corners) return 0;
    const cm_face_table *t = faces_of(info->linear);
    const ho_table *h = ho_of(info->linear);
    if (!t || !h || f < 0 || f >= t->n_faces) return 0;
    const int64_t *conn = mesh->conn + mesh->offset[c];
    unsigned mask = 0;
    for (int i = 0; i < t->size[f]; ++i) mask |= 1u << t->node[f][i];
    int n = 0;
    for (int e = 0; e < h->n_edges && info->corners + e < info->nodes; ++e) {
        const unsigned em = (1u << h->edge[e][0]) | (1u << h->edge[e][1]);
        if ((em & mask) == em && n < 5) nodes[n++] = conn[info->corners + e];
    }
    const int first_face_node = info->corners + h->n_edges;
    for (int k = 0; k < h->n_face_nodes && first_face_node + k < info->nodes; ++k) {
        unsigned fm = 0;
        for (int i = 0; i < h->face_size[k]; ++i) fm |= 1u << h->face_nodes[k][i];
        if (fm == mask && n < 5) nodes[n++] = conn[first_face_node + k];
    }
    return n;
}
