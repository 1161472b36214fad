/* Tables of live temporary paths (files in file.c, directories in output_dir.c), so that a
 * program's signal handler can remove them. Slots are claimed and released with atomic
 * exchanges; a handler only reads them (atomic_load) and calls async-signal-safe functions. A
 * full table only means that the extra temporaries are not removed on a signal. Internal to
 * core/. */
#ifndef CM_CORE_LIVE_PATHS_H
#define CM_CORE_LIVE_PATHS_H

#include <stdatomic.h>

#define CM_LIVE_SLOTS 64

typedef struct cm_live_table {
    _Atomic(char *) slot[CM_LIVE_SLOTS];
} cm_live_table;

static inline void cm_live_add(cm_live_table *t, char *path)
{
    for (int i = 0; i < CM_LIVE_SLOTS; ++i) {
        char *expected = NULL;
        if (atomic_compare_exchange_strong(&t->slot[i], &expected, path)) return;
    }
}

static inline void cm_live_remove(cm_live_table *t, const char *path)
{
    for (int i = 0; i < CM_LIVE_SLOTS; ++i) {
        char *expected = (char *)path;
        if (atomic_compare_exchange_strong(&t->slot[i], &expected, NULL)) return;
    }
}

#endif
