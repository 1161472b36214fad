/* Whether a path names a readable regular file (study_internal.h): the variant lists and the
 * design tables check their STEP files with it before anything is read. */
#include "study_internal.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>

const char *cm_study_unreadable(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0) return strerror(errno);
    if (S_ISDIR(st.st_mode)) return "is a directory";
    FILE *f = fopen(path, "rb");
    if (!f) return strerror(errno);
    fclose(f);
    return NULL;
}
