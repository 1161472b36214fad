/* Exact nearest-neighbour search over FLANN's C API: a single kd-tree searched with unlimited
 * checks, so the answer is the true nearest point (paper section 4: nearest CAD sample). */
#include "cadmorph/kdtree.h"

#include <flann/flann.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

struct cm_kdtree {
    flann_index_t index;
    const double *xyz; /* FLANN keeps a pointer to the data set: the tree's copy, or the
                          caller's points (borrowed) */
    int owns;
    size_t n;
    struct FLANNParameters params;
};

/* Queries are sent to FLANN in blocks so that the int-sized result buffers stay bounded. */
enum { KDTREE_BLOCK = 1 << 16 };

static struct FLANNParameters kdtree_params(const cm_context *ctx)
{
    struct FLANNParameters p = DEFAULT_FLANN_PARAMETERS;
    p.algorithm = FLANN_INDEX_KDTREE_SINGLE;
    p.checks = FLANN_CHECKS_UNLIMITED;
    p.eps = 0.0f;
    p.leaf_max_size = 10;
    p.log_level = FLANN_LOG_NONE; /* the library never prints */
    p.cores = cm_context_threads_for(ctx, SIZE_MAX, 1); /* set per search below */
    p.random_seed = 1;
    return p;
}

static cm_status create(cm_context *ctx, const double *xyz, size_t n, int borrow,
                        cm_kdtree **tree)
{
    if (!tree) return cm_error(ctx, CM_ERR_ARGUMENT, "cm_kdtree_create: tree is NULL");
    *tree = NULL;
    if (!xyz || n == 0)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_kdtree_create: no points");
    if (n > (size_t)INT_MAX)
        return cm_error(ctx, CM_ERR_UNSUPPORTED,
                        "cm_kdtree_create: %zu points, FLANN indexes at most %d", n, INT_MAX);
    for (size_t i = 0; i < 3 * n; ++i)
        if (!isfinite(xyz[i]))
            return cm_error(ctx, CM_ERR_NUMERIC, "cm_kdtree_create: point %zu is not finite",
                            i / 3);
    cm_kdtree *t = calloc(1, sizeof *t);
    if (!t) return cm_error(ctx, CM_ERR_NOMEM, "cm_kdtree_create: out of memory");
    if (borrow) {
        t->xyz = xyz;
    } else {
        double *copy = malloc(3 * n * sizeof *copy);
        if (!copy) {
            free(t);
            return cm_error(ctx, CM_ERR_NOMEM, "cm_kdtree_create: out of memory for %zu points",
                            n);
        }
        memcpy(copy, xyz, 3 * n * sizeof *copy);
        t->xyz = copy;
        t->owns = 1;
    }
    t->n = n;
    t->params = kdtree_params(ctx);
    float speedup = 0.0f;
    /* FLANN's C API takes a non-const pointer; it only reads the data set */
    t->index = flann_build_index_double((double *)(uintptr_t)t->xyz, (int)n, 3, &speedup,
                                        &t->params);
    if (!t->index) {
        if (t->owns) free((void *)(uintptr_t)t->xyz);
        free(t);
        return cm_error(ctx, CM_ERR_INTERNAL, "cm_kdtree_create: FLANN failed to build the index");
    }
    *tree = t;
    return CM_OK;
}

cm_status cm_kdtree_create(cm_context *ctx, const double *xyz, size_t n, cm_kdtree **tree)
{
    return create(ctx, xyz, n, 0, tree);
}

cm_status cm_kdtree_create_borrowed(cm_context *ctx, const double *xyz, size_t n,
                                    cm_kdtree **tree)
{
    return create(ctx, xyz, n, 1, tree);
}

void cm_kdtree_destroy(cm_kdtree **tree)
{
    if (!tree || !*tree) return;
    cm_kdtree *t = *tree;
    if (t->index) flann_free_index_double(t->index, &t->params);
    if (t->owns) free((void *)(uintptr_t)t->xyz);
    free(t);
    *tree = NULL;
}

size_t cm_kdtree_size(const cm_kdtree *tree) { return tree ? tree->n : 0; }

cm_status cm_kdtree_nearest(cm_context *ctx, const cm_kdtree *tree, const double *query, size_t m,
                            int k, int64_t *index, double *dist2)
{
    if (!tree || (!query && m) || (!index && m))
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_kdtree_nearest: NULL tree, query or index");
    if (k < 1 || (size_t)k > tree->n)
        return cm_error(ctx, CM_ERR_ARGUMENT, "cm_kdtree_nearest: k = %d, tree has %zu points", k,
                        tree->n);
    if (m == 0) return CM_OK;
    size_t block = KDTREE_BLOCK < m ? KDTREE_BLOCK : m;
    int *idx = malloc(block * (size_t)k * sizeof *idx);
    double *d2 = malloc(block * (size_t)k * sizeof *d2);
    if (!idx || !d2) {
        free(idx);
        free(d2);
        return cm_error(ctx, CM_ERR_NOMEM, "cm_kdtree_nearest: out of memory");
    }
    /* FLANN's signature takes non-const pointers but does not write the data or the params. */
    struct FLANNParameters p = tree->params;
    p.cores = cm_context_threads_for(ctx, m, 1);
    cm_status st = CM_OK;
    for (size_t q0 = 0; q0 < m; q0 += block) {
        size_t nq = m - q0 < block ? m - q0 : block;
        if (flann_find_nearest_neighbors_index_double(tree->index, (double *)(query + 3 * q0),
                                                      (int)nq, idx, d2, k, &p) != 0) {
            st = cm_error(ctx, CM_ERR_INTERNAL, "cm_kdtree_nearest: FLANN search failed");
            break;
        }
        for (size_t i = 0; i < nq * (size_t)k; ++i) {
            index[q0 * (size_t)k + i] = idx[i];
            if (dist2) dist2[q0 * (size_t)k + i] = d2[i];
        }
    }
    free(idx);
    free(d2);
    return st;
}
