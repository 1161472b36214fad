/* What the RFP Cholesky tests share: their random numbers and a recorder of the progress
 * calls ("rbf factor", monotonic, one total). */
#ifndef CADMORPH_CHOLESKY_TEST_UTIL_H
#define CADMORPH_CHOLESKY_TEST_UTIL_H

#include "test_rng.h"

#include <string.h>

/* uniform in [-0.5, 0.5) from the file's own state */
static inline double chol_urand(uint64_t *state) { return test_rng_range(state, -0.5, 0.5); }

typedef struct calls {
    int count, monotonic, stage_ok;
    double last, total;
} calls;

static inline void on_progress(void *user, const char *stage, double done, double total)
{
    calls *c = user;
    if (c->count > 0 && (done < c->last || total != c->total)) c->monotonic = 0;
    if (strcmp(stage, "rbf factor") != 0) c->stage_ok = 0;
    c->last = done;
    c->total = total;
    ++c->count;
}

#endif
