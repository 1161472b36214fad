/* `cm_model MODEL T OUT.step`: writes a benchmark model (bore, pipe, bracket) at parameter T
 * in [0, 1] as STEP. `cm_model MODEL T --signature` prints its topology signature and volume. */
#include "models.h"

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
    if (!strcmp(argv[3], "--signature")) {
        static char buf[1 << 16];
        double vol = 0;
        if (cm_model_signature(argv[1], t, buf, (int)sizeof buf, &vol) < 0) {
            fprintf(stderr, "cm_model: %s\n", cm_model_error());
            return 2;
        }
        printf("%svolume %.12g\n", buf, vol);
        return 0;
    }
    const int rc = cm_model_write_step(argv[1], t, argv[3]);
    if (rc != 0) {
        fprintf(stderr, "cm_model: %s\n", cm_model_error());
        return rc == -1 ? 1 : 2;
    }
    return 0;
}
