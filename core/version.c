/* The library's version, from the generated cadmorph/version.h. */
#include "cadmorph/version.h"

const char *cm_version(void) { return CM_VERSION_STRING; }
