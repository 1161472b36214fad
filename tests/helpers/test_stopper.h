/* A progress callback that asks to stop (cm_context_interrupt) on its k-th call, for the
 * tests of stopping long calls on request (docs/DESIGN.md, "progress"). Header-only: static
 * functions, each test includes what it uses. */
#ifndef CADMORPH_TEST_STOPPER_H
#define CADMORPH_TEST_STOPPER_H

#include "cadmorph/core.h"

#include <stdio.h>
#include <string.h>

typedef struct stopper {
    cm_context *ctx;
    int calls, at;  /* progress calls seen; the one that asks to stop (0: none) */
    char stage[64]; /* the stage of that call */
} stopper;

/* The cm_progress_fn: user is a stopper. */
static void on_progress(void *user, const char *stage, double done, double total)
{
    (void)done;
    (void)total;
    stopper *s = user;
    if (++s->calls == s->at) {
        snprintf(s->stage, sizeof s->stage, "%s", stage);
        cm_context_interrupt(s->ctx);
    }
}

/* Counts again from 0 and asks to stop on call `at` (0: never). */
static inline void arm(stopper *s, int at)
{
    s->calls = 0;
    s->at = at;
    s->stage[0] = 0;
}

/* s is the status of a call stopped on request, with its message. */
static inline int interrupted(cm_context *ctx, cm_status s)
{
    return s == CM_ERR_INTERRUPTED && strstr(cm_context_message(ctx), "interrupted") != NULL;
}

#endif
