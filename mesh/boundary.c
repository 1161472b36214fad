/* Boundary faces and nodes of the volume cells of a mesh, connected components of cells that
 * share a face, and the checks that go with them (non-manifold faces, duplicate cells). */
#include "cell_faces.h"

#include <omp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Polyhedron faces with more nodes than this are refused (keys live on the stack). */
#define CM_FACE_MAX_NODES 1024
#define CM_BOUNDARY_PARALLEL_MIN 20000

typedef int32_t cm_idx;
#define CM_IDX_MAX INT32_MAX

/* A face instance (one face of one cell) keyed by its node set, stored in the bucket of its
 * smallest node (which is therefore not stored): a, b, c are the next three smallest nodes,
 * c = -1 for triangles; for faces of more than four nodes (polyhedra only) c is a negative
 * 30-bit hash of the whole sorted list and its length, and equal keys are confirmed on the
 * full lists. Indices are 32-bit: the face arrays dominate the memory (and, through page
 * faults, the time) of the whole extraction, and 2^31 nodes or faces is far beyond what a
 * morph handles. */
typedef struct face_key {
    cm_idx inst;
    cm_idx a, b, c;
} face_key;

static void sort_small(int64_t *v, int n)
{
    for (int i = 1; i < n; ++i) {
        const int64_t x = v[i];
        int j = i - 1;
        while (j >= 0 && v[j] > x) {
            v[j + 1] = v[j];
            --j;
        }
        v[j + 1] = x;
    }
}

static int cmp_i64(const void *a, const void *b)
{
    const int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

static void sort_nodes(int64_t *v, int n)
{
    if (n <= 16) sort_small(v, n);
    else qsort(v, (size_t)n, sizeof *v, cmp_i64);
}

/* Sorts nodes[0..n) and fills the key; returns the smallest node (the bucket). */
static int64_t make_key(int64_t *nodes, int n, cm_idx inst, face_key *key)
{
    sort_nodes(nodes, n);
    key->inst = inst;
    key->a = (cm_idx)nodes[1];
    key->b = (cm_idx)nodes[2];
    key->c = n > 3 ? (cm_idx)nodes[3] : -1;
    if (n > 4) {
        uint64_t h = 0x9e3779b97f4a7c15ull ^ (uint64_t)n;
        for (int i = 0; i < n; ++i) {
            h ^= (uint64_t)nodes[i] + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
            h *= 0xff51afd7ed558ccdull;
        }
        key->c = -2 - (cm_idx)(h >> 34);
    }
    return nodes[0];
}

static inline int key_eq(const face_key *x, const face_key *y)
{
    /* a and b side by side: one 64-bit compare decides almost every pair */
    uint64_t ab_x, ab_y;
    memcpy(&ab_x, &x->a, sizeof ab_x);
    memcpy(&ab_y, &y->a, sizeof ab_y);
    return ab_x == ab_y && x->c == y->c;
}

/* by node set, then instance (so runs list their instances ascending) */
static int key_cmp(const void *pa, const void *pb)
{
    const face_key *x = pa, *y = pb;
    if (x->a != y->a) return x->a < y->a ? -1 : 1;
    if (x->b != y->b) return x->b < y->b ? -1 : 1;
    if (x->c != y->c) return x->c < y->c ? -1 : 1;
    return (x->inst > y->inst) - (x->inst < y->inst);
}

static cm_idx uf_find(cm_idx *parent, cm_idx x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]]; /* path halving */
        x = parent[x];
    }
    return x;
}

static void uf_union(cm_idx *parent, cm_idx a, cm_idx b)
{
    a = uf_find(parent, a);
    b = uf_find(parent, b);
    if (a == b) return;
    /* the smaller index becomes the root: components are then numbered by first cell */
    if (a < b) parent[b] = a;
    else parent[a] = b;
}

/* Face tables by type, looked up once: the face loops below run over millions of faces. */
typedef struct faces_of_types {
    const cm_face_table *t[CM_CELL_TYPE_COUNT];
} faces_of_types;

