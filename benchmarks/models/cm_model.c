/* `cm_model MODEL T OUT.step`: writes a benchmark model (bore, pipe, bracket) at parameter T
 * in [0, 1] as STEP. `cm_model MODEL T --signature` prints its topology signature and volume. */
#include "cadmorph/models.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: cm_model bore|pipe|bracket T OUT.step | --signature\n");
        return 1;
    }
    char *end = NULL;
    errno = 0;
    const double t = strtod(argv[2], &end);
    if (errno || *end || !(t >= 0 && t <= 1)) {
        fprintf(stderr, "cm_model: T must be a number in [0, 1], got '%s'\n", argv[2]);
        return 1;
    }
    cm_context *ctx = NULL;
    if (cm_context_create(&ctx) != CM_OK) return 4;
    cm_status s;
    if (!strcmp(argv[3], "--signature")) {
        static char buf[1 << 16];
        double vol = 0;
        s = cm_model_signature(ctx, argv[1], t, buf, sizeof buf, &vol);
        if (s >= 0) printf("%svolume %.12g\n", buf, vol);
    } else {
        s = cm_model_write_step(ctx, argv[1], t, argv[3]);
    }
    if (s < 0) fprintf(stderr, "cm_model: %s\n", cm_context_message(ctx));
    cm_context_destroy(&ctx);
    return s >= 0 ? 0 : s == CM_ERR_ARGUMENT ? 1 : 2;
}
