/* Tables of live temporary paths (files in file.c, directories in output_dir.c), so that a
 * program's signal handler can remove them. Slots are claimed and released with atomic
 * exchanges; a handler only reads them and calls async-signal-safe functions. A full table only
 * means that the extra temporaries are not removed on a signal. Internal to core/. */
#ifndef CM_CORE_LIVE_PATHS_H
#define CM_CORE_LIVE_PATHS_H

#include <stdatomic.h>

static inline void cm_live_add(_Atomic(char *) *table, int n, char *path)
{
    for (int i = 0; i < n; ++i) {
        char *expected = NULL;
        if (atomic_compare_exchange_strong(&table[i], &expected, path)) return;
    }
}

static inline void cm_live_remove(_Atomic(char *) *table, int n, const char *path)
{
    for (int i = 0; i < n; ++i) {
        char *expected = (char *)path;
        if (atomic_compare_exchange_strong(&table[i], &expected, NULL)) return;
    }
}

#endif
