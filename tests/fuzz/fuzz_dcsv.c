/* libFuzzer driver for the displacement table reader (D.csv) against a mesh of 64 nodes. */
#include "cadmorph/warp.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char path[256];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!path[0])
        snprintf(path, sizeof path, "%s/cm-fuzz-%ld.csv", access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp",
                 (long)getpid());
    FILE *f = fopen(path, "wb");
    if (!f) abort();
    if (size && fwrite(data, 1, size, f) != size) abort();
    fclose(f);
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) abort();
    double disp[64 * 3];
    unsigned char listed[64];
    cm_status s = cm_warp_read_displacements(ctx, path, 64, disp, listed);
    if (s < 0 && strchr(cm_context_message(ctx), '\n')) abort();
    for (int i = 0; s >= 0 && i < 64 * 3; ++i)
        if (!(disp[i] == disp[i]) || disp[i] > 1e150 || disp[i] < -1e150) abort();
    cm_context_destroy(&ctx);
    return 0;
}