static void faces_init(faces_of_types *ft)
{
    for (int t = 0; t < CM_CELL_TYPE_COUNT; ++t) ft->t[t] = cm_cell_face_table((cm_cell_type)t);
}

static inline int face_count(const cm_mesh *mesh, const faces_of_types *ft, size_t c)
{
    const cm_face_table *t = ft->t[mesh->type[c]];
    return t ? t->n_faces : cm_cell_face_count(mesh, c);
}

static inline int face_nodes(const cm_mesh *mesh, const faces_of_types *ft, size_t c, int f, int64_t *nodes)
{
    const cm_face_table *t = ft->t[mesh->type[c]];
    if (!t) return cm_cell_face_nodes(mesh, c, f, nodes, CM_FACE_MAX_NODES);
    const int64_t *conn = mesh->conn + mesh->offset[c];
    for (int i = 0; i < t->size[f]; ++i) nodes[i] = conn[t->node[f][i]];
    return t->size[f];
}

/* Sorted distinct nodes of a cell (all nodes; for polyhedra those of the face stream);
 * -1 if more than cap. */
static int cell_node_set(const cm_mesh *mesh, size_t c, int64_t *out, int cap)
{
    const int64_t *conn = mesh->conn + mesh->offset[c];
    const int64_t len = mesh->offset[c + 1] - mesh->offset[c];
    int n = 0;
    if (mesh->type[c] == CM_CELL_POLYHEDRON) {
        for (cm_polyhedron_face f = cm_polyhedron_begin(conn, len); cm_polyhedron_more(&f);
             cm_polyhedron_next(&f))
            for (int64_t i = 0; i < f.n; ++i) {
                if (n >= cap) return -1;
                out[n++] = f.nodes[i];
            }
    } else {
        if (len > cap) return -1;
        for (int64_t i = 0; i < len; ++i) out[n++] = conn[i];
    }
    sort_nodes(out, n);
    int m = 0;
    for (int i = 0; i < n; ++i)
        if (m == 0 || out[m - 1] != out[i]) out[m++] = out[i];
    return m;
}

static int same_node_set(const cm_mesh *mesh, size_t a, size_t b)
{
    int64_t sa[64], sb[64];
    const int na = cell_node_set(mesh, a, sa, 64), nb = cell_node_set(mesh, b, sb, 64);
    if (na < 0 || nb < 0 || na != nb) return 0;
    return memcmp(sa, sb, (size_t)na * sizeof *sa) == 0;
}

void cm_mesh_boundary_destroy(cm_mesh_boundary **b)
{
    if (!b || !*b) return;
    free((*b)->face_offset);
    free((*b)->face_nodes);
    free((*b)->face_cell);
    free((*b)->nodes);
    free((*b)->cell_component);
    free(*b);
    *b = NULL;
}

typedef struct work {
    int64_t *inst_off;  /* #cells + 1: first face instance of each cell */
    cm_idx *inst_cell;  /* #instances: the cell of each instance */
    cm_idx *mate;       /* #instances: the next instance with the same node set (a cycle in
                           ascending order), -1 for a face of one cell */
    int64_t *bucket_off;
    face_key *bucket;   /* #instances: keys grouped by smallest node */
    cm_idx *parent;
    unsigned char *mark;
} work;

static void work_free(work *w)
{
    free(w->inst_off);
    free(w->inst_cell);
    free(w->mate);
    free(w->bucket_off);
    free(w->bucket);
    free(w->parent);
    free(w->mark);
}

/* Phase 1: every face instance and its key, bucketed by its smallest node (a hash table
 * whose hash is the smallest node, chained in CSR form: each bucket is tiny - about 12 faces
 * for a tet mesh). Keys are made here, in cell order, so that matching never goes back to
 * the connectivity of scattered cells. */
