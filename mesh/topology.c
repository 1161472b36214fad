/* The face matching of volume cells (topology.h): every face instance keyed by its node set,
 * bucketed by its smallest node, equal keys linked into cycles; then, on demand, the unique
 * faces with owner and neighbour and the lookup of a face by its nodes. */
#include "topology.h"

#include "cell_faces.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define CM_TOPOLOGY_PARALLEL_MIN 20000

/* A face instance keyed by its node set, stored in the bucket of its smallest node (which is
 * therefore not stored): a, b, c are the next three smallest nodes, c = -1 for triangles; for
 * faces of more than four nodes (polyhedra only) c is a negative 30-bit hash of the whole
 * sorted list and its length, and equal keys are confirmed on the full lists. */
struct cm_topo_key {
    cm_topo_idx inst;
    cm_topo_idx a, b, c;
};
typedef cm_topo_key face_key;

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
static int64_t make_key(int64_t *nodes, int n, cm_topo_idx inst, face_key *key)
{
    sort_nodes(nodes, n);
    key->inst = inst;
    key->a = (cm_topo_idx)nodes[1];
    key->b = (cm_topo_idx)nodes[2];
    key->c = n > 3 ? (cm_topo_idx)nodes[3] : -1;
    if (n > 4) {
        uint64_t h = 0x9e3779b97f4a7c15ull ^ (uint64_t)n;
        for (int i = 0; i < n; ++i) {
            h ^= (uint64_t)nodes[i] + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
            h *= 0xff51afd7ed558ccdull;
        }
        key->c = -2 - (cm_topo_idx)(h >> 34);
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

/* Face tables by type, looked up once: the face loops below run over millions of faces. */
typedef struct faces_of_types {
    const cm_face_table *t[CM_CELL_TYPE_COUNT];
    int cap; /* the caller's limit on the nodes of one face */
} faces_of_types;

static void faces_init(faces_of_types *ft, int cap)
{
    for (int t = 0; t < CM_CELL_TYPE_COUNT; ++t) ft->t[t] = cm_cell_face_table((cm_cell_type)t);
    ft->cap = cap;
}

static inline int face_count(const cm_mesh *mesh, const faces_of_types *ft, size_t c)
{
    const cm_face_table *t = ft->t[mesh->type[c]];
    return t ? t->n_faces : cm_cell_face_count(mesh, c);
}

static inline int face_nodes(const cm_mesh *mesh, const faces_of_types *ft, size_t c, int f, int64_t *nodes)
{
    const cm_face_table *t = ft->t[mesh->type[c]];
    if (!t) return cm_cell_face_nodes(mesh, c, f, nodes, ft->cap);
    const int64_t *conn = mesh->conn + mesh->offset[c];
    for (int i = 0; i < t->size[f]; ++i) nodes[i] = conn[t->node[f][i]];
    return t->size[f];
}

int cm_mesh_cell_nodes(const cm_mesh *mesh, size_t c, int64_t *out, int cap)
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

void cm_topology_free(cm_topology *t)
{
    if (!t) return;
    free(t->inst_off);
    free(t->inst_cell);
    free(t->mate);
    free(t->face_inst);
    free(t->owner);
    free(t->neighbour);
    free(t->bucket_off);
    free(t->bucket);
    memset(t, 0, sizeof *t);
}

typedef struct bad_face {
    size_t cell; /* SIZE_MAX: none */
    int face, n;
    int64_t node;
} bad_face;

/* Counts the instances of each bucket (smallest node) into parts histograms, one per
 * contiguous cell range, so that both passes run in parallel and every bucket still lists its
 * instances in ascending order (part by part). Records the first face (in instance order)
 * with fewer than 3 or too many nodes or a node out of range. */
static void count_pass(const cm_mesh *mesh, const faces_of_types *ft, cm_topology *t, cm_topo_idx *hist,
                       int parts, bad_face *bad)
{
    const size_t nc = mesh->n_cells, nn = mesh->n_nodes;
    bad->cell = SIZE_MAX;
#pragma omp parallel num_threads(parts) if (nc > CM_TOPOLOGY_PARALLEL_MIN)
    for (int p = omp_get_thread_num(); p < parts; p += omp_get_num_threads()) {
        int64_t nodes[CM_TOPOLOGY_MAX_FACE_NODES];
        cm_topo_idx *h = hist + (size_t)p * (nn + 1);
        const size_t c0 = nc * (size_t)p / (size_t)parts, c1 = nc * (size_t)(p + 1) / (size_t)parts;
        for (size_t c = c0; c < c1; ++c) {
            const int nf = (int)(t->inst_off[c + 1] - t->inst_off[c]);
            for (int f = 0; f < nf; ++f) {
                const int n = face_nodes(mesh, ft, c, f, nodes);
                int64_t mn = n > 0 ? nodes[0] : 0, out = 0;
                int outside = 0;
                for (int k = 0; k < n; ++k) {
                    if (nodes[k] < 0 || (size_t)nodes[k] >= nn) {
                        outside = 1;
                        out = nodes[k];
                    }
                    if (nodes[k] < mn) mn = nodes[k];
                }
                if (n < 3 || outside) {
#pragma omp critical(cm_topology_error)
                    if (c < bad->cell) {
                        bad->cell = c;
                        bad->face = f;
                        bad->n = n;
                        bad->node = out;
                    }
                    c = c1; /* stop this part */
                    break;
                }
                t->inst_cell[t->inst_off[c] + f] = (cm_topo_idx)c;
                ++h[mn];
            }
        }
    }
}

static cm_status nomem(cm_topology_problem *why, int counted, size_t n_inst)
{
    why->what = CM_TOPOLOGY_NOMEM;
    why->counted = counted;
    why->n_inst = n_inst;
    return CM_ERR_NOMEM;
}

/* Phase 1: every face instance and its key, bucketed by its smallest node (a hash table
 * whose hash is the smallest node, chained in CSR form: each bucket is tiny - about 12 faces
 * for a tet mesh). Keys are made here, in cell order, so that matching never goes back to
 * the connectivity of scattered cells. A bad face truncates the instances before it. */
static cm_status bucket_faces(const cm_mesh *mesh, const faces_of_types *ft, cm_topology *t, int threads,
                              cm_topology_problem *why)
{
    const size_t nc = mesh->n_cells, nn = mesh->n_nodes;
    t->inst_off = malloc((nc + 1) * sizeof *t->inst_off);
    if (!t->inst_off) return nomem(why, 0, 0);
    t->inst_off[0] = 0;
    for (size_t c = 0; c < nc; ++c) t->inst_off[c + 1] = t->inst_off[c] + face_count(mesh, ft, c);
    size_t ni = (size_t)t->inst_off[nc];
    t->n_inst = ni;
    if (nn > CM_TOPO_IDX_MAX || nc > CM_TOPO_IDX_MAX || ni > CM_TOPO_IDX_MAX) {
        why->what = CM_TOPOLOGY_TOO_LARGE;
        why->n_nodes = nn;
        why->n_cells = nc;
        why->n_inst = ni;
        return CM_ERR_UNSUPPORTED;
    }
    t->inst_cell = malloc((ni ? ni : 1) * sizeof *t->inst_cell);
    t->mate = malloc((ni ? ni : 1) * sizeof *t->mate);
    t->bucket = malloc((ni ? ni : 1) * sizeof *t->bucket);
    t->bucket_off = malloc((nn + 1) * sizeof *t->bucket_off);
    if (!t->inst_cell || !t->mate || !t->bucket || !t->bucket_off) return nomem(why, 1, ni);
    const int parts = threads < 1 ? 1 : threads > 4 ? 4 : threads;
    cm_topo_idx *hist = calloc((size_t)parts * (nn + 1), sizeof *hist);
    if (!hist) return nomem(why, 0, 0);
    bad_face bad;
    count_pass(mesh, ft, t, hist, parts, &bad);
    cm_status status = CM_OK;
    if (bad.cell != SIZE_MAX) {
        why->what = bad.n >= 3 ? CM_TOPOLOGY_BAD_NODE : CM_TOPOLOGY_BAD_FACE;
        why->cell = bad.cell;
        why->face = bad.face;
        why->n = bad.n;
        why->node = bad.node;
        why->n_nodes = nn;
        status = bad.n < 0 ? CM_ERR_UNSUPPORTED : CM_ERR_FORMAT;
        /* keep the instances before the bad one, counted again */
        const int64_t end = t->inst_off[bad.cell] + bad.face;
        for (size_t c = 0; c <= nc; ++c)
            if (t->inst_off[c] > end) t->inst_off[c] = end;
        ni = (size_t)end;
        t->n_inst = ni;
        memset(hist, 0, (size_t)parts * (nn + 1) * sizeof *hist);
        count_pass(mesh, ft, t, hist, parts, &bad);
    }
    /* bucket starts, and each part's first slot inside each bucket */
    int64_t run = 0;
    for (size_t v = 0; v < nn; ++v) {
        t->bucket_off[v] = run;
        for (int p = 0; p < parts; ++p) {
            cm_topo_idx *h = hist + (size_t)p * (nn + 1);
            const cm_topo_idx cnt = h[v];
            h[v] = (cm_topo_idx)run;
            run += cnt;
        }
    }
    t->bucket_off[nn] = run;
#pragma omp parallel num_threads(parts) if (nc > CM_TOPOLOGY_PARALLEL_MIN)
    for (int p = omp_get_thread_num(); p < parts; p += omp_get_num_threads()) {
        int64_t nodes[CM_TOPOLOGY_MAX_FACE_NODES];
        cm_topo_idx *pos = hist + (size_t)p * (nn + 1);
        const size_t c0 = nc * (size_t)p / (size_t)parts, c1 = nc * (size_t)(p + 1) / (size_t)parts;
        for (size_t c = c0; c < c1; ++c) {
            const int nf = (int)(t->inst_off[c + 1] - t->inst_off[c]);
            for (int f = 0; f < nf; ++f) {
                face_key key;
                const int n = face_nodes(mesh, ft, c, f, nodes);
                const int64_t mn = make_key(nodes, n, (cm_topo_idx)(t->inst_off[c] + f), &key);
                t->bucket[pos[mn]++] = key;
            }
        }
    }
    free(hist);
    return status;
}

/* Hashed keys (faces of more than four nodes): confirmed on the node lists. */
static int same_long_face(const cm_mesh *mesh, const faces_of_types *ft, const cm_topology *t, const face_key *x,
                          const face_key *y)
{
    int64_t nx[CM_TOPOLOGY_MAX_FACE_NODES], ny[CM_TOPOLOGY_MAX_FACE_NODES];
    const cm_topo_idx cx = t->inst_cell[x->inst], cy = t->inst_cell[y->inst];
    const int n = face_nodes(mesh, ft, (size_t)cx, (int)(x->inst - t->inst_off[cx]), nx);
    if (n != face_nodes(mesh, ft, (size_t)cy, (int)(y->inst - t->inst_off[cy]), ny)) return 0;
    sort_nodes(nx, n);
    sort_nodes(ny, n);
    return memcmp(nx, ny, (size_t)n * sizeof *nx) == 0;
}

static inline int same_face(const cm_mesh *mesh, const faces_of_types *ft, const cm_topology *t, const face_key *x,
                            const face_key *y)
{
    if (!key_eq(x, y)) return 0;
    return x->c > -2 || same_long_face(mesh, ft, t, x, y);
}

/* Links the run of keys equal to keys[first] among keys[first..end) into a cycle (ascending
 * instances); returns the run length. done marks the members. */
static size_t link_run(const cm_mesh *mesh, const faces_of_types *ft, const cm_topology *t, cm_topo_idx *mate,
                       const face_key *keys, unsigned char *done, size_t end, size_t first)
{
    size_t r = 1, prev = first;
    for (size_t e = first + 1; e < end; ++e) {
        if (done[e] || !same_face(mesh, ft, t, &keys[first], &keys[e])) continue;
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
 * cells) are matched pairwise in place; large ones (polyhedral meshes) are sorted first, so
 * that each run is scanned within its equal keys. */
static cm_status match_faces(const cm_mesh *mesh, const faces_of_types *ft, cm_topology *t, int threads,
                             cm_topology_problem *why)
{
    const long long nn = (long long)mesh->n_nodes;
    size_t nonmanifold = 0;
    int failed = 0;
#pragma omp parallel for schedule(static, 1024) num_threads(threads) if (nn > CM_TOPOLOGY_PARALLEL_MIN) reduction(+ : nonmanifold)
    for (long long v = 0; v < nn; ++v) {
        face_key *keys = t->bucket + t->bucket_off[v];
        const size_t k = (size_t)(t->bucket_off[v + 1] - t->bucket_off[v]);
        if (k == 1) t->mate[keys[0].inst] = -1;
        if (k < 2) continue;
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
            const size_t r = link_run(mesh, ft, t, t->mate, keys, done, end, j);
            if (r >= 3) ++nonmanifold;
        }
        if (done != small_done) free(done);
    }
    t->n_nonmanifold = nonmanifold;
    if (failed) return nomem(why, 0, 0);
    return CM_OK;
}

cm_status cm_topology_build(const cm_mesh *mesh, int max_face_nodes, int threads, cm_topology *t,
                            cm_topology_problem *why)
{
    memset(t, 0, sizeof *t);
    memset(why, 0, sizeof *why);
    if (max_face_nodes > CM_TOPOLOGY_MAX_FACE_NODES || max_face_nodes < 3) max_face_nodes = CM_TOPOLOGY_MAX_FACE_NODES;
    t->n_cells = mesh->n_cells;
    t->n_nodes = mesh->n_nodes;
    t->max_face_nodes = max_face_nodes;
    faces_of_types ft;
    faces_init(&ft, max_face_nodes);
    cm_status s = bucket_faces(mesh, &ft, t, threads, why);
    /* a bad face leaves the instances before it to match (see topology.h) */
    if (s == CM_OK || why->what == CM_TOPOLOGY_BAD_FACE || why->what == CM_TOPOLOGY_BAD_NODE) {
        const cm_status m = match_faces(mesh, &ft, t, threads, why);
        if (m != CM_OK) s = m;
    }
    return s;
}

cm_status cm_topology_faces(cm_topology *t)
{
    const size_t ni = t->n_inst;
    /* an instance that some smaller one links to is not the first of its face */
    unsigned char *later = calloc(ni ? ni : 1, 1);
    if (!later) return CM_ERR_NOMEM;
    for (size_t i = 0; i < ni; ++i)
        if (t->mate[i] > (cm_topo_idx)i) later[t->mate[i]] = 1;
    size_t nf = 0;
    for (size_t i = 0; i < ni; ++i) nf += !later[i];
    t->face_inst = malloc((nf ? nf : 1) * sizeof *t->face_inst);
    t->owner = malloc((nf ? nf : 1) * sizeof *t->owner);
    t->neighbour = malloc((nf ? nf : 1) * sizeof *t->neighbour);
    if (!t->face_inst || !t->owner || !t->neighbour) {
        free(later);
        return CM_ERR_NOMEM;
    }
    size_t f = 0;
    for (size_t i = 0; i < ni; ++i) {
        if (later[i]) continue;
        const cm_topo_idx m = t->mate[i];
        t->face_inst[f] = (cm_topo_idx)i;
        t->owner[f] = t->inst_cell[i];
        t->neighbour[f] = m >= 0 ? t->inst_cell[m] : -1;
        ++f;
    }
    t->n_faces = nf;
    free(later);
    return CM_OK;
}

int64_t cm_topology_find(const cm_topology *t, const cm_mesh *mesh, int64_t *nodes, int n)
{
    if (n < 3 || n > t->max_face_nodes || !t->face_inst) return -1;
    for (int k = 0; k < n; ++k)
        if (nodes[k] < 0 || (size_t)nodes[k] >= t->n_nodes) return -1;
    faces_of_types ft;
    faces_init(&ft, t->max_face_nodes);
    face_key key;
    const int64_t v = make_key(nodes, n, -1, &key);
    int64_t hit = -1;
    for (int64_t e = t->bucket_off[v]; e < t->bucket_off[v + 1] && hit < 0; ++e) {
        const face_key *k = &t->bucket[e];
        if (!key_eq(&key, k)) continue;
        if (key.c <= -2) { /* hashed: compare the lists */
            int64_t other[CM_TOPOLOGY_MAX_FACE_NODES];
            const cm_topo_idx c = t->inst_cell[k->inst];
            if (face_nodes(mesh, &ft, (size_t)c, (int)(k->inst - t->inst_off[c]), other) != n) continue;
            sort_nodes(other, n);
            if (memcmp(other, nodes, (size_t)n * sizeof *nodes)) continue;
        }
        hit = k->inst;
    }
    if (hit < 0) return -1;
    /* the face's first instance is the smallest of its cycle */
    int64_t first = hit;
    for (cm_topo_idx j = t->mate[hit]; j >= 0 && j != hit; j = t->mate[j])
        if (j < first) first = j;
    size_t lo = 0, hi = t->n_faces;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (t->face_inst[mid] < first) lo = mid + 1;
        else hi = mid;
    }
    return lo < t->n_faces && t->face_inst[lo] == first ? (int64_t)lo : -1;
}

int64_t cm_topology_first_overshared(const cm_topology *t)
{
    int64_t best = -1;
    if (!t->n_nonmanifold || !t->face_inst) return -1;
    for (size_t f = 0; f < t->n_faces; ++f) {
        const cm_topo_idx a = t->face_inst[f], b = t->mate[a];
        if (b < 0 || t->mate[b] == a) continue;
        const int64_t third = t->mate[b];
        if (best < 0 || third < best) best = third;
    }
    return best;
}
