/* libFuzzer driver for the STEP pre-scan (cad/step_scan.c): linear, constant memory, one-line
 * messages, whatever the bytes. */
#include "step_scan.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) abort();
    cm_status s = cm_step_scan(ctx, "fuzz.step", (const char *)data, size);
    if (s < 0 && strchr(cm_context_message(ctx), '\n')) abort();
    cm_context_destroy(&ctx);
    return 0;
}