static cm_status bucket_faces(cm_context *ctx, const cm_mesh *mesh, const faces_of_types *ft, work *w,
                              int threads, size_t *n_inst_out)
{
    const size_t nc = mesh->n_cells, nn = mesh->n_nodes;
    w->inst_off = malloc((nc + 1) * sizeof *w->inst_off);
    if (!w->inst_off) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    w->inst_off[0] = 0;
    for (size_t c = 0; c < nc; ++c) w->inst_off[c + 1] = w->inst_off[c] + face_count(mesh, ft, c);
    const size_t ni = (size_t)w->inst_off[nc];
    *n_inst_out = ni;
    if (nn > CM_IDX_MAX || nc > CM_IDX_MAX || ni > CM_IDX_MAX)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_mesh_boundary_create: %zu nodes, %zu cells, %zu faces: more than 2^31-1", nn, nc, ni);
    w->inst_cell = malloc((ni ? ni : 1) * sizeof *w->inst_cell);
    w->mate = malloc((ni ? ni : 1) * sizeof *w->mate);
    w->bucket = malloc((ni ? ni : 1) * sizeof *w->bucket);
    w->bucket_off = malloc((nn + 1) * sizeof *w->bucket_off);
    if (!w->inst_cell || !w->mate || !w->bucket || !w->bucket_off)
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory (%zu faces)", ni);
    /* A counting sort by smallest node over parts contiguous cell ranges, each with its own
     * histogram, so that both passes run in parallel and every bucket still lists its
     * instances in ascending order (part by part). */
    const int parts = threads < 1 ? 1 : threads > 4 ? 4 : threads;
    cm_idx *hist = calloc((size_t)parts * (nn + 1), sizeof *hist);
    if (!hist) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    size_t bad_cell = SIZE_MAX;
    int bad_face = 0, bad_n = 0;
    int64_t bad_node = 0;
#pragma omp parallel num_threads(parts) if (nc > CM_BOUNDARY_PARALLEL_MIN)
    for (int t = omp_get_thread_num(); t < parts; t += omp_get_num_threads()) {
        int64_t nodes[CM_FACE_MAX_NODES];
        cm_idx *h = hist + (size_t)t * (nn + 1);
        const size_t c0 = nc * (size_t)t / (size_t)parts, c1 = nc * (size_t)(t + 1) / (size_t)parts;
        for (size_t c = c0; c < c1; ++c) {
            const int nf = (int)(w->inst_off[c + 1] - w->inst_off[c]);
            for (int f = 0; f < nf; ++f) {
                const int n = face_nodes(mesh, ft, c, f, nodes);
                int64_t mn = n > 0 ? nodes[0] : 0, out = -1;
                for (int k = 0; k < n; ++k) {
                    if (nodes[k] < 0 || (size_t)nodes[k] >= nn) out = nodes[k];
                    if (nodes[k] < mn) mn = nodes[k];
                }
                if (n < 3 || out != -1) {
#pragma omp critical(cm_boundary_error)
                    if (c < bad_cell) {
                        bad_cell = c;
                        bad_face = f;
                        bad_n = n;
                        bad_node = out;
                    }
                    c = c1; /* stop this part */
                    break;
                }
                w->inst_cell[w->inst_off[c] + f] = (cm_idx)c;
                ++h[mn];
            }
        }
    }
    if (bad_cell != SIZE_MAX) {
        free(hist);
        if (bad_n < 0)
            return cm_error(ctx, CM_ERR_UNSUPPORTED, "cm_mesh_boundary_create: cell %zu: face %d has more than %d nodes",
                            bad_cell, bad_face, CM_FACE_MAX_NODES);
        if (bad_n < 3)
            return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_boundary_create: cell %zu: face %d has %d nodes", bad_cell,
                            bad_face, bad_n);
        return cm_error(ctx, CM_ERR_FORMAT, "cm_mesh_boundary_create: cell %zu: node %lld out of range (%zu nodes)",
                        bad_cell, (long long)bad_node, nn);
    }
    /* bucket starts, and each part's first slot inside each bucket */
    int64_t run = 0;
    for (size_t v = 0; v < nn; ++v) {
        w->bucket_off[v] = run;
        for (int t = 0; t < parts; ++t) {
            cm_idx *h = hist + (size_t)t * (nn + 1);
            const cm_idx cnt = h[v];
            h[v] = (cm_idx)run;
            run += cnt;
        }
    }
    w->bucket_off[nn] = run;
