/* Merging of duplicate RBF centres: a grid of cell size tol, sorted by cell, so that each
 * centre looks only at the 3^dim cells around it (O(m log m), even on planar faces where
 * many centres share a coordinate). */
#include "rbf_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

typedef struct cell_entry {
    int64_t key[3];
    size_t index;
} cell_entry;

static int key_cmp(const int64_t *a, const int64_t *b)
{
    for (int d = 0; d < 3; ++d) {
        if (a[d] != b[d]) return a[d] < b[d] ? -1 : 1;
    }
    return 0;
}

static int entry_cmp(const void *pa, const void *pb)
{
    const cell_entry *a = pa, *b = pb;
    int c = key_cmp(a->key, b->key);
    if (c) return c;
    return a->index < b->index ? -1 : a->index > b->index;
}

/* First entry with key >= key (lower bound). */
static size_t lower_bound(const cell_entry *e, size_t n, const int64_t *key)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (key_cmp(e[mid].key, key) < 0) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

long cm_rbf_merge_duplicates(int dim, size_t m_in, const double *c, double tol, size_t *rep,
                             size_t *first)
{
    cell_entry *e = malloc((m_in ? m_in : 1) * sizeof *e);
    if (!e) return -1;
    for (size_t i = 0; i < m_in; ++i) {
        for (int d = 0; d < 3; ++d)
            e[i].key[d] = d < dim ? (int64_t)floor(c[d * m_in + i] / tol) : 0;
        e[i].index = i;
    }
    qsort(e, m_in, sizeof *e, entry_cmp);

    const double tol2 = tol * tol;
    const int reach_z = dim == 3 ? 1 : 0;
    size_t count = 0;
    /* In input order, so that the representative of a group is its first input index and
     * every earlier centre already has its merged index. */
    for (size_t i = 0; i < m_in; ++i) {
        size_t best = i;
        int64_t base[3];
        for (int d = 0; d < 3; ++d)
            base[d] = d < dim ? (int64_t)floor(c[d * m_in + i] / tol) : 0;
        for (int dx = -1; dx <= 1; ++dx) {
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dz = -reach_z; dz <= reach_z; ++dz) {
                    int64_t key[3] = {base[0] + dx, base[1] + dy, base[2] + dz};
                    for (size_t s = lower_bound(e, m_in, key);
                         s < m_in && key_cmp(e[s].key, key) == 0 && e[s].index < best; ++s) {
                        size_t j = e[s].index;
                        double r2 = 0.0;
                        for (int d = 0; d < dim; ++d) {
                            double t = c[d * m_in + i] - c[d * m_in + j];
                            r2 += t * t;
                        }
                        if (r2 <= tol2) best = j;
                    }
                }
            }
        }
        if (best == i) {
            first[count] = i;
            rep[i] = count++;
        } else {
            rep[i] = rep[best];
        }
    }
    free(e);
    return (long)count;
}
