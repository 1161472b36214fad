/* Whether a path names a readable regular file (study_internal.h): the variant lists and the
 * design tables check their STEP files with it before anything is read. */
#include "study_internal.h"
#include "cadmorph/core.h"

#include <stdio.h>

const char *cm_study_unreadable(const char *path)
{
    /* the input rule of every reader (core.h): a FIFO named in a list must not block */
    const char *why = NULL;
    FILE *f = cm_file_open_quiet(path, &why);
    if (!f) return why;
    fclose(f);
    return NULL;
}