#pragma omp parallel num_threads(parts) if (nc > CM_BOUNDARY_PARALLEL_MIN)
    for (int t = omp_get_thread_num(); t < parts; t += omp_get_num_threads()) {
        int64_t nodes[CM_FACE_MAX_NODES];
        cm_idx *pos = hist + (size_t)t * (nn + 1);
        const size_t c0 = nc * (size_t)t / (size_t)parts, c1 = nc * (size_t)(t + 1) / (size_t)parts;
        for (size_t c = c0; c < c1; ++c) {
            const int nf = (int)(w->inst_off[c + 1] - w->inst_off[c]);
            for (int f = 0; f < nf; ++f) {
                face_key key;
                const int n = face_nodes(mesh, ft, c, f, nodes);
                const int64_t mn = make_key(nodes, n, (cm_idx)(w->inst_off[c] + f), &key);
                w->bucket[pos[mn]++] = key;
            }
        }
    }
    free(hist);
    return CM_OK;
}

/* Phase 2: inside each bucket, sort by node set and link equal faces; counts non-manifold
 * faces (3+ cells). Buckets are independent: OpenMP over nodes. */
/* Hashed keys (faces of more than four nodes): confirmed on the node lists. */
static int same_long_face(const cm_mesh *mesh, const faces_of_types *ft, const work *w, const face_key *x,
                          const face_key *y)
{
    int64_t nx[CM_FACE_MAX_NODES], ny[CM_FACE_MAX_NODES];
    const cm_idx cx = w->inst_cell[x->inst], cy = w->inst_cell[y->inst];
    const int n = face_nodes(mesh, ft, (size_t)cx, (int)(x->inst - w->inst_off[cx]), nx);
    if (n != face_nodes(mesh, ft, (size_t)cy, (int)(y->inst - w->inst_off[cy]), ny)) return 0;
    sort_nodes(nx, n);
    sort_nodes(ny, n);
    return memcmp(nx, ny, (size_t)n * sizeof *nx) == 0;
}

static inline int same_face(const cm_mesh *mesh, const faces_of_types *ft, const work *w, const face_key *x,
                            const face_key *y)
{
    if (!key_eq(x, y)) return 0;
    return x->c > -2 || same_long_face(mesh, ft, w, x, y);
}

/* Links the run of keys equal to keys[first] among keys[first..end) into a cycle (ascending
 * instances); returns the run length. done marks the members. */
static size_t link_run(const cm_mesh *mesh, const faces_of_types *ft, const work *w, cm_idx *mate,
                       const face_key *keys, unsigned char *done, size_t end, size_t first)
{
    size_t r = 1, prev = first;
    for (size_t e = first + 1; e < end; ++e) {
        if (done[e] || !same_face(mesh, ft, w, &keys[first], &keys[e])) continue;
        done[e] = 1;
        mate[keys[prev].inst] = keys[e].inst;
        prev = e;
        ++r;
    }
    mate[keys[prev].inst] = r == 1 ? -1 : keys[first].inst;
    return r;
}

/* Phase 2: inside each bucket, link equal faces; count non-manifold faces (3+ cells).
 * Buckets are independent: OpenMP over nodes. Small buckets (all of them for standard
 * cells) are matched pairwise in place; large ones (polyhedral meshes) are sorted first. */
