/* libFuzzer driver for one mesh reader (CM_FUZZ_EXT picks it by extension: ".msh", ".vtu",
 * ".cas" for Fluent, ...). The readers take paths, so each input goes to a file of that extension first
 * (in /dev/shm when there is one). A reader may refuse anything, but must not crash, leak,
 * hang or let a message span lines, and a mesh it accepts has finite coordinates. */
#include "cadmorph/mesh.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef CM_FUZZ_EXT
#error "define CM_FUZZ_EXT"
#endif

static char path[256];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!path[0])
        snprintf(path, sizeof path, "%s/cm-fuzz-%ld%s", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp",
                 (long)getpid(), CM_FUZZ_EXT);
    FILE *f = fopen(path, "wb");
    if (!f) abort();
    if (size && fwrite(data, 1, size, f) != size) abort();
    fclose(f);
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) abort();
    cm_mesh *m = NULL;
    cm_status s = cm_mesh_read(ctx, path, &m);
    if (s < 0 && (m != NULL || strchr(cm_context_message(ctx), '\n'))) abort();
    for (size_t i = 0; s >= 0 && m && i < 3 * m->n_nodes; ++i)
        if (!isfinite(m->xyz[i])) abort();
    cm_mesh_destroy(&m);
    cm_context_destroy(&ctx);
    return 0;
}
