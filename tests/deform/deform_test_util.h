/* Shared by the deform tests: a seeded generator and lattice helpers. */
#ifndef CADMORPH_TEST_DEFORM_UTIL_H
#define CADMORPH_TEST_DEFORM_UTIL_H

#include "cadmorph/deform.h"

#include <stdint.h>
#include <stdlib.h>

/* xorshift64*: the same numbers on every machine */
static uint64_t test_rng_state = 0x9E3779B97F4A7C15ull;
static inline double urand(void)
{
    test_rng_state ^= test_rng_state >> 12;
    test_rng_state ^= test_rng_state << 25;
    test_rng_state ^= test_rng_state >> 27;
    return (double)((test_rng_state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}
static inline double urange(double a, double b) { return a + (b - a) * urand(); }

/* A rotated, non-axis-aligned lattice: origin o, axes R diag(L) with R from angles. */
static inline void rotated_desc(cm_ffd_desc *d, int n, cm_ffd_basis basis, cm_ffd_knots knots)
{
    cm_ffd_desc_init(d);
    d->n[0] = d->n[1] = d->n[2] = n;
    d->basis = basis;
    d->knots = knots;
    double len[3] = {2.0, 1.5, 1.0}, ang[3] = {10, 20, 30};
    cm_ffd_box_axes(len, ang, d->axes);
    d->origin[0] = 0.3;
    d->origin[1] = -0.2;
    d->origin[2] = 0.5;
}

/* x = origin + A s */
static inline void desc_point(const cm_ffd_desc *d, const double s[3], double x[3])
{
    for (int r = 0; r < 3; ++r)
        x[r] = d->origin[r] + d->axes[3 * r] * s[0] + d->axes[3 * r + 1] * s[1] +
               d->axes[3 * r + 2] * s[2];
}

/* x(u) = sum_p c_p N_p(u) from the public basis (ctrl: #ctrl x 3) */
static inline void lattice_point(const cm_ffd *f, const double *ctrl, const double u[3], double x[3])
{
    size_t cap = cm_ffd_support_size(f);
    int64_t *idx = malloc(cap * sizeof *idx);
    double *w = malloc(cap * sizeof *w);
    size_t q = cm_ffd_basis_eval(f, u, idx, w);
    x[0] = x[1] = x[2] = 0;
    for (size_t e = 0; e < q; ++e)
        for (int r = 0; r < 3; ++r)
            x[r] += w[e] * ctrl[3 * idx[e] + r];
    free(idx);
    free(w);
}

#endif