static cm_status match_faces(cm_context *ctx, const cm_mesh *mesh, const faces_of_types *ft, work *w,
                             int threads, size_t *n_nonmanifold)
{
    const long long nn = (long long)mesh->n_nodes;
    size_t nonmanifold = 0;
    int failed = 0;
#pragma omp parallel for schedule(static, 1024) num_threads(threads) if (nn > CM_BOUNDARY_PARALLEL_MIN) reduction(+ : nonmanifold)
    for (long long v = 0; v < nn; ++v) {
        face_key *keys = w->bucket + w->bucket_off[v];
        const size_t k = (size_t)(w->bucket_off[v + 1] - w->bucket_off[v]);
        if (k == 1) w->mate[keys[0].inst] = -1;
        if (k < 2) continue;
        /* small buckets (all of them for standard cells): pairwise; large ones (polyhedral
         * meshes) sorted first so that each run is scanned within its equal keys */
        unsigned char small_done[64], *done = k <= 64 ? small_done : malloc(k);
        if (!done) {
#pragma omp atomic write
            failed = 1;
            continue;
        }
        memset(done, 0, k);
        if (k > 64) qsort(keys, k, sizeof *keys, key_cmp);
        for (size_t j = 0; j < k; ++j) {
            if (done[j]) continue;
            done[j] = 1;
            size_t end = k;
            if (k > 64)
                for (end = j + 1; end < k && key_eq(&keys[j], &keys[end]);) ++end;
            const size_t r = link_run(mesh, ft, w, w->mate, keys, done, end, j);
            if (r >= 3) ++nonmanifold;
        }
        if (done != small_done) free(done);
    }
    *n_nonmanifold = nonmanifold;
    if (failed) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    return CM_OK;
}

/* Phase 3: components by union-find over matched faces; duplicates among the cells that share
 * their first face (a copy shares every face, so looking at one suffices). */
static cm_status components(cm_context *ctx, const cm_mesh *mesh, work *w, size_t ni, int threads,
                            cm_mesh_boundary *b)
{
    const size_t nc = mesh->n_cells;
    w->parent = malloc((nc ? nc : 1) * sizeof *w->parent);
    b->cell_component = malloc((nc ? nc : 1) * sizeof *b->cell_component);
    if (!w->parent || !b->cell_component)
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    for (size_t c = 0; c < nc; ++c) w->parent[c] = (cm_idx)c;
    for (size_t i = 0; i < ni; ++i)
        if (w->mate[i] > (cm_idx)i) uf_union(w->parent, w->inst_cell[i], w->inst_cell[w->mate[i]]);
    int next = 0;
    for (size_t c = 0; c < nc; ++c) {
        const cm_cell_info *info = cm_cell_type_info((cm_cell_type)mesh->type[c]);
        if (!info || info->dim < 3) {
            b->cell_component[c] = -1;
            continue;
        }
        const cm_idx r = uf_find(w->parent, (cm_idx)c);
        /* roots are the smallest cell of their component, so they are labelled first */
        b->cell_component[c] = r == (cm_idx)c ? next++ : b->cell_component[r];
    }
    b->n_components = (size_t)next;

    size_t dup = 0;
    const long long nn = (long long)nc;
#pragma omp parallel for schedule(static) num_threads(threads) if (nn > CM_BOUNDARY_PARALLEL_MIN) reduction(+ : dup)
    for (long long c = 0; c < nn; ++c) {
        const cm_idx i0 = (cm_idx)w->inst_off[c];
        if (w->inst_off[c + 1] == i0 || w->mate[i0] < 0) continue;
        const cm_idx i1 = i0 + 1 < w->inst_off[c + 1] ? i0 + 1 : i0;
        for (cm_idx j = w->mate[i0]; j != i0; j = w->mate[j]) {
            const cm_idx d = w->inst_cell[j];
            if (d >= c) continue;
            /* a copy shares every face: cheap test on the second face before the node sets */
            int shares = i1 == i0;
            for (cm_idx q = w->mate[i1]; !shares && q >= 0 && q != i1; q = w->mate[q]) shares = w->inst_cell[q] == d;
            if (shares && same_node_set(mesh, (size_t)c, (size_t)d)) {
                ++dup;
                break;
            }
        }
    }
    b->n_duplicate = dup;
    return CM_OK;
}

/* Phase 4: faces of one cell, in cell order, and the nodes on them. */
static cm_status collect_boundary(cm_context *ctx, const cm_mesh *mesh, work *w, size_t ni,
                                  cm_mesh_boundary *b)
{
    size_t nb = 0, nb_nodes = 0;
    int64_t nodes[CM_FACE_MAX_NODES];
    for (size_t i = 0; i < ni; ++i) {
        if (w->mate[i] != -1) continue;
        const size_t c = (size_t)w->inst_cell[i];
        ++nb;
        nb_nodes += (size_t)cm_cell_face_nodes(mesh, c, (int)((int64_t)i - w->inst_off[c]), nodes,
                                               CM_FACE_MAX_NODES);
    }
    b->n_faces = nb;
    b->face_offset = malloc((nb + 1) * sizeof *b->face_offset);
    b->face_nodes = malloc((nb_nodes ? nb_nodes : 1) * sizeof *b->face_nodes);
    b->face_cell = malloc((nb ? nb : 1) * sizeof *b->face_cell);
    w->mark = calloc(mesh->n_nodes ? mesh->n_nodes : 1, 1);
    if (!b->face_offset || !b->face_nodes || !b->face_cell || !w->mark)
        return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory (%zu faces)", nb);
    b->face_offset[0] = 0;
    size_t f = 0;
    for (size_t i = 0; i < ni; ++i) {
        if (w->mate[i] != -1) continue;
        const size_t c = (size_t)w->inst_cell[i];
        const int local = (int)((int64_t)i - w->inst_off[c]);
        const int n = cm_cell_face_nodes(mesh, c, local, b->face_nodes + b->face_offset[f],
                                         CM_FACE_MAX_NODES);
        for (int k = 0; k < n; ++k) w->mark[b->face_nodes[b->face_offset[f] + k]] = 1;
        int64_t extra[5];
        const int ne = cm_cell_face_extra_nodes(mesh, c, local, extra);
        for (int k = 0; k < ne; ++k)
            if (extra[k] >= 0 && (size_t)extra[k] < mesh->n_nodes) w->mark[extra[k]] = 1;
        b->face_cell[f] = (int64_t)c;
        b->face_offset[f + 1] = b->face_offset[f] + n;
        ++f;
    }
    size_t m = 0;
    for (size_t v = 0; v < mesh->n_nodes; ++v) m += w->mark[v];
    b->n_nodes = m;
    b->nodes = malloc((m ? m : 1) * sizeof *b->nodes);
    if (!b->nodes) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    m = 0;
    for (size_t v = 0; v < mesh->n_nodes; ++v)
        if (w->mark[v]) b->nodes[m++] = (int64_t)v;
    return CM_OK;
}

cm_status cm_mesh_boundary_create(cm_context *ctx, const cm_mesh *mesh, cm_mesh_boundary **out)
{
    if (!out) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_boundary_create: output is NULL");
    *out = NULL;
    if (!mesh) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_mesh_boundary_create: mesh is NULL");
    cm_mesh_boundary *b = calloc(1, sizeof *b);
    if (!b) return cm_error(ctx, CM_ERR_NOMEM, "cm_mesh_boundary_create: out of memory");
    int threads = cm_context_threads_for(ctx, mesh->n_cells, 1);

    faces_of_types ft;
    faces_init(&ft);
    work w = {0};
    size_t ni = 0;
    cm_status s = bucket_faces(ctx, mesh, &ft, &w, threads, &ni);
    if (s == CM_OK) s = match_faces(ctx, mesh, &ft, &w, threads, &b->n_nonmanifold);
    if (s == CM_OK) s = components(ctx, mesh, &w, ni, threads, b);
    if (s == CM_OK) s = collect_boundary(ctx, mesh, &w, ni, b);
    work_free(&w);
    if (s != CM_OK) {
        cm_mesh_boundary_destroy(&b);
        return s;
    }
    *out = b;
    if (b->n_nonmanifold || b->n_duplicate)
        return cm_error(ctx, CM_WARNING,
                        "cm_mesh_boundary_create: %zu non-manifold faces (shared by 3 or more cells), "
                        "%zu duplicate cells (same nodes as an earlier cell)",
                        b->n_nonmanifold, b->n_duplicate);
    return CM_OK;
}
